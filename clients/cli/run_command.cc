// `driftlab run JOB [--runs N] [--seed S] [--threads T] [--shard i/K] --out RESULT
//  [--report REPORT.html]`: the Monte-Carlo job in-process, its result as protobuf JSON, and
// optionally the HTML report. `driftlab merge SHARD... --out RESULT [--report REPORT.html]`
// combines shards of one job into the result a single process gives, bit for bit.
//
// Progress goes to stderr: a bar redrawn in place when stderr is a terminal, otherwise a plain
// line at every 10 % of the runs. Ctrl-C (SIGINT) or SIGTERM cancels the job: the engine stops
// within about 1024 samples per worker, nothing is written, and the exit status is 130.
//
// With `--server ADDR [--token T] [--tls-ca F]` the job runs on a driftlab-server instead: it is
// submitted (Jobs.Submit, validated by the server exactly as here), the progress bar follows
// Jobs.Watch, and the result (Jobs.GetResult) is printed and written exactly as a local result;
// Ctrl-C while watching cancels the remote job (Jobs.Cancel), nothing is written, exit status 130.
#include <fmt/format.h>
#include <sys/resource.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "commands.h"
#include "driftlab/app/consistency_check.h"
#include "driftlab/app/job_file.h"
#include "driftlab/app/job_validator.h"
#include "driftlab/app/monte_carlo_job.h"
#include "driftlab/app/result_file.h"
#include "driftlab/app/translate.h"
#include "driftlab/monte_carlo.h"
#include "driftlab/output_files.h"
#include "driftlab/report/html_report.h"
#include "driftlab/spec_error.h"
#include "progress.h"
#include "remote.h"
#include "run_output.h"
#include "slurm_run.h"

namespace driftlab::cli {
namespace {

std::atomic<bool> g_cancel{false};
extern "C" void OnSignal(int) { g_cancel.store(true); }

double ProcessCpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  auto seconds = [](const timeval& t) { return t.tv_sec + 1e-6 * t.tv_usec; };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

}  // namespace

void PrintFinalSummary(const v1::JobResult& result) {
  const v1::EpochStatistics& final_epoch = result.epochs(result.epochs_size() - 1);
  fmt::print("{}: runs {}..{} of {}, seed {}, final epoch t = {:.3f} s\n",
             result.job().name().empty() ? "(unnamed)" : result.job().name(), result.first_run(),
             result.first_run() + result.run_count() - 1, result.runs(), result.seed(),
             final_epoch.t_s());
  fmt::print("{:<30}{:>12}{:>12}{:>26}{:>12}\n", "final error", "mean", "std", "std 95 % CI",
             "rms");
  for (const v1::ComponentStatistics& c : final_epoch.components()) {
    const std::string name =
        fmt::format("{} [{}]", app::ComponentKey(c.component()), app::ComponentUnit(c.component()));
    fmt::print("{:<30}{:>12.4e}{:>12.4e}  [{:>10.4e}, {:>10.4e}]{:>12.4e}\n", name, c.mean(),
               c.std(), c.std_ci95_low(), c.std_ci95_high(), c.rms());
  }
  const v1::Checkpoint& last = result.checkpoints(result.checkpoints_size() - 1);
  fmt::print("horizontal: CEP50 {:.4g} m, CEP95 {:.4g} m, 2DRMS {:.4g} m, max {:.4g} m\n",
             last.cep50_m(), last.cep95_m(), last.drms2_m(),
             last.components(static_cast<int>(ErrorComponent::kHorizontalPosition)).max_abs());
  const v1::Timings& t = result.timings();
  fmt::print("{} samples in {:.2f} s wall ({:.3g} samples/s, {} threads)\n", t.samples(),
             t.wall_s(), t.samples_per_s(), t.threads());
  // Say when the filter or the covariance analysis is wrong about its own uncertainty
  // (a shard holds too few runs to judge: only whole results are tested).
  if (result.run_count() == result.runs()) {
    const app::ConsistencyVerdict verdict = app::AssessConsistency(result);
    if (verdict.tested()) {
      if (verdict.consistent()) {
        fmt::print("consistency: {}\n", verdict.Summary());
      } else {
        std::fflush(stdout);
        fmt::print(stderr, "warning: consistency: {}\n", verdict.Summary());
      }
    }
  }
}

// Writes the result and the report; SpecError for I/O problems (named by the file).
void WriteOutputs(const v1::JobResult& result, const std::string& out,
                  const std::optional<std::string>& report) {
  const std::filesystem::path out_path(out);
  if (out_path.has_parent_path()) std::filesystem::create_directories(out_path.parent_path());
  app::WriteJobResult(out_path, result);
  fmt::print("wrote {}\n", out);
  if (report) {
    const std::filesystem::path report_path(*report);
    if (report_path.has_parent_path()) {
      std::filesystem::create_directories(report_path.parent_path());
    }
    WriteOutputFile(report_path, app::RenderHtmlReport(result), "--report");
    fmt::print("wrote {}\n", *report);
  }
}

int PrintAndWriteOutputs(const v1::JobResult& result, const std::string& out,
                         const std::optional<std::string>& report) {
  try {
    PrintFinalSummary(result);
    WriteOutputs(result, out, report);
  } catch (const std::exception& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitFailure;
  }
  return kExitOk;
}

namespace {

struct RunOptions {
  std::string job_path;
  std::string out;
  std::optional<std::string> report;
  std::optional<uint32_t> runs;
  std::optional<uint64_t> seed;
  std::optional<int> threads;
  std::optional<std::string> shard;
  bool quiet = false;
  bool covariance = false;
  std::optional<double> max_memory_gb;
  RemoteOptions remote;
  bool slurm = false;
  uint32_t slurm_shards = 4;
  std::optional<uint32_t> slurm_shards_option;
  std::string slurm_partition;
  std::string slurm_dir;
};

int RunRun(const RunOptions& options) {
  if (options.slurm) {
    const char* conflict = !options.remote.server.empty() ? "--server"
                           : options.shard                ? "--shard"
                           : options.threads              ? "--threads"
                                                          : nullptr;
    if (conflict != nullptr) {
      fmt::print(stderr,
                 "error: --slurm: given with {} is not allowed; allowed: --slurm alone (the tasks "
                 "take the array's CPUs and shards)\n",
                 conflict);
      return kExitBadJob;
    }
    SlurmRunOptions slurm;
    slurm.job_path = options.job_path;
    slurm.out = options.out;
    slurm.report = options.report;
    slurm.runs = options.runs;
    slurm.seed = options.seed;
    slurm.covariance = options.covariance;
    slurm.quiet = options.quiet;
    slurm.shards = options.slurm_shards;
    slurm.partition = options.slurm_partition;
    slurm.work_dir = options.slurm_dir;
    return RunOnSlurm(slurm);
  }
  if (!options.remote.server.empty()) {
    if (options.threads) {
      fmt::print(stderr,
                 "note: --threads is not used with --server (the server sets each job's "
                 "threads)\n");
    }
    return RunRemoteJob(options.remote,
                        {options.job_path, options.runs, options.seed, options.shard, options.out,
                         options.report, options.quiet, options.covariance});
  }
  app::JobFile file;
  MonteCarloSpec spec;
  try {
    file = app::LoadJobFile(options.job_path);
    app::JobValidationOptions validation;
    app::MonteCarloOverrides& overrides = validation.overrides;
    overrides.runs = options.runs;
    overrides.seed = options.seed;
    overrides.threads = options.threads;
    overrides.covariance = options.covariance;
    if (options.max_memory_gb)
      overrides.max_memory_bytes = MemoryLimitBytes(*options.max_memory_gb);
    if (options.shard) app::ParseShard(*options.shard, &overrides);
    std::vector<CommandPath> inputs = {{options.job_path, "JOB"}};
    for (const CommandPath& p : app::JobInputFiles(file.job, file.base_dir)) inputs.push_back(p);
    CheckCommandOutputs(inputs, {{options.out, "--out"}, {options.report.value_or(""), "--report"}},
                        /*creates_directories=*/true);
    spec = app::ValidateJob(file, validation).spec;
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }

  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
  ProgressPrinter printer;
  const double cpu0_s = ProcessCpuSeconds();
  MonteCarloOutput output;
  try {
    output = RunMonteCarloWithAnalysis(
        spec,
        [&printer, &options](const MonteCarloProgress& p) {
          if (!options.quiet) printer.Update(p);
        },
        &g_cancel);
    printer.Finish();
  } catch (const SpecError& e) {
    printer.Finish();
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }
  if (output.statistics.cancelled()) {
    fmt::print(stderr, "cancelled: nothing written\n");
    return kExitCancelled;
  }
  const double cpu_s = ProcessCpuSeconds() - cpu0_s;
  v1::JobResult result;
  try {
    result = app::ToJobResult(app::JobAsRun(file.job, spec), output, DRIFTLAB_VERSION, cpu_s);
  } catch (const std::exception& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitFailure;
  }
  return PrintAndWriteOutputs(result, options.out, options.report);
}

struct MergeOptions {
  std::vector<std::string> shards;
  std::string out;
  std::optional<std::string> report;
};

int RunMerge(const MergeOptions& options) {
  std::vector<v1::JobResult> shards;
  v1::JobResult result;
  try {
    std::vector<CommandPath> inputs;
    for (const std::string& path : options.shards) inputs.push_back({path, "SHARD"});
    CheckCommandOutputs(inputs, {{options.out, "--out"}, {options.report.value_or(""), "--report"}},
                        /*creates_directories=*/true);
    for (const std::string& path : options.shards) shards.push_back(app::ReadJobResult(path));
    result = app::MergeJobResults(shards, options.shards, DRIFTLAB_VERSION);
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }
  return PrintAndWriteOutputs(result, options.out, options.report);
}

const RegisterCommand kRun("run", [](CLI::App& app) -> std::function<int()> {
  auto options = std::make_shared<RunOptions>();
  CLI::App* command = app.add_subcommand(
      "run",
      "Run the job's Monte-Carlo analysis in-process; write the result (protobuf JSON) and "
      "optionally the HTML report");
  command->add_option("job", options->job_path, "Job file (.json, .yaml, .yml)")->required();
  command->add_option("--out,-o", options->out, "Result file (.json)")->required();
  command->add_option("--report", options->report, "Also write this HTML report");
  AddUnsignedOption(command, "--runs", &options->runs,
                    "Runs (default: the job's monte_carlo.runs)");
  AddUnsignedOption(command, "--seed", &options->seed,
                    "Seed (default: the job's monte_carlo.seed)");
  command->add_option("--threads", options->threads, "Worker threads (default 0 = all cores)");
  command->add_option("--shard", options->shard,
                      "Run only shard i of K (i/K, 0 <= i < K); combine with `driftlab merge`");
  command->add_flag("--quiet,-q", options->quiet, "No progress output");
  command->add_option("--max-memory-gb", options->max_memory_gb,
                      "Refuse a job needing more memory than this (default 8 GB; 0 = no limit)");
  command->add_flag(
      "--covariance", options->covariance,
      "Add the linear covariance analysis (predicted sigma of every error component)");
  AddRemoteOptions(command, &options->remote, /*server_required=*/false);
  command->add_flag("--slurm", options->slurm,
                    "Run the shards as a Slurm job array (sbatch), then merge them here");
  AddUnsignedOption(command, "--shards", &options->slurm_shards_option,
                    "With --slurm: array tasks, one shard each (default 4)");
  command->add_option("--partition", options->slurm_partition,
                      "With --slurm: the Slurm partition (default: the cluster's)");
  command->add_option(
      "--slurm-dir", options->slurm_dir,
      "With --slurm: shared directory for the shards and logs (default RESULT.slurm)");
  return [options] {
    if (!options->slurm && (options->slurm_shards_option || !options->slurm_partition.empty() ||
                            !options->slurm_dir.empty())) {
      fmt::print(stderr,
                 "error: --shards, --partition, --slurm-dir: given without --slurm is not "
                 "allowed; allowed: with --slurm only\n");
      return kExitBadJob;
    }
    if (options->slurm_shards_option) options->slurm_shards = *options->slurm_shards_option;
    return RunRun(*options);
  };
});

const RegisterCommand kMerge("merge", [](CLI::App& app) -> std::function<int()> {
  auto options = std::make_shared<MergeOptions>();
  CLI::App* command = app.add_subcommand(
      "merge", "Merge the shard results of one job (`run --shard i/K`) into one result");
  command->add_option("shards", options->shards, "Shard result files")->required();
  command->add_option("--out,-o", options->out, "Merged result file (.json)")->required();
  command->add_option("--report", options->report, "Also write this HTML report");
  return [options] { return RunMerge(*options); };
});

}  // namespace
}  // namespace driftlab::cli
