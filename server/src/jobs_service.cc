#include "driftlab/server/jobs_service.h"

#include <string>

namespace driftlab::server {
namespace {

class JobsService final : public v1::Jobs::Service {
 public:
  JobsService(const Authenticator* auth, JobManager* manager) : auth_(auth), manager_(manager) {}

  grpc::Status Submit(grpc::ServerContext* context, const v1::SubmitJobRequest* request,
                      v1::JobStatus* response) override {
    std::string owner;
    grpc::Status status = auth_->Authenticate(*context, &owner);
    return status.ok() ? manager_->Submit(owner, *request, response) : status;
  }

  grpc::Status Get(grpc::ServerContext* context, const v1::JobRef* request,
                   v1::JobStatus* response) override {
    std::string owner;
    grpc::Status status = auth_->Authenticate(*context, &owner);
    return status.ok() ? manager_->Get(owner, request->job_id(), response) : status;
  }

  grpc::Status Watch(grpc::ServerContext* context, const v1::JobRef* request,
                     grpc::ServerWriter<v1::JobStatus>* writer) override {
    std::string owner;
    grpc::Status status = auth_->Authenticate(*context, &owner);
    if (!status.ok()) return status;
    return manager_->Watch(
        owner, request->job_id(), [writer](const v1::JobStatus& s) { return writer->Write(s); },
        [context] { return context->IsCancelled(); }, context->deadline());
  }

  grpc::Status Cancel(grpc::ServerContext* context, const v1::JobRef* request,
                      v1::JobStatus* response) override {
    std::string owner;
    grpc::Status status = auth_->Authenticate(*context, &owner);
    return status.ok() ? manager_->Cancel(owner, request->job_id(), response) : status;
  }

  grpc::Status List(grpc::ServerContext* context, const v1::ListJobsRequest* request,
                    v1::ListJobsResponse* response) override {
    std::string owner;
    grpc::Status status = auth_->Authenticate(*context, &owner);
    return status.ok() ? manager_->List(owner, *request, response) : status;
  }

  grpc::Status GetResult(grpc::ServerContext* context, const v1::JobRef* request,
                         v1::JobResult* response) override {
    std::string owner;
    grpc::Status status = auth_->Authenticate(*context, &owner);
    return status.ok() ? manager_->GetResult(owner, request->job_id(), response) : status;
  }

  grpc::Status GetMetrics(grpc::ServerContext* context, const v1::GetMetricsRequest*,
                          v1::ServerMetrics* response) override {
    std::string owner;
    grpc::Status status = auth_->Authenticate(*context, &owner);
    if (status.ok()) manager_->Metrics(response);
    return status;
  }

 private:
  const Authenticator* auth_;
  JobManager* manager_;
};

}  // namespace

std::unique_ptr<v1::Jobs::Service> MakeJobsService(const Authenticator* auth, JobManager* manager) {
  return std::make_unique<JobsService>(auth, manager);
}

}  // namespace driftlab::server
