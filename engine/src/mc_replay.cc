// ReplayMonteCarloRun: one run of a job sample by sample, as RunMonteCarlo computes it.
#include <optional>

#include "driftlab/sensors.h"
#include "driftlab/spec_error.h"
#include "mc_internal.h"

namespace driftlab {

using mc_detail::BuildSharedTruth;
using mc_detail::FilterName;
using mc_detail::kPollSamples;
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
  const bool truth_height =
      !seed000 && spec.simulation.ned.vertical == VerticalChannel::kTruthHeight;

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

  // Two simulators of the run, as RunSimulation: increments (what mechanization A and
  // RunMonteCarlo's kNed runs use) and point samples (mechanization B).
  std::optional<ImuErrorSimulator> increment_errors, sample_errors;
  if (spec.sensor) {
    increment_errors.emplace(*spec.sensor, spec.seed, run, s.rate_hz);
    sample_errors.emplace(*spec.sensor, spec.seed, run, s.rate_hz);
  }
  TrajectoryGenerator generator(spec.simulation.motion, spec.simulation.rate_hz);
  const NavState truth0 = generator.initial_state();
  ImuIncrement measured_increment;  // zero at k = 0
  ImuSample measured_sample = generator.initial_sample();
  if (sample_errors) sample_errors->Apply(generator.initial_sample(), &measured_sample);

  std::optional<NedMechanization> ned;
  std::optional<Seed000Mechanization> mech;
  Eigen::Vector3d sum_dtheta = Eigen::Vector3d::Zero(), sum_dv = Eigen::Vector3d::Zero();
  NavState nav;
  size_t next_report = 0;
  auto emit = [&](int64_t k, const NavState& truth) {
    MonteCarloRunStep step;
    step.k = k;
    step.truth = &truth;
    step.measured_increment = &measured_increment;
    step.measured_sample = &measured_sample;
    if (navigate && k >= s.start_step) step.nav = &nav;
    if (next_report < s.reports.size() && s.reports[next_report].k == k) {
      step.epoch = s.reports[next_report].epoch;
      step.checkpoint = s.reports[next_report].checkpoint;
      step.report_t_s = static_cast<double>(k) * s.dt_s;
      ++next_report;
    }
    on_step(step);
  };

  // k = 0: mechanization B takes its first sample; mechanization A starts here unless aligning.
  if (navigate && seed000) {
    mech.emplace(s.dt_s, spec.simulation.seed000);
    mech->Update(measured_sample);
    if (s.start_step == 0) nav = mech->ToNed(s.env, truth0);
  } else if (navigate && s.start_step == 0) {
    ned.emplace(s.env, NedStartState(s, spec, run, gyrocompass, sum_dtheta, sum_dv), s.dt_s,
                spec.simulation.ned);
    nav = ned->state();
  }
  emit(0, truth0);

  TrajectorySample sample;
  while (generator.Next(&sample)) {
    const int64_t k = generator.step();
    if (increment_errors) {
      increment_errors->Apply(sample.increment, &measured_increment);
      sample_errors->Apply(sample.sample, &measured_sample);
    } else {
      measured_increment = sample.increment;
      measured_sample = sample.sample;
    }
    if (navigate && seed000) {
      mech->Update(measured_sample);
      if (k >= s.start_step) nav = mech->ToNed(s.env, truth0);
    } else if (navigate && k <= s.start_step) {
      // Alignment window (k = 1..s0), then the start state at s0 (RunNed).
      sum_dtheta += measured_increment.delta_theta_ib_b;
      sum_dv += measured_increment.delta_v_ib_b;
      if (k == s.start_step) {
        ned.emplace(s.env, NedStartState(s, spec, run, gyrocompass, sum_dtheta, sum_dv), s.dt_s,
                    spec.simulation.ned);
        nav = ned->state();
      }
    } else if (navigate) {
      ned->Update(measured_increment);
      if (truth_height) ned->SetVertical(sample.truth.llh.h_m, sample.truth.v_eb_n.z());
      nav = ned->state();
    }
    emit(k, sample.truth);
    if ((k & (kPollSamples - 1)) == 0 && cancel != nullptr &&
        cancel->load(std::memory_order_relaxed)) {
      return false;
    }
  }
  return true;
}

}  // namespace driftlab
