// What every driftlab gRPC service implementation shares (server/): authentication of a call,
// the server's limits, and the mapping of validation errors to gRPC status codes.
//
// Services never compute physics (DESIGN.md): they translate protobuf <-> engine and
// application-layer calls (clients/app).
#pragma once

#include <grpcpp/grpcpp.h>

#include <cstdint>
#include <string>

#include "driftlab/monte_carlo.h"
#include "driftlab/spec_error.h"

namespace driftlab::server {

// Limits from the command line of driftlab-server.
struct ServerLimits {
  uint32_t max_concurrent_jobs = 1;          // jobs running at once
  uint32_t max_queued_jobs = 100;            // QUEUED jobs per owner (token)
  uint64_t max_job_samples = 2'000'000'000;  // runs x IMU samples of one job (or one export run)
  int max_message_bytes = 64 << 20;          // largest request message
  int threads_per_job = 0;  // TBB arena size; 0 = hardware threads / max_concurrent_jobs
  // Memory one job may need (EstimateMonteCarloMemoryBytes); over it Submit answers
  // RESOURCE_EXHAUSTED naming --max-job-memory-gb. 0 = no limit.
  uint64_t max_job_memory_bytes = kDefaultMaxJobMemoryBytes;
  // Values (rows x columns) one Calibrate or FitNoiseModel call may upload: 50 M doubles = 400 MB.
  uint64_t max_upload_values = 50'000'000;
};

// Bearer-token authentication (`authorization: Bearer <token>` metadata).
class Authenticator {
 public:
  virtual ~Authenticator() = default;
  // OK and *owner = the token's owner name; UNAUTHENTICATED when the server has tokens and the
  // call carries none or an unknown one. Without a tokens file every call is owner "anonymous".
  virtual grpc::Status Authenticate(const grpc::ServerContext& context,
                                    std::string* owner) const = 0;
};

// INVALID_ARGUMENT with the SpecError's one-line message (field path, value, allowed range).
inline grpc::Status InvalidArgument(const SpecError& error) {
  return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, error.what());
}

}  // namespace driftlab::server
