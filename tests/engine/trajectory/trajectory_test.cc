// Trajectory generator: consistency of the ideal increments with the truth, quadrature
// convergence, seed 002's circle, coordinated turns, gnss-ins-sim semantics, truth-profile round
// trip, validation and limits.
#include "driftlab/trajectory.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "driftlab/io.h"
#include "driftlab/spec_error.h"
#include "support/motion_builders.h"

namespace driftlab {
namespace {

MotionSpec Motion(EarthModel model, double lat_deg, const Vector3d& v_eb_n, double yaw_deg,
                  double pitch_deg = 0.0, double roll_deg = 0.0) {
  MotionSpec m;
  m.earth_model = model;
  m.initial.llh = {lat_deg * kDeg, 10.0 * kDeg, 100.0};
  m.initial.v_eb_n = v_eb_n;
  m.initial.attitude = {roll_deg * kDeg, pitch_deg * kDeg, yaw_deg * kDeg};
  return m;
}

TurnSegment Turn(double rate_deg_per_s, double angle_deg, double transition_s) {
  return testing::TurnByRate(rate_deg_per_s, angle_deg, transition_s);
}

struct Sums {
  Vector3d delta_theta = Vector3d::Zero();
  Vector3d delta_v = Vector3d::Zero();
  NavState last;
  int64_t steps = 0;
};

Sums SumIncrements(TrajectoryGenerator& generator) {
  Sums sums;
  sums.last = generator.initial_state();
  TrajectorySample s;
  while (generator.Next(&s)) {
    sums.delta_theta += s.increment.delta_theta_ib_b;
    sums.delta_v += s.increment.delta_v_ib_b;
    sums.last = s.truth;
    ++sums.steps;
  }
  return sums;
}

// Expects `what()` of the SpecError thrown by constructing a generator to contain every part.
void ExpectRejected(const MotionSpec& motion, double rate_hz,
                    std::initializer_list<std::string> parts) {
  try {
    TrajectoryGenerator generator(motion, rate_hz);
    ADD_FAILURE() << "accepted; expected an error containing " << *parts.begin();
  } catch (const SpecError& e) {
    for (const std::string& part : parts) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos)
          << "message: " << e.what() << "\nmissing: " << part;
    }
  }
}

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

// ---- gnss-ins-sim
// ----------------------------------------------------------------------------------

void Check90DegreeTurn(const std::filesystem::path& file) {
  SCOPED_TRACE(file.string());
  const MotionSpec m = ReadGnssInsSimMotion(file);
  TrajectoryGenerator g(m, 100.0);
  // 1000 executor steps of 0.01 s; gnss-ins-sim's output (and driftlab's) ends before the last.
  EXPECT_DOUBLE_EQ(g.duration_s(), 9.99);
  // Errata: starts at yaw 315 deg, turns at +15 deg/s for 6 s, ends at 45 deg. The type-1 rate
  // passes gnss-ins-sim's low-pass filter (0.9 per step): the turn ends late, but the area under
  // the rate still missing 300 steps after the rate command is gone is 15 deg/s x 0.9^300 x 9 dt
  // = 4e-15 rad. Tolerance 1e-9 rad: rounding of the summed steps and the quaternion (1e-15).
  EXPECT_NEAR(WrapPi(g.initial_state().euler().yaw_rad - 315.0 * kDeg), 0.0, 1e-9);
  const Sums s = SumIncrements(g);
  EXPECT_NEAR(WrapPi(s.last.euler().yaw_rad - 45.0 * kDeg), 0.0, 1e-9);
  // The body velocity (10 m/s forward) turned with the body: the final track is 45 deg too.
  EXPECT_NEAR(s.last.v_eb_n.x(), 10.0 * std::cos(45.0 * kDeg), 1e-9);
  EXPECT_NEAR(s.last.v_eb_n.y(), 10.0 * std::sin(45.0 * kDeg), 1e-9);
}

TEST(TrajectoryGenerator, GnssInsSim90DegreeTurnFileStartsAt315AndEndsAtYaw45Degrees) {
  Check90DegreeTurn(kTestData / "gnss_ins_sim_90deg_turn.csv");
  Check90DegreeTurn(kTestData / "gnss_ins_sim" / "motion_def-90deg_turn.csv");  // the tool's own
}

// Reference values: gnss-ins-sim's own pathgen.path_gen() (github.com/Aceinna/gnss-ins-sim, commit
// 966ff271bf21d08fbd0e31d1eb47fa5f3acef8d3, Debian python3-numpy 1.24.2) on its demo files,
// reading them as Sim.__parse_motion() does; last row of its 'nav' output (lat, lon [rad], h [m],
// v_N, v_E, v_D [m/s], yaw, pitch, roll [rad]) and its odometer distance at that row [m].
struct GnssInsSimReference {
  const char* file;
  double rate_hz;
  double max_acceleration, max_angular_acceleration, max_angular_rate;  // its 'mobility'
  int64_t samples;
  double lat, lon, h, v_n, v_e, v_d, yaw, pitch, roll, distance;
};

// Default mobility: gnss-ins-sim's high_mobility [1 m/s^2, 0.5 rad/s^2, 2 rad/s].
constexpr GnssInsSimReference kGnssInsSimReferences[] = {
    {"motion_def-0to100.csv", 100, 1.0, 0.5, 2.0, 1000, 0.55858242236527089, 2.0943951023931953, 0,
     98.999999999998479, 0, 0, 0, 0, 0, 489.59999999999911},
    {"motion_def-0to100_sample_by_sample.csv", 100, 1.0, 0.5, 2.0, 1000, 0.55858242236527089,
     2.0943951023931953, 0, 98.999999999998479, 0, 0, 0, 0, 0, 489.59999999999911},
    {"motion_def-100to0.csv", 100, 1.0, 0.5, 2.0, 1000, 0.558585538831046, 2.0943951023931953, 0,
     0.99999999999978784, 0, 0, 0, 0, 0, 509.40000000000038},
    {"motion_def-3d.csv", 100, 1.0, 0.5, 2.0, 8006, 0.55852111611411714, 2.0944135914778532,
     100.10000000000031, 0, 0, 0, 0, 0, 0, 300.30000000000092},
    {"motion_def-90deg_turn.csv", 100, 1.0, 0.5, 2.0, 1000, 0.55845721989082675, 2.0944672664347022,
     0, 7.0710678118658299, 7.0710678118651229, 0, 0.78539816339739854, 0, 0, 99.899999999998599},
    {"motion_def-Allan.csv", 100, 1.0, 0.5, 2.0, 180000, 0.55850536063818546, 2.0943951023931953, 0,
     0, 0, 0, 0, 0, 0, 0},
    {"motion_def-Holland_tunnel.csv", 100, 1.0, 0.5, 2.0, 52940, 0.71073118487845699,
     -1.2916843130034161, 0, 1.5594258024323611e-74, -2.7016234499276758e-74, 0,
     -1.0472967260331272, 0, 0, 4812.6354999983105},
    {"motion_def-ins.csv", 100, 1.0, 0.5, 2.0, 73250, 0.55849947162519165, 2.0945288704068457,
     172.73429102086527, 9.1259954965734194e-07, 0.0099999999401036363, 6.0692708210119667e-07,
     1.5707050668396376, -6.0692708246712357e-05, 0, 5224.9999000013013},
    {"motion_def-long_drive.csv", 100, 1.0, 0.5, 2.0, 96552, 0.5499254725023256, 2.101410866369477,
     0, -6.7552273909345399e-14, -3.3817520520279719e-15, 0, -3.0915731492831564, 0, 0,
     7409.5749999979253},
    {"motion_def-static.csv", 100, 1.0, 0.5, 2.0, 50000, 0.55850536063818546, 2.0943951023931953, 0,
     0, 0, 0, 0, 0.52359877559829882, 0, 0},
    {"motion_def-static-54b4415.csv", 100, 1.0, 0.5, 2.0, 50000, 0.55850536063818546,
     2.0943951023931953, 0, 0, 0, 0, 0, 0.52359877559829882, 0, 0},
    {"motion_def.csv", 100, 1.0, 0.5, 2.0, 54250, 0.55849947162519165, 2.0945288704068457,
     172.73429102086527, 9.1259954965734194e-07, 0.0099999999401036363, 6.0692708210119667e-07,
     1.5707050668396376, -6.0692708246712357e-05, 0, 5224.9999000013013},
    {"motion_def_mag_cal.csv", 100, 1.0, 0.5, 2.0, 14001, 0.55850536063818546, 2.0943951023931953,
     0, 0, 0, 0, -2.0943951023932783, -0.00020789850610825056, -5.5918398800258728e-09, 0},
    // Its dependence on the simulation rate: the same files at 200 Hz.
    {"motion_def-Holland_tunnel.csv", 200, 1.0, 0.5, 2.0, 105851, 0.71073139127000851,
     -1.2916848074129184, 0, 8.4477706608728788e-149, -1.4635337579428618e-148, 0,
     -1.0472972521220711, 0, 0, 4809.618874998383},
    {"motion_def-3d.csv", 200, 1.0, 0.5, 2.0, 16006, 0.55852110824424928, 2.0944135822424559,
     100.04999999999725, 2.4703282292062327e-323, 2.0786633759404042e-274, -2.7495485213387944e-91,
     0, 0, 0, 300.14999999999185},
    // A user mobility: Sim(mode=np.array([0.5, 10.0, 20.0])) = 0.5 m/s^2, 10 deg/s^2, 20 deg/s.
    {"motion_def-Holland_tunnel.csv", 100, 0.5, 10.0 * kDeg, 20.0 * kDeg, 53854,
     0.71075426014744703, -1.2917272278058491, 0, 0.37248948646298163, -0.64519499569815431, 0,
     -1.0472138464040013, 0, 0, 4748.6448927430347},
    {"motion_def-long_drive.csv", 100, 0.5, 10.0 * kDeg, 20.0 * kDeg, 108222, 0.54992580474225794,
     2.1014297450518891, 0, -8.9515658601777221e-14, -6.8014349385993479e-15, 0,
     -3.0657579681259146, 0, 0, 8585.4861999914574},
};

// The two large Komatsu files (not committed; run with DRIFTLAB_GNSS_INS_SIM_DIR).
constexpr GnssInsSimReference kGnssInsSimKomatsuReferences[] = {
    {"motion_def/motion_def-Komatsu_level_50m_0_0.csv", 100, 1.0, 0.5, 2.0, 34573,
     0.55851528087169577, 2.0943951023931953, 0, -3.9999999361873503e-07, 0, 0, 0, 0, 0,
     63.274777011827027},
    {"motion_def/motion_def-Komatsu_loaded_-5_0.csv", 100, 1.0, 0.5, 2.0, 21033,
     0.55851361835637781, 2.0943951023931953, -4.5900162121403678, 1.9923894078251818e-07, 0,
     1.7431148651383232e-08, 0, -0.087266462599716377, 0, 52.691876593676341},
};

void CheckAgainstGnssInsSim(const std::filesystem::path& file, const GnssInsSimReference& r) {
  SCOPED_TRACE(file.string() + " at " + std::to_string(r.rate_hz) + " Hz");
  MotionSpec m = ReadGnssInsSimMotion(file);
  m.gnss_ins_sim_limits = {r.max_acceleration, r.max_angular_acceleration, r.max_angular_rate};
  TrajectoryGenerator g(m, r.rate_hz);
  // gnss-ins-sim's samples are at t = 0 .. (N - 1) dt, driftlab's at t = 0 .. num_steps dt.
  EXPECT_EQ(g.num_steps() + 1, r.samples);
  const Sums s = SumIncrements(g);
  // Velocity and attitude: the same executor arithmetic in IEEE double; what differs is the
  // representation (steps merged when their rates agree to 1e-12 over <= 1e5 s: <= 1e-7, and the
  // quaternion round trip, 1e-15). Tolerance 1e-6 (m/s, rad), the required agreement.
  EXPECT_NEAR(s.last.v_eb_n.x(), r.v_n, 1e-6);
  EXPECT_NEAR(s.last.v_eb_n.y(), r.v_e, 1e-6);
  EXPECT_NEAR(s.last.v_eb_n.z(), r.v_d, 1e-6);
  const EulerAngles e = s.last.euler();
  EXPECT_NEAR(WrapPi(e.yaw_rad - r.yaw), 0.0, 1e-6);
  EXPECT_NEAR(WrapPi(e.pitch_rad - r.pitch), 0.0, 1e-6);
  EXPECT_NEAR(WrapPi(e.roll_rad - r.roll), 0.0, 1e-6);
  // Position: gnss-ins-sim integrates (L, lambda, h) by forward Euler, with the velocity at each
  // step's start, while its velocity (and the IMU data it outputs) changes linearly over the step;
  // driftlab integrates that motion exactly. Per step the forward-Euler sum lags the exact
  // integral by (v_{k+1} - v_k) dt / 2, in total by (v_end - v_start) dt / 2 [NED]; e.g. 0.495 m on
  // motion_def-0to100.csv (0 -> 99 m/s), 0.101 % of its 489.6 m: the required "0.1 % of the
  // distance" is met by gnss-ins-sim's own position only up to this lag. With the lag removed, the
  // remainder (velocity not exactly linear in NED within a turning step: O(omega |dv| dt) per
  // step) is asserted below 1e-5 of the distance, and exact for a vehicle at rest (1e-6 m: the
  // rounding of L ~ 1 rad, 1e-16 x 6.4e6 m).
  const Vector3d error = g.environment().PositionErrorNed(s.last.llh, Llh{r.lat, r.lon, r.h});
  const Vector3d lag = 0.5 * g.dt_s() * (Vector3d(r.v_n, r.v_e, r.v_d) - g.initial_state().v_eb_n);
  std::printf(
      "%s %.0f Hz: final position differs by %.3e m over %.1f m (%.4f %%), %.3e m after "
      "the forward-Euler lag\n",
      file.filename().c_str(), r.rate_hz, error.norm(), r.distance,
      100.0 * error.norm() / std::max(r.distance, 1e-300), (error - lag).norm());
  EXPECT_LE((error - lag).norm(), std::max(1e-5 * r.distance, 1e-6));
  EXPECT_LE(error.norm(), std::max(1e-3 * r.distance + lag.norm(), 1e-6));
}

TEST(TrajectoryGenerator, GnssInsSimDemoFilesMatchItsOwnTrajectory) {
  for (const GnssInsSimReference& r : kGnssInsSimReferences) {
    CheckAgainstGnssInsSim(kTestData / "gnss_ins_sim" / r.file, r);
  }
  if (const char* dir = std::getenv("DRIFTLAB_GNSS_INS_SIM_DIR")) {
    for (const GnssInsSimReference& r : kGnssInsSimKomatsuReferences) {
      CheckAgainstGnssInsSim(std::filesystem::path(dir) / "demo_motion_def_files" / r.file, r);
    }
  }
}

TEST(TrajectoryGenerator, GnssInsSimType1CommandPassesAFirstOrderLowPass) {
  // motion_def-0to100.csv: a 10 m/s^2 command for 10 s from rest. The filtered acceleration of step
  // k (k = 0, 1, ...) is a_k = 10 (1 - 0.9^(k+1)), so after n = 999 recorded steps of dt = 0.01 s
  //   v = dt sum_{k<n} a_k = 0.1 (n - 0.9 (1 - 0.9^n) / 0.1) = 0.1 n - 0.9 (1 - 0.9^n).
  const MotionSpec m = ReadGnssInsSimMotion(kTestData / "gnss_ins_sim" / "motion_def-0to100.csv");
  TrajectoryGenerator g(m, 100.0);
  const Sums s = SumIncrements(g);
  const double n = 999.0;
  // Tolerance: rounding of 999 additions of ~0.1, 1e-16 x 100 x 999 = 1e-11.
  EXPECT_NEAR(s.last.v_eb_n.x(), 0.1 * n - 0.9 * (1.0 - std::pow(0.9, n)), 1e-10);
}

TEST(TrajectoryGenerator, GnssInsSimCommandEndsEarlyOnceConvergedOrAtItsMaximumTime) {
  // Type 5 from rest to 2 m/s forward at <= 1 m/s^2 (flat frame, level): the filtered command
  // saturates the acceleration for about 2 s, then v_b converges geometrically (0.9 per step) to
  // within 1e-4 m/s: the command ends before its 50 s maximum. With a 1 s maximum it is cut at
  // round(1 s x 100 Hz) = 100 steps, at 1 m/s (saturated all along: (v_filt - v) / dt >> 1).
  MotionSpec m = Motion(EarthModel::kFlat, 30.0, Vector3d::Zero(), 0.0);
  GnssInsSimCommand c;
  c.type = 5;
  c.v_b = Vector3d(2.0, 0.0, 0.0);
  c.duration_s = 50.0;
  GnssInsSimCommand hold;
  hold.type = 1;
  hold.duration_s = 1.0;
  m.segments = {c, hold};
  TrajectoryGenerator early(m, 100.0);
  EXPECT_LT(early.duration_s(), 4.0);
  EXPECT_GT(early.duration_s(), 2.0);
  const Sums s = SumIncrements(early);
  EXPECT_NEAR(s.last.v_eb_n.x(), 2.0, 1e-4);  // the convergence threshold
  c.duration_s = 1.0;
  m.segments = {c, hold};
  TrajectoryGenerator cut(m, 100.0);
  // 100 steps, then 100 of the hold minus the last one gnss-ins-sim does not record.
  EXPECT_EQ(cut.num_steps(), 199);
  const Sums t = SumIncrements(cut);
  // The hold's acceleration command is 0: the 1 m/s^2 decays by 0.9 per step, adding
  // dt sum_{k=1..99} 0.9^k = 0.01 x 9 (1 - 0.9^99) m/s to 1 m/s over the 99 recorded steps.
  // Tolerance: rounding of ~200 additions of 0.01 m/s, 200 x 2e-16 = 4e-14; 1e-12.
  EXPECT_NEAR(t.last.v_eb_n.x(), 1.0 + 0.09 * (1.0 - std::pow(0.9, 99.0)), 1e-12);
}

TEST(TrajectoryGenerator, GnssInsSimGpsVisibilityZeroMarksTheTimesOfThoseCommands) {
  // 10 s visible, 5 s + 5 s invisible (merged), 3 s visible, 2 s invisible at the end: windows
  // [10, 20) and [23, 24.99] (the output ends one step before the executor's last).
  MotionSpec m = Motion(EarthModel::kFlat, 30.0, Vector3d::Zero(), 0.0);
  auto hold = [](double duration_s, bool visible) {
    GnssInsSimCommand c;
    c.duration_s = duration_s;
    c.gps_visible = visible;
    return c;
  };
  m.segments = {hold(10, true), hold(5, false), hold(5, false), hold(3, true), hold(2, false)};
  const TrajectoryGenerator g(m, 100.0);
  ASSERT_EQ(g.gps_invisible_s().size(), 2u);
  // Tolerance: k dt with dt = 1 / 100 rounds by 1 ulp of the time, < 1e-12 s.
  EXPECT_NEAR(g.gps_invisible_s()[0].first, 10.0, 1e-12);
  EXPECT_NEAR(g.gps_invisible_s()[0].second, 20.0, 1e-12);
  EXPECT_NEAR(g.gps_invisible_s()[1].first, 23.0, 1e-12);
  EXPECT_NEAR(g.gps_invisible_s()[1].second, 24.99, 1e-12);
  EXPECT_EQ(g.gps_invisible_s()[1].second, g.duration_s());
}

TEST(TrajectoryGenerator, GnssInsSimType1HugeRateIsRefusedNamingTheLimit) {
  MotionSpec m = Motion(EarthModel::kWgs84, 30.0, Vector3d::Zero(), 0.0);
  GnssInsSimCommand c;
  c.type = 1;
  c.euler_ypr = Vector3d(1e300 * kDeg, 0.0, 0.0);
  c.duration_s = 10.0;
  c.source = "m.csv:4";
  m.segments = {c};
  ExpectRejected(m, 100.0, {"m.csv:4 (yaw)", "|yaw rate| <= 5729.57", "deg/s"});
  c.euler_ypr.setZero();
  c.v_b = Vector3d(0.0, 0.0, -1e10);
  m.segments = {c};
  ExpectRejected(m, 100.0, {"m.csv:4 (vz_body): -10000000000", "1000 m/s^2"});
  // Within the acceleration limit but too fast in the end: 500 m/s^2 for 100 s.
  c.v_b = Vector3d(500.0, 0.0, 0.0);
  c.duration_s = 100.0;
  m.segments = {c};
  ExpectRejected(m, 100.0, {"m.csv:4 (vx_body)", "speed <= 10000 m/s"});
}

TEST(TrajectoryGenerator, PeriodicMotionBelowFourSamplesPerPeriodIsRefused) {
  MotionSpec m = Motion(EarthModel::kWgs84, 30.0, Vector3d(5.0, 0.0, 0.0), 0.0);
  ShipMotionSegment ship;
  ship.duration_s = 60.0;
  ship.roll_amplitude_rad = 5.0 * kDeg;
  ship.roll_period_s = 0.001;  // far below the 0.01 s sample interval
  ship.ramp_s = 5.0;
  m.segments = {ship};
  ExpectRejected(m, 100.0,
                 {"motion.segments[0].ship_motion.roll_period_s: 0.001", "roll_period_s >= 0.04 s",
                  "Nyquist"});
  ship.roll_period_s = 0.04;  // 4 samples per period: accepted
  m.segments = {ship};
  EXPECT_NO_THROW(TrajectoryGenerator(m, 100.0));
  ship.roll_amplitude_rad = 0.0;  // the period of a component that is off does not matter
  ship.heave_amplitude_m = 0.5;
  ship.heave_period_s = 8.0;
  ship.roll_period_s = 0.001;
  m.segments = {ship};
  EXPECT_NO_THROW(TrajectoryGenerator(m, 100.0));
  m.segments = {ZigzagSegment{1.0, 0.1, 30.0}};
  ExpectRejected(m, 10.0, {"motion.segments[0].zigzag.period_s: 0.1", "period_s >= 0.4 s"});
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

// ---- Validation
// ----------------------------------------------------------------------------------

TEST(TrajectoryGenerator, BadInputNamesFieldValueAndRange) {
  const MotionSpec base = Motion(EarthModel::kWgs84, 40.0, Vector3d(10.0, 0, 0), 0.0);
  {
    MotionSpec m = base;
    TurnSegment t = Turn(10.0, 90.0, 0.0);
    t.angle_rad.reset();
    t.duration_s = -5.0;
    m.segments = {ConstantVelocitySegment{1.0}, t};
    ExpectRejected(m, 100.0, {"motion.segments[1].turn.duration_s: -5 is not allowed", "100000"});
  }
  {
    MotionSpec m = base;
    m.initial.llh.lat_rad = NAN;
    m.segments = {ConstantVelocitySegment{1.0}};
    ExpectRejected(m, 100.0, {"motion.initial.lat_deg: nan"});
  }
  {
    MotionSpec m = base;
    m.initial.llh.lat_rad = 89.95 * kDeg;
    m.segments = {ConstantVelocitySegment{1.0}};
    ExpectRejected(m, 100.0, {"motion.initial.lat_deg: 89.95", "89.9"});
  }
  {
    MotionSpec m = base;
    m.segments = {StaticSegment{5.0}};
    ExpectRejected(m, 100.0, {"motion.segments[0].static", "speed 10 m/s", "allowed: 0"});
  }
  {
    MotionSpec m = base;
    AccelerateSegment a;
    a.acceleration_m_per_s2 = 1.0;
    a.target_speed_m_per_s = 20.0;
    a.duration_s = 3.0;
    m.segments = {a};
    ExpectRejected(m, 100.0, {"motion.segments[0].accelerate", "exactly one"});
  }
  {
    MotionSpec m = base;
    AccelerateSegment a;
    a.acceleration_m_per_s2 = 2.0;
    a.duration_s = 6.0;
    a.decelerate = true;
    m.segments = {a};
    ExpectRejected(m, 100.0, {"motion.segments[0].accelerate.duration_s: 6", "<= 5 s"});
  }
  {
    MotionSpec m = base;
    m.vehicle.coordinated_turns = true;
    m.segments = {ZigzagSegment{5.0, 10.0, 30.0}};
    ExpectRejected(m, 100.0, {"motion.segments[0].zigzag", "coordinated_turns"});
  }
  {
    MotionSpec m = base;
    m.vehicle.coordinated_turns = true;
    m.segments = {Turn(3.0, 90.0, 0.0)};
    ExpectRejected(m, 100.0, {"motion.segments[0].turn.transition_s: 0", "transition_s > 0"});
  }
  {
    MotionSpec m = base;
    ShipMotionSegment s;
    s.duration_s = 10.0;
    s.roll_amplitude_rad = -1.0 * kDeg;
    m.segments = {s};
    ExpectRejected(m, 100.0, {"motion.segments[0].ship_motion.roll_amplitude_deg: -1"});
  }
  {
    MotionSpec m = base;
    ShipMotionSegment s;
    s.duration_s = 10.0;
    s.roll_amplitude_rad = 1.0 * kDeg;
    s.ramp_s = 6.0;
    m.segments = {s};
    ExpectRejected(m, 100.0, {"motion.segments[0].ship_motion.ramp_s: 6", "<= duration_s / 2"});
  }
  {
    MotionSpec m = base;
    ShipMotionSegment s;
    s.duration_s = 10.0;
    s.roll_amplitude_rad = 1.0 * kDeg;
    s.roll_period_s = 8.0;  // ramp_s = 0 defaults to the longest period: 8 s > 5 s
    m.segments = {s};
    ExpectRejected(m, 100.0, {"ship_motion.ramp_s: 0", "longest period, 8 s"});
  }
  {
    MotionSpec m = base;
    m.segments = {ZigzagSegment{5.0, -10.0, 30.0}};
    ExpectRejected(m, 100.0, {"motion.segments[0].zigzag.period_s: -10"});
  }
  {
    MotionSpec m = base;
    GnssInsSimCommand c;
    c.type = 7;
    c.duration_s = 1.0;
    c.source = "drive.csv:9";
    m.segments = {c};
    ExpectRejected(m, 100.0, {"drive.csv:9 (type): 7", "1, 2, 3, 4 or 5"});
  }
  {
    MotionSpec m = base;
    m.segments = {ConstantVelocitySegment{60000.0}, ConstantVelocitySegment{60000.0}};
    ExpectRejected(m, 100.0, {"motion.segments: 120000", "100000"});
  }
  {
    MotionSpec m = base;
    m.segments.clear();
    ExpectRejected(m, 100.0, {"motion:", "neither segments and a truth profile"});
  }
  {
    MotionSpec m = base;
    TurnSegment t = Turn(10.0, 10.0, 2.0);  // the two ramps alone turn 20 deg
    m.segments = {t};
    ExpectRejected(m, 100.0, {"motion.segments[0].turn.angle_deg: 10", ">= |rate| x transition_s"});
  }
  {
    MotionSpec m = base;
    ClimbSegment c;
    c.climb_rate_m_per_s = 5.0;
    c.height_change_m = -100.0;
    m.segments = {c};
    ExpectRejected(m, 100.0, {"motion.segments[0].climb.height_change_m: -100", "sign"});
  }
  {
    MotionSpec m = base;
    m.initial.v_eb_n = Vector3d::Zero();
    m.vehicle.pitch_follows_flight_path = true;
    ClimbSegment c;
    c.climb_rate_m_per_s = 5.0;
    c.duration_s = 30.0;
    m.segments = {c};
    ExpectRejected(m, 100.0, {"motion.segments[0].climb", "ground speed"});
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
}  // namespace driftlab
