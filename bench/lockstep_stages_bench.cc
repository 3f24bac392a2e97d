// Stages of the lockstep free-inertial NED runs, on one core, for one group of lanes
// of the widest path the CPU has (DRIFTLAB_ISA forces another), IMU samples x lanes per second:
//   * deviates: LoadBlock alone (Philox + Box-Muller of every per-sample and flicker stream);
//   * sensor errors: LoadBlock + the sensor-error step (kernel advance in the alignment mode,
//     which sums the measured increments instead of navigating);
//   * mechanization: the NED step with coning/sculling on ideal increments (no sensor model);
//   * statistics: at each epoch (every 100 samples, as bench/lockstep_bench.cc's job) the error
//     components of the group's lanes against the truth (Kernel::errors, nav_error_lanes.h) and
//     their exact sums and sums of squares (ExactSum), counted per sample covered; /1: the errors
//     one run at a time instead (ComputeNavError + ErrorComponentsOf, as the scalar RunNed);
// for three models: white noise only; white + Gauss-Markov + random walk on 6 axes; the tactical
// preset. The trajectory stage is bench/engine_bench.cc's BM_Generator; end to end (shared truth,
// runs, per-epoch statistics) is bench/lockstep_bench.cc.
// The drive: 600 s at 100 Hz (60 s static, accelerate to 20 m/s, 90-degree turn, cruise).
//   nice -n 19 build/bench/driftlab_bench_lockstep_stages --benchmark_repetitions=3
//     --benchmark_report_aggregates_only=true   (one command line)
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <vector>

#include "car_like_motion.h"
#include "driftlab/mc_statistics.h"
#include "driftlab/presets.h"
#include "driftlab/trajectory.h"
#include "lockstep/lockstep_ned.h"

namespace driftlab {
namespace {

constexpr double kRate_hz = 100.0;

const Trajectory& Drive() {
  static const Trajectory t = GenerateTrajectory(bench::CarLike600s(), kRate_hz);
  return t;
}

// Increments indexed as the shared truth's: [k] covers (t_(k-1), t_k], [0] unused.
const std::vector<ImuIncrement>& Increments() {
  static const std::vector<ImuIncrement> inc = [] {
    const Trajectory& t = Drive();
    std::vector<ImuIncrement> v(t.increments.size() + 1);
    for (size_t k = 0; k < t.increments.size(); ++k) v[k + 1] = t.increments[k];
    return v;
  }();
  return inc;
}

ImuErrorModel Model(int which) {
  ImuErrorModel m;
  if (which == 2) return FindImuPreset("tactical");
  m.gyro.white_noise_density = 1e-4;
  m.accel.white_noise_density = 1e-3;
  if (which == 1) {
    m.gyro.bias_gauss_markov.sigma = 1e-5;
    m.gyro.bias_gauss_markov.tau_s = 100.0;
    m.gyro.random_walk = 1e-6;
    m.accel.bias_gauss_markov.sigma = 1e-3;
    m.accel.bias_gauss_markov.tau_s = 100.0;
    m.accel.random_walk = 1e-5;
  }
  return m;
}
const char* kModels[] = {"white", "white+GM+RW", "tactical"};

enum class Stage { kDeviates, kSensorErrors, kMechanization };

void RunStage(benchmark::State& state, Stage stage) {
  const int which = static_cast<int>(state.range(0));
  const Trajectory& t = Drive();
  const std::vector<ImuIncrement>& inc = Increments();
  const int64_t n = static_cast<int64_t>(inc.size()) - 1;
  const lockstep::Kernel kernel = lockstep::SelectKernel();
  const ImuErrorModel model = Model(which);
  const bool with_sensor = stage != Stage::kMechanization;
  const lockstep::LockstepJob job = lockstep::ComposeJob(
      with_sensor ? &model : nullptr, 1, t.environment, kRate_hz, NedMechanizationOptions());
  auto group = std::make_unique<lockstep::LockstepGroup>();
  lockstep::GroupStreams streams;
  group->lanes = kernel.width;
  lockstep::KernelInputs in;
  in.increments = &inc[0].delta_theta_ib_b[0];
  int64_t samples = 0;
  for (auto _ : state) {
    for (int lane = 0; lane < kernel.width; ++lane) {
      lockstep::StartSensorLane(job, static_cast<uint32_t>(lane), lane, group.get(), &streams);
      lockstep::SetNavLane(t.truth[0], lane, group.get());
    }
    for (int64_t k = 1; k <= n; k += lockstep::kBlock) {
      const int64_t end = std::min<int64_t>(k + lockstep::kBlock, n + 1);
      if (with_sensor) lockstep::LoadBlock(job, kernel, k - 1, &streams, group.get());
      if (stage == Stage::kSensorErrors) {
        kernel.advance(job.kernel, in, k, end, /*navigate=*/false, group.get());
      } else if (stage == Stage::kMechanization) {
        kernel.advance(job.kernel, in, k, end, /*navigate=*/true, group.get());
      }
    }
    benchmark::DoNotOptimize(group->nav.lat_rad[0]);
    benchmark::DoNotOptimize(group->nav.sum_dv[0][0]);
    samples += n * kernel.width;
  }
  state.SetItemsProcessed(samples);
  state.SetLabel(std::string(kernel.name) + (with_sensor ? std::string(" ") + kModels[which] : ""));
}

void BM_Deviates(benchmark::State& state) { RunStage(state, Stage::kDeviates); }
void BM_SensorErrors(benchmark::State& state) { RunStage(state, Stage::kSensorErrors); }
void BM_Mechanization(benchmark::State& state) { RunStage(state, Stage::kMechanization); }

BENCHMARK(BM_Deviates)->DenseRange(0, 2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SensorErrors)->DenseRange(0, 2)->Unit(benchmark::kMillisecond);
// The statistics stage: the navigation state of the lanes is the mechanization's at its end on
// ideal increments (errors of a few metres after 600 s: ordinary values for the sums), held
// fixed; the truth is the trajectory's at each epoch.
void BM_Statistics(benchmark::State& state) {
  constexpr int64_t kEpochEvery = 100;
  const Trajectory& t = Drive();
  const std::vector<ImuIncrement>& inc = Increments();
  const int64_t n = static_cast<int64_t>(inc.size()) - 1;
  const lockstep::Kernel kernel = lockstep::SelectKernel();
  const lockstep::LockstepJob job =
      lockstep::ComposeJob(nullptr, 1, t.environment, kRate_hz, NedMechanizationOptions());
  auto group = std::make_unique<lockstep::LockstepGroup>();
  lockstep::GroupStreams streams;
  group->lanes = kernel.width;
  lockstep::KernelInputs in;
  in.increments = &inc[0].delta_theta_ib_b[0];
  for (int lane = 0; lane < kernel.width; ++lane) {
    lockstep::SetNavLane(t.truth[0], lane, group.get());
  }
  for (int64_t k = 1; k <= n; k += lockstep::kBlock) {
    kernel.advance(job.kernel, in, k, std::min<int64_t>(k + lockstep::kBlock, n + 1), true,
                   group.get());
  }
  std::vector<nav_error_lanes::TruthTerms> truth;
  for (int64_t k = kEpochEvery; k <= n; k += kEpochEvery) {
    truth.push_back(lockstep::ErrorTruthTerms(t.environment, t.truth[static_cast<size_t>(k)]));
  }
  std::vector<EpochSums> sums(truth.size());
  const bool per_run = state.range(0) == 1;
  int64_t samples = 0;
  for (auto _ : state) {
    for (size_t epoch = 0; epoch < truth.size(); ++epoch) {
      double errors[kNumErrorComponents][lockstep::kMaxLanes];
      if (per_run) {
        const NavState& truth_state = t.truth[(epoch + 1) * kEpochEvery];
        for (int lane = 0; lane < kernel.width; ++lane) {
          const ErrorComponentValues v = ErrorComponentsOf(ComputeNavError(
              t.environment, lockstep::NavStateOfLane(*group, 1.0 / kRate_hz, lane), truth_state));
          for (int c = 0; c < kNumErrorComponents; ++c) errors[c][lane] = v[c];
        }
      } else {
        kernel.errors(truth[epoch], group->nav, errors);
      }
      for (int lane = 0; lane < kernel.width; ++lane) {
        for (int c = 0; c < kNumErrorComponents; ++c) {
          sums[epoch].sum[c].Add(errors[c][lane]);
          sums[epoch].sum_squares[c].AddSquare(errors[c][lane]);
        }
      }
    }
    samples += static_cast<int64_t>(truth.size()) * kEpochEvery * kernel.width;
  }
  benchmark::DoNotOptimize(sums[0].sum[0]);
  state.SetItemsProcessed(samples);
  state.SetLabel(std::string(kernel.name) + (per_run ? " one run at a time" : ""));
}

BENCHMARK(BM_Mechanization)->Arg(0)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Statistics)->DenseRange(0, 1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace driftlab

BENCHMARK_MAIN();
