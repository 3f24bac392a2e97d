// A driftlab job's K shards as one Slurm job array: array task i runs
// `driftlab run JOB --shard i/K --out DIR/shard-i.json`. Submission (sbatch), progress (squeue),
// resubmission of a task that left the queue without its result (once), cancellation (scancel)
// and the exact merge of the shard results. Used by `driftlab run --slurm` and by
// driftlab-server's Slurm backend, which stores job_ids() to re-attach after a restart.
//
// The work directory must be visible to the compute nodes at the same path, as must the job file
// and the driftlab binary (a shared filesystem). The Slurm client programs are found on PATH and
// talk to the cluster SLURM_CONF names.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "driftlab/v1/result.pb.h"

namespace driftlab::slurm {

// A Slurm client program failed, or a shard failed its last attempt; what() is one line.
class SlurmError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct CommandOutput {
  int status = -1;   // exit status, 128 + signal, or -1 when the program could not be started
  std::string text;  // stdout and stderr together (at most 1 MiB kept)
};

// Runs args[0] (searched on PATH) with the arguments, without a shell; `input` is its stdin
// (at most 64 KiB: written before the output is read).
CommandOutput RunCommand(const std::vector<std::string>& args, const std::string& input = "");

// 'text' for sh, with ' written as '\''.
std::string ShellQuote(const std::string& text);

// The last non-empty line of a file (escaped and bounded as MessageText), "(no log)" without it.
std::string LastLine(const std::filesystem::path& path);

// Reads DIR/shard-0.json .. DIR/shard-(K-1).json and merges them (exact sums: equal to an
// in-process run of the job, timings aside). Throws SpecError naming a missing or bad shard.
// Also used by driftlab-server's Kubernetes backend, whose pods write the same files.
v1::JobResult MergeShardResults(const std::filesystem::path& work_dir, uint32_t shards,
                                const std::string& engine_version);

struct ShardArrayOptions {
  std::filesystem::path work_dir;  // absolute; shard-i.json, shard-i.log, driftlab-shard.sh
  uint32_t shards = 4;
  std::string partition;  // empty: the cluster's default
  std::string job_name = "driftlab";
  int max_attempts = 2;  // per shard: the first and one resubmission
};

// Shards done (result written), and array tasks running or waiting in the queue.
struct ShardProgress {
  uint32_t done = 0;
  uint32_t running = 0;
  uint32_t queued = 0;
  uint32_t total = 0;
  std::vector<uint32_t> done_shards;  // indices with a result, ascending
  // "slurm: 3/4 shards done, 1 running, 0 queued"
  std::string Text() const;
};

class ShardArray {
 public:
  explicit ShardArray(ShardArrayOptions options);

  // Creates the work directory, removes shard results of an earlier run and writes
  // driftlab-shard.sh: `exec DRIFTLAB run JOB --quiet --shard $TASK/K --out DIR/shard-$TASK.json
  // --threads ${SLURM_CPUS_PER_TASK:-0} EXTRA...`. Throws std::exception (I/O, a shard path that
  // is not a regular file).
  void Prepare(const std::filesystem::path& driftlab_binary, const std::filesystem::path& job_path,
               const std::vector<std::string>& extra_args);
  // sbatch of every task; returns the array job id. Throws SlurmError.
  std::string SubmitAll();
  // Re-attaches to arrays submitted before (job_ids() of an earlier ShardArray on the same work
  // directory): shard results already written stay, each shard has one resubmission left.
  void Attach(const std::vector<std::string>& job_ids);

  // One squeue: progress, and every shard that left the queue without its result resubmitted
  // (`notes` receives one line per resubmission). Returns nullopt when squeue failed (the reason
  // in *warning): the caller polls again. Throws SlurmError when a shard failed max_attempts
  // times (naming the shard, its log and the log's last line; the other tasks are cancelled) or
  // sbatch fails.
  std::optional<ShardProgress> Poll(std::vector<std::string>* notes, std::string* warning);
  // scancel of every array submitted; true when scancel succeeded.
  bool Cancel();
  // Tasks of our arrays still in the queue (squeue); -1 when squeue failed.
  int TasksInQueue();

  // The merged result of all shards (exact sums: equal to an in-process run of the job, timings
  // aside). Throws SpecError when a shard result is missing or does not merge.
  v1::JobResult Merge(const std::string& engine_version) const;

  const std::vector<std::string>& job_ids() const { return job_ids_; }
  std::filesystem::path ShardPath(uint32_t i) const;
  std::filesystem::path LogPath(uint32_t i) const;
  const ShardArrayOptions& options() const { return options_; }

 private:
  std::string Submit(const std::string& array);

  ShardArrayOptions options_;
  std::filesystem::path script_;
  std::vector<std::string> job_ids_;  // the array, then resubmissions
  std::vector<int> attempts_;
};

}  // namespace driftlab::slurm
