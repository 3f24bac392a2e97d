#include "slurm_run.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "commands.h"
#include "driftlab/app/job_file.h"
#include "driftlab/app/monte_carlo_job.h"
#include "driftlab/app/translate.h"
#include "driftlab/output_files.h"
#include "driftlab/slurm/shard_array.h"
#include "driftlab/spec_error.h"
#include "interrupt.h"
#include "remote.h"
#include "run_output.h"

namespace driftlab::cli {
namespace {

namespace fs = std::filesystem;

constexpr auto kPollInterval = std::chrono::milliseconds(500);

}  // namespace

int RunOnSlurm(const SlurmRunOptions& options) {
  // The job is validated here, before anything is submitted: the tasks then only run it.
  fs::path work_dir;
  try {
    const app::JobFile file = app::LoadJobFile(options.job_path);
    app::MonteCarloOverrides overrides;
    overrides.runs = options.runs;
    overrides.seed = options.seed;
    overrides.covariance = options.covariance;
    const MonteCarloSpec spec = app::ToMonteCarloSpec(file, overrides);
    if (options.shards < 1 || options.shards > spec.runs || options.shards > 100000) {
      throw SpecError("--shards", std::to_string(options.shards),
                      fmt::format("1 .. the job's runs ({}), at most 100000", spec.runs));
    }
    std::vector<CommandPath> inputs = {{options.job_path, "JOB"}};
    for (const CommandPath& p : app::JobInputFiles(file.job, file.base_dir)) inputs.push_back(p);
    CheckCommandOutputs(inputs, {{options.out, "--out"}, {options.report.value_or(""), "--report"}},
                        /*creates_directories=*/true);
    work_dir = fs::absolute(options.work_dir.empty() ? options.out + ".slurm" : options.work_dir);
    if (fs::exists(work_dir) && !fs::is_directory(work_dir)) {
      throw SpecError("--slurm-dir", work_dir.string(), "a directory (or a path to create one)");
    }
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }

  slurm::ShardArrayOptions array_options;
  array_options.work_dir = work_dir;
  array_options.shards = options.shards;
  array_options.partition = options.partition;
  slurm::ShardArray array(array_options);
  try {
    std::vector<std::string> extra;
    if (options.runs) extra.insert(extra.end(), {"--runs", std::to_string(*options.runs)});
    if (options.seed) extra.insert(extra.end(), {"--seed", std::to_string(*options.seed)});
    if (options.covariance) extra.push_back("--covariance");
    array.Prepare(fs::read_symlink("/proc/self/exe"), fs::absolute(options.job_path), extra);
  } catch (const std::exception& e) {
    fmt::print(stderr, "error: {}: {}\n", work_dir.string(), e.what());
    return kExitFailure;
  }
  try {
    const std::string first = array.SubmitAll();
    fmt::print(stderr, "slurm: submitted job {} ({} array tasks; logs and shards in {})\n", first,
               options.shards, work_dir.string());
  } catch (const slurm::SlurmError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitFailure;
  }

  std::atomic<bool> interrupted{false};
  std::string last_progress;
  {
    InterruptWatch watch([&interrupted] { interrupted.store(true); });
    const auto deadline = std::chrono::steady_clock::now() +
                          std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                              std::chrono::duration<double>(options.timeout_s));
    while (true) {
      if (interrupted.load()) {
        array.Cancel();
        fmt::print(stderr, "cancelled: scancel {}; nothing written\n",
                   fmt::join(array.job_ids(), " "));
        return kExitCancelled;
      }
      if (std::chrono::steady_clock::now() > deadline) {
        array.Cancel();
        fmt::print(stderr, "error: the Slurm job did not finish within {} s; cancelled\n",
                   options.timeout_s);
        return kExitFailure;
      }
      std::vector<std::string> notes;
      std::string warning;
      std::optional<slurm::ShardProgress> progress;
      try {
        progress = array.Poll(&notes, &warning);
      } catch (const slurm::SlurmError& e) {
        fmt::print(stderr, "error: {}\n", e.what());
        return kExitFailure;
      }
      if (!progress) {
        fmt::print(stderr, "warning: {}\n", warning);
        std::this_thread::sleep_for(kPollInterval);
        continue;
      }
      const std::string text = progress->Text();
      if (!options.quiet && text != last_progress) {
        fmt::print(stderr, "{}\n", text);
        last_progress = text;
      }
      for (const std::string& note : notes) fmt::print(stderr, "{}\n", note);
      if (progress->done == progress->total) break;
      std::this_thread::sleep_for(kPollInterval);
    }
  }

  v1::JobResult result;
  try {
    result = array.Merge(DRIFTLAB_VERSION);
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitFailure;
  }
  return PrintAndWriteOutputs(result, options.out, options.report);
}

}  // namespace driftlab::cli
