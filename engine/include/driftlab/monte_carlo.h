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

#include "driftlab/mc_statistics.h"
#include "driftlab/sensor_params.h"
#include "driftlab/simulate.h"

namespace driftlab {

// 1-sigma initial navigation errors, independent Gaussian per axis and per run (zero = none).
// Drawn from RandomStream(seed, run, {SensorId::kInitialConditions, axis, ErrorTerm::kInitialError,
// component 0 = position, 1 = velocity, 2 = attitude, 3 = alignment heading}) at index 0.
struct InitialErrorSigmas {
  Eigen::Vector3d position_ned_m = Eigen::Vector3d::Zero();        // N, E, D [m]
  Eigen::Vector3d velocity_ned_m_per_s = Eigen::Vector3d::Zero();  // N, E, D [m/s]
  // Added to the truth's roll, pitch and yaw (Euler angles of C_b_n) [rad].
  Eigen::Vector3d attitude_rad = Eigen::Vector3d::Zero();
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
// cancel (optional): polled every 1024 samples of every run and before each run starts. Once set,
// the workers stop within ~1024 samples and the function returns statistics with cancelled() ==
// true and no runs, epochs or checkpoint values (timings are filled in).
MonteCarloStatistics RunMonteCarlo(
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
