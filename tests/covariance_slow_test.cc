// Linear covariance analysis against a 500-run Monte-Carlo on a car drive (tactical preset,
// representable terms). Slow: ~15 M IMU samples.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "driftlab/covariance.h"
#include "driftlab/error_state.h"
#include "driftlab/mc_statistics.h"
#include "driftlab/monte_carlo.h"
#include "driftlab/presets.h"
#include "driftlab/trajectory.h"
#include "support/motion_builders.h"

namespace driftlab {
namespace {

constexpr double kDeg = M_PI / 180.0;

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
  spec.seed = 11;
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

  const std::vector<EpochSummary> epochs = stats.SummarizeEpochs();
  ASSERT_EQ(epochs.size(), predicted.size());
  for (int c = 0; c < 9; ++c) {
    int inside = 0;
    for (size_t e = 0; e < epochs.size(); ++e) {
      ASSERT_NEAR(epochs[e].t_s, predicted[e].t_s, 1e-9);
      const double p = c < 6 ? predicted[e].sigma[c] : predicted[e].euler_sigma_rad[c - 6];
      const ComponentEpochSummary& s = epochs[e].components[c];
      if (p >= s.std_ci95_low && p <= s.std_ci95_high) ++inside;
    }
    const double fraction = static_cast<double>(inside) / epochs.size();
    const std::string name(ErrorComponentName(static_cast<ErrorComponent>(c)));
    std::printf("%-22s inside at %5.1f %% of %zu epochs; final predicted %.4g MC %.4g\n",
                name.c_str(), 100.0 * fraction, epochs.size(),
                c < 6 ? predicted.back().sigma[c] : predicted.back().euler_sigma_rad[c - 6],
                epochs.back().components[c].std);
    // Brief: predicted sigma inside the MC sigma's 95 % CI (500 runs: about +-6 %) at >= 90 % of
    // the epochs, for every position, velocity and attitude component.
    EXPECT_GE(fraction, 0.90) << name;
  }
}

}  // namespace
}  // namespace driftlab
