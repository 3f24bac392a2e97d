// `--server ADDR [--token T] [--tls-ca F]`: what the command files need to run a command on a
// driftlab-server (proto/driftlab/v1/service.proto) instead of in-process. The gRPC side itself
// (channels, status mapping, Watch) is in remote_client.h; this header includes no gRPC or
// service header, so command files that also use <csignal> can include it.
//
// Exit statuses (commands.h): INVALID_ARGUMENT -> 2 with the server's message (the same field
// path, value and allowed range the local validation prints); UNAUTHENTICATED,
// PERMISSION_DENIED, NOT_FOUND, UNAVAILABLE ("cannot reach ADDR") and every other failure -> 1
// with a message naming the server. A job that ends FAILED exits 2 (the engine rejected the job,
// as a local run does), one that ends CANCELLED exits 1 (130 when this client cancelled it on
// Ctrl-C).
#pragma once

#include <CLI/CLI.hpp>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "driftlab/app/calibration_job.h"
#include "driftlab/v1/calibration.pb.h"

namespace driftlab::cli {

inline constexpr int kExitCancelled = 130;  // 128 + SIGINT, the shell convention

// How to reach a server.
struct RemoteOptions {
  std::string server;  // ADDR: host:port (gRPC target syntax, e.g. 127.0.0.1:50051, dns:///h:p)
  std::string token;   // bearer token; empty: no authorization metadata
  std::string tls_ca;  // PEM file of the CA that signed the server's certificate; empty: plaintext
};

// Declares --server (required or optional), --token (default: environment DRIFTLAB_TOKEN) and
// --tls-ca on `command`. Returns the --server option.
CLI::Option* AddRemoteOptions(CLI::App* command, RemoteOptions* options, bool server_required);

// `driftlab run JOB --server ...`: the options of `run` that apply to a remote run.
struct RemoteRunRequest {
  std::string job_path;
  std::optional<uint32_t> runs;
  std::optional<uint64_t> seed;
  std::optional<std::string> shard;
  std::string out;
  std::optional<std::string> report;
  bool quiet = false;       // no progress output
  bool covariance = false;  // --covariance: sets the job's monte_carlo.covariance
};

// Submits the job (Jobs.Submit: the server validates it as `run` does), follows Jobs.Watch with
// the progress bar, fetches the result (Jobs.GetResult) and prints and writes it exactly as a
// local run. SIGINT / SIGTERM while watching cancel the job (Jobs.Cancel), write nothing and
// return kExitCancelled. Returns the exit status.
int RunRemoteJob(const RemoteOptions& options, const RemoteRunRequest& request);

// `driftlab calibrate ... --server`: streams the settings and then the table's rows (chunks of at
// most kMaxRowsMessageBytes) to Calibration.Calibrate and stores the reply in *result (the
// command prints and writes it as for a local fit). Returns the exit status (kExitOk or the
// status mapping above; the message is printed).
int RemoteCalibrate(const RemoteOptions& options, const app::CalibrateSettings& settings,
                    const app::NumericTable& table, v1::CalibrationResult* result);

// Largest payload of one streamed SampleRows message [bytes] (well under gRPC's default 4 MB
// receive limit and the server's --max-message-bytes).
inline constexpr size_t kMaxRowsMessageBytes = 1 << 20;

// Rows per streamed chunk for `columns` columns: as many as fit in kMaxRowsMessageBytes as packed
// doubles (8 bytes each, minus a small allowance for the tag and length), at least 1.
size_t RowsPerChunk(size_t columns);

}  // namespace driftlab::cli
