// Lockstep free-inertial NED throughput per instruction-set path: IMU samples per second on one
// core for the scalar one-run-at-a-time reference (DRIFTLAB_ISA=scalar) and each
// lockstep path the CPU has (baseline, avx2, avx512), for three sensor models:
//   * white noise only on all 6 axes;
//   * white + Gauss-Markov + random walk on all 6 axes (no other term);
//   * the tactical preset (presets.h: every term it has, incl. flicker, scale factor,
//     misalignment, turn-on bias, range).
// The job: 600 s at 100 Hz (60 s static, accelerate to 20 m/s, 90-degree turn, cruise), NED
// mechanization with coning/sculling, WGS-84, epochs every 100 samples, 64 runs, 1 thread.
// items_per_second: IMU samples per CPU second of the benchmark thread, which does all the work
// with threads = 1 (end to end: shared truth, runs, reduction); CPU time rather than wall time
// because the bench machines are shared. truth_fraction: the shared truth's share of the wall
// time.
// Run under nice with repetitions for medians, e.g.
//   nice -n 19 build/bench/driftlab_bench_lockstep --benchmark_repetitions=5
//     --benchmark_report_aggregates_only=true   (one command line)
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdlib>
#include <string>

#include "car_like_motion.h"
#include "driftlab/monte_carlo.h"
#include "driftlab/presets.h"

namespace driftlab {
namespace {

MonteCarloSpec BenchJob(const ImuErrorModel& model) {
  MonteCarloSpec spec;
  spec.simulation.motion = bench::CarLike600s();
  spec.simulation.rate_hz = 100.0;
  spec.sensor = model;
  spec.runs = 64;
  spec.epoch_every_samples = 100;
  spec.initial_errors.attitude_rad = Eigen::Vector3d(1e-3, 1e-3, 1e-2);
  spec.threads = 1;
  return spec;
}

ImuErrorModel WhiteGaussMarkovRandomWalk() {
  ImuErrorModel m;
  m.gyro.white_noise_density = 1e-4;
  m.gyro.bias_gauss_markov.sigma = 1e-5;
  m.gyro.bias_gauss_markov.tau_s = 100.0;
  m.gyro.random_walk = 1e-6;
  m.accel.white_noise_density = 1e-3;
  m.accel.bias_gauss_markov.sigma = 1e-3;
  m.accel.bias_gauss_markov.tau_s = 100.0;
  m.accel.random_walk = 1e-5;
  return m;
}

// White noise only on all 6 axes (the static gnss-ins-sim comparison's model).
ImuErrorModel WhiteOnly() {
  ImuErrorModel m;
  m.gyro.white_noise_density = 1e-4;
  m.accel.white_noise_density = 1e-3;
  return m;
}

const char* kPaths[] = {"scalar", "baseline", "avx2", "avx512"};

bool PathAvailable(const std::string& path) {
#if defined(__x86_64__)
  if (path == "avx2") return __builtin_cpu_supports("avx2");
  if (path == "avx512") {
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
           __builtin_cpu_supports("avx512vl");
  }
  return true;
#else
  return path == "scalar" || path == "baseline";
#endif
}

void Run(benchmark::State& state, const ImuErrorModel& model) {
  const std::string path = kPaths[state.range(0)];
  if (!PathAvailable(path)) {
    state.SkipWithError(("the CPU has no " + path).c_str());
    return;
  }
  setenv("DRIFTLAB_ISA", path.c_str(), 1);
  state.SetLabel(path);
  const MonteCarloSpec spec = BenchJob(model);
  int64_t samples = 0;
  double truth_s = 0.0, wall_s = 0.0;
  for (auto _ : state) {
    const MonteCarloStatistics stats = RunMonteCarlo(spec);
    samples += stats.data().timings.samples_processed;
    truth_s += stats.data().timings.truth_s;
    wall_s += stats.data().timings.wall_s;
    benchmark::DoNotOptimize(stats.data().epochs.data());
  }
  unsetenv("DRIFTLAB_ISA");
  state.SetItemsProcessed(samples);
  state.counters["truth_fraction"] = truth_s / wall_s;
}

void BM_NedWhiteOnly(benchmark::State& state) { Run(state, WhiteOnly()); }
void BM_NedWhiteGaussMarkovRandomWalk(benchmark::State& state) {
  Run(state, WhiteGaussMarkovRandomWalk());
}
void BM_NedTactical(benchmark::State& state) { Run(state, FindImuPreset("tactical")); }

// Thread scaling (strong: the same job on 1 and 2 threads, wall time): white + Gauss-Markov +
// random walk, 256 runs, the widest path the CPU has. The shared truth (one thread) is the
// serial part: its share of the one-thread time bounds the speed-up (Amdahl).
void BM_NedThreads(benchmark::State& state) {
  MonteCarloSpec spec = BenchJob(WhiteGaussMarkovRandomWalk());
  spec.runs = 256;
  spec.threads = static_cast<int>(state.range(0));
  int64_t samples = 0;
  double truth_s = 0.0, wall_s = 0.0;
  for (auto _ : state) {
    const MonteCarloStatistics stats = RunMonteCarlo(spec);
    samples += stats.data().timings.samples_processed;
    truth_s += stats.data().timings.truth_s;
    wall_s += stats.data().timings.wall_s;
    benchmark::DoNotOptimize(stats.data().epochs.data());
  }
  state.SetItemsProcessed(samples);
  state.counters["truth_fraction"] = truth_s / wall_s;
}

BENCHMARK(BM_NedWhiteOnly)->DenseRange(0, 3)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_NedWhiteGaussMarkovRandomWalk)->DenseRange(0, 3)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_NedTactical)->DenseRange(0, 3)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_NedThreads)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace driftlab

BENCHMARK_MAIN();
