// Gate rules: rules files (YAML or JSON) and metric-name globs (gate.h).
#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "driftlab/app/gate.h"
#include "driftlab/input_files.h"
#include "driftlab/spec_error.h"
#include "result/gate_text.h"

namespace driftlab::app {
namespace {

// Shortest text that reads back to the same double (fmt's default for doubles), as ListMetrics
// prints times.

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
    out += plain ? MetricTimeText(t_s) : number;
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

}  // namespace

std::vector<GateRule> DefaultGateRules() {
  return {{"final.*", 0, kDefaultRelTol, false},
          {"final.*.p95", 0, kDefaultRelTolP95, false},
          {"final.*.p99", 0, kDefaultRelTolP99, true},
          {"final.*.abs_mean", 0, 0, true}};
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

}  // namespace driftlab::app
