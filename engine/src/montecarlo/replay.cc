// ReplayMonteCarloRun: run N of a job sample by sample, computed by the Monte Carlo's own run
// functions (montecarlo/runs.cc: the run loop of run_loop.h with the run's initial errors,
// alignment, aiding and filter) with an observer at every sample; the truth and both measured IMU
// streams for the output are streamed beside it from a generator of the same motion.
#include <type_traits>
#include <utility>

#include "driftlab/sensors.h"
#include "driftlab/spec_error.h"
#include "montecarlo/internal.h"
#include "montecarlo/progress.h"
#include "montecarlo/run_loop.h"

namespace driftlab {

using mc_detail::BuildSharedTruth;
using mc_detail::EpochAccumulator;
using mc_detail::Monitor;
using mc_detail::NeesAccumulator;
using mc_detail::PrepareFilterModel;
using mc_detail::Report;
using mc_detail::RunComplementary;
using mc_detail::RunEkf;
using mc_detail::RunNed;
using mc_detail::RunObserver;
using mc_detail::RunSeed000;
using mc_detail::RunSink;
using mc_detail::SharedTruth;
using mc_detail::UseGyrocompass;
using mc_detail::ValidateSpec;

namespace {

// The replay's observer: the streamed truth and IMU data at k, the run's solution and filter, the
// run's recorded error values at the checkpoints, to on_step.
class ReplayObserver : public RunObserver {
 public:
  ReplayObserver(const SharedTruth& s, run_loop::StreamedImu* imu, bool navigate,
                 const std::vector<std::vector<ErrorComponentValues>>* checkpoint_values,
                 const std::function<void(const MonteCarloRunStep&)>& on_step)
      : s_(s),
        imu_(imu),
        navigate_(navigate),
        checkpoint_values_(checkpoint_values),
        on_step_(on_step) {}

  void At(int64_t k, const std::function<NavState(const NavState&)>& solution,
          const InsGnssFilter* filter) override {
    imu_->Advance(k);
    const TrajectorySample& ideal = imu_->ideal();
    MonteCarloRunStep step;
    step.k = k;
    step.truth = &ideal.truth;
    step.increment = &ideal.increment;
    step.sample = &ideal.sample;
    step.measured_increment = &imu_->measured_increment();
    step.measured_sample = &imu_->measured_sample();
    if (navigate_ && k >= s_.start_step) {
      nav_ = solution(ideal.truth);
      step.nav = &nav_;
      step.filter = filter;
    }
    if (next_ < s_.reports.size() && s_.reports[next_].k == k) {
      const Report& r = s_.reports[next_++];
      step.epoch = r.epoch;
      step.checkpoint = r.checkpoint;
      step.report_t_s = static_cast<double>(k) * s_.dt_s;
      if (r.checkpoint >= 0) {
        step.checkpoint_values = &(*checkpoint_values_)[static_cast<size_t>(r.checkpoint)][0];
      }
    }
    on_step_(step);
  }

 private:
  const SharedTruth& s_;
  run_loop::StreamedImu* imu_;
  bool navigate_;
  const std::vector<std::vector<ErrorComponentValues>>* checkpoint_values_;
  const std::function<void(const MonteCarloRunStep&)>& on_step_;
  NavState nav_;
  size_t next_ = 0;
};

}  // namespace

bool ReplayMonteCarloRun(const MonteCarloSpec& spec_in, uint32_t run, bool navigate,
                         const std::function<void(const MonteCarloRunLayout&)>& on_start,
                         const std::function<void(const MonteCarloRunStep&)>& on_step,
                         const std::atomic<bool>* cancel) {
  MonteCarloSpec spec = spec_in;
  spec.first_run = run;
  spec.run_count = 1;
  ValidateSpec(spec);
  if (spec.sensor) ValidateImuErrorModel(*spec.sensor, "sensor");
  // The run's shared truth and filter model, as RunMonteCarloWithAnalysis builds them.
  SharedTruth s = BuildSharedTruth(spec, /*keep_imu=*/true, cancel);
  if (cancel != nullptr && cancel->load(std::memory_order_relaxed)) return false;
  PrepareFilterModel(spec, &s);
  const bool seed000 = spec.simulation.mechanization == MechanizationKind::kSeed000;

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

  // The run's errors at the reports, as the Monte Carlo records them (one slot: this run).
  EpochAccumulator epochs(layout.num_epochs);
  std::vector<std::vector<ErrorComponentValues>> checkpoint_values(
      layout.num_checkpoints, std::vector<ErrorComponentValues>(1));
  RunSink sink;
  sink.epochs = &epochs;
  sink.checkpoint_values = &checkpoint_values;
  NeesAccumulator nees;
  nees.sum.resize(layout.num_epochs);
  nees.count.assign(layout.num_epochs, 0);
  const std::function<void(const MonteCarloProgress&)> no_progress;
  Monitor monitor(no_progress, cancel, 1, seed000 ? s.n + 1 : s.n, mc_detail::Clock::now());

  // Both measured streams of the run for the output: the navigator's own stream (increments, or
  // the point samples of mechanization B and the complementary filter) is the one the run
  // navigates with (the same simulator of the same ideal data), the other made alike.
  TrajectoryGenerator generator(spec.simulation.motion, spec.simulation.rate_hz);
  run_loop::StreamedImu imu(&generator, spec.sensor ? &*spec.sensor : nullptr, spec.seed, run,
                            s.rate_hz);
  ReplayObserver observer(s, &imu, navigate, &checkpoint_values, on_step);
  switch (spec.filter) {
    case NavigationFilterKind::kInsGnssEkf:
      return RunEkf(s, spec, run, sink, &nees, &monitor, &observer);
    case NavigationFilterKind::kComplementary:
      return RunComplementary(s, spec, run, sink, &monitor, &observer);
    case NavigationFilterKind::kNone:
      break;
  }
  if (seed000) return RunSeed000(s, spec, run, sink, &monitor, &observer);
  return RunNed(s, spec, run, UseGyrocompass(spec, s), sink, &monitor, &observer);
}

}  // namespace driftlab
