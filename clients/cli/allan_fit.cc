// RunAllanFit (allan_fit.h): option parsing, printing and file writing around
// app::RunNoiseFit (calibration_job.h), the core `driftlab allan --fit` shares with the gRPC
// Calibration service.
#include "allan_fit.h"

#include <fmt/format.h>
#include <google/protobuf/util/json_util.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "commands.h"
#include "driftlab/app/calibration_job.h"
#include "driftlab/report/calibration_report.h"
#include "driftlab/spec_error.h"
#include "driftlab/v1/job.pb.h"

namespace driftlab::cli {

std::vector<std::string> SplitColumnNames(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  std::string name;
  while (std::getline(in, name, ',')) {
    const size_t a = name.find_first_not_of(" \t"), b = name.find_last_not_of(" \t");
    out.push_back(a == std::string::npos ? "" : name.substr(a, b - a + 1));
  }
  return out;
}

int RunAllanFit(const AllanFitOptions& options) {
  v1::NoiseModelFit fit;
  try {
    if (!std::isfinite(options.rate_hz) || options.rate_hz <= 0.0) {
      throw SpecError("--rate", fmt::format("{:g}", options.rate_hz), "> 0 Hz (finite)");
    }
    if (options.points_per_octave < 1 || options.points_per_octave > 64) {
      throw SpecError("--points-per-octave", std::to_string(options.points_per_octave), "1 to 64");
    }
    CheckCommandOutputs({{options.data_path, "DATA"}, {options.datasheet_path, "--datasheet"}},
                        {{options.out_path, "--out"},
                         {options.fit_json_path, "--fit-json"},
                         {options.report_path, "--report"}});
    app::NoiseFitSettings settings;
    settings.rate_hz = options.rate_hz;
    settings.bias_model = options.bias_model;
    settings.points_per_octave = options.points_per_octave;
    settings.flicker_tau_min_s = options.flicker_tau_min_s;
    settings.flicker_tau_max_s = options.flicker_tau_max_s;
    settings.data_name = options.data_path;
    if (!options.datasheet_path.empty()) {
      std::ifstream in(options.datasheet_path, std::ios::binary);
      if (!in) {
        throw SpecError("--datasheet", "'" + options.datasheet_path + "'",
                        "an existing, readable datasheet summary (open failed)");
      }
      std::ostringstream text;
      text << in.rdbuf();
      settings.datasheet_yaml = text.str();
      settings.datasheet_source = options.datasheet_path;
    }
    // Without --columns the imu.csv columns are required (checked before any row is read).
    settings.columns = options.columns.empty()
                           ? std::vector<std::string>{"omega_x_rad_per_s", "omega_y_rad_per_s",
                                                      "omega_z_rad_per_s", "f_x_m_per_s2",
                                                      "f_y_m_per_s2",      "f_z_m_per_s2"}
                           : SplitColumnNames(options.columns);
    const app::NumericTable table = app::ReadNumericCsv(
        options.data_path, settings.columns, options.columns.empty() ? "DATA" : "--columns");
    fit = app::RunNoiseFit(settings, table);
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }
  for (const std::string& m : fit.messages()) {
    fmt::print("{}{}", m, !m.empty() && m.back() == '\n' ? "" : "\n");
  }
  if (fit.warnings_size() > 0) {
    fmt::print("{} warning(s) about the fit (also in --fit-json):\n", fit.warnings_size());
    for (const std::string& w : fit.warnings()) fmt::print("  WARNING {}\n", w);
  }
  fmt::print("fit time {:.3f} s\n", fit.fit_time_s());
  if (!options.fit_json_path.empty()) {
    std::string json;
    try {
      json = app::NoiseModelFitToJson(fit);
    } catch (const SpecError& e) {
      fmt::print(stderr, "error: {}\n", e.what());
      return kExitFailure;
    }
    if (const int status = WriteOutputText(options.fit_json_path, json, "--fit-json")) {
      return status;
    }
  }
  if (!options.out_path.empty()) {
    v1::Job job;
    *job.mutable_sensor() = fit.sensor();
    google::protobuf::util::JsonPrintOptions print;
    print.add_whitespace = true;
    print.preserve_proto_field_names = true;
    std::string json;
    if (!google::protobuf::util::MessageToJsonString(job, &json, print).ok()) {
      fmt::print(stderr, "error: cannot convert the model to JSON\n");
      return kExitFailure;
    }
    if (const int status = WriteOutputText(options.out_path, json, "--out")) return status;
  }
  if (options.report_path.empty()) return kExitOk;
  return WriteOutputText(options.report_path, app::RenderNoiseFitReport(fit, options.data_path),
                         "--report");
}

}  // namespace driftlab::cli
