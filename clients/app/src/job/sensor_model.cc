#include "driftlab/app/sensor_model.h"

#include <fmt/format.h>
#include <google/protobuf/descriptor.h>
#include <google/protobuf/message.h>

#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "driftlab/presets.h"
#include "driftlab/sensors.h"
#include "driftlab/spec_error.h"
#include "driftlab/units.h"
#include "job/field_checks.h"

namespace driftlab::app {
namespace {

using google::protobuf::FieldDescriptor;
using google::protobuf::Message;
using google::protobuf::Reflection;

// What a datasheet field means: its unit (units.h syntax, converted to SI by the units module),
// its allowed range in that unit, and where the SI value goes. Scalar fields have `set`; per-axis
// fields (3 values) have `set_axis`; misalignment (6 off-diagonal values) has `set_element`.
struct FieldRule {
  int number = 0;  // field number in v1::GyroModel / v1::AccelModel (job.proto)
  std::string_view unit;
  Dimension dimension;
  double lo = 0.0;
  double hi = 0.0;
  std::function<void(TriadErrorParams*, double)> set;
  std::function<void(TriadErrorParams*, int, double)> set_axis;
};

// Limits: far beyond any real MEMS, FOG or RLG sensor, inside the ranges where the error models
// stay meaningful (|scale factor|, |misalignment| << 1; bias below the sensors' ranges).
constexpr double kMaxScaleFactor_ppm = 1.0e5;    // 10 %
constexpr double kMaxMisalignment_mrad = 100.0;  // 5.7 deg
constexpr double kMaxTau_s = 1.0e7;              // 116 days

// Rules shared by both triads (same field numbers, job.proto); `u` holds the triad's units.
struct TriadUnits {
  std::string_view bias;
  double max_bias;
  std::string_view instability;
  double max_instability;
  std::string_view white;
  Dimension white_dimension;
  double max_white;
  std::string_view random_walk;
  Dimension random_walk_dimension;
  double max_random_walk;
  Dimension rate_dimension;  // of bias, instability, range
  std::string_view quantization;
  Dimension quantization_dimension;
  double max_quantization;
  std::string_view range;
  double max_range;
};

std::vector<FieldRule> TriadRules(const TriadUnits& u) {
  using P = TriadErrorParams;
  const Dimension ratio = dims::kDimensionless;
  const Dimension angle = dims::kAngle;
  return {
      {1, u.bias, u.rate_dimension, -u.max_bias, u.max_bias, nullptr,
       [](P* p, int i, double v) { p->fixed_bias[i] = v; }},
      {2, u.bias, u.rate_dimension, 0, u.max_bias,
       [](P* p, double v) { p->turn_on_bias_sigma = v; }, nullptr},
      {3, u.instability, u.rate_dimension, 0, u.max_instability,
       [](P* p, double v) { p->bias_flicker.bias_instability = v; }, nullptr},
      {4, "s", dims::kTime, 0, kMaxTau_s, [](P* p, double v) { p->bias_flicker.tau_min_s = v; },
       nullptr},
      {5, "s", dims::kTime, 0, kMaxTau_s, [](P* p, double v) { p->bias_flicker.tau_max_s = v; },
       nullptr},
      {6, u.instability, u.rate_dimension, 0, u.max_instability,
       [](P* p, double v) { p->bias_gauss_markov.sigma = v; }, nullptr},
      {7, "s", dims::kTime, 0, kMaxTau_s, [](P* p, double v) { p->bias_gauss_markov.tau_s = v; },
       nullptr},
      {8, u.white, u.white_dimension, 0, u.max_white,
       [](P* p, double v) { p->white_noise_density = v; }, nullptr},
      {9, u.random_walk, u.random_walk_dimension, 0, u.max_random_walk,
       [](P* p, double v) { p->random_walk = v; }, nullptr},
      {10, "ppm", ratio, -kMaxScaleFactor_ppm, kMaxScaleFactor_ppm, nullptr,
       [](P* p, int i, double v) { p->scale_factor_fixed[i] = v; }},
      {11, "ppm", ratio, 0, kMaxScaleFactor_ppm, [](P* p, double v) { p->scale_factor_sigma = v; },
       nullptr},
      {12, "ppm", ratio, -kMaxScaleFactor_ppm, kMaxScaleFactor_ppm, nullptr,
       [](P* p, int i, double v) { p->scale_factor_asymmetry[i] = v; }},
      // 13: fixed misalignment, 6 values, handled separately.
      {14, "mrad", angle, 0, kMaxMisalignment_mrad,
       [](P* p, double v) { p->misalignment_sigma_rad = v; }, nullptr},
      {15, u.quantization, u.quantization_dimension, 0, u.max_quantization,
       [](P* p, double v) { p->quantization = v; }, nullptr},
      {16, u.range, u.rate_dimension, 0, u.max_range, [](P* p, double v) { p->range = v; },
       nullptr},
  };
}

const TriadUnits kGyroUnits{
    .bias = "deg/h",
    .max_bias = 1.0e6,  // ~ 280 deg/s
    .instability = "deg/h",
    .max_instability = 1.0e5,
    .white = "deg/sqrt(h)",
    .white_dimension = dims::kAngleRandomWalk,
    .max_white = 1000.0,
    .random_walk = "deg/h/sqrt(h)",
    .random_walk_dimension = dims::kRateRandomWalk,
    .max_random_walk = 1.0e5,
    .rate_dimension = dims::kAngularRate,
    .quantization = "urad",
    .quantization_dimension = dims::kAngle,
    .max_quantization = 1.0e5,  // 0.1 rad per increment
    .range = "deg/s",
    .max_range = 1.0e5,
};
const TriadUnits kAccelUnits{
    .bias = "mg",
    .max_bias = 1.0e4,  // 10 g
    .instability = "ug",
    .max_instability = 1.0e6,
    .white = "m/s/sqrt(h)",
    .white_dimension = dims::kVelocityRandomWalk,
    .max_white = 1000.0,
    .random_walk = "ug/sqrt(s)",
    .random_walk_dimension = dims::kAccelRandomWalk,
    .max_random_walk = 1.0e6,
    .rate_dimension = dims::kAcceleration,
    .quantization = "mm/s",
    .quantization_dimension = dims::kVelocity,
    .max_quantization = 1.0e4,
    .range = "g",
    .max_range = 1.0e4,
};

void ApplyTriad(const Message& in, const TriadUnits& units, const std::string& prefix,
                TriadErrorParams* out) {
  const Reflection* reflection = in.GetReflection();
  const auto* descriptor = in.GetDescriptor();
  for (const FieldRule& rule : TriadRules(units)) {
    const FieldDescriptor* field = descriptor->FindFieldByNumber(rule.number);
    const std::string path = fmt::format("{}.{}", prefix, field->name());
    if (rule.set) {
      if (!reflection->HasField(in, field)) continue;
      const double value = reflection->GetDouble(in, field);
      Check(path, value, Closed(rule.lo, rule.hi, rule.unit));
      rule.set(out, ToSi(value, rule.unit, rule.dimension, path));
      continue;
    }
    const int n = reflection->FieldSize(in, field);
    if (n == 0) continue;
    if (n != 3) throw SpecError(path, fmt::format("{} values", n), "exactly 3 values (x, y, z)");
    for (int i = 0; i < 3; ++i) {
      const std::string element = fmt::format("{}[{}]", path, i);
      const double value = reflection->GetRepeatedDouble(in, field, i);
      Check(element, value, Closed(rule.lo, rule.hi, rule.unit));
      rule.set_axis(out, i, ToSi(value, rule.unit, rule.dimension, element));
    }
  }

  // Fixed misalignment: off-diagonal elements of M in row order xy, xz, yx, yz, zx, zy.
  const FieldDescriptor* misalignment = descriptor->FindFieldByNumber(13);
  const int n = reflection->FieldSize(in, misalignment);
  if (n != 0) {
    const std::string path = fmt::format("{}.{}", prefix, misalignment->name());
    if (n != 6) {
      throw SpecError(path, fmt::format("{} values", n),
                      "exactly 6 values: the off-diagonal elements xy, xz, yx, yz, zx, zy");
    }
    constexpr int kRow[6] = {0, 0, 1, 1, 2, 2};
    constexpr int kCol[6] = {1, 2, 0, 2, 0, 1};
    for (int i = 0; i < 6; ++i) {
      const std::string element = fmt::format("{}[{}]", path, i);
      const double value = reflection->GetRepeatedDouble(in, misalignment, i);
      Check(element, value, Closed(-kMaxMisalignment_mrad, kMaxMisalignment_mrad, "mrad"));
      out->misalignment_fixed(kRow[i], kCol[i]) = ToSi(value, "mrad", dims::kAngle, element);
    }
  }

  // Field 18 (both triads): the Gauss-Markov start.
  const FieldDescriptor* gm_start = descriptor->FindFieldByNumber(18);
  if (reflection->HasField(in, gm_start)) {
    out->bias_gauss_markov.start_at_zero = reflection->GetBool(in, gm_start);
  }

  // Combinations the engine also checks, reported here with the job's field names.
  const auto& fields = *descriptor;
  auto name = [&fields](int number) { return fields.FindFieldByNumber(number)->name(); };
  if (out->bias_gauss_markov.sigma > 0.0 && !(out->bias_gauss_markov.tau_s > 0.0)) {
    const std::string path = fmt::format("{}.{}", prefix, name(7));
    throw SpecError(
        path, fmt::format("{}", out->bias_gauss_markov.tau_s),
        fmt::format("0 < {} <= {} s (required when {} > 0)", name(7), kMaxTau_s, name(6)));
  }
  if (out->bias_flicker.bias_instability > 0.0 &&
      !(out->bias_flicker.tau_min_s > 0.0 &&
        out->bias_flicker.tau_min_s < out->bias_flicker.tau_max_s)) {
    const std::string path = fmt::format("{}.{}", prefix, name(4));
    throw SpecError(
        path, fmt::format("{}", out->bias_flicker.tau_min_s),
        fmt::format("0 < {} < {} = {} s", name(4), name(5), out->bias_flicker.tau_max_s));
  }
}

bool IsEmpty(const v1::SensorModel& sensor) { return sensor.ByteSizeLong() == 0; }

}  // namespace

std::optional<ImuErrorModel> ToImuErrorModel(const v1::Job& job) {
  if (!job.has_sensor() || IsEmpty(job.sensor())) return std::nullopt;
  return ToImuErrorModel(job.sensor(), "sensor");
}

ImuErrorModel ToImuErrorModel(const v1::SensorModel& in, const std::string& prefix) {
  ImuErrorModel model;
  if (!in.preset().empty()) {
    model = FindImuPreset(in.preset());  // SpecError "sensor.preset: ... allowed: one of ..."
  } else {
    model.name = "custom";
    model.description = "explicit parameters from the job file";
  }
  ApplyTriad(in.gyro(), kGyroUnits, prefix + ".gyro", &model.gyro);
  ApplyTriad(in.accel(), kAccelUnits, prefix + ".accel", &model.accel);

  // g-sensitivity [deg/h/g]: 3 values (diagonal) or 9 (row order).
  const auto& g_sensitivity = in.gyro().g_sensitivity_deg_per_h_per_g();
  if (!g_sensitivity.empty()) {
    const std::string path = prefix + ".gyro.g_sensitivity_deg_per_h_per_g";
    if (g_sensitivity.size() != 3 && g_sensitivity.size() != 9) {
      throw SpecError(path, fmt::format("{} values", g_sensitivity.size()),
                      "3 values (diagonal) or 9 (row order)");
    }
    constexpr double kMaxGSensitivity_deg_per_h_per_g = 1.0e4;
    // (deg/h)/g -> (rad/s)/(m/s^2): one conversion factor from the units module.
    const double factor =
        ToSi(1.0, "deg/h", dims::kAngularRate, path) / ToSi(1.0, "g", dims::kAcceleration, path);
    model.gyro_g_sensitivity.setZero();
    for (int i = 0; i < g_sensitivity.size(); ++i) {
      const std::string element = fmt::format("{}[{}]", path, i);
      Check(element, g_sensitivity[i],
            Closed(-kMaxGSensitivity_deg_per_h_per_g, kMaxGSensitivity_deg_per_h_per_g, "deg/h/g"));
      if (g_sensitivity.size() == 3) {
        model.gyro_g_sensitivity(i, i) = g_sensitivity[i] * factor;
      } else {
        model.gyro_g_sensitivity(i / 3, i % 3) = g_sensitivity[i] * factor;
      }
    }
  }
  ValidateImuErrorModel(model, prefix);  // the engine's own checks, as a last line
  return model;
}

}  // namespace driftlab::app

namespace driftlab::app {

uint64_t JobSeed(const v1::Job& job) {
  return job.monte_carlo().has_seed() ? job.monte_carlo().seed() : kDefaultSeed;
}

}  // namespace driftlab::app
