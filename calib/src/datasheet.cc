// Datasheet summary -> ImuErrorModel (datasheet.h documents the file format and the keys).
#include "driftlab/calib/datasheet.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>

#include "driftlab/sensors.h"
#include "driftlab/spec_error.h"

namespace driftlab::calib {
namespace {

// Angular rate per acceleration (gyro g-sensitivity): rad s^-1 / (m s^-2) = rad m^-1 s.
constexpr Dimension kRatePerAcceleration{2, -2, 2};

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) {
    s.remove_suffix(1);
  }
  return s;
}

std::string Where(std::string_view source, int line) {
  return std::string(source) + ":" + std::to_string(line);
}

// Removes a '#' comment that is not inside quotes (YAML: '#' starts a comment at the line start or
// after whitespace).
std::string_view StripComment(std::string_view line) {
  char quote = 0;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quote != 0) {
      if (c == '\\' && quote == '"') {
        ++i;
      } else if (c == quote) {
        quote = 0;
      }
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '#' && (i == 0 || line[i - 1] == ' ' || line[i - 1] == '\t')) {
      return line.substr(0, i);
    }
  }
  return line;
}

// A scalar: "double quoted" (escapes \" \\), 'single quoted' ('' = '), or plain.
std::string Scalar(std::string_view s, const std::string& where) {
  s = Trim(s);
  if (s.empty()) return "";
  if (s.front() == '"' || s.front() == '\'') {
    const char q = s.front();
    std::string out;
    size_t i = 1;
    for (; i < s.size(); ++i) {
      if (q == '"' && s[i] == '\\' && i + 1 < s.size()) {
        out += s[++i];
      } else if (q == '\'' && s[i] == '\'' && i + 1 < s.size() && s[i + 1] == '\'') {
        out += '\'';
        ++i;
      } else if (s[i] == q) {
        break;
      } else {
        out += s[i];
      }
    }
    if (i >= s.size() || !Trim(s.substr(i + 1)).empty()) {
      throw SpecError(where, "'" + std::string(s) + "'",
                      "a scalar in matching quotes with nothing after the closing quote");
    }
    return out;
  }
  return std::string(s);
}

// Splits "key: value" at the first ':' followed by a space or the end (outside quotes).
bool SplitKey(std::string_view line, std::string_view* key, std::string_view* value) {
  char quote = 0;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quote != 0) {
      if (c == quote) quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == ':' && (i + 1 == line.size() || line[i + 1] == ' ' || line[i + 1] == '\t')) {
      *key = Trim(line.substr(0, i));
      *value = Trim(line.substr(i + 1));
      return !key->empty();
    }
  }
  return false;
}

// Entries of a one-line flow mapping "{a: x, b: "y, z"}".
void ParseFlowMapping(std::string_view text, const std::string& section, int line,
                      std::string_view source, std::vector<DatasheetEntry>* out) {
  const std::string where = Where(source, line);
  if (text.size() < 2 || text.back() != '}') {
    throw SpecError(where, "'" + std::string(text) + "'",
                    "a flow mapping {key: value, ...} on one line");
  }
  std::string_view body = text.substr(1, text.size() - 2);
  char quote = 0;
  size_t start = 0;
  for (size_t i = 0; i <= body.size(); ++i) {
    const char c = i < body.size() ? body[i] : ',';
    if (quote != 0) {
      if (c == quote) quote = 0;
      continue;
    }
    if (c == '"' || c == '\'') {
      quote = c;
      continue;
    }
    if (c != ',') continue;
    const std::string_view item = Trim(body.substr(start, i - start));
    start = i + 1;
    if (item.empty()) continue;
    std::string_view key, value;
    if (!SplitKey(item, &key, &value)) {
      throw SpecError(where, "'" + std::string(item) + "'", "key: value");
    }
    out->push_back({section + "." + Scalar(key, where), Scalar(value, where), line});
  }
  if (quote != 0) throw SpecError(where, "'" + std::string(text) + "'", "closed quotes");
}

// What one key means.
struct KeyRule {
  std::string_view key;
  Dimension dimension;
  std::string_view field;  // model field (without the triad prefix)
  std::function<void(TriadErrorParams*, double)> set;
};

std::vector<KeyRule> Rules(bool gyro) {
  using P = TriadErrorParams;
  const Dimension rate = gyro ? dims::kAngularRate : dims::kAcceleration;
  const Dimension white = gyro ? dims::kAngleRandomWalk : dims::kVelocityRandomWalk;
  const Dimension walk = gyro ? dims::kRateRandomWalk : dims::kAccelRandomWalk;
  const Dimension quantum = gyro ? dims::kAngle : dims::kVelocity;
  auto white_set = [](P* p, double v) { p->white_noise_density = v; };
  std::vector<KeyRule> rules = {
      {gyro ? "arw" : "vrw", white, "white_noise_density", white_set},
      {gyro ? "rate_noise_density" : "noise_density", white, "white_noise_density", white_set},
      {"bias_instability", rate, "bias_flicker.bias_instability",
       [](P* p, double v) { p->bias_flicker.bias_instability = v; }},
      {"bias_instability_tau_min", dims::kTime, "bias_flicker.tau_min_s",
       [](P* p, double v) { p->bias_flicker.tau_min_s = v; }},
      {"bias_instability_tau_max", dims::kTime, "bias_flicker.tau_max_s",
       [](P* p, double v) { p->bias_flicker.tau_max_s = v; }},
      {"gauss_markov_sigma", rate, "bias_gauss_markov.sigma",
       [](P* p, double v) { p->bias_gauss_markov.sigma = v; }},
      {"gauss_markov_tau", dims::kTime, "bias_gauss_markov.tau_s",
       [](P* p, double v) { p->bias_gauss_markov.tau_s = v; }},
      {gyro ? "rate_random_walk" : "acceleration_random_walk", walk, "random_walk",
       [](P* p, double v) { p->random_walk = v; }},
      {"turn_on_bias", rate, "turn_on_bias_sigma",
       [](P* p, double v) { p->turn_on_bias_sigma = v; }},
      {"scale_factor", dims::kDimensionless, "scale_factor_sigma",
       [](P* p, double v) { p->scale_factor_sigma = v; }},
      {"misalignment", dims::kAngle, "misalignment_sigma_rad",
       [](P* p, double v) { p->misalignment_sigma_rad = v; }},
      {"quantization", quantum, "quantization", [](P* p, double v) { p->quantization = v; }},
      {"range", rate, "range", [](P* p, double v) { p->range = v; }},
  };
  if (gyro) rules.push_back({"g_sensitivity", kRatePerAcceleration, "gyro_g_sensitivity", nullptr});
  return rules;
}

std::string AllowedKeys(bool gyro) {
  std::string out;
  for (const KeyRule& r : Rules(gyro)) out += (out.empty() ? "" : ", ") + std::string(r.key);
  return out;
}

std::string AllowedUnitsFor(Dimension d) {
  if (d == kRatePerAcceleration) return "(deg/h)/g, (deg/s)/g, (rad/s)/(m/s^2)";
  return AllowedUnits(d);
}

}  // namespace

std::string SiUnitText(Dimension d) {
  if (d == dims::kDimensionless) return "1";
  if (d == dims::kAngle) return "rad";
  if (d == dims::kAngularRate) return "rad/s";
  if (d == dims::kAngleRandomWalk) return "rad/sqrt(s)";
  if (d == dims::kRateRandomWalk) return "rad/s/sqrt(s)";
  if (d == dims::kVelocity) return "m/s";
  if (d == dims::kAcceleration) return "m/s^2";
  if (d == dims::kVelocityRandomWalk) return "m/s/sqrt(s)";
  if (d == dims::kAccelRandomWalk) return "m/s^2/sqrt(s)";
  if (d == dims::kTime) return "s";
  if (d == kRatePerAcceleration) return "(rad/s)/(m/s^2)";
  return DimensionName(d);
}

std::vector<DatasheetEntry> ParseDatasheetText(std::string_view text, std::string_view source) {
  std::vector<DatasheetEntry> entries;
  std::set<std::string> seen;
  std::string section;  // "gyro" / "accel" while inside a block mapping
  int line_no = 0;
  size_t pos = 0;
  if (text.starts_with("\xEF\xBB\xBF")) pos = 3;  // UTF-8 byte-order mark
  auto add = [&](DatasheetEntry e) {
    if (!seen.insert(e.key).second) {
      throw SpecError(Where(source, e.line) + ": " + e.key, "a second value", "each key once");
    }
    entries.push_back(std::move(e));
  };
  while (pos <= text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view raw = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_no;
    const std::string_view content = StripComment(raw);
    if (Trim(content).empty() || Trim(content) == "---") continue;
    const std::string where = Where(source, line_no);
    if (content.find('\t') != std::string_view::npos &&
        content.find_first_not_of(" \t") > content.find('\t')) {
      throw SpecError(where, "a tab in the indentation", "spaces (YAML)");
    }
    const bool indented = content.front() == ' ';
    std::string_view key, value;
    if (!SplitKey(Trim(content), &key, &value)) {
      throw SpecError(where, "'" + std::string(Trim(raw)) + "'", "key: value (YAML mapping)");
    }
    const std::string k = Scalar(key, where);
    if (indented) {
      if (section.empty()) {
        throw SpecError(where, "'" + std::string(Trim(raw)) + "' (indented)",
                        "indented keys only under gyro: or accel:");
      }
      add({section + "." + k, Scalar(value, where), line_no});
      continue;
    }
    section.clear();
    if (k == "name" || k == "description") {
      add({k, Scalar(value, where), line_no});
    } else if (k == "gyro" || k == "accel") {
      if (!seen.insert(k).second)
        throw SpecError(where + ": " + k, "a second section", "each once");
      if (value.empty()) {
        section = k;
      } else if (value.front() == '{') {
        ParseFlowMapping(value, k, line_no, source, &entries);
      } else {
        throw SpecError(where + ": " + k, "'" + std::string(value) + "'",
                        "a mapping (indented lines below, or {key: value, ...})");
      }
    } else {
      throw SpecError(where + ": " + k, "unknown key", "name, description, gyro, accel");
    }
  }
  return entries;
}

DatasheetModel DatasheetToModel(const std::vector<DatasheetEntry>& entries) {
  DatasheetModel out;
  ImuErrorModel& model = out.model;
  model.name = "datasheet";
  std::set<std::string> fields_set;
  for (const DatasheetEntry& e : entries) {
    if (e.key == "name") {
      model.name = e.text;
      continue;
    }
    if (e.key == "description") {
      model.description = e.text;
      continue;
    }
    const size_t dot = e.key.find('.');
    const std::string triad = e.key.substr(0, dot);
    const std::string key = e.key.substr(dot + 1);
    const bool gyro = triad == "gyro";
    const std::vector<KeyRule> rules = Rules(gyro);
    const auto rule =
        std::find_if(rules.begin(), rules.end(), [&key](const KeyRule& r) { return r.key == key; });
    if (rule == rules.end()) {
      throw SpecError(e.key, "unknown key (line " + std::to_string(e.line) + ")",
                      "one of: " + AllowedKeys(gyro));
    }
    const std::string field =
        rule->set ? triad + "." + std::string(rule->field) : std::string(rule->field);
    if (!fields_set.insert(field).second) {
      throw SpecError(e.key, "'" + e.text + "'",
                      "one value for " + field +
                          " (arw/rate_noise_density and vrw/noise_density "
                          "are alternatives)");
    }
    // Datasheets print symmetric figures as "±450 deg/s": the magnitude is what is meant.
    std::string_view text = Trim(e.text);
    for (std::string_view sign : {"±", "+/-", "+-"}) {
      if (text.starts_with(sign)) {
        text.remove_prefix(sign.size());
        break;
      }
    }
    double value_si = 0.0;
    if (rule->dimension == kRatePerAcceleration) {
      // ParseQuantity knows the named dimensions only; the unit is checked here.
      const size_t split = text.find_first_not_of("0123456789.eE+- ");
      const std::string_view number = Trim(text.substr(0, split));
      const std::string_view unit_text = split == std::string_view::npos ? "" : text.substr(split);
      Unit unit;
      try {
        unit = ParseUnit(unit_text, e.key);
      } catch (const SpecError&) {
        throw SpecError(e.key, "'" + e.text + "'",
                        "a number and a unit of angular rate per acceleration: " +
                            AllowedUnitsFor(kRatePerAcceleration));
      }
      char* end = nullptr;
      const std::string number_text(number);
      const double v = std::strtod(number_text.c_str(), &end);
      if (number_text.empty() || end != number_text.c_str() + number_text.size() ||
          !(unit.dimension == kRatePerAcceleration)) {
        throw SpecError(e.key, "'" + e.text + "'",
                        "a number and a unit of angular rate per acceleration: " +
                            AllowedUnitsFor(kRatePerAcceleration));
      }
      value_si = v * unit.si_factor;
    } else {
      value_si = ParseQuantity(text, rule->dimension, e.key).value_si;
    }
    if (!(value_si >= 0.0) || !std::isfinite(value_si)) {
      throw SpecError(e.key, "'" + e.text + "'",
                      "a finite magnitude >= 0 in " + AllowedUnitsFor(rule->dimension));
    }
    TriadErrorParams& params = gyro ? model.gyro : model.accel;
    if (rule->set) {
      rule->set(&params, value_si);
    } else {
      model.gyro_g_sensitivity = Eigen::Matrix3d::Identity() * value_si;
    }
    out.values.push_back({e.key, e.text, value_si, SiUnitText(rule->dimension), field});
  }
  // The model-level checks (tau of a Gauss-Markov term that is on, flicker band order, ...).
  for (const char* triad : {"gyro", "accel"}) {
    const TriadErrorParams& p = std::string(triad) == "gyro" ? model.gyro : model.accel;
    if (p.bias_gauss_markov.sigma > 0.0 && !(p.bias_gauss_markov.tau_s > 0.0)) {
      throw SpecError(std::string(triad) + ".gauss_markov_tau", "missing",
                      "a correlation time > 0 (s, min, h) when gauss_markov_sigma is given");
    }
    if (p.bias_flicker.bias_instability > 0.0 &&
        !(p.bias_flicker.tau_min_s > 0.0 && p.bias_flicker.tau_min_s < p.bias_flicker.tau_max_s)) {
      throw SpecError(std::string(triad) + ".bias_instability_tau_min",
                      std::to_string(p.bias_flicker.tau_min_s) + " s",
                      "0 < bias_instability_tau_min < bias_instability_tau_max (" +
                          std::to_string(p.bias_flicker.tau_max_s) + " s)");
    }
  }
  if (model.description.empty()) model.description = "from a datasheet summary";
  ValidateImuErrorModel(model, "sensor");
  return out;
}

DatasheetModel LoadDatasheet(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SpecError("DATASHEET", path.string(), "an existing, readable YAML file");
  std::ostringstream text;
  text << in.rdbuf();
  return DatasheetToModel(ParseDatasheetText(text.str(), path.string()));
}

}  // namespace driftlab::calib
