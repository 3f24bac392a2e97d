#include "driftlab/server/cluster.h"

#include <fmt/format.h>
#include <google/protobuf/util/json_util.h>

#include <algorithm>
#include <sstream>

#include "driftlab/output_files.h"
#include "driftlab/slurm/shard_array.h"

namespace driftlab::server {
namespace {

namespace fs = std::filesystem;

// The Slurm backend: the job array of clients/slurm (the code of `driftlab run --slurm`).
class SlurmRun : public ClusterRun {
 public:
  SlurmRun(const ClusterOptions& options, const std::string& job_id,
           const v1::SubmitJobRequest& request, uint32_t shards)
      : options_(options), request_(request), array_(ArrayOptions(options, job_id, shards)) {
    shards_ = shards;
  }

  void Submit() override {
    const fs::path dir = array_.options().work_dir;
    try {
      fs::create_directories(dir);
      const std::vector<std::string> extra = WriteClusterJobFile(dir, request_);
      array_.Prepare(options_.driftlab_binary, dir / "job.json", extra);
      array_.SubmitAll();
    } catch (const slurm::SlurmError& e) {
      throw ClusterError(e.what());
    } catch (const std::exception& e) {
      throw ClusterError(fmt::format("{}: {}", dir.string(), e.what()));
    }
  }

  void Attach(const std::string& handle) override {
    std::istringstream words(handle);
    std::string kind, id;
    std::vector<std::string> ids;
    words >> kind;
    while (words >> id) ids.push_back(id);
    array_.Attach(ids);
  }

  std::string Handle() const override {
    return fmt::format("slurm {}", fmt::join(array_.job_ids(), " "));
  }

  std::optional<ClusterProgress> Poll(std::vector<std::string>* notes,
                                      std::string* warning) override {
    std::optional<slurm::ShardProgress> p;
    try {
      p = array_.Poll(notes, warning);
    } catch (const slurm::SlurmError& e) {
      throw ClusterError(e.what());
    }
    if (!p) return std::nullopt;
    ClusterProgress out;
    out.total = p->total;
    out.done = p->done;
    out.running = p->running;
    out.queued = p->queued;
    out.done_shards = p->done_shards;
    out.text = p->Text();
    return out;
  }

  bool Cancel() override { return array_.Cancel(); }

  v1::JobResult Merge(const std::string& engine_version) override {
    return array_.Merge(engine_version);
  }

 private:
  static slurm::ShardArrayOptions ArrayOptions(const ClusterOptions& options,
                                               const std::string& job_id, uint32_t shards) {
    slurm::ShardArrayOptions out;
    out.work_dir = options.work_dir / job_id;
    out.shards = shards;
    out.partition = options.slurm_partition;
    out.job_name = "driftlab-" + job_id;
    return out;
  }

  ClusterOptions options_;
  v1::SubmitJobRequest request_;
  slurm::ShardArray array_;
};

}  // namespace

std::unique_ptr<ClusterRun> MakeKubernetesRun(const ClusterOptions& options,
                                              const std::string& job_id,
                                              const v1::SubmitJobRequest& request,
                                              uint32_t shards);  // cluster_k8s.cc

uint32_t ClusterShardCount(const ClusterOptions& options, uint32_t runs) {
  return std::max(1u, std::min(options.shards, runs));
}

std::unique_ptr<ClusterRun> MakeClusterRun(const ClusterOptions& options, const std::string& job_id,
                                           const v1::SubmitJobRequest& request, uint32_t runs) {
  const uint32_t shards = ClusterShardCount(options, runs);
  if (options.kind == ClusterKind::kKubernetes) {
    return MakeKubernetesRun(options, job_id, request, shards);
  }
  return std::make_unique<SlurmRun>(options, job_id, request, shards);
}

std::vector<std::string> WriteClusterJobFile(const fs::path& dir,
                                             const v1::SubmitJobRequest& request) {
  google::protobuf::util::JsonPrintOptions print;
  print.preserve_proto_field_names = true;  // job files use the proto field names
  print.add_whitespace = true;
  std::string json;
  const auto status = google::protobuf::util::MessageToJsonString(request.job(), &json, print);
  if (!status.ok()) throw ClusterError("the job cannot be written as JSON: " + status.ToString());
  WriteOutputFile(dir / "job.json", json, "--cluster-dir");
  std::vector<std::string> extra;
  if (request.has_runs()) extra.insert(extra.end(), {"--runs", std::to_string(request.runs())});
  if (request.has_seed()) extra.insert(extra.end(), {"--seed", std::to_string(request.seed())});
  return extra;
}

}  // namespace driftlab::server
