#include "driftlab/app/schema_check.h"

#include <fmt/format.h>
#include <google/protobuf/unknown_field_set.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <string_view>
#include <vector>

#include "driftlab/spec_error.h"
#include "text.h"

namespace driftlab::app {
namespace {

using google::protobuf::Descriptor;
using google::protobuf::EnumDescriptor;
using google::protobuf::FieldDescriptor;
using google::protobuf::Value;

std::string FieldNames(const Descriptor& descriptor) {
  std::vector<std::string> names;
  for (int i = 0; i < descriptor.field_count(); ++i) names.push_back(descriptor.field(i)->name());
  return Join(names, ", ");
}

// Enum names a user should write (the *_UNSPECIFIED zero value is accepted but not advertised).
std::string EnumNames(const EnumDescriptor& descriptor) {
  std::vector<std::string> names;
  for (int i = 0; i < descriptor.value_count(); ++i) {
    const std::string& name = descriptor.value(i)->name();
    if (!name.ends_with("_UNSPECIFIED")) names.push_back(name);
  }
  return Join(names, ", ");
}

// The value as the user wrote it, for messages: numbers in shortest form, strings quoted.
std::string Describe(const Value& value) {
  switch (value.kind_case()) {
    case Value::kNumberValue:
      return fmt::format("{}", value.number_value());
    case Value::kStringValue: {
      std::string_view text = value.string_value();
      constexpr size_t kMaxShown = 60;
      if (text.size() > kMaxShown) return fmt::format("\"{}...\"", text.substr(0, kMaxShown));
      return fmt::format("\"{}\"", text);
    }
    case Value::kBoolValue:
      return value.bool_value() ? "true" : "false";
    case Value::kStructValue:
      return "an object";
    case Value::kListValue:
      return "a list";
    default:
      return "null";
  }
}

std::string Child(const std::string& path, std::string_view name) {
  return path.empty() ? std::string(name) : fmt::format("{}.{}", path, name);
}

// Finds a field by its proto name or its JSON (lowerCamelCase) name, as the JSON parser does.
const FieldDescriptor* FindField(const Descriptor& descriptor, const std::string& key) {
  for (int i = 0; i < descriptor.field_count(); ++i) {
    const FieldDescriptor* field = descriptor.field(i);
    if (field->name() == key || field->json_name() == key) return field;
  }
  return nullptr;
}

std::string IntegerRange(const FieldDescriptor& field) {
  switch (field.cpp_type()) {
    case FieldDescriptor::CPPTYPE_INT32:
      return "an integer from -2147483648 to 2147483647";
    case FieldDescriptor::CPPTYPE_UINT32:
      return "an integer from 0 to 4294967295";
    case FieldDescriptor::CPPTYPE_UINT64:
      return "an integer from 0 to 18446744073709551615";
    default:
      return "an integer from -9223372036854775808 to 9223372036854775807";
  }
}

bool IntegerInRange(const FieldDescriptor& field, double x) {
  if (!std::isfinite(x) || x != std::floor(x)) return false;
  switch (field.cpp_type()) {
    case FieldDescriptor::CPPTYPE_INT32:
      return x >= std::numeric_limits<int32_t>::min() && x <= std::numeric_limits<int32_t>::max();
    case FieldDescriptor::CPPTYPE_UINT32:
      return x >= 0 && x <= std::numeric_limits<uint32_t>::max();
    case FieldDescriptor::CPPTYPE_UINT64:
      return x >= 0 && x < 18446744073709551616.0;  // 2^64
    default:
      return x >= -9223372036854775808.0 && x < 9223372036854775808.0;  // [-2^63, 2^63)
  }
}

void CheckMessage(const Value& value, const Descriptor& descriptor, const std::string& path);

// One non-repeated value of `field` (also each element of a repeated field).
void CheckSingle(const Value& value, const FieldDescriptor& field, const std::string& path) {
  if (value.kind_case() == Value::kNullValue) {
    // null means "absent" for a field, but is not a value inside a list.
    if (field.is_repeated())
      throw SpecError(path, "null", std::string("a value of type ") + field.type_name());
    return;
  }
  switch (field.cpp_type()) {
    case FieldDescriptor::CPPTYPE_MESSAGE:
      CheckMessage(value, *field.message_type(), path);
      return;
    case FieldDescriptor::CPPTYPE_DOUBLE:
    case FieldDescriptor::CPPTYPE_FLOAT: {
      double x = 0.0;
      if (value.kind_case() == Value::kNumberValue) return;
      if (value.kind_case() == Value::kStringValue) {
        const std::string& s = value.string_value();
        if (s == "NaN" || s == "Infinity" || s == "-Infinity" || ParseWholeNumber(s, &x)) return;
      }
      throw SpecError(path, Describe(value), "a number");
    }
    case FieldDescriptor::CPPTYPE_INT32:
    case FieldDescriptor::CPPTYPE_INT64:
    case FieldDescriptor::CPPTYPE_UINT32:
    case FieldDescriptor::CPPTYPE_UINT64: {
      double x = 0.0;
      bool ok = false;
      if (value.kind_case() == Value::kNumberValue) {
        ok = IntegerInRange(field, value.number_value());
      } else if (value.kind_case() == Value::kStringValue) {
        ok = ParseWholeNumber(value.string_value(), &x) && IntegerInRange(field, x);
      }
      if (!ok) throw SpecError(path, Describe(value), IntegerRange(field));
      return;
    }
    case FieldDescriptor::CPPTYPE_BOOL:
      if (value.kind_case() != Value::kBoolValue) {
        throw SpecError(path, Describe(value), "true or false");
      }
      return;
    case FieldDescriptor::CPPTYPE_STRING:
      if (value.kind_case() != Value::kStringValue)
        throw SpecError(path, Describe(value), "a string");
      return;
    case FieldDescriptor::CPPTYPE_ENUM: {
      const EnumDescriptor& enum_type = *field.enum_type();
      if (value.kind_case() == Value::kStringValue &&
          enum_type.FindValueByName(value.string_value()) != nullptr) {
        return;
      }
      if (value.kind_case() == Value::kNumberValue) {
        double x = value.number_value();
        if (x == std::floor(x) && std::abs(x) < 2147483648.0 &&
            enum_type.FindValueByNumber(static_cast<int>(x)) != nullptr) {
          return;
        }
      }
      throw SpecError(path, Describe(value), EnumNames(enum_type));
    }
  }
}

void CheckField(const Value& value, const FieldDescriptor& field, const std::string& path) {
  if (field.is_map()) {
    if (value.kind_case() == Value::kNullValue) return;
    if (value.kind_case() != Value::kStructValue)
      throw SpecError(path, Describe(value), "an object");
    const FieldDescriptor& map_value = *field.message_type()->map_value();
    for (const auto& [key, element] : value.struct_value().fields()) {
      CheckSingle(element, map_value, fmt::format("{}[\"{}\"]", path, key));
    }
    return;
  }
  if (field.is_repeated()) {
    if (value.kind_case() == Value::kNullValue) return;
    if (value.kind_case() != Value::kListValue) throw SpecError(path, Describe(value), "a list");
    const auto& elements = value.list_value().values();
    for (int i = 0; i < elements.size(); ++i) {
      CheckSingle(elements[i], field, fmt::format("{}[{}]", path, i));
    }
    return;
  }
  CheckSingle(value, field, path);
}

void CheckMessage(const Value& value, const Descriptor& descriptor, const std::string& path) {
  // Well-known types have their own JSON forms (Duration "1s", Struct ...): protobuf checks them.
  if (descriptor.file()->package() == "google.protobuf") return;
  if (value.kind_case() != Value::kStructValue) {
    throw SpecError(path.empty() ? std::string("job") : path, Describe(value),
                    "an object with fields " + FieldNames(descriptor));
  }
  // google.protobuf.Struct keeps its fields in a hash map: sort the keys so that which error is
  // reported first does not depend on hashing.
  const auto& fields = value.struct_value().fields();
  std::vector<std::string> keys;
  keys.reserve(fields.size());
  for (const auto& entry : fields) keys.push_back(entry.first);
  std::sort(keys.begin(), keys.end());
  for (const std::string& key : keys) {
    if (FindField(descriptor, key) == nullptr) {
      throw SpecError(Child(path, key), "unknown field; allowed: " + FieldNames(descriptor), 0);
    }
  }
  std::vector<const FieldDescriptor*> oneof_member_set(descriptor.oneof_decl_count(), nullptr);
  for (int i = 0; i < descriptor.field_count(); ++i) {
    const FieldDescriptor& field = *descriptor.field(i);
    const Value* field_value = nullptr;
    for (const auto& [key, element] : fields) {
      if (key == field.name() || key == field.json_name()) {
        if (field_value != nullptr) {
          throw SpecError(Child(path, field.name()),
                          fmt::format("given twice (as {} and {}); allowed: once", field.name(),
                                      field.json_name()),
                          0);
        }
        field_value = &element;
      }
    }
    if (field_value == nullptr) continue;
    const auto* oneof = field.real_containing_oneof();
    if (oneof != nullptr && field_value->kind_case() != Value::kNullValue) {
      const FieldDescriptor*& first = oneof_member_set[oneof->index()];
      if (first != nullptr) {
        std::vector<std::string> members;
        for (int m = 0; m < oneof->field_count(); ++m) members.push_back(oneof->field(m)->name());
        throw SpecError(path.empty() ? std::string(oneof->name()) : path,
                        fmt::format("{} and {} are both set; allowed: exactly one of {}",
                                    first->name(), field.name(), Join(members, ", ")),
                        0);
      }
      first = &field;
    }
    CheckField(*field_value, field, Child(path, field.name()));
  }
}

}  // namespace

void CheckJsonAgainstDescriptor(const Value& value, const Descriptor& descriptor,
                                const std::string& path) {
  CheckMessage(value, descriptor, path);
}

void CheckFieldSizes(const google::protobuf::Message& message, const std::string& path) {
  using google::protobuf::FieldDescriptor;
  const google::protobuf::Reflection& r = *message.GetReflection();
  std::vector<const FieldDescriptor*> fields;
  r.ListFields(message, &fields);
  for (const FieldDescriptor* field : fields) {
    const std::string name = path.empty() ? field->name() : path + "." + field->name();
    const int count = field->is_repeated() ? r.FieldSize(message, field) : 1;
    if (field->is_repeated() && count > kMaxJobRepeatedFieldSize) {
      throw SpecError(name, std::to_string(count) + " entries",
                      "at most " + std::to_string(kMaxJobRepeatedFieldSize) + " entries");
    }
    if (field->cpp_type() == FieldDescriptor::CPPTYPE_STRING) {
      const size_t limit =
          path.empty() && field->name() == "name" ? kMaxJobNameBytes : kMaxJobStringBytes;
      for (int i = 0; i < count; ++i) {
        std::string scratch;
        const std::string& value = field->is_repeated()
                                       ? r.GetRepeatedStringReference(message, field, i, &scratch)
                                       : r.GetStringReference(message, field, &scratch);
        if (value.size() > limit) {
          throw SpecError(field->is_repeated() ? name + "[" + std::to_string(i) + "]" : name,
                          std::to_string(value.size()) + " bytes",
                          "at most " + std::to_string(limit) + " bytes");
        }
      }
    } else if (field->cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE) {
      for (int i = 0; i < count; ++i) {
        const google::protobuf::Message& child = field->is_repeated()
                                                     ? r.GetRepeatedMessage(message, field, i)
                                                     : r.GetMessage(message, field);
        CheckFieldSizes(child, field->is_repeated() ? name + "[" + std::to_string(i) + "]" : name);
      }
    }
  }
}

namespace {

std::string FieldPath(const std::string& path, const FieldDescriptor& field, int index) {
  std::string out = path.empty() ? field.name() : path + "." + field.name();
  if (index >= 0) out += "[" + std::to_string(index) + "]";
  return out;
}

void CheckFieldValue(const google::protobuf::Message& message, const FieldDescriptor& field,
                     int index, const std::string& path) {
  const google::protobuf::Reflection& r = *message.GetReflection();
  const bool repeated = field.is_repeated();
  switch (field.cpp_type()) {
    case FieldDescriptor::CPPTYPE_ENUM: {
      const int value = repeated ? r.GetRepeatedEnumValue(message, &field, index)
                                 : r.GetEnumValue(message, &field);
      if (field.enum_type()->FindValueByNumber(value) == nullptr) {
        throw SpecError(FieldPath(path, field, index), std::to_string(value),
                        EnumNames(*field.enum_type()));
      }
      break;
    }
    case FieldDescriptor::CPPTYPE_DOUBLE:
    case FieldDescriptor::CPPTYPE_FLOAT: {
      const double value = field.cpp_type() == FieldDescriptor::CPPTYPE_DOUBLE
                               ? (repeated ? r.GetRepeatedDouble(message, &field, index)
                                           : r.GetDouble(message, &field))
                               : (repeated ? r.GetRepeatedFloat(message, &field, index)
                                           : r.GetFloat(message, &field));
      if (!std::isfinite(value)) {
        throw SpecError(FieldPath(path, field, index),
                        std::isnan(value) ? "NaN" : (value > 0 ? "Infinity" : "-Infinity"),
                        "a finite number");
      }
      break;
    }
    case FieldDescriptor::CPPTYPE_MESSAGE:
      CheckMessageValues(
          repeated ? r.GetRepeatedMessage(message, &field, index) : r.GetMessage(message, &field),
          FieldPath(path, field, index));
      break;
    default:
      break;
  }
}

}  // namespace

void CheckMessageValues(const google::protobuf::Message& message, const std::string& path) {
  const google::protobuf::Reflection& r = *message.GetReflection();
  const google::protobuf::UnknownFieldSet& unknown = r.GetUnknownFields(message);
  if (!unknown.empty()) {
    throw SpecError(path.empty() ? "(job)" : path,
                    "unknown field number " + std::to_string(unknown.field(0).number()),
                    "the fields of " + message.GetDescriptor()->full_name());
  }
  std::vector<const FieldDescriptor*> fields;
  r.ListFields(message, &fields);  // set fields, in field-number order
  for (const FieldDescriptor* field : fields) {
    if (field->is_map()) continue;
    if (field->is_repeated()) {
      for (int i = 0; i < r.FieldSize(message, field); ++i) {
        CheckFieldValue(message, *field, i, path);
      }
    } else {
      CheckFieldValue(message, *field, -1, path);
    }
  }
}

bool IsSchemaFieldPath(const Descriptor& descriptor, std::string_view path) {
  const Descriptor* message = &descriptor;
  while (!path.empty()) {
    if (message == nullptr) return false;  // a scalar field has no sub-fields
    const size_t dot = path.find('.');
    std::string_view part = path.substr(0, dot);
    path = dot == std::string_view::npos ? std::string_view() : path.substr(dot + 1);
    if (dot != std::string_view::npos && path.empty()) return false;  // a trailing dot
    const size_t bracket = part.find('[');
    const std::string_view name = part.substr(0, bracket);
    const FieldDescriptor* field = message->FindFieldByName(std::string(name));
    if (field == nullptr) return false;
    if (bracket != std::string_view::npos) {
      // [digits] once, only on a repeated field, and nothing after it.
      const std::string_view index = part.substr(bracket);
      if (!field->is_repeated() || index.size() < 3 || index.back() != ']' ||
          index.substr(1, index.size() - 2).find_first_not_of("0123456789") !=
              std::string_view::npos) {
        return false;
      }
    }
    message =
        field->cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE ? field->message_type() : nullptr;
  }
  return true;
}

}  // namespace driftlab::app
