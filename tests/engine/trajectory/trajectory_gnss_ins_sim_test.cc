// Trajectory generator on gnss-ins-sim motion-definition files: the 90-degree turn, its demo files
// against its own trajectories, the type-1 low-pass, early ends, GPS visibility and refused rates.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "driftlab/io.h"
#include "driftlab/trajectory.h"
#include "trajectory_test_util.h"

namespace driftlab::trajectory_test {
namespace {

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

}  // namespace
}  // namespace driftlab::trajectory_test
