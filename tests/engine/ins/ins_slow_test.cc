// Closure of mechanization A on hour-long example motions: error-free increments from the
// trajectory generator must reproduce the truth to within the mechanization's own truncation
// error (DESIGN.md, "Trajectory generator").
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "driftlab/simulate.h"
#include "driftlab/trajectory.h"
#include "support/motion_builders.h"

namespace driftlab {
namespace {

// Final-epoch closure bounds for the hour-long runs (brief). Why they are reachable:
//  - a tilt error psi makes a Schuler position error up to R psi (6.4e6 m x psi): 0.05 m needs the
//    accumulated tilt below ~8e-9 rad;
//  - the two-sample coning/sculling algorithms are exact for rates and specific force linear in
//    time, with second-order rotation terms included; the remaining local errors are O(dt^4) per
//    step (e.g. coning: |omega| |omega''| dt^4 / 720 ~ 1e-14 rad per step at 100 Hz for the
//    ship), i.e. < 4e-9 rad over 360,000 steps even if all add up;
//  - midpoint gravity/Coriolis and trapezoidal position: O(dt^3) local errors that sum to
//    dt^2/12 x (change of the derivative) ~ 1e-5 of the quantity's variation;
//  - the vertical channel is aided (kTruthHeight), so the unstable vertical loop is removed;
//  - except at discontinuities of the angular rate, where the two-sample algorithms make a one-off
//    O(dt^2) error (see the aircraft test, the only profile with rate steps large enough to
//    matter).
constexpr double kMaxHorizontal_m = 0.05;
constexpr double kMaxVelocity_m_per_s = 1e-4;
constexpr double kMaxAttitude_rad = 1e-6;

struct ClosureResult {
  SimulationSummary summary;
  double final_velocity_m_per_s = 0.0;
  double final_attitude_rad = 0.0;
};

ClosureResult RunClosure(const MotionSpec& motion, const std::string& name,
                         double rate_hz = 100.0) {
  SimulationSpec spec;
  spec.motion = motion;
  spec.rate_hz = rate_hz;
  spec.mechanization = MechanizationKind::kNed;
  spec.ned.vertical = VerticalChannel::kTruthHeight;
  spec.ned.coning_sculling = true;
  ClosureResult r;
  r.summary = RunErrorFreeSimulation(spec, nullptr);
  r.final_velocity_m_per_s = r.summary.final_error.v_ned_m_per_s.norm();
  r.final_attitude_rad = r.summary.final_error.psi_nb_n_rad.norm();
  std::printf("%-14s %7.0f s  final horiz %.3e m  vel %.3e m/s  att %.3e rad  max horiz %.3e m\n",
              name.c_str(), r.summary.duration_s, r.summary.final_horizontal_position_m,
              r.final_velocity_m_per_s, r.final_attitude_rad, r.summary.max_horizontal_position_m);
  ::testing::Test::RecordProperty(name + "_final_horizontal_m",
                                  std::to_string(r.summary.final_horizontal_position_m));
  ::testing::Test::RecordProperty(name + "_final_velocity_m_per_s",
                                  std::to_string(r.final_velocity_m_per_s));
  ::testing::Test::RecordProperty(name + "_final_attitude_rad",
                                  std::to_string(r.final_attitude_rad));
  return r;
}

void ExpectClosure(const ClosureResult& r) {
  EXPECT_GE(r.summary.duration_s, 3600.0);
  EXPECT_LE(r.summary.final_horizontal_position_m, kMaxHorizontal_m);
  EXPECT_LE(r.final_velocity_m_per_s, kMaxVelocity_m_per_s);
  EXPECT_LE(r.final_attitude_rad, kMaxAttitude_rad);
}

MotionSpec Wgs84Motion(double lat_deg, double lon_deg, double h_m, const Vector3d& v_eb_n,
                       double yaw_deg) {
  MotionSpec m;
  m.earth_model = EarthModel::kWgs84;
  m.initial.llh = {lat_deg * kDeg, lon_deg * kDeg, h_m};
  m.initial.v_eb_n = v_eb_n;
  m.initial.attitude.yaw_rad = yaw_deg * kDeg;
  return m;
}

AccelerateSegment AccelerateTo(double speed_m_per_s, double accel_m_per_s2) {
  AccelerateSegment a;
  a.acceleration_m_per_s2 = accel_m_per_s2;
  a.target_speed_m_per_s = speed_m_per_s;
  return a;
}

TurnSegment TurnByRadius(double radius_m, bool right, double angle_deg, double transition_s) {
  TurnSegment t;
  t.radius_m = radius_m;
  t.right = right;
  t.angle_rad = angle_deg * kDeg;
  t.transition_s = transition_s;
  return t;
}

using testing::TurnByRate;

TEST(InsClosureSlowTest, CarDriveWithTurnsAndStopsClosesAfterAnHour) {
  // examples/car_drive.json (town drive, ~9.5 min) repeated seven times.
  MotionSpec m = Wgs84Motion(48.1374, 11.5755, 520.0, Vector3d::Zero(), 90.0);
  for (int lap = 0; lap < 7; ++lap) {
    m.segments.push_back(StaticSegment{30.0});
    m.segments.push_back(AccelerateTo(14.0, 2.0));
    m.segments.push_back(ConstantVelocitySegment{60.0});
    m.segments.push_back(AccelerateTo(6.0, 2.5));
    m.segments.push_back(TurnByRadius(15.0, true, 90.0, 2.0));
    m.segments.push_back(AccelerateTo(14.0, 1.5));
    m.segments.push_back(ConstantVelocitySegment{90.0});
    m.segments.push_back(AccelerateTo(0.0, 2.5));
    m.segments.push_back(StaticSegment{25.0});
    m.segments.push_back(AccelerateTo(8.0, 2.0));
    m.segments.push_back(TurnByRate(-15.0, 90.0, 2.0));
    m.segments.push_back(AccelerateTo(16.0, 1.5));
    m.segments.push_back(ConstantVelocitySegment{120.0});
    m.segments.push_back(AccelerateTo(6.0, 2.5));
    m.segments.push_back(TurnByRadius(12.0, false, 90.0, 2.0));
    m.segments.push_back(ConstantVelocitySegment{40.0});
    m.segments.push_back(TurnByRadius(12.0, true, 90.0, 2.0));
    m.segments.push_back(AccelerateTo(12.0, 1.5));
    m.segments.push_back(ConstantVelocitySegment{90.0});
    m.segments.push_back(AccelerateTo(0.0, 2.0));
    m.segments.push_back(StaticSegment{30.0});
  }
  ExpectClosure(RunClosure(m, "car_drive"));
}

MotionSpec AircraftProfile() {
  // examples/aircraft_climb_turns.yaml: 80 m/s, climbs and descents, banked turns; six laps.
  MotionSpec m = Wgs84Motion(52.3667, 4.8945, 1000.0, Vector3d(80.0, 0.0, 0.0), 0.0);
  m.vehicle.coordinated_turns = true;
  m.vehicle.pitch_follows_flight_path = true;
  for (int lap = 0; lap < 6; ++lap) {
    m.segments.push_back(ConstantVelocitySegment{60.0});
    ClimbSegment climb;
    climb.climb_rate_m_per_s = 5.0;
    climb.vertical_acceleration_m_per_s2 = 0.5;
    climb.height_change_m = 600.0;
    m.segments.push_back(climb);
    m.segments.push_back(ConstantVelocitySegment{30.0});
    m.segments.push_back(TurnByRate(3.0, 180.0, 5.0));
    m.segments.push_back(ConstantVelocitySegment{60.0});
    m.segments.push_back(TurnByRate(-3.0, 90.0, 5.0));
    ClimbSegment descent;
    descent.climb_rate_m_per_s = -5.0;
    descent.vertical_acceleration_m_per_s2 = 0.5;
    descent.height_change_m = -600.0;
    m.segments.push_back(descent);
    m.segments.push_back(TurnByRate(3.0, 90.0, 5.0));
    m.segments.push_back(ConstantVelocitySegment{60.0});
  }
  return m;
}

TEST(InsClosureSlowTest, AircraftClimbWithCoordinatedTurnsClosesWithinItsKinkBound) {
  // The generator ramps the turn rate linearly over transition_s, so the bank angle
  // phi = atan(V psi_dot / g) starts and stops changing abruptly: the roll rate jumps by
  //   Delta = (V psi_ddot / g) / (1 + (V psi_dot / g)^2) = 0.072 rad/s   (V 80 m/s, 3 deg/s, 5 s)
  // at each end of each transition. The two-sample algorithms assume rates linear over two
  // intervals; across a rate step at a sample instant the coning term (1/12) dtheta_prev x dtheta
  // and the sculling terms are off by a one-off
  //   tilt  psi_j <= dt^2 |omega x Delta| / 12 <= dt^2 (psi_dot + Omega) Delta / 12 = 3.2e-8 rad,
  //   dv_j       <= dt^2 |f| Delta / 12 = 6.4e-6 m/s            (|f| = g / cos phi),
  // which the Schuler loop turns into at most 2 R psi_j of position, sqrt(g R) psi_j * 2 of
  // velocity and 2 psi_j of attitude, and dv_j / omega_s of position. With 2 tilt steps and
  // 4 velocity steps per turn, 18 turns: bound ~15 m, 0.018 m/s, 1.2e-6 rad at 100 Hz. So the
  // brief's 0.05 m cannot be promised at 100 Hz on this profile (measured ~0.47 m). Two sharper
  // checks: the error must scale as dt^2 (100 Hz / 200 Hz = 4 within 5 %: the kink errors are
  // exactly O(dt^2), the Schuler response linear), and at 400 Hz (kink tilt 2e-9 rad) the brief's
  // bounds must hold.
  const MotionSpec m = AircraftProfile();
  const double g = 9.81, V = 80.0, rate = 3.0 * kDeg, transition = 5.0;
  const double x = V * rate / g;
  const double roll_step = (V * rate / transition / g) / (1.0 + x * x);
  const double f_mag = g * std::sqrt(1.0 + x * x);
  const double omega_s = std::sqrt(g / 6.371e6), R = 6.4e6;
  const int turns = 18;
  const auto kink_bounds = [&](double dt) {
    const double psi_j = dt * dt * (rate + kWgs84EarthRate_rad_per_s) * roll_step / 12.0;
    const double dv_j = dt * dt * f_mag * roll_step / 12.0;
    struct {
      double r, v, att;
    } b{turns * (2 * 2 * R * psi_j + 4 * dv_j / omega_s),
        turns * (2 * 2 * std::sqrt(g * R) * psi_j + 4 * dv_j), turns * 2 * 2 * psi_j};
    return b;
  };
  const ClosureResult r100 = RunClosure(m, "aircraft", 100.0);
  const auto b100 = kink_bounds(0.01);
  std::printf("aircraft kink bound at 100 Hz: %.3e m, %.3e m/s, %.3e rad\n", b100.r, b100.v,
              b100.att);
  EXPECT_GE(r100.summary.duration_s, 3600.0);
  EXPECT_LE(r100.summary.final_horizontal_position_m, b100.r);
  EXPECT_LE(r100.final_velocity_m_per_s, b100.v);
  EXPECT_LE(r100.final_attitude_rad, b100.att);
  const ClosureResult r200 = RunClosure(m, "aircraft_200hz", 200.0);
  const double ratio =
      r100.summary.max_horizontal_position_m / r200.summary.max_horizontal_position_m;
  EXPECT_NEAR(ratio, 4.0, 0.2);
  ExpectClosure(RunClosure(m, "aircraft_400hz", 400.0));
}

ShipMotionSegment Seaway(double duration_s) {
  // Seed 000-like seaway: roll 8 deg / 8 s, pitch 3 deg / 6 s, yaw 1 deg / 10 s, heave 0.5 m / 7 s.
  ShipMotionSegment s;
  s.duration_s = duration_s;
  s.roll_amplitude_rad = 8.0 * kDeg;
  s.roll_period_s = 8.0;
  s.pitch_amplitude_rad = 3.0 * kDeg;
  s.pitch_period_s = 6.0;
  s.pitch_phase_rad = 0.5 * M_PI;
  s.yaw_amplitude_rad = 1.0 * kDeg;
  s.yaw_period_s = 10.0;
  s.yaw_phase_rad = 0.25 * M_PI;
  s.heave_amplitude_m = 0.5;
  s.heave_period_s = 7.0;
  s.ramp_s = 20.0;
  return s;
}

TEST(InsClosureSlowTest, ShipInASeawayClosesAfterAnHour) {
  // Slow ship (3 m/s north-east) rolling, pitching and heaving for an hour.
  MotionSpec m = Wgs84Motion(43.36, -8.41, 0.0, Vector3d(2.1, 2.1, 0.0), 45.0);
  m.segments.push_back(ConstantVelocitySegment{30.0});
  m.segments.push_back(Seaway(3600.0));
  m.segments.push_back(ConstantVelocitySegment{30.0});
  ExpectClosure(RunClosure(m, "ship"));
}

TEST(InsClosureSlowTest, Seed002StaticClosesAfterAnHour) {
  MotionSpec m = Wgs84Motion(22.99, -82.47, 100.0, Vector3d::Zero(), 0.0);
  m.segments.push_back(StaticSegment{3600.0});
  ExpectClosure(RunClosure(m, "static"));
}

TEST(InsClosureSlowTest, Seed002StraightLineClosesAfterAnHour) {
  MotionSpec m = Wgs84Motion(22.99, -82.47, 100.0, Vector3d(10.0, 0.0, 0.0), 0.0);
  m.segments.push_back(ConstantVelocitySegment{3600.0});
  ExpectClosure(RunClosure(m, "straight"));
}

TEST(InsClosureSlowTest, Seed002CircleClosesAfterAnHour) {
  // examples/seed002_circle.json: 5 m/s, 36 deg/s (10 s per circle), 360 circles.
  MotionSpec m = Wgs84Motion(22.99, -82.47, 100.0, Vector3d(5.0, 0.0, 0.0), 0.0);
  m.segments.push_back(ConstantVelocitySegment{10.0});
  TurnSegment circles = TurnByRate(36.0, 0.0, 1.0);
  circles.angle_rad.reset();
  circles.duration_s = 3600.0;
  m.segments.push_back(circles);
  m.segments.push_back(ConstantVelocitySegment{10.0});
  ExpectClosure(RunClosure(m, "circle"));
}

TEST(InsClosureSlowTest, Seed002ZigzagClosesAfterAnHour) {
  // examples/seed002_zigzag.json: 10 m/s weaving +-20 m with a 60 s period, for an hour.
  MotionSpec m = Wgs84Motion(22.99, -82.47, 100.0, Vector3d(10.0, 0.0, 0.0), 0.0);
  m.segments.push_back(ConstantVelocitySegment{10.0});
  ZigzagSegment z;
  z.amplitude_m = 20.0;
  z.period_s = 60.0;
  z.duration_s = 3600.0;
  m.segments.push_back(z);
  m.segments.push_back(ConstantVelocitySegment{10.0});
  ExpectClosure(RunClosure(m, "zigzag"));
}

}  // namespace
}  // namespace driftlab
