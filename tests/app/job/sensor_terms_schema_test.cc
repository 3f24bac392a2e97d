// The sensor-term table (sensor_terms.h) against the job schema (job.proto GyroModel, AccelModel):
// every field of the two messages is one term, of the term's shape, and named with the term's job
// unit; every term alone round-trips through the job fragment into exactly its own field.
#include <google/protobuf/descriptor.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "driftlab/app/sensor_model.h"
#include "driftlab/app/sensor_model_json.h"
#include "driftlab/sensor_terms.h"
#include "driftlab/v1/job.pb.h"

namespace driftlab::app {
namespace {

using google::protobuf::Descriptor;
using google::protobuf::FieldDescriptor;

// "deg/h/sqrt(h)" -> "deg_per_h_per_sqrt_h": how job.proto spells a unit in a field name.
std::string UnitToken(std::string unit) {
  std::string out;
  for (size_t i = 0; i < unit.size(); ++i) {
    if (unit[i] == '/') {
      out += "_per_";
    } else if (unit.compare(i, 5, "sqrt(") == 0) {
      out += "sqrt_";
      i += 4;
    } else if (unit[i] != ')') {
      out += unit[i];
    }
  }
  return out;
}

void CheckMessage(const Descriptor& message, SensorTriad t) {
  for (int i = 0; i < message.field_count(); ++i) {
    const FieldDescriptor& field = *message.field(i);
    const SensorTerm* term = SensorTermByField(field.number());
    ASSERT_NE(term, nullptr) << message.name() << "." << field.name() << " has no term";
    EXPECT_TRUE(term->applies_to(t)) << field.name();
    if (term->shape == TermShape::kFlag) {
      EXPECT_EQ(field.type(), FieldDescriptor::TYPE_BOOL) << field.name();
      continue;
    }
    EXPECT_EQ(field.type(), FieldDescriptor::TYPE_DOUBLE) << field.name();
    EXPECT_EQ(field.is_repeated(), term->shape != TermShape::kScalar) << field.name();
    const std::string suffix = "_" + UnitToken(JobUnitText(*term, t));
    EXPECT_TRUE(field.name().ends_with(suffix)) << field.name() << " vs unit " << suffix;
  }
  for (const SensorTerm& term : SensorTerms()) {
    if (term.applies_to(t)) {
      EXPECT_NE(message.FindFieldByNumber(term.proto_field), nullptr)
          << message.name() << " lacks field " << term.proto_field << " (" << term.param << ")";
    }
  }
}

TEST(SensorTermsSchemaTest, EveryTriadFieldIsOneTermOfItsShapeAndUnit) {
  CheckMessage(*v1::GyroModel::descriptor(), SensorTriad::kGyro);
  CheckMessage(*v1::AccelModel::descriptor(), SensorTriad::kAccel);
}

TEST(SensorTermsSchemaTest, EachTermAloneRoundTripsThroughItsOwnField) {
  for (const SensorTerm& term : SensorTerms()) {
    for (const SensorTriad t : {SensorTriad::kGyro, SensorTriad::kAccel}) {
      if (!term.applies_to(t)) continue;
      ImuErrorModel model;
      int expected_fields = 1;
      if (term.written_with != 0) {  // its sigma on (1e-6 rad/s or m/s^2), else it is not written
        SetTermValue(*SensorTermByField(term.written_with), &model, t, 0, 1e-6);
        ++expected_fields;
      }
      if (term.shape == TermShape::kFlag) {
        *term.flag(&model, t) = true;
      } else {
        // Values inside the field's range (up to 9/16 of its maximum); a correlation time of 10 s,
        // inside the flicker band's default [1 s, 1000 s] order.
        const double job_value = term.written_with != 0 ? term.max(t) * 1e-6 : term.max(t) / 16;
        const double si = JobValueToSi(term, t, job_value, "test");
        for (int i = 0; i < TermValueCount(term.shape); ++i) {
          const bool stored = term.shape != TermShape::kOffDiagonal || i % 4 != 0;
          if (stored) SetTermValue(term, &model, t, i, si * (1 + i));
        }
      }
      // Its parts that a model with the term on requires (a Gauss-Markov tau): 10 s.
      for (const SensorTerm& part : SensorTerms()) {
        if (part.written_with == term.proto_field && TermValue(part, model, t, 0) == 0) {
          SetTermValue(part, &model, t, 0, 10.0);
        }
      }
      const v1::SensorModel proto = ToSensorModelProto(model);
      const google::protobuf::Message& triad =
          t == SensorTriad::kGyro ? static_cast<const google::protobuf::Message&>(proto.gyro())
                                  : proto.accel();
      std::vector<const FieldDescriptor*> set;
      triad.GetReflection()->ListFields(triad, &set);
      // The term's own field is written, and nothing but it, the term it belongs to (a sigma for
      // its correlation time) and their parts (a flicker band with its B, at its defaults).
      const int group = term.written_with != 0 ? term.written_with : term.proto_field;
      bool own = false;
      for (const FieldDescriptor* f : set) {
        const SensorTerm& written = *SensorTermByField(f->number());
        own |= f->number() == term.proto_field;
        EXPECT_TRUE(written.proto_field == group || written.written_with == group)
            << term.param << " wrote " << f->name();
      }
      ASSERT_TRUE(own) << term.param << " not written";
      EXPECT_GE(static_cast<int>(set.size()), expected_fields) << term.param;
      const ImuErrorModel back = ToImuErrorModel(proto, "sensor");
      if (term.shape == TermShape::kFlag) {
        EXPECT_TRUE(*term.flag(const_cast<ImuErrorModel*>(&back), t)) << term.param;
        continue;
      }
      for (int i = 0; i < TermValueCount(term.shape); ++i) {
        // Two conversions through the units module, each exact to a few ulp: 1e-12 relative.
        const double a = TermValue(term, model, t, i), b = TermValue(term, back, t, i);
        EXPECT_LE(std::fabs(a - b), 1e-12 * std::fabs(a)) << term.param << "[" << i << "]";
      }
    }
  }
}

}  // namespace
}  // namespace driftlab::app
