// Attitude mathematics: round trips between representations and the Euler-rate kinematics.
#include "driftlab/attitude.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace driftlab {
namespace {

std::vector<EulerAngles> SampleAttitudes() {
  std::vector<EulerAngles> out;
  for (double roll : {-3.0, -1.2, 0.0, 0.4, 2.9}) {
    for (double pitch : {-1.5, -0.7, 0.0, 0.3, 1.5}) {
      for (double yaw : {-3.1, -2.0, 0.0, 1.0, 3.1}) out.push_back({roll, pitch, yaw});
    }
  }
  return out;
}

TEST(AttitudeTest, EulerDcmRoundTripIsExact) {
  // Rounding only: a few eps on O(1) quantities; asin near pitch +-1.5 amplifies by
  // 1/cos(1.5) = 14, so 1e-13 rad.
  for (const EulerAngles& e : SampleAttitudes()) {
    const Matrix3d C = EulerToDcm(e);
    EXPECT_LT((C * C.transpose() - Matrix3d::Identity()).norm(), 1e-14);
    EXPECT_NEAR(C.determinant(), 1.0, 1e-14);
    const EulerAngles back = DcmToEuler(C);
    EXPECT_NEAR(WrapPi(back.roll_rad - e.roll_rad), 0.0, 1e-13);
    EXPECT_NEAR(back.pitch_rad, e.pitch_rad, 1e-13);
    EXPECT_NEAR(WrapPi(back.yaw_rad - e.yaw_rad), 0.0, 1e-13);
  }
}

TEST(AttitudeTest, EulerDcmIsYawPitchRollProduct) {
  // C_b_n = Rz(yaw) Ry(pitch) Rx(roll) (Groves 2.22 transposed); exact up to rounding.
  const EulerAngles e{0.3, -0.4, 2.0};
  const Matrix3d expected = (Eigen::AngleAxisd(e.yaw_rad, Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(e.pitch_rad, Vector3d::UnitY()) *
                             Eigen::AngleAxisd(e.roll_rad, Vector3d::UnitX()))
                                .toRotationMatrix();
  EXPECT_LT((EulerToDcm(e) - expected).norm(), 1e-15 * 10);
}

TEST(AttitudeTest, RotationVectorQuaternionDcmAgree) {
  // Angles from 1e-9 rad (Taylor branch) to near pi; rounding only (1e-15 relative), except that
  // the rotation vector recovered from a quaternion near pi loses digits as 1/sin(angle/2)... ~1.
  for (double angle : {1e-9, 1e-5, 9.9e-5, 1e-4, 1e-3, 0.1, 1.0, 3.0}) {
    const Vector3d axis = Vector3d(0.3, -0.5, 0.81).normalized();
    const Vector3d rho = angle * axis;
    const Matrix3d C = RotationVectorToDcm(rho);
    const Quaterniond q = RotationVectorToQuaternion(rho);
    const Matrix3d expected = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
    EXPECT_LT((C - expected).norm(), 2e-15) << angle;
    EXPECT_LT((q.toRotationMatrix() - expected).norm(), 2e-15) << angle;
    EXPECT_NEAR(q.norm(), 1.0, 1e-15);
    EXPECT_LT((QuaternionToRotationVector(q) - rho).norm(), 1e-15 * std::max(1.0, angle) * 4)
        << angle;
  }
}

TEST(AttitudeTest, EulerRatesToBodyRateMatchesNumericalDifferentiationOfDcm) {
  // omega_nb_b = vee(C_b_n^T dC_b_n/dt) (Groves (2.56)). Central differences with step 1e-5 s:
  // truncation |C'''| h^2 / 6 ~ 1e-10 for rates ~1 rad/s, rounding eps / h ~ 2e-11; tolerance 1e-9.
  const double h = 1e-5;
  const Vector3d rates(0.7, -0.3, 1.1);  // roll, pitch, yaw rates [rad/s]
  for (const EulerAngles& e0 : SampleAttitudes()) {
    if (std::abs(e0.pitch_rad) > 1.4) continue;  // keep away from gimbal lock
    auto at = [&](double t) {
      return EulerToDcm(
          {e0.roll_rad + rates.x() * t, e0.pitch_rad + rates.y() * t, e0.yaw_rad + rates.z() * t});
    };
    const Matrix3d dC = (at(h) - at(-h)) / (2.0 * h);
    const Matrix3d W = at(0.0).transpose() * dC;  // [omega_nb_b x]
    const Vector3d omega_numeric(W(2, 1), W(0, 2), W(1, 0));
    EXPECT_LT((EulerRatesToBodyRate(e0, rates) - omega_numeric).norm(), 1e-9);
  }
}

TEST(AttitudeTest, AttitudeErrorIsTheSmallRotationFromTruthToEstimate) {
  // exp([psi x]) C_true = C_est by definition; a known psi is recovered to rounding.
  const Matrix3d C_true = EulerToDcm({0.2, -0.1, 2.5});
  const Vector3d psi(1e-6, -2e-7, 3e-5);
  const Matrix3d C_est = RotationVectorToDcm(psi) * C_true;
  EXPECT_LT((AttitudeErrorNed(C_est, C_true) - psi).norm(), 1e-15);
  EXPECT_NEAR(WrapPi(3.0 * M_PI), M_PI, 1e-15);
  EXPECT_NEAR(WrapPi(-M_PI), M_PI, 1e-15);
}

TEST(AttitudeTest, WrapPiReturnsAnglesInItsRangeUnchangedAndWrapsTheRestByRemainder) {
  // (-pi, pi] is returned as it is (bit for bit: the remainder by 2 pi of such an angle is the
  // angle itself); outside, the IEEE remainder by 2 pi, moved from -pi to pi. Tolerance: none,
  // both are exact operations.
  EXPECT_EQ(WrapPi(M_PI), M_PI);
  EXPECT_EQ(WrapPi(-M_PI), M_PI);
  EXPECT_EQ(WrapPi(std::nextafter(-M_PI, 0.0)), std::nextafter(-M_PI, 0.0));
  EXPECT_EQ(WrapPi(-0.0), -0.0);
  EXPECT_TRUE(std::signbit(WrapPi(-0.0)));
  for (int i = -200000; i <= 200000; ++i) {
    const double x = 1e-4 * i + 1e-9 * (i % 13);  // -20 .. 20 rad
    double expected = std::remainder(x, 2.0 * M_PI);
    if (expected <= -M_PI) expected += 2.0 * M_PI;
    ASSERT_EQ(WrapPi(x), expected) << x;
    ASSERT_TRUE(WrapPi(x) > -M_PI && WrapPi(x) <= M_PI) << x;
  }
  EXPECT_TRUE(std::isnan(WrapPi(std::numeric_limits<double>::quiet_NaN())));
}

}  // namespace
}  // namespace driftlab
