// Durable store of driftlab-server's jobs: one SQLite file (DIR/driftlab.db) in WAL mode.
//
// Table `jobs`: id, owner, state (driftlab.v1.JobState number), the serialized SubmitJobRequest,
// name, runs and samples of the job, the error text, timestamps (Unix seconds), the deadline
// (Unix seconds, absent = none), attempts, the serialized JobResult and `cluster`: where a job
// handed to a cluster runs ("slurm 123 130": the array job ids; "k8s NAME": the Job's name), so a
// restarted server re-attaches to it (cluster.h). `seq` (INTEGER PRIMARY
// KEY) orders jobs by submission.
//
// Durability rules (DESIGN.md "Service", invariant 3):
//  * every write is one transaction (SQLite statement or BEGIN IMMEDIATE ... COMMIT);
//  * a result is written in the same transaction that makes the state SUCCEEDED, so a SUCCEEDED
//    job always has its result;
//  * a stored result is never overwritten or deleted: SQLite triggers abort any UPDATE of a
//    non-null result and any DELETE of a row with a result;
//  * on start, RUNNING jobs (interrupted by a crash) go back to QUEUED with their attempts kept.
// Table `calibrations` (StoredCalibration): one row per successful Calibrate / FitNoiseModel call,
// immutable (triggers abort UPDATE and DELETE).
// All methods are thread-safe (one connection behind a mutex; progress is kept in memory by the
// JobManager, the store sees only state transitions). Errors throw std::runtime_error with the
// SQLite message.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "driftlab/v1/service.pb.h"

struct sqlite3;

namespace driftlab::server {

// A new record id: `prefix` and 24 random hex digits (OpenSSL RAND_bytes), e.g. "job-3f2a...".
std::string NewStoreId(std::string_view prefix);

// One row of the jobs table (without the result bytes).
struct StoredJob {
  int64_t seq = 0;  // submission order, assigned by Insert
  std::string id;
  std::string owner;
  v1::JobState state = v1::QUEUED;
  std::string request;  // serialized v1::SubmitJobRequest
  std::string name;
  uint32_t runs_total = 0;
  uint64_t samples_total = 0;
  std::string error;
  double submitted_unix_s = 0.0;
  std::optional<double> started_unix_s;
  std::optional<double> finished_unix_s;
  std::optional<double> deadline_unix_s;
  uint32_t attempts = 0;
  bool has_result = false;
  std::string cluster;  // "" = runs in the server's process (cluster.h)
};

// One call of Calibration.Calibrate or Calibration.FitNoiseModel that returned a result (table
// `calibrations`; rows are never updated or deleted). The uploaded samples are not kept.
struct StoredCalibration {
  int64_t seq = 0;  // order of the calls, assigned by InsertCalibration
  std::string id;   // "cal-" and 24 hex digits
  std::string owner;
  std::string kind;      // "calibrate" (v1::CalibrateSettings / CalibrationResult) or "noise_fit"
                         // (v1::NoiseFitSettings / NoiseModelFit)
  std::string name;      // CalibrateSettings.data_name, or the fitted columns
  std::string settings;  // the serialized settings message
  std::string result;    // the serialized result (empty in List)
  uint64_t rows = 0;     // rows uploaded
  double created_unix_s = 0.0;
  double elapsed_s = 0.0;  // wall time of the call
};

class JobStore {
 public:
  // Opens (creating if needed) DIR/driftlab.db.
  explicit JobStore(const std::filesystem::path& data_dir);
  ~JobStore();
  JobStore(const JobStore&) = delete;
  JobStore& operator=(const JobStore&) = delete;

  // Inserts a new QUEUED job; sets job->seq.
  void Insert(StoredJob* job);
  std::optional<StoredJob> Get(const std::string& id) const;
  // QUEUED -> RUNNING with attempts + 1 and the start time; returns the new attempt count.
  uint32_t MarkRunning(const std::string& id, double started_unix_s);
  // RUNNING -> SUCCEEDED with the result, in one transaction. Throws if a result is stored already.
  void StoreResult(const std::string& id, const std::string& result, double finished_unix_s);
  // -> FAILED or CANCELLED with the error text (a SUCCEEDED job is left alone: returns false).
  bool MarkFinished(const std::string& id, v1::JobState state, const std::string& error,
                    double finished_unix_s);
  // RUNNING -> QUEUED (graceful shutdown: the job runs again after a restart).
  void Requeue(const std::string& id);
  // Start-up recovery: RUNNING -> QUEUED; returns every QUEUED job in submission order.
  std::vector<StoredJob> RecoverQueued();
  // Records where the job runs on a cluster (kept through Requeue and RecoverQueued).
  void SetCluster(const std::string& id, const std::string& cluster);
  std::optional<std::string> GetResult(const std::string& id) const;
  // The owner's jobs, newest first, with seq < before_seq (0 = from the newest), in `states`
  // (empty = all), whose name contains `name_contains` ignoring ASCII case (empty = all), at most
  // `limit`.
  std::vector<StoredJob> List(const std::string& owner, const std::vector<v1::JobState>& states,
                              int64_t before_seq, uint32_t limit,
                              const std::string& name_contains = "") const;
  std::map<v1::JobState, uint32_t> CountByState() const;

  // Inserts a calibration record; sets record->seq.
  void InsertCalibration(StoredCalibration* record);
  std::optional<StoredCalibration> GetCalibration(const std::string& id) const;
  // The owner's calibrations without their result bytes, newest first, with seq < before_seq
  // (0 = from the newest), at most `limit`.
  std::vector<StoredCalibration> ListCalibrations(const std::string& owner, int64_t before_seq,
                                                  uint32_t limit) const;

 private:
  void Exec(const char* sql) const;
  sqlite3* db_ = nullptr;
  mutable std::mutex mutex_;
};

}  // namespace driftlab::server
