// Small builders of motion segments shared by the tests.
#pragma once

#include <cmath>

#include "driftlab/trajectory.h"

namespace driftlab::testing {

// Turn at rate_deg_per_s (signed) through angle_deg, with ramps of transition_s.
inline TurnSegment TurnByRate(double rate_deg_per_s, double angle_deg, double transition_s) {
  constexpr double kDegToRad = M_PI / 180.0;
  TurnSegment t;
  t.rate_rad_per_s = rate_deg_per_s * kDegToRad;
  t.angle_rad = angle_deg * kDegToRad;
  t.transition_s = transition_s;
  return t;
}

}  // namespace driftlab::testing
