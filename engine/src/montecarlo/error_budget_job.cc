// The error budget of a Monte-Carlo job: the job's covariance analysis (as
// RunMonteCarloWithAnalysis computes it for `run --covariance`) with every error source propagated
// alone beside it.
#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>
#include <vector>

#include "driftlab/error_budget.h"
#include "driftlab/ins_gnss_filter.h"
#include "driftlab/monte_carlo.h"
#include "driftlab/spec_error.h"
#include "montecarlo/internal.h"

namespace driftlab {

ErrorBudgetResult ComputeErrorBudget(const MonteCarloSpec& job) {
  MonteCarloSpec spec = job;
  spec.covariance = true;
  ValidateMonteCarloSpec(spec);
  if (spec.filter_sensor) {
    throw SpecError("navigation.ekf.sensor", "set",
                    "absent for `budget`: the budget of a filter that assumes its own IMU model "
                    "(truth and filter models differ) is not implemented");
  }
  const bool ekf = spec.filter == NavigationFilterKind::kInsGnssEkf;
  mc_detail::SharedTruth shared;
  const std::unique_ptr<TrajectoryGenerator> generator =
      mc_detail::PrepareSharedTruth(spec, true, &shared);
  bool cancelled = false;
  mc_detail::StreamSharedTruth(spec, true, generator.get(), &shared, nullptr, &cancelled, nullptr);
  const ErrorStateNoiseFromImu noise = mc_detail::PrepareFilterModel(spec, &shared);

  ErrorBudgetResult out;
  out.filter = spec.filter;
  out.unrepresented = noise.unrepresented;
  std::vector<int64_t> epoch_samples;
  std::vector<EulerAngles> epoch_attitude;
  for (const mc_detail::Report& r : shared.reports) {
    if (r.epoch >= 0) {
      epoch_samples.push_back(r.k);
      epoch_attitude.push_back(r.truth.euler());
      out.epoch_times_s.push_back(static_cast<double>(r.k) * shared.dt_s);
    }
  }
  ErrorBudgetRecord record;
  record.sources =
      SplitErrorSources(spec.sensor.value_or(ImuErrorModel{}), shared.ekf_noise, shared.ekf_P0,
                        ekf ? shared.schedule->sensors() : AidingSensors{});
  // The same call as RunMonteCarloWithAnalysis's analysis (monte_carlo.cc).
  out.step_samples = ekf ? spec.ekf_propagation_step_samples : spec.covariance_step_samples;
  const std::vector<CovarianceEpoch> epochs = FilterCovarianceAnalysis(
      spec.simulation.motion, spec.simulation.rate_hz, shared.ekf_noise, shared.ekf_P0,
      ekf ? shared.schedule.get() : nullptr, epoch_samples, out.step_samples,
      ekf ? InsGnssFilterOptions().discretization : Discretization::kVanLoan, &record);
  for (size_t e = 0; e < epochs.size(); ++e) {
    out.total.push_back(ComponentVariancesOf(epochs[e].P, epoch_attitude[e]));
  }
  out.sources = std::move(record.sources);
  out.contribution = std::move(record.variances);
  for (size_t e = 0; e < out.total.size(); ++e) {
    for (int c = 0; c < kNumErrorComponents; ++c) {
      double sum = 0.0;
      for (const ComponentVariances& v : out.contribution[e]) sum += v[c];
      const double total = out.total[e][c];
      if (total > 0.0) {
        out.max_relative_sum_error =
            std::max(out.max_relative_sum_error, std::abs(sum - total) / total);
      }
    }
  }
  return out;
}

}  // namespace driftlab
