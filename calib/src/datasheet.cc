// Datasheet summary -> ImuErrorModel (datasheet.h documents the file format and the keys).
#include "driftlab/calib/datasheet.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "driftlab/calib/yaml_document.h"
#include "driftlab/input_files.h"
#include "driftlab/sensor_terms.h"
#include "driftlab/sensors.h"
#include "driftlab/spec_error.h"

namespace driftlab::calib {
namespace {

// Angular rate per acceleration (gyro g-sensitivity): rad s^-1 / (m s^-2) = rad m^-1 s.
constexpr Dimension kRatePerAcceleration = kRatePerAccelerationDimension;

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) {
    s.remove_suffix(1);
  }
  return s;
}

// The line of a YAML node, 1-based, for messages.
int LineOf(const YAML::Node& node) { return node.Mark().line + 1; }

std::string Where(std::string_view source, int line) {
  return std::string(source) + ":" + std::to_string(line);
}

// Only plain values: no application tags (YAML's own, the quoted-scalar "!" and none are fine).
void CheckTag(const YAML::Node& node, std::string_view source) {
  const std::string& tag = node.Tag();
  if (!tag.empty() && tag != "?" && tag != "!" && !tag.starts_with("tag:yaml.org,2002:")) {
    throw SpecError(Where(source, LineOf(node)), "the tag '" + tag + "'", "plain YAML values");
  }
}

// A scalar value of `key`: its text as written (quotes removed by YAML). `text` is the document.
std::string ScalarText(const YAML::Node& node, const std::string& key, std::string_view text,
                       std::string_view source) {
  CheckTag(node, source);
  if (node.IsNull()) return "";
  if (!node.IsScalar()) {
    throw SpecError(Where(source, LineOf(node)) + ": " + key, "a list or mapping",
                    "one value (a figure as printed, e.g. \"0.15 deg/√h\")");
  }
  if (node.Tag() == "!" && node.Mark().pos >= 0 &&
      !YamlQuotedScalarIsClosed(text, static_cast<size_t>(node.Mark().pos))) {
    throw SpecError(Where(source, LineOf(node)) + ": " + key, "a quote that is never closed",
                    "a closed 'single' or \"double\" quoted value");
  }
  return node.Scalar();
}

std::string KeyText(const YAML::Node& key, std::string_view source) {
  CheckTag(key, source);
  if (!key.IsScalar()) {
    throw SpecError(Where(source, LineOf(key)), "a key that is not a name", "key: value");
  }
  return key.Scalar();
}

// What one key means: the term of the sensor-term table (sensor_terms.h) it gives, the dimension
// its figure must have and the model field it sets (for messages).
struct KeyRule {
  std::string_view key;
  Dimension dimension;
  std::string field;  // "gyro.white_noise_density", "gyro_g_sensitivity"
  const SensorTerm* term;
};

std::vector<KeyRule> Rules(bool gyro) {
  const SensorTriad t = gyro ? SensorTriad::kGyro : SensorTriad::kAccel;
  std::vector<KeyRule> rules;
  for (const SensorTerm& term : SensorTerms()) {
    if (!term.applies_to(t)) continue;
    const Dimension dimension = term.figure_dimension(t);
    const std::string field =
        term.gyro_only ? std::string(term.param)
                       : std::string(gyro ? "gyro." : "accel.") + std::string(term.param);
    for (const std::string_view key : {term.datasheet_key.of(t), term.datasheet_alt_key.of(t)}) {
      if (!key.empty()) rules.push_back({key, dimension, field, &term});
    }
  }
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

// Any valid YAML (block or flow style, comments, multi-line flow mappings) read with yaml-cpp;
// the structure is fixed (a mapping of name, description, gyro, accel; gyro and accel mappings of
// scalars), so nothing is walked beyond two levels and aliases cannot expand it.
std::vector<DatasheetEntry> ParseDatasheetText(std::string_view text, std::string_view source) {
  YamlDocuments documents;
  try {
    documents = LoadYamlDocuments(text);
  } catch (const YAML::Exception& e) {
    throw SpecError(Where(source, e.mark.line + 1), "invalid YAML (" + e.msg + ")",
                    "a YAML mapping of name, description, gyro, "
                    "accel");
  }
  if (documents.count != 1 || !documents.first.IsMap() || documents.first.size() == 0) {
    const bool empty = documents.count == 0 || (documents.count == 1 && documents.first.IsNull());
    throw SpecError(std::string(source),
                    empty ? std::string("an empty datasheet")
                    : documents.count > 1
                        ? std::string("more than one YAML document (a --- separator, or a ',' "
                                      "outside [ ] and { })")
                        : std::string("not a mapping of keys"),
                    "one YAML document: a mapping of name, description, gyro, accel with at "
                    "least one figure");
  }
  const YAML::Node& root = documents.first;
  CheckTag(root, source);
  std::vector<DatasheetEntry> entries;
  std::set<std::string> seen;
  auto add = [&](DatasheetEntry e) {
    if (!seen.insert(e.key).second) {
      throw SpecError(Where(source, e.line) + ": " + e.key, "a second value", "each key once");
    }
    entries.push_back(std::move(e));
  };
  size_t figures = 0;
  for (const auto& item : root) {
    const std::string k = KeyText(item.first, source);
    const int line = LineOf(item.first);
    if (k == "name" || k == "description") {
      add({k, ScalarText(item.second, k, text, source), line});
    } else if (k == "gyro" || k == "accel") {
      if (!seen.insert(k).second) {
        throw SpecError(Where(source, line) + ": " + k, "a second section", "each once");
      }
      CheckTag(item.second, source);
      if (!item.second.IsMap()) {
        throw SpecError(Where(source, line) + ": " + k, "not a mapping",
                        "a mapping (indented lines below, or {key: value, ...})");
      }
      for (const auto& figure : item.second) {
        const std::string key = k + "." + KeyText(figure.first, source);
        add({key, ScalarText(figure.second, key, text, source), LineOf(figure.first)});
        ++figures;
      }
    } else {
      throw SpecError(Where(source, line) + ": " + k, "unknown key",
                      "name, description, gyro, accel");
    }
  }
  if (figures == 0) {
    throw SpecError(std::string(source), "no figures", "at least one figure under gyro or accel");
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
    const std::string& field = rule->field;
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
    // A figure is a magnitude: a scalar term's value, or a matrix term's diagonal (a same-axis
    // g-sensitivity).
    const SensorTriad t = gyro ? SensorTriad::kGyro : SensorTriad::kAccel;
    const int count = TermValueCount(rule->term->shape);
    for (int i = 0; i < count; ++i) {
      SetTermValue(*rule->term, &model, t, i, count == 1 || i % 4 == 0 ? value_si : 0.0);
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
  const std::string text = ReadInputFile(path, kMaxSmallTextFileBytes, "DATASHEET");
  return DatasheetToModel(ParseDatasheetText(text, path.string()));
}

}  // namespace driftlab::calib
