// The sensor-term table (sensor_terms.h): every unit it names is one the units module parses with
// the term's dimension, every term reaches its own parameter, and the datasheet keys are unique.
#include "driftlab/sensor_terms.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>

namespace driftlab {
namespace {

constexpr SensorTriad kTriads[] = {SensorTriad::kGyro, SensorTriad::kAccel};

const char* Name(SensorTriad t) { return t == SensorTriad::kGyro ? "gyro" : "accel"; }

// A unit text of the table parses and has `dimension` (ToSi throws otherwise).
void ExpectUnit(std::string_view unit, Dimension dimension, const std::string& what) {
  if (unit.empty()) return;
  EXPECT_NO_THROW({
    const double si = ToSi(1.0, unit, dimension, what);
    EXPECT_TRUE(std::isfinite(si) && si > 0) << what;
  }) << what
     << ": " << unit;
}

TEST(SensorTermsTest, EveryUnitParsesWithTheTermsDimension) {
  for (const SensorTerm& term : SensorTerms()) {
    for (const SensorTriad t : kTriads) {
      if (!term.applies_to(t) || term.shape == TermShape::kFlag) continue;
      const std::string what = std::string(Name(t)) + "." + std::string(term.param);
      ExpectUnit(term.job_unit.of(t), term.dimension(t), what + " job unit");
      ExpectUnit(term.job_per_unit.of(t), term.per_dimension, what + " job per-unit");
      ExpectUnit(term.preset_density_unit.of(t), term.dimension(t), what + " density unit");
      ExpectUnit(term.report_unit.of(t), term.dimension(t), what + " report unit");
      ExpectUnit(term.preset_si_unit.of(t), term.figure_dimension(t), what + " SI unit");
      if (term.job_per_unit.of(t).empty()) {
        ExpectUnit(term.preset_unit.of(t), term.dimension(t), what + " preset unit");
        // The SI unit's factor is 1.
        if (!term.preset_si_unit.of(t).empty()) {
          EXPECT_EQ(ToSi(1.0, term.preset_si_unit.of(t), term.dimension(t)), 1.0) << what;
        }
      }
    }
  }
}

TEST(SensorTermsTest, EachTermReachesItsOwnParameter) {
  // Writing one value of one term changes that value and nothing any other term reads.
  for (const SensorTerm& term : SensorTerms()) {
    if (term.shape == TermShape::kFlag) continue;
    for (const SensorTriad t : kTriads) {
      if (!term.applies_to(t)) continue;
      for (int i = 0; i < TermValueCount(term.shape); ++i) {
        ImuErrorModel model;
        SetTermValue(term, &model, t, i, 0.125);
        for (const SensorTerm& other : SensorTerms()) {
          if (other.shape == TermShape::kFlag) continue;
          for (const SensorTriad u : kTriads) {
            if (!other.applies_to(u)) continue;
            for (int j = 0; j < TermValueCount(other.shape); ++j) {
              const double defaults = TermValue(other, ImuErrorModel{}, u, j);
              const bool same = &other == &term && u == t && j == i;
              EXPECT_EQ(TermValue(other, model, u, j), same ? 0.125 : defaults)
                  << Name(t) << "." << term.param << "[" << i << "] vs " << Name(u) << "."
                  << other.param << "[" << j << "]";
            }
          }
        }
      }
    }
  }
}

TEST(SensorTermsTest, FieldNumbersAndDatasheetKeysAreUnique) {
  std::set<int> fields;
  for (const SensorTerm& term : SensorTerms()) {
    EXPECT_TRUE(fields.insert(term.proto_field).second) << term.param;
    EXPECT_EQ(SensorTermByField(term.proto_field), &term) << term.param;
  }
  for (const SensorTriad t : kTriads) {
    std::set<std::string_view> keys;
    for (const SensorTerm& term : SensorTerms()) {
      for (const std::string_view key : {term.datasheet_key.of(t), term.datasheet_alt_key.of(t)}) {
        if (!key.empty()) {
          EXPECT_TRUE(keys.insert(key).second) << Name(t) << "." << key;
        }
      }
    }
  }
}

TEST(SensorTermsTest, ARatioUnitConvertsWithOneFactor) {
  const SensorTerm& g = *SensorTermByField(17);
  // 1 (deg/h)/g = (pi / 180 / 3600) / 9.80665 (rad/s)/(m/s^2); the round trip is exact to 2 ulp.
  const double si = JobValueToSi(g, SensorTriad::kGyro, 1.0, "g");
  EXPECT_NEAR(si, M_PI / 180.0 / 3600.0 / 9.80665, 4e-16 * si);
  EXPECT_NEAR(JobValueFromSi(g, SensorTriad::kGyro, si), 1.0, 4.5e-16);
  EXPECT_EQ(JobUnitText(g, SensorTriad::kGyro), "deg/h/g");
}

}  // namespace
}  // namespace driftlab
