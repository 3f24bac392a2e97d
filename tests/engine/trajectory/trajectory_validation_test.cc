// Trajectory generator validation: bad segments and periodic motion sampled below four samples per
// period are refused with a message naming the field, the value and the allowed range.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "driftlab/trajectory.h"
#include "trajectory_test_util.h"

namespace driftlab::trajectory_test {
namespace {

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

}  // namespace
}  // namespace driftlab::trajectory_test
