#include "driftlab/jobspec/gate.h"

#include <fmt/format.h>
#include <google/protobuf/util/message_differencer.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <unordered_map>

#include "driftlab/input_files.h"
#include "driftlab/jobspec/result_file.h"
#include "driftlab/spec_error.h"

namespace driftlab::jobspec {
namespace {

// Shortest text that reads back to the same double (fmt's default for doubles).
std::string TimeText(double t_s) { return fmt::format("{}", t_s); }

// Appends a metric unless it is NaN (sigma of a one-run result: undefined, not gated).
void Add(std::string name, double value, std::vector<Metric>& out) {
  if (!std::isnan(value)) out.push_back({std::move(name), value});
}

void AddEpochMetrics(const std::string& prefix, const v1::ComponentStatistics& s,
                     std::vector<Metric>& out) {
  Add(prefix + "abs_mean", std::abs(s.mean()), out);
  Add(prefix + "std", s.std(), out);
  Add(prefix + "rms", s.rms(), out);
  Add(prefix + "std_ci95_low", s.std_ci95_low(), out);
  Add(prefix + "std_ci95_high", s.std_ci95_high(), out);
  Add(prefix + "rms_ci95_low", s.rms_ci95_low(), out);
  Add(prefix + "rms_ci95_high", s.rms_ci95_high(), out);
}

void AddCheckpointMetrics(const std::string& prefix, const v1::Checkpoint& checkpoint, int c,
                          std::vector<Metric>& out) {
  const v1::ComponentPercentiles& p = checkpoint.components(c);
  Add(prefix + "p50", p.p50(), out);
  Add(prefix + "p68", p.p68(), out);
  Add(prefix + "p95", p.p95(), out);
  Add(prefix + "p99", p.p99(), out);
  Add(prefix + "max_abs", p.max_abs(), out);
  if (c + 1 == v1::HORIZONTAL_POSITION_M) {
    Add(prefix + "cep50", checkpoint.cep50_m(), out);
    Add(prefix + "cep95", checkpoint.cep95_m(), out);
    Add(prefix + "drms2", checkpoint.drms2_m(), out);
  }
}

std::string Key(int c) { return ComponentKey(static_cast<v1::ErrorComponent>(c + 1)); }

// Rewrites every "[t=NUMBER]" of a pattern without wildcards inside the brackets to the form
// ListMetrics prints, so that "epoch[t=600.0]" names "epoch[t=600]".
std::string NormalizePattern(const std::string& pattern) {
  std::string out;
  size_t i = 0;
  while (i < pattern.size()) {
    const size_t open = pattern.find("[t=", i);
    if (open == std::string::npos) break;
    const size_t close = pattern.find(']', open);
    if (close == std::string::npos) break;
    const std::string number = pattern.substr(open + 3, close - open - 3);
    out += pattern.substr(i, open + 3 - i);
    char* end = nullptr;
    const double t_s = std::strtod(number.c_str(), &end);
    const bool plain = !number.empty() && number.find_first_of("*?") == std::string::npos &&
                       end == number.c_str() + number.size() && std::isfinite(t_s);
    out += plain ? TimeText(t_s) : number;
    out += ']';
    i = close + 1;
  }
  out += pattern.substr(std::min(i, pattern.size()));
  return out;
}

std::string ScalarText(const YAML::Node& node) {
  if (node.IsScalar()) return "\"" + node.Scalar() + "\"";
  if (node.IsSequence()) return "a list";
  if (node.IsMap()) return "a mapping";
  return "null";
}

// Rejects keys of `node` (a mapping) outside `allowed`; `path` prefixes the field names.
void CheckKeys(const YAML::Node& node, const std::string& path,
               const std::vector<std::string>& allowed) {
  for (const auto& entry : node) {
    const std::string key = entry.first.Scalar();
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
      throw SpecError(path + key,
                      fmt::format("unknown field; allowed: {}", fmt::join(allowed, ", ")), 0);
    }
  }
}

// A tolerance: a finite number in [0, max].
double ReadTolerance(const YAML::Node& node, const std::string& field, const std::string& name,
                     double max) {
  const std::string allowed = fmt::format("0 <= {} <= {}", name, max);
  double value = 0;
  try {
    value = node.as<double>();
  } catch (const YAML::Exception&) {
    throw SpecError(field, ScalarText(node), "a number, " + allowed);
  }
  if (!(value >= 0 && value <= max)) throw SpecError(field, fmt::format("{}", value), allowed);
  return value;
}

constexpr double kMaxAbsTol = 1e12;  // larger than any error of a navigation solution
constexpr double kMaxRelTol = 100;

struct Tolerances {
  double abs_tol = 0;
  double rel_tol = kDefaultRelTol;
};

void ReadTolerances(const YAML::Node& node, const std::string& path, Tolerances& tolerances) {
  if (node["abs_tol"]) {
    tolerances.abs_tol = ReadTolerance(node["abs_tol"], path + "abs_tol", "abs_tol", kMaxAbsTol);
  }
  if (node["rel_tol"]) {
    tolerances.rel_tol = ReadTolerance(node["rel_tol"], path + "rel_tol", "rel_tol", kMaxRelTol);
  }
}

std::string EscapeXml(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char ch : text) {
    switch (ch) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      case '\t':
      case '\n':
      case '\r':
        out += ch;
        break;
      default:
        // Control characters other than tab and line breaks are not allowed in XML 1.0.
        out += static_cast<unsigned char>(ch) < 0x20 ? '?' : ch;
    }
  }
  return out;
}

std::string Number(double value) { return fmt::format("{:.6g}", value); }

// First line of the differences between two jobs, shortened for a one-line error.
std::string FirstDifference(const v1::Job& baseline, const v1::Job& current) {
  google::protobuf::util::MessageDifferencer differencer;
  std::string report;
  differencer.ReportDifferencesToString(&report);
  differencer.Compare(baseline, current);
  std::string line = report.substr(0, report.find('\n'));
  if (line.size() > 160) line = line.substr(0, 157) + "...";
  return line;
}

}  // namespace

std::vector<Metric> ListMetrics(const v1::JobResult& result) {
  std::vector<Metric> metrics;
  const v1::EpochStatistics& final_epoch = *result.epochs().rbegin();
  const v1::Checkpoint& final_checkpoint = *result.checkpoints().rbegin();
  for (int c = 0; c < kErrorComponentCount; ++c) {
    const std::string prefix = "final." + Key(c) + ".";
    AddEpochMetrics(prefix, final_epoch.components(c), metrics);
    AddCheckpointMetrics(prefix, final_checkpoint, c, metrics);
  }
  for (const v1::EpochStatistics& epoch : result.epochs()) {
    const std::string selector = "epoch[t=" + TimeText(epoch.t_s()) + "].";
    for (int c = 0; c < kErrorComponentCount; ++c) {
      AddEpochMetrics(selector + Key(c) + ".", epoch.components(c), metrics);
    }
  }
  for (const v1::Checkpoint& checkpoint : result.checkpoints()) {
    const std::string selector = "checkpoint[t=" + TimeText(checkpoint.t_s()) + "].";
    for (int c = 0; c < kErrorComponentCount; ++c) {
      AddCheckpointMetrics(selector + Key(c) + ".", checkpoint, c, metrics);
    }
  }
  return metrics;
}

std::vector<GateRule> DefaultGateRules() {
  return {{"final.*", 0, kDefaultRelTol, false},
          {"final.*.p95", 0, kDefaultRelTolP95, false},
          {"final.*.cep95", 0, kDefaultRelTolP95, false},
          {"final.*.p99", 0, kDefaultRelTolP99, false},
          {"final.*.max_abs", 0, kDefaultRelTolMax, false},
          {"final.*.abs_mean", 0, 0, true},
          {"final.*.*_ci95_*", 0, 0, true}};
}

bool MetricMatches(std::string_view pattern, std::string_view name) {
  // Iterative glob match with backtracking to the last '*' (linear in practice).
  size_t p = 0, n = 0, star = std::string_view::npos, resume = 0;
  while (n < name.size()) {
    if (p < pattern.size() && (pattern[p] == '?' || pattern[p] == name[n])) {
      ++p;
      ++n;
    } else if (p < pattern.size() && pattern[p] == '*') {
      star = p++;
      resume = n;
    } else if (star != std::string_view::npos) {
      p = star + 1;
      n = ++resume;
    } else {
      return false;
    }
  }
  while (p < pattern.size() && pattern[p] == '*') ++p;
  return p == pattern.size();
}

std::vector<GateRule> ParseGateRules(std::string_view text, std::string_view source) {
  YAML::Node root;
  try {
    root = YAML::Load(std::string(text));
  } catch (const YAML::Exception& e) {
    throw SpecError(std::string(source),
                    fmt::format("invalid YAML/JSON at line {}: {}", e.mark.line + 1, e.msg), 0);
  }
  if (!root.IsMap()) {
    throw SpecError(std::string(source), ScalarText(root),
                    "a mapping with `rules` (and optional `defaults`)");
  }
  CheckKeys(root, "", {"defaults", "rules"});
  Tolerances defaults;
  if (root["defaults"]) {
    if (!root["defaults"].IsMap()) {
      throw SpecError("defaults", ScalarText(root["defaults"]), "a mapping {abs_tol, rel_tol}");
    }
    CheckKeys(root["defaults"], "defaults.", {"abs_tol", "rel_tol"});
    ReadTolerances(root["defaults"], "defaults.", defaults);
  }
  const YAML::Node list = root["rules"];
  if (!list || !list.IsSequence() || list.size() == 0) {
    throw SpecError("rules",
                    !list               ? ""
                    : list.IsSequence() ? "an empty list"
                                        : ScalarText(list),
                    "a non-empty list of {metric, abs_tol, rel_tol, skip}");
  }
  std::vector<GateRule> rules;
  for (size_t i = 0; i < list.size(); ++i) {
    const YAML::Node& item = list[i];
    const std::string path = fmt::format("rules[{}].", i);
    if (!item.IsMap()) {
      throw SpecError(fmt::format("rules[{}]", i), ScalarText(item),
                      "a mapping {metric, abs_tol, rel_tol, skip}");
    }
    CheckKeys(item, path, {"metric", "abs_tol", "rel_tol", "skip"});
    const YAML::Node metric = item["metric"];
    if (!metric || !metric.IsScalar() || metric.Scalar().empty()) {
      throw SpecError(path + "metric", metric ? ScalarText(metric) : "",
                      "a metric name or glob, e.g. \"final.*.cep95\"");
    }
    Tolerances tolerances = defaults;
    ReadTolerances(item, path, tolerances);
    bool skip = false;
    if (item["skip"]) {
      try {
        skip = item["skip"].as<bool>();
      } catch (const YAML::Exception&) {
        throw SpecError(path + "skip", ScalarText(item["skip"]), "true or false");
      }
    }
    rules.push_back(
        {NormalizePattern(metric.Scalar()), tolerances.abs_tol, tolerances.rel_tol, skip});
  }
  return rules;
}

std::vector<GateRule> LoadGateRules(const std::filesystem::path& path) {
  const std::string name = path.string();
  const std::string text = ReadInputFile(path, kMaxSmallTextFileBytes, name);
  try {
    return ParseGateRules(text, name);
  } catch (const SpecError& e) {
    if (e.field() == name) throw;
    throw SpecError(name, e.what(), 0);
  }
}

GateReport RunGate(const v1::JobResult& baseline, const v1::JobResult& current,
                   const std::vector<GateRule>& rules, bool allow_different_job) {
  GateReport report;
  report.job_name = baseline.job().name();
  if (!google::protobuf::util::MessageDifferencer::Equals(baseline.job(), current.job())) {
    const std::string difference = FirstDifference(baseline.job(), current.job());
    if (!allow_different_job) {
      throw SpecError("job",
                      fmt::format("the current result is of a different job than the baseline "
                                  "({}); results of different jobs are not comparable; pass "
                                  "--allow-different-job to compare them anyway",
                                  difference),
                      0);
    }
    report.notes.push_back("different jobs compared (--allow-different-job): " + difference);
  }
  if (baseline.engine_version() != current.engine_version()) {
    report.notes.push_back(fmt::format("engine versions differ: baseline {}, current {}",
                                       baseline.engine_version(), current.engine_version()));
  }
  if (baseline.seed() != current.seed() || baseline.run_count() != current.run_count()) {
    report.notes.push_back(fmt::format(
        "different samples: baseline seed {} with {} runs, current seed {} with {} runs",
        baseline.seed(), baseline.run_count(), current.seed(), current.run_count()));
  }

  const std::vector<Metric> baseline_metrics = ListMetrics(baseline);
  std::unordered_map<std::string, double> current_values;
  for (Metric& metric : ListMetrics(current)) {
    current_values.emplace(std::move(metric.name), metric.value);
  }
  std::vector<bool> rule_used(rules.size(), false);
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
    GateRow row;
    row.metric = metric.name;
    row.baseline = metric.value;
    // Errors: larger is worse, so only an increase beyond the tolerance is a regression.
    row.limit = metric.value + std::max(rule->abs_tol, rule->rel_tol * std::abs(metric.value));
    const auto found = current_values.find(metric.name);
    if (found == current_values.end()) {
      row.current = std::numeric_limits<double>::quiet_NaN();
      row.note = "missing in the current result";
    } else {
      row.current = found->second;
      row.pass = row.current <= row.limit;
      if (!row.pass) {
        row.note = fmt::format("current {} > limit {} (baseline {})", Number(row.current),
                               Number(row.limit), Number(row.baseline));
      }
    }
    report.failures += row.pass ? 0 : 1;
    report.rows.push_back(std::move(row));
  }
  for (size_t r = 0; r < rules.size(); ++r) {
    if (!rule_used[r]) {
      throw SpecError(fmt::format("rules[{}].metric", r), "\"" + rules[r].metric + "\"",
                      "a name or glob matching at least one metric of the baseline (list them "
                      "with `driftlab gate BASELINE --list-metrics`)");
    }
  }
  return report;
}

std::string FormatGateTable(const GateReport& report) {
  size_t width = std::string_view("metric").size();
  for (const GateRow& row : report.rows) width = std::max(width, row.metric.size());
  std::string out;
  for (const std::string& note : report.notes) out += "note: " + note + "\n";
  out += fmt::format("{:<{}}  {:>12}  {:>12}  {:>12}  {}\n", "metric", width, "baseline", "current",
                     "limit", "result");
  std::vector<std::string> failed;
  for (const GateRow& row : report.rows) {
    out +=
        fmt::format("{:<{}}  {:>12}  {:>12}  {:>12}  {}\n", row.metric, width, Number(row.baseline),
                    Number(row.current), Number(row.limit), row.pass ? "PASS" : "FAIL");
    if (!row.pass) failed.push_back(row.metric);
  }
  if (report.passed()) {
    out += fmt::format("gate: PASS, {} metrics compared, no regression\n", report.rows.size());
  } else {
    out += fmt::format("gate: FAIL, {} of {} metrics regressed: {}\n", report.failures,
                       report.rows.size(), fmt::join(failed, ", "));
  }
  return out;
}

std::string RenderJunitXml(const GateReport& report) {
  std::string out = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  out += fmt::format(
      "<testsuite name=\"{}\" tests=\"{}\" failures=\"{}\" errors=\"0\" skipped=\"0\" "
      "time=\"0\">\n",
      EscapeXml("driftlab gate: " + report.job_name), report.rows.size(), report.failures);
  for (const GateRow& row : report.rows) {
    const std::string detail =
        fmt::format("baseline {}, current {}, limit {}", Number(row.baseline), Number(row.current),
                    Number(row.limit));
    out += fmt::format("  <testcase classname=\"driftlab.gate\" name=\"{}\" time=\"0\"",
                       EscapeXml(row.metric));
    if (row.pass) {
      out += fmt::format(">\n    <system-out>{}</system-out>\n  </testcase>\n", EscapeXml(detail));
    } else {
      out += fmt::format(
          ">\n    <failure message=\"{}\" type=\"regression\">{}</failure>\n  </testcase>\n",
          EscapeXml(row.metric + ": " + row.note), EscapeXml(detail));
    }
  }
  out += "</testsuite>\n";
  return out;
}

}  // namespace driftlab::jobspec
