#include "driftlab/app/sensor_model.h"

#include <fmt/format.h>
#include <google/protobuf/descriptor.h>
#include <google/protobuf/message.h>

#include <algorithm>
#include <string>
#include <string_view>
#include <vector>

#include "driftlab/presets.h"
#include "driftlab/sensor_terms.h"
#include "driftlab/sensors.h"
#include "driftlab/spec_error.h"
#include "driftlab/units.h"
#include "job/field_checks.h"

namespace driftlab::app {
namespace {

using google::protobuf::FieldDescriptor;
using google::protobuf::Message;
using google::protobuf::Reflection;

// The terms in the order their fields are checked: scalars and axes by field number, then the
// matrices and the flags (a message names the first bad field of a triad in that order).
std::vector<const SensorTerm*> TermsInCheckOrder() {
  std::vector<const SensorTerm*> terms;
  for (const SensorTerm& term : SensorTerms()) terms.push_back(&term);
  const auto group = [](const SensorTerm* t) {
    switch (t->shape) {
      case TermShape::kScalar:
      case TermShape::kAxes:
        return 0;
      case TermShape::kOffDiagonal:
      case TermShape::kMatrix:
        return 1;
      case TermShape::kFlag:
        break;
    }
    return 2;
  };
  std::stable_sort(terms.begin(), terms.end(), [&](const SensorTerm* a, const SensorTerm* b) {
    return std::pair(group(a), a->proto_field) < std::pair(group(b), b->proto_field);
  });
  return terms;
}

// Row-major index of the off-diagonal element k of the job field (xy, xz, yx, yz, zx, zy).
constexpr int kOffDiagonalIndex[6] = {1, 2, 3, 5, 6, 7};

// Reads one term of triad t from `in` (its proto message) into `model`. Unset fields keep the
// model's value (the preset's, or off).
void ApplyTerm(const Message& in, const SensorTerm& term, SensorTriad t, const std::string& prefix,
               ImuErrorModel* model) {
  const Reflection* reflection = in.GetReflection();
  const FieldDescriptor* field = in.GetDescriptor()->FindFieldByNumber(term.proto_field);
  const std::string path = fmt::format("{}.{}", prefix, field->name());
  if (term.shape == TermShape::kFlag) {
    if (reflection->HasField(in, field)) *term.flag(model, t) = reflection->GetBool(in, field);
    return;
  }
  const std::string unit = JobUnitText(term, t);
  const double lo = term.is_signed ? -term.max(t) : 0.0;
  const Range range = Closed(lo, term.max(t), unit);
  if (term.shape == TermShape::kScalar) {
    if (!reflection->HasField(in, field)) return;
    const double value = reflection->GetDouble(in, field);
    Check(path, value, range);
    SetTermValue(term, model, t, 0, JobValueToSi(term, t, value, path));
    return;
  }
  const int n = reflection->FieldSize(in, field);
  if (n == 0) return;
  const auto set = [&](int element, int index) {
    const std::string element_path = fmt::format("{}[{}]", path, element);
    const double value = reflection->GetRepeatedDouble(in, field, element);
    Check(element_path, value, range);
    SetTermValue(term, model, t, index, JobValueToSi(term, t, value, element_path));
  };
  switch (term.shape) {
    case TermShape::kAxes:
      if (n != 3) throw SpecError(path, fmt::format("{} values", n), "exactly 3 values (x, y, z)");
      for (int i = 0; i < 3; ++i) set(i, i);
      break;
    case TermShape::kOffDiagonal:
      if (n != 6) {
        throw SpecError(path, fmt::format("{} values", n),
                        "exactly 6 values: the off-diagonal elements xy, xz, yx, yz, zx, zy");
      }
      for (int i = 0; i < 6; ++i) set(i, kOffDiagonalIndex[i]);
      break;
    default:  // kMatrix: 3 values (diagonal) or 9 (row order)
      if (n != 3 && n != 9) {
        throw SpecError(path, fmt::format("{} values", n), "3 values (diagonal) or 9 (row order)");
      }
      for (int i = 0; i < 9; ++i) SetTermValue(term, model, t, i, 0.0);
      for (int i = 0; i < n; ++i) set(i, n == 3 ? 4 * i : i);
      break;
  }
}

void ApplyTriad(const Message& in, SensorTriad t, const std::string& prefix, ImuErrorModel* model) {
  for (const SensorTerm* term : TermsInCheckOrder()) {
    if (!term->gyro_only) ApplyTerm(in, *term, t, prefix, model);
  }
  const TriadErrorParams* out = t == SensorTriad::kGyro ? &model->gyro : &model->accel;
  const auto* descriptor = in.GetDescriptor();

  // Combinations the engine also checks, reported here with the job's field names.
  const auto& fields = *descriptor;
  auto name = [&fields](int number) { return fields.FindFieldByNumber(number)->name(); };
  if (out->bias_gauss_markov.sigma > 0.0 && !(out->bias_gauss_markov.tau_s > 0.0)) {
    const std::string path = fmt::format("{}.{}", prefix, name(7));
    throw SpecError(path, fmt::format("{}", out->bias_gauss_markov.tau_s),
                    fmt::format("0 < {} <= {} s (required when {} > 0)", name(7),
                                SensorTermByField(7)->gyro_max, name(6)));
  }
  if (out->bias_flicker.bias_instability > 0.0 &&
      !(out->bias_flicker.tau_min_s > 0.0 &&
        out->bias_flicker.tau_min_s < out->bias_flicker.tau_max_s)) {
    const std::string path = fmt::format("{}.{}", prefix, name(4));
    throw SpecError(
        path, fmt::format("{}", out->bias_flicker.tau_min_s),
        fmt::format("0 < {} < {} = {} s", name(4), name(5), out->bias_flicker.tau_max_s));
  }
  if (out->bias_flicker.bias_instability > 0.0 &&
      out->bias_flicker.tau_max_s > kMaxFlickerRangeRatio * out->bias_flicker.tau_min_s) {
    const std::string path = fmt::format("{}.{}", prefix, name(5));
    throw SpecError(path, fmt::format("{}", out->bias_flicker.tau_max_s),
                    fmt::format("{} <= 1e9 {} = {} s", name(5), name(4),
                                kMaxFlickerRangeRatio * out->bias_flicker.tau_min_s));
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
  ApplyTriad(in.gyro(), SensorTriad::kGyro, prefix + ".gyro", &model);
  ApplyTriad(in.accel(), SensorTriad::kAccel, prefix + ".accel", &model);
  // Model-level terms (g-sensitivity: GyroModel only).
  for (const SensorTerm* term : TermsInCheckOrder()) {
    if (term->gyro_only) ApplyTerm(in.gyro(), *term, SensorTriad::kGyro, prefix + ".gyro", &model);
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
