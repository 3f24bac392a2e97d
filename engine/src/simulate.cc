// Error-free simulation loop: ideal IMU data from the trajectory generator through mechanization A
// or B, errors against the truth at every output step.
#include "driftlab/simulate.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

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
  TrajectoryGenerator generator(spec.motion, spec.rate_hz);  // validates motion and rate
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
    seed000->Update(generator.initial_sample());
    nav = seed000->ToNed(env, truth0);
  }

  SimulationSummary summary;
  const ImuIncrement zero_increment;
  NavError error = ComputeNavError(env, nav, truth0);
  Accumulate(error, &summary);
  if (on_step) {
    SimulationStep step;
    step.k = 0;
    step.truth = &truth0;
    step.increment = &zero_increment;
    step.sample = &generator.initial_sample();
    step.nav = &nav;
    step.error = &error;
    on_step(step);
  }

  TrajectorySample sample;
  while (generator.Next(&sample)) {
    if (ned) {
      ned->Update(sample.increment);
      if (spec.ned.vertical == VerticalChannel::kTruthHeight) {
        ned->SetVertical(sample.truth.llh.h_m, sample.truth.v_eb_n.z());
      }
      nav = ned->state();
    } else {
      seed000->Update(sample.sample);
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
