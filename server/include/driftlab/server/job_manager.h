// The job queue of driftlab-server: validation at submission, a FIFO queue, worker threads that
// run Monte-Carlo jobs, cancellation, deadlines, progress for Watch, and graceful shutdown.
//
// A job runs exactly as `driftlab run` runs it (clients/cli/run_command.cc): the request's job
// is validated and translated by app::ValidateJob (job_validator.h, the validator of every entry)
// with the request's overrides and no file references, RunMonteCarloWithAnalysis runs it, and
// app::ToJobResult turns the statistics into the stored driftlab.v1.JobResult (a result with a
// non-finite statistic is refused there: the job fails instead of being stored as a success). The
// engine's statistics are exact sums whatever the thread count (monte_carlo.h), so the server's
// result equals the in-process one bit for bit apart from the timings, and a job re-run after a
// crash gives the same result.
//
// CPU per job is bounded by running it with MonteCarloSpec::threads = threads_per_job: the engine
// runs the job inside a tbb::task_arena of that many threads. Cancellation sets the job's
// std::atomic<bool>, which the engine polls every 1024 samples of every run; Cancel returns when
// the worker has stopped. Queued jobs are kept in memory (and in the store); progress lives in
// memory only, state transitions go to the store (job_store.h).
//
// With a cluster backend (cluster.h), a job whose cost exceeds the threshold runs as shards on the
// cluster: a worker hands it to a thread of its own that submits (or, after a restart, re-attaches
// to) the shards, maps shard progress to runs_done / samples_done (the runs of the shards done),
// cancels them on Cancel or the deadline, and stores the merged result. Such a job does not hold
// one of max_concurrent_jobs; the per-owner queue limit and --max-job-samples apply as for every
// job. At shutdown its shards keep running and the job goes back to QUEUED: the next server
// process re-attaches to them (the handle is in the store).
#pragma once

#include <grpcpp/grpcpp.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "driftlab/monte_carlo.h"
#include "driftlab/server/cluster.h"
#include "driftlab/server/job_store.h"
#include "driftlab/server/service_common.h"
#include "driftlab/v1/service.pb.h"

namespace driftlab::server {

// A submitted job after validation: the engine spec and its cost.
struct ValidatedJob {
  MonteCarloSpec spec;
  uint32_t runs_total = 0;     // runs of this job (or of its shard)
  uint64_t samples_total = 0;  // runs_total x IMU samples per run
};

// Validates a SubmitJobRequest with app::ValidateJob, exactly as `driftlab validate` / `run`
// validate a job file (file references refused: the server does not read files), plus the
// request's own fields: runs in [1, 1000000], shard "i/K", deadline_s >= 0. Field paths are those
// of the job file (e.g. "motion.segments[0].static.duration_s") and, for the request's own fields,
// "runs", "seed", "shard", "deadline_s". Throws SpecError.
ValidatedJob ValidateSubmitRequest(const v1::SubmitJobRequest& request, int threads_per_job,
                                   uint64_t max_memory_bytes = kDefaultMaxJobMemoryBytes);

// Serializes a message deterministically (map entries sorted): equal messages give equal bytes.
std::string SerializeDeterministic(const google::protobuf::Message& message);

class JobManager {
 public:
  // `store` outlives the manager. limits.threads_per_job = 0 means hardware threads divided by
  // max_concurrent_jobs (at least 1).
  JobManager(JobStore* store, const ServerLimits& limits, std::string version,
             ClusterOptions cluster = {});
  ~JobManager();
  JobManager(const JobManager&) = delete;
  JobManager& operator=(const JobManager&) = delete;

  // Start-up: RUNNING jobs in the store go back to QUEUED, every QUEUED job is queued again in
  // submission order, and the workers start.
  void Start();

  // Each returns the gRPC status the service answers with; `owner` is the authenticated caller.
  // Another owner's job is NOT_FOUND (its existence is not revealed).
  grpc::Status Submit(const std::string& owner, const v1::SubmitJobRequest& request,
                      v1::JobStatus* status);
  grpc::Status Get(const std::string& owner, const std::string& job_id, v1::JobStatus* status);
  grpc::Status Cancel(const std::string& owner, const std::string& job_id, v1::JobStatus* status);
  grpc::Status GetResult(const std::string& owner, const std::string& job_id,
                         v1::JobResult* result);
  grpc::Status List(const std::string& owner, const v1::ListJobsRequest& request,
                    v1::ListJobsResponse* response);
  void Metrics(v1::ServerMetrics* metrics);

  // Sends the job's status now and at every change (progress at most ~10 per second, the
  // engine's progress interval) until the final state, which is sent last (OK). Stops with
  // CANCELLED when `send` fails or `cancelled()` is true (client gone), DEADLINE_EXCEEDED at
  // `deadline` (the client's gRPC deadline), UNAVAILABLE when the server shuts down.
  grpc::Status Watch(const std::string& owner, const std::string& job_id,
                     const std::function<bool(const v1::JobStatus&)>& send,
                     const std::function<bool()>& cancelled,
                     std::chrono::system_clock::time_point deadline);

  // Graceful shutdown: Submit answers UNAVAILABLE, no queued job starts, running jobs may finish
  // for up to `grace`; those still running then are cancelled back to QUEUED (a restart runs
  // them again). Returns when every worker has stopped. Idempotent.
  void Shutdown(std::chrono::milliseconds grace);

  int threads_per_job() const { return threads_per_job_; }

 private:
  enum class CancelReason { kNone, kOwner, kDeadline, kShutdown };
  struct LiveJob;

  void WorkerLoop();
  void DeadlineLoop();
  void RunJob(const std::shared_ptr<LiveJob>& live);
  // RunJob for a job on the cluster (cluster.h); runs on a thread of its own.
  void RunClusterJob(const std::shared_ptr<LiveJob>& live);
  void FinishJob(const std::shared_ptr<LiveJob>& live, v1::JobState final_state, bool requeue,
                 const std::string& error, std::string_view requeue_note);
  // True when the job runs on the cluster: a backend is configured and the job is over its
  // threshold (and not itself a shard), or it was handed to the cluster before a restart.
  bool UsesCluster(const StoredJob& row) const;
  // Records where a cluster job runs, in the store and in memory (JobStatus.cluster).
  void SetCluster(const std::shared_ptr<LiveJob>& live, const std::string& handle);
  // Marks the job RUNNING in the store and in memory; returns the attempt number.
  uint32_t MarkRunning(const std::shared_ptr<LiveJob>& live);
  // Status of a job from its live entry (queued/running) or the store; mutex_ held for live.
  v1::JobStatus LiveStatus(const LiveJob& live) const;
  // Removes a queued job from the queue and the live map; mutex_ held.
  void DropQueuedLocked(const std::string& job_id);
  void CancelQueuedLocked(const std::shared_ptr<LiveJob>& live, const std::string& error);

  JobStore* store_;
  ServerLimits limits_;
  std::string version_;
  int threads_per_job_ = 1;
  std::chrono::steady_clock::time_point start_time_;

  mutable std::mutex mutex_;
  std::condition_variable changed_;  // any job changed, the queue grew, or shutdown began
  std::map<std::string, std::shared_ptr<LiveJob>> live_;  // QUEUED and RUNNING jobs
  std::deque<std::string> queue_;
  std::map<std::string, uint32_t> queued_by_owner_;
  bool accepting_ = false;
  bool draining_ = false;          // shutdown: workers take no new job
  bool stopped_ = false;           // workers joined
  uint64_t samples_finished_ = 0;  // samples of finished attempts since start

  std::vector<std::thread> workers_;
  ClusterOptions cluster_;
  struct ClusterThread {
    std::thread thread;
    std::shared_ptr<std::atomic<bool>> finished;
  };
  std::vector<ClusterThread> cluster_threads_;  // guarded by mutex_
  std::thread deadline_thread_;
};

}  // namespace driftlab::server
