#include "driftlab/server/server.h"

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/health_check_service_interface.h>
#include <grpcpp/support/server_interceptor.h>
#include <signal.h>
#include <spdlog/spdlog.h>

#include <fstream>
#include <memory>
#include <sstream>
#include <vector>

#include "driftlab/input_files.h"
#include "driftlab/server/data_services.h"
#include "driftlab/server/jobs_service.h"
#include "driftlab/spec_error.h"

namespace driftlab::server {
namespace {

std::string ReadPem(const std::filesystem::path& path, const std::string& option) {
  std::string text = ReadInputFile(path, kMaxSmallTextFileBytes, option);
  if (text.empty()) throw SpecError(option, path.string(), "a PEM file (it is empty)");
  return text;
}

// gRPC's protobuf deserialization answers a request that is not a valid protobuf message with
// INTERNAL and an empty message (grpcpp/impl/codegen/proto_utils.h: the message is
// InitializationErrorString(), empty for proto3), before any service code runs. That is
// bad input, not a server fault: this interceptor turns exactly that status (INTERNAL, empty
// message; driftlab's own INTERNAL errors always carry a message) into INVALID_ARGUMENT naming the
// method.
class MalformedRequestInterceptor : public grpc::experimental::Interceptor {
 public:
  explicit MalformedRequestInterceptor(grpc::experimental::ServerRpcInfo* info)
      : method_(info->method() ? info->method() : "") {}

  void Intercept(grpc::experimental::InterceptorBatchMethods* methods) override {
    if (methods->QueryInterceptionHookPoint(
            grpc::experimental::InterceptionHookPoints::PRE_SEND_STATUS)) {
      const grpc::Status status = methods->GetSendStatus();
      if (status.error_code() == grpc::StatusCode::INTERNAL && status.error_message().empty()) {
        methods->ModifySendStatus(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                                               "request: not a valid protobuf message for " +
                                                   MessageText(method_, 200) +
                                                   " (it could not be parsed)"));
      }
    }
    methods->Proceed();
  }

 private:
  std::string method_;
};

class MalformedRequestInterceptorFactory
    : public grpc::experimental::ServerInterceptorFactoryInterface {
 public:
  grpc::experimental::Interceptor* CreateServerInterceptor(
      grpc::experimental::ServerRpcInfo* info) override {
    return new MalformedRequestInterceptor(info);
  }
};

}  // namespace

namespace {

sigset_t ShutdownSignals() {
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  return signals;
}

}  // namespace

void BlockShutdownSignals() {
  const sigset_t signals = ShutdownSignals();
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
}

std::string WaitForShutdownSignal() {
  const sigset_t signals = ShutdownSignals();
  int signal_number = 0;
  sigwait(&signals, &signal_number);
  return signal_number == SIGTERM ? "SIGTERM" : "SIGINT";
}

bool IsLoopbackAddress(const std::string& listen) {
  return listen.rfind("127.", 0) == 0 || listen.rfind("[::1]", 0) == 0 ||
         listen.rfind("localhost:", 0) == 0 || listen.rfind("unix:", 0) == 0;
}

Server::Server(const ServerOptions& options) : options_(options) {
  if (options.tls_cert.has_value() != options.tls_key.has_value()) {
    throw SpecError(options.tls_cert ? "--tls-key" : "--tls-cert", "",
                    "--tls-cert and --tls-key together");
  }
  if (options.tokens_file) {
    auth_ = TokenAuthenticator::FromFile(*options.tokens_file);
    spdlog::info("authentication: {} token(s) from {}", auth_.size(),
                 options.tokens_file->string());
  } else {
    spdlog::warn("no --tokens file: every call is accepted as owner \"{}\"", kAnonymousOwner);
  }
  store_ = std::make_unique<JobStore>(options.data_dir);
  manager_ =
      std::make_unique<JobManager>(store_.get(), options.limits, DRIFTLAB_VERSION, options.cluster);

  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder builder;
  std::shared_ptr<grpc::ServerCredentials> credentials;
  if (options.tls_cert) {
    grpc::SslServerCredentialsOptions ssl;
    ssl.pem_key_cert_pairs.push_back(
        {ReadPem(*options.tls_key, "--tls-key"), ReadPem(*options.tls_cert, "--tls-cert")});
    credentials = grpc::SslServerCredentials(ssl);
  } else {
    credentials = grpc::InsecureServerCredentials();
    if (!IsLoopbackAddress(options.listen)) {
      spdlog::warn("listening on {} without TLS: tokens and jobs travel in clear text",
                   options.listen);
    }
  }
  builder.AddListeningPort(options.listen, credentials, &port_);
  builder.SetMaxReceiveMessageSize(options.limits.max_message_bytes);

  services_.push_back(MakeJobsService(&auth_, manager_.get()));
  services_.push_back(MakeCatalogService(&auth_, options.examples_dir));
  services_.push_back(MakeCalibrationService(&auth_, options.limits, store_.get()));
  services_.push_back(MakeDatasetsService(&auth_, options.limits));
  for (const auto& service : services_) builder.RegisterService(service.get());
  std::vector<std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface>> interceptors;
  interceptors.push_back(std::make_unique<MalformedRequestInterceptorFactory>());
  builder.experimental().SetInterceptorCreators(std::move(interceptors));

  manager_->Start();
  server_ = builder.BuildAndStart();
  if (!server_ || port_ == 0) {
    manager_->Shutdown(std::chrono::milliseconds(0));
    throw SpecError("--listen", options.listen, "an address this host can listen on (host:port)");
  }
  if (options.web.port >= 0) {
    WebOptions web = options.web;
    web.tls_cert = options.tls_cert;
    web.tls_key = options.tls_key;
    WebContext context;
    context.auth = &auth_;
    context.jobs = manager_.get();
    context.store = store_.get();
    context.grpc_listen = options.listen;
    context.grpc_port = port_;
    context.grpc_tls = options.tls_cert.has_value();
    try {
      web_ = std::make_unique<WebServer>(web, context);
    } catch (...) {
      server_->Shutdown();
      manager_->Shutdown(std::chrono::milliseconds(0));
      throw;
    }
  }
  spdlog::info("listening on {} (port {}, {}, {} worker(s) x {} thread(s), data {})",
               options.listen, port_, options.tls_cert ? "TLS" : "insecure",
               options.limits.max_concurrent_jobs, manager_->threads_per_job(),
               options.data_dir.string());
}

Server::~Server() { Shutdown(); }

int Server::http_port() const { return web_ ? web_->port() : -1; }

void Server::Shutdown() {
  if (shut_down_) return;
  shut_down_ = true;
  spdlog::info("shutting down: no new jobs; running jobs get {} ms",
               options_.shutdown_grace.count());
  if (server_ && server_->GetHealthCheckService()) {
    server_->GetHealthCheckService()->SetServingStatus(false);
  }
  if (web_) web_->Stop();
  manager_->Shutdown(options_.shutdown_grace);
  if (server_) {
    server_->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(2));
    server_->Wait();
  }
  spdlog::info("stopped");
}

}  // namespace driftlab::server
