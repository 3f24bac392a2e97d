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

// The job's MonteCarloSpec as validated by ValidateJob (job_validator.h), the one validator every
// entry calls: ValidateJob(file, {overrides}).spec. Throws SpecError naming the field
// ("monte_carlo.epoch_interval_s", "aiding.gnss.outages[1].start_s", "--runs", "--shard", ...).
MonteCarloSpec ToMonteCarloSpec(const JobFile& file, const MonteCarloOverrides& overrides);

// The job as run: the job file's message with the overrides written into monte_carlo (runs,
// seed), for the result's echo.
v1::Job JobAsRun(const v1::Job& job, const MonteCarloSpec& spec);

}  // namespace driftlab::app
