// Linear covariance analysis against a 500-run Monte-Carlo on a car drive (tactical preset,
// representable terms). Slow: ~15 M IMU samples.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "driftlab/allan.h"
#include "driftlab/covariance.h"
#include "driftlab/error_state.h"
#include "driftlab/mc_statistics.h"
#include "driftlab/monte_carlo.h"
#include "driftlab/presets.h"
#include "driftlab/trajectory.h"
#include "support/bonferroni_checks.h"
#include "support/motion_builders.h"

namespace driftlab {
namespace {

// Car drive of 300 s: static, accelerate to 20 m/s, turns both ways, straights, slow down.
MotionSpec CarDrive() {
  MotionSpec m;
  m.initial.llh = {45.0 * kDeg, 7.0 * kDeg, 300.0};
  m.segments.push_back(StaticSegment{10.0});
  AccelerateSegment a;
  a.acceleration_m_per_s2 = 2.0;
  a.target_speed_m_per_s = 20.0;
  m.segments.push_back(a);
  m.segments.push_back(ConstantVelocitySegment{40.0});
  m.segments.push_back(testing::TurnByRate(10.0, 90.0, 2.0));
  m.segments.push_back(ConstantVelocitySegment{60.0});
  m.segments.push_back(testing::TurnByRate(-15.0, 180.0, 2.0));
  m.segments.push_back(ConstantVelocitySegment{100.0});
  AccelerateSegment d;
  d.acceleration_m_per_s2 = 1.0;
  d.target_speed_m_per_s = 5.0;
  m.segments.push_back(d);
  m.segments.push_back(ConstantVelocitySegment{40.0});
  return m;
}

// Acceptance criterion (family-wise, not per epoch). Epochs of one run are strongly correlated
// (one turn-on bias draw drives every later epoch), so "inside at >= 90 % of epochs" fails far
// more often than its nominal level. Instead m = 5 epochs per component, chosen by rule (evenly
// spaced among the epochs after the start, ending at the last), x 9 components = 45 checks, and
// EVERY check must pass at the Bonferroni-corrected two-sided level alpha = 0.05 / 45 = 1.1e-3:
// family-wise false-alarm probability <= 5 % whatever the correlation between epochs (Bonferroni
// needs no independence). A check: for N = 500 independent Gaussian runs (N - 1) s^2 / sigma^2 ~
// chi2(N - 1) (Papoulis & Pillai, 4th ed., 8.3), so the MC / predicted variance ratio must lie in
// [chi2_{alpha/2}(499), chi2_{1 - alpha/2}(499)] / 499 = [0.81, 1.22] (-10 % / +10 % in
// sigma; quantiles by ChiSquareQuantile, allan.h). Seed 1, the first tried. The check:
// support/bonferroni_checks.h.

TEST(LinearCovarianceSlow, FreeInertialCarDriveSigmaMatchesFiveHundredRuns) {
  MonteCarloSpec spec;
  spec.simulation.motion = CarDrive();
  spec.simulation.rate_hz = 100.0;
  ImuErrorModel model = FindImuPreset("tactical");
  for (TriadErrorParams* p : {&model.gyro, &model.accel}) {
    p->bias_flicker = {};  // not representable by one bias state (error_state.h)
    p->scale_factor_sigma = 0.0;
    p->misalignment_sigma_rad = 0.0;
    p->range = 0.0;
  }
  spec.sensor = model;
  spec.runs = 500;
  spec.seed = 1;  // seed 1, the first tried
  spec.initial_errors.position_ned_m = Vector3d(2.0, 2.0, 3.0);
  spec.initial_errors.velocity_ned_m_per_s = Vector3d(0.05, 0.05, 0.05);
  spec.initial_errors.attitude_rad = Vector3d(0.5e-3, 0.5e-3, 3e-3);
  spec.epoch_every_samples = 200;  // 2 s
  const MonteCarloStatistics stats = RunMonteCarlo(spec);

  const Trajectory t = GenerateTrajectory(spec.simulation.motion, spec.simulation.rate_hz);
  const ErrorStateNoiseFromImu noise = MakeErrorStateNoise(model);
  ASSERT_TRUE(noise.unrepresented.empty());
  const ErrorStateMatrix P0 = InitialErrorCovariance(
      spec.initial_errors.position_ned_m, spec.initial_errors.velocity_ned_m_per_s,
      spec.initial_errors.attitude_rad, t.truth[0].euler(), noise.noise);
  CovarianceAnalysisOptions o;
  o.step_samples = 10;
  o.epoch_every_samples = 200;
  const std::vector<CovarianceEpoch> predicted = FreeInertialCovariance(t, noise.noise, P0, o);

  testing::ExpectMonteCarloSigmaMatchesPrediction(stats, predicted);
}

}  // namespace
}  // namespace driftlab
