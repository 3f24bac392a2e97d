// `driftlab calibrate accel|gyro|imu|reference DATA.csv [--rate HZ] [--lat DEG] [--height M]
//  --out CALIB.json`: multi-position calibration of a raw recording (Tedaldi et al., ICRA 2014) or
// a reference (rate-table / tilt) calibration; prints the parameters +- 1 sigma and writes the
// protobuf JSON of driftlab.v1.CalibrationResult (proto/driftlab/v1/calibration.proto).
//
// Data: accel|gyro|imu read `t_s, gx, gy, gz [rad/s], ax, ay, az [m/s^2]` rows (without t_s when
// --rate is given); reference reads `in_x, in_y, in_z, out_x, out_y, out_z` rows (known input in
// --input-unit, raw output in --output-unit) and fits each axis (or, with --matrix, the full
// sensitivity matrix).
#include <fmt/format.h>
#include <google/protobuf/util/json_util.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "commands.h"
#include "driftlab/calib/multi_position.h"
#include "driftlab/calib/reference_calibration.h"
#include "driftlab/calib/static_detection.h"
#include "driftlab/spec_error.h"
#include "driftlab/v1/calibration.pb.h"

namespace driftlab::cli {
namespace {

struct CalibrateOptions {
  std::string kind;
  std::string data_path;
  std::string out_path;
  double rate_hz = 0.0;
  double lat_deg = 0.0;
  double height_m = 0.0;
  double init_static_s = 20.0;
  double window_s = 1.0;
  double min_pose_s = 2.0;
  std::string loss = "none";
  bool matrix = false;
  std::string input_unit = "input";
  std::string output_unit = "V";
};

void AddFit(const calib::CalibrationFit& fit, v1::CalibrationResult* result) {
  v1::CalibrationFitResult* out = result->add_fits();
  out->set_kind(fit.kind);
  for (const calib::FitParameter& p : fit.parameters) {
    v1::CalibrationParameter* q = out->add_parameters();
    q->set_name(p.name);
    q->set_value(p.value);
    q->set_unit(p.unit);
    q->set_sigma(p.sigma);
  }
  out->set_residual_rms(fit.residual_rms);
  out->set_residual_unit(fit.residual_unit);
  out->set_iterations(fit.iterations);
  out->set_poses_used(fit.poses_used);
  for (double r : fit.residuals) out->add_residuals(r);
  out->set_fit_time_s(fit.fit_time_s);
  for (const std::string& m : fit.messages) out->add_messages(m);
}

void PrintFit(const calib::CalibrationFit& fit) {
  fmt::print("{} fit: {} poses/rows, {} iterations, residual RMS {:.4g} {}, {:.1f} ms\n", fit.kind,
             fit.poses_used, fit.iterations, fit.residual_rms, fit.residual_unit,
             1e3 * fit.fit_time_s);
  fmt::print("  {:<24} {:>14}   {:>12}  {}\n", "parameter", "value", "1 sigma", "unit");
  for (const calib::FitParameter& p : fit.parameters) {
    fmt::print("  {:<24} {:>14.6g} +- {:>12.3g}  {}\n", p.name, p.value, p.sigma, p.unit);
  }
  for (const std::string& m : fit.messages) fmt::print("  note: {}\n", m);
}

std::vector<std::vector<double>> ReadRows(const std::string& path, size_t columns) {
  std::ifstream in(path);
  if (!in) throw SpecError(path, "cannot open the file", 0);
  std::vector<std::vector<double>> rows;
  std::string line;
  int line_no = 0;
  bool first = true;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line[0] == '#' || line.find_first_not_of(" \t\r") == std::string::npos) {
      continue;
    }
    std::vector<double> row;
    std::stringstream fields(line);
    std::string field;
    bool numeric = true;
    while (std::getline(fields, field, ',')) {
      try {
        size_t used = 0;
        row.push_back(std::stod(field, &used));
        if (field.find_first_not_of(" \t\r", used) != std::string::npos) numeric = false;
      } catch (const std::exception&) {
        numeric = false;
      }
      if (!numeric) break;
    }
    if (!numeric) {
      if (first) {
        first = false;
        continue;  // header
      }
      throw SpecError(fmt::format("{}:{}", path, line_no), "a field is not a number", 0);
    }
    first = false;
    if (row.size() != columns) {
      throw SpecError(fmt::format("{}:{}", path, line_no),
                      fmt::format("{} columns; expected {} (in_x, in_y, in_z, out_x, out_y, out_z)",
                                  row.size(), columns),
                      0);
    }
    for (double v : row) {
      if (!std::isfinite(v)) {
        throw SpecError(fmt::format("{}:{}", path, line_no), "a value is not finite", 0);
      }
    }
    rows.push_back(row);
  }
  return rows;
}

int RunCalibrate(const CalibrateOptions& o) {
  v1::CalibrationResult result;
  result.set_kind(o.kind);
  result.set_data_file(o.data_path);
  result.set_lat_deg(o.lat_deg);
  result.set_height_m(o.height_m);
  try {
    if (o.kind == "reference") {
      const auto rows = ReadRows(o.data_path, 6);
      if (o.matrix) {
        std::vector<Eigen::Vector3d> in, out;
        for (const auto& r : rows) {
          in.emplace_back(r[0], r[1], r[2]);
          out.emplace_back(r[3], r[4], r[5]);
        }
        const calib::MatrixReferenceFit fit =
            calib::FitReferenceMatrix(in, out, o.input_unit, o.output_unit);
        PrintFit(fit.fit);
        AddFit(fit.fit, &result);
      } else {
        const char* axes[3] = {"x", "y", "z"};
        for (int a = 0; a < 3; ++a) {
          std::vector<double> in, out;
          for (const auto& r : rows) {
            in.push_back(r[a]);
            out.push_back(r[3 + a]);
          }
          const calib::AxisReferenceFit fit =
              calib::FitReferenceAxis(in, out, axes[a], o.input_unit, o.output_unit);
          PrintFit(fit.fit);
          AddFit(fit.fit, &result);
        }
      }
    } else {
      const calib::RawImuRecording rec = calib::ReadRawImuCsv(o.data_path, o.rate_hz);
      calib::StaticDetectionOptions so;
      so.init_static_s = o.init_static_s;
      so.window_s = o.window_s;
      so.min_pose_s = o.min_pose_s;
      const calib::StaticDetection det = calib::DetectStaticIntervals(rec, so);
      const std::string summary = fmt::format(
          "{} samples at {:.4g} Hz; {} static poses (threshold {:.3g} (m/s^2)^2 = {} x initial "
          "variance {:.3g})",
          rec.size(), det.rate_hz, det.intervals.size(), det.threshold, so.threshold_factor,
          det.init_variance_norm);
      fmt::print("{}\n", summary);
      result.add_messages(summary);
      calib::AccelCalibrationOptions ao;
      ao.lat_rad = o.lat_deg * M_PI / 180.0;
      ao.h_m = o.height_m;
      if (o.loss == "huber") ao.loss = calib::RobustLoss::kHuber;
      if (o.loss == "cauchy") ao.loss = calib::RobustLoss::kCauchy;
      const calib::AccelCalibration accel = calib::CalibrateAccelerometers(det.intervals, ao);
      if (o.kind != "gyro") {
        PrintFit(accel.fit);
        AddFit(accel.fit, &result);
      }
      if (o.kind != "accel") {
        const calib::GyroCalibration gyro =
            calib::CalibrateGyros(rec, det.intervals, accel, calib::GyroCalibrationOptions{});
        PrintFit(gyro.fit);
        AddFit(gyro.fit, &result);
      }
    }
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }
  std::string json;
  google::protobuf::util::JsonPrintOptions print;
  print.add_whitespace = true;
  print.preserve_proto_field_names = true;
  print.always_print_primitive_fields = true;
  if (!google::protobuf::util::MessageToJsonString(result, &json, print).ok()) {
    fmt::print(stderr, "error: cannot convert the result to JSON\n");
    return kExitFailure;
  }
  std::ofstream out(o.out_path);
  out << json;
  if (!out) {
    fmt::print(stderr, "error: cannot write {}\n", o.out_path);
    return kExitFailure;
  }
  fmt::print("wrote {}\n", o.out_path);
  return kExitOk;
}

const RegisterCommand kCalibrate("calibrate", [](CLI::App& app) -> std::function<int()> {
  auto o = std::make_shared<CalibrateOptions>();
  CLI::App* c = app.add_subcommand(
      "calibrate",
      "Multi-position (accel|gyro|imu) or reference calibration; parameters +- 1 sigma");
  c->add_option("kind", o->kind, "accel, gyro, imu (both) or reference")
      ->required()
      ->check(CLI::IsMember({"accel", "gyro", "imu", "reference"}));
  c->add_option("data", o->data_path,
                "CSV: t_s,gx,gy,gz [rad/s],ax,ay,az [m/s^2] (no t_s with --rate); reference: "
                "in_x,in_y,in_z,out_x,out_y,out_z")
      ->required();
  c->add_option("--rate", o->rate_hz, "Sample rate [Hz] when the file has no time column")
      ->check(CLI::PositiveNumber);
  c->add_option("--lat", o->lat_deg, "Latitude [deg] for local gravity")
      ->check(CLI::Range(-90.0, 90.0));
  c->add_option("--height", o->height_m, "Height above the ellipsoid [m]")
      ->check(CLI::Range(-1000.0, 10000.0));
  c->add_option("--init-static", o->init_static_s, "Initial static period [s] (default 20)");
  c->add_option("--window", o->window_s, "Moving-variance window [s] (default 1)");
  c->add_option("--min-pose", o->min_pose_s, "Shortest pose [s] (default 2)");
  c->add_option("--loss", o->loss, "Robust loss of the accel fit: none, huber, cauchy")
      ->check(CLI::IsMember({"none", "huber", "cauchy"}));
  c->add_flag("--matrix", o->matrix, "reference: fit the full 3x3 sensitivity matrix");
  c->add_option("--input-unit", o->input_unit, "reference: unit of the known inputs");
  c->add_option("--output-unit", o->output_unit, "reference: unit of the raw outputs");
  c->add_option("--out", o->out_path, "Result (CalibrationResult, protobuf JSON)")->required();
  return [o] { return RunCalibrate(*o); };
});

}  // namespace
}  // namespace driftlab::cli
