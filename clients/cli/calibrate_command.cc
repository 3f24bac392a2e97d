// `driftlab calibrate accel|gyro|imu|reference DATA.csv [--rate HZ] [--lat DEG] [--height M]
//  --out CALIB.json [--report REPORT.html]`: multi-position calibration of a raw recording
// (Tedaldi et al., ICRA 2014) or a reference (rate-table / tilt) calibration; prints the
// parameters +- 1 sigma, writes the protobuf JSON of driftlab.v1.CalibrationResult
// (proto/driftlab/v1/calibration.proto) and, with --report, the HTML report
// (calibration_report.h: parameter table, residuals per pose / rotation / row).
//
// Data: accel|gyro|imu read `t_s, gx, gy, gz [rad/s], ax, ay, az [m/s^2]` rows (without t_s when
// --rate is given); reference reads `in_x, in_y, in_z, out_x, out_y, out_z` rows (known input in
// --input-unit, raw output in --output-unit) and fits each axis (or, with --matrix, the full
// sensitivity matrix). The header row is optional; columns are taken by position. The fits are
// app::RunCalibration (calibration_job.h), the core the gRPC Calibration service shares.
#include <fmt/format.h>
#include <google/protobuf/util/json_util.h>

#include <cstdio>
#include <fstream>
#include <memory>
#include <string>

#include "commands.h"
#include "driftlab/app/calibration_job.h"
#include "driftlab/report/calibration_report.h"
#include "driftlab/spec_error.h"
#include "driftlab/v1/calibration.pb.h"
#include "remote.h"

namespace driftlab::cli {
namespace {

struct CalibrateOptions {
  app::CalibrateSettings settings;
  std::string data_path;
  std::string out_path;
  std::string report_path;
  RemoteOptions remote;  // --server: fit on a driftlab-server (Calibration.Calibrate)
};

void PrintFit(const v1::CalibrationFitResult& fit) {
  fmt::print("{} fit: {} poses/rows, {} iterations, residual RMS {:.4g} {}, {:.1f} ms\n",
             fit.kind(), fit.poses_used(), fit.iterations(), fit.residual_rms(),
             fit.residual_unit(), 1e3 * fit.fit_time_s());
  fmt::print("  {:<24} {:>14}   {:>12}  {}\n", "parameter", "value", "1 sigma", "unit");
  for (const v1::CalibrationParameter& p : fit.parameters()) {
    fmt::print("  {:<24} {:>14.6g} +- {:>12.3g}  {}\n", p.name(), p.value(), p.sigma(), p.unit());
  }
  for (const std::string& m : fit.messages()) fmt::print("  note: {}\n", m);
}

int RunCalibrate(CalibrateOptions o) {
  v1::CalibrationResult result;
  app::NumericTable table;
  try {
    CheckCommandOutputs({{o.data_path, "DATA"}},
                        {{o.out_path, "--out"}, {o.report_path, "--report"}});
    o.settings.data_name = o.data_path;
    table = app::ReadNumericCsv(o.data_path);
    if (o.remote.server.empty()) {
      result = app::RunCalibration(o.settings, table);
    } else if (const int status = RemoteCalibrate(o.remote, o.settings, table, &result);
               status != kExitOk) {
      return status;
    }
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }
  for (const std::string& m : result.messages()) fmt::print("{}\n", m);
  for (const v1::CalibrationFitResult& fit : result.fits()) PrintFit(fit);
  std::string json;
  try {
    json = app::CalibrationResultToJson(result);
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitFailure;
  }
  if (const int status = WriteOutputText(o.out_path, json, "--out")) return status;
  if (o.report_path.empty()) return kExitOk;
  return WriteOutputText(
      o.report_path, app::RenderCalibrationReport(result, &table, o.settings.rate_hz), "--report");
}

const RegisterCommand kCalibrate("calibrate", [](CLI::App& app) -> std::function<int()> {
  auto o = std::make_shared<CalibrateOptions>();
  app::CalibrateSettings& s = o->settings;
  CLI::App* c = app.add_subcommand(
      "calibrate",
      "Multi-position (accel|gyro|imu) or reference calibration; parameters +- 1 sigma");
  c->add_option("kind", s.kind, "accel, gyro, imu (both) or reference")
      ->required()
      ->check(CLI::IsMember({"accel", "gyro", "imu", "reference"}));
  c->add_option("data", o->data_path,
                "CSV: t_s,gx,gy,gz [rad/s],ax,ay,az [m/s^2] (no t_s with --rate); reference: "
                "in_x,in_y,in_z,out_x,out_y,out_z")
      ->required();
  c->add_option("--rate", s.rate_hz, "Sample rate [Hz] when the file has no time column")
      ->check(CLI::PositiveNumber);
  c->add_option("--lat", s.lat_deg, "Latitude [deg] for local gravity")
      ->check(CLI::Range(-90.0, 90.0));
  c->add_option("--height", s.height_m, "Height above the ellipsoid [m]")
      ->check(CLI::Range(-1000.0, 10000.0));
  c->add_option("--init-static", s.init_static_s, "Initial static period [s] (default 20)");
  c->add_option("--window", s.window_s, "Moving-variance window [s] (default 1)");
  c->add_option("--min-pose", s.min_pose_s, "Shortest pose [s] (default 2)");
  c->add_option("--loss", s.loss, "Robust loss of the accel fit: none, huber, cauchy")
      ->check(CLI::IsMember({"none", "huber", "cauchy"}));
  c->add_flag("--matrix", s.matrix, "reference: fit the full 3x3 sensitivity matrix");
  c->add_option("--input-unit", s.input_unit, "reference: unit of the known inputs");
  c->add_option("--output-unit", s.output_unit, "reference: unit of the raw outputs");
  c->add_option("--out", o->out_path, "Result (CalibrationResult, protobuf JSON)")->required();
  AddRemoteOptions(c, &o->remote, false);
  c->add_option("--report", o->report_path,
                "Self-contained HTML report: parameters +- 1 sigma, residuals per pose, rotation "
                "or row, static-detection summary");
  return [o] { return RunCalibrate(*o); };
});

}  // namespace
}  // namespace driftlab::cli
