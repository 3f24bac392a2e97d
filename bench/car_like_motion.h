// The motion of the Monte-Carlo benches (monte_carlo_bench, lockstep_bench,
// lockstep_stages_bench): 600 s, 60 s static, accelerate at 1 m/s^2 to 20 m/s, a 90-degree turn
// at 3 deg/s, cruise; at 45 deg N, 7 deg E, 300 m.
#pragma once

#include <cmath>

#include "driftlab/trajectory.h"

namespace driftlab::bench {

inline MotionSpec CarLike600s() {
  constexpr double kDeg = M_PI / 180.0;
  MotionSpec m;
  m.initial.llh = {45.0 * kDeg, 7.0 * kDeg, 300.0};
  m.segments.push_back(StaticSegment{60.0});
  AccelerateSegment acc;
  acc.acceleration_m_per_s2 = 1.0;
  acc.target_speed_m_per_s = 20.0;
  m.segments.push_back(acc);
  TurnSegment turn;
  turn.rate_rad_per_s = 3.0 * kDeg;
  turn.angle_rad = 90.0 * kDeg;
  turn.transition_s = 2.0;
  m.segments.push_back(turn);
  m.segments.push_back(ConstantVelocitySegment{600.0 - 60.0 - 20.0 - 32.0});
  return m;
}

}  // namespace driftlab::bench
