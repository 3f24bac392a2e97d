#include "slurm_run.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <thread>
#include <vector>

#include "commands.h"
#include "driftlab/jobspec/job_file.h"
#include "driftlab/jobspec/monte_carlo_job.h"
#include "driftlab/jobspec/result_file.h"
#include "driftlab/output_files.h"
#include "driftlab/spec_error.h"
#include "interrupt.h"
#include "remote.h"
#include "run_output.h"

extern char** environ;

namespace driftlab::cli {
namespace {

namespace fs = std::filesystem;

// Attempts per shard: the first and one resubmission (a node lost, a task killed by scancel).
constexpr int kMaxAttempts = 2;
constexpr auto kPollInterval = std::chrono::milliseconds(500);

struct CommandOutput {
  int status = -1;   // exit status, 128 + signal, or -1 when the program could not be started
  std::string text;  // stdout and stderr together
};

// Runs argv[0] (searched on PATH) with the arguments, without a shell; returns its status and
// output.
CommandOutput RunCommand(const std::vector<std::string>& args) {
  CommandOutput result;
  int pipe_fds[2];
  if (pipe(pipe_fds) != 0) return result;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDERR_FILENO);
  posix_spawn_file_actions_addclose(&actions, pipe_fds[0]);
  std::vector<std::string> copy = args;
  std::vector<char*> argv;
  for (std::string& a : copy) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  close(pipe_fds[1]);
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

// 'text' for sh, with ' written as '\''.
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

fs::path ShardPath(const fs::path& dir, uint32_t i) {
  return dir / fmt::format("shard-{}.json", i);
}

}  // namespace

int RunOnSlurm(const SlurmRunOptions& options) {
  // The job is validated here, before anything is submitted: the tasks then only run it.
  fs::path work_dir;
  try {
    const jobspec::JobFile file = jobspec::LoadJobFile(options.job_path);
    jobspec::MonteCarloOverrides overrides;
    overrides.runs = options.runs;
    overrides.seed = options.seed;
    overrides.covariance = options.covariance;
    const MonteCarloSpec spec = jobspec::ToMonteCarloSpec(file, overrides);
    if (options.shards < 1 || options.shards > spec.runs || options.shards > 100000) {
      throw SpecError("--shards", std::to_string(options.shards),
                      fmt::format("1 .. the job's runs ({}), at most 100000", spec.runs));
    }
    CheckOutputPath(options.out, "--out");
    if (options.report) CheckOutputPath(*options.report, "--report");
    work_dir = fs::absolute(options.work_dir.empty() ? options.out + ".slurm" : options.work_dir);
    if (fs::exists(work_dir) && !fs::is_directory(work_dir)) {
      throw SpecError("--slurm-dir", work_dir.string(), "a directory (or a path to create one)");
    }
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }

  const uint32_t k = options.shards;
  std::string script;
  try {
    fs::create_directories(work_dir);
    for (uint32_t i = 0; i < k; ++i) {  // no stale shard result from an earlier run
      const fs::path shard = ShardPath(work_dir, i);
      if (fs::is_symlink(shard) || fs::is_regular_file(shard)) {
        fs::remove(shard);
      } else if (fs::exists(shard)) {
        throw SpecError("--slurm-dir", shard.string() + " (not a regular file)",
                        "a directory whose shard-*.json are results or absent");
      }
    }
    const fs::path self = fs::read_symlink("/proc/self/exe");
    std::string run = fmt::format(
        "exec {} run {} --quiet --shard \"${{SLURM_ARRAY_TASK_ID}}/{}\" --out {}/shard-\"${{"
        "SLURM_ARRAY_TASK_ID}}\".json --threads \"${{SLURM_CPUS_PER_TASK:-0}}\"",
        ShellQuote(self.string()), ShellQuote(fs::absolute(options.job_path).string()), k,
        ShellQuote(work_dir.string()));
    if (options.runs) run += fmt::format(" --runs {}", *options.runs);
    if (options.seed) run += fmt::format(" --seed {}", *options.seed);
    if (options.covariance) run += " --covariance";
    const fs::path script_path = work_dir / "driftlab-shard.sh";
    WriteOutputFile(
        script_path,
        "#!/bin/sh\n# Written by `driftlab run --slurm`: array task i runs shard i of " +
            std::to_string(k) + ".\n" + run + "\n",
        "--slurm-dir");
    script = script_path.string();
  } catch (const std::exception& e) {
    fmt::print(stderr, "error: {}: {}\n", work_dir.string(), e.what());
    return kExitFailure;
  }

  // sbatch of the tasks `array` ("0-3" or "2"); returns the array job id or "" (message printed).
  auto submit = [&](const std::string& array) -> std::string {
    std::vector<std::string> args = {"sbatch",
                                     "--parsable",
                                     "--job-name=driftlab",
                                     "--array=" + array,
                                     "--open-mode=append",
                                     "--output=" + (work_dir / "shard-%a.log").string()};
    if (!options.partition.empty()) args.push_back("--partition=" + options.partition);
    args.push_back(script);
    const CommandOutput r = RunCommand(args);
    std::string id = r.text.substr(0, r.text.find_first_of(";\n"));
    const bool numeric = !id.empty() && id.find_first_not_of("0123456789") == std::string::npos;
    if (r.status != 0 || !numeric) {
      fmt::print(stderr, "error: sbatch failed (status {}): {}\n", r.status,
                 MessageText(r.text, 500));
      return "";
    }
    return id;
  };

  std::vector<std::string> jobs;  // array job ids submitted (first, then resubmissions)
  const std::string first = submit(fmt::format("0-{}", k - 1));
  if (first.empty()) return kExitFailure;
  jobs.push_back(first);
  fmt::print(stderr, "slurm: submitted job {} ({} array tasks; logs and shards in {})\n", first, k,
             work_dir.string());

  auto cancel_all = [&jobs] {
    std::vector<std::string> args = {"scancel"};
    args.insert(args.end(), jobs.begin(), jobs.end());
    RunCommand(args);
  };
  std::atomic<bool> interrupted{false};
  std::vector<int> attempts(k, 1);
  std::string last_progress;
  {
    InterruptWatch watch([&interrupted] { interrupted.store(true); });
    const auto deadline = std::chrono::steady_clock::now() +
                          std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                              std::chrono::duration<double>(options.timeout_s));
    while (true) {
      if (interrupted.load()) {
        cancel_all();
        fmt::print(stderr, "cancelled: scancel {}; nothing written\n", fmt::join(jobs, " "));
        return kExitCancelled;
      }
      if (std::chrono::steady_clock::now() > deadline) {
        cancel_all();
        fmt::print(stderr, "error: the Slurm job did not finish within {} s; cancelled\n",
                   options.timeout_s);
        return kExitFailure;
      }
      // Tasks still queued or running: "ARRAY_JOB_ID TASK_ID STATE" per task (-r: one line each).
      const CommandOutput q = RunCommand({"squeue", "-h", "-r", "-o", "%F %K %T"});
      if (q.status != 0) {
        fmt::print(stderr, "warning: squeue failed (status {}): {}\n", q.status,
                   MessageText(q.text, 300));
        std::this_thread::sleep_for(kPollInterval);
        continue;
      }
      const std::set<std::string> ours(jobs.begin(), jobs.end());
      std::set<uint32_t> active;
      int running = 0;
      std::istringstream lines(q.text);
      std::string array_id, task, state;
      while (lines >> array_id >> task >> state) {
        if (ours.count(array_id) == 0) continue;
        uint32_t index = 0;
        if (std::sscanf(task.c_str(), "%u", &index) == 1) active.insert(index);
        running += state == "RUNNING" ? 1 : 0;
      }
      uint32_t done = 0;
      std::vector<uint32_t> failed;
      for (uint32_t i = 0; i < k; ++i) {
        if (fs::exists(ShardPath(work_dir, i))) {
          ++done;
        } else if (active.count(i) == 0) {
          failed.push_back(i);  // left the queue without writing its result
        }
      }
      const std::string progress =
          fmt::format("slurm: {}/{} shards done, {} running, {} queued", done, k, running,
                      active.size() - static_cast<size_t>(running));
      if (!options.quiet && progress != last_progress) {
        fmt::print(stderr, "{}\n", progress);
        last_progress = progress;
      }
      if (done == k) break;
      for (const uint32_t i : failed) {
        const fs::path log = work_dir / fmt::format("shard-{}.log", i);
        if (attempts[i] >= kMaxAttempts) {
          cancel_all();
          fmt::print(stderr,
                     "error: shard {}/{} failed {} times (log {}: {}); the other shards were "
                     "cancelled\n",
                     i, k, attempts[i], log.string(), LastLine(log));
          return kExitFailure;
        }
        const std::string again = submit(std::to_string(i));
        if (again.empty()) {
          cancel_all();
          return kExitFailure;
        }
        jobs.push_back(again);
        ++attempts[i];
        fmt::print(stderr,
                   "slurm: shard {}/{} ended without a result (log {}: {}); resubmitted "
                   "as job {}\n",
                   i, k, log.string(), LastLine(log), again);
      }
      std::this_thread::sleep_for(kPollInterval);
    }
  }

  std::vector<v1::JobResult> shards;
  std::vector<std::string> names;
  v1::JobResult result;
  try {
    for (uint32_t i = 0; i < k; ++i) {
      names.push_back(ShardPath(work_dir, i).string());
      shards.push_back(jobspec::ReadJobResult(names.back()));
    }
    result = jobspec::MergeJobResults(shards, names, DRIFTLAB_VERSION);
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitFailure;
  }
  return PrintAndWriteOutputs(result, options.out, options.report);
}

}  // namespace driftlab::cli
