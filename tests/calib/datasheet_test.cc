// Datasheet summary -> model (calib/datasheet.h): catalogue IMUs written as datasheet files give
// the presets' numbers; bad inputs are named with key, value and allowed units.
#include "driftlab/calib/datasheet.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "driftlab/presets.h"
#include "driftlab/spec_error.h"

namespace driftlab::calib {
namespace {

const std::string kData = std::string(DRIFTLAB_SOURCE_DIR) + "/tests/cli/data/";

// presets.cc converts with constexpr factors, the datasheet path with the units module: the same
// exact definitions in a different order of operations, a few ulp apart -> 1e-12 relative.
void ExpectClose(double a, double b, const std::string& what) {
  EXPECT_LE(std::fabs(a - b), 1e-12 * std::max(std::fabs(a), std::fabs(b)))
      << what << ": " << a << " vs " << b;
}

void ExpectTriad(const TriadErrorParams& a, const TriadErrorParams& b, const std::string& n) {
  ExpectClose(a.white_noise_density, b.white_noise_density, n + " white noise");
  ExpectClose(a.bias_flicker.bias_instability, b.bias_flicker.bias_instability, n + " B");
  ExpectClose(a.bias_flicker.tau_min_s, b.bias_flicker.tau_min_s, n + " tau_min");
  ExpectClose(a.bias_flicker.tau_max_s, b.bias_flicker.tau_max_s, n + " tau_max");
  ExpectClose(a.turn_on_bias_sigma, b.turn_on_bias_sigma, n + " turn-on bias");
  ExpectClose(a.scale_factor_sigma, b.scale_factor_sigma, n + " scale factor");
  ExpectClose(a.misalignment_sigma_rad, b.misalignment_sigma_rad, n + " misalignment");
  ExpectClose(a.range, b.range, n + " range");
  ExpectClose(a.random_walk, b.random_walk, n + " random walk");
  ExpectClose(a.quantization, b.quantization, n + " quantization");
}

TEST(DatasheetTest, TacticalDatasheetGivesThePresetNumbers) {
  const DatasheetModel d = LoadDatasheet(kData + "datasheet_tactical.yaml");
  const ImuErrorModel& preset = FindImuPreset("tactical");
  EXPECT_EQ(d.model.name, "tactical");
  ExpectTriad(d.model.gyro, preset.gyro, "gyro");
  ExpectTriad(d.model.accel, preset.accel, "accel");
  ASSERT_EQ(d.values.size(), 12u);
  EXPECT_EQ(d.values[0].key, "gyro.arw");
  EXPECT_EQ(d.values[0].si_unit, "rad/sqrt(s)");
  EXPECT_EQ(d.values[0].field, "gyro.white_noise_density");
}

TEST(DatasheetTest, Stim300FlowMappingDatasheetGivesThePresetNumbersWithGSensitivity) {
  const DatasheetModel d = LoadDatasheet(kData + "datasheet_stim300.yaml");
  const ImuErrorModel& preset = FindImuPreset("stim300-rev9");
  ExpectTriad(d.model.gyro, preset.gyro, "gyro");
  ExpectTriad(d.model.accel, preset.accel, "accel");
  for (int i = 0; i < 9; ++i) {
    ExpectClose(d.model.gyro_g_sensitivity(i / 3, i % 3), preset.gyro_g_sensitivity(i / 3, i % 3),
                "g sensitivity");
  }
}

std::string ErrorOf(const std::string& file) {
  try {
    LoadDatasheet(kData + file);
  } catch (const SpecError& e) {
    return e.what();
  }
  return "no error";
}

TEST(DatasheetTest, BadInputsNameTheKeyTheValueAndTheAllowedUnits) {
  const std::string bad_unit = ErrorOf("datasheet_bad_unit.yaml");
  EXPECT_NE(bad_unit.find("gyro.arw"), std::string::npos) << bad_unit;
  EXPECT_NE(bad_unit.find("furlong"), std::string::npos) << bad_unit;

  const std::string dimension = ErrorOf("datasheet_wrong_dimension.yaml");
  EXPECT_NE(dimension.find("gyro.arw"), std::string::npos) << dimension;
  EXPECT_NE(dimension.find("0.15 deg/h"), std::string::npos) << dimension;
  EXPECT_NE(dimension.find("deg/sqrt(h)"), std::string::npos) << dimension;  // allowed units

  const std::string unknown = ErrorOf("datasheet_unknown_key.yaml");
  EXPECT_NE(unknown.find("accel.bias_stability"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("bias_instability"), std::string::npos) << unknown;  // allowed keys

  const std::string negative = ErrorOf("datasheet_negative.yaml");
  EXPECT_NE(negative.find("gyro.bias_instability"), std::string::npos) << negative;
  EXPECT_NE(negative.find("-3 deg/h"), std::string::npos) << negative;

  EXPECT_NE(ErrorOf("no_such_datasheet.yaml").find("DATASHEET"), std::string::npos);
  EXPECT_THROW(ParseDatasheetText("gyro:\n  arw: \"0.1 deg/√h\n", "t"), SpecError);  // open quote
  EXPECT_THROW(ParseDatasheetText("sensor: x\n", "t"), SpecError);  // unknown top-level key
  EXPECT_THROW(ParseDatasheetText("gyro:\n  arw: 1 deg/√h\n  arw: 2 deg/√h\n", "t"), SpecError);
  EXPECT_THROW(DatasheetToModel(ParseDatasheetText(
                   "gyro: {arw: 0.1 deg/√h, rate_noise_density: 0.01 deg/s/√Hz}", "t")),
               SpecError);  // two values for one field
  EXPECT_THROW(DatasheetToModel(ParseDatasheetText("gyro: {gauss_markov_sigma: 1 deg/h}", "t")),
               SpecError);  // tau missing
}

// yaml-cpp's LoadAll never returns on a ',' at a document's top level (yaml_document.h): such
// texts are refused, as is a second document.
TEST(DatasheetTest, StrayTopLevelCommaIsRefusedInsteadOfLoopingForever) {
  for (const std::string text : {",", "\n,", "# comment\n,", "name: x\n---\n,"}) {
    try {
      ParseDatasheetText(text, "t.yaml");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const SpecError& e) {
      EXPECT_NE(std::string(e.what()).find("more than one YAML document"), std::string::npos)
          << e.what();
    }
  }
  EXPECT_THROW(ParseDatasheetText("gyro: {arw: 0.1 deg/√h}\n---\ngyro: {arw: 0.2 deg/√h}\n", "t"),
               SpecError);
  EXPECT_EQ(ParseDatasheetText("gyro: {arw: 0.1 deg/√h}\n", "t").size(), 1u);
}

}  // namespace
}  // namespace driftlab::calib
