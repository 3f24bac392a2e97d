// RunAllanFit (allan_fit.h): the noise-model fit behind `driftlab allan DATA.csv --fit`.
#include "allan_fit.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "commands.h"
#include "driftlab/allan.h"
#include "driftlab/calib/datasheet.h"
#include "driftlab/calib/noise_fit.h"
#include "driftlab/jobspec/sensor_model_json.h"
#include "driftlab/spec_error.h"
#include "driftlab/units.h"

namespace driftlab::cli {
namespace {

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) {
    s.remove_suffix(1);
  }
  return s;
}

std::vector<std::string> Split(std::string_view line, char sep) {
  std::vector<std::string> out;
  size_t start = 0;
  while (true) {
    const size_t end = line.find(sep, start);
    out.emplace_back(Trim(line.substr(start, end == std::string_view::npos ? end : end - start)));
    if (end == std::string_view::npos) break;
    start = end + 1;
  }
  return out;
}

struct Column {
  std::string name;
  size_t index = 0;
  double to_si = 1.0;
  bool gyro = true;
  std::vector<double> samples;
};

// Unit of a column from its name: the longest '_'-separated tail that parses as an angular rate
// or an acceleration ("per" = '/').
std::optional<Unit> UnitFromName(const std::string& name) {
  const std::vector<std::string> words = Split(name, '_');
  for (size_t first = 1; first < words.size(); ++first) {
    std::string text;
    for (size_t i = first; i < words.size(); ++i) {
      text += (text.empty() ? "" : " ") + (words[i] == "per" ? std::string("/") : words[i]);
    }
    try {
      const Unit unit = ParseUnit(text, name);
      if (unit.dimension == dims::kAngularRate || unit.dimension == dims::kAcceleration) {
        return unit;
      }
    } catch (const SpecError&) {
      // not a unit: a shorter tail may be
    }
  }
  return std::nullopt;
}

std::vector<Column> ReadColumns(const AllanFitOptions& options) {
  std::ifstream in(options.data_path);
  if (!in) throw SpecError("DATA", options.data_path, "an existing, readable CSV file");
  std::string line;
  int line_no = 0;
  std::vector<std::string> header;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string_view t = Trim(line);
    if (t.empty() || t.front() == '#') continue;
    header = Split(t, ',');
    break;
  }
  if (header.empty()) {
    throw SpecError("DATA", options.data_path + " (empty)", "a header row and numeric rows");
  }
  const std::vector<std::string> names =
      options.columns.empty()
          ? std::vector<std::string>{"omega_x_rad_per_s", "omega_y_rad_per_s", "omega_z_rad_per_s",
                                     "f_x_m_per_s2",      "f_y_m_per_s2",      "f_z_m_per_s2"}
          : Split(options.columns, ',');
  std::vector<Column> columns;
  for (const std::string& name : names) {
    const auto it = std::find(header.begin(), header.end(), name);
    if (it == header.end()) {
      std::string all;
      for (const std::string& h : header) all += (all.empty() ? "" : ", ") + h;
      throw SpecError(options.columns.empty() ? "DATA" : "--columns", "'" + name + "'",
                      "a column of " + options.data_path + " (" + all +
                          (options.columns.empty() ? "); without --columns the imu.csv columns "
                                                     "omega_*_rad_per_s and f_*_m_per_s2 are read"
                                                   : ")"));
    }
    const std::optional<Unit> unit = UnitFromName(name);
    if (!unit) {
      throw SpecError("--columns", "'" + name + "'",
                      "a column whose name ends in a unit of angular rate or acceleration "
                      "(_rad_per_s, _deg_per_s, _deg_per_h, _m_per_s2, _g, _mg, _ug)");
    }
    columns.push_back({name,
                       static_cast<size_t>(it - header.begin()),
                       unit->si_factor,
                       unit->dimension == dims::kAngularRate,
                       {}});
  }
  while (std::getline(in, line)) {
    ++line_no;
    const std::string_view t = Trim(line);
    if (t.empty() || t.front() == '#') continue;
    const std::vector<std::string> fields = Split(t, ',');
    if (fields.size() != header.size()) {
      throw SpecError(fmt::format("{}:{}", options.data_path, line_no),
                      fmt::format("{} fields", fields.size()),
                      fmt::format("{} fields, as in the header", header.size()));
    }
    for (Column& c : columns) {
      const std::string& text = fields[c.index];
      double value = 0.0;
      const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
      if (ec != std::errc() || ptr != text.data() + text.size() || !std::isfinite(value)) {
        throw SpecError(fmt::format("{}:{}: column '{}'", options.data_path, line_no, c.name),
                        "'" + text + "'", "a finite number");
      }
      c.samples.push_back(value * c.to_si);
    }
  }
  return columns;
}

calib::BiasModel ParseBiasModel(const std::string& name) {
  if (name == "flicker") return calib::BiasModel::kFlickerFlat;
  if (name == "gauss-markov") return calib::BiasModel::kGaussMarkov;
  if (name == "none") return calib::BiasModel::kNone;
  throw SpecError("--bias-model", "'" + name + "'", "flicker, gauss-markov or none");
}

}  // namespace

int RunAllanFit(const AllanFitOptions& options) {
  std::string json;
  try {
    if (!std::isfinite(options.rate_hz) || options.rate_hz <= 0.0) {
      throw SpecError("--rate", fmt::format("{:g}", options.rate_hz), "> 0 Hz (finite)");
    }
    if (options.points_per_octave < 1 || options.points_per_octave > 64) {
      throw SpecError("--points-per-octave", std::to_string(options.points_per_octave), "1 to 64");
    }
    calib::NoiseFitOptions fit_options;
    fit_options.bias_model = ParseBiasModel(options.bias_model);
    fit_options.flicker_tau_min_s = options.flicker_tau_min_s;
    fit_options.flicker_tau_max_s = options.flicker_tau_max_s;
    std::optional<calib::DatasheetModel> datasheet;
    if (!options.datasheet_path.empty()) datasheet = calib::LoadDatasheet(options.datasheet_path);

    const std::vector<Column> columns = ReadColumns(options);
    ImuErrorModel model;
    model.name = "allan-fit";
    model.description = "noise terms fitted to the Allan deviation of " + options.data_path;
    for (const bool gyro : {true, false}) {
      std::vector<std::vector<AllanPoint>> curves;
      for (const Column& c : columns) {
        if (c.gyro != gyro) continue;
        AllanOptions allan;
        allan.points_per_octave = options.points_per_octave;
        curves.push_back(OverlappingAllanDeviation(c.samples, options.rate_hz, allan));
        const calib::NoiseFitResult fit = calib::FitAllanNoiseModel(curves.back(), fit_options);
        fmt::print("column {} ({} samples at {:g} Hz):\n{}", c.name, c.samples.size(),
                   options.rate_hz, calib::FormatNoiseFit(fit, gyro));
      }
      if (curves.empty()) continue;
      const calib::NoiseFitResult triad = calib::FitAllanNoiseModel(curves, fit_options);
      const TriadErrorParams* reference =
          datasheet ? (gyro ? &datasheet->model.gyro : &datasheet->model.accel) : nullptr;
      fmt::print("{} triad ({} axes, one parameter set; written to the model):\n{}",
                 gyro ? "gyro" : "accelerometer", curves.size(),
                 calib::FormatNoiseFit(triad, gyro, reference,
                                       datasheet ? "datasheet " + datasheet->model.name : ""));
      if (triad.rate_ramp.determined) {
        fmt::print("  note: the rate ramp has no term in the sensor model; it is not written.\n");
      }
      (gyro ? model.gyro : model.accel) = calib::ToTriadErrorParams(triad);
      fmt::print("\n");
    }
    json = jobspec::SensorModelJson(model);
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }
  if (options.out_path.empty()) return kExitOk;
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

}  // namespace driftlab::cli
