// `driftlab run JOB --slurm [--shards K] [--partition P] [--slurm-dir DIR]`: the job's runs as a
// Slurm job array, one array task per shard (`driftlab run JOB --shard i/K`), submitted with
// sbatch; progress from squeue; a failed task is resubmitted once, then the run fails naming the
// shard and its log; Ctrl-C or SIGTERM cancels the array (scancel); when every shard has written
// its result the shards are merged here (exact sums: the merged result equals an in-process run
// of the same job byte for byte, timings aside) and written as `run` writes a result.
//
// The work directory (default: RESULT.slurm beside the result) must be visible to the compute
// nodes at the same path, as must the job file and the driftlab binary (a shared filesystem).
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace driftlab::cli {

struct SlurmRunOptions {
  std::string job_path;
  std::string out;
  std::optional<std::string> report;
  std::optional<uint32_t> runs;
  std::optional<uint64_t> seed;
  bool covariance = false;
  bool quiet = false;
  uint32_t shards = 4;
  std::string partition;  // empty: the cluster's default
  std::string work_dir;   // empty: OUT.slurm
  double timeout_s = 7 * 86400.0;
};

int RunOnSlurm(const SlurmRunOptions& options);

}  // namespace driftlab::cli
