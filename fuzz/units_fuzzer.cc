// Fuzz target: the units parser (fuzz_targets.h). The input is a unit or a quantity text, as in a
// datasheet figure, an `allan --unit` option or a column name's suffix.
#include <array>

#include "driftlab/spec_error.h"
#include "driftlab/units.h"
#include "fuzz_support.h"
#include "fuzz_targets.h"

namespace driftlab::fuzz {

void FuzzUnits(const uint8_t* data, size_t size) {
  const std::string_view text = AsText(data, size);
  try {
    const Unit unit = ParseUnit(text, "fuzz");
    FromSi(1.0, text);
    FormatQuantity(unit.si_factor, text, 3);
    FormatQuantity(-1e308, text, 0);
  } catch (const SpecError&) {
  }
  constexpr std::array<Dimension, 15> kDimensions = {
      dims::kDimensionless,      dims::kAngle,          dims::kAngularRate,
      dims::kAngularAcceleration, dims::kAngleRandomWalk, dims::kRateRandomWalk,
      dims::kLength,             dims::kVelocity,       dims::kAcceleration,
      dims::kJerk,               dims::kVelocityRandomWalk, dims::kAccelRandomWalk,
      dims::kTime,               dims::kFrequency,      Dimension{1, 3, -7}};
  for (const Dimension& dimension : kDimensions) {
    try {
      ParseQuantity(text, dimension, "fuzz");
    } catch (const SpecError&) {
    }
  }
}

}  // namespace driftlab::fuzz
