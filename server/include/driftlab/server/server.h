// driftlab-server assembled: the SQLite store, the job manager, the four gRPC services (Jobs,
// Catalog, Calibration, Datasets), standard health checking (grpc.health.v1) and server
// reflection, on one listening address with TLS or without; and, when asked for, the web pages
// (web_server.h) on their own address, from the same store and job manager with the same tokens.
#pragma once

#include <grpcpp/grpcpp.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "driftlab/server/auth.h"
#include "driftlab/server/cluster.h"
#include "driftlab/server/job_manager.h"
#include "driftlab/server/job_store.h"
#include "driftlab/server/service_common.h"
#include "driftlab/server/web_server.h"

namespace driftlab::server {

struct ServerOptions {
  std::string listen = "127.0.0.1:0";  // host:port; port 0 = an ephemeral port (see port())
  std::filesystem::path data_dir;      // holds driftlab.db
  // TLS: both or neither (PEM files). Without them the server listens without encryption.
  std::optional<std::filesystem::path> tls_cert;
  std::optional<std::filesystem::path> tls_key;
  std::optional<std::filesystem::path> tokens_file;  // absent: no authentication
  std::filesystem::path examples_dir;                // Catalog.ListExamples
  ServerLimits limits;
  ClusterOptions cluster;  // kind kNone: every job runs in the server's process
  std::chrono::milliseconds shutdown_grace{10000};  // running jobs may finish for this long
  // The web pages (web_server.h): off unless web.port >= 0; TLS with tls_cert / tls_key.
  WebOptions web;
};

// Blocks SIGTERM and SIGINT in the calling thread. Call it in main before any thread exists:
// every thread inherits the mask, and WaitForShutdownSignal then takes the signal synchronously.
void BlockShutdownSignals();
// Waits for SIGTERM or SIGINT (blocked by BlockShutdownSignals); returns its name.
std::string WaitForShutdownSignal();

// True for 127.0.0.0/8, [::1], localhost and unix: addresses.
bool IsLoopbackAddress(const std::string& listen);

class Server {
 public:
  // Opens the store, recovers queued jobs, starts the workers and the gRPC server. Throws
  // SpecError for bad options (unreadable files, a port that cannot be bound).
  explicit Server(const ServerOptions& options);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  int port() const { return port_; }
  // The web pages' port (-1 when they are off).
  int http_port() const;
  // Graceful shutdown (job_manager.h): stop accepting jobs, drain for the grace period, then stop
  // the gRPC server. Idempotent.
  void Shutdown();
  JobManager& jobs() { return *manager_; }

 private:
  ServerOptions options_;
  TokenAuthenticator auth_;
  std::unique_ptr<JobStore> store_;
  std::unique_ptr<JobManager> manager_;
  std::vector<std::unique_ptr<grpc::Service>> services_;
  std::unique_ptr<grpc::Server> server_;
  std::unique_ptr<WebServer> web_;
  int port_ = 0;
  bool shut_down_ = false;
};

}  // namespace driftlab::server
