// Internal declarations shared by the Monte-Carlo runner's files (not a public header):
//   montecarlo/validation.cc   spec validation, the job plan (navigation start, report samples),
//   memory montecarlo/shared_truth.cc the truth generated once per job, the filter's error model
//   montecarlo/progress.h      progress and cancellation (Monitor)
//   montecarlo/alignment.cc    navigation start states: initial-error draws, static alignment,
//   gyrocompass montecarlo/runs.cc         the scalar runs, one run at a time (free NED, seed 000,
//   EKF, complementary) montecarlo/lockstep_runs.cc the free-NED runs in lockstep groups
//   (lockstep_ned.h) montecarlo/reduction.cc    merging the per-thread sums montecarlo/replay.cc
//   ReplayMonteCarloRun monte_carlo.cc     RunMonteCarlo: the job from validation to statistics
#pragma once

#include <tbb/enumerable_thread_specific.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "driftlab/aiding.h"
#include "driftlab/error_state.h"
#include "driftlab/ins_gnss_filter.h"
#include "driftlab/monte_carlo.h"
#include "montecarlo/run_loop.h"

namespace driftlab::lockstep {
struct Kernel;
}  // namespace driftlab::lockstep

namespace driftlab::mc_detail {

using Clock = std::chrono::steady_clock;

// Cancellation and progress are polled every kPollSamples samples of a run (run_loop.h).
using run_loop::kPollSamples;

inline double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

// A sample at which errors are reported: an epoch (per-epoch sums), a checkpoint (per-run values)
// or both. `truth` is the truth state at sample k.
struct Report {
  int64_t k = 0;
  int epoch = -1;
  int checkpoint = -1;
  NavState truth;
};

// What the runs share, read-only.
struct SharedTruth {
  NavEnvironment env;
  double dt_s = 0.0;
  double rate_hz = 0.0;
  int64_t n = 0;           // output intervals; samples k = 0..n
  int64_t start_step = 0;  // s0: sample at which navigation starts
  NavState truth0;         // truth at t = 0
  NavState truth_start;    // truth at s0
  // Mechanization A: increments[k] covers (t_{k-1}, t_k], k = 1..n (index 0 unused).
  std::vector<ImuIncrement> increments;
  // Mechanization B: point samples k = 0..n.
  std::vector<ImuSample> samples;
  // Truth-height aiding: h and v_D at every sample.
  std::vector<double> h_m, v_D_m_per_s;
  std::vector<Report> reports;  // ascending k, all >= start_step
  // Aiding (kInsGnssEkf): the one schedule of the job's aids (aiding.h) and, at each sample where
  // an aid is due (ascending k), the truth it measures. Magnetometer (kComplementary): the truth
  // attitude at its epochs j (sample j * mag_decimation).
  std::shared_ptr<const AidingSchedule> schedule;
  struct AidingEpoch {
    int64_t k = 0;
    uint32_t due = 0;  // AidingSchedule::Due
    AidingTruth truth;
  };
  std::vector<AidingEpoch> aiding_epochs;
  int64_t mag_decimation = 0;
  std::vector<Quaterniond> mag_q_b_n;
  // kInsGnssEkf: the filter's noise model and initial covariance.
  ErrorStateNoise ekf_noise;
  ErrorStateMatrix ekf_P0;
};

// The layout of a job, from the motion's plan alone (no trajectory streamed): navigation start,
// the report samples (epochs and checkpoints), with every check that needs the trajectory.
struct JobPlan {
  int64_t n = 0;                // output intervals; samples k = 0..n
  int64_t start_step = 0;       // s0
  std::vector<Report> reports;  // truth states not filled in
};

// Per-thread accumulator of the epoch sums.
using EpochAccumulator = std::vector<EpochSums>;

// Where one run's reported errors go.
struct RunSink {
  EpochAccumulator* epochs = nullptr;
  // checkpoint_values[c][run - first_run]
  std::vector<std::vector<ErrorComponentValues>>* checkpoint_values = nullptr;
  uint32_t slot = 0;

  void Record(const Report& r, const NavError& error) const { Record(r, ErrorComponentsOf(error)); }
  void Record(const Report& r, const ErrorComponentValues& v) const {
    if (r.epoch >= 0) {
      EpochSums& sums = (*epochs)[static_cast<size_t>(r.epoch)];
      for (int c = 0; c < kNumErrorComponents; ++c) {
        sums.sum[c].Add(v[c]);
        sums.sum_squares[c].AddSquare(v[c]);
      }
    }
    if (r.checkpoint >= 0) (*checkpoint_values)[static_cast<size_t>(r.checkpoint)][slot] = v;
  }
};

// Per-thread NEES sums of a kInsGnssEkf job (FilterConsistencyData), indexed by epoch.
struct NeesAccumulator {
  std::vector<ExactSum> sum;
  std::vector<uint64_t> count;
};

// ---- montecarlo/validation.cc
void ValidateSigmas(const Eigen::Vector3d& v, const std::string& field, const std::string& unit);
const char* FilterName(NavigationFilterKind f);
// The filter, the aiding and the covariance analysis fit together and with the navigation.
void ValidateFilter(const MonteCarloSpec& spec);
// Validates the Monte-Carlo fields that do not need the trajectory.
void ValidateSpec(const MonteCarloSpec& spec);
JobPlan PlanJob(const MonteCarloSpec& spec, const TrajectoryGenerator& generator);
// Memory of a job [bytes] from its plan (EstimateMonteCarloMemoryBytes, monte_carlo.h).
uint64_t MemoryOfPlan(const MonteCarloSpec& spec, const JobPlan& plan, double rate_hz);

// ---- montecarlo/shared_truth.cc
// The shared truth published while it streams, so that runs can start before it is complete
// (RunMonteCarlo overlaps the truth with the lockstep runs): samples 0 .. ready are written
// (increments, truth heights, the truth of reports at those samples, the start state).
inline constexpr int64_t kTruthPublishSamples = 1024;  // a power of two
class TruthStream {
 public:
  void Publish(int64_t k) {
    ready_.store(k, std::memory_order_release);
    ready_.notify_all();
  }
  // No more samples will come (cancelled or failed): waiting readers return false.
  void Stop() {
    ready_.store(kStopped, std::memory_order_release);
    ready_.notify_all();
  }
  // Blocks until sample k is written (true) or the stream stopped (false).
  bool WaitFor(int64_t k) const {
    int64_t r = ready_.load(std::memory_order_acquire);
    while (r < k) {
      if (r == kStopped) return false;
      ready_.wait(r, std::memory_order_acquire);
      r = ready_.load(std::memory_order_acquire);
    }
    return true;
  }

 private:
  static constexpr int64_t kStopped = INT64_MIN;
  std::atomic<int64_t> ready_{-1};
};

// Generates the truth once and keeps what the runs need (without keep_imu: only the layout, the
// reports and the start state, for ReplayMonteCarloRun). `cancel` is polled while the trajectory
// streams (every 4096 samples); when it is set the function returns early with `cancelled`.
SharedTruth BuildSharedTruth(const MonteCarloSpec& spec, bool keep_imu = true,
                             const std::atomic<bool>* cancel = nullptr, bool* cancelled = nullptr);
// BuildSharedTruth in two steps: the layout (sizes, reports, aiding decimations, start state;
// returns the generator positioned at sample 0), then the stream of samples 1..n, published to
// `stream` (if not null) every kTruthPublishSamples samples and at the end.
std::unique_ptr<TrajectoryGenerator> PrepareSharedTruth(const MonteCarloSpec& spec, bool keep_imu,
                                                        SharedTruth* out);
void StreamSharedTruth(const MonteCarloSpec& spec, bool keep_imu, TrajectoryGenerator* generator,
                       SharedTruth* out, const std::atomic<bool>* cancel, bool* cancelled,
                       TruthStream* stream);
// FilterErrorModel into s->ekf_noise and, with its initial covariance from the initial errors at
// the navigation start, s->ekf_P0 (for kInsGnssEkf or the covariance analysis; else nothing).
// Returns the model (with its unrepresented terms).
ErrorStateNoiseFromImu PrepareFilterModel(const MonteCarloSpec& spec, SharedTruth* s);
// The error-state model the EKF and the covariance analysis use (MakeErrorStateNoise of the
// filter's IMU model, spec.filter_sensor or else the truth's), with the GNSS and barometer
// Gauss-Markov errors as states for the EKF, and the run's time scales and motion bounds.
ErrorStateNoiseFromImu FilterErrorModel(const MonteCarloSpec& spec, const SharedTruth& s);

// ---- montecarlo/alignment.cc
Eigen::Vector3d InitialErrorDraw(uint64_t seed, uint32_t run, uint8_t component,
                                 const Eigen::Vector3d& sigma);
// Truth position and velocity at navigation start plus the run's initial errors; attitude set by
// the caller.
NavState PerturbedStart(const SharedTruth& s, const MonteCarloSpec& spec, uint32_t run);
// Mechanization A's state at navigation start s0 for `run`: the truth at s0 plus the run's
// position and velocity errors, with the attitude from the static alignment (sum_dtheta, sum_dv:
// the measured increments summed over the window, k = 1..s0) or the truth's plus the attitude
// errors.
NavState NedStartState(const SharedTruth& s, const MonteCarloSpec& spec, uint32_t run,
                       bool gyrocompass, const Eigen::Vector3d& sum_dtheta,
                       const Eigen::Vector3d& sum_dv);
// The initial error covariance of the EKF and of the covariance analysis from the job's initial
// errors (InitialErrorCovariance of error_state.h, plus the attitude rotation's sigma; the EKF is
// given sigma^2 + fixed^2 per axis) at the truth's start attitude.
ErrorStateMatrix StartErrorCovariance(const MonteCarloSpec& spec, const EulerAngles& attitude,
                                      const ErrorStateNoise& noise);
// Gyrocompass or external heading: one decision per job (it depends on the model only).
bool UseGyrocompass(const MonteCarloSpec& spec, const SharedTruth& truth);

// ---- montecarlo/runs.cc: one run each through run_loop::RunLoop, its reports into `sink`; false
// if stopped early, else the run is counted as done in `monitor`.
class Monitor;

// Sees every sample of one run (ReplayMonteCarloRun: `driftlab simulate --run N`, `export --run
// N`): called at each k = 0..n after the navigator's step and the report at k, before the aiding
// updates at k, i.e. with the solution the statistics score. `solution(truth_k)` is the
// navigator's navigation solution (valid from the navigation start on), `filter` the run's EKF
// (nullptr for the other navigators). The Monte-Carlo runs pass no observer.
class RunObserver {
 public:
  virtual ~RunObserver() = default;
  virtual void At(int64_t k, const std::function<NavState(const NavState&)>& solution,
                  const InsGnssFilter* filter) = 0;
};

bool RunNed(const SharedTruth& s, const MonteCarloSpec& spec, uint32_t run, bool gyrocompass,
            const RunSink& sink, Monitor* monitor, RunObserver* observer = nullptr);
bool RunSeed000(const SharedTruth& s, const MonteCarloSpec& spec, uint32_t run, const RunSink& sink,
                Monitor* monitor, RunObserver* observer = nullptr);
// With the NEES of the 9 navigation states at every epoch into `nees`.
bool RunEkf(const SharedTruth& s, const MonteCarloSpec& spec, uint32_t run, const RunSink& sink,
            NeesAccumulator* nees, Monitor* monitor, RunObserver* observer = nullptr);
bool RunComplementary(const SharedTruth& s, const MonteCarloSpec& spec, uint32_t run,
                      const RunSink& sink, Monitor* monitor, RunObserver* observer = nullptr);

// ---- montecarlo/lockstep_runs.cc
// All runs of a kNed job in lockstep groups of kernel.width runs, in parallel over groups.
// With a `truth` stream the shared truth is still being written: each group waits for the samples
// it needs, returns when the stream stops, and decides the gyrocompass itself once the start
// state is there (UseGyrocompass: the same decision as `gyrocompass`).
void RunNedLockstep(const SharedTruth& s, const MonteCarloSpec& spec,
                    const lockstep::Kernel& kernel, bool gyrocompass, uint32_t run_count,
                    tbb::task_arena& arena,
                    tbb::enumerable_thread_specific<EpochAccumulator>& accumulators,
                    std::vector<std::vector<ErrorComponentValues>>& checkpoint_values,
                    Monitor* monitor, const TruthStream* truth = nullptr);

// ---- montecarlo/reduction.cc
// The per-thread epoch sums merged (exact sums: the order does not change a bit).
std::vector<EpochSums> MergeEpochSums(
    const tbb::enumerable_thread_specific<EpochAccumulator>& accumulators, size_t n_epochs);
// The per-thread NEES sums merged.
FilterConsistencyData MergeNees(
    const tbb::enumerable_thread_specific<NeesAccumulator>& accumulators, size_t n_epochs);

}  // namespace driftlab::mc_detail
