// Monte-Carlo runner with navigation filters (monte_carlo.h): the EKF's NEES sums and
// the covariance analysis are bit-identical for any thread count and shard split; the
// complementary filter's tilt at rest is the accelerometer's; a barometer bounds the vertical
// channel as the analysis predicts. Short scenarios; the 500-run statistical checks are in
// tests/app/job/aided_job_slow_test.cc (through the job schema).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "driftlab/monte_carlo.h"
#include "driftlab/presets.h"
#include "driftlab/spec_error.h"
#include "driftlab/trajectory.h"
#include "support/ins_gnss_scenarios.h"
#include "support/motion_builders.h"

namespace driftlab {
namespace {

// 10 s static, accelerate to 10 m/s, a 90 deg turn, 30 s straight, stop, 10 s static.
MotionSpec ShortDrive() {
  MotionSpec m;
  m.initial.llh = {45.0 * kDeg, 7.0 * kDeg, 300.0};
  m.segments.push_back(StaticSegment{10.0});
  AccelerateSegment a;
  a.acceleration_m_per_s2 = 2.0;
  a.target_speed_m_per_s = 10.0;
  m.segments.push_back(a);
  m.segments.push_back(testing::TurnByRate(10.0, 90.0, 1.0));
  m.segments.push_back(ConstantVelocitySegment{30.0});
  AccelerateSegment b;
  b.acceleration_m_per_s2 = 2.0;
  b.target_speed_m_per_s = 0.0;
  m.segments.push_back(b);
  m.segments.push_back(StaticSegment{10.0});
  return m;
}

using testing::TacticalRepresentable;

MonteCarloSpec EkfSpec() {
  MonteCarloSpec spec;
  spec.simulation.motion = ShortDrive();
  spec.simulation.rate_hz = 50.0;
  spec.sensor = TacticalRepresentable();
  spec.runs = 9;
  spec.seed = 21;
  spec.initial_errors.position_ned_m = Vector3d(1.0, 1.0, 2.0);
  spec.initial_errors.velocity_ned_m_per_s = Vector3d(0.05, 0.05, 0.05);
  spec.initial_errors.attitude_rad = Vector3d(1e-3, 1e-3, 3e-3);
  spec.epoch_every_samples = 50;
  spec.filter = NavigationFilterKind::kInsGnssEkf;
  spec.aiding.gnss = GnssConfig();
  spec.aiding.gnss->lever_arm_b_m = Vector3d(0.5, 0.0, -1.0);
  spec.aiding.gnss->outages.push_back({30.0, 15.0});
  spec.aiding.barometer = BarometerConfig();
  spec.aiding.barometer->bias = {1.0, 60.0};
  spec.aiding.zupt = ZuptConfig();
  spec.covariance = true;
  return spec;
}

void ExpectSameSums(const MonteCarloOutput& a, const MonteCarloOutput& b) {
  ASSERT_TRUE(a.consistency && b.consistency);
  ASSERT_EQ(a.consistency->nees_sum.size(), b.consistency->nees_sum.size());
  for (size_t e = 0; e < a.consistency->nees_sum.size(); ++e) {
    EXPECT_TRUE(a.consistency->nees_sum[e] == b.consistency->nees_sum[e]) << e;
    EXPECT_EQ(a.consistency->nees_count[e], b.consistency->nees_count[e]) << e;
  }
  const auto& ea = a.statistics.data().epochs;
  const auto& eb = b.statistics.data().epochs;
  ASSERT_EQ(ea.size(), eb.size());
  for (size_t e = 0; e < ea.size(); ++e) {
    for (int c = 0; c < kNumErrorComponents; ++c) {
      EXPECT_TRUE(ea[e].sum[c] == eb[e].sum[c]) << e << " " << c;
      EXPECT_TRUE(ea[e].sum_squares[c] == eb[e].sum_squares[c]) << e << " " << c;
    }
  }
}

// Invariant 3: every aiding error comes from the run's streams, so the filter's results are the
// same bits for any thread count and any split into shards.
TEST(MonteCarloAided, EkfStatisticsAndNeesAreBitIdenticalForThreadsAndShards) {
  MonteCarloSpec spec = EkfSpec();
  spec.threads = 1;
  const MonteCarloOutput one = RunMonteCarloWithAnalysis(spec);
  spec.threads = 3;
  const MonteCarloOutput three = RunMonteCarloWithAnalysis(spec);
  ExpectSameSums(one, three);

  MonteCarloOutput merged;
  for (uint32_t first : {6u, 0u, 3u}) {
    MonteCarloSpec shard = EkfSpec();
    shard.first_run = first;
    shard.run_count = 3;
    shard.threads = 2;
    MonteCarloOutput part = RunMonteCarloWithAnalysis(shard);
    if (!merged.consistency) {
      merged = std::move(part);
    } else {
      merged.statistics.Merge(part.statistics);
      merged.consistency->Merge(*part.consistency);
    }
  }
  ExpectSameSums(one, merged);

  // The analysis depends on the job only.
  ASSERT_TRUE(one.covariance && three.covariance);
  ASSERT_EQ(one.covariance->epochs.size(), one.statistics.num_epochs());
  for (size_t e = 0; e < one.covariance->epochs.size(); ++e) {
    EXPECT_EQ(one.covariance->epochs[e].P, three.covariance->epochs[e].P);
  }
  // The barometer's Gauss-Markov bias is a filter state: nothing left out.
  EXPECT_TRUE(one.covariance->unrepresented.empty());
  EXPECT_EQ(one.covariance->epochs[0].P.rows(), kNumErrorStates + 1);
}

// Seed 003's complementary filter on a vehicle at rest with a fixed accelerometer bias b and no
// other error: after the transient the tilt is the accelerometer's, roll = atan2(-b_y, g) and
// pitch = atan(b_x / sqrt(b_y^2 + g^2)) (AccelerometerTilt of f = (b_x, b_y, -g)), the same in
// every run; position and velocity errors are reported as 0.
TEST(MonteCarloAided, ComplementaryTiltAtRestIsTheAccelerometerTilt) {
  MonteCarloSpec spec;
  spec.simulation.motion.initial.llh = {45.0 * kDeg, 7.0 * kDeg, 0.0};
  spec.simulation.motion.earth_model = EarthModel::kFlat;
  spec.simulation.motion.segments.push_back(StaticSegment{60.0});
  spec.simulation.rate_hz = 100.0;
  ImuErrorModel model;
  model.accel.fixed_bias = Vector3d(2e-3, -3e-3, 0.0);  // [m/s^2]
  spec.sensor = model;
  spec.runs = 3;
  spec.seed = 1;
  spec.epoch_every_samples = 100;
  spec.filter = NavigationFilterKind::kComplementary;
  spec.complementary.crossover_hz = 0.5;
  const MonteCarloOutput out = RunMonteCarloWithAnalysis(spec);
  const EpochSummary last = out.statistics.SummarizeEpoch(out.statistics.num_epochs() - 1);
  // Flat model: constant gravity, the specific force at rest is (0, 0, -g0) + b.
  const TrajectoryGenerator generator(spec.simulation.motion, spec.simulation.rate_hz);
  const Vector3d f = generator.initial_sample().f_ib_b + model.accel.fixed_bias;
  const double roll = std::atan2(-f.y(), -f.z());
  const double pitch = std::atan(f.x() / std::hypot(f.y(), f.z()));
  // 60 s after start at 0.5 Hz crossover: the filter holds the measured tilt (no gyro error,
  // constant input); round-off of the IIR recursion only.
  EXPECT_NEAR(last.components[static_cast<int>(ErrorComponent::kRoll)].mean, roll, 1e-9);
  EXPECT_NEAR(last.components[static_cast<int>(ErrorComponent::kPitch)].mean, pitch, 1e-9);
  EXPECT_NEAR(last.components[static_cast<int>(ErrorComponent::kRoll)].std, 0.0, 1e-12);
  for (int c = 0; c < 6; ++c) EXPECT_EQ(last.components[c].rms, 0.0) << c;
  EXPECT_FALSE(out.consistency.has_value());
  EXPECT_FALSE(out.covariance.has_value());
}

// A barometer (0.5 m white noise at 10 Hz) bounds the vertical channel: the analysis predicts a
// final down-position sigma far below the free INS's, and 40 runs agree with it within their
// chi-square interval (40 runs: 95 % interval of sigma ratio [0.82, 1.28]).
TEST(MonteCarloAided, BarometerBoundsTheVerticalChannelAsPredicted) {
  MonteCarloSpec spec = EkfSpec();
  spec.aiding.gnss.reset();
  spec.aiding.zupt.reset();
  spec.aiding.barometer->bias = {};
  spec.runs = 40;
  const MonteCarloOutput aided = RunMonteCarloWithAnalysis(spec);
  MonteCarloSpec free_spec = spec;
  free_spec.filter = NavigationFilterKind::kNone;
  free_spec.aiding = {};
  free_spec.runs = 2;
  const MonteCarloOutput free_ins = RunMonteCarloWithAnalysis(free_spec);
  const int down = static_cast<int>(ErrorComponent::kPositionDown);
  const double predicted = aided.covariance->epochs.back().sigma[down];
  const double predicted_free = free_ins.covariance->epochs.back().sigma[down];
  const EpochSummary last = aided.statistics.SummarizeEpoch(aided.statistics.num_epochs() - 1);
  EXPECT_LT(predicted, 0.5 * predicted_free);
  EXPECT_GE(predicted, last.components[down].std_ci95_low);
  EXPECT_LE(predicted, last.components[down].std_ci95_high);
}

TEST(MonteCarloAided, FilterAndAidingThatDoNotFitAreRejected) {
  auto error_of = [](const MonteCarloSpec& spec) {
    try {
      RunMonteCarloWithAnalysis(spec);
    } catch (const SpecError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  MonteCarloSpec spec = EkfSpec();
  spec.filter = NavigationFilterKind::kNone;
  EXPECT_EQ(error_of(spec).rfind("aiding.gnss: ", 0), 0u);
  spec = EkfSpec();
  spec.aiding = {};
  EXPECT_EQ(error_of(spec).rfind("navigation.filter: INS_GNSS_EKF", 0), 0u);
  spec = EkfSpec();
  spec.aiding.gnss->outages[0] = {90.0, 100.0};  // ends after the ~62 s drive
  EXPECT_EQ(error_of(spec).rfind("aiding.gnss.outages[0].end_s", 0), 0u);
  spec = EkfSpec();
  spec.simulation.ned.vertical = VerticalChannel::kTruthHeight;
  EXPECT_EQ(error_of(spec).rfind("navigation.ned.vertical_channel", 0), 0u);
}

}  // namespace
}  // namespace driftlab
