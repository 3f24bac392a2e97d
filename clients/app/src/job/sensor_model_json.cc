// ImuErrorModel -> driftlab.v1.SensorModel (sensor_model_json.h). GyroModel and AccelModel share
// their field numbers (job.proto), so one table, applied by reflection, serves both triads.
#include "driftlab/app/sensor_model_json.h"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/message.h>
#include <google/protobuf/util/json_util.h>

#include <functional>
#include <string_view>
#include <vector>

#include "driftlab/spec_error.h"
#include "driftlab/units.h"

namespace driftlab::app {
namespace {

using google::protobuf::FieldDescriptor;
using google::protobuf::Message;

// Units of the fields, as in their names (job.proto; sensor_model.cc converts back with these).
struct TriadUnits {
  std::string_view bias, instability, white, random_walk, quantization, range;
};
constexpr TriadUnits kGyro{"deg/h", "deg/h", "deg/sqrt(h)", "deg/h/sqrt(h)", "urad", "deg/s"};
constexpr TriadUnits kAccel{"mg", "ug", "m/s/sqrt(h)", "ug/sqrt(s)", "mm/s", "g"};

// One field: number, unit ("" = SI seconds, written as is), and its SI values (1 for optional
// scalars, 3 / 6 for repeated); nothing is written when every value is 0.
struct Field {
  int number;
  std::string_view unit;
  std::vector<double> si;
};

std::vector<Field> Fields(const TriadErrorParams& p, const TriadUnits& u) {
  const auto v3 = [](const Eigen::Vector3d& v) { return std::vector<double>{v[0], v[1], v[2]}; };
  const Eigen::Matrix3d& m = p.misalignment_fixed;
  const bool flicker = p.bias_flicker.bias_instability > 0.0;
  const bool gm = p.bias_gauss_markov.sigma > 0.0;
  return {
      {1, u.bias, v3(p.fixed_bias)},
      {2, u.bias, {p.turn_on_bias_sigma}},
      {3, u.instability, {p.bias_flicker.bias_instability}},
      {4, "", {flicker ? p.bias_flicker.tau_min_s : 0.0}},
      {5, "", {flicker ? p.bias_flicker.tau_max_s : 0.0}},
      {6, u.instability, {p.bias_gauss_markov.sigma}},
      {7, "", {gm ? p.bias_gauss_markov.tau_s : 0.0}},
      {8, u.white, {p.white_noise_density}},
      {9, u.random_walk, {p.random_walk}},
      {10, "ppm", v3(p.scale_factor_fixed)},
      {11, "ppm", {p.scale_factor_sigma}},
      {12, "ppm", v3(p.scale_factor_asymmetry)},
      // Off-diagonal elements in row order xy, xz, yx, yz, zx, zy.
      {13, "mrad", {m(0, 1), m(0, 2), m(1, 0), m(1, 2), m(2, 0), m(2, 1)}},
      {14, "mrad", {p.misalignment_sigma_rad}},
      {15, u.quantization, {p.quantization}},
      {16, u.range, {p.range}},
  };
}

void FillTriad(const TriadErrorParams& p, const TriadUnits& u, Message* out) {
  const auto* descriptor = out->GetDescriptor();
  const auto* reflection = out->GetReflection();
  if (p.bias_gauss_markov.start_at_zero) {  // field 18 in both triads
    reflection->SetBool(out, descriptor->FindFieldByNumber(18), true);
  }
  for (const Field& f : Fields(p, u)) {
    bool any = false;
    for (double v : f.si) any |= v != 0.0;
    if (!any) continue;
    const FieldDescriptor* field = descriptor->FindFieldByNumber(f.number);
    for (double v : f.si) {
      const double value = f.unit.empty() ? v : FromSi(v, f.unit);
      if (field->is_repeated()) {
        reflection->AddDouble(out, field, value);
      } else {
        reflection->SetDouble(out, field, value);
      }
    }
  }
}

}  // namespace

v1::SensorModel ToSensorModelProto(const ImuErrorModel& model) {
  v1::SensorModel out;
  FillTriad(model.gyro, kGyro, out.mutable_gyro());
  FillTriad(model.accel, kAccel, out.mutable_accel());
  const Eigen::Matrix3d& g = model.gyro_g_sensitivity;
  if (!g.isZero(0.0)) {
    // (rad/s)/(m/s^2) -> (deg/h)/g, through the units module as sensor_model.cc does.
    const double per_si = FromSi(1.0, "deg/h") * ToSi(1.0, "g", dims::kAcceleration);
    const bool diagonal = g.isDiagonal(0.0);
    for (int i = 0; i < (diagonal ? 3 : 9); ++i) {
      const double v = diagonal ? g(i, i) : g(i / 3, i % 3);
      out.mutable_gyro()->add_g_sensitivity_deg_per_h_per_g(v * per_si);
    }
  }
  return out;
}

std::string SensorModelJson(const ImuErrorModel& model) {
  v1::Job job;
  *job.mutable_sensor() = ToSensorModelProto(model);
  google::protobuf::util::JsonPrintOptions options;
  options.add_whitespace = true;
  options.preserve_proto_field_names = true;
  std::string json;
  const auto status = google::protobuf::util::MessageToJsonString(job, &json, options);
  if (!status.ok()) throw SpecError("sensor", "JSON output failed: " + status.ToString(), 0);
  return json;
}

}  // namespace driftlab::app
