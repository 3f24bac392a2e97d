// The one validator of a job. `driftlab validate`, `run`, `simulate`, `export` (local), `run
// --slurm`, and the server's Jobs.Submit and Datasets service all call ValidateJob, so a job that
// validates runs, and a job that would fail (or give a non-finite statistic) is refused before any
// work with the field named.
//
// In order, each step throwing SpecError (LimitError for the memory limit) naming the proto field
// path, the value and the allowed range:
//  1. schema sizes: every string and repeated field within its limit (CheckFieldSizes);
//  2. file references: a job received by the server may not name files (motion.*_file.path);
//  3. fields that would be ignored: options of the mechanization or aid that is not used
//     (navigation.seed000 with NED, navigation.ned with SEED000, aiding.zupt fields with
//     enabled false, motion.vehicle with an imported motion);
//  4. translation with value ranges and cross-field rules: motion, rate, navigation, sensor,
//     aiding, monte_carlo and the command-line overrides (monte_carlo_job.h);
//  5. the engine's own checks on the planned motion and the Monte-Carlo plan, without running:
//     segments planned, epochs and checkpoints against the trajectory, alignment window,
//     aiding against rate and duration, the memory estimate (ValidateMonteCarloSpec); errors
//     about an imported motion file name the file's field (motion.gnss_ins_sim_file.path,
//     motion.truth_profile_file.path);
//  6. time constants the navigation models can represent: a Gauss-Markov correlation time at
//     least one IMU interval (shorter is white noise at the IMU rate), and at least the
//     propagation interval of the EKF and of the covariance analysis where they model it (their
//     discrete steps give non-finite or meaningless covariances below it);
//  7. every numeric field finite, every enum value known, no unknown field (CheckMessageValues:
//     a binary request may carry them), also in fields the translation does not read.
#pragma once

#include <cstdint>
#include <filesystem>

#include "driftlab/app/job_file.h"
#include "driftlab/app/monte_carlo_job.h"
#include "driftlab/monte_carlo.h"
#include "driftlab/v1/job.pb.h"

namespace driftlab::app {

struct JobValidationOptions {
  MonteCarloOverrides overrides;
  // Motion files (motion.gnss_ins_sim_file, motion.truth_profile_file) are read relative to the
  // job's directory; false (the server) refuses a job that names one.
  bool allow_file_references = true;
};

// A valid job, ready to run.
struct ValidatedJob {
  MonteCarloSpec spec;  // for RunMonteCarloWithAnalysis, ReplayMonteCarloRun, RunSimulation
  uint32_t runs = 0;    // runs of this call (the shard's, with --shard)
  uint64_t samples_per_run = 0;  // IMU samples each run processes
  uint64_t samples_total = 0;    // runs x samples_per_run, the job's cost
  uint64_t memory_bytes = 0;     // EstimateMonteCarloMemoryBytes
};

// Validates a job whose relative file paths resolve against base_dir. Throws SpecError.
ValidatedJob ValidateJob(const v1::Job& job, const std::filesystem::path& base_dir,
                         const JobValidationOptions& options = {});
inline ValidatedJob ValidateJob(const JobFile& file, const JobValidationOptions& options = {}) {
  return ValidateJob(file.job, file.base_dir, options);
}

}  // namespace driftlab::app
