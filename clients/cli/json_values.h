// google.protobuf.Value builders for the commands' JSON outputs (`allan --json`, `presets --json`):
// a number (null when not finite: JSON has no NaN or infinity) and a string.
#pragma once

#include <google/protobuf/struct.pb.h>

#include <cmath>
#include <string>

namespace driftlab::cli {

inline google::protobuf::Value JsonNumber(double v) {
  google::protobuf::Value value;
  if (std::isfinite(v)) {
    value.set_number_value(v);
  } else {
    value.set_null_value(google::protobuf::NULL_VALUE);
  }
  return value;
}

inline google::protobuf::Value JsonText(const std::string& s) {
  google::protobuf::Value value;
  value.set_string_value(s);
  return value;
}

}  // namespace driftlab::cli
