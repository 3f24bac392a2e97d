// Overlapping Allan deviation of 10 h of one gyro axis at 100 Hz (3.6e6 rate samples), octave
// and 8-per-octave tau grids, including noise identification and confidence intervals.
// Reported as samples per second (items). Not yet in bench/CMakeLists.txt: add
//   add_executable(driftlab_bench_allan allan_bench.cc) and link it like driftlab_bench_engine.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "driftlab/allan.h"

namespace driftlab {
namespace {

std::vector<double> WhiteRates(int64_t n) {
  std::mt19937_64 engine(1);
  std::normal_distribution<double> gauss;
  std::vector<double> y(static_cast<size_t>(n));
  for (auto& v : y) v = 1e-3 * gauss(engine);
  return y;
}

void BM_OverlappingAdevTenHoursAt100Hz(benchmark::State& state) {
  static const std::vector<double> y = WhiteRates(3600000);
  for (auto _ : state) {
    auto curve = OverlappingAllanDeviation(y, 100.0, static_cast<int>(state.range(0)));
    benchmark::DoNotOptimize(curve.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(y.size()));
}
BENCHMARK(BM_OverlappingAdevTenHoursAt100Hz)->Arg(1)->Arg(8)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace driftlab

BENCHMARK_MAIN();
