// The web pages of driftlab-server (`--http-port`): the signed-in owner's jobs (list with filters
// and live progress, each job's file, progress, cancel, report, result download, consistency
// verdict and the CLI commands that fetch or rerun it), the recorded calibrations and noise fits,
// and the IMU catalogue, served over HTTP or HTTPS by the same process from the same store, with
// the same tokens and the same owner checks as the gRPC services (docs/web.md).
//
// Security model (docs/web.md): a sign-in form takes a token of the tokens file and sets a
// session cookie (HttpOnly, SameSite=Lax, Secure and the __Host- prefix with TLS); every page and
// download asks the JobManager with the session's owner exactly as the gRPC services do, so
// another owner's job is "404 not found" on every route; forms that change state (cancel, sign
// out) carry a per-session CSRF token and are refused without it or from another origin; failed
// sign-ins are limited per client address; every response carries a content security policy and
// loads nothing from elsewhere (the stylesheet and script are embedded at build time); the
// connection layer bounds request size, time and connections per client
// (web/bounded_http_server.h).
#pragma once

#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "driftlab/server/auth.h"
#include "driftlab/server/job_manager.h"
#include "driftlab/server/job_store.h"

namespace driftlab::server {

struct WebOptions {
  std::string host = "127.0.0.1";  // address to listen on
  int port = -1;                   // -1: no web pages; 0: an ephemeral port (see WebServer::port)
  // TLS with the gRPC server's certificate (both or neither).
  std::optional<std::filesystem::path> tls_cert;
  std::optional<std::filesystem::path> tls_key;
  // Connections (web/bounded_http_server.h).
  int threads = 32;
  size_t queue = 128;
  int max_connections_per_client = 8;
  std::chrono::milliseconds request_timeout{10000};
  std::chrono::milliseconds write_timeout{60000};
  std::chrono::milliseconds keep_alive_timeout{5000};
  // Sign-in: each client address has `sign_in_burst` tries and gets one back every
  // `sign_in_refill`; a failed sign-in takes one.
  int sign_in_burst = 5;
  std::chrono::seconds sign_in_refill{60};
  // Sessions end after this long without a request, or this long after sign-in.
  std::chrono::seconds session_idle{8 * 3600};
  std::chrono::seconds session_lifetime{24 * 3600};
};

// What the pages need from the rest of the server. Everything outlives the WebServer.
struct WebContext {
  const TokenAuthenticator* auth = nullptr;
  JobManager* jobs = nullptr;
  JobStore* store = nullptr;
  // The gRPC address the CLI commands on the pages name: the bound "host:port" (a wildcard host
  // is replaced by the host the browser used), and whether it uses TLS.
  std::string grpc_listen;
  int grpc_port = 0;
  bool grpc_tls = false;
};

class WebServer {
 public:
  // Binds and starts serving on its own threads. Throws SpecError for options that cannot be
  // used (TLS files, an address that cannot be bound: "--http-port").
  WebServer(const WebOptions& options, const WebContext& context);
  ~WebServer();
  WebServer(const WebServer&) = delete;
  WebServer& operator=(const WebServer&) = delete;

  int port() const;
  // Stops accepting and waits for the requests in progress. Idempotent.
  void Stop();

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace driftlab::server
