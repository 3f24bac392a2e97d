// The commands that only talk to a driftlab-server (Jobs and Datasets services of
// proto/driftlab/v1/service.proto); each takes --server ADDR (required), --token T (or the
// environment's DRIFTLAB_TOKEN) and --tls-ca F:
//   submit JOB [--runs N] [--seed S] [--shard i/K] [--deadline SECONDS]   prints the job id
//   status ID                                    one line: state, runs done, speed, error
//   watch ID                                     progress bar until the job's final state
//   cancel ID                                    cancels a queued or running job
//   result ID --out RESULT.json [--report R.html]  writes the result as `driftlab run` does
//   jobs [--state S]...                          this token's jobs, newest first
//   score JOB SOLUTION.csv [--seed S] [--run R] --out RESULT.json [--report R.html]
//       error statistics of an external navigation solution (CSV with a header row of the
//       column names `driftlab export --server --navigation` writes in navigation.csv) against
//       the truth of that seeded run, as a one-run result.
// Exit statuses as remote.h describes.
#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "commands.h"
#include "driftlab/app/calibration_job.h"
#include "driftlab/app/job_file.h"
#include "driftlab/spec_error.h"
#include "remote_client.h"
#include "run_output.h"

namespace driftlab::cli {
namespace {

// A channel and a Jobs stub, or the exit status of a bad --tls-ca.
struct JobsClient {
  std::unique_ptr<v1::Jobs::Stub> stub;
  int error = kExitOk;
};

JobsClient ConnectJobs(const RemoteOptions& options) {
  JobsClient client;
  try {
    client.stub = v1::Jobs::NewStub(MakeChannel(options));
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    client.error = kExitBadJob;
  }
  return client;
}

v1::JobRef Ref(const std::string& job_id) {
  v1::JobRef ref;
  ref.set_job_id(job_id);
  return ref;
}

// ---------------------------------------------------------------------------------------------

struct SubmitOptions {
  RemoteOptions remote;
  std::string job_path;
  std::optional<uint32_t> runs;
  std::optional<uint64_t> seed;
  std::optional<std::string> shard;
  std::optional<double> deadline_s;
};

int RunSubmit(const SubmitOptions& options) {
  v1::SubmitJobRequest request;
  try {
    *request.mutable_job() = app::LoadJobFile(options.job_path).job;
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }
  if (options.runs) request.set_runs(*options.runs);
  if (options.seed) request.set_seed(*options.seed);
  if (options.shard) request.set_shard(*options.shard);
  if (options.deadline_s) request.set_deadline_s(*options.deadline_s);
  JobsClient client = ConnectJobs(options.remote);
  if (client.error != kExitOk) return client.error;
  grpc::ClientContext context;
  PrepareContext(options.remote, &context);
  v1::JobStatus status;
  const grpc::Status rpc = client.stub->Submit(&context, request, &status);
  if (!rpc.ok()) return ReportRpcError(rpc, options.remote);
  fmt::print("{}\n", status.job_id());
  return kExitOk;
}

// ---------------------------------------------------------------------------------------------

struct JobIdOptions {
  RemoteOptions remote;
  std::string job_id;
};

int RunStatus(const JobIdOptions& options) {
  JobsClient client = ConnectJobs(options.remote);
  if (client.error != kExitOk) return client.error;
  grpc::ClientContext context;
  PrepareContext(options.remote, &context);
  v1::JobStatus status;
  const grpc::Status rpc = client.stub->Get(&context, Ref(options.job_id), &status);
  if (!rpc.ok()) return ReportRpcError(rpc, options.remote);
  fmt::print("{}\n", DescribeStatus(status));
  return kExitOk;
}

int RunWatch(const JobIdOptions& options) {
  JobsClient client = ConnectJobs(options.remote);
  if (client.error != kExitOk) return client.error;
  ProgressPrinter printer;
  const WatchOutcome watched =
      WatchJob(client.stub.get(), options.remote, options.job_id, &printer);
  if (watched.interrupted) {
    fmt::print(stderr, "stopped watching; job {} goes on at {} (`driftlab cancel` stops it)\n",
               options.job_id, options.remote.server);
    return kExitCancelled;
  }
  if (!watched.status.ok()) return ReportRpcError(watched.status, options.remote);
  if (!watched.last) {
    fmt::print(stderr, "error: {}: the Watch stream of job {} ended without a status\n",
               options.remote.server, options.job_id);
    return kExitFailure;
  }
  fmt::print("{}\n", DescribeStatus(*watched.last));
  return ReportFinalState(*watched.last);
}

int RunCancel(const JobIdOptions& options) {
  JobsClient client = ConnectJobs(options.remote);
  if (client.error != kExitOk) return client.error;
  grpc::ClientContext context;
  PrepareContext(options.remote, &context);
  v1::JobStatus status;
  const grpc::Status rpc = client.stub->Cancel(&context, Ref(options.job_id), &status);
  if (!rpc.ok()) return ReportRpcError(rpc, options.remote);
  fmt::print("{}\n", DescribeStatus(status));
  return kExitOk;
}

// ---------------------------------------------------------------------------------------------

struct ResultOptions {
  RemoteOptions remote;
  std::string job_id;
  std::string out;
  std::optional<std::string> report;
};

int RunResult(const ResultOptions& options) {
  try {
    CheckCommandOutputs({}, {{options.out, "--out"}, {options.report.value_or(""), "--report"}},
                        /*creates_directories=*/true);
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }
  JobsClient client = ConnectJobs(options.remote);
  if (client.error != kExitOk) return client.error;
  grpc::ClientContext context;
  PrepareContext(options.remote, &context);
  v1::JobResult result;
  const grpc::Status rpc = client.stub->GetResult(&context, Ref(options.job_id), &result);
  if (!rpc.ok()) return ReportRpcError(rpc, options.remote);
  return PrintAndWriteOutputs(result, options.out, options.report);
}

// ---------------------------------------------------------------------------------------------

struct JobsOptions {
  RemoteOptions remote;
  std::vector<std::string> states;
};

int RunJobs(const JobsOptions& options) {
  v1::ListJobsRequest request;
  for (const std::string& name : options.states) {
    v1::JobState state;
    if (!v1::JobState_Parse(name, &state) || state == v1::JOB_STATE_UNSPECIFIED) {
      fmt::print(stderr,
                 "error: --state: {} is not allowed; allowed: QUEUED, RUNNING, SUCCEEDED, FAILED, "
                 "CANCELLED\n",
                 name);
      return kExitBadJob;
    }
    request.add_states(state);
  }
  JobsClient client = ConnectJobs(options.remote);
  if (client.error != kExitOk) return client.error;
  size_t listed = 0;
  do {
    grpc::ClientContext context;
    PrepareContext(options.remote, &context);
    v1::ListJobsResponse page;
    const grpc::Status rpc = client.stub->List(&context, request, &page);
    if (!rpc.ok()) return ReportRpcError(rpc, options.remote);
    for (const v1::JobStatus& job : page.jobs()) fmt::print("{}\n", DescribeStatus(job));
    listed += static_cast<size_t>(page.jobs_size());
    request.set_page_token(page.next_page_token());
  } while (!request.page_token().empty());
  if (listed == 0) fmt::print(stderr, "no jobs\n");
  return kExitOk;
}

// ---------------------------------------------------------------------------------------------

struct ScoreOptions {
  RemoteOptions remote;
  std::string job_path;
  std::string solution_path;
  std::optional<uint64_t> seed;
  std::optional<uint32_t> run_index;
  std::string out;
  std::optional<std::string> report;
};

int RunScore(const ScoreOptions& options) {
  v1::ScoreSolutionRequest header;
  app::NumericTable table;
  std::unique_ptr<v1::Datasets::Stub> stub;
  try {
    CheckCommandOutputs({{options.job_path, "JOB"}, {options.solution_path, "SOLUTION"}},
                        {{options.out, "--out"}, {options.report.value_or(""), "--report"}},
                        /*creates_directories=*/true);
    v1::RunRef* run = header.mutable_header()->mutable_run();
    *run->mutable_job() = app::LoadJobFile(options.job_path).job;
    if (options.seed) run->set_seed(*options.seed);
    if (options.run_index) run->set_run_index(*options.run_index);
    table = app::ReadNumericCsv(options.solution_path);
    if (table.columns.empty() || table.rows() == 0) {
      throw SpecError(options.solution_path, "(empty)",
                      "a header row of column names and at least one row");
    }
    for (const std::string& column : table.columns) header.mutable_header()->add_columns(column);
    stub = v1::Datasets::NewStub(MakeChannel(options.remote));
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }

  grpc::ClientContext context;
  PrepareContext(options.remote, &context);
  v1::JobResult result;
  std::unique_ptr<grpc::ClientWriter<v1::ScoreSolutionRequest>> writer =
      stub->ScoreSolution(&context, &result);
  bool open = writer->Write(header);
  const size_t columns = table.columns.size();
  const size_t rows_per_chunk = RowsPerChunk(columns);
  v1::ScoreSolutionRequest chunk;
  for (size_t row = 0; open && row < table.rows(); row += rows_per_chunk) {
    const size_t end_row = std::min(table.rows(), row + rows_per_chunk);
    chunk.Clear();
    chunk.mutable_rows()->mutable_values()->Add(table.values.begin() + row * columns,
                                                table.values.begin() + end_row * columns);
    open = writer->Write(chunk);
  }
  if (open) writer->WritesDone();
  const grpc::Status rpc = writer->Finish();
  if (!rpc.ok()) return ReportRpcError(rpc, options.remote);
  return PrintAndWriteOutputs(result, options.out, options.report);
}

// ---------------------------------------------------------------------------------------------

CLI::App* AddJobIdCommand(CLI::App& app, const std::string& name, const std::string& help,
                          JobIdOptions* options) {
  CLI::App* command = app.add_subcommand(name, help);
  command->add_option("id", options->job_id, "Job id (as `driftlab submit` printed it)")
      ->required();
  AddRemoteOptions(command, &options->remote, /*server_required=*/true);
  return command;
}

const RegisterCommand kSubmit("submit", [](CLI::App& app) -> std::function<int()> {
  auto options = std::make_shared<SubmitOptions>();
  CLI::App* command =
      app.add_subcommand("submit", "Submit a job to a driftlab-server; prints the job id");
  command->add_option("job", options->job_path, "Job file (.json, .yaml, .yml)")->required();
  AddUnsignedOption(command, "--runs", &options->runs,
                    "Runs (default: the job's monte_carlo.runs)");
  AddUnsignedOption(command, "--seed", &options->seed,
                    "Seed (default: the job's monte_carlo.seed)");
  command->add_option("--shard", options->shard, "Run only shard i of K (i/K, 0 <= i < K)");
  command->add_option("--deadline", options->deadline_s,
                      "Cancel the job when it has not finished this many seconds after "
                      "submission (0 = none)");
  AddRemoteOptions(command, &options->remote, /*server_required=*/true);
  return [options] { return RunSubmit(*options); };
});

const RegisterCommand kStatus("status", [](CLI::App& app) -> std::function<int()> {
  auto options = std::make_shared<JobIdOptions>();
  AddJobIdCommand(app, "status", "Print a remote job's state and progress", options.get());
  return [options] { return RunStatus(*options); };
});

const RegisterCommand kWatch("watch", [](CLI::App& app) -> std::function<int()> {
  auto options = std::make_shared<JobIdOptions>();
  AddJobIdCommand(app, "watch",
                  "Follow a remote job's progress until it finishes (exit 0 when it succeeded)",
                  options.get());
  return [options] { return RunWatch(*options); };
});

const RegisterCommand kCancel("cancel", [](CLI::App& app) -> std::function<int()> {
  auto options = std::make_shared<JobIdOptions>();
  AddJobIdCommand(app, "cancel", "Cancel a queued or running remote job", options.get());
  return [options] { return RunCancel(*options); };
});

const RegisterCommand kResult("result", [](CLI::App& app) -> std::function<int()> {
  auto options = std::make_shared<ResultOptions>();
  CLI::App* command = app.add_subcommand(
      "result", "Fetch a finished remote job's result; write it (and the report) as `run` does");
  command->add_option("id", options->job_id, "Job id")->required();
  command->add_option("--out,-o", options->out, "Result file (.json)")->required();
  command->add_option("--report", options->report, "Also write this HTML report");
  AddRemoteOptions(command, &options->remote, /*server_required=*/true);
  return [options] { return RunResult(*options); };
});

const RegisterCommand kJobs("jobs", [](CLI::App& app) -> std::function<int()> {
  auto options = std::make_shared<JobsOptions>();
  CLI::App* command =
      app.add_subcommand("jobs", "List this token's jobs on a driftlab-server, newest first");
  command->add_option("--state", options->states,
                      "Only jobs in these states (QUEUED, RUNNING, SUCCEEDED, FAILED, CANCELLED)");
  AddRemoteOptions(command, &options->remote, /*server_required=*/true);
  return [options] { return RunJobs(*options); };
});

const RegisterCommand kScore("score", [](CLI::App& app) -> std::function<int()> {
  auto options = std::make_shared<ScoreOptions>();
  CLI::App* command = app.add_subcommand(
      "score",
      "Error statistics of an external navigation solution against the truth of one seeded run "
      "of the job (computed by the server), as a one-run result");
  command->add_option("job", options->job_path, "Job file (.json, .yaml, .yml)")->required();
  command
      ->add_option("solution", options->solution_path,
                   "Solution CSV: a header row of column names (t_s, lat_deg, lon_deg, height_m, "
                   "v_north_m_per_s, v_east_m_per_s, v_down_m_per_s, roll_deg, pitch_deg, "
                   "yaw_deg; any order), then one row per epoch")
      ->required();
  AddUnsignedOption(command, "--seed", &options->seed,
                    "Random seed (default: the job's monte_carlo.seed)");
  AddUnsignedOption(command, "--run", &options->run_index, "Run index (default 0)");
  command->add_option("--out,-o", options->out, "Result file (.json)")->required();
  command->add_option("--report", options->report, "Also write this HTML report");
  AddRemoteOptions(command, &options->remote, /*server_required=*/true);
  return [options] { return RunScore(*options); };
});

}  // namespace
}  // namespace driftlab::cli
