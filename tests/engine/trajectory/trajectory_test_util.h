// Shared by the trajectory generator tests (trajectory_test.cc, trajectory_gnss_ins_sim_test.cc,
// trajectory_validation_test.cc): a motion at a given place and attitude, turns by rate, the summed
// increments of a generator, and the check that a motion is refused with a given message.
#pragma once

#include <gtest/gtest.h>

#include <initializer_list>
#include <string>

#include "driftlab/spec_error.h"
#include "driftlab/trajectory.h"
#include "support/motion_builders.h"

namespace driftlab::trajectory_test {

inline MotionSpec Motion(EarthModel model, double lat_deg, const Vector3d& v_eb_n, double yaw_deg,
                         double pitch_deg = 0.0, double roll_deg = 0.0) {
  MotionSpec m;
  m.earth_model = model;
  m.initial.llh = {lat_deg * kDeg, 10.0 * kDeg, 100.0};
  m.initial.v_eb_n = v_eb_n;
  m.initial.attitude = {roll_deg * kDeg, pitch_deg * kDeg, yaw_deg * kDeg};
  return m;
}

inline TurnSegment Turn(double rate_deg_per_s, double angle_deg, double transition_s) {
  return testing::TurnByRate(rate_deg_per_s, angle_deg, transition_s);
}

struct Sums {
  Vector3d delta_theta = Vector3d::Zero();
  Vector3d delta_v = Vector3d::Zero();
  NavState last;
  int64_t steps = 0;
};

inline Sums SumIncrements(TrajectoryGenerator& generator) {
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
inline void ExpectRejected(const MotionSpec& motion, double rate_hz,
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

}  // namespace driftlab::trajectory_test
