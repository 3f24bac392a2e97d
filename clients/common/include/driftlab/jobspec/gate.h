// CI accuracy gate: compares named metrics of a result against a baseline result.
//
// Metric names (every metric is an error magnitude: larger is worse):
//   metric    := selector "." component "." statistic
//   selector  := "final"                 the final epoch and the final checkpoint
//              | "epoch[t=" T "]"        the output epoch at time T [s]
//              | "checkpoint[t=" T "]"   the checkpoint at time T [s]
//   component := lower-case ErrorComponent name: position_north_m, ..., yaw_deg,
//                horizontal_position_m, position_3d_m
//   statistic := epoch statistics   abs_mean (|mean|), std, rms, std_ci95_low, std_ci95_high,
//                                   rms_ci95_low, rms_ci95_high
//              | checkpoint ones    p50, p68, p95, p99, max_abs; for horizontal_position_m also
//                                   cep50, cep95, drms2
//   "final" has both kinds; "epoch[...]" the epoch ones; "checkpoint[...]" the checkpoint ones.
//   T is printed in the shortest form that reads back to the same double ("600", "0.5"); a rule
//   may write it in any form (600.0, 6e2). Examples: final.horizontal_position_m.cep95,
//   final.position_north_m.p95, final.yaw_deg.rms, epoch[t=600].velocity_down_m_per_s.std.
//
// Rules (YAML or JSON, read with yaml-cpp):
//   defaults: {abs_tol: 0, rel_tol: 0.1}     # optional; these are the built-in defaults
//   rules:                                   # required, at least one
//     - metric: "final.*"                    # exact name or glob: * any text, ? one character
//       rel_tol: 0.1                         # optional, default from `defaults`
//     - metric: final.*.max_abs
//       abs_tol: 0.5                         # optional, in the metric's unit
//     - metric: final.*.std_ci95_*
//       skip: true                           # optional: do not gate the matched metrics
// The last rule matching a metric decides; metrics no rule matches are not gated; a rule that
// matches no metric of the baseline is an error (a typo would silently gate nothing). A metric
// regresses when current > baseline + max(abs_tol, rel_tol * |baseline|).
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "driftlab/v1/result.pb.h"

namespace driftlab::jobspec {

// One named number of a result.
struct Metric {
  std::string name;
  double value = 0;  // in the unit of the metric's component
};

// Every metric of a result, in a fixed order: final, then epochs, then checkpoints, each by
// component in enum order, statistics in the order of the grammar above. Undefined (NaN) values
// are left out: sigma and its interval of a one-run result. The result must be valid
// (ValidateJobResult).
std::vector<Metric> ListMetrics(const v1::JobResult& result);

// One gate rule; `metric` is an exact name or a glob (see above).
struct GateRule {
  std::string metric;
  double abs_tol = 0;  // [unit of the metric]
  double rel_tol = 0;  // fraction of |baseline|
  bool skip = false;
};

// Built-in relative tolerances. A re-run of the same job and seed reproduces the result to the
// bit (DESIGN.md invariant 3), so any change comes from the code or the model; the tolerances are
// set above the 95 % spread of the ratio of a statistic between two independent seeds of 1000
// runs each (normal errors), so a change of seed alone does not trip them, while an error 1.5
// times larger does:
//   sigma, RMS (and p50, p68, CEP50, 2DRMS): +-6.2 % = 1.96 sqrt(2) / sqrt(2 N)      -> 10 %
//   p95, CEP95: +-8.7 %; p99: +-12 %; max: -23 % / +29 % (order statistics; 2000 simulated
//   pairs of 1000-sample |N(0, 1)| sets)                                        -> 15, 20, 40 %
inline constexpr double kDefaultRelTol = 0.10;
inline constexpr double kDefaultRelTolP95 = 0.15;
inline constexpr double kDefaultRelTolP99 = 0.20;
inline constexpr double kDefaultRelTolMax = 0.40;

// The rules used without --rules: every final-epoch and final-checkpoint statistic ("final.*")
// at the tolerances above; not gated: abs_mean (the bias of a zero-mean error is noise of
// sigma / sqrt(N); a real bias shows in the RMS) and the confidence-interval bounds (they follow
// sigma and RMS).
std::vector<GateRule> DefaultGateRules();

// Parses a rules document (YAML or JSON). `source` names the text in errors. Throws SpecError
// naming the field path, e.g. "rules[1].rel_tol: -0.1 is not allowed; allowed: 0 <= rel_tol <=
// 100".
std::vector<GateRule> ParseGateRules(std::string_view text, std::string_view source = "rules");

// Reads a rules file. Throws SpecError naming the file.
std::vector<GateRule> LoadGateRules(const std::filesystem::path& path);

// True when `name` matches `pattern` (* any text, ? one character, all else literal).
bool MetricMatches(std::string_view pattern, std::string_view name);

// One compared metric.
struct GateRow {
  std::string metric;
  double baseline = 0;
  double current = 0;  // NaN when the metric is missing from the current result
  double limit = 0;    // baseline + max(abs_tol, rel_tol * |baseline|)
  bool pass = false;
  std::string note;  // why it failed ("missing in the current result"), else empty
};

struct GateReport {
  std::vector<GateRow> rows;  // in ListMetrics order of the baseline
  int failures = 0;
  std::string job_name;            // the baseline's job name (JUnit suite name)
  std::vector<std::string> notes;  // e.g. different engine versions; informational
  bool passed() const { return failures == 0; }
};

// Compares `current` against `baseline` under `rules`. Throws SpecError when the two results are
// of different jobs (job echoes differ) and allow_different_job is false, and when a rule matches
// no metric of the baseline ("rules[i].metric").
GateReport RunGate(const v1::JobResult& baseline, const v1::JobResult& current,
                   const std::vector<GateRule>& rules, bool allow_different_job);

// A plain-text table: metric, baseline, current, limit, PASS/FAIL, then a summary line.
std::string FormatGateTable(const GateReport& report);

// JUnit XML: one <testsuite>, one <testcase> per compared metric, a <failure message="..."> for
// each regression. All text escaped for XML 1.0.
std::string RenderJunitXml(const GateReport& report);

}  // namespace driftlab::jobspec
