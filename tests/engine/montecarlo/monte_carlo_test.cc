// Fast tests of the Monte-Carlo runner (monte_carlo.h): bit-identical statistics for any thread
// count and shard split, per-run reproducibility, validation, cancellation, alignment physics.
// Runs under ASan too, so the jobs are small.
#include "driftlab/monte_carlo.h"

#include <gtest/gtest.h>

#include <atomic>
#include <bit>
#include <cmath>
#include <string>
#include <vector>

#include "driftlab/allan.h"
#include "driftlab/presets.h"
#include "driftlab/spec_error.h"
#include "support/small_monte_carlo_job.h"

namespace driftlab {
namespace {

// The shared small job (tests/support/small_monte_carlo_job.h).
MonteCarloSpec SmallJob() { return testing::SmallMonteCarloJob(); }

// Every stored number equal bit for bit (== on the exact sums' integer states and the doubles).
void ExpectIdentical(const MonteCarloStatistics& a, const MonteCarloStatistics& b) {
  const MonteCarloStatisticsData& x = a.data();
  const MonteCarloStatisticsData& y = b.data();
  ASSERT_FALSE(x.cancelled);
  ASSERT_FALSE(y.cancelled);
  EXPECT_EQ(x.runs, y.runs);
  EXPECT_EQ(x.epoch_times_s, y.epoch_times_s);
  ASSERT_EQ(x.epochs.size(), y.epochs.size());
  for (size_t e = 0; e < x.epochs.size(); ++e) {
    for (int c = 0; c < kNumErrorComponents; ++c) {
      ASSERT_EQ(x.epochs[e].sum[c].Serialize(), y.epochs[e].sum[c].Serialize()) << e << " " << c;
      ASSERT_EQ(x.epochs[e].sum_squares[c].Serialize(), y.epochs[e].sum_squares[c].Serialize());
    }
  }
  ASSERT_EQ(x.checkpoints.size(), y.checkpoints.size());
  for (size_t c = 0; c < x.checkpoints.size(); ++c) {
    EXPECT_EQ(x.checkpoints[c].t_s, y.checkpoints[c].t_s);
    EXPECT_EQ(x.checkpoints[c].run_index, y.checkpoints[c].run_index);
    EXPECT_EQ(x.checkpoints[c].values, y.checkpoints[c].values);
  }
  // The summaries are functions of the above, so they match to the bit as well.
  for (size_t e = 0; e < a.num_epochs(); ++e) {
    const EpochSummary sa = a.SummarizeEpoch(e), sb = b.SummarizeEpoch(e);
    for (int c = 0; c < kNumErrorComponents; ++c) {
      EXPECT_EQ(std::bit_cast<uint64_t>(sa.components[c].std),
                std::bit_cast<uint64_t>(sb.components[c].std));
      EXPECT_EQ(std::bit_cast<uint64_t>(sa.components[c].mean),
                std::bit_cast<uint64_t>(sb.components[c].mean));
    }
  }
  const CheckpointSummary ca = a.SummarizeCheckpoint(a.num_checkpoints() - 1);
  const CheckpointSummary cb = b.SummarizeCheckpoint(b.num_checkpoints() - 1);
  EXPECT_EQ(ca.cep50_m, cb.cep50_m);
  EXPECT_EQ(ca.drms2_m, cb.drms2_m);
}

TEST(MonteCarloTest, StatisticsAreBitIdenticalForOneAndTwoThreads) {
  MonteCarloSpec spec = SmallJob();
  spec.threads = 1;
  const MonteCarloStatistics one = RunMonteCarlo(spec);
  spec.threads = 2;
  const MonteCarloStatistics two = RunMonteCarlo(spec);
  ExpectIdentical(one, two);
  EXPECT_EQ(one.run_count(), 16u);
  // 60 s at 20 Hz: epochs every 20 samples from 0 to 1200 -> 61; checkpoints at 30 s and final.
  EXPECT_EQ(one.num_epochs(), 61u);
  ASSERT_EQ(one.num_checkpoints(), 2u);
  EXPECT_EQ(one.data().checkpoints[1].t_s, 60.0);
  EXPECT_EQ(one.data().timings.samples_processed, 16 * 1200);
}

TEST(MonteCarloTest, FourShardsMergedInAnyGroupingEqualOneCall) {
  MonteCarloSpec spec = SmallJob();
  spec.threads = 2;
  const MonteCarloStatistics whole = RunMonteCarlo(spec);
  std::vector<MonteCarloStatistics> shards;
  for (uint32_t i = 0; i < 4; ++i) {
    MonteCarloSpec s = spec;
    s.first_run = 4 * i;
    s.run_count = 4;
    s.threads = 1 + static_cast<int>(i % 2);
    shards.push_back(RunMonteCarlo(s));
  }
  MonteCarloStatistics left = shards[0];
  left.Merge(shards[1]);
  MonteCarloStatistics right = shards[2];
  right.Merge(shards[3]);
  left.Merge(right);  // (0 + 1) + (2 + 3)
  ExpectIdentical(whole, left);
  MonteCarloStatistics reversed = shards[3];
  for (int i : {1, 0, 2}) reversed.Merge(shards[i]);  // 3 + 1 + 0 + 2
  ExpectIdentical(whole, reversed);
}

TEST(MonteCarloTest, RunAloneEqualsSameRunInsideLargerJob) {
  MonteCarloSpec spec = SmallJob();
  spec.runs = 10;
  const MonteCarloStatistics job = RunMonteCarlo(spec);
  spec.first_run = 7;
  spec.run_count = 1;
  const MonteCarloStatistics alone = RunMonteCarlo(spec);
  ASSERT_EQ(alone.run_count(), 1u);
  for (size_t c = 0; c < job.num_checkpoints(); ++c) {
    ASSERT_EQ(alone.data().checkpoints[c].run_index[0], 7u);
    EXPECT_EQ(alone.data().checkpoints[c].values[0], job.data().checkpoints[c].values[7]);
    // Different runs differ (the per-run errors are independent).
    EXPECT_NE(job.data().checkpoints[c].values[6], job.data().checkpoints[c].values[7]);
  }
}

void ExpectSpecError(const MonteCarloSpec& spec, const std::string& field) {
  try {
    RunMonteCarlo(spec);
    FAIL() << "accepted; expected an error on " << field;
  } catch (const SpecError& e) {
    EXPECT_EQ(e.field(), field) << e.what();
  }
}

TEST(MonteCarloTest, BadSpecsNameTheField) {
  MonteCarloSpec spec = SmallJob();
  spec.runs = 0;
  ExpectSpecError(spec, "monte_carlo.runs");

  spec = SmallJob();
  spec.epoch_every_samples = 0;
  spec.epoch_times_s = {10.0, 61.0};  // the trajectory ends at 60 s
  ExpectSpecError(spec, "monte_carlo.epoch_times_s[1]");
  spec.epoch_times_s = {-1.0};
  ExpectSpecError(spec, "monte_carlo.epoch_times_s[0]");
  spec.epoch_times_s = {10.0, 10.01};  // the same 20 Hz sample after snapping
  ExpectSpecError(spec, "monte_carlo.epoch_times_s[1]");

  spec = SmallJob();
  spec.first_run = 10;
  spec.run_count = 7;  // 17 > 16
  ExpectSpecError(spec, "monte_carlo.run_count");
  spec.first_run = 16;
  spec.run_count = 0;
  ExpectSpecError(spec, "monte_carlo.first_run");

  spec = SmallJob();
  spec.initial_errors.attitude_rad = Vector3d::Zero();
  spec.initialization = InitializationKind::kStaticAlignment;
  spec.alignment.duration_s = 25.0;  // the vehicle starts moving at 20 s
  ExpectSpecError(spec, "monte_carlo.initialization.alignment_duration_s");

  spec = SmallJob();
  spec.initial_errors.position_ned_m.y() = -1.0;
  ExpectSpecError(spec, "monte_carlo.initial_errors.position_ned_m[1]");

  spec = SmallJob();
  spec.checkpoint_times_s = {70.0};
  ExpectSpecError(spec, "monte_carlo.checkpoint_times_s[0]");
}

TEST(MonteCarloTest, CancellationFromProgressCallbackStopsPromptly) {
  MonteCarloSpec spec = SmallJob();
  spec.runs = 200;
  spec.threads = 2;
  std::atomic<bool> cancel{false};
  int calls = 0;
  const MonteCarloStatistics stats = RunMonteCarlo(
      spec,
      [&](const MonteCarloProgress& p) {
        ++calls;
        EXPECT_EQ(p.runs_total, 200u);
        cancel = true;
      },
      &cancel);
  EXPECT_TRUE(stats.cancelled());
  EXPECT_EQ(stats.run_count(), 0u);
  EXPECT_EQ(stats.num_epochs(), 0u);
  EXPECT_GE(calls, 1);
  // The first progress call comes at a run's first poll (1024 samples); each worker then stops
  // within one more poll interval, so at most ~2 x 2 x 1200 of the 240000 samples are processed.
  EXPECT_LT(stats.data().timings.samples_processed, 240000 / 20);
}

TEST(MonteCarloTest, TruthRejectedMidStreamThrowsTheSameErrorOnOneAndTwoThreads) {
  // With 2 threads the lockstep runs start while the truth streams (monte_carlo.cc); a trajectory
  // rejected part-way (climbing through the 100 km height limit after ~200 s) must stop the runs
  // already going and give the error a 1-thread job gives, not hang or crash.
  MonteCarloSpec spec = SmallJob();
  spec.simulation.motion.segments.clear();
  spec.simulation.motion.segments.push_back(StaticSegment{5.0});
  ClimbSegment climb;
  climb.climb_rate_m_per_s = 500.0;
  climb.vertical_acceleration_m_per_s2 = 50.0;
  climb.height_change_m = 2e5;
  spec.simulation.motion.segments.push_back(climb);
  spec.checkpoint_times_s.clear();
  std::string messages[2];
  for (int threads : {1, 2}) {
    spec.threads = threads;
    try {
      RunMonteCarlo(spec);
      FAIL() << "accepted with " << threads << " threads";
    } catch (const SpecError& e) {
      EXPECT_EQ(e.field(), "motion") << e.what();
      messages[threads - 1] = e.what();
    }
  }
  EXPECT_EQ(messages[0], messages[1]);
  EXPECT_NE(messages[1].find("reaches height"), std::string::npos) << messages[1];
}

TEST(MonteCarloTest, CancelWhileTheTruthStreamsStopsTheOverlappedRuns) {
  // 2 threads: the runs start with the truth; a cancel set at the first progress call (a run's
  // first poll) stops the truth at its next check (4096 samples) and the runs at theirs.
  MonteCarloSpec spec = SmallJob();
  spec.simulation.motion.segments.push_back(ConstantVelocitySegment{3000.0});
  spec.runs = 64;
  spec.threads = 2;
  std::atomic<bool> cancel{false};
  const MonteCarloStatistics stats = RunMonteCarlo(
      spec, [&](const MonteCarloProgress&) { cancel = true; }, &cancel);
  EXPECT_TRUE(stats.cancelled());
  EXPECT_EQ(stats.num_epochs(), 0u);
}

TEST(MonteCarloTest, ProgressEndsWithAllRunsDone) {
  MonteCarloSpec spec = SmallJob();
  MonteCarloProgress last;
  RunMonteCarlo(spec, [&](const MonteCarloProgress& p) { last = p; });
  EXPECT_EQ(last.runs_done, 16u);
  EXPECT_EQ(last.samples_done, 16 * 1200);
  EXPECT_EQ(last.samples_total, 16 * 1200);
}

// One error-free run aligned statically: the alignment errors are those of the biases alone.
TEST(MonteCarloTest, StaticAlignmentTiltAndHeadingFollowSensorBiases) {
  MonteCarloSpec spec;
  const double L = 45.0 * kDeg;
  spec.simulation.motion.initial.llh = {L, 0.0, 0.0};
  spec.simulation.motion.segments.push_back(StaticSegment{30.0});
  spec.simulation.rate_hz = 10.0;
  spec.runs = 1;
  spec.initialization = InitializationKind::kStaticAlignment;
  spec.alignment.duration_s = 20.0;
  spec.epoch_every_samples = 10;
  const double b_gyro_y = 0.01 * kDeg / 3600.0;  // east gyro bias (body = NED at zero attitude)
  const double b_accel_y = 1e-3;                 // east accelerometer bias [m/s^2]
  ImuErrorModel model;
  model.gyro.fixed_bias = Vector3d(0.0, b_gyro_y, 0.0);
  model.accel.fixed_bias = Vector3d(0.0, b_accel_y, 0.0);
  spec.sensor = model;
  const MonteCarloStatistics stats = RunMonteCarlo(spec);
  ASSERT_EQ(stats.data().epoch_times_s.front(), 20.0);  // navigation starts after the window
  // With one run, the first epoch's sums are that run's errors at the navigation start.
  auto start_error = [&](ErrorComponent c) {
    return static_cast<double>(stats.data().epochs[0].sum[static_cast<int>(c)].Value());
  };
  // Levelling: f = (0, b_a, -g) -> roll = atan2(-b_a, g) ~ -b_a / g. Gyrocompassing: the levelled
  // east rate is b_g + Omega sin L * roll error, so yaw error ~ -b_g / (Omega cos L) - roll error
  // tan L (Groves section 5.6.3). The neglected terms are second order in the errors
  // (~1e-3 x 1e-4 rad) and cubic terms of atan (~3e-10 rad): 1e-6 rad.
  const double g = GravityNed(L, 0.0).z();
  const double roll_expected = -b_accel_y / g;
  const double yaw_expected =
      -b_gyro_y / (kWgs84EarthRate_rad_per_s * std::cos(L)) - roll_expected * std::tan(L);
  EXPECT_NEAR(start_error(ErrorComponent::kRoll), roll_expected, 1e-6);
  EXPECT_NEAR(start_error(ErrorComponent::kPitch), 0.0, 1e-9);  // ideal data: rounding only
  EXPECT_NEAR(start_error(ErrorComponent::kYaw), yaw_expected, 1e-6);
}

TEST(MonteCarloTest, ExternalHeadingUsedWhenGyroCannotGyrocompass) {
  MonteCarloSpec spec;
  spec.simulation.motion.initial.llh = {30.0 * kDeg, 0.0, 0.0};
  spec.simulation.motion.segments.push_back(StaticSegment{11.0});
  spec.simulation.rate_hz = 10.0;
  ImuErrorModel model;
  model.gyro = FindImuPreset("rate-grade").gyro;  // ~30 deg/h bias: gyrocompass error > 1 rad
  spec.sensor = model;                            // perfect accelerometers: exact levelling
  spec.runs = 400;
  spec.initialization = InitializationKind::kStaticAlignment;
  spec.alignment.duration_s = 10.0;
  spec.alignment.heading_sigma_rad = 0.02;
  spec.epoch_every_samples = 1000;
  ASSERT_GT(PredictedGyrocompassHeadingSigma(model.gyro, 30.0 * kDeg, 10.0), 1.0);
  const EpochSummary start = RunMonteCarlo(spec).SummarizeEpoch(0);
  // Yaw error at the start ~ N(0, 0.02^2): 400 runs, sample sigma within the 95 % chi-square(399)
  // interval of 0.02.
  const double s = start.components[static_cast<int>(ErrorComponent::kYaw)].std;
  EXPECT_GT(s, 0.02 * std::sqrt(ChiSquareQuantile(0.025, 399.0) / 399.0));
  EXPECT_LT(s, 0.02 * std::sqrt(ChiSquareQuantile(0.975, 399.0) / 399.0));
  // Exact levelling from ideal specific force: tilt errors are rounding only.
  EXPECT_LT(start.components[static_cast<int>(ErrorComponent::kRoll)].rms, 1e-9);
}

TEST(MonteCarloTest, InitialErrorsHaveRequestedSigmas) {
  MonteCarloSpec spec = SmallJob();
  spec.sensor.reset();
  spec.runs = 400;
  spec.epoch_every_samples = 1200;
  const MonteCarloStatistics stats = RunMonteCarlo(spec);
  const EpochSummary e0 = stats.SummarizeEpoch(0);  // t = 0: the initial errors themselves
  const double sigmas[9] = {1.0, 2.0, 3.0, 0.01, 0.02, 0.03, 1e-3, 2e-3, 3e-3};
  // 400 runs: sample sigma / true sigma in [sqrt(chi2_{a/2}(399)/399), sqrt(chi2_{1-a/2}/399)];
  // with 9 comparisons, Bonferroni a = 0.05 / 9.
  const double a = 0.05 / 9.0;
  const double lo = std::sqrt(ChiSquareQuantile(a / 2, 399.0) / 399.0);
  const double hi = std::sqrt(ChiSquareQuantile(1 - a / 2, 399.0) / 399.0);
  for (int c = 0; c < 9; ++c) {
    EXPECT_GT(e0.components[c].std, lo * sigmas[c]) << ErrorComponentName(ErrorComponent(c));
    EXPECT_LT(e0.components[c].std, hi * sigmas[c]) << ErrorComponentName(ErrorComponent(c));
  }
}

// One error-free run with an initial pitch error at the equator, compared sample by sample with
// the linear solution dr_N = R_N th0 w^2 / (w^2 - Omega^2) (cos(Omega t) - cos(w t)) (the east-axis
// tilt rotates with the Earth, see monte_carlo_slow_test.cc). Two Schuler periods at 1 Hz.
TEST(MonteCarloTest, PitchErrorAtEquatorFollowsSchulerAndEarthRateSolution) {
  MonteCarloSpec spec;
  spec.simulation.motion.initial.llh = {0.0, 0.0, 0.0};
  spec.simulation.motion.segments.push_back(StaticSegment{10200.0});
  spec.simulation.rate_hz = 1.0;
  spec.simulation.ned.vertical = VerticalChannel::kTruthHeight;
  spec.runs = 1;
  spec.initial_errors.attitude_rad = Vector3d(0.0, 1e-3, 0.0);
  spec.epoch_every_samples = 300;
  const MonteCarloStatistics stats = RunMonteCarlo(spec);
  auto value = [&](size_t e, ErrorComponent c) {
    return static_cast<double>(stats.data().epochs[e].sum[static_cast<int>(c)].Value());
  };
  const double th0 = value(0, ErrorComponent::kPitch);  // the run's drawn pitch error
  ASSERT_GT(std::abs(th0), 1e-5);
  const double R_N = MeridianRadius(0.0);
  const double w2 = GravityNed(0.0, 0.0).z() / R_N;
  const double Omega = kWgs84EarthRate_rad_per_s;
  for (size_t e = 0; e < stats.num_epochs(); ++e) {
    const double t = stats.data().epoch_times_s[e];
    const double theory =
        R_N * th0 * w2 / (w2 - Omega * Omega) * (std::cos(Omega * t) - std::cos(std::sqrt(w2) * t));
    // Linear theory: the neglected terms are of relative order th0 (~1e-3) of the peak error
    // 2 R_N |th0|; the sign convention of the Euler difference makes dr_N = -theory.
    EXPECT_NEAR(value(e, ErrorComponent::kPositionNorth), -theory, 2e-3 * 2.0 * R_N * std::abs(th0))
        << "t = " << t;
  }
}

// Mechanization B estimates a constant gyro bias over its static period and removes it: on the
// flat Earth (seed 000's frame, no Earth rate) a vehicle at rest then keeps its attitude to
// rounding, while the same bias uncorrected would give b t = 1e-4 rad/s x 50 s = 5 mrad.
TEST(MonteCarloTest, Seed000MechanizationStartsAfterItsStaticPeriodAndRemovesGyroBias) {
  MonteCarloSpec spec;
  spec.simulation.motion.earth_model = EarthModel::kFlat;
  spec.simulation.motion.initial.llh = {40.0 * kDeg, -3.0 * kDeg, 600.0};
  spec.simulation.motion.segments.push_back(StaticSegment{60.0});
  spec.simulation.rate_hz = 50.0;
  spec.simulation.mechanization = MechanizationKind::kSeed000;
  spec.simulation.seed000.static_period_s = 10.0;
  ImuErrorModel model;
  model.gyro.fixed_bias = Vector3d(1e-4, -2e-4, 1e-4);
  spec.sensor = model;
  spec.runs = 3;
  spec.epoch_every_samples = 50;
  spec.threads = 2;
  const MonteCarloStatistics stats = RunMonteCarlo(spec);
  EXPECT_EQ(stats.data().epoch_times_s.front(), 10.0);
  EXPECT_EQ(stats.data().epoch_times_s.back(), 60.0);
  const EpochSummary last = stats.SummarizeEpoch(stats.num_epochs() - 1);
  for (ErrorComponent c : {ErrorComponent::kRoll, ErrorComponent::kPitch, ErrorComponent::kYaw}) {
    // Bias estimate exact to rounding (~1e-16 rad/s x 50 s): 1e-9 rad.
    EXPECT_LT(last.components[static_cast<int>(c)].rms, 1e-9) << ErrorComponentName(c);
  }
  spec.initial_errors.position_ned_m.x() = 1.0;
  ExpectSpecError(spec, "monte_carlo.initial_errors");
}

// Mechanization B with gyro white noise N (point samples, N / sqrt(dt) per sample): after its
// static period T, the attitude error is the angle random walk N sqrt(t') plus the bias-estimate
// error (mean of the T / dt static samples, sigma N / sqrt(T)) times t', independent of each other:
//   sigma^2 = N^2 (t' + t'^2 / T),   t' = time since navigation start.
TEST(MonteCarloTest, Seed000AttitudeErrorCombinesRandomWalkAndBiasEstimate) {
  MonteCarloSpec spec;
  spec.simulation.motion.earth_model = EarthModel::kFlat;
  spec.simulation.motion.initial.llh = {40.0 * kDeg, -3.0 * kDeg, 600.0};
  spec.simulation.motion.segments.push_back(StaticSegment{60.0});
  spec.simulation.rate_hz = 10.0;
  spec.simulation.mechanization = MechanizationKind::kSeed000;
  spec.simulation.seed000.static_period_s = 10.0;
  ImuErrorModel model;
  const double N = 1e-3;  // [rad/sqrt(s)]
  model.gyro.white_noise_density = N;
  spec.sensor = model;
  spec.runs = 300;
  spec.epoch_every_samples = 500;
  const MonteCarloStatistics stats = RunMonteCarlo(spec);
  const EpochSummary last = stats.SummarizeEpoch(stats.num_epochs() - 1);
  const double t = last.t_s - 10.0;
  const double sigma = N * std::sqrt(t + t * t / 10.0);
  // 300 runs, 3 comparisons: chi-square(299) interval at Bonferroni level 0.05 / 3.
  const double a = 0.05 / 3.0;
  for (ErrorComponent c : {ErrorComponent::kRoll, ErrorComponent::kPitch, ErrorComponent::kYaw}) {
    const double s = last.components[static_cast<int>(c)].std;
    EXPECT_GT(s, sigma * std::sqrt(ChiSquareQuantile(a / 2, 299.0) / 299.0))
        << ErrorComponentName(c);
    EXPECT_LT(s, sigma * std::sqrt(ChiSquareQuantile(1 - a / 2, 299.0) / 299.0))
        << ErrorComponentName(c);
  }
}

}  // namespace
}  // namespace driftlab
