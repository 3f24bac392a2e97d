// The gRPC side of the `driftlab` remote commands (remote.h): channels with TLS and bearer-token
// metadata, the mapping of the server's status codes to exit statuses and messages, and the
// progress bar that follows Jobs.Watch.
#pragma once

#include <grpcpp/grpcpp.h>

#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "driftlab/monte_carlo.h"
#include "driftlab/v1/service.grpc.pb.h"
#include "progress.h"
#include "remote.h"

namespace driftlab::cli {

// A channel to options.server: TLS with the CA file when tls_ca is set, else plaintext; no
// receive size limit (results of large jobs exceed gRPC's 4 MB default; the server bounds them).
// Throws SpecError("--tls-ca", path, ...) when the CA file cannot be read. Connects lazily.
std::shared_ptr<grpc::Channel> MakeChannel(const RemoteOptions& options);

// Adds the per-call metadata `authorization: Bearer <token>` when a token is set.
void PrepareContext(const RemoteOptions& options, grpc::ClientContext* context);

// Prints the failed call's message to stderr ("error: ...") and returns the exit status
// (remote.h).
int ReportRpcError(const grpc::Status& status, const RemoteOptions& options);

// True for the states after which a job never changes.
bool IsFinal(v1::JobState state);

// The engine's progress record built from a JobStatus (absent fields are 0).
MonteCarloProgress ToProgress(const v1::JobStatus& status);

// Prints a final JobStatus that is not SUCCEEDED to stderr and returns the exit status
// (0 for SUCCEEDED, 2 for FAILED, 1 for CANCELLED and anything else).
int ReportFinalState(const v1::JobStatus& status);

// One line describing a job's status (id, state, name, runs done of total, time, speed, error).
std::string DescribeStatus(const v1::JobStatus& status);

// The call in progress of a command that cancels its calls on Ctrl-C (interrupt.h): Cancel() may
// come from another thread at any time, before, during or between calls.
class ActiveCall {
 public:
  // Makes `context` (null: none) the call in progress; cancels it at once after Cancel().
  void Set(grpc::ClientContext* context);
  // Cancels the call in progress and every later one.
  void Cancel();

 private:
  std::mutex mutex_;
  grpc::ClientContext* context_ = nullptr;
  bool cancelled_ = false;
};

// Result of following a job with Watch.
struct WatchOutcome {
  grpc::Status status;                // of the Watch call (CANCELLED after an interrupt)
  std::optional<v1::JobStatus> last;  // the last status received
  bool interrupted = false;           // SIGINT / SIGTERM arrived while watching
};

// Follows Jobs.Watch of `job_id` until the stream ends (after the final state), feeding each
// status to `printer` (may be null). With `active` null, SIGINT and SIGTERM are caught while
// watching (interrupt.h): the call is cancelled and the outcome says `interrupted`; otherwise the
// caller's InterruptWatch cancels the call through `active` (and `interrupted` stays false).
WatchOutcome WatchJob(v1::Jobs::Stub* stub, const RemoteOptions& options, const std::string& job_id,
                      ProgressPrinter* printer, ActiveCall* active = nullptr);

}  // namespace driftlab::cli
