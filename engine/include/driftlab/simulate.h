// One simulation run: trajectory generator -> (sensor model) -> mechanization -> errors against the
// truth. The loop used by `driftlab simulate` and by the closure tests.
#pragma once

#include <functional>
#include <optional>

#include "driftlab/ins.h"
#include "driftlab/nav_state.h"
#include "driftlab/trajectory.h"

namespace driftlab {

enum class MechanizationKind {
  kNed,      // mechanization A
  kSeed000,  // mechanization B
};

struct SimulationSpec {
  MotionSpec motion;
  double rate_hz = 100.0;
  MechanizationKind mechanization = MechanizationKind::kNed;
  NedMechanizationOptions ned;
  Seed000Options seed000;
};

// Everything known at one output step k (k = 0 is the initial epoch, increment zero).
struct SimulationStep {
  int64_t k = 0;
  const NavState* truth = nullptr;
  const ImuIncrement* increment = nullptr;  // ideal increment over (t_{k-1}, t_k]
  const ImuSample* sample = nullptr;        // ideal point sample at t_k
  const NavState* nav = nullptr;            // INS solution at t_k (NED)
  const NavError* error = nullptr;          // nav - truth
};

struct SimulationSummary {
  int64_t steps = 0;
  double duration_s = 0.0;
  NavError final_error;
  // Maxima over the run of |horizontal position error|, |3-D velocity error| and of the absolute
  // roll, pitch, yaw errors.
  double max_horizontal_position_m = 0.0;
  double max_vertical_position_m = 0.0;
  double max_velocity_m_per_s = 0.0;
  Eigen::Vector3d max_abs_euler_rad = Eigen::Vector3d::Zero();
  double final_horizontal_position_m = 0.0;
};

// Runs the error-free simulation; `on_step` (optional) sees every step in order.
// Throws SpecError for invalid specs.
SimulationSummary RunErrorFreeSimulation(const SimulationSpec& spec,
                                         const std::function<void(const SimulationStep&)>& on_step);

}  // namespace driftlab
