// `driftlab presets [NAME] [--json]`: the IMU catalogue (presets.h) in datasheet units.
//
// Without NAME: one row per preset with the headline figures (gyro bias instability in deg/h,
// ARW in deg/sqrt(h), accel bias instability in ug or mg, VRW in m/s/sqrt(h), ranges). With NAME:
// every term of that preset's error model in the datasheet unit of the sensor-term table
// (sensor_terms.h) with the SI value beside it, and the preset's description (source, revision,
// assumptions). All conversions go through the units module (units.h FromSi / FormatQuantity).
// --json prints the same content as JSON (google.protobuf.Struct printed by protobuf's JSON
// printer, which escapes strings).
#include <fmt/format.h>
#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "commands.h"
#include "driftlab/presets.h"
#include "driftlab/sensor_params.h"
#include "driftlab/sensor_terms.h"
#include "driftlab/spec_error.h"
#include "driftlab/units.h"
#include "json_values.h"

namespace driftlab::cli {
namespace {

namespace pb = google::protobuf;

constexpr int kDigits = 6;  // significant digits of datasheet-unit values (trailing zeros dropped)

std::string Datasheet(double value_si, const char* unit) {
  return FormatQuantity(value_si, unit, kDigits);
}
std::string Si(double value_si, const char* unit) {
  return *unit == '\0' ? fmt::format("{:.6g}", value_si) : fmt::format("{:.6g} {}", value_si, unit);
}

// One parameter: label, datasheet text, SI text, plus the JSON value.
struct Row {
  std::string key;    // JSON key
  std::string label;  // table label
  std::string datasheet;
  std::string si;
  pb::Value json;
};

// {"si": v, "si_unit": "...", "datasheet": "..."} for a scalar.
Row Scalar(std::string key, std::string label, double value_si, const char* unit,
           const char* si_unit) {
  Row row{std::move(key), std::move(label), Datasheet(value_si, unit), Si(value_si, si_unit), {}};
  pb::Struct& s = *row.json.mutable_struct_value();
  (*s.mutable_fields())["si"] = JsonNumber(value_si);
  (*s.mutable_fields())["si_unit"] = JsonText(si_unit);
  (*s.mutable_fields())["datasheet"] = JsonText(row.datasheet);
  return row;
}

// A noise density printed both as a random walk and as a density.
Row Noise(std::string key, std::string label, double value_si, const char* unit,
          const char* si_unit, const char* density_unit) {
  Row row = Scalar(std::move(key), std::move(label), value_si, unit, si_unit);
  row.datasheet += " = " + Datasheet(value_si, density_unit);
  (*row.json.mutable_struct_value()->mutable_fields())["datasheet_density"] =
      JsonText(Datasheet(value_si, density_unit));
  return row;
}

// Vectors and matrices: the numbers in the datasheet unit, space-separated, and in SI.
Row Values(std::string key, std::string label, const double* values, int count, const char* unit,
           const char* si_unit) {
  Row row{std::move(key), std::move(label), "", "", {}};
  pb::Struct& s = *row.json.mutable_struct_value();
  pb::ListValue& si_list = *(*s.mutable_fields())["si"].mutable_list_value();
  pb::ListValue& ds_list = *(*s.mutable_fields())["datasheet_values"].mutable_list_value();
  for (int i = 0; i < count; ++i) {
    const double ds = FromSi(values[i], unit);
    if (i > 0) {
      row.datasheet += ' ';
      row.si += ' ';
    }
    row.datasheet += fmt::format("{:.{}g}", ds, kDigits);
    row.si += fmt::format("{:.6g}", values[i]);
    *si_list.add_values() = JsonNumber(values[i]);
    *ds_list.add_values() = JsonNumber(ds);
  }
  row.datasheet += std::string(" ") + unit;
  if (*si_unit != '\0') row.si += std::string(" ") + si_unit;
  (*s.mutable_fields())["si_unit"] = JsonText(si_unit);
  (*s.mutable_fields())["datasheet_unit"] = JsonText(unit);
  return row;
}

// The printed rows of the terms that apply to triad t (model-level terms when model_level: the
// g-sensitivity), in the table's order (sensor_terms.h).
std::vector<Row> TermRows(const ImuErrorModel& m, SensorTriad t, bool model_level) {
  std::vector<Row> rows;
  for (const SensorTerm& term : SensorTerms()) {
    if (term.preset_label.empty() || term.gyro_only != model_level || !term.applies_to(t)) {
      continue;
    }
    const std::string key(term.preset_key), label(term.preset_label);
    const std::string si_unit(term.preset_si_unit.of(t));
    std::string unit(term.preset_unit.of(t));
    if (term.preset_bias_unit && t == SensorTriad::kAccel) {
      unit = AccelBiasPrintUnit(m.accel.bias_flicker.bias_instability);
    }
    const int count = TermValueCount(term.shape);
    if (count == 1) {
      const double value = TermValue(term, m, t, 0);
      const std::string density(term.preset_density_unit.of(t));
      rows.push_back(density.empty() ? Scalar(key, label, value, unit.c_str(), si_unit.c_str())
                                     : Noise(key, label, value, unit.c_str(), si_unit.c_str(),
                                             density.c_str()));
      continue;
    }
    double values[9];
    for (int i = 0; i < count; ++i) values[i] = TermValue(term, m, t, i);
    rows.push_back(Values(key, label, values, count, unit.c_str(), si_unit.c_str()));
  }
  return rows;
}

pb::Value RowsToJson(const std::vector<Row>& rows) {
  pb::Value value;
  pb::Struct& s = *value.mutable_struct_value();
  for (const Row& row : rows) (*s.mutable_fields())[row.key] = row.json;
  return value;
}

pb::Value PresetJson(const ImuErrorModel& model) {
  pb::Value value;
  pb::Struct& s = *value.mutable_struct_value();
  (*s.mutable_fields())["name"] = JsonText(model.name);
  (*s.mutable_fields())["description"] = JsonText(model.description);
  (*s.mutable_fields())["gyro"] = RowsToJson(TermRows(model, SensorTriad::kGyro, false));
  (*s.mutable_fields())["accel"] = RowsToJson(TermRows(model, SensorTriad::kAccel, false));
  for (const Row& row : TermRows(model, SensorTriad::kGyro, true)) {
    (*s.mutable_fields())[row.key] = row.json;
  }
  return value;
}

int PrintJson(const pb::Value& value) {
  std::string json;
  pb::util::JsonPrintOptions options;
  options.add_whitespace = true;
  options.preserve_proto_field_names = true;
  const auto status = pb::util::MessageToJsonString(value, &json, options);
  if (!status.ok()) {
    fmt::print(stderr, "error: JSON output failed: {}\n", status.ToString());
    return kExitFailure;
  }
  fmt::print("{}", json);
  if (json.empty() || json.back() != '\n') fmt::print("\n");
  return kExitOk;
}

// Wraps text at `width` columns with `indent` leading spaces.
std::string Wrap(std::string_view text, size_t width, size_t indent) {
  std::string out;
  std::string line(indent, ' ');
  size_t pos = 0;
  while (pos < text.size()) {
    size_t end = text.find(' ', pos);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view word = text.substr(pos, end - pos);
    if (line.size() > indent && line.size() + 1 + word.size() > width) {
      out += line + "\n";
      line.assign(indent, ' ');
    }
    if (line.size() > indent) line += ' ';
    line += word;
    pos = end + 1;
  }
  if (line.size() > indent) out += line + "\n";
  return out;
}

// "Tactical grade IMU" from "Tactical grade IMU. Source: ...": the text up to the first ". ", or
// up to a parenthesis naming the source document ("ADIS16470 (ADIS16470 datasheet Rev. C)"), at
// most 40 characters. Parentheses without a digit ("Rate (consumer) grade") stay.
std::string ShortDescription(const std::string& description) {
  size_t end = std::min(description.find(". "), description.size());
  for (size_t open = description.find(" ("); open < end; open = description.find(" (", open + 1)) {
    const size_t close = std::min(description.find(')', open), description.size());
    const std::string inner = description.substr(open, close - open);
    if (std::any_of(inner.begin(), inner.end(), [](char c) { return c >= '0' && c <= '9'; })) {
      end = open;
      break;
    }
  }
  std::string s = description.substr(0, end);
  if (s.size() > 40) s = s.substr(0, 37) + "...";
  return s;
}

// "-" for an absent term (0), else the value in `unit`.
std::string Cell(double value_si, const char* unit) {
  if (value_si == 0.0) return "-";
  return FormatQuantity(value_si, unit, 3);
}

int PrintTable() {
  const std::vector<ImuErrorModel>& catalogue = ImuCatalogue();
  const std::vector<std::string> header = {"NAME", "GYRO BI",    "ARW",         "ACCEL BI",
                                           "VRW",  "GYRO RANGE", "ACCEL RANGE", "DESCRIPTION"};
  std::vector<std::vector<std::string>> rows;
  for (const ImuErrorModel& m : catalogue) {
    const double accel_bi = m.accel.bias_flicker.bias_instability;
    rows.push_back({m.name, Cell(m.gyro.bias_flicker.bias_instability, "deg/h"),
                    Cell(m.gyro.white_noise_density, "deg/sqrt(h)"),
                    Cell(accel_bi, std::string(AccelBiasPrintUnit(accel_bi)).c_str()),
                    Cell(m.accel.white_noise_density, "m/s/sqrt(h)"),
                    m.gyro.range > 0.0 ? FormatQuantity(m.gyro.range, "deg/s", 4) : "unlimited",
                    m.accel.range > 0.0 ? FormatQuantity(m.accel.range, "g", 4) : "unlimited",
                    ShortDescription(m.description)});
  }
  std::vector<size_t> width(header.size());
  for (size_t c = 0; c < header.size(); ++c) {
    width[c] = header[c].size();
    for (const auto& row : rows) width[c] = std::max(width[c], row[c].size());
  }
  auto print_row = [&](const std::vector<std::string>& row) {
    std::string line;
    for (size_t c = 0; c < row.size(); ++c) {
      line += c + 1 < row.size() ? fmt::format("{:<{}}  ", row[c], width[c]) : row[c];
    }
    fmt::print("{}\n", line);
  };
  print_row(header);
  for (const auto& row : rows) print_row(row);
  fmt::print(
      "\n{} presets. BI = bias instability (flicker coefficient B; Allan floor 0.664 B), ARW/VRW "
      "= white noise; '-' = term absent. `driftlab presets NAME` shows every parameter and the "
      "source.\n",
      catalogue.size());
  return kExitOk;
}

void PrintRows(const char* title, const std::vector<Row>& rows) {
  size_t label_width = 0, ds_width = 0;
  for (const Row& row : rows) {
    label_width = std::max(label_width, row.label.size());
    ds_width = std::max(ds_width, row.datasheet.size());
  }
  fmt::print("{}\n", title);
  for (const Row& row : rows) {
    fmt::print("  {:<{}}  {:<{}}  [SI: {}]\n", row.label, label_width, row.datasheet, ds_width,
               row.si);
  }
}

int PrintPreset(const ImuErrorModel& m) {
  fmt::print("{}\n{}\n", m.name, Wrap(m.description, 100, 2));
  PrintRows("gyro", TermRows(m, SensorTriad::kGyro, false));
  fmt::print("\n");
  PrintRows("accelerometer", TermRows(m, SensorTriad::kAccel, false));
  fmt::print("\n");
  PrintRows("gyro g-sensitivity", TermRows(m, SensorTriad::kGyro, true));
  return kExitOk;
}

struct PresetsOptions {
  std::string name;
  bool json = false;
};

int RunPresets(const PresetsOptions& options) {
  try {
    if (options.name.empty()) {
      if (!options.json) return PrintTable();
      pb::Value value;
      pb::ListValue& list =
          *(*value.mutable_struct_value()->mutable_fields())["presets"].mutable_list_value();
      for (const ImuErrorModel& m : ImuCatalogue()) *list.add_values() = PresetJson(m);
      return PrintJson(value);
    }
    const ImuErrorModel& model = FindImuPreset(options.name);
    return options.json ? PrintJson(PresetJson(model)) : PrintPreset(model);
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }
}

const RegisterCommand kPresets("presets", [](CLI::App& app) -> std::function<int()> {
  auto options = std::make_shared<PresetsOptions>();
  CLI::App* command = app.add_subcommand(
      "presets", "List the IMU catalogue, or show one preset in datasheet units");
  command->add_option("name", options->name, "Preset name (omit to list all)");
  command->add_flag("--json", options->json, "Print JSON (SI values and datasheet-unit strings)");
  return [options] { return RunPresets(*options); };
});

}  // namespace
}  // namespace driftlab::cli
