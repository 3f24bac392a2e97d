// Time of the error budget (`driftlab budget`, monte_carlo.h ComputeErrorBudget) on the example
// jobs against the job's plain covariance analysis (`run --covariance` with one run): the budget
// propagates every source beside P with the same transition, so its cost over the analysis is the
// price of the sources.
//   build/bench/driftlab_bench_budget --benchmark_repetitions=5 --benchmark_report_aggregates_only
#include <benchmark/benchmark.h>

#include <string>

#include "driftlab/app/job_file.h"
#include "driftlab/app/monte_carlo_job.h"
#include "driftlab/monte_carlo.h"

namespace {

const char* const kExamples[] = {"car_drive.json", "car_drive_gnss.json"};

driftlab::MonteCarloSpec Example(int i) {
  return driftlab::app::ToMonteCarloSpec(
      driftlab::app::LoadJobFile(std::string(DRIFTLAB_SOURCE_DIR) + "/examples/" + kExamples[i]),
      {});
}

void BM_ErrorBudget(benchmark::State& state) {
  const driftlab::MonteCarloSpec spec = Example(static_cast<int>(state.range(0)));
  size_t sources = 0;
  for (auto _ : state) {
    const driftlab::ErrorBudgetResult budget = driftlab::ComputeErrorBudget(spec);
    sources = budget.sources.size();
    benchmark::DoNotOptimize(budget.total.data());
  }
  state.SetLabel(std::string(kExamples[state.range(0)]) + ", " + std::to_string(sources) +
                 " sources");
}
BENCHMARK(BM_ErrorBudget)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(1);

// The covariance analysis alone, with one Monte-Carlo run (RunMonteCarloWithAnalysis).
void BM_CovarianceAnalysisWithOneRun(benchmark::State& state) {
  driftlab::MonteCarloSpec spec = Example(static_cast<int>(state.range(0)));
  spec.covariance = true;
  spec.runs = 1;
  spec.run_count = 1;
  spec.threads = 1;
  for (auto _ : state) {
    const driftlab::MonteCarloOutput output = driftlab::RunMonteCarloWithAnalysis(spec);
    benchmark::DoNotOptimize(output.covariance->epochs.data());
  }
  state.SetLabel(kExamples[state.range(0)]);
}
BENCHMARK(BM_CovarianceAnalysisWithOneRun)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
