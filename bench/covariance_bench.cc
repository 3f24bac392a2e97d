// Time of the linear covariance analysis alone (FilterCovarianceAnalysis, what `driftlab run
// --covariance` adds to a job) on the example jobs, one thread: the shared truth, the filter's
// error model and the aiding schedule are prepared once outside the timed loop, as
// RunMonteCarloWithAnalysis prepares them.
//   build/bench/driftlab_bench_covariance --benchmark_repetitions=5
//   --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <memory>
#include <string>
#include <vector>

#include "driftlab/app/job_file.h"
#include "driftlab/app/monte_carlo_job.h"
#include "driftlab/ins_gnss_filter.h"
#include "driftlab/monte_carlo.h"
#include "montecarlo/internal.h"

namespace {

const char* const kExamples[] = {"car_drive.json", "car_drive_gnss.json"};

// The analysis's inputs for example i, built as RunMonteCarloWithAnalysis builds them.
struct AnalysisInputs {
  driftlab::MonteCarloSpec spec;
  driftlab::mc_detail::SharedTruth truth;
  std::vector<int64_t> epoch_samples;
  bool ekf = false;
};

const AnalysisInputs& Inputs(int i) {
  static std::unique_ptr<AnalysisInputs> cache[2];
  if (cache[i] != nullptr) return *cache[i];
  auto in = std::make_unique<AnalysisInputs>();
  in->spec = driftlab::app::ToMonteCarloSpec(
      driftlab::app::LoadJobFile(std::string(DRIFTLAB_SOURCE_DIR) + "/examples/" + kExamples[i]),
      {});
  in->spec.covariance = true;
  driftlab::ValidateMonteCarloSpec(in->spec);
  const std::unique_ptr<driftlab::TrajectoryGenerator> generator =
      driftlab::mc_detail::PrepareSharedTruth(in->spec, false, &in->truth);
  bool cancelled = false;
  driftlab::mc_detail::StreamSharedTruth(in->spec, false, generator.get(), &in->truth, nullptr,
                                         &cancelled, nullptr);
  driftlab::mc_detail::PrepareFilterModel(in->spec, &in->truth);
  for (const driftlab::mc_detail::Report& r : in->truth.reports) {
    if (r.epoch >= 0) in->epoch_samples.push_back(r.k);
  }
  in->ekf = in->spec.filter == driftlab::NavigationFilterKind::kInsGnssEkf;
  cache[i] = std::move(in);
  return *cache[i];
}

void BM_CovarianceAnalysis(benchmark::State& state) {
  const AnalysisInputs& in = Inputs(static_cast<int>(state.range(0)));
  const driftlab::MonteCarloSpec& spec = in.spec;
  const int64_t step = in.ekf ? spec.ekf_propagation_step_samples : spec.covariance_step_samples;
  for (auto _ : state) {
    const std::vector<driftlab::CovarianceEpoch> epochs = driftlab::FilterCovarianceAnalysis(
        spec.simulation.motion, spec.simulation.rate_hz, in.truth.ekf_noise, in.truth.ekf_P0,
        in.ekf ? in.truth.schedule.get() : nullptr, in.epoch_samples, step,
        in.ekf ? driftlab::InsGnssFilterOptions().discretization
               : driftlab::Discretization::kVanLoan);
    benchmark::DoNotOptimize(epochs.data());
  }
  state.SetLabel(std::string(kExamples[state.range(0)]) + ", " +
                 std::to_string(in.truth.ekf_P0.rows()) + " states");
}
BENCHMARK(BM_CovarianceAnalysis)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
