// An in-process gRPC server on 127.0.0.1 with an ephemeral port for service tests (Catalog,
// Calibration, Datasets): the services under test are registered directly, with a test
// Authenticator that accepts every call (owner "test") or rejects every call (UNAUTHENTICATED).
// No child process, no store: these services are stateless. Header-only.
#pragma once

#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "driftlab/server/service_common.h"

namespace driftlab::testing {

class TestAuthenticator : public server::Authenticator {
 public:
  explicit TestAuthenticator(bool accept) : accept_(accept) {}
  grpc::Status Authenticate(const grpc::ServerContext&, std::string* owner) const override {
    if (!accept_) return grpc::Status(grpc::StatusCode::UNAUTHENTICATED, "test: no valid token");
    *owner = "test";
    return grpc::Status::OK;
  }

 private:
  bool accept_;
};

// Starts at construction, shuts down at destruction (the services must outlive it).
class InProcessServer {
 public:
  explicit InProcessServer(const std::vector<grpc::Service*>& services) {
    grpc::ServerBuilder builder;
    builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), &port_);
    builder.SetMaxReceiveMessageSize(64 << 20);
    for (grpc::Service* service : services) builder.RegisterService(service);
    server_ = builder.BuildAndStart();
    EXPECT_TRUE(server_ != nullptr && port_ > 0) << "cannot start the in-process server";
    grpc::ChannelArguments args;
    args.SetMaxReceiveMessageSize(64 << 20);
    channel_ = grpc::CreateCustomChannel("127.0.0.1:" + std::to_string(port_),
                                         grpc::InsecureChannelCredentials(), args);
  }
  ~InProcessServer() {
    if (server_) server_->Shutdown();
  }
  InProcessServer(const InProcessServer&) = delete;
  InProcessServer& operator=(const InProcessServer&) = delete;

  std::shared_ptr<grpc::Channel> channel() const { return channel_; }

 private:
  int port_ = 0;
  std::unique_ptr<grpc::Server> server_;
  std::shared_ptr<grpc::Channel> channel_;
};

}  // namespace driftlab::testing
