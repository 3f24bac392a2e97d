// calibration_job.h: the core of `driftlab allan --fit` and the gRPC noise-model fit: settings
// checked, the Allan deviation fitted per axis (calib/noise_fit.h), the terms as noise_fit.proto
// messages in the sensor model's units.
#include <fmt/format.h>
#include <google/protobuf/util/json_util.h>

#include <chrono>
#include <cmath>
#include <optional>
#include <string_view>

#include "driftlab/allan.h"
#include "driftlab/app/calibration_job.h"
#include "driftlab/app/sensor_model_json.h"
#include "driftlab/calib/datasheet.h"
#include "driftlab/calib/noise_fit.h"
#include "driftlab/spec_error.h"
#include "driftlab/units.h"
#include "job/field_checks.h"
#include "text.h"

namespace driftlab::app {
namespace {

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
