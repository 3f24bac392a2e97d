// A job's Monte-Carlo side: translation of `monte_carlo` (and of the whole job) into the engine's
// MonteCarloSpec with validation. The conversion of the engine's statistics into the result
// schema and back (`driftlab merge`) is job_result.h.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "driftlab/app/job_file.h"
#include "driftlab/app/job_result.h"
#include "driftlab/mc_statistics.h"
#include "driftlab/monte_carlo.h"
#include "driftlab/v1/result.pb.h"

namespace driftlab::app {

inline constexpr uint32_t kDefaultRuns = 100;
inline constexpr double kDefaultEpochInterval_s = 1.0;

// Command-line overrides of the job's monte_carlo section.
struct MonteCarloOverrides {
  std::optional<uint32_t> runs;
  std::optional<uint64_t> seed;
  std::optional<int> threads;
  // Shard i of K (`--shard i/K`): runs [floor(i N / K), floor((i + 1) N / K)).
  std::optional<uint32_t> shard_index;
  std::optional<uint32_t> shard_count;
  // `run --covariance`: add the linear covariance analysis (as monte_carlo.covariance = true).
  bool covariance = false;
  // `run --max-memory-gb` / the server's --max-job-memory-gb: the job's memory limit [bytes]
  // (MonteCarloSpec::max_memory_bytes; default kDefaultMaxJobMemoryBytes, 0 = none).
  std::optional<uint64_t> max_memory_bytes;
};

// Parses "i/K" (`--shard`); throws SpecError("--shard", text, "i/K with 0 <= i < K, K >= 1").
void ParseShard(const std::string& text, MonteCarloOverrides* overrides);

// Translates and validates the whole job for a Monte-Carlo run: motion, rate and navigation
// (ValidateJob), sensor (ToImuErrorModel), monte_carlo (runs, seed, initial errors,
// initialization, epochs, checkpoints) and the overrides. Throws SpecError naming the field
// ("monte_carlo.epoch_interval_s", "--runs", "--shard", ...). The engine checks the rest when it
// runs (epochs outside the trajectory, alignment over a moving segment) with the same field paths.
// Also navigation.filter / ekf / complementary and aiding (GNSS, barometer, magnetometer, ZUPT):
// every number range-checked ("aiding.gnss.position_sigma_ned_m[2]"), outages ascending, not
// overlapping and inside the trajectory ("aiding.gnss.outages[1].start_s" / ".end_s"), aiding
// rates at most the IMU rate and dividing it, each aid only with the filter that uses it.
// Ends with ValidateMonteCarloSpec (monte_carlo.h): every check RunMonteCarlo makes, including
// those against the trajectory and the memory estimate, so that `validate`, `run` and the
// server's Submit accept exactly the jobs that run.
MonteCarloSpec ToMonteCarloSpec(const JobFile& file, const MonteCarloOverrides& overrides);

// The job as run: the job file's message with the overrides written into monte_carlo (runs,
// seed), for the result's echo.
v1::Job JobAsRun(const v1::Job& job, const MonteCarloSpec& spec);

}  // namespace driftlab::app
