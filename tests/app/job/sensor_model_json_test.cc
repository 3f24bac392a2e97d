// ImuErrorModel -> job-schema sensor section (app/sensor_model_json.h) and back through
// app::ToImuErrorModel: the same model to 1e-12 relative (two unit conversions, each exact to
// a few ulp ~ 1e-16; 1e-12 leaves margin and still catches any wrong factor, e.g. 60 or 3600).
#include "driftlab/app/sensor_model_json.h"

#include <gtest/gtest.h>

#include <cmath>

#include "driftlab/app/job_file.h"
#include "driftlab/app/sensor_model.h"
#include "driftlab/presets.h"

namespace driftlab::app {
namespace {

void ExpectClose(double a, double b, const std::string& what) {
  EXPECT_LE(std::fabs(a - b), 1e-12 * std::max(std::fabs(a), std::fabs(b)))
      << what << ": " << a << " vs " << b;
}

void ExpectSameTriad(const TriadErrorParams& a, const TriadErrorParams& b, const std::string& n) {
  for (int i = 0; i < 3; ++i) {
    ExpectClose(a.fixed_bias[i], b.fixed_bias[i], n + ".fixed_bias");
    ExpectClose(a.scale_factor_fixed[i], b.scale_factor_fixed[i], n + ".scale_factor_fixed");
    ExpectClose(a.scale_factor_asymmetry[i], b.scale_factor_asymmetry[i], n + ".asymmetry");
    for (int j = 0; j < 3; ++j) {
      if (i != j) {
        ExpectClose(a.misalignment_fixed(i, j), b.misalignment_fixed(i, j), n + ".misalignment");
      }
    }
  }
  ExpectClose(a.turn_on_bias_sigma, b.turn_on_bias_sigma, n + ".turn_on_bias_sigma");
  ExpectClose(a.bias_flicker.bias_instability, b.bias_flicker.bias_instability, n + ".B");
  if (a.bias_flicker.bias_instability > 0) {
    ExpectClose(a.bias_flicker.tau_min_s, b.bias_flicker.tau_min_s, n + ".tau_min_s");
    ExpectClose(a.bias_flicker.tau_max_s, b.bias_flicker.tau_max_s, n + ".tau_max_s");
  }
  ExpectClose(a.bias_gauss_markov.sigma, b.bias_gauss_markov.sigma, n + ".gm.sigma");
  ExpectClose(a.bias_gauss_markov.tau_s, b.bias_gauss_markov.tau_s, n + ".gm.tau_s");
  ExpectClose(a.white_noise_density, b.white_noise_density, n + ".white_noise_density");
  ExpectClose(a.random_walk, b.random_walk, n + ".random_walk");
  ExpectClose(a.scale_factor_sigma, b.scale_factor_sigma, n + ".scale_factor_sigma");
  ExpectClose(a.misalignment_sigma_rad, b.misalignment_sigma_rad, n + ".misalignment_sigma");
  ExpectClose(a.quantization, b.quantization, n + ".quantization");
  ExpectClose(a.range, b.range, n + ".range");
}

void ExpectRoundTrip(const ImuErrorModel& model) {
  // Through the JSON text, as a user would use the fragment.
  const v1::Job job = ParseJobJson(SensorModelJson(model), model.name);
  const auto back = ToImuErrorModel(job);
  ASSERT_TRUE(back.has_value()) << model.name;
  ExpectSameTriad(model.gyro, back->gyro, model.name + " gyro");
  ExpectSameTriad(model.accel, back->accel, model.name + " accel");
  for (int i = 0; i < 9; ++i) {
    ExpectClose(model.gyro_g_sensitivity(i / 3, i % 3), back->gyro_g_sensitivity(i / 3, i % 3),
                model.name + " g_sensitivity");
  }
}

TEST(SensorModelJsonTest, EveryCataloguePresetRoundTripsThroughTheJobSchema) {
  for (const ImuErrorModel& preset : ImuCatalogue()) ExpectRoundTrip(preset);
}

TEST(SensorModelJsonTest, EveryFieldRoundTripsIncludingMatricesAndGaussMarkov) {
  ImuErrorModel m;
  m.name = "all-fields";
  for (TriadErrorParams* t : {&m.gyro, &m.accel}) {
    const double u = t == &m.gyro ? 1e-5 : 1e-3;  // rad/s or m/s^2 scale
    t->fixed_bias = Eigen::Vector3d(1.1, -2.2, 3.3) * u;
    t->turn_on_bias_sigma = 0.7 * u;
    t->bias_flicker = {0.3 * u, 0.5, 2000.0};
    t->bias_gauss_markov = {0.2 * u, 321.0};
    t->white_noise_density = 0.01 * u;
    t->random_walk = 1e-3 * u;
    t->scale_factor_fixed = Eigen::Vector3d(100e-6, -200e-6, 300e-6);
    t->scale_factor_sigma = 150e-6;
    t->scale_factor_asymmetry = Eigen::Vector3d(10e-6, 20e-6, -30e-6);
    t->misalignment_fixed << 0, 1e-4, -2e-4, 3e-4, 0, 4e-4, -5e-4, 6e-4, 0;
    t->misalignment_sigma_rad = 2e-4;
    t->quantization = t == &m.gyro ? 1e-7 : 1e-4;
    t->range = 100.0 * u * 1e3;
  }
  m.gyro_g_sensitivity << 1e-5, 2e-6, -3e-6, 4e-6, 5e-5, 6e-6, 7e-6, -8e-6, 9e-5;
  ExpectRoundTrip(m);
}

TEST(SensorModelJsonTest, FragmentUsesTheSchemaFieldNamesAndLeavesZeroTermsOut) {
  const std::string json = SensorModelJson(FindImuPreset("tactical"));
  EXPECT_NE(json.find("\"sensor\""), std::string::npos);
  EXPECT_NE(json.find("\"arw_deg_per_sqrt_h\": 0.15"), std::string::npos) << json;
  EXPECT_NE(json.find("\"bias_instability_deg_per_h\": 3"), std::string::npos) << json;
  EXPECT_EQ(json.find("rate_random_walk"), std::string::npos) << json;  // the preset has none
  EXPECT_EQ(json.find("preset"), std::string::npos) << json;
}

}  // namespace
}  // namespace driftlab::app
