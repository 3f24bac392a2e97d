// Trajectory generator: consistency of the ideal increments with the truth, quadrature
// convergence, seed 002's circle, coordinated turns, truth-profile round trip, rates and
// durations.
#include "driftlab/trajectory.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "driftlab/io.h"
#include "trajectory_test_util.h"

namespace driftlab::trajectory_test {
namespace {

// ---- Consistency of the increments with the truth ---------------------------------------------

TEST(TrajectoryGenerator, FlatLevelTurnSummedDeltaThetaEqualsYawChange) {
  MotionSpec m = Motion(EarthModel::kFlat, 40.0, Vector3d(10.0, 0.0, 0.0), 0.0);
  m.segments = {ConstantVelocitySegment{2.0}, Turn(10.0, 90.0, 1.5), ConstantVelocitySegment{2.0}};
  TrajectoryGenerator g(m, 100.0);
  const Sums s = SumIncrements(g);
  // Level, no Earth rate: omega_ib_b = [0, 0, yaw'] exactly, piecewise polynomial of degree <= 1,
  // which 4-point Gauss-Legendre integrates exactly; left: rounding of ~1300 sums, ~1e-13 rel.
  EXPECT_NEAR(s.delta_theta.z(), M_PI / 2, 1e-9 * M_PI / 2);
  EXPECT_NEAR(s.delta_theta.x(), 0.0, 1e-15);
  EXPECT_NEAR(s.delta_theta.y(), 0.0, 1e-15);
  EXPECT_NEAR(s.last.euler().yaw_rad, M_PI / 2, 1e-12);
  // Speed is unchanged by the turn, and the velocity now points east.
  EXPECT_NEAR(s.last.v_eb_n.y(), 10.0, 1e-12);
  EXPECT_NEAR(s.last.v_eb_n.x(), 0.0, 1e-12);
}

TEST(TrajectoryGenerator, FlatStraightAccelerationSummedDeltaVIsVelocityChangeMinusGravity) {
  // Constant attitude (pitch does not follow the flight path): C_n_b constant, so
  // sum dv = C_n_b (delta v_eb_n - g T) exactly.
  MotionSpec m = Motion(EarthModel::kFlat, 40.0, Vector3d::Zero(), 30.0, 5.0, -3.0);
  m.flat_gravity_m_per_s2 = 9.81;
  AccelerateSegment a;
  a.acceleration_m_per_s2 = 2.0;
  a.target_speed_m_per_s = 10.0;
  m.segments = {StaticSegment{1.0}, a, ConstantVelocitySegment{1.0}};
  TrajectoryGenerator g(m, 100.0);
  const Sums s = SumIncrements(g);
  const double T = 7.0;
  const Matrix3d C_b_n = EulerToDcm(m.initial.attitude);
  const Vector3d expected =
      C_b_n.transpose() * (s.last.v_eb_n - Vector3d::Zero() - Vector3d(0, 0, 9.81) * T);
  // Exact to rounding: ~700 sums of ~0.1 m/s terms, 1e-9 relative is 1e6 times the rounding.
  EXPECT_LE((s.delta_v - expected).norm(), 1e-9 * expected.norm());
  EXPECT_NEAR(s.last.v_eb_n.norm(), 10.0, 1e-12);
  EXPECT_NEAR(std::atan2(s.last.v_eb_n.y(), s.last.v_eb_n.x()), 30.0 * kDeg, 1e-14);
  EXPECT_LE(s.delta_theta.norm(), 1e-15);
}

TEST(TrajectoryGenerator, Wgs84StaticIncrementsAreEarthRateAndGravity) {
  MotionSpec m = Motion(EarthModel::kWgs84, 45.0, Vector3d::Zero(), 30.0, 2.0, 1.0);
  m.segments = {StaticSegment{60.0}};
  TrajectoryGenerator g(m, 100.0);
  const Sums s = SumIncrements(g);
  const double T = 60.0;
  const Matrix3d C_n_b = EulerToDcm(m.initial.attitude).transpose();
  const double L = m.initial.llh.lat_rad, h = m.initial.llh.h_m;
  const Vector3d dtheta = C_n_b * EarthRateNed(L) * T;
  const Vector3d dv = -C_n_b * GravityNed(L, h) * T;
  // Constant integrands: exact to the rounding of 6000 sums.
  EXPECT_LE((s.delta_theta - dtheta).norm(), 1e-9 * dtheta.norm());
  EXPECT_LE((s.delta_v - dv).norm(), 1e-9 * dv.norm());
  // At rest the position does not move at all.
  EXPECT_EQ(s.last.llh.lat_rad, L);
  EXPECT_EQ(s.last.llh.h_m, h);
  EXPECT_TRUE(g.IsStaticAt(0.0));
  EXPECT_TRUE(g.IsStaticAt(60.0));
}

// ---- Quadrature convergence ---------------------------------------------------------------------

MotionSpec ShipAndTurn() {
  MotionSpec m = Motion(EarthModel::kWgs84, 40.5, Vector3d(5.0, 0.0, 0.0), 0.0);
  ShipMotionSegment ship;
  ship.duration_s = 12.0;
  ship.roll_amplitude_rad = 4.0 * kDeg;
  ship.roll_period_s = 1.6;
  ship.pitch_amplitude_rad = 2.0 * kDeg;
  ship.pitch_period_s = 1.2;
  ship.pitch_phase_rad = 90.0 * kDeg;
  ship.yaw_amplitude_rad = 1.0 * kDeg;
  ship.yaw_period_s = 3.0;
  ship.heave_amplitude_m = 0.3;
  ship.heave_period_s = 1.2;
  ship.ramp_s = 3.0;
  m.segments = {ConstantVelocitySegment{0.5}, ship, Turn(20.0, 90.0, 0.73),
                ConstantVelocitySegment{1.0}};
  return m;
}

// set_point_samples(false) leaves the point samples out and changes nothing else: the truth and
// the increments are the same bits as with them (exact equality: the same operations).
TEST(TrajectoryGenerator, WithoutPointSamplesTruthAndIncrementsAreTheSameBits) {
  const MotionSpec m = ShipAndTurn();
  TrajectoryGenerator with(m, 100.0), without(m, 100.0);
  without.set_point_samples(false);
  TrajectorySample a, b;
  b.sample.omega_ib_b = Vector3d(7.0, 8.0, 9.0);  // left as it is by Next
  int64_t steps = 0;
  while (with.Next(&a)) {
    ASSERT_TRUE(without.Next(&b));
    ++steps;
    ASSERT_EQ(a.truth.llh.lat_rad, b.truth.llh.lat_rad) << steps;
    ASSERT_EQ(a.truth.llh.lon_rad, b.truth.llh.lon_rad) << steps;
    ASSERT_EQ(a.truth.llh.h_m, b.truth.llh.h_m) << steps;
    ASSERT_EQ(a.truth.v_eb_n, b.truth.v_eb_n) << steps;
    ASSERT_EQ(a.truth.q_b_n.coeffs(), b.truth.q_b_n.coeffs()) << steps;
    ASSERT_EQ(a.increment.delta_theta_ib_b, b.increment.delta_theta_ib_b) << steps;
    ASSERT_EQ(a.increment.delta_v_ib_b, b.increment.delta_v_ib_b) << steps;
  }
  EXPECT_FALSE(without.Next(&b));
  EXPECT_EQ(steps, with.num_steps());
  EXPECT_EQ(b.sample.omega_ib_b, Vector3d(7.0, 8.0, 9.0));
  EXPECT_NE(a.sample.omega_ib_b, Vector3d(7.0, 8.0, 9.0));
}

TEST(TrajectoryGenerator, IncrementsAt100HzEqualSummedIncrementsAt2000Hz) {
  const MotionSpec m = ShipAndTurn();
  const Trajectory coarse = GenerateTrajectory(m, 100.0);
  const Trajectory fine = GenerateTrajectory(m, 2000.0);
  ASSERT_EQ(fine.increments.size(), 20 * coarse.increments.size());
  // Differences relative to the sum of the magnitudes of the 20 fine increments, the scale of
  // the rounding of their sum.
  double worst_theta = 0.0, worst_v = 0.0;
  for (size_t k = 0; k < coarse.increments.size(); ++k) {
    Vector3d dtheta = Vector3d::Zero(), dv = Vector3d::Zero();
    double scale_theta = 0.0, scale_v = 0.0;
    for (size_t j = 20 * k; j < 20 * (k + 1); ++j) {
      dtheta += fine.increments[j].delta_theta_ib_b;
      dv += fine.increments[j].delta_v_ib_b;
      scale_theta += fine.increments[j].delta_theta_ib_b.norm();
      scale_v += fine.increments[j].delta_v_ib_b.norm();
    }
    const ImuIncrement& c = coarse.increments[k];
    worst_theta = std::max(worst_theta, (dtheta - c.delta_theta_ib_b).norm() / scale_theta);
    worst_v = std::max(worst_v, (dv - c.delta_v_ib_b).norm() / scale_v);
  }
  std::printf("100 Hz vs 20 x 2000 Hz: worst relative difference dtheta %.2e, dv %.2e\n",
              worst_theta, worst_v);
  // Both are the exact integral to quadrature error ~(omega h)^8 / 10^7 < 1e-16 (omega <= 5.3
  // rad/s, h <= 0.01 s) plus the rounding of 20 sums (~20 eps = 4e-15 of the scale).
  EXPECT_LE(worst_theta, 1e-12);
  EXPECT_LE(worst_v, 1e-12);
}

// ---- Seed 002's circle -------------------------------------------------------------------------

MotionSpec Circle(EarthModel model) {
  // V = 5 m/s, heading rate 2 pi / T with T = 10 s (36 deg/s), radius V T / (2 pi) = 7.96 m.
  MotionSpec m = Motion(model, 22.99, Vector3d(5.0, 0.0, 0.0), 0.0);
  m.segments = {Turn(36.0, 360.0, 0.0)};
  return m;
}

TEST(TrajectoryGenerator, Seed002CircleClosesOnTheFlatFrame) {
  const MotionSpec m = Circle(EarthModel::kFlat);
  TrajectoryGenerator g(m, 100.0);
  const Sums s = SumIncrements(g);
  ASSERT_EQ(s.steps, 1000);
  const Vector3d closure = g.environment().PositionErrorNed(s.last.llh, g.initial_state().llh);
  std::printf("flat circle closure %.3e m\n", closure.norm());
  // RK4 on x' = v(t) is Simpson's rule: error T h^4 V omega^4 / 2880 = 3e-11 m; the position sum
  // is compensated (TwoSum), so rounding stays ~ulp(L) x R = 7e-10 m instead of growing per step.
  EXPECT_LE(closure.norm(), 1e-8);
  EXPECT_NEAR(WrapPi(s.last.euler().yaw_rad), 0.0, 1e-12);
}

TEST(TrajectoryGenerator, Seed002CircleCentripetalAccelerationIsV2PiOverTPerpendicularToVelocity) {
  const MotionSpec m = Circle(EarthModel::kFlat);
  const Trajectory t = GenerateTrajectory(m, 100.0);
  const double V = 5.0, T = 10.0, g = t.environment.Gravity(0, 0).z();
  for (size_t k : {size_t{1}, size_t{237}, size_t{500}, size_t{999}}) {
    // Flat frame: dv/dt = C_b_n f_ib_b + g_n exactly (no Coriolis, no transport rate).
    const Vector3d a = t.truth[k].C_b_n() * t.samples[k].f_ib_b + Vector3d(0, 0, g);
    const Vector3d v = t.truth[k].v_eb_n;
    // Rounding of f = C_n_b (a - g) and back: a few eps x g = 1e-14 m/s^2.
    EXPECT_NEAR(a.norm(), V * 2.0 * M_PI / T, 1e-12);
    EXPECT_NEAR(a.dot(v), 0.0, 1e-12);
    EXPECT_GT(v.cross(a).z(), 0.0);  // clockwise (right) turn: a points to the right of v
    // Seed 002's components with its own heading convention: |a_N|, |a_E| = 2 pi V |sin|, |cos|.
    const double psi = std::atan2(v.y(), v.x());
    EXPECT_NEAR(std::abs(a.x()), 2.0 * M_PI * V * std::abs(std::sin(psi)) / T, 1e-12);
    EXPECT_NEAR(std::abs(a.y()), 2.0 * M_PI * V * std::abs(std::cos(psi)) / T, 1e-12);
  }
}

TEST(TrajectoryGenerator, Seed002CircleOnWgs84ClosesToTheMeridianConvergenceOffset) {
  const MotionSpec m = Circle(EarthModel::kWgs84);
  TrajectoryGenerator g(m, 100.0);
  const Sums s = SumIncrements(g);
  const Vector3d closure = g.environment().PositionErrorNed(s.last.llh, g.initial_state().llh);
  // A constant yaw rate relative to local north is not a closed curve on the ellipsoid: with
  // dL = (V / (R_N omega)) (sin psi - sin psi_0), the 1 / cos L factor in lambda' adds
  //   dE = tan L (V / (R_N omega)) V int sin psi (sin psi - sin psi_0) dt = pi r^2 tan L / R_N
  // to the east (r = V / omega), while the north terms integrate to zero. With the ellipsoid,
  // d/dL ln(1 / (R_E cos L)) = tan L - e^2 sin L cos L / (1 - e^2 sin^2 L) replaces tan L, and the
  // radii are R + h. Higher-order terms are O(r / R) ~ 1e-6 relative; rounding and RK4 1e-8 m
  // (see the flat test).
  const double L = m.initial.llh.lat_rad, h = m.initial.llh.h_m, r = 5.0 / (36.0 * kDeg);
  const double e2 = kWgs84Eccentricity2, sl = std::sin(L), cl = std::cos(L);
  const double expected_east =
      M_PI * r * r * (std::tan(L) - e2 * sl * cl / (1 - e2 * sl * sl)) / (MeridianRadius(L) + h);
  std::printf("WGS-84 circle closure N %.3e E %.3e m, predicted E %.3e m\n", closure.x(),
              closure.y(), expected_east);
  EXPECT_NEAR(closure.y(), expected_east, 1e-3 * expected_east + 1e-8);
  EXPECT_LE(std::abs(closure.x()), 1e-8);
  EXPECT_LE(std::abs(closure.z()), 1e-9);
}

// ---- Coordinated turn --------------------------------------------------------------------------

TEST(TrajectoryGenerator, CoordinatedTurnHasNoLateralSpecificForceInTheSteadyTurn) {
  MotionSpec m = Motion(EarthModel::kFlat, 45.0, Vector3d(100.0, 0.0, 0.0), 0.0);
  m.vehicle.coordinated_turns = true;
  m.segments = {ConstantVelocitySegment{1.0}, Turn(3.0, 90.0, 2.0), ConstantVelocitySegment{1.0}};
  const Trajectory t = GenerateTrajectory(m, 100.0);
  const double g = t.environment.Gravity(0, 0).z();
  const double omega = 3.0 * kDeg, V = 100.0;
  int checked = 0;
  for (size_t k = 1; k < t.truth.size(); ++k) {
    const double time = t.truth[k].t_s;
    if (time < 3.0 - 1e-9 || time > 31.0 + 1e-9) continue;  // steady part: 3 s .. 31 s
    // f_y = V omega cos(phi) - g sin(phi) = 0 for tan(phi) = V omega / g; rounding ~ eps x g.
    EXPECT_NEAR(t.samples[k].f_ib_b.y(), 0.0, 1e-12);
    EXPECT_NEAR(t.increments[k - 1].delta_v_ib_b.y(), 0.0, 1e-12 * 0.01);
    EXPECT_NEAR(t.truth[k].euler().roll_rad, std::atan(V * omega / g), 1e-12);
    ++checked;
  }
  EXPECT_EQ(checked, 2801);
  // The bank returns to zero after the turn (continuous roll through the ramps).
  EXPECT_NEAR(t.truth.back().euler().roll_rad, 0.0, 1e-12);
}

// ---- Truth profile round trip ------------------------------------------------------------------

TEST(TrajectoryGenerator, TruthProfileRoundTripMatchesToSplineInterpolationError) {
  MotionSpec m = Motion(EarthModel::kWgs84, 50.0, Vector3d(3.0, 4.0, 0.0), 53.13);
  ShipMotionSegment ship;
  ship.duration_s = 100.0;
  ship.roll_amplitude_rad = 5.0 * kDeg;
  ship.roll_period_s = 8.0;
  ship.pitch_amplitude_rad = 2.0 * kDeg;
  ship.pitch_period_s = 6.0;
  ship.pitch_phase_rad = 1.0;
  ship.yaw_amplitude_rad = 3.0 * kDeg;
  ship.yaw_period_s = 10.0;
  ship.heave_amplitude_m = 0.5;
  ship.heave_period_s = 6.0;
  ship.ramp_s = 10.0;
  m.segments = {ship};
  const Trajectory original = GenerateTrajectory(m, 100.0);

  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("driftlab_profile_" + std::to_string(::getpid()));
  {
    GrovesProfileWriter writer(file);
    for (size_t k = 0; k < original.truth.size(); k += 10) writer.Write(original.truth[k]);
    writer.Close();
  }
  const MotionSpec imported = TruthProfileMotion(ReadTruthProfile(file));
  std::filesystem::remove(file);
  const Trajectory again = GenerateTrajectory(imported, 100.0);
  ASSERT_EQ(again.truth.size(), original.truth.size());

  // Between samples (h = 0.1 s) the spline error of a sinusoid A sin(w t) is at most
  // (5 / 384) h^4 A w^4 (complete cubic spline, de Boor ch. V); the not-a-knot interior is the same
  // order. Roll: A = 5 deg, w = 2 pi / 8: 4.3e-8 rad; yaw 3 deg, 10 s: 1.0e-8; pitch 2 deg, 6 s:
  // 3.5e-8; heave velocity A w = 0.52 m/s, w = 1.05: 8.2e-7 m/s. Only the interior of the full-
  // amplitude part is compared: the envelope's kinks (t = 10 s and 90 s) have O(h^2) errors that
  // decay by (2 - sqrt 3) per knot, negligible 2 s (20 knots) away.
  const double h4 = std::pow(0.1, 4), c = 5.0 / 384.0;
  const double w_roll = 2 * M_PI / 8, w_pitch = 2 * M_PI / 6, w_yaw = 2 * M_PI / 10;
  const double att_tol = c * h4 *
                         (5 * kDeg * std::pow(w_roll, 4) + 2 * kDeg * std::pow(w_pitch, 4) +
                          3 * kDeg * std::pow(w_yaw, 4));
  const double vel_tol = c * h4 * 0.5 * std::pow(w_pitch, 5);
  double worst_att = 0.0, worst_vel = 0.0, worst_sample_att = 0.0, worst_sample_vel = 0.0;
  for (size_t k = 0; k < original.truth.size(); ++k) {
    const double time = original.truth[k].t_s;
    const double att = AttitudeErrorNed(again.truth[k].C_b_n(), original.truth[k].C_b_n()).norm();
    const double vel = (again.truth[k].v_eb_n - original.truth[k].v_eb_n).norm();
    if (k % 10 == 0) {
      worst_sample_att = std::max(worst_sample_att, att);
      worst_sample_vel = std::max(worst_sample_vel, vel);
    } else if (time > 12.0 && time < 88.0) {
      worst_att = std::max(worst_att, att);
      worst_vel = std::max(worst_vel, vel);
    }
  }
  std::printf(
      "profile round trip: at samples att %.2e rad vel %.2e m/s; between att %.2e "
      "(bound %.2e) vel %.2e (bound %.2e)\n",
      worst_sample_att, worst_sample_vel, worst_att, att_tol, worst_vel, vel_tol);
  // At the samples the spline interpolates: equal to the rounding of the deg <-> rad conversions.
  EXPECT_LE(worst_sample_att, 1e-13);
  EXPECT_LE(worst_sample_vel, 1e-13);
  EXPECT_LE(worst_att, att_tol);
  EXPECT_LE(worst_vel, vel_tol);
  // Position: integrated from the interpolated velocity; error <= duration x velocity error.
  const Vector3d dr =
      again.environment.PositionErrorNed(again.truth.back().llh, original.truth.back().llh);
  EXPECT_LE(dr.norm(), 100.0 * vel_tol);
}

TEST(TrajectoryGenerator, TruthProfileSplineReproducesACubicExactly) {
  // A not-a-knot cubic spline is exact for cubic polynomials: v_N(t) = 1 + 0.5 t - 0.2 t^2 +
  // 0.03 t^3 sampled at uneven times must come back exactly between the samples.
  std::vector<TruthProfileSample> samples;
  for (double t : {0.0, 0.3, 0.5, 1.1, 1.4, 2.0, 2.2, 3.0}) {
    TruthProfileSample s;
    s.t_s = t;
    s.llh = {10 * kDeg, 20 * kDeg, 5.0};
    s.v_eb_n = Vector3d(1 + 0.5 * t - 0.2 * t * t + 0.03 * t * t * t, 0, 0);
    s.attitude.yaw_rad = 0.1 * t * t * t;
    samples.push_back(s);
  }
  const Trajectory t = GenerateTrajectory(TruthProfileMotion(samples, EarthModel::kFlat), 100.0);
  for (size_t k = 0; k < t.truth.size(); ++k) {
    const double x = t.truth[k].t_s;
    // Rounding of the tridiagonal solve and the polynomial evaluation: ~1e-14.
    EXPECT_NEAR(t.truth[k].v_eb_n.x(), 1 + 0.5 * x - 0.2 * x * x + 0.03 * x * x * x, 1e-13);
    EXPECT_NEAR(t.truth[k].euler().yaw_rad, 0.1 * x * x * x, 1e-13);
    EXPECT_NEAR(t.samples[k].omega_ib_b.z(), 0.3 * x * x, 1e-12);
  }
}

// ---- Rates and durations
// ---------------------------------------------------------------------------

TEST(TrajectoryGenerator, RatesOneAnd2000HzAcceptedHalfAnd2001HzRejected) {
  MotionSpec m = Motion(EarthModel::kWgs84, 40.0, Vector3d::Zero(), 0.0);
  m.segments = {StaticSegment{2.0}};
  EXPECT_EQ(TrajectoryGenerator(m, 1.0).num_steps(), 2);
  EXPECT_EQ(TrajectoryGenerator(m, 2000.0).num_steps(), 4000);
  ExpectRejected(m, 0.5, {"rate_hz: 0.5 is not allowed", "1 <= rate_hz <= 2000 Hz"});
  ExpectRejected(m, 2001.0, {"rate_hz: 2001 is not allowed"});
  ExpectRejected(m, NAN, {"rate_hz: nan is not allowed"});
}

TEST(TrajectoryGenerator, HundredThousandSecondsAtOneHertzStreamInConstantMemory) {
  // Static on WGS-84 and straight on the flat frame, each 100,000 s (seed 002's longest run).
  MotionSpec still = Motion(EarthModel::kWgs84, 40.0, Vector3d::Zero(), 0.0);
  still.segments = {StaticSegment{kMaxDuration_s}};
  MotionSpec straight = Motion(EarthModel::kFlat, 40.0, Vector3d(20.0, 0.0, 0.0), 0.0);
  straight.segments = {ConstantVelocitySegment{kMaxDuration_s}};
  for (const MotionSpec* m : {&still, &straight}) {
    const auto start = std::chrono::steady_clock::now();
    TrajectoryGenerator g(*m, 1.0);
    const Sums s = SumIncrements(g);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("100,000 s at 1 Hz: %lld steps in %.3f s\n", static_cast<long long>(s.steps),
                seconds);
    EXPECT_EQ(s.steps, 100000);
    EXPECT_DOUBLE_EQ(s.last.t_s, kMaxDuration_s);
    const Vector3d r = g.environment().PositionErrorNed(s.last.llh, g.initial_state().llh);
    // Straight: 2,000 km north. RK4 is exact for constant v; the compensated position sum leaves
    // the rounding of the final L and of the metre conversion: a few ulp(L) x R ~ 1e-9 m.
    EXPECT_NEAR(r.x(), m->initial.v_eb_n.x() * kMaxDuration_s, 1e-6);
    EXPECT_NEAR(r.y(), 0.0, 1e-9);
  }
}

TEST(TrajectoryGenerator, IsStaticOnlyWhileAtRestWithZeroRates) {
  MotionSpec m = Motion(EarthModel::kFlat, 40.0, Vector3d::Zero(), 0.0);
  AccelerateSegment a;
  a.acceleration_m_per_s2 = 1.0;
  a.target_speed_m_per_s = 5.0;
  m.segments = {StaticSegment{10.0}, a};
  TrajectoryGenerator g(m, 100.0);
  EXPECT_TRUE(g.IsStaticAt(0.0));
  EXPECT_TRUE(g.IsStaticAt(10.0));  // left limit: the static segment ends at 10 s
  EXPECT_FALSE(g.IsStaticAt(10.01));
  EXPECT_FALSE(g.IsStaticAt(15.0));
  ASSERT_EQ(g.breakpoints_s().size(), 1u);
  EXPECT_EQ(g.breakpoints_s()[0], 10.0);
}

TEST(TrajectoryGenerator, ClimbChangesHeightByTheRequestedAmountWithPitchOnFlightPath) {
  MotionSpec m = Motion(EarthModel::kFlat, 40.0, Vector3d(50.0, 0.0, 0.0), 0.0);
  m.vehicle.pitch_follows_flight_path = true;
  ClimbSegment c;
  c.climb_rate_m_per_s = 5.0;
  c.vertical_acceleration_m_per_s2 = 0.5;
  c.height_change_m = 300.0;
  m.segments = {c, ConstantVelocitySegment{1.0}};
  TrajectoryGenerator g(m, 100.0);
  // Ramps of 10 s each (25 m each) and a hold of (300 - 50) / 5 = 50 s: 70 s + 1 s.
  EXPECT_NEAR(g.duration_s(), 71.0, 1e-12);
  TrajectorySample s;
  double max_pitch = 0.0;
  while (g.Next(&s)) max_pitch = std::max(max_pitch, s.truth.euler().pitch_rad);
  // RK4 on a piecewise-quadratic height is exact to rounding.
  EXPECT_NEAR(s.truth.llh.h_m - m.initial.llh.h_m, 300.0, 1e-9);
  EXPECT_NEAR(max_pitch, std::atan2(5.0, 50.0), 1e-12);
  EXPECT_NEAR(s.truth.euler().pitch_rad, 0.0, 1e-12);
}

}  // namespace
}  // namespace driftlab::trajectory_test
