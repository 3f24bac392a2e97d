#include "driftlab/slurm/shard_array.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <set>
#include <sstream>

#include "driftlab/app/monte_carlo_job.h"
#include "driftlab/app/result_file.h"
#include "driftlab/output_files.h"
#include "driftlab/spec_error.h"

extern char** environ;

namespace driftlab::slurm {

namespace fs = std::filesystem;

CommandOutput RunCommand(const std::vector<std::string>& args, const std::string& input) {
  CommandOutput result;
  int pipe_fds[2];
  int input_fds[2];
  if (pipe2(pipe_fds, O_CLOEXEC) != 0) return result;
  if (pipe2(input_fds, O_CLOEXEC) != 0) {
    close(pipe_fds[0]);
    close(pipe_fds[1]);
    return result;
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, input_fds[0], STDIN_FILENO);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDERR_FILENO);
  std::vector<std::string> copy = args;
  std::vector<char*> argv;
  for (std::string& a : copy) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  close(pipe_fds[1]);
  close(input_fds[0]);
  if (spawned == 0 && !input.empty()) {
    // Small inputs only (a manifest): they fit the pipe buffer, so this cannot block on a child
    // that writes before it reads.
    ssize_t written = 0;
    for (size_t at = 0; at < input.size(); at += static_cast<size_t>(written)) {
      written = write(input_fds[1], input.data() + at, input.size() - at);
      if (written <= 0) break;
    }
  }
  close(input_fds[1]);
  if (spawned != 0) {
    close(pipe_fds[0]);
    result.text = fmt::format("cannot start {}: {}", args[0], std::strerror(spawned));
    return result;
  }
  char buffer[4096];
  ssize_t n = 0;
  while ((n = read(pipe_fds[0], buffer, sizeof buffer)) > 0) {
    if (result.text.size() < (1 << 20)) result.text.append(buffer, static_cast<size_t>(n));
  }
  close(pipe_fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  result.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return result;
}

std::string ShellQuote(const std::string& text) {
  std::string out = "'";
  for (const char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string LastLine(const fs::path& path) {
  std::FILE* f = std::fopen(path.c_str(), "r");
  if (f == nullptr) return "(no log)";
  std::string line, last;
  char buffer[512];
  while (std::fgets(buffer, sizeof buffer, f) != nullptr) {
    line += buffer;
    if (!line.empty() && line.back() == '\n') {
      line.pop_back();
      if (!line.empty()) last = line;
      line.clear();
    }
  }
  if (!line.empty()) last = line;
  std::fclose(f);
  return last.empty() ? "(empty log)" : MessageText(last, 300);
}

std::string ShardProgress::Text() const {
  return fmt::format("slurm: {}/{} shards done, {} running, {} queued", done, total, running,
                     queued);
}

ShardArray::ShardArray(ShardArrayOptions options)
    : options_(std::move(options)),
      script_(options_.work_dir / "driftlab-shard.sh"),
      attempts_(options_.shards, 1) {}

fs::path ShardArray::ShardPath(uint32_t i) const {
  return options_.work_dir / fmt::format("shard-{}.json", i);
}

fs::path ShardArray::LogPath(uint32_t i) const {
  return options_.work_dir / fmt::format("shard-{}.log", i);
}

void ShardArray::Prepare(const fs::path& driftlab_binary, const fs::path& job_path,
                         const std::vector<std::string>& extra_args) {
  const uint32_t k = options_.shards;
  fs::create_directories(options_.work_dir);
  for (uint32_t i = 0; i < k; ++i) {  // no stale shard result from an earlier run
    const fs::path shard = ShardPath(i);
    if (fs::is_symlink(shard) || fs::is_regular_file(shard)) {
      fs::remove(shard);
    } else if (fs::exists(shard)) {
      throw SpecError("--slurm-dir", shard.string() + " (not a regular file)",
                      "a directory whose shard-*.json are results or absent");
    }
  }
  std::string run = fmt::format(
      "exec {} run {} --quiet --shard \"${{SLURM_ARRAY_TASK_ID}}/{}\" --out {}/shard-\"${{"
      "SLURM_ARRAY_TASK_ID}}\".json --threads \"${{SLURM_CPUS_PER_TASK:-0}}\"",
      ShellQuote(driftlab_binary.string()), ShellQuote(job_path.string()), k,
      ShellQuote(options_.work_dir.string()));
  for (const std::string& arg : extra_args) run += " " + ShellQuote(arg);
  WriteOutputFile(script_,
                  "#!/bin/sh\n# Written by driftlab: array task i runs shard i of " +
                      std::to_string(k) + ".\n" + run + "\n",
                  "--slurm-dir");
}

std::string ShardArray::Submit(const std::string& array) {
  std::vector<std::string> args = {"sbatch",
                                   "--parsable",
                                   "--job-name=" + options_.job_name,
                                   "--array=" + array,
                                   "--open-mode=append",
                                   "--output=" + (options_.work_dir / "shard-%a.log").string()};
  if (!options_.partition.empty()) args.push_back("--partition=" + options_.partition);
  args.push_back(script_.string());
  const CommandOutput r = RunCommand(args);
  std::string id = r.text.substr(0, r.text.find_first_of(";\n"));
  const bool numeric = !id.empty() && id.find_first_not_of("0123456789") == std::string::npos;
  if (r.status != 0 || !numeric) {
    throw SlurmError(
        fmt::format("sbatch failed (status {}): {}", r.status, MessageText(r.text, 500)));
  }
  job_ids_.push_back(id);
  return id;
}

std::string ShardArray::SubmitAll() { return Submit(fmt::format("0-{}", options_.shards - 1)); }

void ShardArray::Attach(const std::vector<std::string>& job_ids) {
  job_ids_ = job_ids;
  attempts_.assign(options_.shards, 1);
}

std::optional<ShardProgress> ShardArray::Poll(std::vector<std::string>* notes,
                                              std::string* warning) {
  const uint32_t k = options_.shards;
  // Tasks still queued or running: "ARRAY_JOB_ID TASK_ID STATE" per task (-r: one line each).
  const CommandOutput q = RunCommand({"squeue", "-h", "-r", "-o", "%F %K %T"});
  if (q.status != 0) {
    *warning = fmt::format("squeue failed (status {}): {}", q.status, MessageText(q.text, 300));
    return std::nullopt;
  }
  const std::set<std::string> ours(job_ids_.begin(), job_ids_.end());
  std::set<uint32_t> active;
  uint32_t running = 0;
  std::istringstream lines(q.text);
  std::string array_id, task, state;
  while (lines >> array_id >> task >> state) {
    if (ours.count(array_id) == 0) continue;
    uint32_t index = 0;
    if (std::sscanf(task.c_str(), "%u", &index) == 1) active.insert(index);
    running += state == "RUNNING" ? 1 : 0;
  }
  ShardProgress progress;
  progress.total = k;
  std::vector<uint32_t> failed;
  for (uint32_t i = 0; i < k; ++i) {
    if (fs::exists(ShardPath(i))) {
      ++progress.done;
      progress.done_shards.push_back(i);
    } else if (active.count(i) == 0) {
      failed.push_back(i);  // left the queue without writing its result
    }
  }
  progress.running = running;
  progress.queued = static_cast<uint32_t>(active.size()) - running;
  for (const uint32_t i : failed) {
    if (attempts_[i] >= options_.max_attempts) {
      Cancel();
      throw SlurmError(
          fmt::format("shard {}/{} failed {} times (log {}: {}); the other shards were cancelled",
                      i, k, attempts_[i], LogPath(i).string(), LastLine(LogPath(i))));
    }
    std::string again;
    try {
      again = Submit(std::to_string(i));
    } catch (const SlurmError&) {
      Cancel();
      throw;
    }
    ++attempts_[i];
    ++progress.queued;
    notes->push_back(
        fmt::format("slurm: shard {}/{} ended without a result (log {}: {}); resubmitted as job {}",
                    i, k, LogPath(i).string(), LastLine(LogPath(i)), again));
  }
  return progress;
}

bool ShardArray::Cancel() {
  if (job_ids_.empty()) return true;
  std::vector<std::string> args = {"scancel"};
  args.insert(args.end(), job_ids_.begin(), job_ids_.end());
  return RunCommand(args).status == 0;
}

int ShardArray::TasksInQueue() {
  const CommandOutput q = RunCommand({"squeue", "-h", "-r", "-o", "%F"});
  if (q.status != 0) return -1;
  const std::set<std::string> ours(job_ids_.begin(), job_ids_.end());
  int count = 0;
  std::istringstream lines(q.text);
  std::string id;
  while (lines >> id) count += ours.count(id) ? 1 : 0;
  return count;
}

v1::JobResult MergeShardResults(const fs::path& work_dir, uint32_t shards,
                                const std::string& engine_version) {
  std::vector<v1::JobResult> results;
  std::vector<std::string> names;
  for (uint32_t i = 0; i < shards; ++i) {
    names.push_back((work_dir / fmt::format("shard-{}.json", i)).string());
    results.push_back(app::ReadJobResult(names.back()));
  }
  return app::MergeJobResults(results, names, engine_version);
}

v1::JobResult ShardArray::Merge(const std::string& engine_version) const {
  return MergeShardResults(options_.work_dir, options_.shards, engine_version);
}

}  // namespace driftlab::slurm
