// driftlab-server: the gRPC service of driftlab (DESIGN.md "Service").
//
//   driftlab-server --listen ADDR --data DIR [--tls-cert F --tls-key F] [--tokens FILE]
//       [--max-concurrent-jobs N] [--max-queued-jobs N] [--max-job-samples N]
//       [--threads-per-job N] [--examples DIR] [--port-file F] [--shutdown-grace-s S]
//       [--http-port P [--http-host ADDR] [--http-port-file F]]
//       [--cluster slurm|k8s --cluster-dir DIR [--cluster-threshold-samples N] [--cluster-shards K]
//        [--slurm-partition P] [--cluster-driftlab PATH]
//        [--k8s-template F] [--k8s-image I] [--k8s-namespace NS] [--k8s-claim C]]
//   driftlab-server hash-token TOKEN      prints the SHA-256 to put in a tokens file
//
// The first line on stdout is "listening on HOST:PORT" (with the bound port when ADDR ends in
// :0); --port-file also writes the port (atomically: written to F.tmp, then renamed). With
// --http-port the web pages (web_server.h, docs/web.md) listen on --http-host (127.0.0.1) at that
// port (0 = any), the second line is "web pages on http[s]://HOST:PORT" and --http-port-file
// gets that port. Logs go to stderr, one line per job transition. SIGTERM / SIGINT: graceful
// shutdown (server.h).
#include <fmt/format.h>
#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include "driftlab/output_files.h"
#include "driftlab/server/auth.h"
#include "driftlab/server/server.h"
#include "driftlab/spec_error.h"

namespace {

// Host part of "host:port" with the bound port.
std::string BoundAddress(const std::string& listen, int port) {
  const size_t colon = listen.rfind(':');
  return (colon == std::string::npos ? listen : listen.substr(0, colon)) + ":" +
         std::to_string(port);
}

void WritePortFile(const std::filesystem::path& path, int port) {
  driftlab::WriteOutputFile(path, std::to_string(port) + "\n", "--port-file");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("driftlab-server: Monte-Carlo INS error analysis as a gRPC service");
  app.set_version_flag("--version", std::string("driftlab-server ") + DRIFTLAB_VERSION);
  driftlab::server::ServerOptions options;
  std::string data_dir, examples_dir;
  std::optional<std::string> tls_cert, tls_key, tokens, port_file;
  double grace_s = 10.0;
  app.add_option("--listen", options.listen, "Address to listen on, host:port (port 0 = any)")
      ->capture_default_str();
  app.add_option("--data", data_dir, "Data directory (SQLite store driftlab.db)");
  app.add_option("--tls-cert", tls_cert, "Server certificate chain (PEM)");
  app.add_option("--tls-key", tls_key, "Server private key (PEM)");
  app.add_option("--tokens", tokens, "Tokens file: lines `OWNER SHA256HEX` (see hash-token)");
  app.add_option("--max-concurrent-jobs", options.limits.max_concurrent_jobs,
                 "Jobs running at once")
      ->check(CLI::Range(1u, 1024u))
      ->capture_default_str();
  app.add_option("--max-queued-jobs", options.limits.max_queued_jobs, "Queued jobs per owner")
      ->check(CLI::Range(1u, 1000000u))
      ->capture_default_str();
  app.add_option("--max-job-samples", options.limits.max_job_samples,
                 "Largest job: runs x IMU samples per run")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  double max_job_memory_gb = static_cast<double>(options.limits.max_job_memory_bytes) / 1e9;
  app.add_option("--max-job-memory-gb", max_job_memory_gb,
                 "Largest job by its memory estimate [GB] (0 = no limit)")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  app.add_option("--max-upload-values", options.limits.max_upload_values,
                 "Largest Calibrate / FitNoiseModel upload: rows x columns")
      ->check(CLI::Range(uint64_t{1}, uint64_t{1} << 40))
      ->capture_default_str();
  app.add_option("--threads-per-job", options.limits.threads_per_job,
                 "Threads of one job (0 = hardware threads / max-concurrent-jobs)")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  app.add_option("--max-message-bytes", options.limits.max_message_bytes, "Largest request message")
      ->check(CLI::Range(1024, 1 << 30))
      ->capture_default_str();
  app.add_option("--examples", examples_dir, "Directory of example jobs (Catalog.ListExamples)");
  app.add_option("--port-file", port_file, "Write the bound port to this file");
  app.add_option("--shutdown-grace-s", grace_s,
                 "On SIGTERM, running jobs may finish for this long before they are requeued")
      ->check(CLI::Range(0.0, 86400.0))
      ->capture_default_str();
  std::string cluster_kind = "none";
  std::string cluster_dir, cluster_driftlab, k8s_template;
  app.add_option("--cluster", cluster_kind,
                 "Run jobs over --cluster-threshold-samples on a cluster: none, slurm or k8s")
      ->check(CLI::IsMember({"none", "slurm", "k8s"}))
      ->capture_default_str();
  app.add_option("--cluster-threshold-samples", options.cluster.threshold_samples,
                 "Jobs with more runs x IMU samples than this go to the cluster")
      ->capture_default_str();
  app.add_option("--cluster-shards", options.cluster.shards,
                 "Shards of a cluster job (at most its runs)")
      ->check(CLI::Range(1u, 100000u))
      ->capture_default_str();
  app.add_option("--cluster-dir", cluster_dir,
                 "Shared directory of cluster jobs (same path on the nodes / in the pods)");
  app.add_option("--cluster-driftlab", cluster_driftlab,
                 "The driftlab binary Slurm tasks run (default: beside driftlab-server)");
  app.add_option("--slurm-partition", options.cluster.slurm_partition,
                 "Slurm partition (default: the cluster's default)");
  app.add_option("--k8s-template", k8s_template,
                 "Indexed Job template (default: deploy/k8s/server-shard-job.yaml installed in "
                 "/usr/share/driftlab)");
  app.add_option("--k8s-image", options.cluster.k8s_image, "Image of the shard pods")
      ->capture_default_str();
  app.add_option("--k8s-namespace", options.cluster.k8s_namespace, "Namespace of the Jobs")
      ->capture_default_str();
  app.add_option("--k8s-claim", options.cluster.k8s_claim,
                 "ReadWriteMany claim mounted at --cluster-dir in the shard pods")
      ->capture_default_str();
  std::optional<int> http_port;
  std::optional<std::string> http_port_file;
  app.add_option("--http-port", http_port,
                 "Serve the web pages (jobs, reports, calibrations, IMU catalogue) on this port "
                 "(0 = any; default: no web pages)")
      ->check(CLI::Range(0, 65535));
  app.add_option("--http-host", options.web.host,
                 "Address of the web pages (TLS with --tls-cert/--tls-key as gRPC)")
      ->capture_default_str();
  app.add_option("--http-port-file", http_port_file, "Write the web pages' port to this file");
  std::string token;
  CLI::App* hash = app.add_subcommand("hash-token", "Print the SHA-256 of TOKEN for a tokens file");
  hash->add_option("token", token, "The bearer token")->required();
  CLI11_PARSE(app, argc, argv);
  options.limits.max_job_memory_bytes = static_cast<uint64_t>(max_job_memory_gb * 1e9);

  if (hash->parsed()) {
    fmt::print("{}\n", driftlab::server::Sha256Hex(token));
    return 0;
  }
  if (data_dir.empty()) {
    fmt::print(stderr, "error: --data DIR is required\n");
    return 2;
  }

  if (cluster_kind != "none") {
    if (cluster_dir.empty()) {
      fmt::print(stderr,
                 "error: --cluster {} needs --cluster-dir DIR (a directory the {} can "
                 "read and write at the same path)\n",
                 cluster_kind, cluster_kind == "slurm" ? "compute nodes" : "shard pods");
      return 2;
    }
    namespace fs = std::filesystem;
    options.cluster.kind = cluster_kind == "slurm" ? driftlab::server::ClusterKind::kSlurm
                                                   : driftlab::server::ClusterKind::kKubernetes;
    options.cluster.work_dir = fs::absolute(cluster_dir);
    options.cluster.driftlab_binary =
        cluster_driftlab.empty() ? fs::read_symlink("/proc/self/exe").parent_path() / "driftlab"
                                 : fs::absolute(cluster_driftlab);
    options.cluster.k8s_template = k8s_template.empty()
                                       ? fs::path("/usr/share/driftlab/k8s/server-shard-job.yaml")
                                       : fs::path(k8s_template);
    if (options.cluster.kind == driftlab::server::ClusterKind::kSlurm &&
        !fs::is_regular_file(options.cluster.driftlab_binary)) {
      fmt::print(stderr,
                 "error: --cluster-driftlab: {} is not a file (the driftlab binary the "
                 "Slurm tasks run)\n",
                 options.cluster.driftlab_binary.string());
      return 2;
    }
    if (options.cluster.kind == driftlab::server::ClusterKind::kKubernetes &&
        !fs::is_regular_file(options.cluster.k8s_template)) {
      fmt::print(stderr,
                 "error: --k8s-template: {} is not a file (the Indexed Job template, "
                 "deploy/k8s/server-shard-job.yaml)\n",
                 options.cluster.k8s_template.string());
      return 2;
    }
  }
  std::signal(SIGPIPE, SIG_IGN);  // a cluster client that exits before reading its input

  driftlab::server::BlockShutdownSignals();  // before any thread exists

  auto logger = spdlog::stderr_logger_mt("driftlab-server");
  logger->set_pattern("%Y-%m-%dT%H:%M:%S.%e %l %v");
  logger->flush_on(spdlog::level::info);
  spdlog::set_default_logger(logger);

  options.data_dir = data_dir;
  options.examples_dir = examples_dir;
  if (tls_cert) options.tls_cert = *tls_cert;
  if (tls_key) options.tls_key = *tls_key;
  if (tokens) options.tokens_file = *tokens;
  options.shutdown_grace = std::chrono::milliseconds(static_cast<int64_t>(grace_s * 1000));
  if (http_port) options.web.port = *http_port;
  if (http_port_file && !http_port) {
    fmt::print(stderr, "error: --http-port-file needs --http-port\n");
    return 2;
  }

  std::unique_ptr<driftlab::server::Server> server;
  try {
    server = std::make_unique<driftlab::server::Server>(options);
    fmt::print("listening on {}\n", BoundAddress(options.listen, server->port()));
    if (server->http_port() > 0) {
      fmt::print("web pages on {}://{}:{}\n", tls_cert ? "https" : "http", options.web.host,
                 server->http_port());
    }
    std::fflush(stdout);
    if (http_port_file) WritePortFile(*http_port_file, server->http_port());
    if (port_file) WritePortFile(*port_file, server->port());
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 2;
  }
  spdlog::info("{} received", driftlab::server::WaitForShutdownSignal());
  server->Shutdown();
  return 0;
}
