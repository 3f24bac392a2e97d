// The job's `sensor` section: preset, explicit datasheet-unit parameters, preset with overrides;
// every field validated with its path, value and range.
#include "driftlab/app/sensor_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "driftlab/app/job_file.h"
#include "driftlab/presets.h"
#include "driftlab/spec_error.h"

namespace driftlab::app {
namespace {

constexpr double kG = 9.80665;  // standard gravity, exact (CGPM 1901)

v1::Job JobWithSensor(const std::string& sensor) {
  return ParseJobJson(R"({"rate_hz": 100, "sensor": )" + sensor + "}");
}

std::string SensorError(const std::string& sensor) {
  try {
    ToImuErrorModel(JobWithSensor(sensor));
  } catch (const SpecError& e) {
    return e.what();
  }
  return "";
}

TEST(SensorModelSection, AbsentOrEmptySensorMeansIdealData) {
  EXPECT_FALSE(ToImuErrorModel(ParseJobJson(R"({"rate_hz": 100})")).has_value());
  EXPECT_FALSE(ToImuErrorModel(JobWithSensor("{}")).has_value());
}

TEST(SensorModelSection, PresetAloneEqualsTheCatalogueEntry) {
  const auto model = ToImuErrorModel(JobWithSensor(R"({"preset": "tactical"})"));
  ASSERT_TRUE(model.has_value());
  const ImuErrorModel& preset = FindImuPreset("tactical");
  // Exact equality: the same numbers copied, nothing recomputed.
  EXPECT_EQ(model->gyro.white_noise_density, preset.gyro.white_noise_density);
  EXPECT_EQ(model->accel.bias_flicker.bias_instability, preset.accel.bias_flicker.bias_instability);
  EXPECT_EQ(model->gyro.scale_factor_sigma, preset.gyro.scale_factor_sigma);
  EXPECT_EQ(model->name, "tactical");
}

TEST(SensorModelSection, OverridesReplaceOnlyTheFieldsSet) {
  const auto model =
      ToImuErrorModel(JobWithSensor(R"({"preset": "tactical", "gyro": {"arw_deg_per_sqrt_h": 0.3},
                                        "accel": {"fixed_bias_mg": [1, -2, 0.5]}})"));
  ASSERT_TRUE(model.has_value());
  const ImuErrorModel& preset = FindImuPreset("tactical");
  // 1 deg/sqrt(h) = (pi/180) rad / 60 sqrt(s); relative 1e-15 = a few ulp of the conversion.
  EXPECT_NEAR(model->gyro.white_noise_density, 0.3 * kDeg / 60.0, 1e-15 * 0.3 * kDeg / 60.0);
  EXPECT_EQ(model->gyro.bias_flicker.bias_instability, preset.gyro.bias_flicker.bias_instability);
  EXPECT_EQ(model->accel.white_noise_density, preset.accel.white_noise_density);
  // 1 mg = 1e-3 g0 m/s^2 exactly; relative 1e-15 for the product's rounding.
  EXPECT_NEAR(model->accel.fixed_bias.x(), 1e-3 * kG, 1e-15 * kG);
  EXPECT_NEAR(model->accel.fixed_bias.y(), -2e-3 * kG, 1e-15 * kG);
  EXPECT_NEAR(model->accel.fixed_bias.z(), 0.5e-3 * kG, 1e-15 * kG);
}

TEST(SensorModelSection, ExplicitParametersConvertFromDatasheetUnits) {
  const auto model = ToImuErrorModel(JobWithSensor(R"({
      "gyro": {"bias_instability_deg_per_h": 0.5, "gauss_markov_sigma_deg_per_h": 2,
               "gauss_markov_tau_s": 300, "rate_random_walk_deg_per_h_per_sqrt_h": 0.6,
               "scale_factor_fixed_ppm": [100, 200, 300], "misalignment_fixed_mrad": [1, 2, 3, 4, 5, 6],
               "quantization_urad": 2, "range_deg_per_s": 400, "g_sensitivity_deg_per_h_per_g": [1, 2, 3]},
      "accel": {"vrw_m_per_s_per_sqrt_h": 0.06, "bias_instability_ug": 25,
                "acceleration_random_walk_ug_per_sqrt_s": 3, "range_g": 16,
                "quantization_mm_per_s": 1}})"));
  ASSERT_TRUE(model.has_value());
  const double rel = 1e-15;  // conversion factor products: a few ulp
  const double deg_per_h = kDeg / 3600.0;
  EXPECT_NEAR(model->gyro.bias_flicker.bias_instability, 0.5 * deg_per_h, rel * deg_per_h);
  EXPECT_NEAR(model->gyro.bias_gauss_markov.sigma, 2 * deg_per_h, rel * deg_per_h);
  EXPECT_EQ(model->gyro.bias_gauss_markov.tau_s, 300.0);
  // (deg/h)/sqrt(h) = deg/h / 60 sqrt(s).
  EXPECT_NEAR(model->gyro.random_walk, 0.6 * deg_per_h / 60.0, rel * deg_per_h);
  EXPECT_NEAR(model->gyro.scale_factor_fixed.z(), 300e-6, rel);
  EXPECT_NEAR(model->gyro.misalignment_fixed(0, 1), 1e-3, rel);  // xy
  EXPECT_NEAR(model->gyro.misalignment_fixed(1, 0), 3e-3, rel);  // yx
  EXPECT_NEAR(model->gyro.misalignment_fixed(2, 1), 6e-3, rel);  // zy
  EXPECT_EQ(model->gyro.misalignment_fixed(0, 0), 0.0);
  EXPECT_NEAR(model->gyro.quantization, 2e-6, rel);
  EXPECT_NEAR(model->gyro.range, 400 * kDeg, rel * 400 * kDeg);
  EXPECT_NEAR(model->gyro_g_sensitivity(1, 1), 2 * deg_per_h / kG, rel * deg_per_h);
  EXPECT_EQ(model->gyro_g_sensitivity(0, 1), 0.0);
  // (m/s)/sqrt(h) = 1/60 (m/s)/sqrt(s).
  EXPECT_NEAR(model->accel.white_noise_density, 0.06 / 60.0, rel);
  EXPECT_NEAR(model->accel.bias_flicker.bias_instability, 25e-6 * kG, rel * kG);
  EXPECT_NEAR(model->accel.random_walk, 3e-6 * kG, rel * kG);
  EXPECT_NEAR(model->accel.range, 16 * kG, rel * 16 * kG);
  EXPECT_NEAR(model->accel.quantization, 1e-3, rel);
  // Unset terms stay off without a preset.
  EXPECT_EQ(model->gyro.white_noise_density, 0.0);
  EXPECT_EQ(model->accel.turn_on_bias_sigma, 0.0);
}

TEST(SensorModelSection, BadValuesNameTheFieldTheValueAndTheRange) {
  struct Case {
    const char* sensor;
    const char* expected;
  };
  const Case cases[] = {
      {R"({"preset": "no-such-imu"})", "sensor.preset: "},
      {R"({"gyro": {"arw_deg_per_sqrt_h": -0.1}})",
       "sensor.gyro.arw_deg_per_sqrt_h: -0.1 is not allowed; allowed: 0 <= arw_deg_per_sqrt_h"},
      {R"({"accel": {"vrw_m_per_s_per_sqrt_h": "NaN"}})",
       "sensor.accel.vrw_m_per_s_per_sqrt_h: nan is not allowed"},
      {R"({"gyro": {"gauss_markov_sigma_deg_per_h": 1}})",
       "sensor.gyro.gauss_markov_tau_s: 0 is not allowed; allowed: 0 < gauss_markov_tau_s"},
      {R"({"gyro": {"gauss_markov_sigma_deg_per_h": 1, "gauss_markov_tau_s": -5}})",
       "sensor.gyro.gauss_markov_tau_s: -5 is not allowed"},
      {R"({"accel": {"bias_instability_ug": 10, "bias_instability_tau_min_s": 100,
                     "bias_instability_tau_max_s": 10}})",
       "sensor.accel.bias_instability_tau_min_s: 100 is not allowed; allowed: 0 < "
       "bias_instability_tau_min_s < bias_instability_tau_max_s = 10 s"},
      {R"({"accel": {"fixed_bias_mg": [1, 2]}})",
       "sensor.accel.fixed_bias_mg: 2 values is not allowed; allowed: exactly 3 values"},
      {R"({"gyro": {"misalignment_fixed_mrad": [1, 2, 3]}})",
       "sensor.gyro.misalignment_fixed_mrad: 3 values is not allowed; allowed: exactly 6"},
      {R"({"gyro": {"scale_factor_fixed_ppm": [0, 2e5, 0]}})",
       "sensor.gyro.scale_factor_fixed_ppm[1]: 200000 is not allowed; allowed: -100000 <= "
       "scale_factor_fixed_ppm[1] <= 100000 ppm"},
      {R"({"gyro": {"g_sensitivity_deg_per_h_per_g": [1, 2]}})",
       "sensor.gyro.g_sensitivity_deg_per_h_per_g: 2 values is not allowed"},
      {R"({"accel": {"range_g": -1}})", "sensor.accel.range_g: -1 is not allowed"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.sensor);
    const std::string error = SensorError(c.sensor);
    EXPECT_NE(error.find(c.expected), std::string::npos) << error;
  }
}

TEST(SensorModelSection, UnknownFieldIsReportedByTheSchemaCheck) {
  try {
    JobWithSensor(R"({"gyro": {"arw_deg_per_rt_h": 0.1}})");
    FAIL() << "accepted an unknown field";
  } catch (const SpecError& e) {
    EXPECT_NE(std::string(e.what()).find("sensor.gyro.arw_deg_per_rt_h: unknown field"),
              std::string::npos)
        << e.what();
  }
}

TEST(SensorModelSection, SeedComesFromMonteCarloOrTheDefault) {
  EXPECT_EQ(JobSeed(ParseJobJson(R"({"rate_hz": 100})")), kDefaultSeed);
  EXPECT_EQ(JobSeed(ParseJobJson(R"({"rate_hz": 100, "monte_carlo": {"seed": "12345678901"}})")),
            12345678901u);
}

}  // namespace
}  // namespace driftlab::app
