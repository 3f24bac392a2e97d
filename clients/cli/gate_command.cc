// `driftlab gate RESULT --baseline BASELINE [--rules RULES] [--alpha A] [--strict]
//  [--junit FILE] [--allow-different-job]`: decides per metric whether RESULT is worse than
// BASELINE by more than the tolerance, as a hypothesis test with family-wise error alpha (gate.h),
// prints a table and exits 0 on pass, 1 on a regression (or, with --strict, an inconclusive
// metric), 2 on bad input (unreadable or invalid result or rules, a result whose statistics
// disagree with its exact sums or per-run values (result_check.h), a result of fewer than 2 runs,
// results of different jobs, unwritable JUnit file).
// `driftlab gate RESULT --list-metrics` prints every metric name of RESULT with its value.
// `driftlab gate RESULT --runs-for-change REL [--rules RULES] [--alpha A]` prints the runs per file
// with which a sigma grown by REL (0.3 = +30 %) is a regression with 90 % power.
#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "driftlab/app/gate.h"
#include "driftlab/app/result_check.h"
#include "driftlab/app/result_file.h"
#include "driftlab/spec_error.h"

namespace driftlab::cli {
namespace {

struct GateOptions {
  std::string result_path;
  std::string baseline_path;
  std::string rules_path;
  std::string junit_path;
  bool allow_different_job = false;
  bool list_metrics = false;
  bool strict = false;
  double alpha = app::kDefaultAlpha;
  double runs_for_change = 0;
};

// The rule deciding `name` (the last matching), or nullptr.
const app::GateRule* RuleFor(const std::vector<app::GateRule>& rules, const std::string& name) {
  for (size_t r = rules.size(); r-- > 0;) {
    if (app::MetricMatches(rules[r].metric, name)) return &rules[r];
  }
  return nullptr;
}

// Planning: runs per file for a sigma change of `change` at the tolerance of the rule deciding
// final.horizontal_position_m.std, over the metrics the rules gate in `result`.
int PrintRunsForChange(const v1::JobResult& result, const std::vector<app::GateRule>& rules,
                       const GateOptions& options) {
  if (!(options.alpha > 0 && options.alpha < 1)) {
    throw SpecError("--alpha", fmt::format("{}", options.alpha), "0 < alpha < 1");
  }
  if (!(options.runs_for_change > 0 && options.runs_for_change <= 100)) {
    throw SpecError("--runs-for-change", fmt::format("{}", options.runs_for_change),
                    "0 < change <= 100 (0.3 = sigma grown by 30 %)");
  }
  int gated = 0;
  for (const app::Metric& metric : app::ListMetrics(result)) {
    const app::GateRule* rule = RuleFor(rules, metric.name);
    gated += rule && !rule->skip ? 1 : 0;
  }
  const std::string reference = "final.horizontal_position_m.std";
  const app::GateRule* rule = RuleFor(rules, reference);
  const double rel_tol = rule && !rule->skip ? rule->rel_tol : app::kDefaultRelTol;
  const long runs = app::RunsForSigmaChange(1.0 + options.runs_for_change, rel_tol, options.alpha,
                                            std::max(gated, 1));
  if (runs == 0) {
    fmt::print(
        "a sigma change of +{:g} % is within the {:g} % tolerance of {}: no run count "
        "makes it a regression\n",
        100.0 * options.runs_for_change, 100.0 * rel_tol, reference);
    return kExitOk;
  }
  fmt::print(
      "runs per file (baseline and current) for a sigma grown by {:g} % to be a "
      "regression with 90 % power: {}\n(tolerance {:g} % from the rule of {}, alpha {} "
      "family-wise over {} gated metrics, variance-ratio F test at alpha / {})\n",
      100.0 * options.runs_for_change, runs, 100.0 * rel_tol, reference, options.alpha, gated,
      gated);
  return kExitOk;
}

int RunGateCommand(const GateOptions& options) {
  app::GateReport report;
  try {
    CheckCommandOutputs({{options.result_path, "RESULT"},
                         {options.baseline_path, "--baseline"},
                         {options.rules_path, "--rules"}},
                        {{options.junit_path, "--junit"}});
    const v1::JobResult current = app::ReadJobResult(options.result_path);
    app::VerifyResultStatistics(current, options.result_path);
    if (options.list_metrics) {
      for (const app::Metric& metric : app::ListMetrics(current)) {
        fmt::print("{} {}\n", metric.name, metric.value);
      }
      return kExitOk;
    }
    const std::vector<app::GateRule> rules = options.rules_path.empty()
                                                 ? app::DefaultGateRules()
                                                 : app::LoadGateRules(options.rules_path);
    if (options.runs_for_change != 0) return PrintRunsForChange(current, rules, options);
    if (options.baseline_path.empty()) {
      throw SpecError("--baseline", "", "a baseline result file (required unless --list-metrics)");
    }
    const v1::JobResult baseline = app::ReadJobResult(options.baseline_path);
    app::VerifyResultStatistics(baseline, options.baseline_path);
    app::GateOptions gate_options;
    gate_options.alpha = options.alpha;
    gate_options.strict = options.strict;
    gate_options.allow_different_job = options.allow_different_job;
    gate_options.baseline_name = options.baseline_path;
    gate_options.current_name = options.result_path;
    report = app::RunGate(baseline, current, rules, gate_options);
    report.baseline_file = options.baseline_path;
    report.current_file = options.result_path;
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }
  fmt::print("{}", app::FormatGateTable(report));
  if (!options.junit_path.empty()) {
    if (const int status =
            WriteOutputText(options.junit_path, app::RenderJunitXml(report), "--junit")) {
      return status;
    }
  }
  return report.passed() ? kExitOk : kExitFailure;
}

const RegisterCommand kGate("gate", [](CLI::App& app) -> std::function<int()> {
  auto options = std::make_shared<GateOptions>();
  CLI::App* command = app.add_subcommand(
      "gate", "Test a result's metrics against a baseline: exit 0 pass, 1 regression, 2 bad input");
  command->add_option("result", options->result_path, "Result file to check")->required();
  command->add_option("--baseline,-b", options->baseline_path, "Baseline result file");
  command->add_option("--rules,-r", options->rules_path,
                      "Rules file (YAML or JSON); default: final statistics, 10 % relative "
                      "(p95 15 %)");
  command->add_option("--alpha", options->alpha,
                      "Family-wise false-alarm rate over all gated metrics (Holm); default 0.05");
  command->add_flag("--strict", options->strict,
                    "Fail on inconclusive metrics too (interval straddles the limit)");
  command->add_option("--runs-for-change", options->runs_for_change,
                      "Print the runs per file that detect a sigma grown by this fraction "
                      "(0.3 = +30 %) with 90 % power, and exit");
  command->add_option("--junit", options->junit_path, "Write a JUnit XML report to this file");
  command->add_flag("--allow-different-job", options->allow_different_job,
                    "Compare results even when their job echoes differ");
  command->add_flag("--list-metrics", options->list_metrics,
                    "Print every metric name of RESULT with its value, and exit");
  return [options] { return RunGateCommand(*options); };
});

}  // namespace
}  // namespace driftlab::cli
