// Multi-position calibration (Tedaldi et al., ICRA 2014) on simulated tumbles: exact recovery
// without noise, honest uncertainties with noise (few trials; 100 per preset in
// multi_position_slow_test.cc), and the clear failures for data that cannot determine the model.
#include "driftlab/calib/multi_position.h"

#include <gtest/gtest.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>

#include "driftlab/calib/static_detection.h"
#include "driftlab/calib/tumble.h"
#include "driftlab/presets.h"
#include "driftlab/spec_error.h"
#include "support/spec_errors.h"

namespace driftlab::calib {
namespace {

// A model with fixed (known) injected errors and no noise.
ImuErrorModel NoiseFreeModel() {
  ImuErrorModel m;
  m.name = "test";
  m.accel.fixed_bias = Eigen::Vector3d(0.05, -0.08, 0.12);                          // m/s^2
  m.accel.scale_factor_fixed = Eigen::Vector3d(2e-3, -1.5e-3, 3e-3);                // -
  m.accel.misalignment_fixed << 0, 1e-3, -2e-3, 1.5e-3, 0, 0.5e-3, -1e-3, 2e-3, 0;  // rad
  m.gyro.fixed_bias = Eigen::Vector3d(1e-3, -2e-3, 0.5e-3);                         // rad/s
  m.gyro.scale_factor_fixed = Eigen::Vector3d(4e-3, -3e-3, 2e-3);
  m.gyro.misalignment_fixed << 0, 2e-3, -1e-3, 1e-3, 0, -2e-3, 3e-3, 1e-3, 0;
  return m;
}

using testing::ErrorOf;

TEST(MultiPosition, NoiseFreeTumbleRecoversInjectedErrorsExactly) {
  TumbleSpec spec;
  spec.earth_rate = false;  // the gyro model has no Earth rate; see the next test
  const Tumble tumble = SimulateTumble(spec, NoiseFreeModel(), 1, 0);
  const StaticDetection det = DetectStaticIntervals(tumble.recording, {});
  ASSERT_EQ(det.intervals.size(), static_cast<size_t>(spec.pose_count));
  AccelCalibrationOptions ao;
  ao.lat_rad = spec.lat_rad;
  const AccelCalibration accel = CalibrateAccelerometers(det.intervals, ao);
  const GyroCalibration gyro = CalibrateGyros(tumble.recording, det.intervals, accel, {});
  Eigen::Matrix3d T_a, T_g;
  TruthInCalibrationFrame(tumble.T_a, tumble.T_g, &T_a, &T_g);
  // Noise-free data fit the model exactly: errors are solver tolerance and rounding (1e-9), far
  // below the 1e-3 injected values.
  EXPECT_LT((accel.T_a - T_a).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((accel.b_a - tumble.b_a).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((gyro.T_g - T_g).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((gyro.b_g - tumble.b_g).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT(accel.fit.residual_rms, 1e-9);
  EXPECT_LT(gyro.fit.residual_rms, 1e-9);
}

TEST(MultiPosition, EarthRateErrorOfGyroFitStaysWithinItsBound) {
  TumbleSpec spec;  // earth_rate = true, lat 45 deg, 1 s rotations
  const Tumble tumble = SimulateTumble(spec, NoiseFreeModel(), 1, 0);
  const StaticDetection det = DetectStaticIntervals(tumble.recording, {});
  AccelCalibrationOptions ao;
  ao.lat_rad = spec.lat_rad;
  const AccelCalibration accel = CalibrateAccelerometers(det.intervals, ao);
  const GyroCalibration gyro = CalibrateGyros(tumble.recording, det.intervals, accel, {});
  Eigen::Matrix3d T_a, T_g;
  TruthInCalibrationFrame(tumble.T_a, tumble.T_g, &T_a, &T_g);
  // Accelerometers do not see Earth rate: exact as above.
  EXPECT_LT((accel.T_a - T_a).cwiseAbs().maxCoeff(), 1e-9);
  // Unmodelled rate error |omega_ie_b(t) - omega_ie_b(pose 0)| <= 2 omega_ie over each
  // integration gap t_gap (rotation plus the window margins), against rotations of >= 80 deg:
  // per-rotation relative error <= 2 omega_ie t_gap / 80 deg; times 2 for the least-squares
  // amplification by the conditioning of this rotation set (rotation-axis singular values
  // ~0.4-0.8).
  double t_gap = 0.0;
  for (size_t k = 0; k + 1 < det.intervals.size(); ++k) {
    t_gap = std::max(t_gap, det.intervals[k + 1].t_begin_s - det.intervals[k].t_end_s);
  }
  const double bound = 2.0 * 2.0 * 7.292115e-5 * t_gap / (80.0 * M_PI / 180.0);
  const double error = (gyro.T_g - T_g).cwiseAbs().maxCoeff();
  EXPECT_LT(error, bound);
  EXPECT_GT(error, 1e-7);  // the effect is real (not hidden by a mistake in the simulator)
  ::testing::Test::RecordProperty("earth_rate_gyro_error", std::to_string(error));
}

// Fraction within 3 sigma and std of normalised errors of the 9 accel + 9 gyro parameters.
void CheckHonesty(const std::string& preset, int trials, double min_fraction, double std_lo,
                  double std_hi) {
  ImuErrorModel model = FindImuPreset(preset);
  // The calibration model has constant biases and no g-sensitivity: in-run bias variation
  // (flicker, Gauss-Markov, random walk) is what the Allan-deviation fit characterises, not this
  // one, and with it the "true" bias of a recording is not the injected constant. Kept from the
  // preset: turn-on bias, scale factor, misalignment (random per run), white noise, range,
  // quantization.
  model.gyro_g_sensitivity.setZero();
  for (TriadErrorParams* t : {&model.gyro, &model.accel}) {
    t->bias_flicker.bias_instability = 0.0;
    t->bias_gauss_markov = {};
    t->random_walk = 0.0;
  }
  TumbleSpec spec;
  spec.earth_rate = false;  // not part of the gyro model (bounded separately above)
  int within = 0, total = 0;
  double sum2 = 0.0;
  for (int t = 0; t < trials; ++t) {
    const Tumble tumble = SimulateTumble(spec, model, 2024, static_cast<uint32_t>(t));
    const StaticDetection det = DetectStaticIntervals(tumble.recording, {});
    AccelCalibrationOptions ao;
    ao.lat_rad = spec.lat_rad;
    const AccelCalibration accel = CalibrateAccelerometers(det.intervals, ao);
    const GyroCalibration gyro = CalibrateGyros(tumble.recording, det.intervals, accel, {});
    Eigen::Matrix3d T_a, T_g;
    TruthInCalibrationFrame(tumble.T_a, tumble.T_g, &T_a, &T_g);
    const double truth_a[9] = {T_a(0, 0) - 1, T_a(1, 1) - 1, T_a(2, 2) - 1, T_a(1, 0),    T_a(2, 0),
                               T_a(2, 1),     tumble.b_a[0], tumble.b_a[1], tumble.b_a[2]};
    const double truth_g[9] = {T_g(0, 0) - 1, T_g(1, 1) - 1, T_g(2, 2) - 1, T_g(0, 1), T_g(0, 2),
                               T_g(1, 0),     T_g(1, 2),     T_g(2, 0),     T_g(2, 1)};
    for (int i = 0; i < 18; ++i) {
      const FitParameter& p = i < 9 ? accel.fit.parameters[i] : gyro.fit.parameters[i - 9];
      const double z = (p.value - (i < 9 ? truth_a[i] : truth_g[i - 9])) / p.sigma;
      if (std::getenv("DRIFTLAB_CALIB_VERBOSE")) std::printf("%s %+.2f\n", p.name.c_str(), z);
      within += std::abs(z) <= 3.0;
      sum2 += z * z;
      ++total;
    }
  }
  const double fraction = double(within) / total;
  const double std_z = std::sqrt(sum2 / total);
  ::testing::Test::RecordProperty(preset + "_fraction_within_3sigma", std::to_string(fraction));
  ::testing::Test::RecordProperty(preset + "_std_normalised", std::to_string(std_z));
  std::printf("%s: %d trials, fraction within 3 sigma %.4f, std of normalised errors %.3f\n",
              preset.c_str(), trials, fraction, std_z);
  EXPECT_GE(fraction, min_fraction) << preset;
  EXPECT_GT(std_z, std_lo) << preset;
  EXPECT_LT(std_z, std_hi) << preset;
}

// 4 trials x 18 parameters = 72 normalised errors: if honest, each z ~ N(0, 1); P(|z| > 3) =
// 0.27 %, so >= 95 % within 3 sigma fails by chance with probability < 1e-3 (binomial); the RMS
// of 72 unit normals lies in [0.75, 1.25] with probability > 99.5 % (chi-square, 72 dof).
TEST(MultiPosition, ReportedUncertaintiesAreHonestForIndustrialFewTrials) {
  CheckHonesty("industrial", 4, 0.95, 0.75, 1.25);
}

TEST(MultiPosition, TooFewPosesIsAClearError) {
  TumbleSpec spec;
  spec.pose_count = 7;
  const Tumble tumble = SimulateTumble(spec, NoiseFreeModel(), 1, 0);
  const StaticDetection det = DetectStaticIntervals(tumble.recording, {});
  const std::string msg = ErrorOf([&] { CalibrateAccelerometers(det.intervals, {}); });
  EXPECT_NE(msg.find("too few poses: 7 static poses found"), std::string::npos) << msg;
  EXPECT_NE(msg.find("at least 9"), std::string::npos) << msg;
}

TEST(MultiPosition, PosesInOnePlaneDoNotSpanTheSphere) {
  // 12 poses with gravity turning about the body x axis only: directions in the y-z plane.
  std::vector<StaticInterval> poses(12);
  for (int k = 0; k < 12; ++k) {
    const double a = 2.0 * M_PI * k / 12.0;
    poses[k].mean_f_ib_s = 9.8 * Eigen::Vector3d(0.0, std::cos(a), std::sin(a));
  }
  const std::string msg = ErrorOf([&] { CalibrateAccelerometers(poses, {}); });
  EXPECT_NE(msg.find("poses do not span the sphere"), std::string::npos) << msg;
}

TEST(MultiPosition, AllPosesAlikeDoNotSpanTheSphere) {
  std::vector<StaticInterval> poses(12);
  for (auto& p : poses) p.mean_f_ib_s = Eigen::Vector3d(0.01, -0.02, -9.8);
  const std::string msg = ErrorOf([&] { CalibrateAccelerometers(poses, {}); });
  EXPECT_NE(msg.find("poses do not span the sphere"), std::string::npos) << msg;
}

TEST(MultiPosition, SixAxisPosesCannotDetermineMisalignment) {
  // +-x, +-y, +-z repeated: spans the sphere but |T^-1 f| is then blind to the lower-triangular
  // terms at first order (each pose excites one axis), so the Jacobian is rank deficient.
  std::vector<StaticInterval> poses;
  for (int rep = 0; rep < 2; ++rep) {
    for (int a = 0; a < 3; ++a) {
      for (double s : {1.0, -1.0}) {
        StaticInterval p;
        p.mean_f_ib_s = Eigen::Vector3d::Zero();
        p.mean_f_ib_s[a] = s * 9.80619;
        poses.push_back(p);
      }
    }
  }
  const std::string msg = ErrorOf([&] { CalibrateAccelerometers(poses, {}); });
  EXPECT_NE(msg.find("the data cannot determine accel.misalignment"), std::string::npos) << msg;
}

TEST(MultiPosition, NoMotionBetweenPosesIsAClearGyroError) {
  // Two static recordings: every "pose" after the first is the same attitude.
  TumbleSpec spec;
  const Tumble tumble = SimulateTumble(spec, NoiseFreeModel(), 1, 0);
  const StaticDetection det = DetectStaticIntervals(tumble.recording, {});
  AccelCalibrationOptions ao;
  ao.lat_rad = spec.lat_rad;
  const AccelCalibration accel = CalibrateAccelerometers(det.intervals, ao);
  std::vector<StaticInterval> same;  // split the initial static period into 12 "poses"
  const int64_t n = det.intervals[0].count() / 12;
  for (int k = 0; k < 12; ++k) {
    StaticInterval p = det.intervals[0];
    p.begin = k * n;
    p.end = k * n + n / 2;
    same.push_back(p);
  }
  const std::string msg = ErrorOf([&] { CalibrateGyros(tumble.recording, same, accel, {}); });
  EXPECT_NE(msg.find("no motion between poses: only 0 of 11"), std::string::npos) << msg;
}

TEST(MultiPosition, TumblePoseDirectionsSpanTheSphere) {
  for (int poses : {9, 12, 19, 24}) {
    TumbleSpec spec;
    spec.pose_count = poses;
    spec.pose_s = 0.1;
    spec.initial_static_s = 0.1;
    const Tumble tumble = SimulateTumble(spec, ImuErrorModel{}, 1, 0);
    Eigen::MatrixXd D(poses, 3);
    for (int k = 0; k < poses; ++k) D.row(k) = tumble.C_b_n[k].row(2);  // down in body
    const double spread =
        Eigen::JacobiSVD<Eigen::MatrixXd>(D).singularValues()[2] / std::sqrt(double(poses));
    EXPECT_GT(spread, 0.39) << poses;  // a python check of the same list gave 0.398..0.43
  }
}

}  // namespace
}  // namespace driftlab::calib
