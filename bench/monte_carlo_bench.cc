// Monte-Carlo throughput (DESIGN.md "Speed by design"): IMU samples per second through
// the full per-run pipeline (sensor error model "tactical" from presets.h with every term it has
// on, mechanization A with coning/sculling, errors and exact sums at the epochs), at 1 and 2
// worker threads. Build Release for numbers:
//   cmake --build build-rel --target driftlab_bench_monte_carlo
//   build-rel/bench/driftlab_bench_monte_carlo
// Counters: samples_per_s (all threads) and samples_per_s_per_core = samples_per_s / threads.
// The shared truth is generated once per iteration, as in a real job; its share is reported as
// truth_fraction.
#include <benchmark/benchmark.h>

#include <cmath>

#include "car_like_motion.h"
#include "driftlab/monte_carlo.h"
#include "driftlab/presets.h"

namespace driftlab {
namespace {

// 600 s at 100 Hz: 60 s static, accelerate to 20 m/s, a 90-degree turn, cruise.
MonteCarloSpec BenchJob(int threads, uint32_t runs) {
  MonteCarloSpec spec;
  spec.simulation.motion = bench::CarLike600s();
  spec.simulation.rate_hz = 100.0;
  spec.sensor = FindImuPreset("tactical");
  spec.runs = runs;
  spec.epoch_every_samples = 100;
  spec.initial_errors.attitude_rad = Eigen::Vector3d(1e-3, 1e-3, 1e-2);
  spec.threads = threads;
  return spec;
}

void BM_MonteCarloTactical(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  const MonteCarloSpec spec = BenchJob(threads, static_cast<uint32_t>(8 * threads));
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
  state.counters["samples_per_s"] =
      benchmark::Counter(static_cast<double>(samples), benchmark::Counter::kIsRate);
  state.counters["samples_per_s_per_core"] =
      benchmark::Counter(static_cast<double>(samples) / threads, benchmark::Counter::kIsRate);
  state.counters["truth_fraction"] = truth_s / wall_s;
}
BENCHMARK(BM_MonteCarloTactical)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace driftlab

BENCHMARK_MAIN();
