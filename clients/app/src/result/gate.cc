#include "driftlab/app/gate.h"

#include <fmt/format.h>
#include <google/protobuf/util/message_differencer.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "driftlab/app/gate_statistics.h"
#include "driftlab/app/result_file.h"
#include "driftlab/spec_error.h"
#include "result/gate_text.h"

namespace driftlab::app {
namespace {

// Shortest text that reads back to the same double (fmt's default for doubles).

// Appends a metric unless it is NaN (sigma of a one-run result: undefined, not gated).
void Add(Metric metric, std::vector<Metric>& out) {
  if (!std::isnan(metric.value)) out.push_back(std::move(metric));
}

std::string UnitOf(int c) { return ComponentUnit(static_cast<v1::ErrorComponent>(c + 1)); }

void AddEpochMetrics(const std::string& prefix, const v1::EpochStatistics& epoch, int e, int c,
                     std::vector<Metric>& out) {
  const v1::ComponentStatistics& s = epoch.components(c);
  const std::string unit = UnitOf(c);
  Add({prefix + "abs_mean", std::abs(s.mean()), MetricKind::kAbsMean, c, e, -1, 0, unit}, out);
  Add({prefix + "std", s.std(), MetricKind::kStd, c, e, -1, 0, unit}, out);
  Add({prefix + "rms", s.rms(), MetricKind::kRms, c, e, -1, 0, unit}, out);
}

void AddCheckpointMetrics(const std::string& prefix, const v1::Checkpoint& checkpoint, int k, int c,
                          std::vector<Metric>& out) {
  const v1::ComponentPercentiles& p = checkpoint.components(c);
  const std::string unit = UnitOf(c);
  Add({prefix + "p50", p.p50(), MetricKind::kQuantile, c, -1, k, 0.50, unit}, out);
  Add({prefix + "p68", p.p68(), MetricKind::kQuantile, c, -1, k, 0.68, unit}, out);
  Add({prefix + "p95", p.p95(), MetricKind::kQuantile, c, -1, k, 0.95, unit}, out);
  Add({prefix + "p99", p.p99(), MetricKind::kQuantile, c, -1, k, 0.99, unit}, out);
}

std::string Key(int c) { return ComponentKey(static_cast<v1::ErrorComponent>(c + 1)); }

// The job's identity for the gate: the echo without monte_carlo.runs and monte_carlo.seed (a
// different sample of the same job, which the tests account for).
v1::Job Identity(const v1::Job& job) {
  v1::Job identity = job;
  identity.mutable_monte_carlo()->clear_runs();
  identity.mutable_monte_carlo()->clear_seed();
  return identity;
}

// The first difference between two jobs: its field path ("sensor.gyro.arw_deg_per_sqrt_h") and
// the differencer's line ("modified: sensor.gyro...: 0.1 -> 0.13"), shortened for one line.
std::pair<std::string, std::string> FirstDifference(const v1::Job& baseline,
                                                    const v1::Job& current) {
  google::protobuf::util::MessageDifferencer differencer;
  std::string report;
  differencer.ReportDifferencesToString(&report);
  differencer.Compare(baseline, current);
  std::string line = report.substr(0, report.find('\n'));
  std::string path = line;
  const size_t space = path.find(": ");
  if (space != std::string::npos) path = path.substr(space + 2);
  path = path.substr(0, path.find(':'));
  if (line.size() > 200) {
    line.resize(197);
    line.append("...");
  }
  return {path, line};
}

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Values of component c of every run at checkpoint k: |error| for quantiles (signed components)
// or the signed error (moments). Empty when the file keeps no per-run values there.
std::vector<double> RunValues(const v1::JobResult& result, int k, int c, bool absolute) {
  std::vector<double> values;
  if (k < 0) return values;
  const v1::Checkpoint& checkpoint = result.checkpoints(k);
  values.reserve(checkpoint.runs_size());
  for (const v1::RunValues& run : checkpoint.runs()) {
    values.push_back(absolute ? std::abs(run.values(c)) : run.values(c));
  }
  return values;
}

// Index of the checkpoint at t_s, or -1.
int CheckpointAt(const v1::JobResult& result, double t_s) {
  for (int k = 0; k < result.checkpoints_size(); ++k) {
    if (result.checkpoints(k).t_s() == t_s) return k;
  }
  return -1;
}

// Paired when both files hold the same runs of the same seed with per-run values kept: then run
// r of both drew the same random numbers (DESIGN.md invariant 3) as long as the random streams
// did not change, and the paired tests stay valid (if weaker) even when they did.
bool SameRuns(const v1::JobResult& baseline, const v1::JobResult& current) {
  if (baseline.seed() != current.seed() || baseline.first_run() != current.first_run() ||
      baseline.run_count() != current.run_count() || baseline.run_count() < 3) {
    return false;
  }
  const v1::Checkpoint& b = *baseline.checkpoints().rbegin();
  const v1::Checkpoint& c = *current.checkpoints().rbegin();
  return b.runs_size() == static_cast<int>(baseline.run_count()) &&
         c.runs_size() == static_cast<int>(current.run_count());
}

// A paired metric whose per-run values are the same in both files: the current population value is
// the baseline's exactly (the runs share every random number and gave the same errors), so the
// ratio is 1 with no uncertainty. The t statistics of the paired tests are undefined there (all
// differences 0 at ratio 1, and a statistic of fixed size at any other ratio).
TestOutcome Identical(double limit_ratio) {
  TestOutcome out;
  out.ratio = out.ratio_low = out.ratio_high = 1.0;
  out.p_value = limit_ratio >= 1.0 ? 1.0 : 0.0;
  out.test = "paired: identical per-run values";
  return out;
}

// Runs the test of one metric present in both results.
TestOutcome TestMetric(const v1::JobResult& baseline, const Metric& mb,
                       const v1::JobResult& current, const Metric& mc, double limit_ratio,
                       bool paired, double alpha) {
  const double n_b = baseline.run_count(), n_c = current.run_count();
  if (mb.kind == MetricKind::kQuantile) {
    std::vector<double> xb = RunValues(baseline, mb.checkpoint, mb.component, true);
    std::vector<double> xc = RunValues(current, mc.checkpoint, mc.component, true);
    if (xb.empty() || xc.empty()) {
      TestOutcome none;
      none.ratio = mc.value / mb.value;
      none.ratio_low = 0;
      none.ratio_high = std::numeric_limits<double>::infinity();
      none.test = "none: per-run values not kept";
      return none;
    }
    if (paired && xb == xc) return Identical(limit_ratio);
    // The bootstrap costs B x n per metric; above kMaxBootstrapRuns the order-statistic bounds
    // (valid for paired samples too) are tight enough and far cheaper.
    if (paired && xb.size() == xc.size() && xb.size() >= 3 && xb.size() <= kMaxBootstrapRuns) {
      TestOutcome out = TestQuantilePaired(xb, xc, mb.quantile, limit_ratio, alpha);
      out.ratio = mc.value / mb.value;
      return out;
    }
    TestOutcome out = TestQuantile(std::move(xb), std::move(xc), mb.quantile, limit_ratio, alpha);
    out.ratio = mc.value / mb.value;  // the files' own percentiles
    return out;
  }
  if (mb.kind == MetricKind::kNees) {
    const double dof = baseline.filter_consistency().state_dimension();
    const double runs_b = baseline.filter_consistency().epochs(mb.epoch).runs();
    const double runs_c = current.filter_consistency().epochs(mc.epoch).runs();
    return TestNees(mb.value, dof * runs_b, mc.value, dof * runs_c, limit_ratio, alpha);
  }
  if (mb.kind != MetricKind::kRms && (n_b < 2 || n_c < 2)) {
    TestOutcome none;
    none.ratio = mc.value / mb.value;
    none.ratio_high = std::numeric_limits<double>::infinity();
    none.test = "none: one run has no sigma";
    return none;
  }
  // Moments: paired on the per-run values of the checkpoint at the epoch's time, when there is
  // one; else from the files' moments.
  if (paired) {
    const double t_s = baseline.epochs(mb.epoch).t_s();
    const std::vector<double> x =
        RunValues(baseline, CheckpointAt(baseline, t_s), mb.component, false);
    const std::vector<double> y =
        RunValues(current, CheckpointAt(current, t_s), mc.component, false);
    if (x.size() >= 3 && x.size() == y.size()) {
      if (x == y) return Identical(limit_ratio);
      switch (mb.kind) {
        case MetricKind::kStd:
          return TestSigmaPaired(x, y, limit_ratio, alpha);
        case MetricKind::kRms:
          return TestRmsPaired(x, y, limit_ratio, alpha);
        default:
          return TestAbsMeanPaired(x, y, limit_ratio, alpha);
      }
    }
  }
  const v1::ComponentStatistics& sb = baseline.epochs(mb.epoch).components(mb.component);
  const v1::ComponentStatistics& sc = current.epochs(mc.epoch).components(mc.component);
  switch (mb.kind) {
    case MetricKind::kStd:
      return TestSigmaIndependent(sb.std(), n_b, sc.std(), n_c, limit_ratio, alpha);
    case MetricKind::kRms:
      return TestRmsIndependent(sb.rms(), n_b, sc.rms(), n_c, limit_ratio, alpha);
    default:
      return TestAbsMeanWelch(sb.mean(), sb.std(), n_b, sc.mean(), sc.std(), n_c, limit_ratio,
                              alpha);
  }
}

}  // namespace

std::vector<Metric> ListMetrics(const v1::JobResult& result) {
  std::vector<Metric> metrics;
  const int final_e = result.epochs_size() - 1;
  const int final_k = result.checkpoints_size() - 1;
  for (int c = 0; c < kErrorComponentCount; ++c) {
    const std::string prefix = "final." + Key(c) + ".";
    AddEpochMetrics(prefix, result.epochs(final_e), final_e, c, metrics);
    AddCheckpointMetrics(prefix, result.checkpoints(final_k), final_k, c, metrics);
  }
  const v1::FilterConsistency& consistency = result.filter_consistency();
  if (consistency.epochs_size() == result.epochs_size() && consistency.state_dimension() > 0) {
    const v1::NeesEpoch& nees = consistency.epochs(final_e);
    if (nees.runs() > 0 && nees.has_average_nees()) {
      Add({"final.nees", nees.average_nees(), MetricKind::kNees, -1, final_e, -1, 0, ""}, metrics);
    }
  }
  for (int e = 0; e < result.epochs_size(); ++e) {
    const std::string selector = "epoch[t=" + MetricTimeText(result.epochs(e).t_s()) + "].";
    for (int c = 0; c < kErrorComponentCount; ++c) {
      AddEpochMetrics(selector + Key(c) + ".", result.epochs(e), e, c, metrics);
    }
  }
  for (int k = 0; k < result.checkpoints_size(); ++k) {
    const std::string selector =
        "checkpoint[t=" + MetricTimeText(result.checkpoints(k).t_s()) + "].";
    for (int c = 0; c < kErrorComponentCount; ++c) {
      AddCheckpointMetrics(selector + Key(c) + ".", result.checkpoints(k), k, c, metrics);
    }
  }
  return metrics;
}

const char* DecisionName(GateDecision decision) {
  switch (decision) {
    case GateDecision::kPass:
      return "pass";
    case GateDecision::kImproved:
      return "improved";
    case GateDecision::kRegression:
      return "regression";
    default:
      return "inconclusive";
  }
}

long RunsForSigmaChange(double true_ratio, double rel_tol, double alpha, int metrics) {
  return RunsToDetectSigmaRatio(true_ratio, 1.0 + rel_tol, alpha / std::max(metrics, 1), 0.9);
}

GateReport RunGate(const v1::JobResult& baseline, const v1::JobResult& current,
                   const std::vector<GateRule>& rules, const GateOptions& options) {
  if (!(options.alpha > 0 && options.alpha < 1)) {
    throw SpecError("--alpha", fmt::format("{}", options.alpha), "0 < alpha < 1");
  }
  // Every test needs each file's sample standard deviation (moments) or at least two order
  // statistics (quantiles): one run has neither.
  for (const auto& [result, name] :
       {std::pair<const v1::JobResult&, const std::string&>{baseline, options.baseline_name},
        {current, options.current_name}}) {
    if (result.run_count() < kMinGateRuns) {
      throw SpecError(name + ": run_count", std::to_string(result.run_count()),
                      fmt::format(">= {} runs per gated file (a gate tests each file's spread; "
                                  "one run has none)",
                                  kMinGateRuns));
    }
  }
  GateReport report;
  report.options = options;
  report.job_name = baseline.job().name();
  report.baseline_runs = baseline.run_count();
  report.current_runs = current.run_count();
  const v1::Job baseline_job = Identity(baseline.job()), current_job = Identity(current.job());
  if (!google::protobuf::util::MessageDifferencer::Equals(baseline_job, current_job)) {
    const auto [path, line] = FirstDifference(baseline_job, current_job);
    if (!options.allow_different_job) {
      throw SpecError("job." + path,
                      fmt::format("differs between the baseline and the current result ({}): "
                                  "they are different jobs (motion, sensor model, navigation or "
                                  "output settings), not comparable; seed and run count may "
                                  "differ; pass --allow-different-job to compare them anyway",
                                  line),
                      0);
    }
    report.notes.push_back("different jobs compared (--allow-different-job): " + line);
  }
  if (baseline.engine_version() != current.engine_version()) {
    report.notes.push_back(fmt::format("engine versions differ: baseline {}, current {}",
                                       baseline.engine_version(), current.engine_version()));
  }
  report.paired = SameRuns(baseline, current);
  report.mode =
      report.paired
          ? fmt::format(
                "paired: same seed {} and runs [{}, {}) in both files; "
                "tests on the per-run differences",
                baseline.seed(), baseline.first_run(), baseline.first_run() + baseline.run_count())
          : fmt::format(
                "independent: baseline seed {} with {} runs, current seed {} "
                "with {} runs; two-sample tests",
                baseline.seed(), baseline.run_count(), current.seed(), current.run_count());

  const std::vector<Metric> baseline_metrics = ListMetrics(baseline);
  std::vector<Metric> current_list = ListMetrics(current);
  std::unordered_map<std::string, const Metric*> current_metrics;
  for (const Metric& metric : current_list) current_metrics.emplace(metric.name, &metric);
  std::vector<bool> rule_used(rules.size(), false);
  std::vector<size_t> tested;  // rows with a p-value, for Holm
  for (const Metric& metric : baseline_metrics) {
    // The last matching rule decides.
    const GateRule* rule = nullptr;
    for (size_t r = rules.size(); r-- > 0;) {
      if (MetricMatches(rules[r].metric, metric.name)) {
        if (!rule) rule = &rules[r];
        rule_used[r] = true;
      }
    }
    if (!rule || rule->skip) continue;
    const auto start = std::chrono::steady_clock::now();
    GateRow row;
    row.metric = metric.name;
    row.unit = metric.unit;
    row.baseline = metric.value;
    // Errors: larger is worse, so only an increase beyond the tolerance is a regression.
    row.limit = metric.value + std::max(rule->abs_tol, rule->rel_tol * std::abs(metric.value));
    const auto found = current_metrics.find(metric.name);
    if (found == current_metrics.end()) {
      row.current = std::numeric_limits<double>::quiet_NaN();
      row.ratio = row.ratio_low = row.ratio_high = row.current;
      row.decision = GateDecision::kRegression;
      row.test = "none";
      row.note = "missing in the current result";
    } else if (!(metric.value > 0)) {
      // A zero baseline (an error-free component) has no ratio: the value itself is compared.
      row.current = found->second->value;
      row.ratio = row.ratio_low = row.ratio_high = std::numeric_limits<double>::quiet_NaN();
      row.test = "exact (baseline 0)";
      row.p_value = row.current > row.limit ? 0.0 : 1.0;
      tested.push_back(report.rows.size());
    } else {
      row.current = found->second->value;
      const double limit_ratio = row.limit / metric.value;
      const TestOutcome outcome = TestMetric(baseline, metric, current, *found->second, limit_ratio,
                                             report.paired, options.alpha);
      row.ratio = outcome.ratio;
      row.ratio_low = outcome.ratio_low;
      row.ratio_high = outcome.ratio_high;
      row.p_value = outcome.p_value;
      row.test = outcome.test;
      tested.push_back(report.rows.size());
    }
    row.wall_s = Seconds(start);
    report.rows.push_back(std::move(row));
  }
  for (size_t r = 0; r < rules.size(); ++r) {
    if (!rule_used[r]) {
      throw SpecError(fmt::format("rules[{}].metric", r), "\"" + rules[r].metric + "\"",
                      "a name or glob matching at least one metric of the baseline (list them "
                      "with `driftlab gate BASELINE --list-metrics`; cep50, cep95, drms2, "
                      "max_abs and the *_ci95_* bounds are no metrics: use p50, p95, rms)");
    }
  }

  // Holm over every tested metric; then the interval decides between pass, improved and
  // inconclusive.
  std::vector<double> p_values;
  for (const size_t i : tested) p_values.push_back(report.rows[i].p_value);
  const std::vector<bool> rejected = HolmReject(p_values, options.alpha);
  for (size_t t = 0; t < tested.size(); ++t) {
    GateRow& row = report.rows[tested[t]];
    const double limit_ratio = row.limit / row.baseline;
    if (rejected[t]) {
      row.decision = GateDecision::kRegression;
      row.note = fmt::format("current {} > limit {} (baseline {}), p = {:.2g} ({})",
                             GateNumberText(row.current), GateNumberText(row.limit),
                             GateNumberText(row.baseline), row.p_value, row.test);
    } else if (std::isnan(row.ratio)) {
      row.decision = GateDecision::kPass;  // exact comparison within the limit
    } else if (row.ratio_high < 1.0) {
      row.decision = GateDecision::kImproved;
    } else if (row.ratio_high <= limit_ratio) {
      row.decision = GateDecision::kPass;
    } else {
      row.decision = GateDecision::kInconclusive;
      row.note = fmt::format("interval of current/baseline [{}, {}] straddles the limit {}",
                             GateNumberText(row.ratio_low), GateNumberText(row.ratio_high),
                             GateNumberText(limit_ratio));
    }
  }
  for (const GateRow& row : report.rows) {
    report.regressions += row.decision == GateDecision::kRegression ? 1 : 0;
    report.inconclusive += row.decision == GateDecision::kInconclusive ? 1 : 0;
  }
  const double m = static_cast<double>(std::max<size_t>(tested.size(), 1));
  if (baseline.run_count() >= 2 && current.run_count() >= 2) {
    report.detectable_sigma_ratio = DetectableSigmaRatio(
        baseline.run_count(), current.run_count(), 1.0 + kDefaultRelTol, options.alpha / m, 0.9);
  }
  return report;
}

}  // namespace driftlab::app
