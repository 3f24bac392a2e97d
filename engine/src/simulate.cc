// Single-run simulation loop: ideal IMU data from the trajectory generator, optionally through a
// sensor error model, through mechanization A or B, errors against the truth at every step.
#include "driftlab/simulate.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "driftlab/sensors.h"
#include "driftlab/spec_error.h"

namespace driftlab {

namespace {

void Accumulate(const NavError& e, SimulationSummary* summary) {
  const double horizontal = e.r_ned_m.head<2>().norm();
  summary->max_horizontal_position_m = std::max(summary->max_horizontal_position_m, horizontal);
  summary->max_vertical_position_m =
      std::max(summary->max_vertical_position_m, std::abs(e.r_ned_m.z()));
  summary->max_velocity_m_per_s = std::max(summary->max_velocity_m_per_s, e.v_ned_m_per_s.norm());
  summary->max_abs_euler_rad = summary->max_abs_euler_rad.cwiseMax(e.euler_rad.cwiseAbs());
  summary->final_error = e;
  summary->final_horizontal_position_m = horizontal;
}

}  // namespace

SimulationSummary RunErrorFreeSimulation(
    const SimulationSpec& spec, const std::function<void(const SimulationStep&)>& on_step) {
  return RunSimulation(spec, nullptr, on_step);
}

SimulationSummary RunSimulation(const SimulationSpec& spec, const SensorRun* sensor,
                                const std::function<void(const SimulationStep&)>& on_step) {
  TrajectoryGenerator generator(spec.motion, spec.rate_hz);  // validates motion and rate
  // Two simulators of the same run: one for the increment stream (mechanization A) and one for
  // the point-sample stream (mechanization B); each Apply advances its simulator by one output.
  // Both draw the run's constants (turn-on bias, scale factor, misalignment) from the same
  // streams, so those are identical; the processes are each a valid realisation, sample k using
  // the deviates of index k and the increment over (t_k, t_k+1] those of index k.
  std::optional<ImuErrorSimulator> imu_increments;  // constructors validate the model
  std::optional<ImuErrorSimulator> imu_samples;
  if (sensor != nullptr) {
    imu_increments.emplace(sensor->model, sensor->seed, sensor->run_index, spec.rate_hz);
    imu_samples.emplace(sensor->model, sensor->seed, sensor->run_index, spec.rate_hz);
  }
  const NavEnvironment& env = generator.environment();
  const NavState truth0 = generator.initial_state();
  const double dt_s = generator.dt_s();

  std::optional<NedMechanization> ned;
  std::optional<Seed000Mechanization> seed000;
  NavState nav = truth0;
  if (spec.mechanization == MechanizationKind::kNed) {
    ned.emplace(env, truth0, dt_s, spec.ned);
  } else {
    if (spec.seed000.static_period_s > generator.duration_s()) {
      throw SpecError(
          "navigation.seed000.static_period_s", std::to_string(spec.seed000.static_period_s),
          "at most the motion's duration (" + std::to_string(generator.duration_s()) + " s)");
    }
    seed000.emplace(dt_s, spec.seed000);
  }

  // The sample at t = 0 is the first IMU output (the point-sample stream starts there; the
  // increment stream starts with the interval (0, dt]).
  const ImuIncrement zero_increment;
  ImuSample measured_sample0 = generator.initial_sample();
  if (imu_samples) imu_samples->Apply(generator.initial_sample(), &measured_sample0);
  if (seed000) {
    seed000->Update(measured_sample0);
    nav = seed000->ToNed(env, truth0);
  }

  SimulationSummary summary;
  NavError error = ComputeNavError(env, nav, truth0);
  Accumulate(error, &summary);
  if (on_step) {
    SimulationStep step;
    step.k = 0;
    step.truth = &truth0;
    step.increment = &zero_increment;
    step.sample = &generator.initial_sample();
    step.measured_increment = &zero_increment;
    step.measured_sample = &measured_sample0;
    step.nav = &nav;
    step.error = &error;
    on_step(step);
  }

  TrajectorySample sample;
  ImuIncrement measured_increment;
  ImuSample measured_sample;
  while (generator.Next(&sample)) {
    if (sensor != nullptr) {
      imu_increments->Apply(sample.increment, &measured_increment);
      imu_samples->Apply(sample.sample, &measured_sample);
    } else {
      measured_increment = sample.increment;
      measured_sample = sample.sample;
    }
    if (ned) {
      ned->Update(measured_increment);
      if (spec.ned.vertical == VerticalChannel::kTruthHeight) {
        ned->SetVertical(sample.truth.llh.h_m, sample.truth.v_eb_n.z());
      }
      nav = ned->state();
    } else {
      seed000->Update(measured_sample);
      nav = seed000->ToNed(env, truth0);
    }
    error = ComputeNavError(env, nav, sample.truth);
    Accumulate(error, &summary);
    if (on_step) {
      SimulationStep step;
      step.k = generator.step();
      step.truth = &sample.truth;
      step.increment = &sample.increment;
      step.sample = &sample.sample;
      step.measured_increment = &measured_increment;
      step.measured_sample = &measured_sample;
      step.nav = &nav;
      step.error = &error;
      on_step(step);
    }
  }
  summary.steps = generator.step();
  summary.duration_s = static_cast<double>(summary.steps) * dt_s;
  return summary;
}

}  // namespace driftlab
