// Strict JSON syntax check (RFC 8259) with limits, run before protobuf's JSON parser sees a text:
// protobuf's parser accepts some non-JSON (single quotes, trailing commas) and takes super-linear
// time on deeply nested arrays, so every JSON input of driftlab (job files, result files, job JSON
// in gRPC requests) passes this check first. One pass, no recursion, O(size).
#pragma once

#include <cstddef>
#include <string_view>

namespace driftlab::app {

// Deepest nesting of arrays and objects in any JSON input. Jobs and results nest at most ~8 levels.
inline constexpr int kMaxJsonDepth = 64;

// Throws SpecError(source, "invalid <kind> at line L, column C: <reason>; allowed: ...") when
// `text` is not exactly one RFC 8259 JSON value (surrounded by whitespace only), or when it nests
// deeper than max_depth.
void CheckJsonSyntax(std::string_view text, std::string_view source, std::string_view kind = "JSON",
                     int max_depth = kMaxJsonDepth);

}  // namespace driftlab::app
