// The stateless gRPC services of driftlab-server: Catalog (presets, example jobs), Calibration
// (calibration and noise-model fits of streamed samples, datasheet conversion) and Datasets (one
// seeded run's IMU data and truth streamed out; an external navigation solution scored against
// that truth). The Jobs service (jobs_service.h) owns the queue and the store.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "driftlab/server/job_store.h"
#include "driftlab/server/service_common.h"
#include "driftlab/v1/service.grpc.pb.h"

namespace driftlab::server {

// examples_dir: directory of example job files (.json/.yaml); jobs that reference files are left
// out of ListExamples (the server does not read client-named files). `auth` outlives the service.
std::unique_ptr<v1::Catalog::Service> MakeCatalogService(const Authenticator* auth,
                                                         std::filesystem::path examples_dir);

// `store` (may be null): every Calibrate and FitNoiseModel call that returns a result is recorded
// there (JobStore::InsertCalibration) for the web pages; a failure to record is logged, and the
// call still returns its result.
std::unique_ptr<v1::Calibration::Service> MakeCalibrationService(const Authenticator* auth,
                                                                 const ServerLimits& limits,
                                                                 JobStore* store = nullptr);

// The IMU catalogue as Catalog.ListPresets and Catalog.GetPreset answer (catalog_service.cc): the
// summaries of every preset, and one preset with its sensor model in the job schema's datasheet
// units (none for an unknown name).
std::vector<v1::PresetSummary> PresetSummaries();
std::optional<v1::Preset> FindPreset(const std::string& name);

std::unique_ptr<v1::Datasets::Service> MakeDatasetsService(const Authenticator* auth,
                                                           const ServerLimits& limits);

}  // namespace driftlab::server
