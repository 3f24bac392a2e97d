// Datasets service: one seeded run of a job streamed out (IMU data, truth and optionally the
// engine's navigation solution), and an external solution scored against that run's truth.
//
// The run is the one a Monte-Carlo job with this seed gives run_index: the job is validated as
// every entry does (app::ValidateJob, file references rejected: the server reads no client-named
// files) and replayed by the engine (ReplayMonteCarloRun: the same
// truth, sensor errors, initial errors, alignment and mechanization as RunMonteCarlo). Rows are
// laid out as dataset_rows.h documents (imu.csv / truth.csv columns of `driftlab export`).
//
// ScoreSolution's result is the JobResult that `driftlab run` gives for the shard holding only
// that run (runs [run_index, run_index + 1) of the job's runs): ToJobResult(JobAsRun(job, spec),
// statistics) with the statistics from the solution's errors at the job's epochs.
#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "driftlab/app/dataset_rows.h"
#include "driftlab/app/job_validator.h"
#include "driftlab/app/monte_carlo_job.h"
#include "driftlab/monte_carlo.h"
#include "driftlab/server/data_services.h"
#include "driftlab/spec_error.h"

namespace driftlab::server {
namespace {

constexpr uint32_t kDefaultRowsPerChunk = 4096;
// 8192 rows x (13 + 10 + 10) doubles = 2.2 MB per message, below gRPC's default 4 MB receive limit.
constexpr uint32_t kMaxRowsPerChunk = 8192;

// A run of a job, validated.
struct ResolvedRun {
  v1::Job job_as_run;   // the job with runs and seed as run (JobAsRun)
  MonteCarloSpec spec;  // first_run = run, run_count = 1
  uint32_t run = 0;
  int64_t samples = 0;  // IMU samples of the run (k = 0..n)
};

// Thrown out of a replay callback to stop it with a status.
struct StopReplay {
  grpc::Status status;
};

// Validates `ref` as the CLI validates a job (`field` is the RunRef's path for its own fields).
// Throws SpecError; returns RESOURCE_EXHAUSTED in *status for a run beyond max_job_samples.
ResolvedRun ResolveRun(const v1::RunRef& ref, const std::string& field, const ServerLimits& limits,
                       grpc::Status* status) {
  app::JobValidationOptions options;
  if (ref.has_seed()) options.overrides.seed = ref.seed();
  options.allow_file_references = false;
  app::ValidatedJob job = app::ValidateJob(ref.job(), "", options);
  ResolvedRun out;
  out.spec = std::move(job.spec);
  out.run = ref.has_run_index() ? ref.run_index() : 0;
  if (out.run >= out.spec.runs) {
    throw SpecError(
        field + ".run_index", std::to_string(out.run),
        fmt::format("[0, monte_carlo.runs - 1] = [0, {}] (a run of the job)", out.spec.runs - 1));
  }
  out.spec.first_run = out.run;
  out.spec.run_count = 1;
  out.job_as_run = app::JobAsRun(ref.job(), out.spec);
  out.samples = static_cast<int64_t>(job.samples_per_run) +
                (out.spec.simulation.mechanization == MechanizationKind::kSeed000 ? 0 : 1);
  if (static_cast<uint64_t>(out.samples) > limits.max_job_samples) {
    *status = grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                           fmt::format("{}: the run has {} IMU samples; the server's limit is {} "
                                       "(--max-job-samples)",
                                       field, out.samples, limits.max_job_samples));
  }
  return out;
}

class DatasetsService final : public v1::Datasets::Service {
 public:
  DatasetsService(const Authenticator* auth, const ServerLimits& limits)
      : auth_(auth), limits_(limits) {}

  grpc::Status ExportRun(grpc::ServerContext* context, const v1::ExportRunRequest* request,
                         grpc::ServerWriter<v1::ExportRunResponse>* writer) override {
    std::string owner;
    if (grpc::Status s = auth_->Authenticate(*context, &owner); !s.ok()) return s;
    try {
      if (request->rows_per_chunk() > kMaxRowsPerChunk) {
        throw SpecError(
            "rows_per_chunk", std::to_string(request->rows_per_chunk()),
            fmt::format("[1, {}] rows, or 0 for {}", kMaxRowsPerChunk, kDefaultRowsPerChunk));
      }
      const uint32_t rows_per_chunk =
          request->rows_per_chunk() == 0 ? kDefaultRowsPerChunk : request->rows_per_chunk();
      grpc::Status limit = grpc::Status::OK;
      const ResolvedRun run = ResolveRun(request->run(), "run", limits_, &limit);
      if (!limit.ok()) return limit;
      return Export(context, run, request->include_navigation(), rows_per_chunk, writer);
    } catch (const SpecError& e) {
      return InvalidArgument(e);
    }
  }

  grpc::Status ScoreSolution(grpc::ServerContext* context,
                             grpc::ServerReader<v1::ScoreSolutionRequest>* reader,
                             v1::JobResult* response) override {
    std::string owner;
    if (grpc::Status s = auth_->Authenticate(*context, &owner); !s.ok()) return s;
    try {
      v1::ScoreSolutionRequest request;
      if (!reader->Read(&request)) throw SpecError("header", "", "a header as the first message");
      if (!request.has_header()) {
        throw SpecError("header", "missing before the rows of message 0",
                        "the header (run and columns) as the first message, then rows");
      }
      grpc::Status limit = grpc::Status::OK;
      const ResolvedRun run = ResolveRun(request.header().run(), "header.run", limits_, &limit);
      if (!limit.ok()) return limit;
      const app::SolutionColumns columns(
          {request.header().columns().begin(), request.header().columns().end()}, "header.columns");
      app::RunScorer scorer(run.spec, run.run);
      uint64_t message = 1, rows_message = 0, row = 0;
      while (reader->Read(&request)) {
        if (request.has_header()) {
          throw SpecError("header", fmt::format("a second header (message {})", message),
                          "exactly one header, the first message");
        }
        const auto& values = request.rows().values();
        if (values.size() % columns.size() != 0) {
          throw SpecError(fmt::format("rows[{}].values", rows_message),
                          fmt::format("{} values", values.size()),
                          fmt::format("a multiple of the {} columns (whole rows)", columns.size()));
        }
        const uint64_t rows_in_message = static_cast<uint64_t>(values.size()) / columns.size();
        if (row + rows_in_message > limits_.max_job_samples) {
          return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                              fmt::format("rows: more than {} rows (the server's "
                                          "--max-job-samples)",
                                          limits_.max_job_samples));
        }
        for (uint64_t i = 0; i < rows_in_message; ++i, ++row) {
          scorer.Add(columns.Parse(values.data() + i * columns.size(), row, "rows"), row, "rows");
        }
        ++message;
        ++rows_message;
      }
      if (context->IsCancelled()) return grpc::Status(grpc::StatusCode::CANCELLED, "cancelled");
      *response = app::ToJobResult(run.job_as_run, scorer.Statistics("rows"), DRIFTLAB_VERSION);
    } catch (const SpecError& e) {
      return InvalidArgument(e);
    }
    return grpc::Status::OK;
  }

 private:
  grpc::Status Export(grpc::ServerContext* context, const ResolvedRun& run, bool navigation,
                      uint32_t rows_per_chunk,
                      grpc::ServerWriter<v1::ExportRunResponse>* writer) const {
    v1::ExportRunResponse chunk;
    uint32_t rows_in_chunk = 0;
    auto flush = [&] {
      if (rows_in_chunk == 0) return;
      if (context->IsCancelled()) {
        throw StopReplay{grpc::Status(grpc::StatusCode::CANCELLED, "cancelled by the client")};
      }
      if (!writer->Write(chunk)) {
        throw StopReplay{grpc::Status(grpc::StatusCode::CANCELLED, "the client went away")};
      }
      chunk.Clear();
      rows_in_chunk = 0;
    };
    // Cancellation: checked at every chunk (at most kMaxRowsPerChunk samples of work).
    std::vector<double> imu, truth, nav;
    imu.reserve(app::kImuRowSize);
    truth.reserve(app::kTruthRowSize);
    nav.reserve(app::kNavigationRowSize);
    try {
      ReplayMonteCarloRun(
          run.spec, run.run, navigation,
          [&](const MonteCarloRunLayout& layout) {
            v1::ExportRunResponse header_message;
            v1::ExportHeader* header = header_message.mutable_header();
            header->set_rate_hz(layout.rate_hz);
            for (const std::string& c : app::ImuColumns()) header->add_imu_columns(c);
            for (const std::string& c : app::TruthColumns()) header->add_truth_columns(c);
            for (const std::string& c : app::NavigationColumns()) {
              header->add_navigation_columns(c);
            }
            const auto rows = static_cast<uint64_t>(layout.num_steps + 1);
            header->set_imu_rows(rows);
            header->set_truth_rows(rows);
            header->set_navigation_rows(
                navigation
                    ? static_cast<uint64_t>(layout.num_steps - layout.navigation_start_step + 1)
                    : 0);
            if (!writer->Write(header_message)) {
              throw StopReplay{grpc::Status(grpc::StatusCode::CANCELLED, "the client went away")};
            }
          },
          [&](const MonteCarloRunStep& step) {
            const double t_s = step.truth->t_s;
            v1::ExportChunk* c = chunk.mutable_chunk();
            imu.clear();
            app::AppendImuRow(t_s, *step.measured_increment, *step.measured_sample, &imu);
            c->mutable_imu()->Add(imu.begin(), imu.end());
            truth.clear();
            app::AppendTruthRow(*step.truth, &truth);
            c->mutable_truth()->Add(truth.begin(), truth.end());
            if (step.nav != nullptr) {
              nav.clear();
              app::AppendNavigationRow(t_s, *step.nav, &nav);
              c->mutable_navigation()->Add(nav.begin(), nav.end());
            }
            if (++rows_in_chunk == rows_per_chunk) flush();
          });
      flush();
    } catch (const StopReplay& stop) {
      return stop.status;
    }
    return grpc::Status::OK;
  }

  const Authenticator* auth_;
  const ServerLimits limits_;
};

}  // namespace

std::unique_ptr<v1::Datasets::Service> MakeDatasetsService(const Authenticator* auth,
                                                           const ServerLimits& limits) {
  return std::make_unique<DatasetsService>(auth, limits);
}

}  // namespace driftlab::server
