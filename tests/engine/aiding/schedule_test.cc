// The one aiding schedule (aiding.h AidingSchedule): which aid measures at which IMU sample.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "driftlab/aiding.h"

namespace driftlab {
namespace {

// GNSS at 2 Hz with an outage [3, 4) s, barometer at 5 Hz, ZUPT at 1 Hz while static (the first
// 2 s and from 5 s on), at 10 Hz from sample 1 to 80: the samples and bits of each aid.
TEST(AidingSchedule, EachAidAtItsRateOutsideOutagesAndZuptOnlyWhileStatic) {
  AidingSpec spec;
  GnssConfig gnss;
  gnss.rate_hz = 2.0;
  gnss.outages.push_back(GnssOutage{3.0, 1.0});
  spec.gnss = gnss;
  BarometerConfig baro;
  baro.rate_hz = 5.0;
  spec.barometer = baro;
  ZuptConfig zupt;
  zupt.rate_hz = 1.0;
  spec.zupt = zupt;
  const AidingSchedule schedule(MakeAidingSensors(spec, 10.0), 10.0, 1, 80,
                                [](double t) { return t <= 2.0 || t >= 5.0; });
  ASSERT_EQ(schedule.sensors().size(), 3u);
  EXPECT_EQ(schedule.sensors()[0]->path(), "aiding.gnss");
  EXPECT_EQ(schedule.sensors()[1]->path(), "aiding.barometer");
  EXPECT_EQ(schedule.sensors()[2]->path(), "aiding.zupt");
  std::vector<int64_t> gnss_k, baro_k, zupt_k;
  for (int64_t k = 0; k <= 100; ++k) {
    const uint32_t due = schedule.Due(k, 0.1 * static_cast<double>(k));
    if (due & 1u) gnss_k.push_back(k);
    if (due & 2u) baro_k.push_back(k);
    if (due & 4u) zupt_k.push_back(k);
    EXPECT_EQ(due >> 3, 0u) << k;
  }
  // Sample 0 is before first_k, samples above 80 after n; GNSS none in [3, 4) s.
  EXPECT_EQ(gnss_k, (std::vector<int64_t>{5, 10, 15, 20, 25, 40, 45, 50, 55, 60, 65, 70, 75, 80}));
  std::vector<int64_t> every_other;
  for (int64_t k = 2; k <= 80; k += 2) every_other.push_back(k);
  EXPECT_EQ(baro_k, every_other);
  EXPECT_EQ(zupt_k, (std::vector<int64_t>{10, 20, 50, 60, 70, 80}));
}

// The list of the aids is the filter's order and names each aid's fields.
TEST(AidingSchedule, AidsInTheFiltersOrderWithTheirPaths) {
  AidingSpec spec;
  spec.zupt = ZuptConfig();
  spec.barometer = BarometerConfig();
  spec.gnss = GnssConfig();
  const AidingSensors sensors = MakeAidingSensors(spec, 100.0);
  ASSERT_EQ(sensors.size(), 3u);
  EXPECT_EQ(sensors[0]->path(), "aiding.gnss");
  EXPECT_EQ(sensors[1]->path(), "aiding.barometer");
  EXPECT_EQ(sensors[2]->path(), "aiding.zupt");
  EXPECT_EQ(AidingSensorPaths(spec),
            (std::vector<std::string>{"aiding.gnss", "aiding.barometer", "aiding.zupt"}));
}

}  // namespace
}  // namespace driftlab
