// The `driftlab` client side of the gRPC API: channels, metadata, status mapping, Watch with a
// progress bar and Ctrl-C, and the remote calibration (remote.h).
#include "remote.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "commands.h"
#include "driftlab/app/job_file.h"
#include "driftlab/input_files.h"
#include "driftlab/spec_error.h"
#include "interrupt.h"
#include "remote_client.h"
#include "run_output.h"

namespace driftlab::cli {
namespace {

const char* CodeName(grpc::StatusCode code) {
  switch (code) {
    case grpc::StatusCode::OK:
      return "OK";
    case grpc::StatusCode::CANCELLED:
      return "CANCELLED";
    case grpc::StatusCode::UNKNOWN:
      return "UNKNOWN";
    case grpc::StatusCode::INVALID_ARGUMENT:
      return "INVALID_ARGUMENT";
    case grpc::StatusCode::DEADLINE_EXCEEDED:
      return "DEADLINE_EXCEEDED";
    case grpc::StatusCode::NOT_FOUND:
      return "NOT_FOUND";
    case grpc::StatusCode::ALREADY_EXISTS:
      return "ALREADY_EXISTS";
    case grpc::StatusCode::PERMISSION_DENIED:
      return "PERMISSION_DENIED";
    case grpc::StatusCode::RESOURCE_EXHAUSTED:
      return "RESOURCE_EXHAUSTED";
    case grpc::StatusCode::FAILED_PRECONDITION:
      return "FAILED_PRECONDITION";
    case grpc::StatusCode::ABORTED:
      return "ABORTED";
    case grpc::StatusCode::OUT_OF_RANGE:
      return "OUT_OF_RANGE";
    case grpc::StatusCode::UNIMPLEMENTED:
      return "UNIMPLEMENTED";
    case grpc::StatusCode::INTERNAL:
      return "INTERNAL";
    case grpc::StatusCode::UNAVAILABLE:
      return "UNAVAILABLE";
    case grpc::StatusCode::DATA_LOSS:
      return "DATA_LOSS";
    case grpc::StatusCode::UNAUTHENTICATED:
      return "UNAUTHENTICATED";
    default:
      return "status";
  }
}

// A bearer token as RFC 6750 section 2.1 defines it (b64token: letters, digits, "-._~+/", then
// "=" padding), at most 4096 characters. Surrounding whitespace, as a token pasted with a Windows
// line ending carries, is removed; any other byte is refused here: gRPC aborts on metadata values
// with control or non-ASCII bytes.
std::string CheckToken(std::string& token) {
  const size_t first = token.find_first_not_of(" \t\r\n");
  const size_t last = token.find_last_not_of(" \t\r\n");
  token = first == std::string::npos ? std::string() : token.substr(first, last - first + 1);
  size_t i = 0;
  while (i < token.size() && (std::isalnum(static_cast<unsigned char>(token[i])) ||
                              std::string_view("-._~+/").find(token[i]) != std::string::npos)) {
    ++i;
  }
  while (i < token.size() && token[i] == '=') ++i;
  if (token.size() > 4096 || (!token.empty() && i == 0) || i != token.size()) {
    return fmt::format(
        "a token with {} is not allowed; allowed: at most 4096 characters of letters, digits "
        "and -._~+/ (then = padding), as RFC 6750 bearer tokens",
        token.size() > 4096 ? fmt::format("{} characters", token.size())
                            : fmt::format("the byte 0x{:02X} at position {}",
                                          static_cast<unsigned char>(token[i]), i + 1));
  }
  return "";
}

}  // namespace

CLI::Option* AddRemoteOptions(CLI::App* command, RemoteOptions* options, bool server_required) {
  CLI::Option* server = command->add_option(
      "--server", options->server,
      server_required ? "driftlab-server address HOST:PORT"
                      : "Run on this driftlab-server (HOST:PORT) instead of in-process");
  if (server_required) server->required();
  command
      ->add_option("--token", options->token,
                   "Bearer token for the server (default: environment DRIFTLAB_TOKEN)")
      ->envname("DRIFTLAB_TOKEN")
      ->transform(CLI::Validator(CheckToken, "TOKEN"));
  command->add_option("--tls-ca", options->tls_ca,
                      "PEM file of the CA that signed the server's certificate (enables TLS)");
  return server;
}

std::shared_ptr<grpc::Channel> MakeChannel(const RemoteOptions& options) {
  grpc::ChannelArguments arguments;
  // Results of large jobs exceed gRPC's default 4 MB receive limit; the server bounds them.
  arguments.SetMaxReceiveMessageSize(-1);
  if (options.tls_ca.empty()) {
    return grpc::CreateCustomChannel(options.server, grpc::InsecureChannelCredentials(), arguments);
  }
  grpc::SslCredentialsOptions ssl;
  ssl.pem_root_certs = ReadInputFile(options.tls_ca, kMaxSmallTextFileBytes, "--tls-ca");
  if (ssl.pem_root_certs.empty()) {
    throw SpecError("--tls-ca", options.tls_ca, "a PEM file of CA certificates (it is empty)");
  }
  return grpc::CreateCustomChannel(options.server, grpc::SslCredentials(ssl), arguments);
}

void PrepareContext(const RemoteOptions& options, grpc::ClientContext* context) {
  if (!options.token.empty()) context->AddMetadata("authorization", "Bearer " + options.token);
}

int ReportRpcError(const grpc::Status& status, const RemoteOptions& options) {
  // The server's text, printed as one bounded line whatever it holds.
  const std::string message = MessageText(status.error_message(), kMaxMessageTextBytes);
  switch (status.error_code()) {
    case grpc::StatusCode::OK:
      return kExitOk;
    case grpc::StatusCode::INVALID_ARGUMENT:
      fmt::print(stderr, "error: {}\n", message);
      return kExitBadJob;
    case grpc::StatusCode::UNAVAILABLE:
      fmt::print(stderr, "error: cannot reach {} ({})\n", options.server, message);
      return kExitFailure;
    case grpc::StatusCode::UNAUTHENTICATED:
      fmt::print(stderr,
                 "error: {} did not accept the credentials ({}); give a valid --token or set "
                 "DRIFTLAB_TOKEN\n",
                 options.server, message);
      return kExitFailure;
    case grpc::StatusCode::PERMISSION_DENIED:
      fmt::print(stderr, "error: {}: permission denied: {}\n", options.server, message);
      return kExitFailure;
    case grpc::StatusCode::NOT_FOUND:
      fmt::print(stderr,
                 "error: {}: not found: {} (a job is visible only to the token that "
                 "submitted it)\n",
                 options.server, message);
      return kExitFailure;
    case grpc::StatusCode::RESOURCE_EXHAUSTED:
      fmt::print(stderr, "error: {}: server limit reached: {}\n", options.server, message);
      return kExitFailure;
    default:
      fmt::print(stderr, "error: {}: {}: {}\n", options.server, CodeName(status.error_code()),
                 message);
      return kExitFailure;
  }
}

bool IsFinal(v1::JobState state) {
  return state == v1::SUCCEEDED || state == v1::FAILED || state == v1::CANCELLED;
}

MonteCarloProgress ToProgress(const v1::JobStatus& status) {
  MonteCarloProgress p;
  p.runs_done = status.runs_done();
  p.runs_total = status.runs_total();
  p.samples_done = static_cast<int64_t>(status.samples_done());
  p.samples_total = static_cast<int64_t>(status.samples_total());
  p.elapsed_s = status.elapsed_s();
  return p;
}

int ReportFinalState(const v1::JobStatus& status) {
  switch (status.state()) {
    case v1::SUCCEEDED:
      return kExitOk;
    case v1::FAILED:
      fmt::print(stderr, "error: job {} failed: {}\n", status.job_id(), status.error());
      return kExitBadJob;
    case v1::CANCELLED:
      fmt::print(stderr, "job {} was cancelled{}{}\n", status.job_id(),
                 status.error().empty() ? "" : ": ", status.error());
      return kExitFailure;
    default:
      fmt::print(stderr, "error: job {} is {} (not finished)\n", status.job_id(),
                 v1::JobState_Name(status.state()));
      return kExitFailure;
  }
}

std::string DescribeStatus(const v1::JobStatus& status) {
  std::string line =
      fmt::format("{}  {:<9}  {}", status.job_id(), v1::JobState_Name(status.state()),
                  status.name().empty() ? "(unnamed)" : status.name());
  if (status.has_runs_total()) {
    line += fmt::format("  {}/{} runs", status.runs_done(), status.runs_total());
  }
  if (status.has_elapsed_s()) line += fmt::format("  {:.1f} s", status.elapsed_s());
  if (status.has_samples_per_s() && status.samples_per_s() > 0) {
    line += fmt::format("  {:.2f} M samples/s", status.samples_per_s() / 1e6);
  }
  if (status.attempts() > 1) line += fmt::format("  attempt {}", status.attempts());
  if (!status.error().empty()) line += "  " + status.error();
  return line;
}

void ActiveCall::Set(grpc::ClientContext* context) {
  const std::lock_guard<std::mutex> lock(mutex_);
  context_ = context;
  if (cancelled_ && context_ != nullptr) context_->TryCancel();
}

void ActiveCall::Cancel() {
  const std::lock_guard<std::mutex> lock(mutex_);
  cancelled_ = true;
  if (context_ != nullptr) context_->TryCancel();
}

namespace {

WatchOutcome FollowWatch(v1::Jobs::Stub* stub, const RemoteOptions& options,
                         const std::string& job_id, ProgressPrinter* printer, ActiveCall* active) {
  WatchOutcome outcome;
  grpc::ClientContext context;
  PrepareContext(options, &context);
  active->Set(&context);
  v1::JobRef ref;
  ref.set_job_id(job_id);
  std::unique_ptr<grpc::ClientReader<v1::JobStatus>> reader = stub->Watch(&context, ref);
  v1::JobStatus status;
  while (reader->Read(&status)) {
    if (printer != nullptr) printer->Update(ToProgress(status));
    outcome.last = status;
  }
  outcome.status = reader->Finish();
  active->Set(nullptr);
  if (printer != nullptr) printer->Finish();
  return outcome;
}

}  // namespace

WatchOutcome WatchJob(v1::Jobs::Stub* stub, const RemoteOptions& options, const std::string& job_id,
                      ProgressPrinter* printer, ActiveCall* active) {
  if (active != nullptr) return FollowWatch(stub, options, job_id, printer, active);
  ActiveCall own;
  const InterruptWatch interrupt([&own] { own.Cancel(); });
  WatchOutcome outcome = FollowWatch(stub, options, job_id, printer, &own);
  outcome.interrupted = interrupt.interrupted();
  return outcome;
}

int RunRemoteJob(const RemoteOptions& options, const RemoteRunRequest& run) {
  v1::SubmitJobRequest request;
  std::shared_ptr<grpc::Channel> channel;
  try {
    CheckCommandOutputs({{run.job_path, "JOB"}},
                        {{run.out, "--out"}, {run.report.value_or(""), "--report"}},
                        /*creates_directories=*/true);
    *request.mutable_job() = app::LoadJobFile(run.job_path).job;
    if (run.covariance) request.mutable_job()->mutable_monte_carlo()->set_covariance(true);
    channel = MakeChannel(options);
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }
  if (run.runs) request.set_runs(*run.runs);
  if (run.seed) request.set_seed(*run.seed);
  if (run.shard) request.set_shard(*run.shard);
  std::unique_ptr<v1::Jobs::Stub> stub = v1::Jobs::NewStub(channel);
  v1::JobRef ref;

  // Ctrl-C from here on cancels the call in progress; once the job exists, the job too.
  ActiveCall active;
  const InterruptWatch interrupt([&active] { active.Cancel(); });
  v1::JobStatus submitted;
  {
    grpc::ClientContext context;
    PrepareContext(options, &context);
    active.Set(&context);
    const grpc::Status status = stub->Submit(&context, request, &submitted);
    active.Set(nullptr);
    if (!status.ok()) {
      if (interrupt.interrupted()) {
        fmt::print(stderr, "interrupted before the job was submitted: nothing written\n");
        return kExitCancelled;
      }
      return ReportRpcError(status, options);
    }
  }
  ref.set_job_id(submitted.job_id());
  if (!run.quiet) fmt::print(stderr, "submitted job {} to {}\n", ref.job_id(), options.server);

  ProgressPrinter printer;
  const WatchOutcome watched =
      WatchJob(stub.get(), options, ref.job_id(), run.quiet ? nullptr : &printer, &active);
  if (interrupt.interrupted()) {
    grpc::ClientContext context;
    PrepareContext(options, &context);
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
    v1::JobStatus cancelled;
    const grpc::Status status = stub->Cancel(&context, ref, &cancelled);
    if (!status.ok()) {
      ReportRpcError(status, options);
      fmt::print(stderr, "interrupted: job {} may still be running on {}\n", ref.job_id(),
                 options.server);
      return kExitCancelled;
    }
    fmt::print(stderr, "cancelled job {} ({}): nothing written\n", ref.job_id(),
               v1::JobState_Name(cancelled.state()));
    return kExitCancelled;
  }
  if (!watched.status.ok()) return ReportRpcError(watched.status, options);
  v1::JobStatus final_status = watched.last.value_or(submitted);
  if (!IsFinal(final_status.state())) {
    // The stream ended without a final state (the API says it does not): ask once more.
    grpc::ClientContext context;
    PrepareContext(options, &context);
    const grpc::Status status = stub->Get(&context, ref, &final_status);
    if (!status.ok()) return ReportRpcError(status, options);
  }
  if (final_status.state() != v1::SUCCEEDED) return ReportFinalState(final_status);

  v1::JobResult result;
  {
    grpc::ClientContext context;
    PrepareContext(options, &context);
    active.Set(&context);
    const grpc::Status status = stub->GetResult(&context, ref, &result);
    active.Set(nullptr);
    if (interrupt.interrupted()) {
      fmt::print(stderr,
                 "interrupted: job {} finished; nothing written (`driftlab result` "
                 "fetches it)\n",
                 ref.job_id());
      return kExitCancelled;
    }
    if (!status.ok()) return ReportRpcError(status, options);
  }
  return PrintAndWriteOutputs(result, run.out, run.report);
}

size_t RowsPerChunk(size_t columns) {
  constexpr size_t kAllowanceBytes = 64;  // field tags, length varints, oneof wrapper
  const size_t doubles = (kMaxRowsMessageBytes - kAllowanceBytes) / sizeof(double);
  return std::max<size_t>(1, doubles / std::max<size_t>(1, columns));
}

int RemoteCalibrate(const RemoteOptions& options, const app::CalibrateSettings& settings,
                    const app::NumericTable& table, v1::CalibrationResult* result) {
  std::shared_ptr<grpc::Channel> channel;
  try {
    channel = MakeChannel(options);
  } catch (const SpecError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitBadJob;
  }
  std::unique_ptr<v1::Calibration::Stub> stub = v1::Calibration::NewStub(channel);
  grpc::ClientContext context;
  PrepareContext(options, &context);
  std::unique_ptr<grpc::ClientWriter<v1::CalibrateRequest>> writer =
      stub->Calibrate(&context, result);

  v1::CalibrateRequest request;
  v1::CalibrateSettings* s = request.mutable_settings();
  s->set_kind(settings.kind);
  if (settings.rate_hz != 0.0) s->set_rate_hz(settings.rate_hz);
  s->set_lat_deg(settings.lat_deg);
  s->set_height_m(settings.height_m);
  s->set_init_static_s(settings.init_static_s);
  s->set_window_s(settings.window_s);
  s->set_min_pose_s(settings.min_pose_s);
  s->set_loss(settings.loss);
  s->set_matrix(settings.matrix);
  s->set_input_unit(settings.input_unit);
  s->set_output_unit(settings.output_unit);
  for (const std::string& column : table.columns) s->add_columns(column);
  s->set_data_name(settings.data_name);
  bool open = writer->Write(request);

  const size_t columns = table.columns.size();
  const size_t rows_per_chunk = RowsPerChunk(columns);
  for (size_t row = 0; open && row < table.rows(); row += rows_per_chunk) {
    const size_t end_row = std::min(table.rows(), row + rows_per_chunk);
    request.Clear();
    request.mutable_rows()->mutable_values()->Add(table.values.begin() + row * columns,
                                                  table.values.begin() + end_row * columns);
    open = writer->Write(request);
  }
  if (open) writer->WritesDone();
  const grpc::Status status = writer->Finish();
  if (!status.ok()) return ReportRpcError(status, options);
  return kExitOk;
}

}  // namespace driftlab::cli
