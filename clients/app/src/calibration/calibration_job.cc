// calibration_job.h: the cores of `driftlab calibrate` and `driftlab allan --fit`, shared with the
// gRPC Calibration service. The numerical work is calib/ (multi_position.h,
// reference_calibration.h, static_detection.h, noise_fit.h); this file validates settings and
// tables and turns the results into calibration.proto messages.
#include "driftlab/app/calibration_job.h"

#include <fmt/format.h>
#include <google/protobuf/util/json_util.h>

#include <charconv>
#include <chrono>
#include <cmath>
#include <fstream>
#include <optional>
#include <string_view>

#include "driftlab/allan.h"
#include "driftlab/app/sensor_model_json.h"
#include "driftlab/calib/datasheet.h"
#include "driftlab/calib/multi_position.h"
#include "driftlab/calib/noise_fit.h"
#include "driftlab/calib/reference_calibration.h"
#include "driftlab/calib/static_detection.h"
#include "driftlab/input_files.h"
#include "driftlab/sensor_terms.h"
#include "driftlab/spec_error.h"
#include "driftlab/units.h"
#include "job/field_checks.h"
#include "text.h"

namespace driftlab::app {
namespace {

// Fewest samples with two overlapping second differences at tau = 1 / rate (n + 1 - 2m >= 2 for
// m = 1), the least the overlapping estimator can average (allan.h).
constexpr size_t kMinAllanSamples = 3;

const std::vector<std::string> kImuCsvColumns = {"omega_x_rad_per_s", "omega_y_rad_per_s",
                                                 "omega_z_rad_per_s", "f_x_m_per_s2",
                                                 "f_y_m_per_s2",      "f_z_m_per_s2"};

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) {
    s.remove_suffix(1);
  }
  return s;
}

// Splits at `sep` into trimmed views of `line` (no allocation when `fields` has capacity).
void SplitInto(std::string_view line, char sep, std::vector<std::string_view>* fields) {
  fields->clear();
  size_t start = 0;
  while (true) {
    const size_t end = line.find(sep, start);
    fields->push_back(Trim(line.substr(start, end == std::string_view::npos ? end : end - start)));
    if (end == std::string_view::npos) return;
    start = end + 1;
  }
}

std::vector<std::string> Split(std::string_view line, char sep) {
  std::vector<std::string_view> views;
  SplitInto(line, sep, &views);
  return {views.begin(), views.end()};
}

// The reader behind both ReadNumericCsv overloads; `selected` empty = every column.
NumericTable ReadCsv(const std::string& path, const std::vector<std::string>* selected,
                     const std::string& columns_field) {
  std::ifstream in = OpenInputFile(path, kMaxRecordingFileBytes, "DATA");
  NumericTable table;
  std::string line;
  size_t line_no = 0;
  std::vector<std::string_view> fields;
  std::vector<std::string> header;
  std::vector<size_t> take;  // header index of each kept column
  bool have_header = false;
  bool pending_data = false;  // the first line was data (no header)
  const auto where = [&] { return fmt::format("{}:{}", path, line_no + 1); };
  while (ReadLine(in, &line, where())) {
    ++line_no;
    const std::string_view t = Trim(line);
    if (t.empty() || t.front() == '#') continue;
    SplitInto(t, ',', &fields);
    bool numeric = true;
    for (std::string_view f : fields) {
      double v = 0.0;
      numeric = numeric && ParseWholeNumber(f, &v);
    }
    if (numeric && selected == nullptr) {
      for (size_t i = 0; i < fields.size(); ++i) header.push_back(fmt::format("column{}", i + 1));
      pending_data = true;
    } else {
      header.assign(fields.begin(), fields.end());
    }
    have_header = true;
    break;
  }
  if (header.size() > kMaxCsvColumns) {
    throw SpecError(fmt::format("{}:{}", path, line_no), fmt::format("{} columns", header.size()),
                    fmt::format("at most {} columns", kMaxCsvColumns));
  }
  for (size_t i = 0; i < header.size(); ++i) {
    if (header[i].size() > kMaxCsvColumnNameBytes) {
      throw SpecError(fmt::format("{}:{}: column {}", path, line_no, i + 1), "'" + header[i] + "'",
                      fmt::format("a column name of at most {} bytes", kMaxCsvColumnNameBytes));
    }
    for (size_t j = 0; j < i; ++j) {
      if (header[i] == header[j]) {
        throw SpecError(fmt::format("{}:{}: column {}", path, line_no, i + 1),
                        "'" + header[i] + "' (also column " + std::to_string(j + 1) + ")",
                        "distinct column names");
      }
    }
  }
  if (!have_header) {
    throw SpecError("DATA", "'" + path + "' (empty)", "a header row and numeric rows");
  }
  if (selected == nullptr) {
    for (size_t i = 0; i < header.size(); ++i) take.push_back(i);
  } else {
    for (const std::string& name : *selected) {
      const auto it = std::find(header.begin(), header.end(), name);
      if (it == header.end()) {
        throw SpecError(columns_field, "'" + name + "'",
                        "a column of " + path + ": " + Join(header, ", "));
      }
      take.push_back(static_cast<size_t>(it - header.begin()));
    }
  }
  for (size_t i : take) table.columns.push_back(header[i]);
  const auto parse_row = [&](size_t row_line) {
    if (fields.size() != header.size()) {
      throw SpecError(fmt::format("{}:{}", path, row_line),
                      fmt::format("{} columns; expected {} ({} fields where the header has {} "
                                  "fields: {})",
                                  fields.size(), header.size(), fields.size(), header.size(),
                                  Join(header, ", ")),
                      0);
    }
    for (size_t i : take) {
      double value = 0.0;
      if (!ParseWholeNumber(fields[i], &value) || !std::isfinite(value)) {
        throw SpecError(fmt::format("{}:{}: column '{}'", path, row_line, header[i]),
                        "'" + std::string(fields[i]) + "'", "a finite number");
      }
      table.values.push_back(value);
    }
  };
  if (pending_data) parse_row(line_no);
  while (ReadLine(in, &line, where())) {
    ++line_no;
    const std::string_view t = Trim(line);
    if (t.empty() || t.front() == '#') continue;
    SplitInto(t, ',', &fields);
    parse_row(line_no);
  }
  return table;
}

bool IsTimeColumn(std::string name) {
  std::transform(name.begin(), name.end(), name.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return name == "t" || name.rfind("t_", 0) == 0 || name.rfind("time", 0) == 0;
}

// Rates, or increments of them.
bool AcceptedDimension(Dimension d) {
  return d == dims::kAngularRate || d == dims::kAcceleration || d == dims::kAngle ||
         d == dims::kVelocity;
}

constexpr const char* kAllowedUnits =
    "an angular rate (rad/s, deg/s, deg/h), an acceleration (m/s^2, g, mg, ug) or an increment "
    "(rad, deg, m/s)";

void SetUnit(RateColumn* column, const std::string& text, const Unit& unit) {
  column->unit = text;
  column->gyro = unit.dimension.angle2 != 0;
  column->increment = unit.dimension == dims::kAngle || unit.dimension == dims::kVelocity;
}

// Unit from the name's suffix: the longest tail of '_'-separated words that parses as a unit of
// an accepted dimension ("per" = '/'). Returns false if no tail does.
// Tails are built from the end, one word at a time, and no longer than a unit text may be
// (kMaxUnitTextBytes), so the search is linear in the name's length.
bool UnitFromName(RateColumn* column) {
  const std::vector<std::string> words = Split(column->name, '_');
  std::string tail;
  bool found = false;
  for (size_t first = words.size(); first-- > 1;) {
    const std::string word = words[first] == "per" ? std::string("/") : words[first];
    tail = tail.empty() ? word : word + " " + tail;
    if (tail.size() > kMaxUnitTextBytes) break;
    try {
      const Unit unit = ParseUnit(tail, column->name);
      if (AcceptedDimension(unit.dimension)) {
        SetUnit(column, tail, unit);  // a longer tail found later replaces it
        found = true;
      }
    } catch (const SpecError&) {
      // Not a unit: try a longer tail.
    }
  }
  return found;
}

// ---------------------------------------------------------------------------------------------
// Calibration

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

// ---------------------------------------------------------------------------------------------
// Noise fit

calib::BiasModel ParseBiasModel(const std::string& name) {
  if (name == "flicker" || name.empty()) return calib::BiasModel::kFlickerFlat;
  if (name == "flicker-band") return calib::BiasModel::kFlickerBand;
  if (name == "gauss-markov") return calib::BiasModel::kGaussMarkov;
  if (name == "none") return calib::BiasModel::kNone;
  throw SpecError("bias_model", "'" + name + "'", "flicker, flicker-band, gauss-markov or none");
}

// SI units of the terms (noise_fit.h model).
struct TermUnits {
  const char* white;
  const char* instability;
  const char* random_walk;
  const char* quantization;
  const char* ramp;
};
constexpr TermUnits kGyroTermUnits{"rad/sqrt(s)", "rad/s", "rad/s/sqrt(s)", "rad", "rad/s^2"};
constexpr TermUnits kAccelTermUnits{"m/s/sqrt(s)", "m/s^2", "m/s^2/sqrt(s)", "m/s", "m/s^3"};

void AddTerms(const calib::NoiseFitResult& fit, bool gyro, const std::string& axis,
              const TriadErrorParams* datasheet, v1::NoiseModelFit* out) {
  const TermUnits& u = gyro ? kGyroTermUnits : kAccelTermUnits;
  const bool gm = fit.bias_model == calib::BiasModel::kGaussMarkov;
  struct Row {
    const char* name;
    const calib::NoiseTermEstimate* term;
    const char* unit;
    double datasheet;  // SI; 0 = no figure
  };
  const std::vector<Row> rows = {
      {"white_noise", &fit.white_noise, u.white, datasheet ? datasheet->white_noise_density : 0},
      {gm ? "gauss_markov_sigma" : "bias_instability", &fit.bias_instability, u.instability,
       datasheet
           ? (gm ? datasheet->bias_gauss_markov.sigma : datasheet->bias_flicker.bias_instability)
           : 0},
      {"gauss_markov_tau", &fit.gauss_markov_tau_s, "s",
       datasheet && gm ? datasheet->bias_gauss_markov.tau_s : 0},
      {"random_walk", &fit.random_walk, u.random_walk, datasheet ? datasheet->random_walk : 0},
      // IEEE Q = LSB / sqrt(12) (noise_fit.h ToTriadErrorParams).
      {"quantization", &fit.quantization, u.quantization,
       datasheet ? datasheet->quantization / std::sqrt(12.0) : 0},
      {"rate_ramp", &fit.rate_ramp, u.ramp, 0},
  };
  const char* triad = gyro ? "gyro" : "accel";
  v1::NoiseFitQuality* q = out->add_quality();
  q->set_triad(triad);
  q->set_axis(axis);
  q->set_points(fit.n_points);
  q->set_points_outside_95(fit.points_outside_95);
  q->set_expected_outside_95(fit.expected_outside_95);
  q->set_max_plausible_outside_95(fit.max_plausible_outside_95);
  for (const double tau : fit.tau_outside_95_s) q->add_tau_outside_95_s(tau);
  q->set_chi2(fit.chi2);
  q->set_dof(fit.n_points - fit.n_parameters);
  q->set_chi2_low(fit.chi2_low);
  q->set_chi2_high(fit.chi2_high);
  for (const std::string& w : fit.warnings) {
    q->add_warnings(w);
    out->add_warnings(fmt::format("{} {}: {}", triad, axis, w));
  }
  for (const Row& row : rows) {
    if (!row.term->fitted) continue;
    v1::NoiseTerm* t = out->add_terms();
    t->set_triad(triad);
    t->set_axis(axis);
    t->set_name(row.name);
    t->set_unit(row.unit);
    t->set_value(row.term->determined ? row.term->value : 0.0);
    t->set_sigma(row.term->determined ? row.term->sigma : NAN);
    t->set_determined(row.term->determined);
    t->set_lower_95(row.term->lower_95);
    t->set_upper_95(row.term->upper_95);
    t->set_upper_bound(row.term->upper_bound);
    t->set_lr_statistic(row.term->lr_statistic);
    t->set_lr_threshold(row.term->lr_threshold);
    if (datasheet != nullptr && row.datasheet > 0.0) t->set_datasheet_value(row.datasheet);
    if (!row.term->determined && axis == "triad") {
      out->add_messages(
          std::isfinite(row.term->upper_bound)
              ? fmt::format("{} {} {}: not determined by the data (< {:.3g} {}, 95 % "
                            "one-sided upper bound)",
                            triad, axis, row.name, row.term->upper_bound, row.unit)
              : fmt::format("{} {} {}: not determined by the data", triad, axis, row.name));
    }
  }
}

}  // namespace

NumericTable ReadNumericCsv(const std::string& path) { return ReadCsv(path, nullptr, ""); }

NumericTable ReadNumericCsv(const std::string& path, const std::vector<std::string>& columns,
                            const std::string& columns_field) {
  return ReadCsv(path, &columns, columns_field);
}

std::vector<RateColumn> SelectRateColumns(const NumericTable& table,
                                          const std::vector<std::string>& names,
                                          const std::string& unit, double rate_hz,
                                          const std::string& data_name,
                                          const std::string& columns_field,
                                          const std::string& unit_field) {
  const size_t width = table.columns.size();
  if (width == 0 || table.values.size() % width != 0) {
    throw SpecError("data",
                    fmt::format("{} values in rows of {} columns", table.values.size(), width), 0);
  }
  const auto find = [&](const std::string& name) -> long {
    const auto it = std::find(table.columns.begin(), table.columns.end(), name);
    return it == table.columns.end() ? -1 : static_cast<long>(it - table.columns.begin());
  };
  std::vector<std::pair<std::string, size_t>> chosen;
  if (!names.empty()) {
    for (const std::string& name : names) {
      const long index = find(name);
      if (index < 0) {
        throw SpecError(columns_field, name.empty() ? "''" : "'" + name + "'",
                        "a column of " + data_name + ": " + Join(table.columns, ", "));
      }
      chosen.emplace_back(name, static_cast<size_t>(index));
    }
  } else {
    const bool imu = std::all_of(kImuCsvColumns.begin(), kImuCsvColumns.end(),
                                 [&](const std::string& n) { return find(n) >= 0; });
    for (size_t i = 0; i < width; ++i) {
      const std::string& name = table.columns[i];
      const bool take = imu ? std::find(kImuCsvColumns.begin(), kImuCsvColumns.end(), name) !=
                                  kImuCsvColumns.end()
                            : !IsTimeColumn(name);
      if (take) chosen.emplace_back(name, i);
    }
    if (chosen.empty()) {
      throw SpecError("data", data_name + " (only a time column)",
                      "at least one column besides the time column");
    }
  }
  std::optional<Unit> common;
  if (!unit.empty()) {
    common = ParseUnit(unit, unit_field);
    if (!AcceptedDimension(common->dimension)) {
      throw SpecError(unit_field, "'" + unit + "' (" + DimensionName(common->dimension) + ")",
                      kAllowedUnits);
    }
  }
  const size_t rows = table.rows();
  std::vector<RateColumn> out;
  for (const auto& [name, index] : chosen) {
    RateColumn column;
    column.name = name;
    if (common) {
      SetUnit(&column, unit, *common);
    } else if (!UnitFromName(&column)) {
      throw SpecError(
          unit_field, "missing",
          fmt::format("a unit for column '{}' of {}: its name has no unit suffix (such as "
                      "_rad_per_s, _deg_per_s, _deg_per_h, _m_per_s2, _g, _mg); give {} as {}",
                      name, data_name, unit_field, kAllowedUnits));
    }
    const Unit parsed = ParseUnit(column.unit, unit_field);
    const double to_si = parsed.si_factor * (column.increment ? rate_hz : 1.0);
    if (rows < kMinAllanSamples) {
      throw SpecError(fmt::format("{}: column '{}'", data_name, name),
                      fmt::format("{} samples", rows),
                      fmt::format("at least {} samples (two overlapping second differences at "
                                  "tau = 1 / rate)",
                                  kMinAllanSamples));
    }
    column.samples.resize(rows);
    for (size_t r = 0; r < rows; ++r) {
      const double v = table.values[r * width + index];
      if (!std::isfinite(v)) {
        throw SpecError(fmt::format("{}: row {} column '{}'", data_name, r + 1, name),
                        fmt::format("{}", v), "a finite number");
      }
      column.samples[r] = v * to_si;
    }
    out.push_back(std::move(column));
  }
  return out;
}

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

v1::NoiseModelFit RunNoiseFit(const NoiseFitSettings& settings, const NumericTable& table) {
  const auto start = std::chrono::steady_clock::now();
  Check("rate_hz", settings.rate_hz, Positive(1e6, "Hz"));
  if (settings.points_per_octave < 1 || settings.points_per_octave > 64) {
    throw SpecError("points_per_octave", std::to_string(settings.points_per_octave), "1 to 64");
  }
  Check("flicker_tau_min_s", settings.flicker_tau_min_s, Closed(0.0, 1e9, "s (0 = first tau)"));
  Check("flicker_tau_max_s", settings.flicker_tau_max_s, Closed(0.0, 1e9, "s (0 = last tau)"));
  if (settings.flicker_tau_max_s > 0.0 &&
      settings.flicker_tau_max_s <= settings.flicker_tau_min_s) {
    throw SpecError("flicker_tau_max_s", fmt::format("{}", settings.flicker_tau_max_s),
                    fmt::format("> flicker_tau_min_s = {} s", settings.flicker_tau_min_s));
  }
  calib::NoiseFitOptions fit_options;
  fit_options.bias_model = ParseBiasModel(settings.bias_model);
  fit_options.flicker_tau_min_s = settings.flicker_tau_min_s;
  fit_options.flicker_tau_max_s = settings.flicker_tau_max_s;
  std::optional<calib::DatasheetModel> datasheet;
  if (!settings.datasheet_yaml.empty()) {
    datasheet = calib::DatasheetToModel(
        calib::ParseDatasheetText(settings.datasheet_yaml, settings.datasheet_source));
  }
  const std::vector<RateColumn> columns = SelectRateColumns(
      table, settings.columns, "", settings.rate_hz, settings.data_name, "columns", "columns");

  v1::NoiseModelFit out;
  ImuErrorModel model;
  model.name = "allan-fit";
  model.description = "noise terms fitted to the Allan deviation of " + settings.data_name;
  std::vector<std::string> notes;
  for (const bool gyro : {true, false}) {
    std::vector<std::vector<AllanPoint>> curves;
    std::vector<const RateColumn*> used;
    for (const RateColumn& c : columns) {
      if (c.gyro != gyro) continue;
      AllanOptions allan;
      allan.points_per_octave = settings.points_per_octave;
      // A fit needs the deviation at two averaging times at least: the overlapping estimator has
      // tau = m / rate_hz for m <= (N - 1) / 2 (allan.h), so m = 1, 2 from N = 5 samples.
      constexpr size_t kMinFitSamples = 5;
      if (c.samples.size() < kMinFitSamples) {
        throw SpecError(fmt::format("{}: column '{}'", settings.data_name, c.name),
                        fmt::format("{} samples", c.samples.size()),
                        fmt::format("at least {} samples for a fit (the Allan deviation at two "
                                    "averaging times; a useful fit needs a recording many times "
                                    "longer than the longest time scale of interest)",
                                    kMinFitSamples));
      }
      curves.push_back(OverlappingAllanDeviation(c.samples, settings.rate_hz, allan));
      used.push_back(&c);
      const calib::NoiseFitResult fit = calib::FitAllanNoiseModel(curves.back(), fit_options);
      out.add_messages(fmt::format("column {} ({} samples at {:g} Hz):\n{}", c.name,
                                   c.samples.size(), settings.rate_hz,
                                   calib::FormatNoiseFit(fit, gyro)));
      AddTerms(fit, gyro, c.name, nullptr, &out);
    }
    if (curves.empty()) continue;
    const calib::NoiseFitResult triad = calib::FitAllanNoiseModel(curves, fit_options);
    const TriadErrorParams* reference =
        datasheet ? (gyro ? &datasheet->model.gyro : &datasheet->model.accel) : nullptr;
    out.add_messages(
        fmt::format("{} triad ({} axes, one parameter set; written to the model):\n{}",
                    gyro ? "gyro" : "accelerometer", curves.size(),
                    calib::FormatNoiseFit(triad, gyro, reference,
                                          datasheet ? "datasheet " + datasheet->model.name : "")));
    if (triad.quantization.determined && fit_options.bias_model == calib::BiasModel::kFlickerFlat) {
      notes.push_back(fmt::format(
          "{} triad: quantization kept beside the flat flicker floor. If the bias instability is "
          "band-limited (driftlab's presets: flicker over 1-1000 s), the flat floor over-predicts "
          "below the band, the fit lowers N and Q absorbs the short-tau excess; check with "
          "--bias-model flicker-band --flicker-tau-min T1 --flicker-tau-max T2.",
          gyro ? "gyro" : "accel"));
    }
    if (triad.rate_ramp.determined) {
      notes.push_back(
          fmt::format("{} triad: the rate ramp has no term in the sensor model; it is not written.",
                      gyro ? "gyro" : "accel"));
    }
    AddTerms(triad, gyro, "triad", reference, &out);
    (gyro ? model.gyro : model.accel) = calib::ToTriadErrorParams(triad);
    for (size_t i = 0; i < curves.size(); ++i) {
      v1::AllanCurve* curve = out.add_curves();
      curve->set_column(used[i]->name);
      curve->set_unit(gyro ? "rad/s" : "m/s^2");
      for (const AllanPoint& p : curves[i]) {
        curve->add_tau_s(p.tau_s);
        curve->add_adev(p.adev);
        curve->add_adev_lower(p.adev_low);
        curve->add_adev_upper(p.adev_high);
        curve->add_adev_fit(calib::FittedAllanDeviation(triad, p.tau_s));
      }
    }
  }
  for (const std::string& note : notes) out.add_messages(note);
  *out.mutable_sensor() = ToSensorModelProto(model);
  out.set_fit_time_s(
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  return out;
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

std::string NoiseModelFitToJson(const v1::NoiseModelFit& fit) {
  google::protobuf::util::JsonPrintOptions print;
  print.add_whitespace = true;
  print.preserve_proto_field_names = true;
  std::string json;
  if (!google::protobuf::util::MessageToJsonString(fit, &json, print).ok()) {
    throw SpecError("result", "the noise-model fit cannot be printed as JSON", 0);
  }
  return json;
}

}  // namespace driftlab::app
