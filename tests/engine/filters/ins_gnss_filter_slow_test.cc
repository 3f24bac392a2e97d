// INS/GNSS filter on a 400 s car drive at 100 Hz with a 60 s outage, 200 runs (slow: ~8 M
// filter steps).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "driftlab/gnss.h"
#include "driftlab/ins_gnss_filter.h"
#include "driftlab/presets.h"
#include "driftlab/random.h"
#include "driftlab/sensors.h"
#include "driftlab/trajectory.h"
#include "support/ins_gnss_scenarios.h"

namespace driftlab {
namespace {

using testing::DriveWithFinalStraight;

// Seed 1, the first tried. Acceptance: every check at its Bonferroni-corrected level, family-wise
// false alarm <= 5 % (ins_gnss_scenarios.h): NEES, 200 runs: average 15-state NEES at 5 epochs,
// alpha = 0.01 each, chi2(3000) / 200 bounds [14.02, 16.02]; outage, 200 runs: MC / predicted
// variance at 5 outage epochs x north, east = 10 checks, alpha = 0.005 each, chi2(200) / 200
// bounds [0.74, 1.30].
constexpr uint64_t kSeed = 1;

TEST(InsGnssFilterSlow, NeesOfTwoHundredRunsWithinChiSquareBounds) {
  // 200 runs, 100 Hz, an epoch every second.
  testing::ExpectNeesWithinChiSquareBounds(GenerateTrajectory(DriveWithFinalStraight(300.0), 100.0),
                                           200, 100, kSeed);
}

TEST(InsGnssFilterSlow, HorizontalErrorDuringSixtySecondOutageFollowsPrediction) {
  // 200 runs, 100 Hz, outage from 150 s to 210 s.
  testing::ExpectOutageFollowsPrediction(GenerateTrajectory(DriveWithFinalStraight(300.0), 100.0),
                                         150.0, 200, 100, kSeed);
}

}  // namespace
}  // namespace driftlab
