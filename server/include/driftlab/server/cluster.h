// Cluster backends of driftlab-server: a job whose cost (runs x IMU samples) exceeds
// --cluster-threshold-samples runs as K shards on a cluster instead of the server's thread pool,
// and the server stores the exact merge of the shard results (equal byte for byte, timings aside,
// to an in-process run of the same job: the shards' statistics are exact sums, monte_carlo.h).
//
//  * Slurm (--cluster slurm): one job array, array task i runs `driftlab run JOB --shard i/K`
//    (clients/slurm: the same code as `driftlab run --slurm`); progress from squeue, a task that
//    left the queue without its result is resubmitted once, cancel = scancel.
//  * Kubernetes (--cluster k8s): one Indexed Job per driftlab job, generated from a template
//    (deploy/k8s/server-shard-job.yaml) with the server's image and created with
//    `kubectl create -f -`; progress and the end from the Job's .status (completedIndexes, active,
//    conditions Complete / Failed); cancel = kubectl delete job. Kubernetes retries a failed
//    index itself (backoffLimitPerIndex in the template).
//
// Each job gets DIR/<job-id>/ (DIR = --cluster-dir, on a filesystem the compute nodes or pods
// mount at the same path): job.json (the request's job), shard-i.json, shard-i.log. The store
// keeps where the job runs (StoredJob::cluster, Handle()) so that a restarted server re-attaches
// to it instead of submitting it again.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "driftlab/v1/result.pb.h"
#include "driftlab/v1/service.pb.h"

namespace driftlab::server {

enum class ClusterKind { kNone, kSlurm, kKubernetes };

// The server's --cluster* options.
struct ClusterOptions {
  ClusterKind kind = ClusterKind::kNone;
  // Jobs with samples_total (runs x samples per run) above this go to the cluster.
  uint64_t threshold_samples = 100'000'000;
  uint32_t shards = 4;             // at most the job's runs
  std::filesystem::path work_dir;  // absolute; DIR/<job-id>/ per job
  // Slurm: the `driftlab` the array tasks run (default: beside driftlab-server).
  std::filesystem::path driftlab_binary;
  std::string slurm_partition;  // empty: the cluster's default
  // Kubernetes: the Job template, the image of the shard pods, the namespace and the
  // ReadWriteMany claim that holds work_dir (mounted at work_dir in the pods).
  std::filesystem::path k8s_template;
  std::string k8s_image = "driftlab:0.1";
  std::string k8s_namespace = "default";
  std::string k8s_claim = "driftlab-shards";
};

// A cluster job failed (a shard failed its last attempt, the Job failed, a client program
// failed); what() is one line for the job's error.
class ClusterError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ClusterProgress {
  uint32_t total = 0;  // shards
  uint32_t done = 0;   // shards with their result
  uint32_t running = 0;
  uint32_t queued = 0;
  std::vector<uint32_t> done_shards;  // ascending
  std::string text;                   // "slurm: 3/4 shards done, 1 running, 0 queued"
};

// One driftlab job on a cluster.
class ClusterRun {
 public:
  virtual ~ClusterRun() = default;
  // Writes the job's work directory and submits its shards. Throws ClusterError.
  virtual void Submit() = 0;
  // Re-attaches to a submission of an earlier server process (its Handle()).
  virtual void Attach(const std::string& handle) = 0;
  // Where the job runs, for the store: "slurm ID..." or "k8s NAME". Changes when Slurm tasks are
  // resubmitted.
  virtual std::string Handle() const = 0;
  // One status query. nullopt: the query failed (*warning), ask again later. `notes`: events
  // worth a log line (a resubmission). Throws ClusterError when the job failed.
  virtual std::optional<ClusterProgress> Poll(std::vector<std::string>* notes,
                                              std::string* warning) = 0;
  // Stops every shard (scancel / kubectl delete job). Returns false when the command failed.
  virtual bool Cancel() = 0;
  // The merged result once every shard is done. Throws SpecError.
  virtual v1::JobResult Merge(const std::string& engine_version) = 0;
  uint32_t shards() const { return shards_; }

 protected:
  uint32_t shards_ = 0;
};

// Shards of a job of `runs` runs: min(options.shards, runs), at least 1.
uint32_t ClusterShardCount(const ClusterOptions& options, uint32_t runs);

// The backend of options.kind for the job `job_id` (never kNone).
std::unique_ptr<ClusterRun> MakeClusterRun(const ClusterOptions& options, const std::string& job_id,
                                           const v1::SubmitJobRequest& request, uint32_t runs);

// Writes DIR/job.json (the request's job as proto JSON, field names as in job files) and returns
// the arguments after the job file that reproduce the request's overrides (--runs, --seed).
std::vector<std::string> WriteClusterJobFile(const std::filesystem::path& dir,
                                             const v1::SubmitJobRequest& request);

// ---- Kubernetes, exposed for tests ------------------------------------------------------------

// Status of a batch/v1 Job as `kubectl get job NAME -o json` prints it. Fields as in the
// Kubernetes API reference, "Job v1 batch" / JobStatus
// (https://kubernetes.io/docs/reference/kubernetes-api/workload-resources/job-v1/).
struct KubernetesJobStatus {
  uint32_t active = 0;                   // .status.active: pending and running pods
  uint32_t succeeded = 0;                // .status.succeeded
  uint32_t failed = 0;                   // .status.failed: pods that failed (retries included)
  std::set<uint32_t> completed_indexes;  // .status.completedIndexes, "1,3-5,7"
  std::set<uint32_t> failed_indexes;     // .status.failedIndexes (backoffLimitPerIndex)
  bool complete = false;    // condition Complete (or SuccessCriteriaMet) with status "True"
  bool failed_job = false;  // condition Failed (or FailureTarget) with status "True"
  std::string failure;      // that condition's "reason: message"
};

// Parses "1,3-5,7" (ascending decimal indexes, runs of 3+ as first-last); throws ClusterError
// naming `field` and the text for anything else or an index >= completions.
std::set<uint32_t> ParseIndexList(const std::string& text, uint32_t completions,
                                  const std::string& field);
// Parses the Job object; throws ClusterError for text that is not a Job object.
KubernetesJobStatus ParseKubernetesJob(const std::string& json, uint32_t completions);
// Progress from the status: done = completed indexes, running = active, queued = the rest not
// failed for good.
ClusterProgress KubernetesProgress(const KubernetesJobStatus& status, uint32_t completions);

// What the template's ${...} placeholders become.
struct KubernetesJobParameters {
  std::string name;        // ${NAME}: the Job's name, "driftlab-" + job id
  std::string name_space;  // ${NAMESPACE}
  std::string job_id;      // ${JOB_ID}: a label
  std::string image;       // ${IMAGE}
  uint32_t shards = 1;     // ${SHARDS}: completions and parallelism
  std::string claim;       // ${CLAIM}: the ReadWriteMany volume claim holding ${WORK_DIR}
  std::string work_dir;    // ${WORK_DIR}: where the claim is mounted (the server's --cluster-dir)
  std::vector<std::string> args;  // ${ARGS}: the container's args, written as a JSON array
};
// The template with its placeholders replaced (strings JSON-escaped: the template puts them in
// double quotes). Throws ClusterError naming an unknown placeholder.
std::string RenderKubernetesJob(const std::string& template_text,
                                const KubernetesJobParameters& parameters);
// The args of shard pod $(JOB_COMPLETION_INDEX): run JOB --quiet --shard=$(...)/K --out=... EXTRA.
std::vector<std::string> KubernetesShardArgs(const std::string& job_file, uint32_t shards,
                                             const std::string& work_dir,
                                             const std::vector<std::string>& extra);

}  // namespace driftlab::server
