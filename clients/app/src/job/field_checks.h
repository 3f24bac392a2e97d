// Range checks shared by the translation files of the job schema (translate.cc, sensor_model.cc,
// monte_carlo_spec.cc): each throws SpecError(path, value, allowed range) on a bad number.
// Internal to driftlab_app.
#pragma once

#include <fmt/format.h>

#include <cmath>
#include <string>
#include <string_view>

#include "driftlab/spec_error.h"

namespace driftlab::app {

// A closed, open or half-open interval with its unit, optionally excluding zero.
struct Range {
  double lo = 0.0;
  double hi = 0.0;
  bool lo_open = false;
  bool hi_open = false;
  std::string_view unit;
  bool nonzero = false;
  std::string note;  // appended to the allowed text, e.g. "(rate_hz / 2)"
};

inline Range Closed(double lo, double hi, std::string_view unit) {
  Range range;
  range.lo = lo;
  range.hi = hi;
  range.unit = unit;
  return range;
}
// (0, hi]: a strictly positive quantity.
inline Range Positive(double hi, std::string_view unit) {
  Range range = Closed(0.0, hi, unit);
  range.lo_open = true;
  return range;
}
// [-limit, limit] without 0: a signed, non-zero quantity.
inline Range NonZero(double limit, std::string_view unit) {
  Range range = Closed(-limit, limit, unit);
  range.nonzero = true;
  return range;
}

inline std::string Leaf(std::string_view path) {
  size_t dot = path.rfind('.');
  return std::string(dot == std::string_view::npos ? path : path.substr(dot + 1));
}

inline std::string Allowed(std::string_view path, const Range& range) {
  std::string unit = range.unit.empty() ? "" : fmt::format(" {}", range.unit);
  std::string text =
      fmt::format("{} {} {} {} {}{}", range.lo, range.lo_open ? "<" : "<=", Leaf(path),
                  range.hi_open ? "<" : "<=", range.hi, unit);
  if (range.nonzero) text += ", not 0";
  if (!range.note.empty()) text += " " + range.note;
  return text;
}

inline double Check(const std::string& path, double value, const Range& range) {
  const bool ok = std::isfinite(value) && (range.lo_open ? value > range.lo : value >= range.lo) &&
                  (range.hi_open ? value < range.hi : value <= range.hi) &&
                  !(range.nonzero && value == 0.0);
  if (!ok) throw SpecError(path, fmt::format("{}", value), Allowed(path, range));
  return value;
}

inline double Required(const std::string& path, bool has, double value, const Range& range) {
  if (!has) throw SpecError(path, "", Allowed(path, range));
  return Check(path, value, range);
}

inline double OptionalOr(const std::string& path, bool has, double value, double default_value,
                         const Range& range) {
  return has ? Check(path, value, range) : default_value;
}

}  // namespace driftlab::app
