// Monte-Carlo runner (DESIGN.md "Data flow of one Monte-Carlo job", invariants 3-5): N runs of
// one trajectory under independent sensor and initial-condition errors, in parallel (oneTBB),
// reduced to mergeable statistics (mc_statistics.h).
//
// Per job: the truth is generated once and only what the runs need is kept (the ideal increments,
// or the point samples for mechanization B; truth height and vertical velocity when the vertical
// channel is truth-aided; the truth states at the output epochs), so memory is O(samples) plus
// O(threads x epochs) for the per-thread sums plus O(runs x checkpoints) for the per-run values,
// never O(runs x samples). Per run: an ImuErrorSimulator (sensors.h) generates the run's sensor
// errors on the fly from RandomStream(seed, run index, ...); the mechanization (ins.h) navigates;
// the errors against the truth (ComputeNavError, as simulate.cc reports them) at the epochs go to
// the statistics. A run's numbers depend only on (spec, seed, run index), and the statistics are
// exact sums, so results are bit-identical for any thread count and any split into shards.
#pragma once

#include <Eigen/Core>
#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "driftlab/aiding.h"
#include "driftlab/complementary_filter.h"
#include "driftlab/covariance.h"
#include "driftlab/error_budget.h"
#include "driftlab/exact_sum.h"
#include "driftlab/ins_gnss_filter.h"
#include "driftlab/mc_statistics.h"
#include "driftlab/sensor_params.h"
#include "driftlab/simulate.h"

namespace driftlab {

// Initial navigation errors of each run: 1-sigma random parts, independent Gaussian per axis and
// per run (zero = none), plus fixed parts, the same in every run. The random parts are drawn from
// RandomStream(seed, run, {SensorId::kInitialConditions, axis, ErrorTerm::kInitialError, component
// 0 = position, 1 = velocity, 2 = attitude (Euler), 3 = alignment heading, 4 = attitude rotation})
// at index 0.
struct InitialErrorSigmas {
  Eigen::Vector3d position_ned_m = Eigen::Vector3d::Zero();        // N, E, D [m]
  Eigen::Vector3d velocity_ned_m_per_s = Eigen::Vector3d::Zero();  // N, E, D [m/s]
  // Added to the truth's roll, pitch and yaw (Euler angles of C_b_n) [rad].
  Eigen::Vector3d attitude_rad = Eigen::Vector3d::Zero();
  // The attitude error as a rotation psi_nb_n about the N, E, D axes [rad]:
  // C_b_n(start) = exp([psi x]) C_b_n (attitude.h AttitudeErrorNed), applied after attitude_rad.
  Eigen::Vector3d attitude_ned_rad = Eigen::Vector3d::Zero();
  // Fixed errors added to every run's draw: position N, E, D [m], velocity N, E, D [m/s], and the
  // attitude rotation psi_nb_n [rad] (exp([psi x]) with psi = fixed + random).
  Eigen::Vector3d fixed_position_ned_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d fixed_velocity_ned_m_per_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d fixed_attitude_ned_rad = Eigen::Vector3d::Zero();

  bool attitude_is_zero() const {
    return attitude_rad.isZero(0.0) && attitude_ned_rad.isZero(0.0) &&
           fixed_attitude_ned_rad.isZero(0.0);
  }
  bool is_zero() const {
    return attitude_is_zero() && position_ned_m.isZero(0.0) && velocity_ned_m_per_s.isZero(0.0) &&
           fixed_position_ned_m.isZero(0.0) && fixed_velocity_ned_m_per_s.isZero(0.0);
  }
};

// How mechanization A (MechanizationKind::kNed) is initialised. Mechanization B
// (MechanizationKind::kSeed000) always initialises itself as seed 000 does (gravity and gyro bias
// from the mean of its static period, navigation frame = initial body frame, zero position and
// velocity): with it, `initialization` must be kTruthPlusErrors and `initial_errors` zero, and the
// epochs start at the end of its static period.
enum class InitializationKind {
  // Truth at t = 0 plus the initial errors; navigation starts at t = 0.
  kTruthPlusErrors,
  // Static coarse alignment over [0, alignment.duration_s] (see AlignmentOptions); navigation
  // starts at the end of the window from the truth position and velocity plus the position and
  // velocity initial errors (initial_errors.attitude_rad must be zero: the attitude comes from the
  // alignment).
  kStaticAlignment,
};

// Static coarse alignment from the run's measured IMU data (Groves, "Principles of GNSS,
// Inertial, and Multisensor Integrated Navigation Systems", 2nd ed., sections 5.6.2 levelling and
// 5.6.3 gyrocompassing). At rest f_ib_b = -C_n_b g_n and omega_ib_b = C_n_b omega_ie_n, so
//   levelling, from the mean measured specific force f over the window:
//     roll  = atan2(-f_y, -f_z),   pitch = atan(f_x / sqrt(f_y^2 + f_z^2))
//   gyrocompassing, from the mean measured angular rate w over the window, levelled with that roll
//   and pitch (w_l = Ry(pitch) Rx(roll) w = omega_ie cos L [cos yaw, -sin yaw, .]):
//     yaw = atan2(-w_y cos(roll) + w_z sin(roll),
//                 w_x cos(pitch) + (w_y sin(roll) + w_z cos(roll)) sin(pitch))
// Gyrocompassing is used when the gyro's predicted heading error (PredictedGyrocompassHeadingSigma)
// is below heading_sigma_rad, or always when heading_sigma_rad is absent; otherwise the heading is
// the truth heading plus N(0, heading_sigma_rad^2) (an external heading source).
// The trajectory must be static over the window.
struct AlignmentOptions {
  double duration_s = 0.0;                  // window length [s], > 0 with kStaticAlignment
  std::optional<double> heading_sigma_rad;  // 1-sigma of the external heading [rad], > 0
};

// The navigation filter of each run (mechanization A only).
enum class NavigationFilterKind {
  kNone,  // free inertial: the mechanization alone
  // Loosely coupled 15-state EKF (ins_gnss_filter.h), closed loop, updated by the configured GNSS,
  // barometer and ZUPT (in that order at a sample where several fall). Needs kTruthPlusErrors
  // (P0 from initial_errors and the sensor's bias sigmas) and VerticalChannel::kFree.
  kInsGnssEkf,
  // Seed 003's complementary attitude filter (complementary_filter.h) on the measured point
  // samples, heading from the magnetometer if configured. Errors: roll, pitch, yaw; the position
  // and velocity errors are reported as 0 (the filter does not estimate them). The initial yaw is
  // the truth's plus initial_errors.attitude_rad[2] (used when there is no magnetometer).
  kComplementary,
};

// Default memory limit of one job: 8 GB (a 1-run, 100 000 s job at 2000 Hz would need ~9.6 GB
// of shared truth). Raised with `driftlab run --max-memory-gb` or the server's
// --max-job-memory-gb.
inline constexpr uint64_t kDefaultMaxJobMemoryBytes = 8'000'000'000ull;

struct MonteCarloSpec {
  SimulationSpec simulation;            // motion, IMU rate, mechanization A or B and its options
  std::optional<ImuErrorModel> sensor;  // absent = error-free IMU (only initial errors act)
  uint32_t runs = 0;                    // runs of the whole job, >= 1
  uint64_t seed = 0;                    // the job seed of every random stream
  // Shard: this call computes runs [first_run, first_run + run_count) of `runs`;
  // run_count = 0 means all runs from first_run on.
  uint32_t first_run = 0;
  uint32_t run_count = 0;
  InitialErrorSigmas initial_errors;
  InitializationKind initialization = InitializationKind::kTruthPlusErrors;
  AlignmentOptions alignment;
  // Output epochs, exactly one of:
  //  * epoch_every_samples = k >= 1: the IMU samples s0, s0 + k, s0 + 2k, ... where s0 is the
  //    sample at which navigation starts (0, or the end of the alignment / static period), plus
  //    the final sample;
  //  * epoch_times_s: times [s] since the trajectory start, each snapped to the nearest IMU sample
  //    (the statistics report the snapped times), strictly ascending after snapping, within
  //    [navigation start, trajectory end].
  int64_t epoch_every_samples = 0;
  std::vector<double> epoch_times_s;
  // Times [s] at which every run's values are kept (snapped like epoch_times_s); the final sample
  // is always a checkpoint and is appended if not listed.
  std::vector<double> checkpoint_times_s;
  int threads = 0;  // worker threads; 0 = all hardware threads

  // Navigation filter and aiding. Random aiding errors come from RandomStream(seed, run,
  // {SensorId::kGnss / kBarometer / kMagnetometer, ...}) (gnss.h, aiding.h), so results stay
  // bit-identical for any thread count and shard split.
  NavigationFilterKind filter = NavigationFilterKind::kNone;
  AidingSpec aiding;
  int64_t ekf_propagation_step_samples = 10;  // InsGnssFilterOptions::propagation_step_samples
  // What the EKF and the covariance analysis assume (error_state.h MakeErrorStateNoise;
  // job fields navigation.ekf.sensor, .augment_scale_misalignment, .flicker_states_per_axis):
  //  * filter_sensor: the IMU model the filter assumes; absent = the truth model `sensor` (set it
  //    to study a mistuned filter: the consistency check then compares the filter's belief with
  //    the truth's Monte-Carlo spread);
  //  * filter_augment_scale_misalignment: scale factor and misalignment as augmented states, or
  //    (false) as a white-noise bound derived from the motion;
  //  * filter_flicker_states_per_axis: Gauss-Markov states per axis for flicker, 1 to
  //    kMaxFlickerComponents (default: every component of the simulator's design).
  std::optional<ImuErrorModel> filter_sensor;
  bool filter_augment_scale_misalignment = true;
  int filter_flicker_states_per_axis = kMaxFlickerComponents;
  // kComplementary: kind and crossover frequencies (magnetic_declination_rad and initial_yaw_rad
  // are set per run from the magnetometer's field and the initial errors).
  ComplementaryFilterOptions complementary;
  // Linear covariance analysis (RunMonteCarloWithAnalysis): needs kNed, kTruthPlusErrors,
  // VerticalChannel::kFree and filter kNone or kInsGnssEkf.
  bool covariance = false;
  int64_t covariance_step_samples = 10;  // propagation interval [IMU samples], 1 to 10000

  // Largest memory the job may need (EstimateMonteCarloMemoryBytes) [bytes]; 0 = no limit.
  uint64_t max_memory_bytes = kDefaultMaxJobMemoryBytes;
};

// Filter consistency of a kInsGnssEkf job: per output epoch, the exact sum over runs of the NEES
// of the 9 navigation error states (position, velocity, attitude psi_nb_n) against the filter's
// own covariance, and the number of runs in it (a run whose 9 x 9 covariance block is not
// positive definite at that epoch, as at a navigation start with zero initial sigmas, adds
// nothing). Mergeable like the epoch sums.
struct FilterConsistencyData {
  static constexpr int kStateDimension = 9;
  std::vector<ExactSum> nees_sum;    // per epoch
  std::vector<uint64_t> nees_count;  // per epoch
  // Adds `other` (a shard of the same job, same epochs); throws SpecError("statistics.nees", ...)
  // for a different number of epochs.
  void Merge(const FilterConsistencyData& other);
};

// Predicted sigmas of the job's error model at the output epochs (FilterCovarianceAnalysis).
struct CovarianceAnalysisResult {
  NavigationFilterKind filter = NavigationFilterKind::kNone;
  int64_t step_samples = 0;
  std::vector<CovarianceEpoch> epochs;     // at the statistics' epoch times
  std::vector<std::string> unrepresented;  // model terms the prediction leaves out (paths)
};

// Error budget of a job (error_budget.h): the covariance analysis of `run --covariance`
// (FilterCovarianceAnalysis with the same error-state model, P0, aiding schedule, propagation
// interval and discretisation) with each independent error source also propagated alone, at the
// job's output epochs. Component variances in SI (angles rad^2).
struct ErrorBudgetResult {
  NavigationFilterKind filter = NavigationFilterKind::kNone;
  int64_t step_samples = 0;
  std::vector<double> epoch_times_s;
  std::vector<ErrorSource> sources;                           // names, groups (P0, q_c kept)
  std::vector<ComponentVariances> total;                      // [epoch], of the full P
  std::vector<std::vector<ComponentVariances>> contribution;  // [epoch][source]
  std::vector<std::string> unrepresented;  // model terms the linear model leaves out (paths)
  // max over epochs and components of |sum_s contribution - total| / total (total > 0).
  double max_relative_sum_error = 0.0;
};

// Validates the job as RunMonteCarloWithAnalysis with the covariance analysis on (SpecError with
// the field path), then computes the budget. A job whose filter assumes its own IMU model
// (navigation.ekf.sensor) is refused: SpecError("navigation.ekf.sensor", ...).
ErrorBudgetResult ComputeErrorBudget(const MonteCarloSpec& spec);

struct MonteCarloOutput {
  MonteCarloStatistics statistics;
  std::optional<CovarianceAnalysisResult> covariance;  // when spec.covariance
  std::optional<FilterConsistencyData> consistency;    // when spec.filter == kInsGnssEkf
};

// Limits (memory and sanity).
inline constexpr uint32_t kMaxMonteCarloRuns = 1000000;
inline constexpr size_t kMaxMonteCarloEpochs = 20000;
inline constexpr size_t kMaxMonteCarloCheckpoints = 100;
inline constexpr int kMaxMonteCarloThreads = 1024;

// Progress of a running job.
struct MonteCarloProgress {
  uint32_t runs_done = 0;     // runs of this call finished
  uint32_t runs_total = 0;    // runs of this call (run_count)
  int64_t samples_done = 0;   // IMU samples processed so far (all runs of this call)
  int64_t samples_total = 0;  // samples of all runs of this call
  double elapsed_s = 0.0;     // wall time since the call started
};

// Runs the Monte-Carlo job (or the shard of it that spec.first_run / run_count select).
//
// Validation: throws SpecError before any run starts, with field paths under "monte_carlo."
// (e.g. "monte_carlo.runs" for 0 runs, "monte_carlo.epoch_times_s[2]" outside the trajectory,
// "monte_carlo.run_count" when first_run + run_count > runs, "monte_carlo.alignment.duration_s"
// for an alignment window over a moving segment), and the engine's own paths ("motion...",
// "sensor...", "navigation.seed000...") for the simulation and sensor parts.
//
// progress (optional): called at most every 100 ms (the first call at the first check, after
// ~1000 samples), from whichever worker thread notices the time, never concurrently with itself
// (a call in progress makes the others skip theirs), and once more at the end from the calling
// thread. It must be thread-safe with respect to the caller's own data; an exception it throws
// propagates out of RunMonteCarlo.
//
// cancel (optional): polled while the truth is generated (every 4096 samples), every 1024 samples
// of every run and before each run starts. Once set, the workers stop within ~1024 samples and the
// function returns statistics with cancelled() == true and no runs, epochs or checkpoint values
// (timings are filled in).
MonteCarloStatistics RunMonteCarlo(
    const MonteCarloSpec& spec,
    const std::function<void(const MonteCarloProgress&)>& progress = nullptr,
    const std::atomic<bool>* cancel = nullptr);

// The layout of one run, reported by ReplayMonteCarloRun before its first step.
struct MonteCarloRunLayout {
  const NavEnvironment* env = nullptr;  // the trajectory's Earth model (valid during the call)
  double rate_hz = 0.0;                 // IMU rate [Hz]
  double dt_s = 0.0;                    // IMU interval [s]
  int64_t num_steps = 0;                // samples k = 0..num_steps
  int64_t navigation_start_step = 0;    // s0: first sample with a navigation solution
  size_t num_epochs = 0;                // output epochs of the statistics
  size_t num_checkpoints = 0;           // checkpoints of the statistics (the last is the final)
};

// One IMU sample k of a replayed run (pointers valid during the callback only).
struct MonteCarloRunStep {
  int64_t k = 0;
  const NavState* truth = nullptr;  // truth at t_k
  // The ideal IMU data: the increment over (t_{k-1}, t_k] (zero at k = 0) and the point sample.
  const ImuIncrement* increment = nullptr;
  const ImuSample* sample = nullptr;
  // The run's measured IMU data: the increment over (t_{k-1}, t_k] (zero at k = 0) and the point
  // sample at t_k, each from its own ImuErrorSimulator of (model, seed, run, rate); the stream the
  // run's navigator reads (increments for mechanization A and the EKF, point samples for
  // mechanization B and the complementary filter) is the one it navigated with.
  const ImuIncrement* measured_increment = nullptr;
  const ImuSample* measured_sample = nullptr;
  // The run's navigation solution at t_k (the solution RunMonteCarlo scores: after the step at k,
  // before the aiding updates at k), from s0 on and only when navigation was asked for; nullptr
  // otherwise.
  const NavState* nav = nullptr;
  // The run's INS/GNSS EKF at t_k (its estimates and covariance; the covariance is propagated to
  // t_k at the output epochs and at aiding updates, between them it is the last propagated one),
  // for a kInsGnssEkf job when navigation was asked for; nullptr otherwise.
  const InsGnssFilter* filter = nullptr;
  // Index of the output epoch / checkpoint at sample k, or -1; report_t_s = k dt_s as the
  // statistics report it (MonteCarloStatisticsData::epoch_times_s, CheckpointValues::t_s).
  int epoch = -1;
  int checkpoint = -1;
  double report_t_s = 0.0;
  // At a checkpoint: the run's error components exactly as RunMonteCarlo keeps them
  // (CheckpointValues::values of this run); nullptr elsewhere.
  const ErrorComponentValues* checkpoint_values = nullptr;
};

// Replays run `run` of the job sample by sample exactly as RunMonteCarlo computes it: the
// Monte Carlo's own run (the same truth, the run's sensor errors from RandomStream(seed, run, ...),
// its initial errors, alignment, aiding measurements, filter and mechanization) with an observer
// at every sample (spec.first_run / run_count are ignored; run < spec.runs is required). For
// `driftlab simulate --run N`, `driftlab export --run N` and users who bring their own navigation
// algorithm (the gRPC Datasets service): the errors of the steps' `nav` against their `truth` at
// the epochs are the numbers RunMonteCarlo accumulates for this run, and checkpoint_values are
// its kept values bit for bit. Validation as RunMonteCarlo (SpecError; "monte_carlo.first_run"
// for run >= runs). The free-inertial mechanization A runs through the scalar run (the lockstep
// runs are tested equal to it bit for bit). Memory O(samples) (the run's ideal IMU data);
// `cancel` is polled every 1024 samples; returns false when it stopped the replay, else true.
// Not a hot path (one virtual call per sample).
bool ReplayMonteCarloRun(const MonteCarloSpec& spec, uint32_t run, bool navigate,
                         const std::function<void(const MonteCarloRunLayout&)>& on_start,
                         const std::function<void(const MonteCarloRunStep&)>& on_step,
                         const std::atomic<bool>* cancel = nullptr);

// Run N of the job as a simulation (`driftlab simulate --run N`, `driftlab export --run N`):
// ReplayMonteCarloRun with navigation, every sample k = 0..n to on_step (optional) as a
// SimulationStep (ideal and measured IMU data, truth; nav and error from the navigation start on,
// nullptr before it), and the summary of the errors from the navigation start on. `filter`
// (optional) receives the run's EKF at each step (nullptr for other navigators). Throws SpecError
// as ReplayMonteCarloRun.
SimulationSummary SimulateMonteCarloRun(
    const MonteCarloSpec& spec, uint32_t run,
    const std::function<void(const SimulationStep&, const InsGnssFilter*)>& on_step);

// Every check RunMonteCarlo makes before it starts, without generating the trajectory (cost
// O(segments + epochs)): the Monte-Carlo fields, the sensor model, the navigation start, the
// alignment window, the epochs and checkpoints against the trajectory, the aiding against the rate
// and duration, and the memory estimate against spec.max_memory_bytes. `driftlab validate`,
// `driftlab run` and the server's Submit call it (through app::ToMonteCarloSpec), so a job
// that validates runs. Throws SpecError.
void ValidateMonteCarloSpec(const MonteCarloSpec& spec);

// The memory a job needs [bytes], approximately and from above: the shared truth (one IMU
// increment or sample per output step, truth height when aided), the aiding truth, the per-run
// values at the checkpoints (engine and result), the per-thread and result epoch statistics.
uint64_t EstimateMonteCarloMemoryBytes(const MonteCarloSpec& spec);

// The checks of the filter, aiding and covariance fields that need no trajectory (RunMonteCarlo
// makes them too; exposed so that a job can be rejected before it is queued). Throws SpecError.
void ValidateFilterAndAiding(const MonteCarloSpec& spec);

// RunMonteCarlo plus, when the spec asks for them, the linear covariance analysis of the same
// error model at the output epochs (computed once, after the runs; not for a cancelled job) and
// the EKF's NEES sums. Validation as RunMonteCarlo, plus "navigation.filter",
// "monte_carlo.covariance", "aiding..." paths for filter, analysis and aiding combinations that
// do not fit.
MonteCarloOutput RunMonteCarloWithAnalysis(
    const MonteCarloSpec& spec,
    const std::function<void(const MonteCarloProgress&)>& progress = nullptr,
    const std::atomic<bool>* cancel = nullptr);

// Predicted 1-sigma heading error [rad] of gyrocompassing with this gyro triad over a static
// window of duration_s at latitude L_b (heading error = horizontal gyro error / (omega_ie cos L),
// Groves section 5.6.3):
//   sigma_psi = sqrt(b^2 + N^2 / T) / (omega_ie cos L_b),
//   b^2 = max_i fixed_bias_i^2 + turn_on_bias_sigma^2 + gauss_markov.sigma^2
//         + (0.664 flicker B)^2 + random_walk^2 T / 3,
// with N = white_noise_density, T = duration_s. Infinite where omega_ie cos L = 0 (pole) or for
// the flat Earth model (no Earth rotation; pass omega_ie = 0).
double PredictedGyrocompassHeadingSigma(const TriadErrorParams& gyro, double L_b, double duration_s,
                                        double omega_ie_rad_per_s = kWgs84EarthRate_rad_per_s);

}  // namespace driftlab
