// CI accuracy gate: decides, metric by metric, whether a result is worse than a baseline result of
// the same job by more than a tolerance, as a hypothesis test that uses the runs of both files
// (gate_statistics.h), with the family-wise error rate over all gated metrics held at alpha.
//
// Metric names (every metric is an error magnitude: larger is worse):
//   metric    := selector "." component "." statistic  |  "final.nees"
//   selector  := "final"                 the final epoch and the final checkpoint
//              | "epoch[t=" T "]"        the output epoch at time T [s]
//              | "checkpoint[t=" T "]"   the checkpoint at time T [s]
//   component := lower-case ErrorComponent name: position_north_m, ..., yaw_deg,
//                horizontal_position_m, position_3d_m
//   statistic := epoch statistics   abs_mean (|mean|), std, rms
//              | checkpoint ones    p50, p68, p95, p99 (of |error| over the runs)
//   "final" has both kinds; "epoch[...]" the epoch ones; "checkpoint[...]" the checkpoint ones;
//   final.nees is the average NEES of the final epoch (filter INS_GNSS_EKF results only).
// One metric per quantity: CEP50 and CEP95 are p50 and p95 of horizontal_position_m, 2DRMS is
// twice its rms, and the confidence-interval bounds follow std and rms, so none is a metric of its
// own; the sample maximum has no population value to test (it grows with the run count) and is
// not gated either. T is printed in the shortest form that reads back to the same double ("600",
// "0.5"); a rule may write it in any form (600.0, 6e2).
//
// Rules (YAML or JSON, read with yaml-cpp):
//   defaults: {abs_tol: 0, rel_tol: 0.1}     # optional; these are the built-in defaults
//   rules:                                   # required, at least one
//     - metric: "final.*"                    # exact name or glob: * any text, ? one character
//       rel_tol: 0.1                         # optional, default from `defaults`
//     - metric: "epoch[t=60].*.std"          # per epoch
//       abs_tol: 0.5                         # optional, in the metric's unit
//     - metric: final.*.abs_mean
//       skip: true                           # optional: do not gate the matched metrics
// The last rule matching a metric decides; metrics no rule matches are not gated; a rule that
// matches no metric of the baseline is an error (a typo would silently gate nothing).
//
// Decision per metric, with limit = baseline + max(abs_tol, rel_tol |baseline|) and
// H0: current <= limit (the population values):
//   regression    H0 rejected by Holm's procedure over all gated metrics at alpha
//   improved      not a regression, and the (1 - alpha) interval of current / baseline is below 1
//   pass          not a regression, and the interval's upper end is at most limit / baseline
//   inconclusive  otherwise: the interval straddles the limit (too few runs to tell)
// The gate fails on a regression, a metric missing from the current result, and with --strict on
// an inconclusive metric.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "driftlab/v1/result.pb.h"

namespace driftlab::app {

// What a metric measures, and so which test decides it (gate_statistics.h).
enum class MetricKind { kAbsMean, kStd, kRms, kQuantile, kNees };

// One named number of a result, with where its samples live.
struct Metric {
  std::string name;
  double value = 0;  // in the unit of the metric's component
  MetricKind kind = MetricKind::kStd;
  int component = -1;   // 0-based ErrorComponent index (component - 1); -1 for NEES
  int epoch = -1;       // index into result.epochs (moments, NEES), else -1
  int checkpoint = -1;  // index into result.checkpoints (quantiles), else -1
  double quantile = 0;  // kQuantile: the probability, e.g. 0.95
  std::string unit;     // "m", "m/s", "deg" or "" (NEES)
};

// Every metric of a result, in a fixed order: final, then epochs, then checkpoints, each by
// component in enum order, statistics in the order of the grammar above. Undefined (NaN) values
// are left out: sigma of a one-run result. The result must be valid (ValidateJobResult).
std::vector<Metric> ListMetrics(const v1::JobResult& result);

// One gate rule; `metric` is an exact name or a glob (see above).
struct GateRule {
  std::string metric;
  double abs_tol = 0;  // [unit of the metric]
  double rel_tol = 0;  // fraction of |baseline|
  bool skip = false;
};

// Built-in relative tolerances: the change that matters to a user, not a noise allowance
// (the tests account for the sampling noise of both files). p95 and p99 get more room because a
// tail quantile moves more with the shape of the distribution for the same change of sigma.
inline constexpr double kDefaultRelTol = 0.10;
inline constexpr double kDefaultRelTolP95 = 0.15;
inline constexpr double kDefaultRelTolP99 = 0.20;
inline constexpr double kDefaultAlpha = 0.05;

// The rules used without --rules: "final.*" at the tolerances above, except abs_mean (the bias of
// a zero-mean error is noise of sigma / sqrt(N); a real bias shows in the RMS) and p99 (its
// distribution-free interval is unbounded below about 440 runs per file at alpha 0.05).
std::vector<GateRule> DefaultGateRules();

// Parses a rules document (YAML or JSON). `source` names the text in errors. Throws SpecError
// naming the field path, e.g. "rules[1].rel_tol: -0.1 is not allowed; allowed: 0 <= rel_tol <=
// 100".
std::vector<GateRule> ParseGateRules(std::string_view text, std::string_view source = "rules");

// Reads a rules file. Throws SpecError naming the file.
std::vector<GateRule> LoadGateRules(const std::filesystem::path& path);

// True when `name` matches `pattern` (* any text, ? one character, all else literal).
bool MetricMatches(std::string_view pattern, std::string_view name);

enum class GateDecision { kPass, kImproved, kInconclusive, kRegression };
const char* DecisionName(GateDecision decision);  // "pass", "improved", ...

// One compared metric.
struct GateRow {
  std::string metric;
  std::string unit;
  double baseline = 0;
  double current = 0;                    // NaN when the metric is missing from the current result
  double limit = 0;                      // baseline + max(abs_tol, rel_tol * |baseline|)
  double ratio = 0;                      // current / baseline (NaN when the baseline is 0)
  double ratio_low = 0, ratio_high = 0;  // (1 - alpha) interval of the population ratio
  double p_value = 1;                    // one-sided, of H0: current <= limit (before Holm)
  std::string test;                      // the test used
  GateDecision decision = GateDecision::kInconclusive;
  std::string note;   // why it failed ("missing in the current result"), else empty
  double wall_s = 0;  // time spent on this metric's test [s]
};

struct GateOptions {
  double alpha = kDefaultAlpha;  // family-wise error rate over the gated metrics
  bool strict = false;           // inconclusive metrics fail the gate
  bool allow_different_job = false;
  // How messages name the two results (the CLI passes the file names).
  std::string baseline_name = "baseline";
  std::string current_name = "current";
};

// Fewest runs a gated file may hold.
inline constexpr uint32_t kMinGateRuns = 2;

struct GateReport {
  std::vector<GateRow> rows;  // in ListMetrics order of the baseline
  int regressions = 0;        // including metrics missing from the current result
  int inconclusive = 0;
  GateOptions options;
  bool paired = false;
  std::string mode;                         // "paired (...)" or "independent (...)", why
  std::string job_name;                     // the baseline's job name (JUnit suite name)
  std::string baseline_file, current_file;  // set by the caller, for the table and JUnit
  uint32_t baseline_runs = 0, current_runs = 0;
  std::vector<std::string> notes;  // e.g. different engine versions; informational
  // Planning: the smallest sigma ratio current / baseline that the worst-placed sigma metric
  // (Holm's first step, alpha / metrics) detects with 90 % power, at the default 10 % tolerance.
  double detectable_sigma_ratio = 0;
  int failures() const { return regressions + (options.strict ? inconclusive : 0); }
  bool passed() const { return failures() == 0; }
};

// Compares `current` against `baseline` under `rules`. Both results must hold at least
// kMinGateRuns runs (SpecError naming the file's run_count otherwise) and should have passed
// VerifyResultStatistics (result_check.h). A paired metric whose per-run values are identical in
// both files has ratio 1 exactly (interval [1, 1]): a file gated against itself passes. The mode
// is paired when both results have
// the same seed and run range and keep per-run values (then they share their random numbers),
// else independent. Throws SpecError when the two results are of different jobs (their job echoes
// differ in anything but monte_carlo.runs and monte_carlo.seed) and allow_different_job is false,
// naming the first differing field ("job.sensor.gyro.arw_deg_per_sqrt_h"); and when a rule matches
// no metric of the baseline ("rules[i].metric").
GateReport RunGate(const v1::JobResult& baseline, const v1::JobResult& current,
                   const std::vector<GateRule>& rules, const GateOptions& options);

// Planning help: the equal run count per file for which a sigma ratio of `true_ratio` (e.g. 1.1
// for +10 %) is a regression with 90 % power at tolerance `rel_tol`, with `metrics` gated metrics
// at family-wise `alpha` (the first Holm step, alpha / metrics, the worst case); 0 when none.
long RunsForSigmaChange(double true_ratio, double rel_tol, double alpha, int metrics);

// A plain-text table: metric, unit, baseline, current, ratio [interval], limit, decision, test;
// the mode, the planning line and a summary line.
std::string FormatGateTable(const GateReport& report);

// JUnit XML: one <testsuite> naming both files, one <testcase> per compared metric with its wall
// time, the test and the interval; a <failure> for each regression (and, with --strict, each
// inconclusive metric), <skipped> for none. All text escaped for XML 1.0.
std::string RenderJunitXml(const GateReport& report);

}  // namespace driftlab::app
