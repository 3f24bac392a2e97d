// Physics of the strapdown mechanizations with hand-computed ideal IMU data: stationary closure,
// vertical-channel instability, Schuler oscillation, and seed 000's lateral move through
// mechanization B.
#include "driftlab/ins.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "driftlab/earth.h"
#include "driftlab/nav_state.h"
#include "driftlab/simulate.h"
#include "driftlab/trajectory.h"

namespace driftlab {
namespace {

// Exact increments of a body at rest on the rotating Earth: omega_ib_b = C_n_b omega_ie_n and
// f_ib_b = -C_n_b g_b_n are constant in the body frame, so the interval integrals are the rates
// times dt (Groves (5.40), (5.54) with v = 0).
ImuIncrement StationaryIncrement(const NavEnvironment& env, const NavState& truth, double dt_s) {
  const Matrix3d C_n_b = truth.C_b_n().transpose();
  ImuIncrement inc;
  inc.delta_theta_ib_b = C_n_b * env.EarthRate(truth.llh.lat_rad) * dt_s;
  inc.delta_v_ib_b = -C_n_b * env.Gravity(truth.llh.lat_rad, truth.llh.h_m) * dt_s;
  return inc;
}

NavState StationaryTruth(double lat_rad, double h_m, const EulerAngles& attitude) {
  NavState s;
  s.llh = {lat_rad, 0.3, h_m};
  s.q_b_n = Quaterniond(EulerToDcm(attitude));
  return s;
}

TEST(NedMechanizationTest, StationaryExactIncrementsStayAtRestForAnHour) {
  // With exact increments for a body at rest, every integral in the step is exact to second order
  // in the rotations (third-order terms ~ zeta^3 = 4e-16 rad), so only rounding remains. The input
  // is the same every step, so rounding is systematic: <= ~4 ulp = 4.4e-16 rad per step, i.e.
  // 1.6e-11 rad over 36,000 steps; a tilt of that size gives at most g psi T = 6e-7 m/s and
  // g psi T^2 / 2 = 1e-3 m (free vertical: rounding grows by cosh(3600 / 570) < 300, negligible).
  const NavEnvironment env = NavEnvironment::Wgs84();
  const double dt = 0.1;
  const NavState truth = StationaryTruth(51.0 * kDeg, 80.0, {0.02, -0.01, 1.3});
  NedMechanization ins(env, truth, dt, {});
  const ImuIncrement inc = StationaryIncrement(env, truth, dt);
  for (int k = 0; k < 36000; ++k) ins.Update(inc);
  NavState truth_end = truth;
  truth_end.t_s = 3600.0;
  const NavError e = ComputeNavError(env, ins.state(), truth_end);
  EXPECT_LT(e.r_ned_m.norm(), 1e-3);
  EXPECT_LT(e.v_ned_m_per_s.norm(), 6e-7);
  EXPECT_LT(e.psi_nb_n_rad.norm(), 1.6e-11);
  RecordProperty("position_error_m", std::to_string(e.r_ned_m.norm()));
  EXPECT_NEAR(ins.state().t_s, 3600.0, 1e-9);
}

TEST(NedMechanizationTest, EastwardCruiseAlongTheEquatorClosesExactly) {
  // Level flight due east along the equator at V = 200 m/s, h = 10 km: the NED frame turns about
  // north at Omega + V / (a + h) (Earth rate plus transport rate, Groves (5.41), (5.44)); the body,
  // aligned with NED, turns with it, so omega_ib_b and
  //   f_ib_b = C_n_b ((omega_en_n + 2 omega_ie_n) x v_eb_n - g_b_n)        Groves (5.54)
  // are constant and the increments are rates x dt exactly. Truth: L = 0, h constant,
  // lambda = lambda_0 + V t / (a + h). Exercises Earth rate, transport rate, Coriolis and the
  // centripetal terms with exactly known answers. Errors: rounding only (as in the stationary test:
  // <= 4 ulp per step, 36,000 steps -> 1.6e-11 rad, g psi T = 6e-7 m/s, g psi T^2 / 2 = 1e-3 m).
  const NavEnvironment env = NavEnvironment::Wgs84();
  const double dt = 0.1, V = 200.0, h = 10000.0, T = 3600.0;
  NavState truth;
  truth.llh = {0.0, 0.4, h};
  truth.v_eb_n = Vector3d(0.0, V, 0.0);
  truth.q_b_n = Quaterniond(EulerToDcm({0.0, 0.0, M_PI / 2}));
  const Vector3d omega_ie_n = env.EarthRate(0.0);
  const Vector3d omega_en_n = env.TransportRate(0.0, h, truth.v_eb_n);
  EXPECT_NEAR(omega_en_n.x(), V / (kWgs84SemiMajorAxis_m + h), 1e-18);
  const Matrix3d C_n_b = truth.C_b_n().transpose();
  ImuIncrement inc;
  inc.delta_theta_ib_b = C_n_b * (omega_ie_n + omega_en_n) * dt;
  inc.delta_v_ib_b =
      C_n_b * ((omega_en_n + 2.0 * omega_ie_n).cross(truth.v_eb_n) - env.Gravity(0.0, h)) * dt;
  NedMechanization ins(env, truth, dt, {});
  const int steps = static_cast<int>(std::lround(T / dt));
  for (int k = 0; k < steps; ++k) ins.Update(inc);
  NavState truth_end = truth;
  truth_end.t_s = T;
  truth_end.llh.lon_rad += V * T / (kWgs84SemiMajorAxis_m + h);
  const NavError e = ComputeNavError(env, ins.state(), truth_end);
  EXPECT_LT(e.r_ned_m.norm(), 1e-3);
  EXPECT_LT(e.v_ned_m_per_s.norm(), 6e-7);
  EXPECT_LT(e.psi_nb_n_rad.norm(), 1.6e-11);
  std::printf("equator cruise: r %.3e m, v %.3e m/s, psi %.3e rad\n", e.r_ned_m.norm(),
              e.v_ned_m_per_s.norm(), e.psi_nb_n_rad.norm());
}

TEST(NedMechanizationTest, VerticalChannelDivergesWithTimeConstantSqrtROver2g) {
  // A height error dh changes modelled gravity by (dg_D/dh) dh, with (Groves (2.139))
  //   dg_D/dh = -k,  k = 2 gamma_0 / a (1 + f (1 - 2 sin^2 L) + m)      (~2 g / R)
  // and Coriolis couples vertical and east velocity errors: dv_E' = 2 Omega cos L dv_D. So
  //   dh'' = (k - 4 Omega^2 cos^2 L) dh  ->  dh(t) = dh_0 cosh(t / tc),
  //   tc = 1 / sqrt(k - 4 Omega^2 cos^2 L)   (~570 s; the Coriolis term shifts it by 0.2 %).
  // Tolerance 2 % on tc (brief); the neglected terms (h^2 term, transport rate) are < 1e-6.
  const NavEnvironment env = NavEnvironment::Wgs84();
  const double L = 45.0 * kDeg, dt = 0.1, T = 1800.0;
  const NavState truth = StationaryTruth(L, 0.0, {});
  NavState start = truth;
  const double dh0 = 1e-3;
  start.llh.h_m += dh0;
  NedMechanization ins(env, start, dt, {});
  const ImuIncrement inc = StationaryIncrement(env, truth, dt);
  std::vector<double> dh;
  const int steps = static_cast<int>(std::lround(T / dt));
  for (int k = 0; k < steps; ++k) {
    ins.Update(inc);
    dh.push_back(ins.state().llh.h_m - truth.llh.h_m);
  }
  const double s2 = std::sin(L) * std::sin(L);
  const double m = kWgs84EarthRate_rad_per_s * kWgs84EarthRate_rad_per_s * kWgs84SemiMajorAxis_m *
                   kWgs84SemiMajorAxis_m * kWgs84SemiMinorAxis_m / kWgs84GM_m3_per_s2;
  const double k_grad = 2.0 * SomiglianaGravity(L) / kWgs84SemiMajorAxis_m *
                        (1.0 + kWgs84Flattening * (1.0 - 2.0 * s2) + m);
  const double c = kWgs84EarthRate_rad_per_s * std::cos(L);
  const double tc_expected = 1.0 / std::sqrt(k_grad - 4.0 * c * c);
  // Fit tc from the growth: dh(T) / dh_0 = cosh(T / tc).
  const double tc_measured = T / std::acosh(dh.back() / dh0);
  EXPECT_NEAR(tc_measured, tc_expected, 0.02 * tc_expected);
  EXPECT_NEAR(tc_expected, 570.0, 10.0);  // the textbook sqrt(R / 2g) value
  // Shape: at T/2 the error is dh_0 cosh(T / 2tc) within the same 2 % on tc (-> ~3 % on dh).
  const double dh_mid_expected = dh0 * std::cosh(0.5 * T / tc_expected);
  EXPECT_NEAR(dh[steps / 2 - 1], dh_mid_expected, 0.05 * dh_mid_expected);
  RecordProperty("tc_measured_s", std::to_string(tc_measured));
  RecordProperty("tc_expected_s", std::to_string(tc_expected));
}

TEST(NedMechanizationTest, SchulerPeriodAndAmplitudeMatchTheory) {
  // Stationary at the equator with a 0.1 m/s north velocity error (vertical held at truth). The
  // error tilts the frame through the transport rate (dpsi_E' = dv_N / R_N), the tilt feeds back
  // -g dpsi_E into dv_N, and at the equator the Earth rate (along north) couples east and down
  // tilts; together
  //   omega^2 = g / R_N + Omega^2,  g = g_D(0, 0) = 9.7803 m/s^2, R_N(0) = a (1 - e^2) = 6335439 m
  // -> period 2 pi / omega = 84.2 min, amplitude of the north position error dv / omega.
  // Tolerances (brief): period +-1 %, amplitude +-2 %.
  const NavEnvironment env = NavEnvironment::Wgs84();
  const double dt = 0.1, dv = 0.1;
  const NavState truth = StationaryTruth(0.0, 0.0, {0.0, 0.0, 0.5});
  NavState start = truth;
  start.v_eb_n.x() += dv;
  NedMechanization ins(env, start, dt, {VerticalChannel::kTruthHeight, true});
  const ImuIncrement inc = StationaryIncrement(env, truth, dt);

  const double g = env.Gravity(0.0, 0.0).z();
  const double omega =
      std::sqrt(g / MeridianRadius(0.0) + kWgs84EarthRate_rad_per_s * kWgs84EarthRate_rad_per_s);
  const double period_expected = 2.0 * M_PI / omega;
  const int steps = static_cast<int>(3.2 * period_expected / dt);
  std::vector<double> crossings;
  double prev = 0.0, max_abs = 0.0;
  for (int k = 1; k <= steps; ++k) {
    ins.Update(inc);
    ins.SetVertical(truth.llh.h_m, 0.0);
    const double dn = env.PositionErrorNed(ins.state().llh, truth.llh).x();
    if (k > 1 && prev > 0.0 && dn <= 0.0) crossings.push_back((k - 1 + prev / (prev - dn)) * dt);
    if (k > 1 && prev < 0.0 && dn >= 0.0) crossings.push_back((k - 1 + prev / (prev - dn)) * dt);
    max_abs = std::max(max_abs, std::abs(dn));
    prev = dn;
  }
  ASSERT_GE(crossings.size(), 5u);
  const double period_measured =
      2.0 * (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
  EXPECT_NEAR(period_measured, period_expected, 0.01 * period_expected);
  EXPECT_NEAR(period_measured / 60.0, 84.4, 0.01 * 84.4);  // textbook 84.4 min (R = 6371 km)
  const double amplitude_expected = dv / omega;
  EXPECT_NEAR(max_abs, amplitude_expected, 0.02 * amplitude_expected);
  RecordProperty("schuler_period_min", std::to_string(period_measured / 60.0));
  RecordProperty("schuler_amplitude_m", std::to_string(max_abs));
}

TEST(NedMechanizationTest, InvalidSampleIntervalIsRejected) {
  EXPECT_THROW(NedMechanization(NavEnvironment::Wgs84(), NavState(), 0.0, {}), std::exception);
  EXPECT_THROW(Seed000Mechanization(0.01, {0.0, 0.0}), std::exception);
  EXPECT_THROW(Seed000Mechanization(0.01, {90.0, 60.0}), std::exception);  // above Nyquist 50 Hz
}

// ---- Mechanization B ---------------------------------------------------------------------------

// Seed 000's sample run, hand-made: flat frame, level vessel at rest for 90 s, then a sideways
// (body y) move of 1.4 m: +0.05 m/s^2 for 4 s, coast 3 s at 0.2 m/s, -0.05 m/s^2 for 4 s, rest.
struct LateralMove {
  static constexpr double kG = 9.80;
  double AccelY(double t) const {
    if (t >= 90.0 && t < 94.0) return 0.05;
    if (t >= 97.0 && t < 101.0) return -0.05;
    return 0.0;
  }
  ImuSample Sample(double t) const {
    ImuSample s;
    s.f_ib_b = Vector3d(0.0, AccelY(t), -kG);  // f = a - g, level body = nav frame
    return s;
  }
};

TEST(Seed000MechanizationTest, RecoversSeed000LateralMoveOfOnePointFourMetres) {
  // Flat frame, no rotation: attitude is exact and a_nav = f - g_mean is exact at every sample
  // (the static mean covers t < 90 s), so the only error is the trapezoidal rule across the
  // acceleration steps. A step da at a sample instant t_j (the sample takes the new value) makes
  // the trapezoid over the interval ending at t_j err by -da dt / 2 in velocity, carried into
  // position until T. The step at 90 s is the start of navigation (no interval before it), so
  //   dv(T) = -0.025 dt (step at 94 s) - 0.025 dt (97 s) + 0.025 dt (101 s) = -2.5e-4 m/s
  //   dr(T) = sum_j dv_j (T - t_j + dt/2)   (the trapezoid on v weights v(t_j) by dt/2; v is
  //           piecewise linear with kinks at samples, so the position rule adds no error itself)
  //         = 0.025 dt (-(T - 94) - (T - 97) + (T - 101)) - 0.025 dt^2 / 2 = -0.00525125 m.
  // Both are met to rounding (1e-9). Independently of where the samples fall, the rigorous bound
  // sum_j |da_j| dt / 2 (T - t_j) = 0.05 * 0.005 * (17 + 14 + 10) = 0.0103 m must hold.
  const double dt = 0.01, T = 111.0;
  LateralMove move;
  Seed000Mechanization ins(dt, {90.0, 0.0});
  const int steps = static_cast<int>(std::lround(T / dt));
  for (int k = 0; k <= steps; ++k) ins.Update(move.Sample(k * dt));
  ASSERT_TRUE(ins.aligned());
  EXPECT_NEAR(ins.r_nav_m().y(), 1.4, 0.0103);
  EXPECT_NEAR(ins.r_nav_m().y(), 1.4 - 0.00525125, 1e-9);
  EXPECT_NEAR(ins.v_nav_m_per_s().y(), -2.5e-4, 1e-12);
  EXPECT_NEAR(ins.r_nav_m().x(), 0.0, 1e-12);  // no surge without sensor errors
  EXPECT_NEAR(ins.r_nav_m().z(), 0.0, 1e-12);
  EXPECT_NEAR(ins.gravity_nav().z(), -LateralMove::kG, 4e-15);  // compensated mean: ~1 ulp
  EXPECT_LT(ins.gyro_bias_rad_per_s().norm(), 1e-15);
  EXPECT_NEAR(ins.t_s(), T, 1e-9);
  RecordProperty("lateral_move_m", std::to_string(ins.r_nav_m().y()));
}

TEST(Seed000MechanizationTest, LowPassDelaysButKeepsTheLateralMove) {
  // A first-order low-pass has unit DC gain, so it delays the acceleration pulse by ~RC but keeps
  // its integrals: after the filter has settled (RC = 1/(2 pi 2 Hz) = 0.08 s, 10 s of rest is
  // 125 RC) the displacement is the same 1.4 m, within the trapezoid bound of the previous test.
  const double dt = 0.01, T = 111.0;
  LateralMove move;
  Seed000Mechanization ins(dt, {90.0, 2.0});
  const int steps = static_cast<int>(std::lround(T / dt));
  double y_at_95 = 0.0;
  for (int k = 0; k <= steps; ++k) {
    ins.Update(move.Sample(k * dt));
    if (k == 9500) y_at_95 = ins.r_nav_m().y();
  }
  EXPECT_NEAR(ins.r_nav_m().y(), 1.4, 0.0103);
  // During the move the filtered solution lags: at t = 95 s the unfiltered position is
  // 0.4 + 0.2 * 1 = 0.6 m; a lag of RC = 0.08 s at 0.2 m/s gives ~0.016 m less.
  EXPECT_LT(y_at_95, 0.6 - 0.01);
  EXPECT_GT(y_at_95, 0.6 - 0.03);
}

TEST(Seed000MechanizationTest, StaticPeriodAbsorbsEarthRateAndGravity) {
  // At rest on the rotating Earth the gyros read the Earth rate; seed 000 treats it as bias, so the
  // solution stays exactly at rest (a_nav = f - mean f = 0, omega_c = 0): rounding only.
  const NavEnvironment env = NavEnvironment::Wgs84();
  const NavState truth = StationaryTruth(40.5 * kDeg, 600.0, {0.03, -0.02, 0.7});
  const Matrix3d C_n_b = truth.C_b_n().transpose();
  ImuSample s;
  s.omega_ib_b = C_n_b * env.EarthRate(truth.llh.lat_rad);
  s.f_ib_b = -C_n_b * env.Gravity(truth.llh.lat_rad, truth.llh.h_m);
  const double dt = 0.01;
  Seed000Mechanization ins(dt, {90.0, 0.0});
  for (int k = 0; k <= 20000; ++k) ins.Update(s);
  // Compensated means: ~1 ulp of |omega| = 7e-5 rad/s and of |g| = 9.8 m/s^2; a residual of
  // 4e-15 m/s^2 integrates over the 110 s after alignment to g t^2 / 2 = 2.4e-11 m.
  EXPECT_LT((ins.gyro_bias_rad_per_s() - s.omega_ib_b).norm(), 4e-20);
  EXPECT_LT((ins.gravity_nav() - s.f_ib_b).norm(), 4e-15);
  EXPECT_LT(ins.r_nav_m().norm(), 3e-11);
  const NavState ned = ins.ToNed(env, truth);
  const NavError e = ComputeNavError(env, ned, truth);
  EXPECT_LT(e.r_ned_m.norm(), 3e-11);
  EXPECT_LT(e.psi_nb_n_rad.norm(), 1e-14);
}

// Seed 000's vessel in waves, analytic: flat frame, at rest until t0 = 90 s, then roll, pitch,
// yaw and heave sinusoids faded in with a raised-cosine envelope over 20 s (all kinks of the
// motion fall on sample instants). Point samples omega_ib_b = omega_nb_b (flat frame: no Earth
// rate), f_ib_b = C_n_b (a_n - g_n).
struct AnalyticSeaway {
  static constexpr double kG = 9.80, kT0 = 90.0, kRamp = 20.0;
  double roll_amp = 8.0 * kDeg, roll_w = 2 * M_PI / 8.0;
  double pitch_amp = 3.0 * kDeg, pitch_w = 2 * M_PI / 6.0;
  double yaw_amp = 1.0 * kDeg, yaw_w = 2 * M_PI / 10.0;
  double heave_amp = 0.5, heave_w = 2 * M_PI / 7.0;

  // Envelope and its first two derivatives.
  void Envelope(double tau, double* w, double* dw, double* ddw) const {
    if (tau <= 0.0) {
      *w = *dw = *ddw = 0.0;
    } else if (tau >= kRamp) {
      *w = 1.0;
      *dw = *ddw = 0.0;
    } else {
      const double c = M_PI / kRamp;
      *w = 0.5 * (1.0 - std::cos(c * tau));
      *dw = 0.5 * c * std::sin(c * tau);
      *ddw = 0.5 * c * c * std::cos(c * tau);
    }
  }
  // x = amp w sin(omega tau) and its first two derivatives.
  void Wave(double tau, double amp, double om, double* x, double* dx, double* ddx) const {
    double w, dw, ddw;
    Envelope(tau, &w, &dw, &ddw);
    const double s = std::sin(om * tau), c = std::cos(om * tau);
    *x = amp * w * s;
    *dx = amp * (dw * s + w * om * c);
    *ddx = amp * (ddw * s + 2.0 * dw * om * c - w * om * om * s);
  }
  EulerAngles Euler(double t, Vector3d* rates) const {
    const double tau = t - kT0;
    double r, dr, pch, dp, y, dy, unused;
    Wave(tau, roll_amp, roll_w, &r, &dr, &unused);
    Wave(tau, pitch_amp, pitch_w, &pch, &dp, &unused);
    Wave(tau, yaw_amp, yaw_w, &y, &dy, &unused);
    *rates = Vector3d(dr, dp, dy);
    return {r, pch, y};
  }
  Matrix3d C_b_n(double t) const {
    Vector3d rates;
    return EulerToDcm(Euler(t, &rates));
  }
  // Heave: height up = z, so NED position D = -z.
  void Heave(double t, double* r_D, double* v_D, double* a_D) const {
    double z, dz, ddz;
    Wave(t - kT0, heave_amp, heave_w, &z, &dz, &ddz);
    *r_D = -z;
    *v_D = -dz;
    *a_D = -ddz;
  }
  ImuSample Sample(double t) const {
    Vector3d rates;
    const EulerAngles e = Euler(t, &rates);
    double r_D, v_D, a_D;
    Heave(t, &r_D, &v_D, &a_D);
    ImuSample s;
    s.omega_ib_b = EulerRatesToBodyRate(e, rates);
    s.f_ib_b = EulerToDcm(e).transpose() * (Vector3d(0.0, 0.0, a_D) - Vector3d(0.0, 0.0, kG));
    return s;
  }
  // |d^n heave / dt^n| <= H (omega + pi / T_ramp)^n (Leibniz rule; |w^(k)| <= (pi/T_ramp)^k / 2).
  double HeaveDerivativeBound(int n) const {
    return heave_amp * std::pow(heave_w + M_PI / kRamp, n);
  }
};

TEST(Seed000MechanizationTest, SeawayStaysWithinFirstOrderTruncationBound) {
  // Mechanization B's attitude step Q(k+1) = normalise((1 + 1/2 omega_k dt) Q(k)) is the exact
  // rotation S_est,k about omega_k by 2 atan(|omega_k| dt / 2). The true step is
  // S_true,k = C_b_n(t_k)^T C_b_n(t_k+1). With the bi-invariant angle metric d,
  // d(A B, C D) <= d(A, C) + d(B, D), so the attitude error obeys the rigorous bound
  //   |psi_k| <= B_att,k = sum_{j<k} d(S_est,j, S_true,j)     (+ rounding, 1e-15 per step).
  // Velocity: |(C_est - C_true) f| <= |psi| |f| and the trapezoid on a_n errs by at most
  // dt^3/12 max|a''| per step, so B_v,k+1 = B_v,k + dt/2 (B_att,k |f_k| + B_att,k+1 |f_k+1|)
  // + dt^3/12 M4; position B_r,k+1 = B_r,k + dt/2 (B_v,k + B_v,k+1) + dt^3/12 M3, with
  // M_n = H (omega_h + pi/T_ramp)^n bounding the heave's n-th derivative.
  // Sharper, first order: the local error of the rectangle rule is -omega_dot dt^2 / 2 in the body
  // frame; resolved in n and summed, sum C_b_n omega_dot_b dt^2/2 = dt/2 (omega_n(t) - omega_n(t0))
  // (d/dt (C_b_n omega_b) = C_b_n omega_dot_b), so
  //   psi(t) = -dt/2 (omega_nb_n(t) - omega_nb_n(t0)) + O(dt^2)
  // The O(dt^2) remainder relative to this term is O(omega dt) ~ 1 %, plus the time-accumulated
  // (1/12) dt^2 coning-type terms: omega dt = 0.8 % here; we allow 2 % of the first-order term.
  const double dt = 0.01, T = AnalyticSeaway::kT0 + 300.0;
  const AnalyticSeaway sea;
  Seed000Mechanization ins(dt, {AnalyticSeaway::kT0, 0.0});
  const int steps = static_cast<int>(std::lround(T / dt));
  const int k0 = static_cast<int>(std::lround(AnalyticSeaway::kT0 / dt));
  double b_att = 0.0, b_v = 0.0, b_r = 0.0;
  double max_att = 0.0, max_v = 0.0, max_r = 0.0, max_first_order = 0.0, max_residual = 0.0;
  double max_att_excess = -1.0, max_att_over_bound = 0.0, max_v_over_bound = 0.0,
         max_r_over_bound = 0.0;
  const double m3 = sea.HeaveDerivativeBound(3), m4 = sea.HeaveDerivativeBound(4);
  ImuSample prev_sample = sea.Sample(0.0);
  double prev_f_norm = prev_sample.f_ib_b.norm();
  for (int k = 0; k <= steps; ++k) {
    const double t = k * dt;
    const ImuSample sample = sea.Sample(t);
    ins.Update(sample);
    if (k <= k0) {
      prev_sample = sample;
      prev_f_norm = sample.f_ib_b.norm();
      continue;
    }
    // Bounds for the step (t_{k-1}, t_k].
    const Vector3d& w = prev_sample.omega_ib_b;
    const double half = 0.5 * dt * w.norm();
    const Quaterniond s_est =
        half > 0.0 ? Quaterniond(Eigen::AngleAxisd(2.0 * std::atan(half), w.normalized()))
                   : Quaterniond::Identity();
    const Matrix3d s_true = sea.C_b_n(t - dt).transpose() * sea.C_b_n(t);
    const double e_step =
        Eigen::AngleAxisd(s_est.toRotationMatrix().transpose() * s_true).angle() + 1e-15;
    const double b_att_prev = b_att;
    b_att += e_step;
    const double f_norm = sample.f_ib_b.norm();
    const double b_v_prev = b_v;
    b_v += 0.5 * dt * (b_att_prev * prev_f_norm + b_att * f_norm) + dt * dt * dt / 12.0 * m4;
    b_r += 0.5 * dt * (b_v_prev + b_v) + dt * dt * dt / 12.0 * m3;

    // Errors against the analytic truth (navigation frame = initial body frame = NED here).
    const Matrix3d C_true = sea.C_b_n(t);
    const double att = AttitudeErrorNed(ins.q_b_nav().toRotationMatrix(), C_true).norm();
    double r_D, v_D, a_D;
    sea.Heave(t, &r_D, &v_D, &a_D);
    const double verr = (ins.v_nav_m_per_s() - Vector3d(0.0, 0.0, v_D)).norm();
    const double rerr = (ins.r_nav_m() - Vector3d(0.0, 0.0, r_D)).norm();
    max_att_excess = std::max(max_att_excess, att - b_att);
    max_att_over_bound = std::max(max_att_over_bound, att / b_att);
    max_v_over_bound = std::max(max_v_over_bound, verr / b_v);
    max_r_over_bound = std::max(max_r_over_bound, rerr / b_r);
    max_att = std::max(max_att, att);
    max_v = std::max(max_v, verr);
    max_r = std::max(max_r, rerr);

    const Vector3d psi = AttitudeErrorNed(ins.q_b_nav().toRotationMatrix(), C_true);
    const Vector3d psi_first_order = -0.5 * dt * (C_true * sample.omega_ib_b);
    max_first_order = std::max(max_first_order, psi_first_order.norm());
    max_residual = std::max(max_residual, (psi - psi_first_order).norm());
    prev_sample = sample;
    prev_f_norm = f_norm;
  }
  // On the first step after alignment the error equals the bound (one local error); rounding of
  // the angle computations is ~1e-16 rad, so the bound is checked with 1e-13 rad of slack.
  EXPECT_LE(max_att_excess, 1e-13);
  EXPECT_LE(max_v_over_bound, 1.0);
  EXPECT_LE(max_r_over_bound, 1.0);
  EXPECT_LE(max_residual, 0.02 * max_first_order);
  std::printf(
      "B seaway: max att %.3e rad (first-order term %.3e, residual %.3e), "
      "max v %.3e m/s, max r %.3e m; bound use att %.3f v %.3f r %.3f\n",
      max_att, max_first_order, max_residual, max_v, max_r, max_att_over_bound, max_v_over_bound,
      max_r_over_bound);
  std::printf("B seaway final bounds: att %.3e rad, v %.3e m/s, r %.3e m\n", b_att, b_v, b_r);
}

// Exact IMU increments of the analytic seaway: 8-point Gauss-Legendre quadrature of omega_ib_b and
// f_ib_b over each interval (exact to rounding for these smooth integrands: the quadrature error
// ~ (dt omega)^16 / 16! is far below 1e-16, and the envelope's kinks fall on sample instants).
ImuIncrement SeawayIncrement(const AnalyticSeaway& sea, double t0, double dt) {
  static constexpr double kX[4] = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267,
                                   0.9602898564975363};
  static constexpr double kW[4] = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745,
                                   0.1012285362903763};
  ImuIncrement inc;
  for (int i = 0; i < 4; ++i) {
    for (double sign : {-1.0, 1.0}) {
      const ImuSample s = sea.Sample(t0 + 0.5 * dt * (1.0 + sign * kX[i]));
      inc.delta_theta_ib_b += 0.5 * dt * kW[i] * s.omega_ib_b;
      inc.delta_v_ib_b += 0.5 * dt * kW[i] * s.f_ib_b;
    }
  }
  return inc;
}

struct FlatSeawayErrors {
  double attitude_rad = 0.0, velocity_m_per_s = 0.0, position_m = 0.0;
};

FlatSeawayErrors RunFlatSeaway(bool coning_sculling, double duration_s) {
  const double dt = 0.01;
  const AnalyticSeaway sea;
  const Llh origin{40.52 * kDeg, -3.77 * kDeg, 600.0};
  const NavEnvironment env = NavEnvironment::Flat(origin, AnalyticSeaway::kG);
  NavState truth;
  truth.llh = origin;
  NedMechanizationOptions options;
  options.coning_sculling = coning_sculling;
  NedMechanization ins(env, truth, dt, options);
  const int steps = static_cast<int>(std::lround((AnalyticSeaway::kT0 + duration_s) / dt));
  FlatSeawayErrors max;
  for (int k = 0; k < steps; ++k) {
    ins.Update(SeawayIncrement(sea, k * dt, dt));
    const double t = (k + 1) * dt;
    double r_D, v_D, a_D;
    sea.Heave(t, &r_D, &v_D, &a_D);
    Vector3d rates;
    truth.t_s = t;
    truth.q_b_n = Quaterniond(EulerToDcm(sea.Euler(t, &rates)));
    truth.v_eb_n = Vector3d(0.0, 0.0, v_D);
    truth.llh.h_m = origin.h_m - r_D;
    const NavError e = ComputeNavError(env, ins.state(), truth);
    max.attitude_rad = std::max(max.attitude_rad, e.psi_nb_n_rad.norm());
    max.velocity_m_per_s = std::max(max.velocity_m_per_s, e.v_ned_m_per_s.norm());
    max.position_m = std::max(max.position_m, e.r_ned_m.norm());
  }
  return max;
}

TEST(NedMechanizationTest, ConingAndScullingCorrectionsCloseTheSeawayWithExactIncrements) {
  // Flat frame (free vertical channel, but constant gravity: no instability), 300 s of seaway.
  // With the corrections the attitude step errs by O(dt^4) (coning |omega| |omega''| dt^4 / 720
  // ~ 1e-14 rad): < 1e-9 rad over 30,000 steps even if all add. The velocity step keeps third-order
  // cross terms ~ |omega| |omega_dot| |f| dt^3 / 12 = 1.3e-9 m/s, oscillating with the waves, so
  // they accumulate over ~ period / (2 pi dt) = 130 steps: bound 2e-7 m/s. Position: the
  // trapezoidal rule errs by dt^2/12 (a(t) - a(t0)) <= dt^2/12 * 2 * 0.4 m/s^2 = 6.7e-6 m of heave;
  // bound 2e-5 m. Without the corrections the single-sample algorithm misses
  // 1/2 dtheta x dv ~ 1/2 |omega| |f| dt^2 = 7e-5 m/s per step, so it must be > 100x worse.
  const FlatSeawayErrors with = RunFlatSeaway(true, 300.0);
  const FlatSeawayErrors without = RunFlatSeaway(false, 300.0);
  std::printf("A flat seaway with corrections: att %.3e rad, v %.3e m/s, r %.3e m\n",
              with.attitude_rad, with.velocity_m_per_s, with.position_m);
  std::printf("A flat seaway without:          att %.3e rad, v %.3e m/s, r %.3e m\n",
              without.attitude_rad, without.velocity_m_per_s, without.position_m);
  EXPECT_LT(with.attitude_rad, 1e-9);
  EXPECT_LT(with.velocity_m_per_s, 2e-7);
  EXPECT_LT(with.position_m, 2e-5);
  EXPECT_GT(without.velocity_m_per_s, 100.0 * with.velocity_m_per_s);
}

// ---- Through the trajectory generator ----------------------------------------------------------

TEST(Seed000MechanizationTest, RecoversSeed000LateralMoveFromGeneratedData) {
  // examples/ship_lateral_move.json: gnss-ins-sim type-1 commands in the body frame, flat frame:
  // 90 s at rest, +0.05 m/s^2 along body y for 4 s, 3 s coasting, -0.05 m/s^2 for 4 s, 10 s rest.
  // As in the hand-made test the only error is the trapezoidal rule across the four acceleration
  // steps; whichever side of a step the sample at the step takes, each step errs by at most
  // |da| dt / 2 in velocity, carried to the end:
  //   |dr(T)| <= sum_j |da_j| dt/2 (T - t_j + dt/2) = 0.05 * 0.005 * (21 + 17 + 14 + 10) = 0.0155
  //   m.
  // The truth itself must have moved 1.4 m east (body y = east at yaw 0): 0.4 + 0.6 + 0.4 m.
  MotionSpec m;
  m.earth_model = EarthModel::kFlat;
  m.initial.llh = {40.5208 * kDeg, -3.7722 * kDeg, 600.0};
  auto command = [](double ay, double duration_s) {
    GnssInsSimCommand c;
    c.type = 1;
    c.v_b = Vector3d(0.0, ay, 0.0);
    c.duration_s = duration_s;
    return c;
  };
  m.segments = {command(0.0, 90.0), command(0.05, 4.0), command(0.0, 3.0), command(-0.05, 4.0),
                command(0.0, 10.0)};
  SimulationSpec spec;
  spec.motion = m;
  spec.rate_hz = 100.0;
  spec.mechanization = MechanizationKind::kSeed000;
  spec.seed000.static_period_s = 90.0;
  NavState truth_start, truth_end, nav_end;
  const SimulationSummary summary = RunErrorFreeSimulation(spec, [&](const SimulationStep& s) {
    if (s.k == 0) truth_start = *s.truth;
    truth_end = *s.truth;
    nav_end = *s.nav;
  });
  // 11100 executor steps; as gnss-ins-sim, the output ends at the state before the last one.
  EXPECT_NEAR(summary.duration_s, 110.99, 1e-9);
  const NavEnvironment env = NavEnvironment::Flat(m.initial.llh, 9.8);  // metre scaling only
  const Vector3d truth_move = env.PositionErrorNed(truth_end.llh, truth_start.llh);
  const Vector3d nav_move = env.PositionErrorNed(nav_end.llh, truth_start.llh);
  EXPECT_LT((truth_move - Vector3d(0.0, 1.4, 0.0)).norm(), 1e-6);  // generator: rounding only
  EXPECT_LT(summary.final_error.r_ned_m.norm(), 0.0155);
  EXPECT_NEAR(nav_move.y(), 1.4, 0.0155);
  EXPECT_LT(std::abs(nav_move.x()), 1e-9);  // seed 000 saw 0.1 m of surge from sensor errors
  std::printf("B lateral move from generator: INS moved %.6f m east, %.3e m north; error %.3e m\n",
              nav_move.y(), nav_move.x(), summary.final_error.r_ned_m.norm());
}

TEST(Seed000MechanizationTest, GeneratedSeawayMatchesFirstOrderAttitudeError) {
  // Seed 000 seaway through the generator (flat frame, 90 s static, 300 s of waves) and
  // mechanization B: the attitude error must follow the first-order law derived in
  // SeawayStaysWithinFirstOrderTruncationBound, psi(t) = -dt/2 C_b_n(t) omega_ib_b(t), to 2 %.
  MotionSpec m;
  m.earth_model = EarthModel::kFlat;
  m.initial.llh = {40.5208 * kDeg, -3.7722 * kDeg, 600.0};
  m.segments.push_back(StaticSegment{90.0});
  ShipMotionSegment sea;
  sea.duration_s = 300.0;
  sea.roll_amplitude_rad = 8.0 * kDeg;
  sea.roll_period_s = 8.0;
  sea.pitch_amplitude_rad = 3.0 * kDeg;
  sea.pitch_period_s = 6.0;
  sea.pitch_phase_rad = 0.5 * M_PI;
  sea.yaw_amplitude_rad = 1.0 * kDeg;
  sea.yaw_period_s = 10.0;
  sea.heave_amplitude_m = 0.5;
  sea.heave_period_s = 7.0;
  sea.ramp_s = 20.0;
  m.segments.push_back(sea);
  SimulationSpec spec;
  spec.motion = m;
  spec.rate_hz = 100.0;
  spec.mechanization = MechanizationKind::kSeed000;
  spec.seed000.static_period_s = 90.0;
  const double dt = 0.01;
  double max_first_order = 0.0, max_residual = 0.0;
  const SimulationSummary summary = RunErrorFreeSimulation(spec, [&](const SimulationStep& s) {
    if (s.truth->t_s <= 90.0) return;
    const Vector3d predicted = -0.5 * dt * (s.truth->C_b_n() * s.sample->omega_ib_b);
    max_first_order = std::max(max_first_order, predicted.norm());
    max_residual = std::max(max_residual, (s.error->psi_nb_n_rad - predicted).norm());
  });
  std::printf(
      "B seaway from generator: first-order %.3e rad, residual %.3e rad, max horiz %.3e m\n",
      max_first_order, max_residual, summary.max_horizontal_position_m);
  EXPECT_GT(max_first_order, 1e-4);
  EXPECT_LE(max_residual, 0.02 * max_first_order);
}

}  // namespace
}  // namespace driftlab
