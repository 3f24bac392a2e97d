// Closed-loop check of the multi-position calibration's reported uncertainties: 100 seeded
// tumbles per catalogue preset, 18 parameters each (9 accelerometer, 9 gyro).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include "driftlab/calib/multi_position.h"
#include "driftlab/calib/static_detection.h"
#include "driftlab/calib/tumble.h"
#include "driftlab/presets.h"

namespace driftlab::calib {
namespace {

// Prints and checks the fraction of |z| <= 3 and the RMS of z over `trials` x 18 normalised errors.
void RunPreset(const std::string& preset, int trials) {
  ImuErrorModel model = FindImuPreset(preset);
  // Constant-bias calibration model: in-run bias terms and g-sensitivity off (see
  // multi_position_test.cc); turn-on bias, scale, misalignment, white noise, range and
  // quantization from the preset. Earth rate off: not in the gyro model (bounded separately).
  model.gyro_g_sensitivity.setZero();
  for (TriadErrorParams* t : {&model.gyro, &model.accel}) {
    t->bias_flicker.bias_instability = 0.0;
    t->bias_gauss_markov = {};
    t->random_walk = 0.0;
  }
  TumbleSpec spec;
  spec.earth_rate = false;
  int within = 0, total = 0;
  double sum2 = 0.0, fit_s = 0.0;
  for (int t = 0; t < trials; ++t) {
    const Tumble tumble = SimulateTumble(spec, model, 77, static_cast<uint32_t>(t));
    const auto start = std::chrono::steady_clock::now();
    const StaticDetection det = DetectStaticIntervals(tumble.recording, {});
    AccelCalibrationOptions ao;
    ao.lat_rad = spec.lat_rad;
    const AccelCalibration accel = CalibrateAccelerometers(det.intervals, ao);
    const GyroCalibration gyro = CalibrateGyros(tumble.recording, det.intervals, accel, {});
    fit_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    Eigen::Matrix3d T_a, T_g;
    TruthInCalibrationFrame(tumble.T_a, tumble.T_g, &T_a, &T_g);
    const double truth[18] = {
        T_a(0, 0) - 1, T_a(1, 1) - 1, T_a(2, 2) - 1, T_a(1, 0),     T_a(2, 0),     T_a(2, 1),
        tumble.b_a[0], tumble.b_a[1], tumble.b_a[2], T_g(0, 0) - 1, T_g(1, 1) - 1, T_g(2, 2) - 1,
        T_g(0, 1),     T_g(0, 2),     T_g(1, 0),     T_g(1, 2),     T_g(2, 0),     T_g(2, 1)};
    for (int i = 0; i < 18; ++i) {
      const FitParameter& p = i < 9 ? accel.fit.parameters[i] : gyro.fit.parameters[i - 9];
      const double z = (p.value - truth[i]) / p.sigma;
      within += std::abs(z) <= 3.0;
      sum2 += z * z;
      ++total;
    }
  }
  const double fraction = double(within) / total;
  const double std_z = std::sqrt(sum2 / total);
  std::printf(
      "%-12s %d trials: within 3 sigma %.4f, std of normalised errors %.3f, "
      "detection + accel + gyro fit %.1f ms per %0.f s tumble\n",
      preset.c_str(), trials, fraction, std_z, 1e3 * fit_s / trials,
      spec.initial_static_s + (spec.pose_count - 1) * (spec.pose_s + spec.rotation_s));
  ::testing::Test::RecordProperty(preset + "_fraction", std::to_string(fraction));
  ::testing::Test::RecordProperty(preset + "_std", std::to_string(std_z));
  // Honest sigmas make z ~ N(0, 1): P(|z| > 3) = 0.27 %, so >= 99 % of 1800 fails by chance with
  // probability ~1e-4 (binomial). Brief's band for the RMS: 0.7..1.3 (for 1800 unit normals the
  // RMS is 1 +- 0.017, so this band tests the order of magnitude, not small biases).
  EXPECT_GE(fraction, 0.99) << preset;
  EXPECT_GT(std_z, 0.7) << preset;
  EXPECT_LT(std_z, 1.3) << preset;
}

TEST(MultiPositionSlow, UncertaintiesHonestIndustrial100Trials) { RunPreset("industrial", 100); }
TEST(MultiPositionSlow, UncertaintiesHonestTactical100Trials) { RunPreset("tactical", 100); }
TEST(MultiPositionSlow, UncertaintiesHonestAdis16470_100Trials) { RunPreset("adis16470", 100); }

}  // namespace
}  // namespace driftlab::calib
