// The lockstep free-inertial NED path (engine/src/lockstep/lockstep_ned.h): every instruction-set
// path (DRIFTLAB_ISA=baseline, avx2, avx512, those the CPU has) and the one-run-at-a-time reference
// (DRIFTLAB_ISA=scalar) give the same bits for every stored number, over sensor models that switch
// on every error term, both Earth models, both vertical channels, static alignment, and run counts
// that leave a partial lockstep group. Tolerance: none (bit equality), because every path performs
// the same IEEE operations in the same order on the same deviates.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "driftlab/monte_carlo.h"
#include "driftlab/presets.h"
#include "driftlab/spec_error.h"
#include "driftlab/trajectory.h"

namespace driftlab {
namespace {

// Sets DRIFTLAB_ISA for the scope.
class ScopedIsa {
 public:
  explicit ScopedIsa(const std::string& isa) { setenv("DRIFTLAB_ISA", isa.c_str(), 1); }
  ~ScopedIsa() { unsetenv("DRIFTLAB_ISA"); }
};

// The paths this CPU can run (baseline always; avx2 and avx512 where present).
std::vector<std::string> AvailablePaths() {
  std::vector<std::string> paths = {"baseline"};
#if defined(__x86_64__)
  if (__builtin_cpu_supports("avx2")) paths.push_back("avx2");
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
      __builtin_cpu_supports("avx512vl")) {
    paths.push_back("avx512");
  }
#endif
  return paths;
}

// 10 s static, a 90-degree turn, an acceleration, at 50 Hz: 13 runs (a partial group of every
// width).
MonteCarloSpec TurnJob() {
  MonteCarloSpec spec;
  spec.simulation.motion.initial.llh = {40.0 * kDeg, -3.0 * kDeg, 650.0};
  spec.simulation.motion.segments.push_back(StaticSegment{10.0});
  AccelerateSegment acc;
  acc.acceleration_m_per_s2 = 2.0;
  acc.duration_s = 5.0;
  spec.simulation.motion.segments.push_back(acc);
  TurnSegment turn;
  turn.rate_rad_per_s = 0.2;
  turn.angle_rad = M_PI / 2.0;
  spec.simulation.motion.segments.push_back(turn);
  spec.simulation.motion.segments.push_back(ConstantVelocitySegment{12.0});
  spec.simulation.rate_hz = 50.0;
  spec.runs = 13;
  spec.seed = 2026;
  spec.initial_errors.position_ned_m = Vector3d(1.0, 2.0, 3.0);
  spec.initial_errors.velocity_ned_m_per_s = Vector3d(0.01, 0.02, 0.03);
  spec.initial_errors.attitude_rad = Vector3d(1e-3, 2e-3, 3e-3);
  spec.epoch_every_samples = 37;
  spec.checkpoint_times_s = {12.0, 20.5};
  return spec;
}

// Every error term on, with g-sensitivity, asymmetry, saturation and quantization.
ImuErrorModel EveryTerm() {
  ImuErrorModel m = FindImuPreset("tactical");
  for (TriadErrorParams* t : {&m.gyro, &m.accel}) {
    t->white_noise_density = t == &m.gyro ? 1e-4 : 1e-3;
    t->random_walk = t == &m.gyro ? 1e-6 : 1e-5;
    t->bias_gauss_markov.sigma = t == &m.gyro ? 1e-5 : 1e-3;
    t->bias_gauss_markov.tau_s = 50.0;
    t->bias_flicker.bias_instability = t == &m.gyro ? 2e-6 : 2e-4;
    t->bias_flicker.tau_min_s = 0.1;
    t->bias_flicker.tau_max_s = 300.0;
    t->scale_factor_sigma = 1e-4;
    t->scale_factor_asymmetry = Vector3d(1e-4, -2e-4, 3e-4);
    t->misalignment_sigma_rad = 1e-4;
    t->turn_on_bias_sigma = t == &m.gyro ? 1e-5 : 1e-3;
    t->fixed_bias = Vector3d(1e-6, -2e-6, 3e-6);
    t->quantization = t == &m.gyro ? 1e-7 : 1e-5;
    t->range = t == &m.gyro ? 0.15 : 200.0;  // the turn's 0.2 rad/s saturates the yaw gyro
  }
  m.gyro_g_sensitivity(0, 2) = 1e-6;
  m.gyro_g_sensitivity(2, 0) = -2e-6;
  return m;
}

void ExpectIdenticalData(const MonteCarloStatisticsData& x, const MonteCarloStatisticsData& y,
                         const std::string& what) {
  ASSERT_FALSE(x.cancelled) << what;
  ASSERT_FALSE(y.cancelled) << what;
  EXPECT_EQ(x.runs, y.runs) << what;
  EXPECT_EQ(x.epoch_times_s, y.epoch_times_s) << what;
  ASSERT_EQ(x.epochs.size(), y.epochs.size()) << what;
  for (size_t e = 0; e < x.epochs.size(); ++e) {
    for (int c = 0; c < kNumErrorComponents; ++c) {
      ASSERT_EQ(x.epochs[e].sum[c].Serialize(), y.epochs[e].sum[c].Serialize())
          << what << " epoch " << e << " component " << c;
      ASSERT_EQ(x.epochs[e].sum_squares[c].Serialize(), y.epochs[e].sum_squares[c].Serialize())
          << what << " epoch " << e << " component " << c;
    }
  }
  ASSERT_EQ(x.checkpoints.size(), y.checkpoints.size()) << what;
  for (size_t c = 0; c < x.checkpoints.size(); ++c) {
    EXPECT_EQ(x.checkpoints[c].run_index, y.checkpoints[c].run_index) << what;
    EXPECT_EQ(x.checkpoints[c].values, y.checkpoints[c].values) << what << " checkpoint " << c;
  }
  EXPECT_EQ(x.timings.samples_processed, y.timings.samples_processed) << what;
}

// Runs `spec` on the scalar reference and on every available path; all must agree bit for bit.
void ExpectAllPathsIdentical(const MonteCarloSpec& spec, const std::string& what) {
  MonteCarloStatisticsData reference;
  {
    ScopedIsa isa("scalar");
    reference = RunMonteCarlo(spec).data();
  }
  for (const std::string& path : AvailablePaths()) {
    ScopedIsa isa(path);
    ExpectIdenticalData(reference, RunMonteCarlo(spec).data(), what + " on " + path);
  }
}

TEST(LockstepNedTest, EveryPathMatchesScalarReferenceTacticalPreset) {
  MonteCarloSpec spec = TurnJob();
  spec.sensor = FindImuPreset("tactical");
  ExpectAllPathsIdentical(spec, "tactical");
}

TEST(LockstepNedTest, EveryPathMatchesScalarReferenceWithEveryErrorTerm) {
  MonteCarloSpec spec = TurnJob();
  spec.sensor = EveryTerm();
  ExpectAllPathsIdentical(spec, "every term");
  // Quantization rounds small differences away: once more without it.
  spec.sensor->gyro.quantization = 0.0;
  spec.sensor->accel.quantization = 0.0;
  ExpectAllPathsIdentical(spec, "every term but quantization");
  spec.simulation.ned.coning_sculling = false;
  ExpectAllPathsIdentical(spec, "every term, no coning/sculling");
}

TEST(LockstepNedTest, EveryPathMatchesScalarReferenceWithoutSensorErrors) {
  MonteCarloSpec spec = TurnJob();
  spec.sensor.reset();
  ExpectAllPathsIdentical(spec, "ideal sensor");
}

TEST(LockstepNedTest, EveryPathMatchesScalarReferenceWithTruthHeightAndFlatEarth) {
  MonteCarloSpec spec = TurnJob();
  spec.sensor = EveryTerm();
  spec.simulation.ned.vertical = VerticalChannel::kTruthHeight;
  ExpectAllPathsIdentical(spec, "truth height");
  spec.simulation.ned.vertical = VerticalChannel::kFree;
  spec.simulation.motion.earth_model = EarthModel::kFlat;
  ExpectAllPathsIdentical(spec, "flat Earth");
}

TEST(LockstepNedTest, EveryPathMatchesScalarReferenceAfterStaticAlignment) {
  MonteCarloSpec spec = TurnJob();
  spec.sensor = FindImuPreset("navigation");
  spec.initialization = InitializationKind::kStaticAlignment;
  spec.initial_errors.attitude_rad = Vector3d::Zero();
  spec.alignment.duration_s = 9.3;  // s0 = 465, not on a deviate block or poll boundary
  ExpectAllPathsIdentical(spec, "gyrocompass");
  spec.sensor = FindImuPreset("industrial");
  spec.alignment.heading_sigma_rad = 0.01;
  ExpectAllPathsIdentical(spec, "external heading");
}

// The statistics' per-lane branches (nav_error_lanes.h): a car heading east at 30 m/s reaches the
// antimeridian after 1 s, then turns to head south (yaw +-180 degrees); with initial errors of
// 30 m east and 5 mrad in yaw, some runs' estimated longitude lies across +-pi from the truth's
// at t = 1 s (the longitude difference goes through remainder in those lanes only) and some runs'
// yaw error wraps at the end while others' does not. The test checks from the checkpoint values
// that both happen for some runs and not for all.
TEST(LockstepNedTest, EveryPathMatchesScalarReferenceAcrossTheAntimeridianAndTheYawWrap) {
  MonteCarloSpec spec;
  const double lat = -20.0 * kDeg, h = 10.0;
  const double east_radius_m = (TransverseRadius(lat) + h) * std::cos(lat);
  spec.simulation.motion.initial.llh = {lat, M_PI - 30.0 / east_radius_m, h};
  spec.simulation.motion.initial.v_eb_n = Vector3d(0.0, 30.0, 0.0);
  spec.simulation.motion.initial.attitude.yaw_rad = M_PI / 2.0;
  spec.simulation.motion.segments.push_back(ConstantVelocitySegment{2.0});
  TurnSegment turn;
  turn.rate_rad_per_s = 0.5;
  turn.angle_rad = M_PI / 2.0;
  spec.simulation.motion.segments.push_back(turn);
  spec.simulation.motion.segments.push_back(ConstantVelocitySegment{2.0});
  spec.simulation.rate_hz = 50.0;
  spec.runs = 13;
  spec.seed = 7;
  spec.sensor = FindImuPreset("tactical");
  spec.initial_errors.position_ned_m = Vector3d(1.0, 30.0, 1.0);
  spec.initial_errors.attitude_rad = Vector3d(1e-3, 1e-3, 5e-3);
  spec.epoch_every_samples = 3;
  spec.checkpoint_times_s = {1.0};
  ExpectAllPathsIdentical(spec, "antimeridian and yaw wrap");

  const MonteCarloStatisticsData d = RunMonteCarlo(spec).data();
  const Trajectory truth = GenerateTrajectory(spec.simulation.motion, spec.simulation.rate_hz);
  ASSERT_EQ(d.checkpoints.size(), 2u);
  // t = 1 s: the truth within a few cm of the antimeridian (30 m/s x 0.02 s steps); a run's
  // estimate is across when its longitude difference takes it past +-pi.
  const NavState& at_1s = truth.truth[50];
  ASSERT_NEAR(std::abs(at_1s.llh.lon_rad), M_PI, 1.0 / east_radius_m);
  int across = 0;
  for (const ErrorComponentValues& v : d.checkpoints[0].values) {
    const double lon = at_1s.llh.lon_rad + v[1] / east_radius_m;
    across += (lon > M_PI || lon <= -M_PI) ? 1 : 0;
  }
  EXPECT_GT(across, 0) << "runs across the antimeridian from the truth at t = 1 s";
  EXPECT_LT(across, spec.runs) << "runs across the antimeridian from the truth at t = 1 s";
  // The end: the truth heads south; a run's yaw error wraps when its estimated yaw is across +-pi.
  const double truth_yaw = truth.truth.back().euler().yaw_rad;
  ASSERT_NEAR(std::abs(truth_yaw), M_PI, 1e-6);
  int wrapped = 0;
  for (const ErrorComponentValues& v : d.checkpoints[1].values) {
    const double yaw = truth_yaw + v[8];
    wrapped += (yaw > M_PI || yaw <= -M_PI) ? 1 : 0;
  }
  EXPECT_GT(wrapped, 0) << "runs whose yaw error wraps at the end";
  EXPECT_LT(wrapped, spec.runs) << "runs whose yaw error wraps at the end";
}

TEST(LockstepNedTest, ThreadsAndShardsGiveTheSameBitsOnEveryPath) {
  MonteCarloSpec spec = TurnJob();
  spec.sensor = EveryTerm();
  spec.runs = 19;
  for (const std::string& path : AvailablePaths()) {
    ScopedIsa isa(path);
    spec.threads = 1;
    const MonteCarloStatistics one = RunMonteCarlo(spec);
    spec.threads = 2;
    ExpectIdenticalData(one.data(), RunMonteCarlo(spec).data(), path + " 1 vs 2 threads");
    // Shards of 5, 5, 5, 4 runs: groups start at other runs than in the whole job.
    MonteCarloStatistics merged;
    for (uint32_t i = 0; i < 4; ++i) {
      MonteCarloSpec s = spec;
      s.first_run = 5 * i;
      s.run_count = i == 3 ? 4 : 5;
      s.threads = 1;
      if (i == 0) {
        merged = RunMonteCarlo(s);
      } else {
        merged.Merge(RunMonteCarlo(s));
      }
    }
    ExpectIdenticalData(one.data(), merged.data(), path + " 4 shards merged");
  }
}

TEST(LockstepNedTest, UnknownOrUnavailablePathNamesTheVariable) {
  MonteCarloSpec spec = TurnJob();
  ScopedIsa isa("sse9");
  try {
    RunMonteCarlo(spec);
    FAIL() << "no error";
  } catch (const SpecError& e) {
    EXPECT_NE(std::string(e.what()).find("DRIFTLAB_ISA"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("sse9"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace driftlab
