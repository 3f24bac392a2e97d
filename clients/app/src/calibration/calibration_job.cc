// calibration_job.h: the core of `driftlab calibrate`, shared with the gRPC Calibration service.
// The numerical work is calib/ (multi_position.h, reference_calibration.h, static_detection.h);
// this file validates settings and tables and turns the results into calibration.proto messages.
// The CSV tables are csv_tables.cc, `driftlab allan --fit` is noise_fit_job.cc.
#include "driftlab/app/calibration_job.h"

#include <fmt/format.h>
#include <google/protobuf/util/json_util.h>

#include <algorithm>
#include <cmath>
#include <string_view>

#include "driftlab/calib/multi_position.h"
#include "driftlab/calib/reference_calibration.h"
#include "driftlab/calib/static_detection.h"
#include "driftlab/sensor_terms.h"
#include "driftlab/spec_error.h"
#include "driftlab/units.h"
#include "job/field_checks.h"
#include "text.h"

namespace driftlab::app {
namespace {

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
  for (double rho : fit.correlation) out->add_correlation(rho);
}

// True when the table came without a header row: its columns are named column1, column2, ...
// (ReadNumericCsv), so only their positions say what they hold.
bool WithoutHeader(const NumericTable& table) {
  for (size_t i = 0; i < table.columns.size(); ++i) {
    if (table.columns[i] != fmt::format("column{}", i + 1)) return false;
  }
  return true;
}

// The columns `expected` of `table`, in that order: taken by name from a header (in any order;
// the header must name exactly these columns), or by position from a file without one. Every
// value must be finite. `units` describes the columns for messages.
NumericTable SelectColumns(const NumericTable& table, const std::vector<std::string>& expected,
                           const std::string& units) {
  const size_t columns = table.columns.size();
  if (columns == 0 || table.values.size() % columns != 0) {
    throw SpecError("data",
                    fmt::format("{} values is not a whole number of rows of {} columns",
                                table.values.size(), columns),
                    0);
  }
  std::vector<size_t> from(expected.size());
  if (WithoutHeader(table)) {
    if (columns != expected.size()) {
      throw SpecError("data",
                      fmt::format("{} columns without a header; expected {} ({})", columns,
                                  expected.size(), units),
                      0);
    }
    for (size_t i = 0; i < from.size(); ++i) from[i] = i;
  } else {
    std::vector<std::string> missing, extra;
    for (size_t i = 0; i < expected.size(); ++i) {
      const auto it = std::find(table.columns.begin(), table.columns.end(), expected[i]);
      if (it == table.columns.end()) {
        missing.push_back(expected[i]);
      } else {
        from[i] = static_cast<size_t>(it - table.columns.begin());
      }
    }
    for (const std::string& name : table.columns) {
      if (std::find(expected.begin(), expected.end(), name) == expected.end()) {
        extra.push_back(name);
      }
    }
    if (!missing.empty() || !extra.empty()) {
      throw SpecError(
          "data: header",
          fmt::format("{}{}{}", Join(table.columns, ", "),
                      missing.empty() ? "" : " (missing " + Join(missing, ", ") + ")",
                      extra.empty() ? "" : " (unknown " + Join(extra, ", ") + ")"),
          fmt::format("a header naming the columns {} ({}), in any order; or no header, the "
                      "columns in that order",
                      Join(expected, ", "), units));
    }
  }
  NumericTable out;
  out.columns = expected;
  out.values.reserve(table.values.size() / columns * expected.size());
  for (size_t r = 0; r < table.rows(); ++r) {
    for (size_t i = 0; i < expected.size(); ++i) {
      const double v = table.values[r * columns + from[i]];
      if (!std::isfinite(v)) {
        throw SpecError(fmt::format("data: row {} column '{}'", r + 1, expected[i]),
                        fmt::format("{}", v), "a finite number");
      }
      out.values.push_back(v);
    }
  }
  return out;
}

// A fitted multi-position parameter outside the sensor model's own ranges (sensor_terms.h: the
// ranges a job accepts, beyond any real sensor) comes from data the model does not describe:
// clipped samples, mislabelled columns or other units. Throws SpecError naming the parameter.
void CheckPlausible(const calib::CalibrationFit& fit) {
  for (const calib::FitParameter& p : fit.parameters) {
    const bool gyro = p.name.starts_with("gyro.");
    const SensorTriad t = gyro ? SensorTriad::kGyro : SensorTriad::kAccel;
    int field = 0;  // the sensor term whose range applies
    if (p.name.find(".scale_factor.") != std::string::npos) field = 10;
    if (p.name.find(".misalignment.") != std::string::npos) field = 13;
    if (p.name.find(".bias.") != std::string::npos) field = 1;
    if (field == 0) continue;
    const SensorTerm& term = *SensorTermByField(field);
    const double limit = JobValueToSi(term, t, term.max(t), p.name);
    if (std::abs(p.value) <= limit) continue;
    throw SpecError(p.name, fmt::format("{} {}", p.value, p.unit),
                    fmt::format("|{}| <= {} {} ({} {}, the sensor model's range: no sensor has "
                                "more; the recording may be clipped, its columns mislabelled or "
                                "not in rad/s and m/s^2)",
                                p.name, limit, p.unit, term.max(t), JobUnitText(term, t)));
  }
}

// Fewest consecutive samples at a column's extreme that count as a flat top.
constexpr size_t kMinClippedRun = 10;

// Clipping (a saturated sensor) shows as flat tops: runs of samples exactly at a column's largest
// or smallest value, in a column that is noisy elsewhere (most consecutive samples differ). A
// noise-free or coarsely quantized recording repeats values everywhere and is not flagged.
// Throws SpecError naming the column, the level and the samples held there.
void CheckNotClipped(const NumericTable& table, size_t first_column, const std::string& unit_of) {
  const size_t columns = table.columns.size(), n = table.rows();
  if (n < 2 * kMinClippedRun) return;
  for (size_t c = first_column; c < columns; ++c) {
    const auto at = [&](size_t r) { return table.values[r * columns + c]; };
    double lo = at(0), hi = at(0);
    for (size_t r = 1; r < n; ++r) {
      lo = std::min(lo, at(r));
      hi = std::max(hi, at(r));
    }
    if (lo == hi) continue;
    for (const double level : {hi, lo}) {
      size_t held = 0, longest = 0, run = 0, changes = 0, pairs = 0;
      for (size_t r = 0; r < n; ++r) {
        run = at(r) == level ? run + 1 : 0;
        held += at(r) == level ? 1 : 0;
        longest = std::max(longest, run);
        if (r > 0 && at(r) != level && at(r - 1) != level) {
          ++pairs;
          changes += at(r) != at(r - 1) ? 1 : 0;
        }
      }
      const bool noisy_elsewhere = pairs > 0 && 2 * changes > pairs;
      if (longest >= kMinClippedRun && noisy_elsewhere) {
        throw SpecError(
            fmt::format("data: column '{}'", table.columns[c]),
            fmt::format("clipped at {} {}: {} samples sit exactly at the recording's {} (runs of "
                        "up to {}) while the column is noisy elsewhere",
                        level, unit_of, held, level == hi ? "maximum" : "minimum", longest),
            "a recording inside the sensor's range (a saturated sensor gives scale factors and "
            "biases no sensor has; record the poses within its range)");
      }
    }
  }
}

void CheckSettings(const CalibrateSettings& s) {
  if (s.kind != "accel" && s.kind != "gyro" && s.kind != "imu" && s.kind != "reference") {
    throw SpecError("kind", "'" + s.kind + "'", "accel, gyro, imu or reference");
  }
  Check("rate_hz", s.rate_hz, Closed(0.0, 1e6, "Hz (0: the data have a t_s column)"));
  Check("lat_deg", s.lat_deg, Closed(-90.0, 90.0, "deg"));
  Check("height_m", s.height_m, Closed(-1000.0, 10000.0, "m"));
  Check("init_static_s", s.init_static_s, Positive(86400.0, "s"));
  Check("window_s", s.window_s, Positive(3600.0, "s"));
  Check("min_pose_s", s.min_pose_s, Positive(3600.0, "s"));
  if (s.loss != "none" && s.loss != "huber" && s.loss != "cauchy") {
    throw SpecError("loss", "'" + s.loss + "'", "none, huber or cauchy");
  }
  if (s.kind == "reference") {
    if (s.input_unit.empty()) throw SpecError("input_unit", "", "a unit name, e.g. deg/s or g");
    // The known inputs are rates or accelerations, in a unit the units module knows.
    const Unit input = ParseUnit(s.input_unit, "input_unit");
    if (input.dimension != dims::kAngularRate && input.dimension != dims::kAcceleration) {
      throw SpecError("input_unit",
                      "'" + s.input_unit + "' (" + DimensionName(input.dimension) + ")",
                      "a unit of angular rate (deg/s, rad/s, ...) or acceleration (g, m/s^2, ...)");
    }
    // The raw outputs are in the sensor's own unit (V, counts, LSB): a short printable name.
    const bool printable = std::all_of(s.output_unit.begin(), s.output_unit.end(), [](char c) {
      return static_cast<unsigned char>(c) >= 0x20 && static_cast<unsigned char>(c) < 0x7F;
    });
    if (s.output_unit.empty() || s.output_unit.size() > 32 || !printable) {
      throw SpecError("output_unit", s.output_unit.empty() ? "" : "'" + s.output_unit + "'",
                      "a unit name of 1 to 32 printable ASCII characters, e.g. V or counts");
    }
  }
}

void RunReference(const CalibrateSettings& s, const NumericTable& data,
                  v1::CalibrationResult* result) {
  const NumericTable table = SelectColumns(
      data, {"in_x", "in_y", "in_z", "out_x", "out_y", "out_z"}, "known inputs, raw outputs");
  const size_t n = table.rows();
  const auto at = [&](size_t row, size_t col) { return table.values[row * 6 + col]; };
  if (s.matrix) {
    std::vector<Eigen::Vector3d> in(n), out(n);
    for (size_t r = 0; r < n; ++r) {
      in[r] = {at(r, 0), at(r, 1), at(r, 2)};
      out[r] = {at(r, 3), at(r, 4), at(r, 5)};
    }
    AddFit(calib::FitReferenceMatrix(in, out, s.input_unit, s.output_unit).fit, result);
    return;
  }
  const char* axes[3] = {"x", "y", "z"};
  for (size_t a = 0; a < 3; ++a) {
    std::vector<double> in(n), out(n);
    for (size_t r = 0; r < n; ++r) {
      in[r] = at(r, a);
      out[r] = at(r, 3 + a);
    }
    AddFit(calib::FitReferenceAxis(in, out, axes[a], s.input_unit, s.output_unit).fit, result);
  }
}

void RunMultiPosition(const CalibrateSettings& s, const NumericTable& data,
                      v1::CalibrationResult* result) {
  const bool has_time = s.rate_hz == 0.0;
  std::vector<std::string> names = {"gx", "gy", "gz", "ax", "ay", "az"};
  if (has_time) names.insert(names.begin(), "t_s");
  const NumericTable table = SelectColumns(
      data, names,
      has_time ? "t_s [s], gyro rates [rad/s], specific forces [m/s^2]; without t_s with rate_hz"
               : "gyro rates [rad/s], specific forces [m/s^2] with rate_hz; with t_s without it");
  CheckNotClipped(table, has_time ? 1 : 0, "(rad/s or m/s^2)");
  const size_t columns = table.columns.size(), o = has_time ? 1 : 0;
  calib::RawImuRecording rec;
  const size_t n = table.rows();
  rec.t_s.resize(n);
  rec.omega_ib_s.resize(n);
  rec.f_ib_s.resize(n);
  for (size_t k = 0; k < n; ++k) {
    const double* row = &table.values[k * columns];
    rec.t_s[k] = has_time ? row[0] : static_cast<double>(k) / s.rate_hz;
    rec.omega_ib_s[k] = {row[o], row[o + 1], row[o + 2]};
    rec.f_ib_s[k] = {row[o + 3], row[o + 4], row[o + 5]};
  }
  calib::ValidateRecording(rec, "data");
  calib::StaticDetectionOptions so;
  so.init_static_s = s.init_static_s;
  so.window_s = s.window_s;
  so.min_pose_s = s.min_pose_s;
  const calib::StaticDetection det = calib::DetectStaticIntervals(rec, so);
  result->add_messages(fmt::format(
      "{} samples at {:.4g} Hz; {} static poses (threshold {:.3g} (m/s^2)^2 = {} x initial "
      "variance {:.3g})",
      rec.size(), det.rate_hz, det.intervals.size(), det.threshold, so.threshold_factor,
      det.init_variance_norm));
  for (size_t p = 0; p < det.intervals.size(); ++p) {
    const calib::StaticInterval& iv = det.intervals[p];
    result->add_messages(fmt::format(
        "pose {}: t {:.3f}-{:.3f} s ({} samples), mean f [{:.5f}, {:.5f}, {:.5f}] m/s^2", p,
        iv.t_begin_s, iv.t_end_s, iv.count(), iv.mean_f_ib_s.x(), iv.mean_f_ib_s.y(),
        iv.mean_f_ib_s.z()));
  }
  calib::AccelCalibrationOptions ao;
  ao.lat_rad = s.lat_deg * M_PI / 180.0;
  ao.h_m = s.height_m;
  if (s.loss == "huber") ao.loss = calib::RobustLoss::kHuber;
  if (s.loss == "cauchy") ao.loss = calib::RobustLoss::kCauchy;
  const calib::AccelCalibration accel = calib::CalibrateAccelerometers(det.intervals, ao);
  CheckPlausible(accel.fit);
  if (s.kind != "gyro") AddFit(accel.fit, result);
  if (s.kind != "accel") {
    const calib::GyroCalibration gyro =
        calib::CalibrateGyros(rec, det.intervals, accel, calib::GyroCalibrationOptions{});
    CheckPlausible(gyro.fit);
    AddFit(gyro.fit, result);
  }
}

}  // namespace

v1::CalibrationResult RunCalibration(const CalibrateSettings& settings, const NumericTable& table) {
  CheckSettings(settings);
  v1::CalibrationResult result;
  result.set_kind(settings.kind);
  result.set_data_file(settings.data_name);
  result.set_lat_deg(settings.lat_deg);
  result.set_height_m(settings.height_m);
  if (settings.kind == "reference") {
    RunReference(settings, table, &result);
  } else {
    RunMultiPosition(settings, table, &result);
  }
  return result;
}

std::string CalibrationResultToJson(const v1::CalibrationResult& result) {
  google::protobuf::util::JsonPrintOptions print;
  print.add_whitespace = true;
  print.preserve_proto_field_names = true;
  print.always_print_primitive_fields = true;
  std::string json;
  if (!google::protobuf::util::MessageToJsonString(result, &json, print).ok()) {
    throw SpecError("result", "the calibration result cannot be printed as JSON", 0);
  }
  return json;
}

}  // namespace driftlab::app
