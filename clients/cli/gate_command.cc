// `driftlab gate RESULT --baseline BASELINE [--rules RULES] [--junit FILE]
//  [--allow-different-job]`: compares named metrics of a result against a baseline (gate.h),
// prints a table and exits 0 on pass, 1 on a regression, 2 on bad input (unreadable or invalid
// result or rules, results of different jobs, unwritable JUnit file).
// `driftlab gate RESULT --list-metrics` prints every metric name of RESULT with its value.
#include <fmt/format.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>

#include "commands.h"
#include "driftlab/jobspec/gate.h"
#include "driftlab/jobspec/result_file.h"
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
};

int RunGateCommand(const GateOptions& options) {
  jobspec::GateReport report;
  try {
    const v1::JobResult current = jobspec::ReadJobResult(options.result_path);
    if (options.list_metrics) {
      for (const jobspec::Metric& metric : jobspec::ListMetrics(current)) {
        fmt::print("{} {}\n", metric.name, metric.value);
      }
      return kExitOk;
    }
    if (options.baseline_path.empty()) {
      throw SpecError("--baseline", "", "a baseline result file (required unless --list-metrics)");
    }
    const v1::JobResult baseline = jobspec::ReadJobResult(options.baseline_path);
    const std::vector<jobspec::GateRule> rules = options.rules_path.empty()
                                                     ? jobspec::DefaultGateRules()
                                                     : jobspec::LoadGateRules(options.rules_path);
    report = jobspec::RunGate(baseline, current, rules, options.allow_different_job);
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }
  fmt::print("{}", jobspec::FormatGateTable(report));
  if (!options.junit_path.empty()) {
    if (const int status =
            WriteOutputText(options.junit_path, jobspec::RenderJunitXml(report), "--junit")) {
      return status;
    }
  }
  return report.passed() ? kExitOk : kExitFailure;
}

const RegisterCommand kGate("gate", [](CLI::App& app) -> std::function<int()> {
  auto options = std::make_shared<GateOptions>();
  CLI::App* command = app.add_subcommand(
      "gate",
      "Compare a result's metrics against a baseline: exit 0 pass, 1 regression, 2 bad input");
  command->add_option("result", options->result_path, "Result file to check")->required();
  command->add_option("--baseline,-b", options->baseline_path, "Baseline result file");
  command->add_option("--rules,-r", options->rules_path,
                      "Rules file (YAML or JSON); default: final statistics, 10 % relative");
  command->add_option("--junit", options->junit_path, "Write a JUnit XML report to this file");
  command->add_flag("--allow-different-job", options->allow_different_job,
                    "Compare results even when their job echoes differ");
  command->add_flag("--list-metrics", options->list_metrics,
                    "Print every metric name of RESULT with its value, and exit");
  return [options] { return RunGateCommand(*options); };
});

}  // namespace
}  // namespace driftlab::cli
