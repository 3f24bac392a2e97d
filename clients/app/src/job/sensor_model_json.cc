// ImuErrorModel -> driftlab.v1.SensorModel (sensor_model_json.h): every term of the sensor-term
// table (sensor_terms.h) written to its field by reflection; GyroModel and AccelModel share their
// field numbers (job.proto).
#include "driftlab/app/sensor_model_json.h"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/message.h>
#include <google/protobuf/util/json_util.h>

#include <vector>

#include "driftlab/sensor_terms.h"
#include "driftlab/spec_error.h"

namespace driftlab::app {
namespace {

using google::protobuf::FieldDescriptor;
using google::protobuf::Message;

// The job field of `term` for triad t from `model`: nothing when every value is 0 or when the term
// it belongs to is off (a correlation time without its sigma).
void FillTerm(const ImuErrorModel& model, const SensorTerm& term, SensorTriad t, Message* out) {
  const FieldDescriptor* field = out->GetDescriptor()->FindFieldByNumber(term.proto_field);
  const auto* reflection = out->GetReflection();
  if (term.shape == TermShape::kFlag) {
    if (*term.flag(const_cast<ImuErrorModel*>(&model), t)) reflection->SetBool(out, field, true);
    return;
  }
  if (term.written_with != 0 &&
      !(TermValue(*SensorTermByField(term.written_with), model, t, 0) > 0.0)) {
    return;
  }
  std::vector<int> indices;  // the values the field writes, in its order
  switch (term.shape) {
    case TermShape::kScalar:
      indices = {0};
      break;
    case TermShape::kAxes:
      indices = {0, 1, 2};
      break;
    case TermShape::kOffDiagonal:  // xy, xz, yx, yz, zx, zy
      indices = {1, 2, 3, 5, 6, 7};
      break;
    default: {  // kMatrix: the diagonal when the matrix is diagonal, else all 9 in row order
      bool diagonal = true;
      for (int i = 0; i < 9; ++i) diagonal &= i % 4 == 0 || TermValue(term, model, t, i) == 0.0;
      indices = diagonal ? std::vector<int>{0, 4, 8} : std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7, 8};
    }
  }
  bool any = false;
  for (int i : indices) any |= TermValue(term, model, t, i) != 0.0;
  if (!any) return;
  for (int i : indices) {
    const double value = JobValueFromSi(term, t, TermValue(term, model, t, i));
    if (field->is_repeated()) {
      reflection->AddDouble(out, field, value);
    } else {
      reflection->SetDouble(out, field, value);
    }
  }
}

}  // namespace

v1::SensorModel ToSensorModelProto(const ImuErrorModel& model) {
  v1::SensorModel out;
  for (const SensorTerm& term : SensorTerms()) {
    FillTerm(model, term, SensorTriad::kGyro, out.mutable_gyro());
    if (term.applies_to(SensorTriad::kAccel)) {
      FillTerm(model, term, SensorTriad::kAccel, out.mutable_accel());
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
