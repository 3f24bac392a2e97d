// job_manager.h: a Submit request checked (runs, seed, shard, deadline, then the job through the
// one job validator, clients/app job_validator.h) and the deterministic bytes the store keeps.
#include <fmt/format.h>
#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/io/zero_copy_stream_impl_lite.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "driftlab/app/job_validator.h"
#include "driftlab/app/monte_carlo_job.h"
#include "driftlab/server/job_manager.h"
#include "driftlab/spec_error.h"

namespace driftlab::server {
namespace {

using google::protobuf::Message;

// Largest accepted deadline_s: one year.
constexpr double kMaxDeadline_s = 365.0 * 86400.0;

}  // namespace

std::string SerializeDeterministic(const Message& message) {
  std::string bytes;
  {
    google::protobuf::io::StringOutputStream stream(&bytes);
    google::protobuf::io::CodedOutputStream coded(&stream);
    coded.SetSerializationDeterministic(true);
    message.SerializeToCodedStream(&coded);
  }
  return bytes;
}

ValidatedJob ValidateSubmitRequest(const v1::SubmitJobRequest& request, int threads_per_job,
                                   uint64_t max_memory_bytes) {
  if (!request.has_job()) throw SpecError("job", "", "a job (motion, rate_hz, navigation, ...)");
  app::MonteCarloOverrides overrides;
  if (request.has_runs()) {
    if (request.runs() < 1 || request.runs() > kMaxMonteCarloRuns) {
      throw SpecError("runs", std::to_string(request.runs()),
                      "1 to " + std::to_string(kMaxMonteCarloRuns));
    }
    overrides.runs = request.runs();
  }
  if (request.has_seed()) overrides.seed = request.seed();
  if (!request.shard().empty()) {
    try {
      app::ParseShard(request.shard(), &overrides);
    } catch (const SpecError&) {
      throw SpecError("shard", "\"" + request.shard() + "\"", "i/K with 0 <= i < K, K >= 1");
    }
  }
  if (request.has_deadline_s()) {
    const double d = request.deadline_s();
    if (!(d >= 0.0 && d <= kMaxDeadline_s)) {
      throw SpecError("deadline_s", std::isnan(d) ? "NaN" : fmt::format("{}", d),
                      fmt::format("0 (none) to {} s", kMaxDeadline_s));
    }
  }
  overrides.threads = threads_per_job;
  overrides.max_memory_bytes = max_memory_bytes;

  app::JobValidationOptions options;
  options.overrides = overrides;
  options.allow_file_references = false;
  app::ValidatedJob job = app::ValidateJob(request.job(), std::filesystem::path(), options);
  ValidatedJob out;
  out.spec = std::move(job.spec);
  out.runs_total = job.runs;
  out.samples_total = job.samples_total;
  return out;
}

}  // namespace driftlab::server
