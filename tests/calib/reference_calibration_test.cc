// Reference (rate-table) calibration, checked on seed 003's characterisation voltages
// (ADXRS300 gyros on a turntable at +-33 rpm = +-198 deg/s, and at rest) and on a synthetic
// full-matrix case.
#include "driftlab/calib/reference_calibration.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "driftlab/spec_error.h"

namespace driftlab::calib {
namespace {

// Seed 003 (../shared/seeds/003, sections 4.2.1-4.2.2; each value the mean of ten 10-minute runs,
// +-0.005 V): inputs -198, 0, +198 deg/s give x 1.51, 2.47, 3.52 V; y 1.36, 2.45, 3.39 V;
// z 1.38, 2.45, 3.37 V. Least squares on the symmetric inputs {-h, 0, h}, by hand:
//   sensitivity = (V+ - V-) / (2 h), null = (V- + V0 + V+) / 3, residual at 0 = V0 - null,
//   residuals at +-h = (V+ + V- - 2 V0) / 6 each; linearity = max|residual| / (2 h sensitivity).
//   x: 2.01 / 396 = 5.07576e-3 V/(deg/s), null 7.50 / 3 = 2.50 V, residuals +0.015, -0.030, +0.015
//      V, linearity 0.030 / 2.01 = 1.4925 %.
//   y: 2.03 / 396 = 5.12626e-3 V/(deg/s), null 7.20 / 3 = 2.40 V, residual at 0 +0.050 V,
//      linearity 0.050 / 2.03 = 2.4631 %.
//   z: 1.99 / 396 = 5.02525e-3 V/(deg/s), null 7.20 / 3 = 2.40 V, residual at 0 +0.050 V,
//      linearity 0.050 / 1.99 = 2.5126 %.
// (The ADXRS300 datasheet's nominal 5 mV/(deg/s) and 2.50 V null agree to 2.5 % and 0.1 V.)
// 1 sigma with one degree of freedom: s^2 = RSS / 1, sigma_k = s / sqrt(2 h^2),
// sigma_null = s / sqrt(3); x: RSS = 0.015^2 * 2 + 0.03^2 = 1.35e-3, s = 0.036742 V,
// sigma_k = 0.036742 / 280.014 = 1.3121e-4 V/(deg/s), sigma_null = 0.021213 V.
TEST(ReferenceCalibration, Seed003GyroVoltagesGiveTheirSensitivitiesAndNulls) {
  const std::vector<double> rate = {-198.0, 0.0, 198.0};
  struct Axis {
    const char* name;
    std::vector<double> volts;
    double sensitivity, null, linearity_percent;
  };
  const Axis axes[] = {{"x", {1.51, 2.47, 3.52}, 2.01 / 396.0, 2.50, 100.0 * 0.030 / 2.01},
                       {"y", {1.36, 2.45, 3.39}, 2.03 / 396.0, 2.40, 100.0 * 0.050 / 2.03},
                       {"z", {1.38, 2.45, 3.37}, 1.99 / 396.0, 2.40, 100.0 * 0.050 / 1.99}};
  for (const Axis& a : axes) {
    const AxisReferenceFit fit = FitReferenceAxis(rate, a.volts, a.name, "deg/s", "V");
    // Linear least squares: exact to rounding (1e-12 relative).
    EXPECT_NEAR(fit.sensitivity, a.sensitivity, 1e-12) << a.name;
    EXPECT_NEAR(fit.null, a.null, 1e-12) << a.name;
    EXPECT_NEAR(fit.linearity_error_percent, a.linearity_percent, 1e-9) << a.name;
    EXPECT_EQ(fit.fit.parameters[0].unit, "V/(deg/s)");
  }
  const AxisReferenceFit x = FitReferenceAxis(rate, axes[0].volts, "x", "deg/s", "V");
  const double s = std::sqrt(2 * 0.015 * 0.015 + 0.03 * 0.03);
  EXPECT_NEAR(x.fit.Find("x.sensitivity").sigma, s / std::sqrt(2 * 198.0 * 198.0), 1e-10);
  EXPECT_NEAR(x.fit.Find("x.null").sigma, s / std::sqrt(3.0), 1e-10);
}

// Seed 003's accelerometer (ADXL330) data are one point per axis (x 1.63 V at 0 g, y 1.62 V at
// 0 g, z 1.25 V at 1 g): a line cannot be fitted; the fit says so instead of inventing a slope.
TEST(ReferenceCalibration, Seed003AccelSinglePointCannotDetermineSensitivity) {
  try {
    FitReferenceAxis({1.0, 1.0, 1.0}, {1.25, 1.25, 1.25}, "z", "g", "V");
    FAIL() << "expected SpecError";
  } catch (const SpecError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot determine z.sensitivity: one input level"),
              std::string::npos)
        << e.what();
  }
}

TEST(ReferenceCalibration, FullMatrixRecoversCrossAxisSensitivity) {
  Eigen::Matrix3d K;
  K << 5.0e-3, 0.1e-3, -0.05e-3, 0.08e-3, 5.1e-3, 0.02e-3, -0.03e-3, 0.06e-3, 4.9e-3;  // V/(deg/s)
  const Eigen::Vector3d null(2.47, 2.45, 2.45);
  std::vector<Eigen::Vector3d> in, out;
  for (int a = 0; a < 3; ++a) {
    for (double r : {-300.0, -150.0, 0.0, 150.0, 300.0}) {
      Eigen::Vector3d x = Eigen::Vector3d::Zero();
      x[a] = r;
      in.push_back(x);
      // Deterministic +-1 mV pattern as "noise" so the residual variance is not zero.
      out.push_back(K * x + null + Eigen::Vector3d::Constant(((in.size() % 3) - 1.0) * 1e-3));
    }
  }
  const MatrixReferenceFit fit = FitReferenceMatrix(in, out, "deg/s", "V");
  // Errors of a linear fit to +-1 mV: sigma_K ~ 1e-3 / sqrt(sum x^2 = 225000) = 2e-6 V/(deg/s);
  // require 5 sigma of the fit's own uncertainty and its sigma within [1e-7, 1e-5].
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      const double sigma = fit.fit.parameters[3 * r + c].sigma;
      EXPECT_NEAR(fit.K(r, c), K(r, c), 5.0 * sigma);
      EXPECT_GT(sigma, 1e-7);
      EXPECT_LT(sigma, 1e-5);
    }
  }
  EXPECT_NEAR(fit.null[0], null[0], 5.0 * fit.fit.Find("null.x").sigma);
}

TEST(ReferenceCalibration, InputsAlongOneAxisCannotDetermineTheMatrix) {
  std::vector<Eigen::Vector3d> in, out;
  for (double r : {-300.0, -100.0, 0.0, 100.0, 300.0, 200.0}) {
    in.emplace_back(r, 0.0, 0.0);
    out.emplace_back(2.5 + 5e-3 * r, 2.45, 2.45 + 1e-5 * r);
  }
  try {
    FitReferenceMatrix(in, out, "deg/s", "V");
    FAIL() << "expected SpecError";
  } catch (const SpecError& e) {
    EXPECT_NE(std::string(e.what()).find("the data cannot determine K."), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace driftlab::calib
