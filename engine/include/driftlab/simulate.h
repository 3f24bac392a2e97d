// One simulation run: trajectory generator -> (sensor model) -> mechanization -> errors against the
// truth. The loop used by `driftlab simulate` and by the closure tests.
#pragma once

#include <functional>
#include <optional>

#include "driftlab/ins.h"
#include "driftlab/nav_state.h"
#include "driftlab/sensor_params.h"
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

// One seeded run of a sensor error model (sensors.h): the run's errors are a pure function of
// (model, seed, run_index, rate).
struct SensorRun {
  ImuErrorModel model;
  uint64_t seed = 1;
  uint32_t run_index = 0;
};

// Everything known at one output step k (k = 0 is the initial epoch, increment zero).
struct SimulationStep {
  int64_t k = 0;
  const NavState* truth = nullptr;
  const ImuIncrement* increment = nullptr;  // ideal increment over (t_{k-1}, t_k]
  const ImuSample* sample = nullptr;        // ideal point sample at t_k
  // What the IMU outputs (= the ideal data without a sensor model); the mechanization uses these.
  const ImuIncrement* measured_increment = nullptr;
  const ImuSample* measured_sample = nullptr;
  const NavState* nav = nullptr;    // INS solution at t_k (NED)
  const NavError* error = nullptr;  // nav - truth
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

// Runs one simulation: ideal IMU data, through `sensor`'s error model when given (else used as
// they are), through the mechanization, with errors against the truth at every step. The
// navigation starts from the true initial state (mechanization A) or from its own static-period
// alignment (mechanization B). `on_step` (optional) sees every step in order.
// Throws SpecError for invalid specs (including the sensor model).
SimulationSummary RunSimulation(const SimulationSpec& spec, const SensorRun* sensor,
                                const std::function<void(const SimulationStep&)>& on_step);

// RunSimulation without a sensor model.
SimulationSummary RunErrorFreeSimulation(const SimulationSpec& spec,
                                         const std::function<void(const SimulationStep&)>& on_step);

}  // namespace driftlab
