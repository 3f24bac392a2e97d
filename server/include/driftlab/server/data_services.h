// The stateless gRPC services of driftlab-server: Catalog (presets, example jobs), Calibration
// (calibration and noise-model fits of streamed samples, datasheet conversion) and Datasets (one
// seeded run's IMU data and truth streamed out; an external navigation solution scored against
// that truth). The Jobs service (jobs_service.h) owns the queue and the store.
#pragma once

#include <filesystem>
#include <memory>

#include "driftlab/server/service_common.h"
#include "driftlab/v1/service.grpc.pb.h"

namespace driftlab::server {

// examples_dir: directory of example job files (.json/.yaml); jobs that reference files are left
// out of ListExamples (the server does not read client-named files). `auth` outlives the service.
std::unique_ptr<v1::Catalog::Service> MakeCatalogService(const Authenticator* auth,
                                                         std::filesystem::path examples_dir);

std::unique_ptr<v1::Calibration::Service> MakeCalibrationService(const Authenticator* auth,
                                                                 const ServerLimits& limits);

std::unique_ptr<v1::Datasets::Service> MakeDatasetsService(const Authenticator* auth,
                                                           const ServerLimits& limits);

}  // namespace driftlab::server
