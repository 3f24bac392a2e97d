// The engine's one run loop: for every IMU sample k = 0..n of a run, the measured data (the ideal
// data through the run's sensor errors) -> the navigator's step -> the report at k -> the
// navigator's corrections at k (aiding updates) -> the cancellation poll. RunMonteCarlo's scalar
// runs (montecarlo/runs.cc), ReplayMonteCarloRun (montecarlo/replay.cc) and RunSimulation
// (simulate.cc) all run through RunLoop; the lockstep runs (montecarlo/lockstep_runs.cc) do the
// same for W runs at once and are tested bit for bit against the scalar runs.
//
// A navigator is a small adapter type with
//   using Input = ImuIncrement or ImuSample;        the data its step consumes
//   void Step(int64_t k, const Input& measured);     k = 0..n (an increment is zero at k = 0)
//   void Correct(int64_t k, const Input& measured);  after the report at k
//   NavState Solution(const NavState& truth_k) const;  its navigation solution at k (valid from
//                                                    its navigation start on)
// The navigators of the free-inertial mechanizations are here; the filters' are in
// montecarlo/runs.cc.
#pragma once

#include <cstdint>
#include <optional>
#include <type_traits>
#include <utility>
#include <vector>

#include "driftlab/ins.h"
#include "driftlab/nav_state.h"
#include "driftlab/sensors.h"
#include "driftlab/trajectory.h"

namespace driftlab::run_loop {

// Cancellation (and progress) are polled at the samples k > 0 with k % kPollSamples == 0.
constexpr int64_t kPollSamples = 1024;

// Runs samples k = 0..n: measure(k) -> navigator.Step -> report(k, navigator) -> navigator.Correct
// -> poll(k) at the poll samples. `measure(k)` is called once per k in ascending order and returns
// the measured Navigator::Input at k; `poll(k)` returns true to stop. Returns false if stopped.
template <class Navigator, class Measure, class ReportAt, class Poll>
bool RunLoop(int64_t n, Measure&& measure, Navigator& navigator, ReportAt&& report, Poll&& poll) {
  for (int64_t k = 0; k <= n; ++k) {
    const typename Navigator::Input& measured = measure(k);
    navigator.Step(k, measured);
    report(k, navigator);
    navigator.Correct(k, measured);
    if (k > 0 && (k & (kPollSamples - 1)) == 0 && poll(k)) return false;
  }
  return true;
}

// The ideal IMU data of a stored trajectory (RunMonteCarlo's shared truth) through a run's sensor
// errors. Increments: ideal[k] covers (t_{k-1}, t_k], the increment at k = 0 is zero and draws no
// errors; point samples: ideal[k] at t_k, k = 0..n.
template <class Input>
class StoredImu {
 public:
  StoredImu(const std::vector<Input>& ideal, const ImuErrorModel* model, uint64_t seed,
            uint32_t run, double rate_hz)
      : ideal_(ideal) {
    if (model != nullptr) errors_.emplace(*model, seed, run, rate_hz);
  }
  const Input& operator()(int64_t k) {
    if constexpr (std::is_same_v<Input, ImuIncrement>) {
      if (k == 0) return zero_;
    }
    const Input& ideal = ideal_[static_cast<size_t>(k)];
    if (!errors_) return ideal;
    errors_->Apply(ideal, &measured_);
    return measured_;
  }

 private:
  const std::vector<Input>& ideal_;
  std::optional<ImuErrorSimulator> errors_;
  Input measured_;
  const ImuIncrement zero_;
};

// The ideal IMU data streamed from a trajectory generator (replay, simulate), both streams through
// the run's sensor errors: one simulator for the increments (mechanization A) and one for the
// point samples (mechanization B). Both draw the run's constants (turn-on bias, scale factor,
// misalignment) from the same streams, so those are identical; the processes are each a valid
// realisation, sample k using the deviates of index k and the increment over (t_{k-1}, t_k] those
// of index k. At k = 0: the initial truth and point sample, a zero increment (no errors drawn).
class StreamedImu {
 public:
  StreamedImu(TrajectoryGenerator* generator, const ImuErrorModel* model, uint64_t seed,
              uint32_t run, double rate_hz)
      : generator_(generator) {
    if (model != nullptr) {
      increment_errors_.emplace(*model, seed, run, rate_hz);
      sample_errors_.emplace(*model, seed, run, rate_hz);
    }
    ideal_.truth = generator_->initial_state();
    ideal_.sample = generator_->initial_sample();
    measured_sample_ = ideal_.sample;
  }
  // Moves to sample k (k = 0 first, then k + 1 each call); false past the trajectory's end.
  bool Advance(int64_t k) {
    if (k == 0) {
      if (sample_errors_) sample_errors_->Apply(ideal_.sample, &measured_sample_);
      return true;
    }
    if (!generator_->Next(&ideal_)) return false;
    if (increment_errors_) {
      increment_errors_->Apply(ideal_.increment, &measured_increment_);
      sample_errors_->Apply(ideal_.sample, &measured_sample_);
    } else {
      measured_increment_ = ideal_.increment;
      measured_sample_ = ideal_.sample;
    }
    return true;
  }
  const TrajectorySample& ideal() const { return ideal_; }
  const ImuIncrement& measured_increment() const { return measured_increment_; }
  const ImuSample& measured_sample() const { return measured_sample_; }
  template <class Input>
  const Input& measured() const {
    if constexpr (std::is_same_v<Input, ImuIncrement>) {
      return measured_increment_;
    } else {
      return measured_sample_;
    }
  }

 private:
  TrajectoryGenerator* generator_;
  std::optional<ImuErrorSimulator> increment_errors_, sample_errors_;
  TrajectorySample ideal_;  // increment zero at k = 0
  ImuIncrement measured_increment_;
  ImuSample measured_sample_;
};

// Mechanization A (ins.h NedMechanization). Samples k = 1..s0 are the static-alignment window: the
// measured increments are summed and the navigation starts at s0 from
// start_state(sum_dtheta, sum_dv); then one step a sample. With the truth-height vertical channel
// the height and vertical velocity are set to truth_vertical(k) = {h_m, v_D_m_per_s} after the
// step.
template <class StartState, class TruthVertical>
class NedNavigator {
 public:
  using Input = ImuIncrement;
  NedNavigator(const NavEnvironment& env, double dt_s, const NedMechanizationOptions& options,
               int64_t start_step, StartState start_state, TruthVertical truth_vertical)
      : env_(env),
        dt_s_(dt_s),
        options_(options),
        start_step_(start_step),
        start_state_(std::move(start_state)),
        truth_vertical_(std::move(truth_vertical)) {}

  void Step(int64_t k, const ImuIncrement& measured) {
    if (k <= start_step_) {
      if (k > 0) {
        sum_dtheta_ += measured.delta_theta_ib_b;
        sum_dv_ += measured.delta_v_ib_b;
      }
      if (k == start_step_) ned_.emplace(env_, start_state_(sum_dtheta_, sum_dv_), dt_s_, options_);
      return;
    }
    ned_->Update(measured);
    if (options_.vertical == VerticalChannel::kTruthHeight) {
      const std::pair<double, double> h_v = truth_vertical_(k);
      ned_->SetVertical(h_v.first, h_v.second);
    }
  }
  void Correct(int64_t, const ImuIncrement&) {}
  const NavState& Solution(const NavState&) const { return ned_->state(); }

 private:
  const NavEnvironment& env_;
  double dt_s_;
  NedMechanizationOptions options_;
  int64_t start_step_;
  StartState start_state_;
  TruthVertical truth_vertical_;
  Eigen::Vector3d sum_dtheta_ = Eigen::Vector3d::Zero(), sum_dv_ = Eigen::Vector3d::Zero();
  std::optional<NedMechanization> ned_;
};

// Mechanization B (ins.h Seed000Mechanization): every point sample from k = 0; it initialises
// itself over its static period. The solution in NED relative to the truth at t = 0.
class Seed000Navigator {
 public:
  using Input = ImuSample;
  Seed000Navigator(const NavEnvironment& env, const NavState& truth0, double dt_s,
                   const Seed000Options& options)
      : env_(env), truth0_(truth0), mech_(dt_s, options) {}
  void Step(int64_t, const ImuSample& measured) { mech_.Update(measured); }
  void Correct(int64_t, const ImuSample&) {}
  NavState Solution(const NavState&) const { return mech_.ToNed(env_, truth0_); }

 private:
  const NavEnvironment& env_;
  NavState truth0_;
  Seed000Mechanization mech_;
};

// No navigation (a replay of the IMU data and truth only).
struct NoNavigator {
  using Input = ImuIncrement;
  void Step(int64_t, const ImuIncrement&) {}
  void Correct(int64_t, const ImuIncrement&) {}
  NavState Solution(const NavState& truth) const { return truth; }
};

}  // namespace driftlab::run_loop
