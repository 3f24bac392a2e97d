// The engine's one run loop (engine/src/montecarlo/run_loop.h) seen through its three callers:
// RunMonteCarlo, ReplayMonteCarloRun and RunSimulation run the same samples through the same
// navigators, so a replayed run scores to RunMonteCarlo's numbers for that run and the simulation
// of a run equals its replay bit for bit; cancellation stops a replay at the first poll (every 1024
// samples).
#include <gtest/gtest.h>

#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <vector>

#include "driftlab/gnss.h"
#include "driftlab/mc_statistics.h"
#include "driftlab/monte_carlo.h"
#include "driftlab/presets.h"
#include "driftlab/simulate.h"
#include "support/small_monte_carlo_job.h"

namespace driftlab {
namespace {

// testing::SmallMonteCarloJob with 4 runs, seed 7 and checkpoints at 25 s, 40 s and the end.
MonteCarloSpec FourRunCheckpointJob() {
  MonteCarloSpec spec = testing::SmallMonteCarloJob();
  spec.runs = 4;
  spec.seed = 7;
  spec.checkpoint_times_s = {25.0, 40.0};
  return spec;
}

// Each run replayed with navigation, its solution scored against the truth at the checkpoints
// (ComputeNavError, ErrorComponentsOf: what RunMonteCarlo stores), equals RunMonteCarlo's
// checkpoint values of that run to the bit.
void ExpectReplayScoresAsRunMonteCarlo(const MonteCarloSpec& spec) {
  const MonteCarloStatistics stats = RunMonteCarlo(spec);
  ASSERT_FALSE(stats.cancelled());
  const std::vector<CheckpointValues>& checkpoints = stats.data().checkpoints;
  ASSERT_EQ(checkpoints.size(), 3u);
  for (uint32_t run = 0; run < spec.runs; ++run) {
    const NavEnvironment* env = nullptr;
    int seen = 0;
    const bool done = ReplayMonteCarloRun(
        spec, run, /*navigate=*/true, [&](const MonteCarloRunLayout& l) { env = l.env; },
        [&](const MonteCarloRunStep& step) {
          if (step.checkpoint < 0) return;
          ASSERT_NE(step.nav, nullptr) << step.k;
          const ErrorComponentValues v =
              ErrorComponentsOf(ComputeNavError(*env, *step.nav, *step.truth));
          const CheckpointValues& cp = checkpoints[static_cast<size_t>(step.checkpoint)];
          EXPECT_EQ(step.report_t_s, cp.t_s);
          // The replay's own record of the run's values, as RunMonteCarlo keeps them.
          ASSERT_NE(step.checkpoint_values, nullptr);
          for (int c = 0; c < kNumErrorComponents; ++c) {
            EXPECT_EQ(std::bit_cast<uint64_t>((*step.checkpoint_values)[c]),
                      std::bit_cast<uint64_t>(cp.values[run][c]))
                << "run " << run << " checkpoint " << step.checkpoint << " component " << c;
          }
          for (int c = 0; c < kNumErrorComponents; ++c) {
            EXPECT_EQ(std::bit_cast<uint64_t>(v[c]), std::bit_cast<uint64_t>(cp.values[run][c]))
                << "run " << run << " checkpoint " << step.checkpoint << " component " << c;
          }
          ++seen;
        },
        nullptr);
    EXPECT_TRUE(done);
    EXPECT_EQ(seen, 3);
  }
}

TEST(RunLoopTest, ReplayedFreeNedRunScoresAsRunMonteCarlo) {
  ExpectReplayScoresAsRunMonteCarlo(FourRunCheckpointJob());
}

TEST(RunLoopTest, ReplayedStaticAlignmentRunWithTruthHeightScoresAsRunMonteCarlo) {
  MonteCarloSpec spec = FourRunCheckpointJob();
  spec.initialization = InitializationKind::kStaticAlignment;
  spec.alignment.duration_s = 15.0;
  spec.initial_errors.attitude_rad = Vector3d::Zero();
  spec.simulation.ned.vertical = VerticalChannel::kTruthHeight;
  ExpectReplayScoresAsRunMonteCarlo(spec);
}

TEST(RunLoopTest, ReplayedSeed000RunScoresAsRunMonteCarlo) {
  MonteCarloSpec spec = FourRunCheckpointJob();
  spec.simulation.mechanization = MechanizationKind::kSeed000;
  spec.simulation.seed000.static_period_s = 15.0;
  spec.initial_errors = InitialErrorSigmas();
  ExpectReplayScoresAsRunMonteCarlo(spec);
}

// The INS/GNSS EKF with initial errors and GNSS fixes (with a lever arm, a Gauss-Markov error as a
// filter state and an outage) and a barometer: the replayed run is the Monte Carlo's run.
MonteCarloSpec SmallEkfJob() {
  MonteCarloSpec spec = FourRunCheckpointJob();
  spec.filter = NavigationFilterKind::kInsGnssEkf;
  GnssConfig gnss;
  gnss.rate_hz = 2.0;
  gnss.lever_arm_b_m = Vector3d(0.5, 0.0, -1.0);
  gnss.position_gauss_markov_sigma_ned_m = Vector3d(0.5, 0.5, 1.0);
  gnss.outages.push_back(GnssOutage{35.0, 10.0});
  spec.aiding.gnss = gnss;
  BarometerConfig baro;
  baro.rate_hz = 5.0;
  baro.bias.sigma = 1.0;
  baro.bias.tau_s = 300.0;
  spec.aiding.barometer = baro;
  return spec;
}

TEST(RunLoopTest, ReplayedEkfRunWithInitialErrorsAndGnssScoresAsRunMonteCarlo) {
  ExpectReplayScoresAsRunMonteCarlo(SmallEkfJob());
}

// `driftlab simulate --run N` (SimulateMonteCarloRun): its errors at the checkpoints are run N's
// values of RunMonteCarlo to the bit, for the EKF job with initial errors and GNSS and for a
// free-inertial job with initial errors and static alignment; no solution before the alignment
// window ends.
TEST(RunLoopTest, SimulatedRunNIsRunNOfTheMonteCarlo) {
  MonteCarloSpec aligned = FourRunCheckpointJob();
  aligned.initialization = InitializationKind::kStaticAlignment;
  aligned.alignment.duration_s = 15.0;
  aligned.initial_errors.attitude_rad = Vector3d::Zero();
  for (const MonteCarloSpec& spec : {SmallEkfJob(), aligned}) {
    const MonteCarloStatistics stats = RunMonteCarlo(spec);
    const std::vector<CheckpointValues>& checkpoints = stats.data().checkpoints;
    ASSERT_EQ(checkpoints.size(), 3u);
    const bool ekf = spec.filter == NavigationFilterKind::kInsGnssEkf;
    const int64_t start = ekf ? 0 : 300;  // 15 s at 20 Hz
    for (const uint32_t run : {0u, 3u}) {
      size_t next = 0;
      int64_t rows = 0;
      const SimulationSummary summary = SimulateMonteCarloRun(
          spec, run, [&](const SimulationStep& step, const InsGnssFilter* filter) {
            EXPECT_EQ(step.nav != nullptr, step.k >= start) << step.k;
            EXPECT_EQ(filter != nullptr, ekf && step.k >= start) << step.k;
            if (step.nav != nullptr) ++rows;
            if (next < checkpoints.size() &&
                std::abs(checkpoints[next].t_s - step.truth->t_s) < 1e-9) {
              const ErrorComponentValues v = ErrorComponentsOf(*step.error);
              for (int c = 0; c < kNumErrorComponents; ++c) {
                EXPECT_EQ(std::bit_cast<uint64_t>(v[c]),
                          std::bit_cast<uint64_t>(checkpoints[next].values[run][c]))
                    << "run " << run << " checkpoint " << next << " component " << c;
              }
              ++next;
            }
          });
      EXPECT_EQ(next, checkpoints.size());
      EXPECT_EQ(summary.steps, 1200);
      EXPECT_EQ(rows, 1201 - start);
    }
  }
}

// RunSimulation of (seed, run) and the replay of run `run` of a job with that seed: the same
// measured IMU data at every sample and, for mechanization B (which starts from its own static
// period in both), the same navigation solution, to the bit.
TEST(RunLoopTest, SimulationOfARunEqualsItsReplay) {
  for (const MechanizationKind mechanization :
       {MechanizationKind::kNed, MechanizationKind::kSeed000}) {
    MonteCarloSpec spec = FourRunCheckpointJob();
    spec.initial_errors = InitialErrorSigmas();
    spec.simulation.mechanization = mechanization;
    spec.simulation.seed000.static_period_s = 15.0;
    const uint32_t run = 2;
    const bool seed000 = mechanization == MechanizationKind::kSeed000;
    std::vector<ImuIncrement> increments;
    std::vector<ImuSample> samples;
    std::vector<NavState> navs;
    const SensorRun sensor{*spec.sensor, spec.seed, run};
    const SimulationSummary summary =
        RunSimulation(spec.simulation, &sensor, [&](const SimulationStep& step) {
          increments.push_back(*step.measured_increment);
          samples.push_back(*step.measured_sample);
          navs.push_back(*step.nav);
        });
    ASSERT_EQ(summary.steps, 1200);
    ASSERT_EQ(increments.size(), 1201u);
    int64_t steps = 0;
    ReplayMonteCarloRun(
        spec, run, /*navigate=*/seed000, nullptr,
        [&](const MonteCarloRunStep& step) {
          const size_t k = static_cast<size_t>(step.k);
          ASSERT_EQ(step.k, steps++);
          ASSERT_LT(k, increments.size());
          EXPECT_EQ(step.measured_increment->delta_theta_ib_b, increments[k].delta_theta_ib_b);
          EXPECT_EQ(step.measured_increment->delta_v_ib_b, increments[k].delta_v_ib_b);
          EXPECT_EQ(step.measured_sample->omega_ib_b, samples[k].omega_ib_b);
          EXPECT_EQ(step.measured_sample->f_ib_b, samples[k].f_ib_b);
          if (step.nav == nullptr) return;
          EXPECT_EQ(step.nav->llh.lat_rad, navs[k].llh.lat_rad) << k;
          EXPECT_EQ(step.nav->llh.lon_rad, navs[k].llh.lon_rad) << k;
          EXPECT_EQ(step.nav->llh.h_m, navs[k].llh.h_m) << k;
          EXPECT_EQ(step.nav->v_eb_n, navs[k].v_eb_n) << k;
          EXPECT_EQ(step.nav->q_b_n.coeffs(), navs[k].q_b_n.coeffs()) << k;
        },
        nullptr);
    EXPECT_EQ(steps, 1201);
  }
}

// The cancel flag set at sample 1500 stops the replay after the poll at sample 2048.
TEST(RunLoopTest, ReplayStopsAtTheFirstPollAfterCancel) {
  MonteCarloSpec spec = FourRunCheckpointJob();
  spec.simulation.rate_hz = 100.0;  // 6000 samples
  std::atomic<bool> cancel{false};
  int64_t last_k = -1;
  const bool done = ReplayMonteCarloRun(
      spec, 0, /*navigate=*/true, nullptr,
      [&](const MonteCarloRunStep& step) {
        last_k = step.k;
        if (step.k == 1500) cancel = true;
      },
      &cancel);
  EXPECT_FALSE(done);
  EXPECT_EQ(last_k, 2048);
}

}  // namespace
}  // namespace driftlab
