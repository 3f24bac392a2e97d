#include "driftlab/server/job_manager.h"

#include <spdlog/spdlog.h>
#include <tbb/info.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "driftlab/app/job_file.h"
#include "driftlab/app/job_validator.h"
#include "driftlab/app/monte_carlo_job.h"
#include "driftlab/spec_error.h"

namespace driftlab::server {
namespace {

using SteadyClock = std::chrono::steady_clock;

constexpr uint32_t kDefaultPageSize = 100;
constexpr uint32_t kMaxPageSize = 1000;
constexpr size_t kMaxNameFilterBytes = 256;
// Cancel waits this long for the worker to stop; the engine stops within 1024 samples per worker
// (milliseconds), so reaching it means a stuck worker, reported as an error.
constexpr std::chrono::seconds kCancelWait{10};

double UnixNow() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

}  // namespace

// ------------------------------------------------------------------------------------------------

struct JobManager::LiveJob {
  StoredJob row;  // mirror of the store's row
  std::atomic<bool> cancel{false};
  CancelReason reason = CancelReason::kNone;  // guarded by mutex_
  bool running = false;
  bool on_cluster = false;  // set when a worker hands it to RunClusterJob
  MonteCarloProgress progress;
  SteadyClock::time_point started;
  uint64_t version = 0;  // bumped at every change Watch reports
};

namespace {

void FillStatus(const StoredJob& row, v1::JobStatus* status) {
  status->set_job_id(row.id);
  status->set_state(row.state);
  status->set_name(row.name);
  status->set_runs_total(row.runs_total);
  status->set_samples_total(row.samples_total);
  status->set_error(row.error);
  status->set_submitted_unix_s(row.submitted_unix_s);
  if (row.started_unix_s) status->set_started_unix_s(*row.started_unix_s);
  if (row.finished_unix_s) status->set_finished_unix_s(*row.finished_unix_s);
  status->set_attempts(row.attempts);
  status->set_cluster(row.cluster);
  if (row.state == v1::SUCCEEDED) {
    status->set_runs_done(row.runs_total);
    status->set_samples_done(row.samples_total);
  }
  if (row.started_unix_s && row.finished_unix_s) {
    status->set_elapsed_s(*row.finished_unix_s - *row.started_unix_s);
  }
}

grpc::Status NotFound(const std::string& job_id) {
  return grpc::Status(grpc::StatusCode::NOT_FOUND, "job " + job_id + " not found");
}

}  // namespace

JobManager::JobManager(JobStore* store, const ServerLimits& limits, std::string version,
                       ClusterOptions cluster)
    : store_(store), limits_(limits), version_(std::move(version)), cluster_(std::move(cluster)) {
  limits_.max_concurrent_jobs = std::max<uint32_t>(1, limits_.max_concurrent_jobs);
  threads_per_job_ = limits_.threads_per_job > 0
                         ? limits_.threads_per_job
                         : std::max(1, tbb::info::default_concurrency() /
                                           static_cast<int>(limits_.max_concurrent_jobs));
  start_time_ = SteadyClock::now();
}

JobManager::~JobManager() { Shutdown(std::chrono::milliseconds(0)); }

void JobManager::Start() {
  const std::vector<StoredJob> queued = store_->RecoverQueued();
  {
    std::lock_guard lock(mutex_);
    for (const StoredJob& row : queued) {
      auto live = std::make_shared<LiveJob>();
      live->row = row;
      live_[row.id] = live;
      queue_.push_back(row.id);
      ++queued_by_owner_[row.owner];
    }
    accepting_ = true;
  }
  if (!queued.empty()) spdlog::info("recovered {} queued job(s) from the store", queued.size());
  for (uint32_t i = 0; i < limits_.max_concurrent_jobs; ++i) {
    workers_.emplace_back([this] { WorkerLoop(); });
  }
  deadline_thread_ = std::thread([this] { DeadlineLoop(); });
}

void JobManager::Shutdown(std::chrono::milliseconds grace) {
  std::unique_lock lock(mutex_);
  if (stopped_) return;
  accepting_ = false;
  draining_ = true;
  changed_.notify_all();
  // Jobs on a cluster are not waited for: their shards keep running and a restart re-attaches.
  const auto any_running = [this] {
    return std::any_of(live_.begin(), live_.end(),
                       [](const auto& e) { return e.second->running && !e.second->on_cluster; });
  };
  if (any_running()) {
    spdlog::info("shutdown: waiting up to {} ms for running jobs", grace.count());
    changed_.wait_for(lock, grace, [&] { return !any_running(); });
  }
  for (auto& [id, live] : live_) {
    if (live->running) {
      live->reason = CancelReason::kShutdown;
      live->cancel.store(true);
    }
  }
  lock.unlock();
  for (std::thread& worker : workers_) worker.join();
  workers_.clear();
  lock.lock();
  std::vector<ClusterThread> cluster_threads = std::move(cluster_threads_);
  cluster_threads_.clear();
  lock.unlock();
  for (ClusterThread& t : cluster_threads) t.thread.join();
  lock.lock();
  stopped_ = true;
  changed_.notify_all();
  lock.unlock();
  if (deadline_thread_.joinable()) deadline_thread_.join();
}

grpc::Status JobManager::Submit(const std::string& owner, const v1::SubmitJobRequest& request,
                                v1::JobStatus* status) {
  ValidatedJob job;
  try {
    job = ValidateSubmitRequest(request, threads_per_job_, limits_.max_job_memory_bytes);
  } catch (const LimitError& e) {
    spdlog::info("submit rejected: owner={} error=\"{}\"", owner, e.what());
    return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED, e.what());
  } catch (const SpecError& e) {
    spdlog::info("submit rejected: owner={} error=\"{}\"", owner, e.what());
    return InvalidArgument(e);
  }
  if (job.samples_total > limits_.max_job_samples) {
    return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                        fmt::format("job cost: {} runs x {} samples = {} samples exceeds the "
                                    "server's limit of {} (--max-job-samples)",
                                    job.runs_total, job.samples_total / job.runs_total,
                                    job.samples_total, limits_.max_job_samples));
  }
  auto live = std::make_shared<LiveJob>();
  StoredJob& row = live->row;
  row.id = NewStoreId("job-");
  row.owner = owner;
  row.request = SerializeDeterministic(request);
  row.name = request.job().name();
  row.runs_total = job.runs_total;
  row.samples_total = job.samples_total;
  row.submitted_unix_s = UnixNow();
  if (request.deadline_s() > 0) row.deadline_unix_s = row.submitted_unix_s + request.deadline_s();

  std::lock_guard lock(mutex_);
  if (!accepting_) {
    return grpc::Status(grpc::StatusCode::UNAVAILABLE, "the server is shutting down");
  }
  uint32_t& queued = queued_by_owner_[owner];
  if (queued >= limits_.max_queued_jobs) {
    return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                        fmt::format("{} jobs of owner {} are queued; the server's limit is {} "
                                    "(--max-queued-jobs)",
                                    queued, owner, limits_.max_queued_jobs));
  }
  store_->Insert(&row);
  ++queued;
  live_[row.id] = live;
  queue_.push_back(row.id);
  // The name is the user's text: escaped and bounded like every echoed input (MessageText).
  spdlog::info("job={} owner={} state=QUEUED runs={} samples={} name=\"{}\"", row.id, owner,
               row.runs_total, row.samples_total, MessageText(row.name, kMaxMessageValueBytes));
  *status = LiveStatus(*live);
  changed_.notify_all();
  return grpc::Status::OK;
}

v1::JobStatus JobManager::LiveStatus(const LiveJob& live) const {
  v1::JobStatus status;
  FillStatus(live.row, &status);
  if (live.running) {
    status.set_runs_done(live.progress.runs_done);
    status.set_samples_done(static_cast<uint64_t>(live.progress.samples_done));
    const double elapsed = std::chrono::duration<double>(SteadyClock::now() - live.started).count();
    status.set_elapsed_s(elapsed);
    if (live.progress.elapsed_s > 0) {
      status.set_samples_per_s(live.progress.samples_done / live.progress.elapsed_s);
    }
  } else {
    status.set_runs_done(0);
    status.set_samples_done(0);
  }
  return status;
}

grpc::Status JobManager::Get(const std::string& owner, const std::string& job_id,
                             v1::JobStatus* status) {
  {
    std::lock_guard lock(mutex_);
    const auto it = live_.find(job_id);
    if (it != live_.end()) {
      if (it->second->row.owner != owner) return NotFound(job_id);
      *status = LiveStatus(*it->second);
      return grpc::Status::OK;
    }
  }
  const std::optional<StoredJob> row = store_->Get(job_id);
  if (!row || row->owner != owner) return NotFound(job_id);
  status->Clear();
  FillStatus(*row, status);
  return grpc::Status::OK;
}

void JobManager::DropQueuedLocked(const std::string& job_id) {
  const auto it = live_.find(job_id);
  if (it == live_.end()) return;
  queue_.erase(std::remove(queue_.begin(), queue_.end(), job_id), queue_.end());
  uint32_t& queued = queued_by_owner_[it->second->row.owner];
  if (queued > 0) --queued;
  live_.erase(it);
}

void JobManager::CancelQueuedLocked(const std::shared_ptr<LiveJob>& live,
                                    const std::string& error) {
  store_->MarkFinished(live->row.id, v1::CANCELLED, error, UnixNow());
  spdlog::info("job={} owner={} state=CANCELLED runs=0 seconds=0 error=\"{}\"", live->row.id,
               live->row.owner, error);
  DropQueuedLocked(live->row.id);
  changed_.notify_all();
}

grpc::Status JobManager::Cancel(const std::string& owner, const std::string& job_id,
                                v1::JobStatus* status) {
  {
    std::unique_lock lock(mutex_);
    const auto it = live_.find(job_id);
    if (it != live_.end()) {
      std::shared_ptr<LiveJob> live = it->second;
      if (live->row.owner != owner) return NotFound(job_id);
      if (!live->running) {
        CancelQueuedLocked(live, "cancelled by its owner");
      } else {
        if (live->reason == CancelReason::kNone) live->reason = CancelReason::kOwner;
        live->cancel.store(true);
        const bool stopped =
            changed_.wait_for(lock, kCancelWait, [&] { return live_.find(job_id) == live_.end(); });
        if (!stopped) {
          return grpc::Status(grpc::StatusCode::INTERNAL,
                              "job " + job_id + " did not stop within 10 s of its cancellation");
        }
      }
    }
  }
  return Get(owner, job_id, status);
}

grpc::Status JobManager::GetResult(const std::string& owner, const std::string& job_id,
                                   v1::JobResult* result) {
  v1::JobStatus status;
  grpc::Status s = Get(owner, job_id, &status);
  if (!s.ok()) return s;
  if (status.state() != v1::SUCCEEDED) {
    return grpc::Status(grpc::StatusCode::FAILED_PRECONDITION,
                        "job " + job_id + " is " + v1::JobState_Name(status.state()) +
                            "; a result exists only for SUCCEEDED jobs");
  }
  const std::optional<std::string> bytes = store_->GetResult(job_id);
  if (!bytes || !result->ParseFromString(*bytes)) {
    return grpc::Status(grpc::StatusCode::DATA_LOSS,
                        "the stored result of " + job_id + " cannot be read");
  }
  return grpc::Status::OK;
}

grpc::Status JobManager::List(const std::string& owner, const v1::ListJobsRequest& request,
                              v1::ListJobsResponse* response) {
  uint32_t page_size = request.page_size() == 0 ? kDefaultPageSize : request.page_size();
  if (page_size > kMaxPageSize) {
    return InvalidArgument(SpecError("page_size", std::to_string(request.page_size()),
                                     "0 (= 100) to " + std::to_string(kMaxPageSize)));
  }
  std::vector<v1::JobState> states;
  for (int s : request.states()) {
    if (!v1::JobState_IsValid(s) || s == v1::JOB_STATE_UNSPECIFIED) {
      return InvalidArgument(
          SpecError("states", std::to_string(s), "QUEUED, RUNNING, SUCCEEDED, FAILED, CANCELLED"));
    }
    states.push_back(static_cast<v1::JobState>(s));
  }
  int64_t before_seq = 0;
  if (!request.page_token().empty()) {
    const std::string& token = request.page_token();
    const bool digits = std::all_of(token.begin(), token.end(), ::isdigit) && token.size() < 19;
    if (!digits || (before_seq = std::stoll(token)) <= 0) {
      return InvalidArgument(
          SpecError("page_token", "\"" + token + "\"", "the next_page_token of the previous page"));
    }
  }
  if (request.name_contains().size() > kMaxNameFilterBytes) {
    return InvalidArgument(SpecError("name_contains",
                                     std::to_string(request.name_contains().size()) + " bytes",
                                     "at most " + std::to_string(kMaxNameFilterBytes) + " bytes"));
  }
  const std::vector<StoredJob> rows =
      store_->List(owner, states, before_seq, page_size + 1, request.name_contains());
  std::lock_guard lock(mutex_);
  for (size_t i = 0; i < rows.size() && i < page_size; ++i) {
    const auto it = live_.find(rows[i].id);
    if (it != live_.end()) {
      *response->add_jobs() = LiveStatus(*it->second);
    } else {
      FillStatus(rows[i], response->add_jobs());
    }
  }
  if (rows.size() > page_size)
    response->set_next_page_token(std::to_string(rows[page_size - 1].seq));
  return grpc::Status::OK;
}

void JobManager::Metrics(v1::ServerMetrics* metrics) {
  for (const auto& [state, count] : store_->CountByState()) {
    (*metrics->mutable_jobs_by_state())[v1::JobState_Name(state)] = count;
  }
  double rate = 0.0;
  uint64_t samples = 0;
  {
    std::lock_guard lock(mutex_);
    samples = samples_finished_;
    for (const auto& [id, live] : live_) {
      if (!live->running) continue;
      samples += static_cast<uint64_t>(live->progress.samples_done);
      if (live->progress.elapsed_s > 0)
        rate += live->progress.samples_done / live->progress.elapsed_s;
    }
  }
  metrics->set_samples_per_s(rate);
  metrics->set_samples_total(samples);
  metrics->set_max_concurrent_jobs(limits_.max_concurrent_jobs);
  metrics->set_max_queued_jobs(limits_.max_queued_jobs);
  metrics->set_max_job_samples(limits_.max_job_samples);
  metrics->set_uptime_s(std::chrono::duration<double>(SteadyClock::now() - start_time_).count());
  metrics->set_version(version_);
}

grpc::Status JobManager::Watch(const std::string& owner, const std::string& job_id,
                               const std::function<bool(const v1::JobStatus&)>& send,
                               const std::function<bool()>& cancelled,
                               std::chrono::system_clock::time_point deadline) {
  // How often a waiting Watch looks at the client's connection and deadline.
  constexpr auto kPoll = std::chrono::milliseconds(50);
  uint64_t sent_version = std::numeric_limits<uint64_t>::max();
  std::unique_lock lock(mutex_);
  for (;;) {
    const auto it = live_.find(job_id);
    if (it == live_.end()) break;  // final (or never existed): answered from the store below
    const std::shared_ptr<LiveJob> live = it->second;
    if (live->row.owner != owner) return NotFound(job_id);
    if (live->version != sent_version) {
      sent_version = live->version;
      const v1::JobStatus status = LiveStatus(*live);
      lock.unlock();
      if (!send(status)) return grpc::Status(grpc::StatusCode::CANCELLED, "client gone");
      lock.lock();
      continue;
    }
    if (stopped_) {
      return grpc::Status(grpc::StatusCode::UNAVAILABLE, "the server is shutting down");
    }
    if (cancelled()) return grpc::Status(grpc::StatusCode::CANCELLED, "client cancelled");
    if (std::chrono::system_clock::now() >= deadline) {
      return grpc::Status(grpc::StatusCode::DEADLINE_EXCEEDED, "the call's deadline passed");
    }
    changed_.wait_for(lock, kPoll);
  }
  lock.unlock();
  const std::optional<StoredJob> row = store_->Get(job_id);
  if (!row || row->owner != owner) return NotFound(job_id);
  v1::JobStatus status;
  FillStatus(*row, &status);
  if (!send(status)) return grpc::Status(grpc::StatusCode::CANCELLED, "client gone");
  return grpc::Status::OK;
}

void JobManager::WorkerLoop() {
  for (;;) {
    std::shared_ptr<LiveJob> live;
    {
      std::unique_lock lock(mutex_);
      changed_.wait(lock, [this] { return draining_ || !queue_.empty(); });
      if (draining_) return;
      live = live_.at(queue_.front());
      queue_.pop_front();
      uint32_t& queued = queued_by_owner_[live->row.owner];
      if (queued > 0) --queued;
      live->running = true;
      live->started = SteadyClock::now();
      live->on_cluster = UsesCluster(live->row);
      if (live->on_cluster) {
        // Join the threads of cluster jobs that ended, then start this one's.
        std::erase_if(cluster_threads_, [](ClusterThread& t) {
          if (!t.finished->load()) return false;
          t.thread.join();
          return true;
        });
        auto finished = std::make_shared<std::atomic<bool>>(false);
        cluster_threads_.push_back({std::thread([this, live, finished] {
                                      RunClusterJob(live);
                                      finished->store(true);
                                    }),
                                    finished});
        continue;
      }
    }
    RunJob(live);
  }
}

bool JobManager::UsesCluster(const StoredJob& row) const {
  if (cluster_.kind == ClusterKind::kNone) {
    if (!row.cluster.empty()) {
      spdlog::warn(
          "job={} was handed to a cluster ({}) but this server has no --cluster: it runs "
          "in-process",
          row.id, row.cluster);
    }
    return false;
  }
  if (!row.cluster.empty()) return true;
  if (row.samples_total <= cluster_.threshold_samples) return false;
  v1::SubmitJobRequest request;
  return request.ParseFromString(row.request) && request.shard().empty();
}

uint32_t JobManager::MarkRunning(const std::shared_ptr<LiveJob>& live) {
  const double started_unix_s = UnixNow();
  const uint32_t attempts = store_->MarkRunning(live->row.id, started_unix_s);
  std::lock_guard lock(mutex_);
  live->row.state = v1::RUNNING;
  live->row.started_unix_s = started_unix_s;
  live->row.attempts = attempts;
  ++live->version;
  changed_.notify_all();
  return attempts;
}

void JobManager::SetCluster(const std::shared_ptr<LiveJob>& live, const std::string& handle) {
  store_->SetCluster(live->row.id, handle);
  std::lock_guard lock(mutex_);
  live->row.cluster = handle;
  ++live->version;
  changed_.notify_all();
}

void JobManager::RunClusterJob(const std::shared_ptr<LiveJob>& live) {
  // How often the cluster is asked for the shards' state (one squeue / kubectl get).
  constexpr auto kClusterPoll = std::chrono::milliseconds(500);
  const std::string& id = live->row.id;
  const uint32_t attempts = MarkRunning(live);
  const uint32_t runs = live->row.runs_total;
  const uint64_t samples_per_run = runs > 0 ? live->row.samples_total / runs : 0;

  v1::JobState final_state = v1::FAILED;
  std::string error;
  bool requeue = false;
  try {
    v1::SubmitJobRequest request;
    if (!request.ParseFromString(live->row.request)) {
      throw std::runtime_error("the stored request cannot be parsed");
    }
    std::unique_ptr<ClusterRun> run = MakeClusterRun(cluster_, id, request, runs);
    const uint32_t k = run->shards();
    if (live->row.cluster.empty()) {
      run->Submit();
      spdlog::info("job={} owner={} state=RUNNING runs={} attempt={} cluster=\"{}\" shards={}", id,
                   live->row.owner, runs, attempts, run->Handle(), k);
    } else {
      run->Attach(live->row.cluster);
      spdlog::info(
          "job={} owner={} state=RUNNING runs={} attempt={} cluster=\"{}\" shards={} "
          "(re-attached)",
          id, live->row.owner, runs, attempts, run->Handle(), k);
    }
    std::string handle = run->Handle();
    SetCluster(live, handle);
    std::string last_text, last_warning;
    for (;;) {
      CancelReason reason = CancelReason::kNone;
      {
        std::lock_guard lock(mutex_);
        if (live->cancel.load()) reason = live->reason;
      }
      if (reason == CancelReason::kShutdown) {
        requeue = true;  // the shards keep running; the next server re-attaches
        break;
      }
      if (reason != CancelReason::kNone) {
        if (!run->Cancel()) spdlog::warn("job={} cancelling {} failed", id, handle);
        final_state = v1::CANCELLED;
        error = reason == CancelReason::kDeadline ? "deadline exceeded" : "cancelled by its owner";
        break;
      }
      std::vector<std::string> notes;
      std::string warning;
      const std::optional<ClusterProgress> progress = run->Poll(&notes, &warning);
      for (const std::string& note : notes) spdlog::info("job={} {}", id, note);
      if (run->Handle() != handle) {
        handle = run->Handle();
        SetCluster(live, handle);
      }
      if (!progress) {
        if (warning != last_warning) spdlog::warn("job={} {}", id, warning);
        last_warning = warning;
      } else {
        if (progress->text != last_text) spdlog::info("job={} {}", id, progress->text);
        last_text = progress->text;
        // Runs of the shards done: shard i holds runs [floor(i N / K), floor((i + 1) N / K)).
        uint32_t runs_done = 0;
        for (const uint32_t i : progress->done_shards) {
          runs_done += static_cast<uint32_t>((uint64_t{i} + 1) * runs / k - uint64_t{i} * runs / k);
        }
        {
          std::lock_guard lock(mutex_);
          live->progress.runs_done = runs_done;
          live->progress.runs_total = runs;
          live->progress.samples_done = static_cast<int64_t>(runs_done * samples_per_run);
          live->progress.samples_total = static_cast<int64_t>(live->row.samples_total);
          live->progress.elapsed_s =
              std::chrono::duration<double>(SteadyClock::now() - live->started).count();
          ++live->version;
          changed_.notify_all();
        }
        if (progress->done == progress->total) {
          const v1::JobResult result = run->Merge(version_);
          app::CheckResultStatistics(result);  // never a non-finite statistic stored as success
          store_->StoreResult(id, SerializeDeterministic(result), UnixNow());
          final_state = v1::SUCCEEDED;
          break;
        }
      }
      std::unique_lock lock(mutex_);
      changed_.wait_for(lock, kClusterPoll, [&] { return live->cancel.load(); });
    }
  } catch (const ClusterError& e) {
    error = std::string("cluster: ") + MessageText(e.what(), kMaxMessageTextBytes);
  } catch (const SpecError& e) {
    error = e.what();
  } catch (const std::exception& e) {
    error = std::string("internal error: ") + MessageText(e.what(), kMaxMessageTextBytes);
  }
  FinishJob(live, final_state, requeue, error, "shutdown; its shards keep running");
}

void JobManager::RunJob(const std::shared_ptr<LiveJob>& live) {
  const std::string& id = live->row.id;
  const uint32_t attempts = MarkRunning(live);
  spdlog::info("job={} owner={} state=RUNNING runs={} attempt={} threads={}", id, live->row.owner,
               live->row.runs_total, attempts, threads_per_job_);

  v1::JobState final_state = v1::FAILED;
  std::string error;
  MonteCarloOutput output;
  bool requeue = false;
  try {
    v1::SubmitJobRequest request;
    if (!request.ParseFromString(live->row.request)) {
      throw std::runtime_error("the stored request cannot be parsed");
    }
    const ValidatedJob job =
        ValidateSubmitRequest(request, threads_per_job_, /*max_memory_bytes=*/0);
    // As `driftlab run`: the Monte-Carlo with the job's analyses (covariance, filter consistency).
    output = RunMonteCarloWithAnalysis(
        job.spec,
        [this, &live](const MonteCarloProgress& p) {
          std::lock_guard lock(mutex_);
          live->progress = p;
          ++live->version;
          changed_.notify_all();
        },
        &live->cancel);
    if (output.statistics.cancelled()) {
      std::lock_guard lock(mutex_);
      final_state = v1::CANCELLED;
      requeue = live->reason == CancelReason::kShutdown;
      error =
          live->reason == CancelReason::kDeadline ? "deadline exceeded" : "cancelled by its owner";
    } else {
      // ToJobResult throws for a non-finite statistic (CheckResultStatistics): never stored as a
      // success.
      const v1::JobResult result =
          app::ToJobResult(app::JobAsRun(request.job(), job.spec), output, version_);
      store_->StoreResult(id, SerializeDeterministic(result), UnixNow());
      final_state = v1::SUCCEEDED;
    }
  } catch (const SpecError& e) {
    error = e.what();
  } catch (const std::exception& e) {
    error = std::string("internal error: ") + MessageText(e.what(), kMaxMessageTextBytes);
  }
  FinishJob(live, final_state, requeue, error, "stopped by shutdown");
}

// The end of a job, in-process or on a cluster: the store's final state (or back to the queue on
// shutdown), the server's sample count, the live entry removed, one log line.
void JobManager::FinishJob(const std::shared_ptr<LiveJob>& live, v1::JobState final_state,
                           bool requeue, const std::string& error, std::string_view requeue_note) {
  const std::string& id = live->row.id;
  if (requeue) {
    store_->Requeue(id);
  } else if (final_state != v1::SUCCEEDED) {
    store_->MarkFinished(id, final_state, error, UnixNow());
  }
  const double seconds = std::chrono::duration<double>(SteadyClock::now() - live->started).count();
  const uint32_t runs = live->row.runs_total;
  std::lock_guard lock(mutex_);
  samples_finished_ += static_cast<uint64_t>(live->progress.samples_done);
  live_.erase(id);
  changed_.notify_all();
  if (requeue) {
    spdlog::info("job={} owner={} state=QUEUED runs={} seconds={:.3f} ({})", id, live->row.owner,
                 runs, seconds, requeue_note);
  } else if (final_state == v1::SUCCEEDED) {
    spdlog::info("job={} owner={} state=SUCCEEDED runs={} seconds={:.3f}", id, live->row.owner,
                 runs, seconds);
  } else {
    spdlog::info("job={} owner={} state={} runs={} seconds={:.3f} error=\"{}\"", id,
                 live->row.owner, v1::JobState_Name(final_state), runs, seconds, error);
  }
}

void JobManager::DeadlineLoop() {
  std::unique_lock lock(mutex_);
  while (!stopped_) {
    const double now = UnixNow();
    double next = std::numeric_limits<double>::infinity();
    std::vector<std::shared_ptr<LiveJob>> expired;
    for (const auto& [id, live] : live_) {
      if (!live->row.deadline_unix_s || live->reason != CancelReason::kNone) continue;
      if (*live->row.deadline_unix_s <= now) {
        expired.push_back(live);
      } else {
        next = std::min(next, *live->row.deadline_unix_s);
      }
    }
    for (const std::shared_ptr<LiveJob>& live : expired) {
      if (live->running) {
        live->reason = CancelReason::kDeadline;
        live->cancel.store(true);
      } else if (!draining_) {
        CancelQueuedLocked(live, "deadline exceeded");
      }
    }
    // Sleep until the next deadline or a change (a new job, shutdown), at most 1 s.
    const double wait_s = std::clamp(next - now, 0.001, 1.0);
    changed_.wait_for(lock, std::chrono::duration<double>(wait_s));
  }
}

}  // namespace driftlab::server
