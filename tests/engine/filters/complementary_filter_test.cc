#include "driftlab/complementary_filter.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "driftlab/sensors.h"
#include "driftlab/spec_error.h"
#include "driftlab/trajectory.h"

namespace driftlab {
namespace {

TEST(ComplementaryPair, FirstOrderPairSumsToOneAndEachIsMinus3dBAtCrossover) {
  const ComplementaryPairDesign d =
      DesignComplementaryPair(ComplementaryPairKind::kFirstOrder, 0.5, 100.0);
  for (double f = 1e-4; f < 50.0; f *= 1.37) {
    // Sum is 1 up to rounding of a few complex operations (~1e-16 each).
    EXPECT_NEAR(std::abs(d.LowPassResponse(f) + d.HighPassResponse(f) - 1.0), 0.0, 1e-12) << f;
  }
  // Prewarped bilinear transform: the analog |L(j w_c)| = |H(j w_c)| = 1/sqrt(2) holds exactly at
  // the digital crossover (rounding only).
  EXPECT_NEAR(std::abs(d.LowPassResponse(0.5)), M_SQRT1_2, 1e-12);
  EXPECT_NEAR(std::abs(d.HighPassResponse(0.5)), M_SQRT1_2, 1e-12);
}

TEST(ComplementaryPair, Butterworth4LowPassIsMaximallyFlatWithPrewarpedCutoff) {
  // Evaluating 1 + a1 z^-1 + a2 z^-2 near z = 1 cancels to ~1 / c^2 with c = 1 / tan(pi fc / rate),
  // so rounding grows as eps c^2: fc / rate = 0.02 keeps it at ~1e-14, well inside 1e-12.
  const double fc = 2.0, rate = 100.0;
  const ComplementaryPairDesign d =
      DesignComplementaryPair(ComplementaryPairKind::kButterworth4, fc, rate);
  // Bilinear image of the Butterworth magnitude: |L|^2 = 1 / (1 + (W / W_c)^8) with
  // W = tan(pi f / rate) (Oppenheim & Schafer 7.2.2), exact up to rounding.
  const double wc = std::tan(M_PI * fc / rate);
  for (double f = 1e-3; f < 49.0; f *= 1.29) {
    const double r = std::tan(M_PI * f / rate) / wc;
    EXPECT_NEAR(std::norm(d.LowPassResponse(f)), 1.0 / (1.0 + std::pow(r, 8)), 1e-12) << f;
    EXPECT_NEAR(std::abs(d.LowPassResponse(f) + d.HighPassResponse(f) - 1.0), 0.0, 1e-12) << f;
  }
  EXPECT_NEAR(20.0 * std::log10(std::abs(d.LowPassResponse(fc))), -10.0 * std::log10(2.0), 1e-9);
  // The complementary high-pass at the crossover: 1 - L(j w_c) = 1 + 1/sqrt(2) (L = -1/sqrt(2)
  // for the 4th-order Butterworth), i.e. +4.65 dB, not -3 dB (see complementary_filter.h).
  EXPECT_NEAR(std::abs(d.HighPassResponse(fc)), 1.0 + M_SQRT1_2, 1e-9);
}

TEST(ComplementaryPair, SeedButterworthPairIsPowerComplementaryAndMinus3dBEach) {
  const double fc = 2.0, rate = 100.0;  // rounding ~eps c^2, see the test above
  const ComplementaryPairDesign d =
      DesignComplementaryPair(ComplementaryPairKind::kButterworth4Seed, fc, rate);
  for (double f = 1e-3; f < 49.0; f *= 1.29) {
    // |L|^2 + |H|^2 = (1 + W^8) / (1 + W^8) = 1, rounding only.
    EXPECT_NEAR(std::norm(d.LowPassResponse(f)) + std::norm(d.HighPassResponse(f)), 1.0, 1e-12)
        << f;
  }
  EXPECT_NEAR(std::abs(d.LowPassResponse(fc)), M_SQRT1_2, 1e-12);
  EXPECT_NEAR(std::abs(d.HighPassResponse(fc)), M_SQRT1_2, 1e-12);
  // Not amplitude complementary: L + H = (1 + p^4) / B(p) = 2 / (-sqrt(2)) = -sqrt(2) at w_c.
  EXPECT_NEAR(std::abs(d.LowPassResponse(fc) + d.HighPassResponse(fc) + M_SQRT2), 0.0, 1e-9);
}

TEST(ComplementaryPair, TimeDomainGainAtCrossoverIsMinus3dB) {
  // The recursion itself (not only the formula): a sinusoid at the crossover through the
  // low-pass, amplitude measured by projection over whole periods after the transient.
  for (ComplementaryPairKind kind :
       {ComplementaryPairKind::kFirstOrder, ComplementaryPairKind::kButterworth4}) {
    const double fc = 1.0, rate = 200.0;
    ComplementaryPairDesign d = DesignComplementaryPair(kind, fc, rate);
    d.low_pass.Reset(0.0);
    double sc = 0.0, ss = 0.0;
    const int n_skip = 40 * 200, n = 20 * 200;  // 40 s transient (> 30 time constants), 20 periods
    for (int k = 0; k < n_skip + n; ++k) {
      const double phase = 2.0 * M_PI * fc * k / rate;
      const double y = d.low_pass.Step(std::sin(phase));
      if (k >= n_skip) {
        sc += y * std::cos(phase);
        ss += y * std::sin(phase);
      }
    }
    const double gain = 2.0 * std::hypot(sc, ss) / n;
    // Whole periods: the projection is exact up to the decayed transient (< 1e-10).
    EXPECT_NEAR(gain, M_SQRT1_2, 1e-9);
  }
}

// Rolling and pitching ship (no translational acceleration, so the accelerometer tilt is exact)
// at the crossover frequency, error-free IMU at 1000 Hz.
Trajectory RollingShip(double period_s) {
  MotionSpec m;
  m.earth_model = EarthModel::kFlat;
  m.initial.llh = {40.0 * kDeg, -3.0 * kDeg, 0.0};
  m.segments.push_back(StaticSegment{1.0});
  ShipMotionSegment s;
  s.duration_s = 40.0;
  s.roll_amplitude_rad = 4.0 * kDeg;
  s.roll_period_s = period_s;
  s.pitch_amplitude_rad = 2.0 * kDeg;
  s.pitch_period_s = period_s;
  s.pitch_phase_rad = M_PI / 2;
  s.ramp_s = 2.0;
  m.segments.push_back(s);
  return GenerateTrajectory(m, 1000.0);
}

double MaxRollError(const Trajectory& t, ComplementaryPairKind kind, double fc) {
  ComplementaryFilterOptions o;
  o.kind = kind;
  o.crossover_hz = fc;
  ComplementaryAttitudeFilter filter(o, 1.0 / t.dt_s);
  double max_err = 0.0;
  for (size_t k = 0; k < t.samples.size(); ++k) {
    filter.Update(t.samples[k]);
    if (t.truth[k].t_s > 20.0) {
      max_err = std::max(
          max_err, std::abs(WrapPi(filter.attitude().roll_rad - t.truth[k].euler().roll_rad)));
    }
  }
  return max_err;
}

TEST(ComplementaryAttitudeFilter, ComplementaryPairPassesTrueAttitudeUndistorted) {
  const Trajectory t = RollingShip(2.0);
  // L + (1 - L) = 1: with exact tilt and exact rates the only error is the trapezoidal gyro
  // integration, O((w dt)^2 A) per step with w dt = 3e-3, plus Euler-rate coupling (pitch 2 deg):
  // bound 1e-4 rad (0.04 % of the 4 deg amplitude), amplified at most |1 - L| <= 1.71.
  EXPECT_LT(MaxRollError(t, ComplementaryPairKind::kFirstOrder, 0.5), 1e-4);
  EXPECT_LT(MaxRollError(t, ComplementaryPairKind::kButterworth4, 0.5), 1e-4);
}

TEST(ComplementaryAttitudeFilter, SeedButterworthPairDistortsAttitudeAtCrossover) {
  const Trajectory t = RollingShip(2.0);
  // L + H = -sqrt(2) at w_c: the roll error is |L + H - 1| = 1 + sqrt(2) times the 4 deg
  // amplitude; the envelope ramp and the integration error change it by < 2 %.
  const double err = MaxRollError(t, ComplementaryPairKind::kButterworth4Seed, 0.5);
  EXPECT_NEAR(err / (4.0 * kDeg), 1.0 + M_SQRT2, 0.02 * (1.0 + M_SQRT2));
}

// Ship weaving in a seaway: 5 m/s, track weave of period 5 s (lateral acceleration ~0.47 m/s^2,
// which tilts the accelerometer's vertical by ~2.7 deg), then roll/pitch/yaw motion.
Trajectory WeavingShip() {
  MotionSpec m;
  m.earth_model = EarthModel::kFlat;
  m.initial.llh = {40.0 * kDeg, -3.0 * kDeg, 0.0};
  m.segments.push_back(StaticSegment{5.0});
  AccelerateSegment a;
  a.acceleration_m_per_s2 = 1.0;
  a.target_speed_m_per_s = 5.0;
  m.segments.push_back(a);
  m.segments.push_back(ZigzagSegment{.amplitude_m = 0.3, .period_s = 5.0, .duration_s = 300.0});
  ShipMotionSegment s;
  s.duration_s = 60.0;
  s.roll_amplitude_rad = 4.0 * kDeg;
  s.roll_period_s = 8.0;
  s.pitch_amplitude_rad = 2.0 * kDeg;
  s.pitch_period_s = 6.0;
  s.yaw_amplitude_rad = 1.0 * kDeg;
  s.yaw_period_s = 10.0;
  s.ramp_s = 5.0;
  m.segments.push_back(s);
  return GenerateTrajectory(m, 100.0);
}

struct TiltErrors {
  double filter_rms = 0.0;  // RMS of sqrt(droll^2 + dpitch^2) over t > t0
  double accel_rms = 0.0;   // same for the accelerometer-only tilt
};

TiltErrors RunWeave(const Trajectory& t, const std::vector<ImuSample>& measured,
                    ComplementaryPairKind kind, double fc, double t0) {
  ComplementaryFilterOptions o;
  o.kind = kind;
  o.crossover_hz = fc;
  ComplementaryAttitudeFilter filter(o, 1.0 / t.dt_s);
  double s_f = 0.0, s_a = 0.0;
  int n = 0;
  for (size_t k = 0; k < measured.size(); ++k) {
    filter.Update(measured[k]);
    if (t.truth[k].t_s < t0) continue;
    const EulerAngles truth = t.truth[k].euler();
    const EulerAngles& e = filter.attitude();
    const EulerAngles& a = filter.accelerometer_attitude();
    s_f += std::pow(e.roll_rad - truth.roll_rad, 2) + std::pow(e.pitch_rad - truth.pitch_rad, 2);
    s_a += std::pow(a.roll_rad - truth.roll_rad, 2) + std::pow(a.pitch_rad - truth.pitch_rad, 2);
    ++n;
  }
  return {std::sqrt(s_f / n), std::sqrt(s_a / n)};
}

TEST(ComplementaryAttitudeFilter, CrossoverTradesGyroDriftAgainstAccelerationLeak) {
  const Trajectory t = WeavingShip();
  // A MEMS gyro (seed 003's ADXRS300 class): fixed bias 0.05 deg/s on x and y, plus ARW.
  ImuErrorModel model;
  model.gyro.fixed_bias = Vector3d(0.05 * kDeg, -0.05 * kDeg, 0.0);
  model.gyro.white_noise_density = 0.1 * kDeg / 60.0;  // 0.1 deg/sqrt(h)
  model.accel.white_noise_density = 1e-3;              // ~100 ug/sqrt(Hz)
  ImuErrorSimulator sim(model, 7, 0, 100.0);
  std::vector<ImuSample> measured(t.samples.size());
  for (size_t k = 0; k < t.samples.size(); ++k) sim.Apply(t.samples[k], &measured[k]);

  const double t0 = 120.0;  // after the slowest transient: 1 / w_c = 80 s at 0.002 Hz
  const double b = std::hypot(0.05, 0.05) * kDeg;
  for (ComplementaryPairKind kind :
       {ComplementaryPairKind::kFirstOrder, ComplementaryPairKind::kButterworth4}) {
    std::vector<double> fcs = {0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 5.0};
    std::vector<double> rms;
    for (double fc : fcs) rms.push_back(RunWeave(t, measured, kind, fc, t0).filter_rms);
    const TiltErrors high = RunWeave(t, measured, kind, 5.0, t0);
    // Low crossover: gyro drift dominates. A rate bias b through H = 1 - L gives a steady tilt
    // error b H(s)/s^2 at s -> 0 = b / w_c (first order) or 2.613 b / w_c (Butterworth: H ~
    // 2.613 s / w_c); the weave's leak is attenuated to |L| < 1.5 % there. The transient left
    // (exp(-1.5) of the first order at t0) and the Euler-rate coupling: 25 % tolerance.
    const double gain = kind == ComplementaryPairKind::kFirstOrder
                            ? 1.0
                            : 2.0 * std::sin(M_PI / 8) + 2.0 * std::sin(3 * M_PI / 8);
    const double predicted_low = gain * b / (2.0 * M_PI * 0.002);
    EXPECT_NEAR(rms.front() / predicted_low, 1.0, 0.25);
    // High crossover: the accelerometer's tilt error (the vessel's accelerations) passes almost
    // unattenuated (|L| > 0.99 below 0.5 Hz at 5 Hz): within 10 % of the accelerometer-only RMS.
    EXPECT_NEAR(high.filter_rms / high.accel_rms, 1.0, 0.10);
    // In between, both are suppressed: the best crossover beats both ends by a factor > 3.
    const double best = *std::min_element(rms.begin(), rms.end());
    EXPECT_LT(best * 3.0, rms.front());
    EXPECT_LT(best * 3.0, rms.back());
    for (size_t i = 0; i < fcs.size(); ++i) {
      std::printf("kind %d crossover %.3f Hz: tilt RMS %.4f deg\n", static_cast<int>(kind), fcs[i],
                  rms[i] / kDeg);
    }
    std::printf("accelerometer-only tilt RMS %.4f deg; predicted low-end %.4f deg\n",
                high.accel_rms / kDeg, predicted_low / kDeg);
  }
}

TEST(ComplementaryAttitudeFilter, MagnetometerHeadingOfATiltedStaticBody) {
  // Field: 45 deg dip, north-pointing horizontal part; body yaw 30 deg, roll 10, pitch -5.
  const EulerAngles truth{10.0 * kDeg, -5.0 * kDeg, 30.0 * kDeg};
  const Matrix3d C_b_n = EulerToDcm(truth);
  const Vector3d m_n(std::cos(45 * kDeg), 0.0, std::sin(45 * kDeg));
  const Vector3d m_b = C_b_n.transpose() * m_n;
  ImuSample s;
  s.f_ib_b = C_b_n.transpose() * Vector3d(0, 0, -9.8);
  ComplementaryFilterOptions o;
  o.kind = ComplementaryPairKind::kButterworth4;
  ComplementaryAttitudeFilter filter(o, 100.0);
  for (int k = 0; k < 100; ++k) filter.Update(s, &m_b);
  // Exact levelling and exact field: only rounding (1e-12 rad).
  EXPECT_NEAR(filter.attitude().roll_rad, truth.roll_rad, 1e-12);
  EXPECT_NEAR(filter.attitude().pitch_rad, truth.pitch_rad, 1e-12);
  EXPECT_NEAR(filter.attitude().yaw_rad, truth.yaw_rad, 1e-12);
}

TEST(ComplementaryAttitudeFilter, CrossoverAboveNyquistNamesTheField) {
  ComplementaryFilterOptions o;
  o.crossover_hz = 60.0;
  try {
    ComplementaryAttitudeFilter filter(o, 100.0);
    FAIL() << "no SpecError";
  } catch (const SpecError& e) {
    EXPECT_EQ(e.field(), "complementary_filter.crossover_hz");
    EXPECT_NE(std::string(e.what()).find("60"), std::string::npos);
  }
  o.crossover_hz = 0.1;
  o.heading_crossover_hz = -1.0;
  EXPECT_THROW(
      {
        try {
          ComplementaryAttitudeFilter filter(o, 100.0);
        } catch (const SpecError& e) {
          EXPECT_EQ(e.field(), "complementary_filter.heading_crossover_hz");
          throw;
        }
      },
      SpecError);
}

}  // namespace
}  // namespace driftlab
