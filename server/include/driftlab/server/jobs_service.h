// The gRPC Jobs service (service.proto): authenticates each call and hands it to the JobManager.
// No logic of its own (STYLE.md: "the service class only adapts").
#pragma once

#include <memory>

#include "driftlab/server/job_manager.h"
#include "driftlab/server/service_common.h"
#include "driftlab/v1/service.grpc.pb.h"

namespace driftlab::server {

// `auth` and `manager` outlive the service.
std::unique_ptr<v1::Jobs::Service> MakeJobsService(const Authenticator* auth, JobManager* manager);

}  // namespace driftlab::server
