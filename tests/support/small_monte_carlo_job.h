// The small Monte-Carlo job of the engine tests: 20 s static, 10 s accelerating at 1 m/s^2
// northward, 30 s at constant velocity, at 20 Hz; the tactical preset, 16 runs, seed 42, initial
// errors, epochs every second, a checkpoint at 30 s.
#pragma once

#include <cmath>

#include "driftlab/monte_carlo.h"
#include "driftlab/presets.h"

namespace driftlab::testing {

inline MonteCarloSpec SmallMonteCarloJob() {
  constexpr double kDeg = M_PI / 180.0;
  MonteCarloSpec spec;
  spec.simulation.motion.initial.llh = {45.0 * kDeg, 7.0 * kDeg, 300.0};
  spec.simulation.motion.segments.push_back(StaticSegment{20.0});
  AccelerateSegment acc;
  acc.acceleration_m_per_s2 = 1.0;
  acc.duration_s = 10.0;
  spec.simulation.motion.segments.push_back(acc);
  spec.simulation.motion.segments.push_back(ConstantVelocitySegment{30.0});
  spec.simulation.rate_hz = 20.0;
  spec.sensor = FindImuPreset("tactical");
  spec.runs = 16;
  spec.seed = 42;
  spec.initial_errors.position_ned_m = Eigen::Vector3d(1.0, 2.0, 3.0);
  spec.initial_errors.velocity_ned_m_per_s = Eigen::Vector3d(0.01, 0.02, 0.03);
  spec.initial_errors.attitude_rad = Eigen::Vector3d(1e-3, 2e-3, 3e-3);
  spec.epoch_every_samples = 20;
  spec.checkpoint_times_s = {30.0};
  return spec;
}

}  // namespace driftlab::testing
