// Aiding sensor models (aiding.h): barometer noise and Gauss-Markov bias, magnetometer heading
// with hard and soft iron, ZUPT epochs from the trajectory's static periods, and their
// validation.
#include "driftlab/aiding.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "driftlab/attitude.h"
#include "driftlab/complementary_filter.h"
#include "driftlab/spec_error.h"
#include "driftlab/trajectory.h"
#include "support/spec_errors.h"

namespace driftlab {
namespace {

using testing::ErrorOf;

// Over N independent runs, the barometer error (measured - truth) at one epoch has variance
// noise^2 + bias^2, and between epochs T apart covariance bias^2 exp(-T / tau) (first-order
// Gauss-Markov, started stationary).
TEST(Aiding, BarometerNoiseAndGaussMarkovBiasHaveTheirVarianceAndCorrelation) {
  BarometerConfig c;
  c.rate_hz = 10.0;
  c.noise_sigma_m = 0.5;
  c.bias = {2.0, 10.0};
  constexpr int kRuns = 4000;
  const int64_t k1 = 100, k2 = 600;  // IMU samples at 100 Hz: t = 1 s and 6 s, T = 5 s
  double s11 = 0.0, s22 = 0.0, s12 = 0.0;
  for (uint32_t run = 0; run < kRuns; ++run) {
    BarometerSimulator baro(c, 100.0, 7, run);
    double e1 = 0.0, e2 = 0.0, h = 0.0;
    for (int64_t k = 0; k <= k2; ++k) {
      if (baro.Measure(k, 100.0, &h)) {
        if (k == k1) e1 = h - 100.0;
        if (k == k2) e2 = h - 100.0;
      }
    }
    s11 += e1 * e1 / kRuns;
    s22 += e2 * e2 / kRuns;
    s12 += e1 * e2 / kRuns;
  }
  const double var = 0.25 + 4.0;
  // 4000 runs: a variance estimate has relative sd sqrt(2 / N) = 2.2 %; 4 sd = 9 %.
  EXPECT_NEAR(s11 / var, 1.0, 4.0 * std::sqrt(2.0 / kRuns));
  EXPECT_NEAR(s22 / var, 1.0, 4.0 * std::sqrt(2.0 / kRuns));
  // Correlation rho = 4 exp(-0.5) / 4.25 = 0.571; its sd (1 - rho^2) / sqrt(N) = 0.011; 4 sd.
  const double rho = 4.0 * std::exp(-0.5) / var;
  EXPECT_NEAR(s12 / std::sqrt(s11 * s22), rho, 4.0 * (1.0 - rho * rho) / std::sqrt(kRuns));
}

// Without iron and noise the levelled magnetometer heading is the true heading, for any attitude
// (roll, pitch up to 60 deg) and a field with declination.
TEST(Aiding, MagnetometerHeadingWithoutIronOrNoiseIsTheTrueHeading) {
  MagnetometerConfig c;
  c.rate_hz = 100.0;
  c.noise_sigma = 0.0;
  c.earth_field_n = Vector3d(20.0 * std::cos(5 * kDeg), 20.0 * std::sin(5 * kDeg), 45.0);
  const MagnetometerSimulator mag(c, 100.0, 1, 0);
  for (double roll : {-60.0, -10.0, 0.0, 25.0}) {
    for (double pitch : {-60.0, 0.0, 30.0}) {
      for (double yaw : {-170.0, -45.0, 0.0, 80.0, 179.0}) {
        const EulerAngles e{roll * kDeg, pitch * kDeg, yaw * kDeg};
        Vector3d m_b;
        ASSERT_TRUE(mag.Measure(0, EulerToDcm(e), &m_b));
        const double heading =
            MagneticHeading(m_b, e.roll_rad, e.pitch_rad, MagneticDeclination(c.earth_field_n));
        // Round-off only (a few operations on O(1) numbers).
        EXPECT_NEAR(WrapPi(heading - e.yaw_rad), 0.0, 1e-12) << roll << " " << pitch << " " << yaw;
      }
    }
  }
}

// Hard iron h along body x on a level vehicle at heading psi: the levelled field is
// (B cos psi + h, -B sin psi), so the compass reads atan2(B sin psi, B cos psi + h) (the
// one-cycle "semicircular" deviation, Groves section 6.1.1); a soft-iron scale s on body x gives
// atan2(B sin psi, s B cos psi) (the two-cycle "quadrantal" deviation).
TEST(Aiding, HardAndSoftIronGiveTheCompassDeviation) {
  const double B = 20.0;
  MagnetometerConfig hard;
  hard.noise_sigma = 0.0;
  hard.earth_field_n = Vector3d(B, 0.0, 45.0);
  hard.hard_iron_b = Vector3d(3.0, 0.0, 0.0);
  MagnetometerConfig soft = hard;
  soft.hard_iron_b.setZero();
  soft.soft_iron(0, 0) = 1.1;
  const MagnetometerSimulator hard_mag(hard, 100.0, 1, 0), soft_mag(soft, 100.0, 1, 0);
  for (double yaw : {-135.0, -90.0, -30.0, 0.0, 45.0, 90.0, 160.0}) {
    const double psi = yaw * kDeg;
    const Matrix3d C = EulerToDcm({0.0, 0.0, psi});
    Vector3d m_b;
    hard_mag.Measure(0, C, &m_b);
    EXPECT_NEAR(MagneticHeading(m_b, 0.0, 0.0, 0.0),
                std::atan2(B * std::sin(psi), B * std::cos(psi) + 3.0), 1e-12)
        << yaw;
    soft_mag.Measure(0, C, &m_b);
    EXPECT_NEAR(MagneticHeading(m_b, 0.0, 0.0, 0.0),
                std::atan2(B * std::sin(psi), 1.1 * B * std::cos(psi)), 1e-12)
        << yaw;
  }
}

// ZUPT epochs: static 10 s, accelerate 2 m/s^2 to 10 m/s (5 s), 10 s straight, brake at 2 m/s^2
// (5 s, stopped at 30 s), 5 s static: 1 Hz epochs at 1..10 s and 31..35 s (30 s, the instant of
// stopping, may count either way), none while moving.
TEST(Aiding, ZuptEpochsAreTheStaticSamplesOfTheTrajectory) {
  MotionSpec m;
  m.initial.llh = {45.0 * kDeg, 7.0 * kDeg, 300.0};
  m.segments.push_back(StaticSegment{10.0});
  AccelerateSegment a;
  a.acceleration_m_per_s2 = 2.0;
  a.target_speed_m_per_s = 10.0;
  m.segments.push_back(a);
  m.segments.push_back(ConstantVelocitySegment{10.0});
  AccelerateSegment b;
  b.acceleration_m_per_s2 = 2.0;
  b.target_speed_m_per_s = 0.0;
  m.segments.push_back(b);
  m.segments.push_back(StaticSegment{5.0});
  const TrajectoryGenerator generator(m, 50.0);
  ZuptConfig z;
  z.rate_hz = 1.0;
  const std::vector<int64_t> epochs = ZuptEpochs(z, 50.0, 1, generator.num_steps(),
                                                 [&](double t) { return generator.IsStaticAt(t); });
  std::vector<int64_t> expected;
  for (int t = 1; t <= 10; ++t) expected.push_back(50 * t);
  for (int t = 31; t <= 35; ++t) expected.push_back(50 * t);
  std::vector<int64_t> without_30;
  for (int64_t k : epochs) {
    if (k != 1500) without_30.push_back(k);
  }
  EXPECT_EQ(without_30, expected);
}

// The ZUPT measurement noise (the standing vehicle's residual motion) has its sigma per axis.
TEST(Aiding, ZuptMeasurementNoiseHasItsSigma) {
  ZuptConfig z;
  z.rate_hz = 10.0;
  z.velocity_sigma_m_per_s = 0.02;
  const ZuptSimulator sim(z, 100.0, 3, 9);
  constexpr int kEpochs = 5000;
  Vector3d sum_squares = Vector3d::Zero();
  for (int j = 0; j < kEpochs; ++j) sum_squares += sim.Measure(10 * j).cwiseAbs2() / kEpochs;
  // 5000 independent deviates: variance within 4 sqrt(2 / N) = 8 %.
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_NEAR(sum_squares[axis] / (0.02 * 0.02), 1.0, 4.0 * std::sqrt(2.0 / kEpochs)) << axis;
  }
}

TEST(Aiding, BadConfigurationNamesTheField) {
  EXPECT_EQ(ErrorOf([] {
              AidingDecimation(200.0, 100.0, "aiding.gnss.rate_hz");
            }).rfind("aiding.gnss.rate_hz: 200", 0),
            0u);
  EXPECT_NE(ErrorOf([] {
              AidingDecimation(3.0, 100.0, "aiding.zupt.rate_hz");
            }).find("divided by an integer"),
            std::string::npos);
  BarometerConfig b;
  b.noise_sigma_m = -1.0;
  EXPECT_EQ(ErrorOf([&] {
              ValidateBarometerConfig(b, 100.0);
            }).rfind("aiding.barometer.noise_sigma_m: -1", 0),
            0u);
  b.noise_sigma_m = 1.0;
  b.bias.sigma = 1.0;
  EXPECT_EQ(ErrorOf([&] {
              ValidateBarometerConfig(b, 100.0);
            }).rfind("aiding.barometer.bias_gauss_markov_tau_s", 0),
            0u);
  MagnetometerConfig m;
  m.earth_field_n = Vector3d(0.0, 0.0, 45.0);
  EXPECT_EQ(ErrorOf([&] {
              ValidateMagnetometerConfig(m, 100.0);
            }).rfind("aiding.magnetometer.earth_field_ned_ut", 0),
            0u);
  AidingSpec spec;
  spec.gnss = GnssConfig();
  spec.gnss->outages.push_back({50.0, 60.0});
  EXPECT_EQ(ErrorOf([&] {
              ValidateAidingSpec(spec, 100.0, 100.0);
            }).rfind("aiding.gnss.outages[0].end_s: 110", 0),
            0u);
  spec.gnss->outages = {{10.0, 20.0}, {25.0, 10.0}};
  EXPECT_EQ(ErrorOf([&] {
              ValidateAidingSpec(spec, 100.0, 100.0);
            }).rfind("aiding.gnss.outages[1].start_s: 25", 0),
            0u);
}

}  // namespace
}  // namespace driftlab
