// `driftlab allan DATA.csv --rate HZ [--columns a,b] [--unit U] [--points-per-octave K]
//  [--out RESULT.json]`: overlapping Allan deviation of the columns of a CSV file, with 95 %
// confidence intervals and the IEEE Std 952 noise-term read-off (allan.h), in datasheet units.
// With --fit (allan_fit.h): the Ceres noise-model fit, --out MODEL.json, --report REPORT.html.
//
// DATA.csv: one header row (names), then numeric rows; lines starting with '#' and empty lines are
// skipped (app::ReadNumericCsv; the column selection and units are
// app::SelectRateColumns, shared with the fit, calibration_job.h). Default columns: the point
// samples of driftlab's imu.csv (omega_{x,y,z}_rad_per_s, f_{x,y,z}_m_per_s2; io.h ImuCsvWriter)
// when all are present, else every column except a time column (t, t_*, time*). A column's unit
// comes from --unit or from its name's suffix, words joined by '_' with "per" for '/':
// omega_x_rad_per_s -> rad/s, f_x_m_per_s2 -> m/s2, gyro_deg_per_h -> deg/h, acc_mg -> mg (units.h
// syntax). Rates (angular rate or acceleration) are analysed as they are; increments (angle or
// velocity, e.g. dtheta_x_rad) are divided by the sample interval 1 / rate first (allan.h: the
// input is the per-interval average rate).
//
// Results are printed in datasheet units: gyro ADEV and bias instability in deg/h, white noise in
// deg/sqrt(h), rate random walk in deg/h/sqrt(h); accelerometer ADEV and bias instability in ug
// (mg above 1 mg), white noise in m/s/sqrt(h). --out writes every point and the read-off, in SI
// and in those units, as JSON (google.protobuf.Struct through protobuf's JSON printer).
#include <fmt/format.h>
#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "allan_fit.h"
#include "commands.h"
#include "driftlab/allan.h"
#include "driftlab/app/calibration_job.h"
#include "driftlab/spec_error.h"
#include "driftlab/units.h"
#include "json_values.h"

namespace driftlab::cli {
namespace {

namespace pb = google::protobuf;

struct AllanCliOptions {
  std::string data_path;
  double rate_hz = 0.0;
  std::string columns;
  std::string unit;
  std::string out_path;
  int points_per_octave = 1;
  // --fit: the noise-model fit (allan_fit.h); --out then names the model file.
  bool fit = false;
  std::string report_path;  // with --fit: HTML report
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

using Column = app::RateColumn;

// Reads `path` (calibration_job.h ReadNumericCsv) and selects the columns as SI rates.
std::vector<Column> ReadColumns(const AllanCliOptions& options) {
  const app::NumericTable table = app::ReadNumericCsv(options.data_path);
  return app::SelectRateColumns(
      table,
      options.columns.empty() ? std::vector<std::string>{} : SplitColumnNames(options.columns),
      options.unit, options.rate_hz, options.data_path, "--columns", "--unit");
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
  Set(s, "name", JsonText(column.name));
  Set(s, "quantity", JsonText(u.quantity));
  Set(s, "input_unit", JsonText(column.unit));
  Set(s, "increments", [&] {
    pb::Value v;
    v.set_bool_value(column.increment);
    return v;
  }());
  Set(s, "n_samples", JsonNumber(static_cast<double>(column.samples.size())));
  Set(s, "si_unit", JsonText(u.si));
  Set(s, "datasheet_unit", JsonText(u.adev));
  pb::ListValue& points = *(*s.mutable_fields())["points"].mutable_list_value();
  for (const AllanPoint& p : curve) {
    fmt::print("  {:>12.6g}  {:>12.6g}  {:>12.6g} - {:>12.6g}  {:>10.4g}  {:>10}  {}\n", p.tau_s,
               FromSi(p.adev, u.adev), FromSi(p.adev_low, u.adev), FromSi(p.adev_high, u.adev),
               p.edf, p.n_clusters, NoiseName(p.noise_type));
    pb::Value point;
    pb::Struct& ps = *point.mutable_struct_value();
    Set(ps, "tau_s", JsonNumber(p.tau_s));
    Set(ps, "adev", JsonNumber(p.adev));
    Set(ps, "adev_low", JsonNumber(p.adev_low));
    Set(ps, "adev_high", JsonNumber(p.adev_high));
    Set(ps, "edf", JsonNumber(p.edf));
    Set(ps, "n_clusters", JsonNumber(static_cast<double>(p.n_clusters)));
    Set(ps, "m", JsonNumber(static_cast<double>(p.m)));
    Set(ps, "noise_type", JsonText(NoiseName(p.noise_type)));
    Set(ps, "adev_datasheet", JsonNumber(FromSi(p.adev, u.adev)));
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
    Set(ts, "si", JsonNumber(fit.value));
    Set(ts, "si_unit", JsonText(term.si_unit));
    Set(ts, "datasheet_unit", JsonText(term.unit));
    Set(ts, "datasheet_value", JsonNumber(fit.found() ? FromSi(fit.value, term.unit) : NAN));
    Set(ts, "tau_min_s", JsonNumber(fit.tau_min_s));
    Set(ts, "tau_max_s", JsonNumber(fit.tau_max_s));
    Set(ts, "n_points", JsonNumber(fit.n_points));
    if (fit.found()) {
      const std::string datasheet = FormatQuantity(fit.value, term.unit, 4);
      Set(ts, "datasheet", JsonText(datasheet));
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
    CheckCommandOutputs({{options.data_path, "DATA"}}, {{options.out_path, "--out"}});
    const std::vector<Column> columns = ReadColumns(options);
    pb::Struct& s = *report.mutable_struct_value();
    Set(s, "file", JsonText(options.data_path));
    Set(s, "rate_hz", JsonNumber(options.rate_hz));
    Set(s, "confidence", JsonNumber(0.95));
    Set(s, "points_per_octave", JsonNumber(options.points_per_octave));
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
  return WriteOutputText(options.out_path, json, "--out");
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
                   "With --fit: flicker (IEEE flat floor), flicker-band (the engine's band-limited "
                   "flicker over --flicker-tau-min..max, what driftlab's presets simulate), "
                   "gauss-markov or none")
      ->capture_default_str();
  command->add_option("--flicker-tau-min", options->fit_options.flicker_tau_min_s,
                      "With --fit: flicker band start [s] (0 = first tau)");
  command->add_option("--flicker-tau-max", options->fit_options.flicker_tau_max_s,
                      "With --fit: flicker band end [s] (0 = last tau)");
  command->add_option("--fit-json", options->fit_options.fit_json_path,
                      "With --fit: the whole fit as JSON (terms with 95 % intervals and the "
                      "selection test, goodness of fit per fit, warnings)");
  command->add_option("--report", options->report_path,
                      "With --fit: self-contained HTML report (ADEV with 95 % CIs and the fitted "
                      "curve per column, fitted terms, the model)");
  return [options] {
    if (!options->fit) {
      if (!options->report_path.empty()) {
        fmt::print(stderr,
                   "error: --report: {} is not allowed; allowed: with --fit (the report shows "
                   "the noise-model fit)\n",
                   options->report_path);
        return kExitBadJob;
      }
      if (!options->fit_options.fit_json_path.empty()) {
        fmt::print(stderr, "error: --fit-json: {} is not allowed; allowed: with --fit\n",
                   options->fit_options.fit_json_path);
        return kExitBadJob;
      }
      return RunAllan(*options);
    }
    AllanFitOptions fit = options->fit_options;
    fit.data_path = options->data_path;
    fit.rate_hz = options->rate_hz;
    fit.columns = options->columns;
    fit.out_path = options->out_path;
    fit.report_path = options->report_path;
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
