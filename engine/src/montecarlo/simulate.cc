// Single-run simulation. SimulateMonteCarloRun: run N of a job (initial errors, alignment, aiding,
// filter) through ReplayMonteCarloRun, the Monte Carlo's own run with an observer at every sample.
// RunSimulation: ideal IMU data from the trajectory generator, optionally through a sensor error
// model, through mechanization A (from the true initial state) or B, errors against the truth at
// every step; the engine's run loop (run_loop.h) with a report at every sample and no
// cancellation (the mechanizations' closure tests).
#include "driftlab/simulate.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "driftlab/monte_carlo.h"
#include "driftlab/sensors.h"
#include "driftlab/spec_error.h"
#include "montecarlo/run_loop.h"

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

SimulationSummary SimulateMonteCarloRun(
    const MonteCarloSpec& spec, uint32_t run,
    const std::function<void(const SimulationStep&, const InsGnssFilter*)>& on_step) {
  SimulationSummary summary;
  const NavEnvironment* env = nullptr;
  NavError error;
  ReplayMonteCarloRun(
      spec, run, /*navigate=*/true,
      [&](const MonteCarloRunLayout& layout) {
        env = layout.env;
        summary.steps = layout.num_steps;
        summary.duration_s = static_cast<double>(layout.num_steps) * layout.dt_s;
      },
      [&](const MonteCarloRunStep& r) {
        SimulationStep step;
        step.k = r.k;
        step.truth = r.truth;
        step.increment = r.increment;
        step.sample = r.sample;
        step.measured_increment = r.measured_increment;
        step.measured_sample = r.measured_sample;
        if (r.nav != nullptr) {
          error = ComputeNavError(*env, *r.nav, *r.truth);
          Accumulate(error, &summary);
          step.nav = r.nav;
          step.error = &error;
        }
        if (on_step) on_step(step, r.filter);
      });
  return summary;
}

SimulationSummary RunErrorFreeSimulation(
    const SimulationSpec& spec, const std::function<void(const SimulationStep&)>& on_step) {
  return RunSimulation(spec, nullptr, on_step);
}

SimulationSummary RunSimulation(const SimulationSpec& spec, const SensorRun* sensor,
                                const std::function<void(const SimulationStep&)>& on_step) {
  TrajectoryGenerator generator(spec.motion, spec.rate_hz);  // validates motion and rate
  // Both streams of the run (run_loop.h StreamedImu); the simulators' constructors validate the
  // model.
  run_loop::StreamedImu imu(&generator, sensor != nullptr ? &sensor->model : nullptr,
                            sensor != nullptr ? sensor->seed : 0,
                            sensor != nullptr ? sensor->run_index : 0, spec.rate_hz);
  const NavEnvironment& env = generator.environment();
  const NavState truth0 = generator.initial_state();
  const double dt_s = generator.dt_s();

  SimulationSummary summary;
  NavState nav;
  NavError error;
  // Errors at every sample k = 0..n, the navigation solution of mechanization B also before its
  // static period has ended.
  auto report = [&](int64_t k, const auto& navigator) {
    const TrajectorySample& ideal = imu.ideal();
    nav = navigator.Solution(ideal.truth);
    error = ComputeNavError(env, nav, ideal.truth);
    Accumulate(error, &summary);
    if (!on_step) return;
    SimulationStep step;
    step.k = k;
    step.truth = &ideal.truth;
    step.increment = &ideal.increment;
    step.sample = &ideal.sample;
    step.measured_increment = &imu.measured_increment();
    step.measured_sample = &imu.measured_sample();
    step.nav = &nav;
    step.error = &error;
    on_step(step);
  };
  auto simulate = [&](auto& navigator) {
    using Input = typename std::decay_t<decltype(navigator)>::Input;
    auto measure = [&](int64_t k) -> const Input& {
      imu.Advance(k);
      return imu.measured<Input>();
    };
    run_loop::RunLoop(generator.num_steps(), measure, navigator, report,
                      [](int64_t) { return false; });
  };
  if (spec.mechanization == MechanizationKind::kNed) {
    // Navigation from the true initial state at k = 0 (no alignment window).
    run_loop::NedNavigator ned(
        env, dt_s, spec.ned, /*start_step=*/0,
        [&](const Eigen::Vector3d&, const Eigen::Vector3d&) { return truth0; },
        [&](int64_t) {
          const NavState& truth = imu.ideal().truth;
          return std::pair<double, double>(truth.llh.h_m, truth.v_eb_n.z());
        });
    simulate(ned);
  } else {
    if (spec.seed000.static_period_s > generator.duration_s()) {
      throw SpecError(
          "navigation.seed000.static_period_s", std::to_string(spec.seed000.static_period_s),
          "at most the motion's duration (" + std::to_string(generator.duration_s()) + " s)");
    }
    run_loop::Seed000Navigator seed000(env, truth0, dt_s, spec.seed000);
    simulate(seed000);
  }
  summary.steps = generator.step();
  summary.duration_s = static_cast<double>(summary.steps) * dt_s;
  return summary;
}

}  // namespace driftlab
