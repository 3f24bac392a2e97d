// ReplayMonteCarloRun: one run of a job sample by sample through the engine's run loop
// (run_loop.h), as RunMonteCarlo computes it.
#include <type_traits>
#include <utility>

#include "driftlab/sensors.h"
#include "driftlab/spec_error.h"
#include "montecarlo/internal.h"
#include "montecarlo/run_loop.h"

namespace driftlab {

using mc_detail::BuildSharedTruth;
using mc_detail::FilterName;
using mc_detail::NedStartState;
using mc_detail::Report;
using mc_detail::SharedTruth;
using mc_detail::UseGyrocompass;
using mc_detail::ValidateSpec;

bool ReplayMonteCarloRun(const MonteCarloSpec& spec_in, uint32_t run, bool navigate,
                         const std::function<void(const MonteCarloRunLayout&)>& on_start,
                         const std::function<void(const MonteCarloRunStep&)>& on_step,
                         const std::atomic<bool>* cancel) {
  MonteCarloSpec spec = spec_in;
  spec.first_run = run;
  spec.run_count = 1;
  ValidateSpec(spec);
  if (spec.sensor) ValidateImuErrorModel(*spec.sensor, "sensor");
  if (navigate && spec.filter != NavigationFilterKind::kNone) {
    throw SpecError("navigation.filter", FilterName(spec.filter),
                    "NONE to replay the run's navigation (the replay reproduces the free-inertial "
                    "mechanization; the IMU data and truth are available with any filter)");
  }
  const SharedTruth s = BuildSharedTruth(spec, /*keep_imu=*/false);
  const bool seed000 = spec.simulation.mechanization == MechanizationKind::kSeed000;
  const bool gyrocompass = UseGyrocompass(spec, s);

  MonteCarloRunLayout layout;
  layout.env = &s.env;
  layout.rate_hz = s.rate_hz;
  layout.dt_s = s.dt_s;
  layout.num_steps = s.n;
  layout.navigation_start_step = s.start_step;
  for (const Report& r : s.reports) {
    if (r.epoch >= 0) ++layout.num_epochs;
    if (r.checkpoint >= 0) ++layout.num_checkpoints;
  }
  if (on_start) on_start(layout);

  // Both measured streams of the run, as RunSimulation makes them: the increments (what
  // mechanization A and RunMonteCarlo's kNed runs use) and the point samples (mechanization B).
  TrajectoryGenerator generator(spec.simulation.motion, spec.simulation.rate_hz);
  run_loop::StreamedImu imu(&generator, spec.sensor ? &*spec.sensor : nullptr, spec.seed, run,
                            s.rate_hz);
  NavState nav;
  size_t next_report = 0;
  auto emit = [&](int64_t k, const auto& navigator) {
    const NavState& truth = imu.ideal().truth;
    MonteCarloRunStep step;
    step.k = k;
    step.truth = &truth;
    step.measured_increment = &imu.measured_increment();
    step.measured_sample = &imu.measured_sample();
    if (navigate && k >= s.start_step) {
      nav = navigator.Solution(truth);
      step.nav = &nav;
    }
    if (next_report < s.reports.size() && s.reports[next_report].k == k) {
      step.epoch = s.reports[next_report].epoch;
      step.checkpoint = s.reports[next_report].checkpoint;
      step.report_t_s = static_cast<double>(k) * s.dt_s;
      ++next_report;
    }
    on_step(step);
  };
  auto stopped = [&](int64_t) {
    return cancel != nullptr && cancel->load(std::memory_order_relaxed);
  };
  auto replay = [&](auto& navigator) {
    using Input = typename std::decay_t<decltype(navigator)>::Input;
    auto measure = [&](int64_t k) -> const Input& {
      imu.Advance(k);
      return imu.measured<Input>();
    };
    return run_loop::RunLoop(s.n, measure, navigator, emit, stopped);
  };
  if (!navigate) {
    run_loop::NoNavigator none;
    return replay(none);
  }
  if (seed000) {
    run_loop::Seed000Navigator mech(s.env, s.truth0, s.dt_s, spec.simulation.seed000);
    return replay(mech);
  }
  run_loop::NedNavigator ned(
      s.env, s.dt_s, spec.simulation.ned, s.start_step,
      [&](const Eigen::Vector3d& sum_dtheta, const Eigen::Vector3d& sum_dv) {
        return NedStartState(s, spec, run, gyrocompass, sum_dtheta, sum_dv);
      },
      [&](int64_t) {
        const NavState& truth = imu.ideal().truth;
        return std::pair<double, double>(truth.llh.h_m, truth.v_eb_n.z());
      });
  return replay(ned);
}

}  // namespace driftlab
