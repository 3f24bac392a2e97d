// Range checks shared by the aiding sensors' validation (a SpecError naming the field, the value
// and the allowed range).
#pragma once

#include <cmath>
#include <string>

#include "driftlab/spec_error.h"

namespace driftlab::aiding_checks {

// A 1-sigma: finite, 0 < (or 0 <= with positive = false) value <= max [unit].
inline void CheckSigma(double value, const std::string& field, double max, const std::string& unit,
                       bool positive) {
  const bool ok = std::isfinite(value) && (positive ? value > 0.0 : value >= 0.0) && value <= max;
  if (!ok) {
    throw SpecError(
        field, ValueText(value),
        std::string(positive ? "0 < " : "0 <= ") + "sigma <= " + ValueText(max) + " " + unit);
  }
}

}  // namespace driftlab::aiding_checks
