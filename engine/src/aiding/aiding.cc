// The list of the EKF's aiding sensors (MakeAidingSensors), the checks common to all aids, and the
// per-run aids of a schedule. Each sensor's model and simulator are in its own file (gnss.cc,
// barometer.cc, zupt.cc, magnetometer.cc, ...); the schedule is in schedule.cc.
#include "driftlab/aiding.h"

#include <cmath>

#include "driftlab/spec_error.h"

namespace driftlab {
int64_t AidingDecimation(double rate_hz, double imu_rate_hz, const std::string& field) {
  if (!std::isfinite(rate_hz) || rate_hz <= 0.0 || rate_hz > imu_rate_hz) {
    throw SpecError(field, ValueText(rate_hz),
                    "0 < rate_hz <= " + ValueText(imu_rate_hz) + " Hz (not above the IMU rate)");
  }
  const double ratio = imu_rate_hz / rate_hz;
  if (std::abs(ratio - std::round(ratio)) > 1e-9 * ratio) {
    throw SpecError(field, ValueText(rate_hz),
                    "the IMU rate " + ValueText(imu_rate_hz) + " Hz divided by an integer");
  }
  return static_cast<int64_t>(std::llround(ratio));
}

AidingSensors MakeAidingSensors(const AidingSpec& a, double imu_rate_hz) {
  AidingSensors out;
  if (a.gnss) out.push_back(MakeGnssSensor(*a.gnss, imu_rate_hz));
  if (a.barometer) out.push_back(MakeBarometerSensor(*a.barometer, imu_rate_hz));
  if (a.zupt) out.push_back(MakeZuptSensor(*a.zupt, imu_rate_hz));
  if (a.odometer) out.push_back(MakeOdometerSensor(*a.odometer, imu_rate_hz));
  return out;
}

std::vector<std::string> AidingSensorPaths(const AidingSpec& a) {
  std::vector<std::string> out;
  if (a.gnss) out.emplace_back("aiding.gnss");
  if (a.barometer) out.emplace_back("aiding.barometer");
  if (a.zupt) out.emplace_back("aiding.zupt");
  if (a.odometer) out.emplace_back("aiding.odometer");
  return out;
}

void ValidateAidingSpec(const AidingSpec& a, double imu_rate_hz, double duration_s) {
  MakeAidingSensors(a, imu_rate_hz);
  if (a.gnss) {
    for (size_t i = 0; duration_s >= 0.0 && i < a.gnss->outages.size(); ++i) {
      const GnssOutage& o = a.gnss->outages[i];
      const double end_s = o.start_s + o.duration_s;
      if (end_s > duration_s * (1.0 + 1e-12)) {
        throw SpecError("aiding.gnss.outages[" + std::to_string(i) + "].end_s", ValueText(end_s),
                        "<= " + ValueText(duration_s) + " s (the trajectory's duration)");
      }
    }
  }
  if (a.magnetometer) ValidateMagnetometerConfig(*a.magnetometer, imu_rate_hz);
}

AidingRuns StartAidingRuns(const AidingSensors& sensors, const NavEnvironment& env, uint64_t seed,
                           uint32_t run, const ErrorStateLayout& layout,
                           const ErrorStateNoise& noise) {
  AidingRuns out;
  for (const auto& sensor : sensors) {
    out.runs.push_back(sensor->Start(env, seed, run));
    out.first_state.push_back(layout.AidingFirst(noise, sensor->path()));
  }
  return out;
}

}  // namespace driftlab
