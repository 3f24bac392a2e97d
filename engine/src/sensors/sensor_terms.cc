// The table of the IMU error model's terms (sensor_terms.h). Job units and ranges are those of
// the field names in job.proto; the limits lie far beyond any real MEMS, FOG or RLG sensor, inside
// the ranges where the error models stay meaningful (|scale factor|, |misalignment| << 1; biases
// below the sensors' ranges).
#include "driftlab/sensor_terms.h"

#include <array>
#include <cmath>
#include <string>

namespace driftlab {
namespace {

TriadErrorParams& Of(ImuErrorModel* m, SensorTriad t) {
  return t == SensorTriad::kGyro ? m->gyro : m->accel;
}

constexpr double kMaxScaleFactor_ppm = 1.0e5;    // 10 %
constexpr double kMaxMisalignment_mrad = 100.0;  // 5.7 deg
constexpr double kMaxTau_s = 1.0e7;              // 116 days

constexpr PerTriad kRateUnits{"deg/h", "mg"};         // fixed and turn-on bias
constexpr PerTriad kInstabilityUnits{"deg/h", "ug"};  // in-run terms
constexpr PerTriad kSeconds{"s", "s"};
constexpr PerTriad kPpm{"ppm", "ppm"};
constexpr PerTriad kMrad{"mrad", "mrad"};
constexpr PerTriad kRateSi{"rad/s", "m/s^2"};
constexpr PerTriad kNoSiUnit{"", ""};

// Each row names only what applies to its term; the others keep SensorTerm's defaults. GCC 12 warns
// for every member a designated initializer leaves to its default member initializer.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
const std::array<SensorTerm, 18> kTerms = {{
    {.param = "white_noise_density",
     .value = [](ImuErrorModel* m, SensorTriad t, int) { return &Of(m, t).white_noise_density; },
     .proto_field = 8,
     .job_unit = {"deg/sqrt(h)", "m/s/sqrt(h)"},
     .gyro_dimension = dims::kAngleRandomWalk,
     .accel_dimension = dims::kVelocityRandomWalk,
     .gyro_max = 1000.0,
     .accel_max = 1000.0,
     .datasheet_key = {"arw", "vrw"},
     .datasheet_alt_key = {"rate_noise_density", "noise_density"},
     .preset_key = "white_noise_density",
     .preset_label = "white noise",
     .preset_unit = {"deg/sqrt(h)", "m/s/sqrt(h)"},
     .preset_si_unit = {"rad/sqrt(s)", "m/s/sqrt(s)"},
     .preset_density_unit = {"(deg/s)/sqrt(Hz)", "ug/sqrt(Hz)"},
     .report_label = {"ARW", "VRW"},
     .report_unit = {"deg/sqrt(h)", "m/s/sqrt(h)"}},
    {.param = "bias_flicker.bias_instability",
     .value = [](ImuErrorModel* m, SensorTriad t,
                 int) { return &Of(m, t).bias_flicker.bias_instability; },
     .proto_field = 3,
     .job_unit = kInstabilityUnits,
     .gyro_dimension = dims::kAngularRate,
     .accel_dimension = dims::kAcceleration,
     .gyro_max = 1.0e5,
     .accel_max = 1.0e6,
     .datasheet_key = {"bias_instability", "bias_instability"},
     .preset_key = "bias_instability",
     .preset_label = "bias instability B (flicker)",
     .preset_unit = kInstabilityUnits,
     .preset_si_unit = kRateSi,
     .preset_bias_unit = true,
     .report_label = {"bias instability", "bias instability"},
     .report_unit = kInstabilityUnits},
    {.param = "bias_flicker.tau_min_s",
     .value = [](ImuErrorModel* m, SensorTriad t, int) { return &Of(m, t).bias_flicker.tau_min_s; },
     .proto_field = 4,
     .job_unit = kSeconds,
     .gyro_dimension = dims::kTime,
     .accel_dimension = dims::kTime,
     .gyro_max = kMaxTau_s,
     .accel_max = kMaxTau_s,
     .written_with = 3,
     .datasheet_key = {"bias_instability_tau_min", "bias_instability_tau_min"},
     .preset_key = "flicker_tau_min",
     .preset_label = "flicker tau min",
     .preset_unit = kSeconds,
     .preset_si_unit = kSeconds},
    {.param = "bias_flicker.tau_max_s",
     .value = [](ImuErrorModel* m, SensorTriad t, int) { return &Of(m, t).bias_flicker.tau_max_s; },
     .proto_field = 5,
     .job_unit = kSeconds,
     .gyro_dimension = dims::kTime,
     .accel_dimension = dims::kTime,
     .gyro_max = kMaxTau_s,
     .accel_max = kMaxTau_s,
     .written_with = 3,
     .datasheet_key = {"bias_instability_tau_max", "bias_instability_tau_max"},
     .preset_key = "flicker_tau_max",
     .preset_label = "flicker tau max",
     .preset_unit = kSeconds,
     .preset_si_unit = kSeconds},
    {.param = "turn_on_bias_sigma",
     .value = [](ImuErrorModel* m, SensorTriad t, int) { return &Of(m, t).turn_on_bias_sigma; },
     .proto_field = 2,
     .job_unit = kRateUnits,
     .gyro_dimension = dims::kAngularRate,
     .accel_dimension = dims::kAcceleration,
     .gyro_max = 1.0e6,   // ~ 280 deg/s
     .accel_max = 1.0e4,  // 10 g
     .datasheet_key = {"turn_on_bias", "turn_on_bias"},
     .preset_key = "turn_on_bias_sigma",
     .preset_label = "turn-on bias (1 sigma)",
     .preset_unit = kInstabilityUnits,
     .preset_si_unit = kRateSi,
     .preset_bias_unit = true,
     .report_label = {"turn-on bias 1σ", "turn-on bias 1σ"},
     .report_unit = kInstabilityUnits},
    {.param = "fixed_bias",
     .shape = TermShape::kAxes,
     .value = [](ImuErrorModel* m, SensorTriad t, int i) { return &Of(m, t).fixed_bias[i]; },
     .proto_field = 1,
     .job_unit = kRateUnits,
     .gyro_dimension = dims::kAngularRate,
     .accel_dimension = dims::kAcceleration,
     .is_signed = true,
     .gyro_max = 1.0e6,
     .accel_max = 1.0e4,
     .preset_key = "fixed_bias",
     .preset_label = "fixed bias (x y z)",
     .preset_unit = kInstabilityUnits,
     .preset_si_unit = kRateSi,
     .preset_bias_unit = true,
     .report_label = {"fixed bias |b|", "fixed bias |b|"},
     .report_unit = kInstabilityUnits},
    {.param = "bias_gauss_markov.sigma",
     .value = [](ImuErrorModel* m, SensorTriad t,
                 int) { return &Of(m, t).bias_gauss_markov.sigma; },
     .proto_field = 6,
     .job_unit = kInstabilityUnits,
     .gyro_dimension = dims::kAngularRate,
     .accel_dimension = dims::kAcceleration,
     .gyro_max = 1.0e5,
     .accel_max = 1.0e6,
     .datasheet_key = {"gauss_markov_sigma", "gauss_markov_sigma"},
     .preset_key = "gauss_markov_sigma",
     .preset_label = "Gauss-Markov bias sigma",
     .preset_unit = kInstabilityUnits,
     .preset_si_unit = kRateSi,
     .preset_bias_unit = true,
     .report_label = {"Gauss-Markov bias 1σ", "Gauss-Markov bias 1σ"},
     .report_unit = kInstabilityUnits},
    {.param = "bias_gauss_markov.tau_s",
     .value = [](ImuErrorModel* m, SensorTriad t,
                 int) { return &Of(m, t).bias_gauss_markov.tau_s; },
     .proto_field = 7,
     .job_unit = kSeconds,
     .gyro_dimension = dims::kTime,
     .accel_dimension = dims::kTime,
     .gyro_max = kMaxTau_s,
     .accel_max = kMaxTau_s,
     .written_with = 6,
     .datasheet_key = {"gauss_markov_tau", "gauss_markov_tau"},
     .preset_key = "gauss_markov_tau",
     .preset_label = "Gauss-Markov bias tau",
     .preset_unit = kSeconds,
     .preset_si_unit = kSeconds,
     .report_label = {"τ", "τ"},
     .report_unit = kSeconds},
    {.param = "bias_gauss_markov.start_at_zero",
     .shape = TermShape::kFlag,
     .flag = [](ImuErrorModel* m,
                SensorTriad t) { return &Of(m, t).bias_gauss_markov.start_at_zero; },
     .proto_field = 18},
    {.param = "random_walk",
     .value = [](ImuErrorModel* m, SensorTriad t, int) { return &Of(m, t).random_walk; },
     .proto_field = 9,
     .job_unit = {"deg/h/sqrt(h)", "ug/sqrt(s)"},
     .gyro_dimension = dims::kRateRandomWalk,
     .accel_dimension = dims::kAccelRandomWalk,
     .gyro_max = 1.0e5,
     .accel_max = 1.0e6,
     .datasheet_key = {"rate_random_walk", "acceleration_random_walk"},
     .preset_key = "random_walk",
     .preset_label = "random walk",
     .preset_unit = {"deg/h/sqrt(h)", "m/s/h/sqrt(h)"},
     .preset_si_unit = {"rad/s/sqrt(s)", "m/s^2/sqrt(s)"},
     .report_label = {"RRW", "AcRW"},
     .report_unit = {"deg/h/sqrt(h)", "ug/sqrt(s)"}},
    {.param = "scale_factor_sigma",
     .value = [](ImuErrorModel* m, SensorTriad t, int) { return &Of(m, t).scale_factor_sigma; },
     .proto_field = 11,
     .job_unit = kPpm,
     .gyro_dimension = dims::kDimensionless,
     .accel_dimension = dims::kDimensionless,
     .gyro_max = kMaxScaleFactor_ppm,
     .accel_max = kMaxScaleFactor_ppm,
     .datasheet_key = {"scale_factor", "scale_factor"},
     .preset_key = "scale_factor_sigma",
     .preset_label = "scale factor (1 sigma)",
     .preset_unit = kPpm,
     .preset_si_unit = kNoSiUnit,
     .report_label = {"scale factor 1σ", "scale factor 1σ"},
     .report_unit = kPpm},
    {.param = "scale_factor_fixed",
     .shape = TermShape::kAxes,
     .value = [](ImuErrorModel* m, SensorTriad t,
                 int i) { return &Of(m, t).scale_factor_fixed[i]; },
     .proto_field = 10,
     .job_unit = kPpm,
     .gyro_dimension = dims::kDimensionless,
     .accel_dimension = dims::kDimensionless,
     .is_signed = true,
     .gyro_max = kMaxScaleFactor_ppm,
     .accel_max = kMaxScaleFactor_ppm,
     .preset_key = "scale_factor_fixed",
     .preset_label = "fixed scale factor (x y z)",
     .preset_unit = kPpm,
     .preset_si_unit = kNoSiUnit},
    {.param = "scale_factor_asymmetry",
     .shape = TermShape::kAxes,
     .value = [](ImuErrorModel* m, SensorTriad t,
                 int i) { return &Of(m, t).scale_factor_asymmetry[i]; },
     .proto_field = 12,
     .job_unit = kPpm,
     .gyro_dimension = dims::kDimensionless,
     .accel_dimension = dims::kDimensionless,
     .is_signed = true,
     .gyro_max = kMaxScaleFactor_ppm,
     .accel_max = kMaxScaleFactor_ppm,
     .preset_key = "scale_factor_asymmetry",
     .preset_label = "scale-factor asymmetry (x y z)",
     .preset_unit = kPpm,
     .preset_si_unit = kNoSiUnit},
    {.param = "misalignment_sigma_rad",
     .value = [](ImuErrorModel* m, SensorTriad t, int) { return &Of(m, t).misalignment_sigma_rad; },
     .proto_field = 14,
     .job_unit = kMrad,
     .gyro_dimension = dims::kAngle,
     .accel_dimension = dims::kAngle,
     .gyro_max = kMaxMisalignment_mrad,
     .accel_max = kMaxMisalignment_mrad,
     .datasheet_key = {"misalignment", "misalignment"},
     .preset_key = "misalignment_sigma",
     .preset_label = "misalignment (1 sigma)",
     .preset_unit = kMrad,
     .preset_si_unit = {"rad", "rad"},
     .report_label = {"misalignment 1σ", "misalignment 1σ"},
     .report_unit = kMrad},
    {.param = "misalignment_fixed",
     .shape = TermShape::kOffDiagonal,
     .value = [](ImuErrorModel* m, SensorTriad t,
                 int i) { return &Of(m, t).misalignment_fixed(i / 3, i % 3); },
     .proto_field = 13,
     .job_unit = kMrad,
     .gyro_dimension = dims::kAngle,
     .accel_dimension = dims::kAngle,
     .is_signed = true,
     .gyro_max = kMaxMisalignment_mrad,
     .accel_max = kMaxMisalignment_mrad,
     .preset_key = "misalignment_fixed",
     .preset_label = "fixed misalignment (rows)",
     .preset_unit = kMrad,
     .preset_si_unit = {"rad", "rad"}},
    {.param = "quantization",
     .value = [](ImuErrorModel* m, SensorTriad t, int) { return &Of(m, t).quantization; },
     .proto_field = 15,
     .job_unit = {"urad", "mm/s"},
     .gyro_dimension = dims::kAngle,
     .accel_dimension = dims::kVelocity,
     .gyro_max = 1.0e5,  // 0.1 rad per increment
     .accel_max = 1.0e4,
     .datasheet_key = {"quantization", "quantization"},
     .preset_key = "quantization",
     .preset_label = "quantization (increment LSB)",
     .preset_unit = {"urad", "mm/s"},
     .preset_si_unit = {"rad", "m/s"}},
    {.param = "range",
     .value = [](ImuErrorModel* m, SensorTriad t, int) { return &Of(m, t).range; },
     .proto_field = 16,
     .job_unit = {"deg/s", "g"},
     .gyro_dimension = dims::kAngularRate,
     .accel_dimension = dims::kAcceleration,
     .gyro_max = 1.0e5,
     .accel_max = 1.0e4,
     .datasheet_key = {"range", "range"},
     .preset_key = "range",
     .preset_label = "range (0 = unlimited)",
     .preset_unit = {"deg/s", "g"},
     .preset_si_unit = kRateSi},
    {.param = "gyro_g_sensitivity",
     .shape = TermShape::kMatrix,
     .gyro_only = true,
     .value = [](ImuErrorModel* m, SensorTriad,
                 int i) { return &m->gyro_g_sensitivity(i / 3, i % 3); },
     .proto_field = 17,
     .job_unit = {"deg/h", ""},
     .job_per_unit = {"g", ""},
     .gyro_dimension = dims::kAngularRate,
     .per_dimension = dims::kAcceleration,
     .is_signed = true,
     .gyro_max = 1.0e4,
     .datasheet_key = {"g_sensitivity", ""},
     .preset_key = "gyro_g_sensitivity",
     .preset_label = "g-sensitivity (rows)",
     .preset_unit = {"(deg/h)/g", ""},
     .preset_si_unit = {"(rad/s)/(m/s^2)", ""}},
}};
#pragma GCC diagnostic pop

}  // namespace

int TermValueCount(TermShape shape) {
  switch (shape) {
    case TermShape::kAxes:
      return 3;
    case TermShape::kOffDiagonal:
    case TermShape::kMatrix:
      return 9;
    default:
      return 1;
  }
}

std::span<const SensorTerm> SensorTerms() { return kTerms; }

const SensorTerm* SensorTermByField(int proto_field) {
  for (const SensorTerm& term : kTerms) {
    if (term.proto_field == proto_field) return &term;
  }
  return nullptr;
}

double TermValue(const SensorTerm& term, const ImuErrorModel& model, SensorTriad t, int i) {
  // The accessor only forms the element's address; nothing is written through it here.
  return *term.value(const_cast<ImuErrorModel*>(&model), t, i);
}

void SetTermValue(const SensorTerm& term, ImuErrorModel* model, SensorTriad t, int i, double v) {
  *term.value(model, t, i) = v;
}

double JobValueToSi(const SensorTerm& term, SensorTriad t, double value,
                    std::string_view field_path) {
  const std::string_view per = term.job_per_unit.of(t);
  if (per.empty()) return ToSi(value, term.job_unit.of(t), term.dimension(t), field_path);
  const double factor = ToSi(1.0, term.job_unit.of(t), term.dimension(t), field_path) /
                        ToSi(1.0, per, term.per_dimension, field_path);
  return value * factor;
}

double JobValueFromSi(const SensorTerm& term, SensorTriad t, double value_si) {
  const std::string_view per = term.job_per_unit.of(t);
  if (per.empty()) return FromSi(value_si, term.job_unit.of(t));
  const double per_si = FromSi(1.0, term.job_unit.of(t)) * ToSi(1.0, per, term.per_dimension);
  return value_si * per_si;
}

std::string JobUnitText(const SensorTerm& term, SensorTriad t) {
  const std::string_view per = term.job_per_unit.of(t);
  std::string text(term.job_unit.of(t));
  if (!per.empty()) text += "/" + std::string(per);
  return text;
}

std::string_view AccelBiasPrintUnit(double bias_instability_si) {
  return std::abs(FromSi(bias_instability_si, "mg")) < 1.0 ? "ug" : "mg";
}

}  // namespace driftlab
