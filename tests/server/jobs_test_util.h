// Shared by the driftlab-server tests: small inline jobs, the in-process result `driftlab run`
// computes for a request, and Jobs client calls with an optional bearer token.
#pragma once

#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/io/zero_copy_stream_impl_lite.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "driftlab/app/job_file.h"
#include "driftlab/app/monte_carlo_job.h"
#include "driftlab/monte_carlo.h"
#include "driftlab/v1/service.grpc.pb.h"

namespace driftlab::testing {

// A vehicle at rest with a tactical-grade IMU (catalogue preset) and initial errors, at
// rate_hz for duration_s: runs x duration_s x rate_hz samples.
inline v1::Job StaticJob(double duration_s, uint32_t runs, uint64_t seed = 7,
                         double rate_hz = 100.0) {
  const std::string json = R"({"name": "server_static", "motion": {"initial": {"lat_deg": 45.07,
      "lon_deg": 7.69, "height_m": 240.0, "yaw_deg": 30.0}, "segments": [{"static":
      {"duration_s": )" + std::to_string(duration_s) +
                           R"(}}]}, "rate_hz": )" + std::to_string(rate_hz) +
                           R"(, "navigation": {"mechanization": "NED"},
      "sensor": {"preset": "tactical"}, "monte_carlo": {"runs": )" +
                           std::to_string(runs) + R"(, "seed": )" + std::to_string(seed) +
                           R"(, "initial_errors": {"position_ned_m": [1, 1, 2],
      "attitude_deg": [0.01, 0.01, 0.05]}, "epoch_interval_s": 1.0}})";
  return app::ParseJobJson(json, "StaticJob");
}

// A job that runs for minutes (1e5 runs x 60 s x 100 Hz = 6e8 samples) but whose trajectory (the
// part the engine builds before the runs, without polling the cancel flag) is short.
inline v1::Job LongJob() { return StaticJob(60.0, 100000); }

inline v1::SubmitJobRequest Request(const v1::Job& job) {
  v1::SubmitJobRequest request;
  *request.mutable_job() = job;
  return request;
}

inline std::string Deterministic(const google::protobuf::Message& message) {
  std::string bytes;
  {
    google::protobuf::io::StringOutputStream stream(&bytes);
    google::protobuf::io::CodedOutputStream coded(&stream);
    coded.SetSerializationDeterministic(true);
    message.SerializeToCodedStream(&coded);
  }
  return bytes;
}

// The result's bytes without its timings (wall time, CPU time, threads differ between runs).
inline std::string WithoutTimings(v1::JobResult result) {
  result.clear_timings();
  return Deterministic(result);
}

// What `driftlab run JOB [--runs] [--seed] [--shard]` computes in-process for this request
// (clients/cli/run_command.cc): ToMonteCarloSpec, RunMonteCarlo, ToJobResult(JobAsRun(...)).
inline v1::JobResult InProcessResult(const v1::SubmitJobRequest& request, int threads = 0) {
  app::MonteCarloOverrides overrides;
  if (request.has_runs()) overrides.runs = request.runs();
  if (request.has_seed()) overrides.seed = request.seed();
  if (!request.shard().empty()) app::ParseShard(request.shard(), &overrides);
  overrides.threads = threads;
  const app::JobFile file{request.job(), {}};
  const MonteCarloSpec spec = app::ToMonteCarloSpec(file, overrides);
  const MonteCarloStatistics statistics = RunMonteCarlo(spec);
  return app::ToJobResult(app::JobAsRun(file.job, spec), statistics, DRIFTLAB_VERSION);
}

// A Jobs client with an optional bearer token.
class JobsClient {
 public:
  JobsClient(std::shared_ptr<grpc::Channel> channel, std::string token = "")
      : stub_(v1::Jobs::NewStub(channel)), token_(std::move(token)) {}
  explicit JobsClient(const std::string& address, std::string token = "")
      : JobsClient(grpc::CreateChannel(address, grpc::InsecureChannelCredentials()),
                   std::move(token)) {}

  void Prepare(grpc::ClientContext* context,
               std::chrono::milliseconds timeout = std::chrono::seconds(60)) const {
    if (!token_.empty()) context->AddMetadata("authorization", "Bearer " + token_);
    context->set_deadline(std::chrono::system_clock::now() + timeout);
  }

  grpc::Status Submit(const v1::SubmitJobRequest& request, v1::JobStatus* status) const {
    grpc::ClientContext context;
    Prepare(&context);
    return stub_->Submit(&context, request, status);
  }
  grpc::Status Get(const std::string& id, v1::JobStatus* status) const {
    grpc::ClientContext context;
    Prepare(&context);
    return stub_->Get(&context, Ref(id), status);
  }
  grpc::Status Cancel(const std::string& id, v1::JobStatus* status) const {
    grpc::ClientContext context;
    Prepare(&context);
    return stub_->Cancel(&context, Ref(id), status);
  }
  grpc::Status GetResult(const std::string& id, v1::JobResult* result) const {
    grpc::ClientContext context;
    Prepare(&context);
    return stub_->GetResult(&context, Ref(id), result);
  }
  grpc::Status List(const v1::ListJobsRequest& request, v1::ListJobsResponse* response) const {
    grpc::ClientContext context;
    Prepare(&context);
    return stub_->List(&context, request, response);
  }
  grpc::Status Metrics(v1::ServerMetrics* metrics) const {
    grpc::ClientContext context;
    Prepare(&context);
    return stub_->GetMetrics(&context, v1::GetMetricsRequest(), metrics);
  }
  // Watches until the stream ends; every message in `statuses` (the final state last).
  // `on_message` (optional) sees each message as it arrives; returning false stops reading.
  grpc::Status Watch(const std::string& id, std::vector<v1::JobStatus>* statuses,
                     std::chrono::milliseconds timeout = std::chrono::seconds(60),
                     const std::function<bool(const v1::JobStatus&)>& on_message = nullptr) const {
    grpc::ClientContext context;
    Prepare(&context, timeout);
    auto reader = stub_->Watch(&context, Ref(id));
    v1::JobStatus status;
    while (reader->Read(&status)) {
      if (statuses) statuses->push_back(status);
      if (on_message && !on_message(status)) {
        context.TryCancel();
        while (reader->Read(&status)) {
        }
        break;
      }
    }
    return reader->Finish();
  }
  // Watches to the final state and returns it (state JOB_STATE_UNSPECIFIED on a stream error).
  v1::JobStatus WaitFinal(const std::string& id,
                          std::chrono::milliseconds timeout = std::chrono::seconds(120)) const {
    std::vector<v1::JobStatus> statuses;
    const grpc::Status s = Watch(id, &statuses, timeout);
    if (!s.ok() || statuses.empty()) {
      ADD_FAILURE() << "Watch " << id << ": " << s.error_code() << " " << s.error_message();
      return v1::JobStatus();
    }
    return statuses.back();
  }

 private:
  static v1::JobRef Ref(const std::string& id) {
    v1::JobRef ref;
    ref.set_job_id(id);
    return ref;
  }
  std::unique_ptr<v1::Jobs::Stub> stub_;
  std::string token_;
};

}  // namespace driftlab::testing
