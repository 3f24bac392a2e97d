// `driftlab budget JOB --out BUDGET.json [--report BUDGET.html] [--mc-check RUNS]`: each error
// source's contribution to every error component's predicted variance (docs/budget.md).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "commands.h"
#include "driftlab/app/error_budget_job.h"
#include "driftlab/app/job_file.h"
#include "driftlab/app/job_validator.h"
#include "driftlab/app/monte_carlo_job.h"
#include "driftlab/app/result_file.h"
#include "driftlab/app/translate.h"
#include "driftlab/report/budget_report.h"
#include "driftlab/spec_error.h"

namespace driftlab::cli {
namespace {

struct BudgetOptions {
  std::string job_path;
  std::string out;
  std::optional<std::string> report;
  std::optional<uint32_t> mc_check_runs;
  uint32_t top = 3;
  std::optional<uint64_t> seed;
  std::optional<int> threads;
  bool quiet = false;
};

// The final epoch's top sources as a table on stdout.
void PrintBudget(const v1::ErrorBudget& b) {
  if (b.t_s_size() == 0) return;
  const int last = b.t_s_size() - 1;
  const int h = static_cast<int>(v1::HORIZONTAL_POSITION_M) - 1;
  const int d = static_cast<int>(v1::POSITION_DOWN_M) - 1;
  const int yaw = static_cast<int>(v1::YAW_DEG) - 1;
  fmt::print(
      "error budget of {} at t = {:g} s ({} sources, filter {}; sum of the sources vs the "
      "total: {:.2g} relative)\n",
      b.job().name().empty() ? "(unnamed)" : b.job().name(), b.t_s(last), b.sources_size(),
      b.filter(), b.max_relative_sum_error());
  fmt::print("{:<34}{:>16}{:>9}{:>16}{:>9}{:>16}{:>9}\n", "source", "horizontal [m]", "share",
             "down [m]", "share", "yaw [deg]", "share");
  auto cell = [&](const google::protobuf::RepeatedPtrField<v1::VarianceSeries>& s, int c) {
    const double v = s[c].variance(last), total = b.total(c).variance(last);
    return fmt::format("{:>16.4g}{:>8.1f}%", std::sqrt(std::max(0.0, v)),
                       total > 0.0 ? 100.0 * v / total : 0.0);
  };
  fmt::print("{:<34}{}{}{}\n", "total", cell(b.total(), h), cell(b.total(), d),
             cell(b.total(), yaw));
  for (int s = 0; s < b.sources_size() && s < 12; ++s) {
    const auto& series = b.sources(s).series();
    fmt::print("{:<34}{}{}{}\n", b.sources(s).name(), cell(series, h), cell(series, d),
               cell(series, yaw));
  }
  if (b.sources_size() > 12) fmt::print("... {} more in the file\n", b.sources_size() - 12);
  fmt::print(
      "(the RMS columns are the square roots of each source's variance; shares add up to "
      "100 %)\n");
}

int RunBudget(const BudgetOptions& options) {
  app::JobFile file;
  MonteCarloSpec spec;
  try {
    file = app::LoadJobFile(options.job_path);
    app::JobValidationOptions validation;
    validation.overrides.seed = options.seed;
    validation.overrides.threads = options.threads;
    std::vector<CommandPath> inputs = {{options.job_path, "JOB"}};
    for (const CommandPath& p : app::JobInputFiles(file.job, file.base_dir)) inputs.push_back(p);
    CheckCommandOutputs(inputs, {{options.out, "--out"}, {options.report.value_or(""), "--report"}},
                        /*creates_directories=*/true);
    spec = app::ValidateJob(file, validation).spec;
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }
  v1::ErrorBudget budget;
  try {
    const ErrorBudgetResult engine_budget = ComputeErrorBudget(spec);
    budget = app::ToErrorBudget(app::JobAsRun(file.job, spec), engine_budget, DRIFTLAB_VERSION);
    if (options.mc_check_runs) {
      app::CheckErrorBudget(spec, engine_budget, *options.mc_check_runs,
                            static_cast<int>(options.top), 0.05, &budget,
                            [&options](const std::string& source) {
                              if (!options.quiet) {
                                fmt::print(stderr, "Monte-Carlo check: {} ...\n", source);
                              }
                            });
    }
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }
  PrintBudget(budget);
  if (budget.checks_size() > 0) {
    const bool confirmed = budget.verdict().rfind("confirmed", 0) == 0;
    std::fflush(stdout);
    fmt::print(confirmed ? stdout : stderr, "{}check: {}\n",
               confirmed ? "" : "warning: ", budget.verdict());
  }
  try {
    for (const std::string* path : {&options.out, options.report ? &*options.report : nullptr}) {
      if (path == nullptr) continue;
      const std::filesystem::path parent = std::filesystem::path(*path).parent_path();
      if (!parent.empty()) std::filesystem::create_directories(parent);
    }
    const int status = WriteOutputText(options.out, app::ErrorBudgetToJson(budget), "--out");
    if (status != kExitOk) return status;
    if (options.report) {
      return WriteOutputText(*options.report, app::RenderBudgetReport(budget), "--report");
    }
  } catch (const std::exception& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitFailure;
  }
  return kExitOk;
}

const RegisterCommand kBudget("budget", [](CLI::App& app) -> std::function<int()> {
  auto options = std::make_shared<BudgetOptions>();
  CLI::App* command = app.add_subcommand(
      "budget",
      "Error budget: each error source's share of every error component's predicted variance "
      "(linear covariance analysis, sources propagated one at a time)");
  command->add_option("job", options->job_path, "Job file (.json, .yaml, .yml)")->required();
  command->add_option("--out,-o", options->out, "Budget file (.json)")->required();
  command->add_option("--report", options->report, "Also write this HTML report");
  AddUnsignedOption(command, "--mc-check", &options->mc_check_runs,
                    "Confirm the top sources by Monte Carlo, RUNS runs each (2 to 100000)", 2,
                    100000);
  AddUnsignedOption(command, "--top", &options->top,
                    "Sources the Monte-Carlo check runs (default 3; 1 to 20)", 1, 20);
  AddUnsignedOption(command, "--seed", &options->seed,
                    "Seed of the Monte-Carlo check (default: the job's monte_carlo.seed)");
  command->add_option("--threads", options->threads, "Worker threads (default 0 = all cores)");
  command->add_flag("--quiet,-q", options->quiet, "No progress output");
  return [options] { return RunBudget(*options); };
});

}  // namespace
}  // namespace driftlab::cli
