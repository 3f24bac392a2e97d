// `driftlab allan DATA.csv --rate HZ [--columns a,b] [--unit U] [--points-per-octave K]
//  [--out RESULT.json]`: overlapping Allan deviation of the columns of a CSV file, with 95 %
// confidence intervals and the IEEE Std 952 noise-term read-off (allan.h), in datasheet units.
//
// DATA.csv: one header row (names), then numeric rows; lines starting with '#' and empty lines are
// skipped. Default columns: the point samples of driftlab's imu.csv (omega_{x,y,z}_rad_per_s,
// f_{x,y,z}_m_per_s2; io.h ImuCsvWriter) when all are present, else every column except a time
// column (t, t_*, time*). A column's unit comes from --unit or from its name's suffix, words
// joined by '_' with "per" for '/': omega_x_rad_per_s -> rad/s, f_x_m_per_s2 -> m/s2,
// gyro_deg_per_h -> deg/h, acc_mg -> mg (units.h syntax). Rates (angular rate or acceleration)
// are analysed as they are; increments (angle or velocity, e.g. dtheta_x_rad) are divided by the
// sample interval 1 / rate first (allan.h: the input is the per-interval average rate).
//
// Results are printed in datasheet units: gyro ADEV and bias instability in deg/h, white noise in
// deg/sqrt(h), rate random walk in deg/h/sqrt(h); accelerometer ADEV and bias instability in ug
// (mg above 1 mg), white noise in m/s/sqrt(h). --out writes every point and the read-off, in SI
// and in those units, as JSON (google.protobuf.Struct through protobuf's JSON printer).
#include <fmt/format.h>
#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "allan_fit.h"
#include "commands.h"
#include "driftlab/allan.h"
#include "driftlab/spec_error.h"
#include "driftlab/units.h"

namespace driftlab::cli {
namespace {

namespace pb = google::protobuf;
namespace fs = std::filesystem;

// Fewest samples with two overlapping second differences at tau = 1 / rate (n + 1 - 2m >= 2 for
// m = 1), the least the overlapping estimator can average (allan.h).
constexpr size_t kMinSamples = 3;

struct AllanCliOptions {
  std::string data_path;
  double rate_hz = 0.0;
  std::string columns;
  std::string unit;
  std::string out_path;
  int points_per_octave = 1;
  // --fit: the noise-model fit (allan_fit.h); --out then names the model file.
  bool fit = false;
  AllanFitOptions fit_options;
};

// Display units for one kind of signal.
struct DisplayUnits {
  bool gyro;             // angle-based rates (else velocity-based)
  const char* quantity;  // "angular rate" / "acceleration"
  const char* si;        // unit of the rates: rad/s, m/s^2
  const char* adev;      // ADEV and bias instability
  const char* white;     // N
  const char* white_si;
  const char* random_walk;  // K
  const char* random_walk_si;
  const char* quantization;  // Q
  const char* quantization_si;
  const char* ramp;  // R
  const char* ramp_si;
};

constexpr DisplayUnits kGyroDisplay{true,          "angular rate", "rad/s",         "deg/h",
                                    "deg/sqrt(h)", "rad/sqrt(s)",  "deg/h/sqrt(h)", "rad/s/sqrt(s)",
                                    "urad",        "rad",          "deg/h/h",       "rad/s^2"};
constexpr DisplayUnits kAccelDisplayUg{
    false,           "acceleration",  "m/s^2", "ug",  "m/s/sqrt(h)", "m/s/sqrt(s)",
    "m/s/h/sqrt(h)", "m/s^2/sqrt(s)", "mm/s",  "m/s", "ug/h",        "m/s^3"};
constexpr DisplayUnits kAccelDisplayMg{
    false,           "acceleration",  "m/s^2", "mg",  "m/s/sqrt(h)", "m/s/sqrt(s)",
    "m/s/h/sqrt(h)", "m/s^2/sqrt(s)", "mm/s",  "m/s", "mg/h",        "m/s^3"};

// One selected column: name, unit, and how to turn its values into SI rates.
struct Column {
  std::string name;
  size_t index = 0;
  std::string unit;    // as parsed (units.h syntax)
  double to_si = 1.0;  // value * to_si = SI rate (includes * rate_hz for increments)
  bool gyro = true;    // angle-based (else velocity-based)
  bool increment = false;
  std::vector<double> samples;  // SI rates
};

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) {
    s.remove_suffix(1);
  }
  return s;
}

std::vector<std::string> Split(std::string_view line, char sep) {
  std::vector<std::string> fields;
  size_t start = 0;
  while (true) {
    const size_t end = line.find(sep, start);
    fields.emplace_back(Trim(line.substr(start, end - start)));
    if (end == std::string_view::npos) break;
    start = end + 1;
  }
  return fields;
}

std::string Join(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& item : items) out += (out.empty() ? "" : ", ") + item;
  return out;
}

bool IsTimeColumn(std::string name) {
  std::transform(name.begin(), name.end(), name.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return name == "t" || name.rfind("t_", 0) == 0 || name.rfind("time", 0) == 0;
}

// Dimension check shared by --unit and name suffixes: rates, or increments of them.
bool AcceptedDimension(Dimension d) {
  return d == dims::kAngularRate || d == dims::kAcceleration || d == dims::kAngle ||
         d == dims::kVelocity;
}

constexpr const char* kAllowedUnits =
    "an angular rate (rad/s, deg/s, deg/h), an acceleration (m/s^2, g, mg, ug) or an increment "
    "(rad, deg, m/s)";

// Fills unit, to_si, gyro, increment from a parsed unit.
void SetUnit(Column& column, const std::string& unit_text, const Unit& unit, double rate_hz) {
  column.unit = unit_text;
  column.gyro = unit.dimension.angle2 != 0;
  column.increment = unit.dimension == dims::kAngle || unit.dimension == dims::kVelocity;
  column.to_si = unit.si_factor * (column.increment ? rate_hz : 1.0);
}

// Unit from the name's suffix: the longest tail of '_'-separated words that parses as a unit of
// an accepted dimension ("per" = '/'). Returns false if no tail does.
bool UnitFromName(Column& column, double rate_hz) {
  const std::vector<std::string> words = Split(column.name, '_');
  for (size_t first = 1; first < words.size(); ++first) {
    std::string text;
    for (size_t i = first; i < words.size(); ++i) {
      text += (text.empty() ? "" : " ") + (words[i] == "per" ? std::string("/") : words[i]);
    }
    try {
      const Unit unit = ParseUnit(text, column.name);
      if (AcceptedDimension(unit.dimension)) {
        SetUnit(column, text, unit, rate_hz);
        return true;
      }
    } catch (const SpecError&) {
      // Not a unit: try a shorter tail.
    }
  }
  return false;
}

// Reads the header and the selected columns of `path` as SI rates.
std::vector<Column> ReadColumns(const AllanCliOptions& options) {
  const std::string file = options.data_path;
  std::ifstream in(file);
  if (!in) {
    throw SpecError("DATA", file, "an existing, readable CSV file (open failed)");
  }
  std::string line;
  size_t line_no = 0;
  std::vector<std::string> header;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string_view t = Trim(line);
    if (t.empty() || t.front() == '#') continue;
    header = Split(t, ',');
    break;
  }
  if (header.empty()) throw SpecError("DATA", file + " (empty)", "a header row and numeric rows");

  // Column selection.
  std::vector<Column> columns;
  auto find = [&header](const std::string& name) -> long {
    const auto it = std::find(header.begin(), header.end(), name);
    return it == header.end() ? -1 : static_cast<long>(it - header.begin());
  };
  if (!options.columns.empty()) {
    for (const std::string& name : Split(options.columns, ',')) {
      const long index = find(name);
      if (index < 0) {
        throw SpecError("--columns", name.empty() ? "''" : "'" + name + "'",
                        "a column of " + file + ": " + Join(header));
      }
      Column column;
      column.name = name;
      column.index = static_cast<size_t>(index);
      columns.push_back(std::move(column));
    }
  } else {
    const std::vector<std::string> imu = {"omega_x_rad_per_s", "omega_y_rad_per_s",
                                          "omega_z_rad_per_s", "f_x_m_per_s2",
                                          "f_y_m_per_s2",      "f_z_m_per_s2"};
    const bool is_imu_csv =
        std::all_of(imu.begin(), imu.end(), [&find](const std::string& n) { return find(n) >= 0; });
    for (size_t i = 0; i < header.size(); ++i) {
      const bool take = is_imu_csv ? std::find(imu.begin(), imu.end(), header[i]) != imu.end()
                                   : !IsTimeColumn(header[i]);
      if (!take) continue;
      Column column;
      column.name = header[i];
      column.index = i;
      columns.push_back(std::move(column));
    }
    if (columns.empty()) {
      throw SpecError("DATA", file + " (only a time column)",
                      "at least one column besides the time column");
    }
  }

  // Units.
  for (Column& column : columns) {
    if (!options.unit.empty()) {
      const Unit unit = ParseUnit(options.unit, "--unit");
      if (!AcceptedDimension(unit.dimension)) {
        throw SpecError("--unit", "'" + options.unit + "' (" + DimensionName(unit.dimension) + ")",
                        kAllowedUnits);
      }
      SetUnit(column, options.unit, unit, options.rate_hz);
    } else if (!UnitFromName(column, options.rate_hz)) {
      throw SpecError(
          "--unit", "missing",
          fmt::format("a unit for column '{}' of {}: its name has no unit suffix (such as "
                      "_rad_per_s, _deg_per_s, _deg_per_h, _m_per_s2, _g, _mg); give --unit as {}",
                      column.name, file, kAllowedUnits));
    }
  }

  // Rows.
  while (std::getline(in, line)) {
    ++line_no;
    const std::string_view t = Trim(line);
    if (t.empty() || t.front() == '#') continue;
    const std::vector<std::string> fields = Split(t, ',');
    if (fields.size() != header.size()) {
      throw SpecError(fmt::format("{}:{}", file, line_no), fmt::format("{} fields", fields.size()),
                      fmt::format("{} fields, as in the header", header.size()));
    }
    for (Column& column : columns) {
      const std::string& text = fields[column.index];
      double value = 0.0;
      const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
      if (ec != std::errc() || ptr != text.data() + text.size() || !std::isfinite(value)) {
        throw SpecError(fmt::format("{}:{}: column '{}'", file, line_no, column.name),
                        "'" + text + "'", "a finite number");
      }
      column.samples.push_back(value * column.to_si);
    }
  }
  for (const Column& column : columns) {
    if (column.samples.size() < kMinSamples) {
      throw SpecError(fmt::format("{}: column '{}'", file, column.name),
                      fmt::format("{} samples", column.samples.size()),
                      fmt::format("at least {} samples (two overlapping second differences at "
                                  "tau = 1 / rate)",
                                  kMinSamples));
    }
  }
  return columns;
}

const char* NoiseName(AllanNoiseType type) {
  switch (type) {
    case AllanNoiseType::kWhitePm:
      return "white PM";
    case AllanNoiseType::kFlickerPm:
      return "flicker PM";
    case AllanNoiseType::kWhiteFm:
      return "white FM";
    case AllanNoiseType::kFlickerFm:
      return "flicker FM";
    case AllanNoiseType::kRandomWalkFm:
      return "random-walk FM";
    case AllanNoiseType::kAuto:
      break;
  }
  return "auto";
}

pb::Value Number(double v) {
  pb::Value value;
  if (std::isfinite(v)) {
    value.set_number_value(v);
  } else {
    value.set_null_value(pb::NULL_VALUE);
  }
  return value;
}

pb::Value Text(const std::string& s) {
  pb::Value value;
  value.set_string_value(s);
  return value;
}

void Set(pb::Struct& s, const std::string& key, pb::Value value) {
  (*s.mutable_fields())[key] = std::move(value);
}

// One read-off term: printed line and JSON.
struct Term {
  const char* key;
  const char* label;
  const char* symbol;
  const AllanTermFit* fit;
  const char* unit;
  const char* si_unit;
};

std::vector<Term> Terms(const AllanReadOff& r, const DisplayUnits& u) {
  return {{"white_noise", u.gyro ? "white noise (ARW)" : "white noise (VRW)", "N", &r.white_noise,
           u.white, u.white_si},
          {"bias_instability", "bias instability", "B", &r.bias_instability, u.adev, u.si},
          {"random_walk", u.gyro ? "rate random walk" : "acceleration random walk", "K",
           &r.random_walk, u.random_walk, u.random_walk_si},
          {"quantization", "quantization", "Q", &r.quantization, u.quantization, u.quantization_si},
          {"rate_ramp", "ramp", "R", &r.rate_ramp, u.ramp, u.ramp_si}};
}

pb::Value AnalyseColumn(const Column& column, const AllanCliOptions& options) {
  AllanOptions allan;
  allan.points_per_octave = options.points_per_octave;
  const std::vector<AllanPoint> curve =
      OverlappingAllanDeviation(column.samples, options.rate_hz, allan);
  const AllanReadOff read_off = ReadOffNoiseTerms(curve);

  double min_adev = curve.front().adev;
  for (const AllanPoint& p : curve) min_adev = std::min(min_adev, p.adev);
  const DisplayUnits& u =
      column.gyro ? kGyroDisplay
                  : (std::fabs(FromSi(min_adev, "mg")) < 1.0 ? kAccelDisplayUg : kAccelDisplayMg);

  fmt::print("column {}: {} ({}{}), {} samples at {:g} Hz\n", column.name, u.quantity, column.unit,
             column.increment ? " increments, divided by 1/rate" : "", column.samples.size(),
             options.rate_hz);
  fmt::print("  {:>12}  {:>12}  {:>27}  {:>10}  {:>10}  {}\n", "tau [s]",
             fmt::format("ADEV [{}]", u.adev), fmt::format("95 % CI [{}]", u.adev), "edf",
             "clusters", "noise (EDF)");
  pb::Value result;
  pb::Struct& s = *result.mutable_struct_value();
  Set(s, "name", Text(column.name));
  Set(s, "quantity", Text(u.quantity));
  Set(s, "input_unit", Text(column.unit));
  Set(s, "increments", [&] {
    pb::Value v;
    v.set_bool_value(column.increment);
    return v;
  }());
  Set(s, "n_samples", Number(static_cast<double>(column.samples.size())));
  Set(s, "si_unit", Text(u.si));
  Set(s, "datasheet_unit", Text(u.adev));
  pb::ListValue& points = *(*s.mutable_fields())["points"].mutable_list_value();
  for (const AllanPoint& p : curve) {
    fmt::print("  {:>12.6g}  {:>12.6g}  {:>12.6g} - {:>12.6g}  {:>10.4g}  {:>10}  {}\n", p.tau_s,
               FromSi(p.adev, u.adev), FromSi(p.adev_low, u.adev), FromSi(p.adev_high, u.adev),
               p.edf, p.n_clusters, NoiseName(p.noise_type));
    pb::Value point;
    pb::Struct& ps = *point.mutable_struct_value();
    Set(ps, "tau_s", Number(p.tau_s));
    Set(ps, "adev", Number(p.adev));
    Set(ps, "adev_low", Number(p.adev_low));
    Set(ps, "adev_high", Number(p.adev_high));
    Set(ps, "edf", Number(p.edf));
    Set(ps, "n_clusters", Number(static_cast<double>(p.n_clusters)));
    Set(ps, "m", Number(static_cast<double>(p.m)));
    Set(ps, "noise_type", Text(NoiseName(p.noise_type)));
    Set(ps, "adev_datasheet", Number(FromSi(p.adev, u.adev)));
    *points.add_values() = std::move(point);
  }

  fmt::print("  read-off (IEEE Std 952-1997 Annex C):\n");
  pb::Struct& rs = *(*s.mutable_fields())["read_off"].mutable_struct_value();
  for (const Term& term : Terms(read_off, u)) {
    pb::Value v;
    pb::Struct& ts = *v.mutable_struct_value();
    const AllanTermFit& fit = *term.fit;
    Set(ts, "found", [&] {
      pb::Value b;
      b.set_bool_value(fit.found());
      return b;
    }());
    Set(ts, "si", Number(fit.value));
    Set(ts, "si_unit", Text(term.si_unit));
    Set(ts, "datasheet_unit", Text(term.unit));
    Set(ts, "datasheet_value", Number(fit.found() ? FromSi(fit.value, term.unit) : NAN));
    Set(ts, "tau_min_s", Number(fit.tau_min_s));
    Set(ts, "tau_max_s", Number(fit.tau_max_s));
    Set(ts, "n_points", Number(fit.n_points));
    if (fit.found()) {
      const std::string datasheet = FormatQuantity(fit.value, term.unit, 4);
      Set(ts, "datasheet", Text(datasheet));
      fmt::print("    {:<26} {} = {:<24} [SI: {:.6g} {}]  from tau {:g}-{:g} s ({} points)\n",
                 term.label, term.symbol, datasheet, fit.value, term.si_unit, fit.tau_min_s,
                 fit.tau_max_s, fit.n_points);
    } else {
      fmt::print("    {:<26} {} : not found on this curve\n", term.label, term.symbol);
    }
    (*rs.mutable_fields())[term.key] = std::move(v);
  }
  fmt::print("\n");
  return result;
}

int RunAllan(const AllanCliOptions& options) {
  pb::Value report;
  try {
    if (!std::isfinite(options.rate_hz) || options.rate_hz <= 0.0) {
      throw SpecError("--rate", fmt::format("{:g}", options.rate_hz), "> 0 Hz (finite)");
    }
    if (options.points_per_octave < 1 || options.points_per_octave > 64) {
      throw SpecError("--points-per-octave", std::to_string(options.points_per_octave), "1 to 64");
    }
    const std::vector<Column> columns = ReadColumns(options);
    pb::Struct& s = *report.mutable_struct_value();
    Set(s, "file", Text(options.data_path));
    Set(s, "rate_hz", Number(options.rate_hz));
    Set(s, "confidence", Number(0.95));
    Set(s, "points_per_octave", Number(options.points_per_octave));
    pb::ListValue& list = *(*s.mutable_fields())["columns"].mutable_list_value();
    for (const Column& column : columns) *list.add_values() = AnalyseColumn(column, options);
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }
  if (options.out_path.empty()) return kExitOk;

  std::string json;
  pb::util::JsonPrintOptions print_options;
  print_options.add_whitespace = true;
  print_options.preserve_proto_field_names = true;
  const auto status = pb::util::MessageToJsonString(report, &json, print_options);
  if (!status.ok()) {
    fmt::print(stderr, "error: JSON output failed: {}\n", status.ToString());
    return kExitFailure;
  }
  std::ofstream out(options.out_path, std::ios::binary | std::ios::trunc);
  out << json;
  out.close();
  if (!out) {
    fmt::print(stderr, "error: --out: cannot write '{}'\n", options.out_path);
    return kExitFailure;
  }
  fmt::print("wrote {}\n", options.out_path);
  return kExitOk;
}

const RegisterCommand kAllan("allan", [](CLI::App& app) -> std::function<int()> {
  auto options = std::make_shared<AllanCliOptions>();
  CLI::App* command = app.add_subcommand(
      "allan", "Overlapping Allan deviation of CSV columns with 95 % CIs and the noise read-off");
  command->add_option("data", options->data_path, "CSV file: header row, numeric columns")
      ->required();
  command->add_option("--rate", options->rate_hz, "Sample rate [Hz] (> 0)")->required();
  command->add_option("--columns", options->columns,
                      "Comma-separated column names (default: imu.csv point samples, else all "
                      "but the time column)");
  command->add_option("--unit", options->unit,
                      "Unit of the columns, units.h syntax (deg/s, deg/h, rad/s, m/s^2, g, mg, "
                      "ug; rad, deg, m/s for increments); default: from the column name suffix");
  command->add_option("--points-per-octave", options->points_per_octave,
                      "Tau grid density (1 = octave grid, up to 64)");
  command->add_option("--out", options->out_path,
                      "Write every point and the read-off as JSON (with --fit: the fitted model "
                      "as a job-schema sensor fragment {\"sensor\": {...}})");
  command->add_flag("--fit", options->fit,
                    "Fit the IEEE Std 952 noise terms (white noise, bias instability, random "
                    "walk, quantization, rate ramp) with Ceres, weighted by each tau's confidence");
  command->add_option("--datasheet", options->fit_options.datasheet_path,
                      "With --fit: a datasheet summary to compare with side by side");
  command
      ->add_option("--bias-model", options->fit_options.bias_model,
                   "With --fit: flicker, gauss-markov or none")
      ->capture_default_str();
  command->add_option("--flicker-tau-min", options->fit_options.flicker_tau_min_s,
                      "With --fit: flicker band start [s] (0 = first tau)");
  command->add_option("--flicker-tau-max", options->fit_options.flicker_tau_max_s,
                      "With --fit: flicker band end [s] (0 = last tau)");
  return [options] {
    if (!options->fit) return RunAllan(*options);
    AllanFitOptions fit = options->fit_options;
    fit.data_path = options->data_path;
    fit.rate_hz = options->rate_hz;
    fit.columns = options->columns;
    fit.out_path = options->out_path;
    fit.points_per_octave = options->points_per_octave;
    if (!options->unit.empty()) {
      fmt::print(stderr,
                 "error: --unit: {} is not allowed; allowed: with --fit, units come "
                 "from the column names\n",
                 options->unit);
      return kExitBadJob;
    }
    return RunAllanFit(fit);
  };
});

}  // namespace
}  // namespace driftlab::cli
