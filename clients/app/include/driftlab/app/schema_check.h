// Descriptor-driven check of a JSON tree against a protobuf message type, before protobuf's own
// JSON parser sees it, so that every problem is reported with its field path:
//   unknown field       "motion.segments[2].spin: unknown field; allowed: static, accelerate, ..."
//   wrong type          "rate_hz: \"fast\" is not allowed; allowed: a number"
//   bad enum name       "navigation.mechanization: \"INS\" is not allowed; allowed: NED, SEED000"
//   two oneof members   "motion.segments[0]: static and turn are both set; allowed: one of ..."
// The check knows nothing about driftlab: it walks the message Descriptor by reflection, and
// accepts exactly what the protobuf JSON mapping accepts for each field type (proto field names
// and lowerCamelCase JSON names; numbers or numeric strings for numeric fields; "NaN",
// "Infinity", "-Infinity" for floating-point fields; enum names or numbers; null = absent).
#pragma once

#include <google/protobuf/descriptor.h>
#include <google/protobuf/message.h>
#include <google/protobuf/struct.pb.h>

#include <string>
#include <string_view>

namespace driftlab::app {

// Throws SpecError at the first problem found (unknown keys first, in sorted order, then the
// fields in descriptor order, depth first: deterministic, whatever the order of the JSON object).
// `path` is the prefix of the field paths reported (empty for a top-level message).
void CheckJsonAgainstDescriptor(const google::protobuf::Value& value,
                                const google::protobuf::Descriptor& descriptor,
                                const std::string& path = "");

// Size limits of a job's fields, whatever way it arrives (file or gRPC request): every
// string field at most kMaxJobStringBytes bytes (a job's `name` at most kMaxJobNameBytes), every
// repeated field at most kMaxJobRepeatedFieldSize entries. Checked before any other work.
inline constexpr size_t kMaxJobNameBytes = 256;
inline constexpr size_t kMaxJobStringBytes = 4096;
inline constexpr int kMaxJobRepeatedFieldSize = 100000;

// Throws SpecError naming the first field over a limit above (path, its size, the limit).
void CheckFieldSizes(const google::protobuf::Message& message, const std::string& path = "");

// The values of a parsed message, whatever way it arrived (a binary gRPC request carries what the
// JSON check above never sees): no unknown field, every enum value one the schema defines, every
// double and float finite. Throws SpecError naming the first offending field path.
void CheckMessageValues(const google::protobuf::Message& message, const std::string& path = "");

// True when `path` names a field of `descriptor`'s schema: dot-separated proto field names, each
// repeated field optionally indexed ("motion.segments[2].turn.radius_m", "sensor.gyro.
// fixed_bias_deg_per_h[1]"). Error messages name fields by such paths.
bool IsSchemaFieldPath(const google::protobuf::Descriptor& descriptor, std::string_view path);

}  // namespace driftlab::app
