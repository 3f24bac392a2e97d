// Monte-Carlo runner: a job from validation to statistics (see monte_carlo.h). The parts live
// beside it, one concern a file (montecarlo/internal.h lists them).
#include "driftlab/monte_carlo.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <exception>
#include <memory>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "driftlab/ins_gnss_filter.h"
#include "driftlab/spec_error.h"
#include "lockstep/lockstep_ned.h"
#include "montecarlo/internal.h"
#include "montecarlo/progress.h"

namespace driftlab {

using mc_detail::Clock;
using mc_detail::EpochAccumulator;
using mc_detail::MergeEpochSums;
using mc_detail::MergeNees;
using mc_detail::Monitor;
using mc_detail::NeesAccumulator;
using mc_detail::PrepareFilterModel;
using mc_detail::PrepareSharedTruth;
using mc_detail::Report;
using mc_detail::RunComplementary;
using mc_detail::RunEkf;
using mc_detail::RunNed;
using mc_detail::RunNedLockstep;
using mc_detail::RunSeed000;
using mc_detail::RunSink;
using mc_detail::Seconds;
using mc_detail::SharedTruth;
using mc_detail::StreamSharedTruth;
using mc_detail::TruthStream;
using mc_detail::UseGyrocompass;

MonteCarloStatistics RunMonteCarlo(const MonteCarloSpec& spec,
                                   const std::function<void(const MonteCarloProgress&)>& progress,
                                   const std::atomic<bool>* cancel) {
  MonteCarloSpec without_analysis = spec;
  without_analysis.covariance = false;
  return std::move(RunMonteCarloWithAnalysis(without_analysis, progress, cancel).statistics);
}

MonteCarloOutput RunMonteCarloWithAnalysis(
    const MonteCarloSpec& spec, const std::function<void(const MonteCarloProgress&)>& progress,
    const std::atomic<bool>* cancel) {
  const Clock::time_point start = Clock::now();
  ValidateMonteCarloSpec(spec);
  const uint32_t run_count = spec.run_count == 0 ? spec.runs - spec.first_run : spec.run_count;

  const bool ekf = spec.filter == NavigationFilterKind::kInsGnssEkf;
  const bool complementary = spec.filter == NavigationFilterKind::kComplementary;
  const bool seed000 = spec.simulation.mechanization == MechanizationKind::kSeed000;
  const int threads = spec.threads > 0 ? spec.threads : tbb::info::default_concurrency();
  // Mechanization A without a filter runs in lockstep groups (DRIFTLAB_ISA=scalar: one run at a
  // time, RunNed, kept as the reference the lockstep path must match bit for bit).
  const bool run_lockstep = !seed000 && !ekf && !complementary && !lockstep::ScalarForced();
  // With two or more threads the lockstep runs start while the truth streams: a thread of its own
  // generates it while the `threads` workers run the groups as far as it has come (the truth is
  // the job's serial part). The same computations, so the same bits.
  const bool overlap_truth = run_lockstep && threads >= 2 && !spec.covariance;

  SharedTruth shared;
  const std::unique_ptr<TrajectoryGenerator> generator = PrepareSharedTruth(spec, true, &shared);
  bool cancelled_early = false;
  double truth_s = 0.0;
  ErrorStateNoiseFromImu noise;
  // The truth's samples, then the error-state model the filter and the analysis assume (no
  // sensor: no process noise, no bias uncertainty).
  auto finish_truth = [&](TruthStream* stream) {
    StreamSharedTruth(spec, true, generator.get(), &shared, cancel, &cancelled_early, stream);
    if (cancelled_early) return;
    noise = PrepareFilterModel(spec, &shared);
    truth_s = Seconds(start);
  };
  auto cancelled_during_truth = [&] {
    MonteCarloOutput output;
    MonteCarloStatisticsData data;
    data.seed = spec.seed;
    data.job_runs = spec.runs;
    data.cancelled = true;
    data.timings.truth_s = Seconds(start);
    data.timings.wall_s = data.timings.truth_s;
    output.statistics = MonteCarloStatistics(std::move(data));
    return output;
  };
  if (!overlap_truth) {
    finish_truth(nullptr);
    if (cancelled_early) return cancelled_during_truth();
  }
  const SharedTruth& truth = shared;
  // Overlapped: decided by each lockstep group once the start state is there.
  const bool gyrocompass = overlap_truth ? false : UseGyrocompass(spec, truth);

  // Output buffers: per-run checkpoint values (each run writes its own slot), per-thread sums.
  size_t n_epochs = 0, n_checkpoints = 0;
  for (const Report& r : truth.reports) {
    if (r.epoch >= 0) ++n_epochs;
    if (r.checkpoint >= 0) ++n_checkpoints;
  }
  if (uint64_t{run_count} * n_checkpoints > uint64_t{kMaxMonteCarloRuns} * 10) {
    throw SpecError("monte_carlo.checkpoint_times_s",
                    std::to_string(n_checkpoints) + " checkpoints",
                    "runs x checkpoints <= " + std::to_string(uint64_t{kMaxMonteCarloRuns} * 10));
  }
  std::vector<std::vector<ErrorComponentValues>> checkpoint_values(
      n_checkpoints, std::vector<ErrorComponentValues>(run_count));
  const EpochAccumulator exemplar(n_epochs);
  tbb::enumerable_thread_specific<EpochAccumulator> accumulators(exemplar);
  NeesAccumulator nees_exemplar;
  if (ekf) {
    nees_exemplar.sum.resize(n_epochs);
    nees_exemplar.count.assign(n_epochs, 0);
  }
  tbb::enumerable_thread_specific<NeesAccumulator> nees_accumulators(nees_exemplar);

  const int64_t samples_per_run = seed000 || complementary ? truth.n + 1 : truth.n;
  Monitor monitor(progress, cancel, run_count, samples_per_run * int64_t{run_count}, start);
  tbb::task_arena arena(threads);
  if (run_lockstep && overlap_truth) {
    // The truth streams on a thread of its own while all of the arena's `threads` slots (this
    // thread and the workers) run the groups from the start, as far as the truth has come.
    TruthStream stream;
    std::exception_ptr truth_error;
    std::thread truth_thread([&] {
      try {
        finish_truth(&stream);
      } catch (...) {
        truth_error = std::current_exception();
      }
      if (truth_error || cancelled_early) stream.Stop();
    });
    std::exception_ptr runs_error;
    try {
      const lockstep::Kernel& kernel = lockstep::SelectKernel();
      arena.execute([&] {
        RunNedLockstep(truth, spec, kernel, gyrocompass, run_count, arena, accumulators,
                       checkpoint_values, &monitor, &stream);
      });
    } catch (...) {
      runs_error = std::current_exception();
    }
    truth_thread.join();
    if (truth_error) std::rethrow_exception(truth_error);
    if (runs_error) std::rethrow_exception(runs_error);
    if (cancelled_early) return cancelled_during_truth();
  } else if (run_lockstep) {
    RunNedLockstep(truth, spec, lockstep::SelectKernel(), gyrocompass, run_count, arena,
                   accumulators, checkpoint_values, &monitor);
  }
  // The other navigators, one run at a time (none left when the runs went in lockstep above).
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, run_lockstep ? 0 : run_count, 1),
                      [&](const tbb::blocked_range<uint32_t>& range) {
                        RunSink sink;
                        sink.epochs = &accumulators.local();
                        sink.checkpoint_values = &checkpoint_values;
                        for (uint32_t slot = range.begin(); slot != range.end(); ++slot) {
                          if (monitor.Stopped()) return;
                          sink.slot = slot;
                          const uint32_t run = spec.first_run + slot;
                          bool done = false;
                          if (seed000) {
                            done = RunSeed000(truth, spec, run, sink, &monitor);
                          } else if (ekf) {
                            done = RunEkf(truth, spec, run, sink, &nees_accumulators.local(),
                                          &monitor);
                          } else if (complementary) {
                            done = RunComplementary(truth, spec, run, sink, &monitor);
                          } else {
                            done = RunNed(truth, spec, run, gyrocompass, sink, &monitor);
                          }
                          if (!done) return;
                        }
                      });
  });

  MonteCarloStatisticsData data;
  data.seed = spec.seed;
  data.job_runs = spec.runs;
  data.timings.truth_s = truth_s;
  data.timings.threads = threads;
  MonteCarloOutput output;
  if (monitor.Stopped()) {
    data.cancelled = true;
    data.timings.samples_processed = monitor.samples_done();
    data.timings.wall_s = Seconds(start);
    output.statistics = MonteCarloStatistics(std::move(data));
    return output;
  }
  monitor.ReportFinal();

  data.runs.push_back(RunRange{spec.first_run, spec.first_run + run_count});
  data.epochs = MergeEpochSums(accumulators, n_epochs);
  size_t c = 0;
  for (const Report& r : truth.reports) {
    if (r.epoch >= 0) data.epoch_times_s.push_back(static_cast<double>(r.k) * truth.dt_s);
    if (r.checkpoint >= 0) {
      CheckpointValues cp;
      cp.t_s = static_cast<double>(r.k) * truth.dt_s;
      cp.run_index.resize(run_count);
      for (uint32_t i = 0; i < run_count; ++i) cp.run_index[i] = spec.first_run + i;
      cp.values = std::move(checkpoint_values[c++]);
      data.checkpoints.push_back(std::move(cp));
    }
  }
  if (ekf) output.consistency = MergeNees(nees_accumulators, n_epochs);
  if (spec.covariance) {
    // The analysis at the epochs' samples, with the runs' aiding schedule.
    std::vector<int64_t> epoch_samples;
    for (const Report& r : truth.reports) {
      if (r.epoch >= 0) epoch_samples.push_back(r.k);
    }
    CovarianceAnalysisResult analysis;
    analysis.filter = spec.filter;
    analysis.step_samples = ekf ? spec.ekf_propagation_step_samples : spec.covariance_step_samples;
    analysis.unrepresented = noise.unrepresented;
    // The EKF's analysis uses its propagation interval and discretisation, so that it predicts
    // that filter; the free INS's uses covariance_step_samples with Van Loan's exact transition.
    analysis.epochs = FilterCovarianceAnalysis(
        spec.simulation.motion, spec.simulation.rate_hz, truth.ekf_noise, truth.ekf_P0,
        ekf ? truth.schedule.get() : nullptr, epoch_samples, analysis.step_samples,
        ekf ? InsGnssFilterOptions().discretization : Discretization::kVanLoan);
    output.covariance = std::move(analysis);
  }
  data.timings.samples_processed = monitor.samples_done();
  data.timings.wall_s = Seconds(start);
  output.statistics = MonteCarloStatistics(std::move(data));
  return output;
}

}  // namespace driftlab
