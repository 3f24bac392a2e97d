// The error budget of a job (`driftlab budget`): the engine's budget (monte_carlo.h
// ComputeErrorBudget) as the result message v1::ErrorBudget (result.proto), its JSON file, and the
// Monte-Carlo check of the top sources.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "driftlab/monte_carlo.h"
#include "driftlab/v1/result.pb.h"

namespace driftlab::app {

// The budget as the result message: variances in the result's units squared (degrees squared for
// the angles), sources sorted by their final contribution (horizontal position, then 3-D, then
// yaw: the first nonzero total), largest first. `job` is echoed.
v1::ErrorBudget ToErrorBudget(const v1::Job& job, const ErrorBudgetResult& budget,
                              const std::string& engine_version);

// Protobuf JSON mapping with proto field names (as the result files).
std::string ErrorBudgetToJson(const v1::ErrorBudget& budget);

// The job of the Monte-Carlo check of `source` (a name in budget.sources): `spec` with every IMU
// error term zeroed but the source's own (for an initial-error source of a free-inertial job: every
// IMU term zeroed and the other initial errors), runs / seed as given. A filter keeps its own model
// (navigation.ekf.sensor = the job's IMU model), its initial errors and its aids, whose errors
// therefore stay in the check: *switched_on receives every source the check's job keeps on.
// Throws SpecError("--mc-check", ...) for a source the check cannot isolate (the white-noise bound
// of an unaugmented scale factor).
MonteCarloSpec BudgetCheckSpec(const MonteCarloSpec& spec, const ErrorBudgetResult& budget,
                               const std::string& source, uint32_t runs,
                               std::vector<std::string>* switched_on);

// Runs the check of the `top` first sources of `out` (its sorted order; a source whose set of
// switched-on sources equals an earlier check's is skipped for the next) over `runs` runs each and
// fills out->checks, check_alpha and verdict. At the final epoch, for each of the 9 position,
// velocity and attitude components with a predicted sigma > 0, the ratio of the Monte-Carlo
// standard deviation to the predicted sigma of the switched-on sources gets its chi-square interval
// (consistency_check.h SigmaRatioInterval) at confidence 1 - alpha / M, M the components tested
// over all checks (Bonferroni: family-wise false-alarm rate <= alpha); a check passes when every
// interval contains 1. `progress` (may be empty) is told each check as it starts.
void CheckErrorBudget(const MonteCarloSpec& spec, const ErrorBudgetResult& budget, uint32_t runs,
                      int top, double alpha, v1::ErrorBudget* out,
                      const std::function<void(const std::string&)>& progress = {});

// The verdict of out->checks: "confirmed at family-wise level A: ..." or "NOT CONFIRMED: ..."
// naming the failed sources and components; "not checked" without checks.
std::string BudgetVerdict(const v1::ErrorBudget& budget);

}  // namespace driftlab::app
