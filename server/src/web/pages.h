// The pages and page fragments of the web interface (web_server.h), rendered on the server so that
// the lists and the downloads work without JavaScript; app.js only refreshes the fragments
// (job rows, a job's status) in place. Each function returns HTML; all text from jobs, results,
// requests and the store is escaped (html.h).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "driftlab/server/job_store.h"
#include "driftlab/v1/service.pb.h"
#include "web/html.h"

namespace driftlab::server::web {

// How the CLI reaches this server's gRPC port, for the commands the pages show.
struct GrpcTarget {
  std::string address;  // host:port
  bool tls = false;
};

// ---- jobs (job_pages.cc)

struct JobFilter {
  std::vector<v1::JobState> states;  // empty = all
  std::string name;                  // substring of the name, ASCII case ignored
};

// The list page: filter form, the table of jobs (JobRows), when more exist a note, and the
// commands that submit and list jobs on this server.
std::string JobListPage(const Viewer& viewer, const JobFilter& filter,
                        const v1::ListJobsResponse& jobs, const GrpcTarget& grpc);
// The table rows of the list; *active is true when a listed job is QUEUED or RUNNING.
std::string JobRows(const v1::ListJobsResponse& jobs, bool* active);

struct JobView {
  v1::JobStatus status;
  v1::SubmitJobRequest request;
  std::optional<v1::JobResult> result;  // SUCCEEDED jobs
};
std::string JobPage(const Viewer& viewer, const JobView& job, const GrpcTarget& grpc);
// The status block of a job page (progress, times, time left).
std::string JobStatusBlock(const v1::JobStatus& status);
// The job as a job file: protobuf JSON with proto field names, as `driftlab` reads job files.
std::string JobFileJson(const v1::Job& job);
bool IsFinal(v1::JobState state);

// ---- calibrations (calibration_pages.cc)

std::string CalibrationListPage(const Viewer& viewer, const std::vector<StoredCalibration>& list);
// `record` with its result. Returns "" when the stored messages cannot be parsed.
std::string CalibrationPage(const Viewer& viewer, const StoredCalibration& record,
                            const GrpcTarget& grpc);
// The result as the CLI writes it (`driftlab calibrate --out`, `driftlab allan --fit
// --fit-json`), and its HTML report; std::nullopt when the stored bytes cannot be parsed.
std::optional<std::string> CalibrationResultJson(const StoredCalibration& record);
std::optional<std::string> CalibrationSettingsJson(const StoredCalibration& record);
std::optional<std::string> CalibrationReport(const StoredCalibration& record);

// ---- catalogue (catalog_pages.cc)

std::string CatalogPage(const Viewer& viewer, const std::vector<v1::PresetSummary>& presets);
std::string PresetPage(const Viewer& viewer, const v1::Preset& preset);
// The preset as the `sensor` section of a job file (JSON).
std::string PresetSensorJson(const v1::Preset& preset);

// ---- sign-in and errors (web_server.cc)

std::string SignInPage(const std::string& message);
std::string ErrorPage(const Viewer& viewer, int status, const std::string& message);

}  // namespace driftlab::server::web
