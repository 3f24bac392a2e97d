#include "driftlab/server/job_store.h"

#include <openssl/rand.h>
#include <sqlite3.h>

#include <stdexcept>

namespace driftlab::server {
namespace {

constexpr const char* kSchema = R"sql(
CREATE TABLE IF NOT EXISTS jobs (
  seq INTEGER PRIMARY KEY AUTOINCREMENT,
  id TEXT NOT NULL UNIQUE,
  owner TEXT NOT NULL,
  state INTEGER NOT NULL,
  request BLOB NOT NULL,
  name TEXT NOT NULL,
  runs_total INTEGER NOT NULL,
  samples_total INTEGER NOT NULL,
  error TEXT NOT NULL DEFAULT '',
  submitted_unix_s REAL NOT NULL,
  started_unix_s REAL,
  finished_unix_s REAL,
  deadline_unix_s REAL,
  attempts INTEGER NOT NULL DEFAULT 0,
  result BLOB
);
CREATE INDEX IF NOT EXISTS jobs_owner_seq ON jobs (owner, seq);
CREATE INDEX IF NOT EXISTS jobs_state ON jobs (state);
CREATE TRIGGER IF NOT EXISTS jobs_result_immutable BEFORE UPDATE OF result ON jobs
  WHEN OLD.result IS NOT NULL
  BEGIN SELECT RAISE(ABORT, 'a stored result is never overwritten'); END;
CREATE TRIGGER IF NOT EXISTS jobs_result_kept BEFORE DELETE ON jobs
  WHEN OLD.result IS NOT NULL
  BEGIN SELECT RAISE(ABORT, 'a stored result is never deleted'); END;
CREATE TABLE IF NOT EXISTS calibrations (
  seq INTEGER PRIMARY KEY AUTOINCREMENT,
  id TEXT NOT NULL UNIQUE,
  owner TEXT NOT NULL,
  kind TEXT NOT NULL,
  name TEXT NOT NULL,
  settings BLOB NOT NULL,
  result BLOB NOT NULL,
  rows INTEGER NOT NULL,
  created_unix_s REAL NOT NULL,
  elapsed_s REAL NOT NULL
);
CREATE INDEX IF NOT EXISTS calibrations_owner_seq ON calibrations (owner, seq);
CREATE TRIGGER IF NOT EXISTS calibrations_immutable BEFORE UPDATE ON calibrations
  BEGIN SELECT RAISE(ABORT, 'a stored calibration is never changed'); END;
CREATE TRIGGER IF NOT EXISTS calibrations_kept BEFORE DELETE ON calibrations
  BEGIN SELECT RAISE(ABORT, 'a stored calibration is never deleted'); END;
)sql";

constexpr const char* kColumns =
    "seq, id, owner, state, request, name, runs_total, samples_total, error, submitted_unix_s, "
    "started_unix_s, finished_unix_s, deadline_unix_s, attempts, result IS NOT NULL, cluster";

// "SELECT <columns><rest>", built by appending (GCC 12 warns falsely, -Warray-bounds, about
// std::string("...") + const char* + "..." chains inlined here).
std::string Select(const char* columns, const char* rest) {
  std::string sql = "SELECT ";
  sql.append(columns);
  sql.append(rest);
  return sql;
}

// A prepared statement, finalized on scope exit.
class Statement {
 public:
  Statement(sqlite3* db, const std::string& sql) : db_(db) {
    if (sqlite3_prepare_v2(db, sql.c_str(), -1, &stmt_, nullptr) != SQLITE_OK) Fail("prepare");
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  Statement& Bind(int i, const std::string& text) {
    Check(
        sqlite3_bind_text(stmt_, i, text.data(), static_cast<int>(text.size()), SQLITE_TRANSIENT));
    return *this;
  }
  Statement& BindBlob(int i, const std::string& bytes) {
    Check(sqlite3_bind_blob(stmt_, i, bytes.data(), static_cast<int>(bytes.size()),
                            SQLITE_TRANSIENT));
    return *this;
  }
  Statement& Bind(int i, int64_t value) {
    Check(sqlite3_bind_int64(stmt_, i, value));
    return *this;
  }
  Statement& Bind(int i, double value) {
    Check(sqlite3_bind_double(stmt_, i, value));
    return *this;
  }
  Statement& Bind(int i, const std::optional<double>& value) {
    Check(value ? sqlite3_bind_double(stmt_, i, *value) : sqlite3_bind_null(stmt_, i));
    return *this;
  }
  // True while a row is available.
  bool Step() {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc != SQLITE_DONE) Fail("step");
    return false;
  }
  int64_t Int(int i) const { return sqlite3_column_int64(stmt_, i); }
  double Real(int i) const { return sqlite3_column_double(stmt_, i); }
  bool IsNull(int i) const { return sqlite3_column_type(stmt_, i) == SQLITE_NULL; }
  std::optional<double> OptionalReal(int i) const {
    return IsNull(i) ? std::nullopt : std::optional<double>(Real(i));
  }
  std::string Bytes(int i) const {
    const void* data = sqlite3_column_blob(stmt_, i);
    const int size = sqlite3_column_bytes(stmt_, i);
    return data ? std::string(static_cast<const char*>(data), size) : std::string();
  }

 private:
  void Check(int rc) const {
    if (rc != SQLITE_OK) Fail("bind");
  }
  [[noreturn]] void Fail(const char* what) const {
    throw std::runtime_error(std::string("sqlite ") + what + ": " + sqlite3_errmsg(db_));
  }
  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
};

StoredJob ReadRow(const Statement& s) {
  StoredJob job;
  job.seq = s.Int(0);
  job.id = s.Bytes(1);
  job.owner = s.Bytes(2);
  job.state = static_cast<v1::JobState>(s.Int(3));
  job.request = s.Bytes(4);
  job.name = s.Bytes(5);
  job.runs_total = static_cast<uint32_t>(s.Int(6));
  job.samples_total = static_cast<uint64_t>(s.Int(7));
  job.error = s.Bytes(8);
  job.submitted_unix_s = s.Real(9);
  job.started_unix_s = s.OptionalReal(10);
  job.finished_unix_s = s.OptionalReal(11);
  job.deadline_unix_s = s.OptionalReal(12);
  job.attempts = static_cast<uint32_t>(s.Int(13));
  job.has_result = s.Int(14) != 0;
  job.cluster = s.Bytes(15);
  return job;
}

constexpr const char* kCalibrationColumns =
    "seq, id, owner, kind, name, settings, rows, created_unix_s, elapsed_s";

StoredCalibration ReadCalibration(const Statement& s) {
  StoredCalibration record;
  record.seq = s.Int(0);
  record.id = s.Bytes(1);
  record.owner = s.Bytes(2);
  record.kind = s.Bytes(3);
  record.name = s.Bytes(4);
  record.settings = s.Bytes(5);
  record.rows = static_cast<uint64_t>(s.Int(6));
  record.created_unix_s = s.Real(7);
  record.elapsed_s = s.Real(8);
  return record;
}

}  // namespace

std::string NewStoreId(std::string_view prefix) {
  unsigned char bytes[12];
  if (RAND_bytes(bytes, sizeof(bytes)) != 1) throw std::runtime_error("RAND_bytes failed");
  static constexpr char kHex[] = "0123456789abcdef";
  std::string id(prefix);
  for (unsigned char b : bytes) {
    id.push_back(kHex[b >> 4]);
    id.push_back(kHex[b & 15]);
  }
  return id;
}

JobStore::JobStore(const std::filesystem::path& data_dir) {
  std::filesystem::create_directories(data_dir);
  const std::string path = (data_dir / "driftlab.db").string();
  if (sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr) !=
      SQLITE_OK) {
    const std::string message = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    throw std::runtime_error("cannot open " + path + ": " + message);
  }
  sqlite3_busy_timeout(db_, 5000);
  // WAL: readers never block the writer; synchronous=FULL: a committed transaction survives a
  // power loss, not only a process crash (SQLite documentation, "Write-Ahead Logging").
  Exec("PRAGMA journal_mode=WAL");
  Exec("PRAGMA synchronous=FULL");
  Exec(kSchema);
  // A store whose jobs table lacks the `cluster` column gets it (empty).
  bool has_cluster = false;
  {
    Statement s(db_, "SELECT name FROM pragma_table_info('jobs')");
    while (s.Step()) has_cluster = has_cluster || s.Bytes(0) == "cluster";
  }
  if (!has_cluster) Exec("ALTER TABLE jobs ADD COLUMN cluster TEXT NOT NULL DEFAULT ''");
}

JobStore::~JobStore() { sqlite3_close(db_); }

void JobStore::Exec(const char* sql) const {
  char* error = nullptr;
  if (sqlite3_exec(db_, sql, nullptr, nullptr, &error) != SQLITE_OK) {
    const std::string message = error ? error : "unknown error";
    sqlite3_free(error);
    throw std::runtime_error("sqlite: " + message);
  }
}

void JobStore::Insert(StoredJob* job) {
  std::lock_guard lock(mutex_);
  Statement s(db_,
              "INSERT INTO jobs (id, owner, state, request, name, runs_total, samples_total, "
              "submitted_unix_s, deadline_unix_s) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?)");
  s.Bind(1, job->id)
      .Bind(2, job->owner)
      .Bind(3, int64_t{v1::QUEUED})
      .BindBlob(4, job->request)
      .Bind(5, job->name)
      .Bind(6, int64_t{job->runs_total})
      .Bind(7, static_cast<int64_t>(job->samples_total))
      .Bind(8, job->submitted_unix_s)
      .Bind(9, job->deadline_unix_s);
  s.Step();
  job->seq = sqlite3_last_insert_rowid(db_);
  job->state = v1::QUEUED;
}

std::optional<StoredJob> JobStore::Get(const std::string& id) const {
  std::lock_guard lock(mutex_);
  Statement s(db_, Select(kColumns, " FROM jobs WHERE id = ?"));
  s.Bind(1, id);
  if (!s.Step()) return std::nullopt;
  return ReadRow(s);
}

uint32_t JobStore::MarkRunning(const std::string& id, double started_unix_s) {
  std::lock_guard lock(mutex_);
  Statement s(db_,
              "UPDATE jobs SET state = ?, started_unix_s = ?, attempts = attempts + 1 "
              "WHERE id = ? AND state = ? RETURNING attempts");
  s.Bind(1, int64_t{v1::RUNNING}).Bind(2, started_unix_s).Bind(3, id).Bind(4, int64_t{v1::QUEUED});
  if (!s.Step()) throw std::runtime_error("job " + id + " is not QUEUED");
  const auto attempts = static_cast<uint32_t>(s.Int(0));
  while (s.Step()) {
  }
  return attempts;
}

void JobStore::StoreResult(const std::string& id, const std::string& result,
                           double finished_unix_s) {
  std::lock_guard lock(mutex_);
  // One statement is one transaction: result and state change together.
  Statement s(db_,
              "UPDATE jobs SET result = ?, state = ?, finished_unix_s = ?, error = '' "
              "WHERE id = ? AND state = ?");
  s.BindBlob(1, result)
      .Bind(2, int64_t{v1::SUCCEEDED})
      .Bind(3, finished_unix_s)
      .Bind(4, id)
      .Bind(5, int64_t{v1::RUNNING});
  s.Step();
  if (sqlite3_changes(db_) != 1) throw std::runtime_error("job " + id + " is not RUNNING");
}

bool JobStore::MarkFinished(const std::string& id, v1::JobState state, const std::string& error,
                            double finished_unix_s) {
  std::lock_guard lock(mutex_);
  Statement s(db_,
              "UPDATE jobs SET state = ?, error = ?, finished_unix_s = ? "
              "WHERE id = ? AND state IN (?, ?)");
  s.Bind(1, int64_t{state})
      .Bind(2, error)
      .Bind(3, finished_unix_s)
      .Bind(4, id)
      .Bind(5, int64_t{v1::QUEUED})
      .Bind(6, int64_t{v1::RUNNING});
  s.Step();
  return sqlite3_changes(db_) == 1;
}

void JobStore::Requeue(const std::string& id) {
  std::lock_guard lock(mutex_);
  Statement s(db_, "UPDATE jobs SET state = ? WHERE id = ? AND state = ?");
  s.Bind(1, int64_t{v1::QUEUED}).Bind(2, id).Bind(3, int64_t{v1::RUNNING});
  s.Step();
}

std::vector<StoredJob> JobStore::RecoverQueued() {
  std::lock_guard lock(mutex_);
  {
    Statement s(db_, "UPDATE jobs SET state = ? WHERE state = ?");
    s.Bind(1, int64_t{v1::QUEUED}).Bind(2, int64_t{v1::RUNNING});
    s.Step();
  }
  Statement s(db_, Select(kColumns, " FROM jobs WHERE state = ? ORDER BY seq"));
  s.Bind(1, int64_t{v1::QUEUED});
  std::vector<StoredJob> jobs;
  while (s.Step()) jobs.push_back(ReadRow(s));
  return jobs;
}

void JobStore::SetCluster(const std::string& id, const std::string& cluster) {
  std::lock_guard lock(mutex_);
  Statement s(db_, "UPDATE jobs SET cluster = ? WHERE id = ?");
  s.Bind(1, cluster).Bind(2, id);
  s.Step();
}

std::optional<std::string> JobStore::GetResult(const std::string& id) const {
  std::lock_guard lock(mutex_);
  Statement s(db_, "SELECT result FROM jobs WHERE id = ? AND result IS NOT NULL");
  s.Bind(1, id);
  if (!s.Step()) return std::nullopt;
  return s.Bytes(0);
}

std::vector<StoredJob> JobStore::List(const std::string& owner,
                                      const std::vector<v1::JobState>& states, int64_t before_seq,
                                      uint32_t limit, const std::string& name_contains) const {
  std::string sql = Select(kColumns, " FROM jobs WHERE owner = ?");
  if (before_seq > 0) sql += " AND seq < ?";
  // SQLite's lower() folds ASCII letters only; instr() compares bytes.
  if (!name_contains.empty()) sql += " AND instr(lower(name), lower(?)) > 0";
  if (!states.empty()) {
    sql += " AND state IN (";
    for (size_t i = 0; i < states.size(); ++i) sql += i ? ", ?" : "?";
    sql += ")";
  }
  sql += " ORDER BY seq DESC LIMIT ?";
  std::lock_guard lock(mutex_);
  Statement s(db_, sql);
  int i = 1;
  s.Bind(i++, owner);
  if (before_seq > 0) s.Bind(i++, before_seq);
  if (!name_contains.empty()) s.Bind(i++, name_contains);
  for (v1::JobState state : states) s.Bind(i++, int64_t{state});
  s.Bind(i, int64_t{limit});
  std::vector<StoredJob> jobs;
  while (s.Step()) jobs.push_back(ReadRow(s));
  return jobs;
}

std::map<v1::JobState, uint32_t> JobStore::CountByState() const {
  std::lock_guard lock(mutex_);
  Statement s(db_, "SELECT state, COUNT(*) FROM jobs GROUP BY state");
  std::map<v1::JobState, uint32_t> counts;
  while (s.Step()) counts[static_cast<v1::JobState>(s.Int(0))] = static_cast<uint32_t>(s.Int(1));
  return counts;
}

void JobStore::InsertCalibration(StoredCalibration* record) {
  std::lock_guard lock(mutex_);
  Statement s(db_,
              "INSERT INTO calibrations (id, owner, kind, name, settings, result, rows, "
              "created_unix_s, elapsed_s) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?)");
  s.Bind(1, record->id)
      .Bind(2, record->owner)
      .Bind(3, record->kind)
      .Bind(4, record->name)
      .BindBlob(5, record->settings)
      .BindBlob(6, record->result)
      .Bind(7, static_cast<int64_t>(record->rows))
      .Bind(8, record->created_unix_s)
      .Bind(9, record->elapsed_s);
  s.Step();
  record->seq = sqlite3_last_insert_rowid(db_);
}

std::optional<StoredCalibration> JobStore::GetCalibration(const std::string& id) const {
  std::lock_guard lock(mutex_);
  Statement s(db_, Select(kCalibrationColumns, ", result FROM calibrations WHERE id = ?"));
  s.Bind(1, id);
  if (!s.Step()) return std::nullopt;
  StoredCalibration record = ReadCalibration(s);
  record.result = s.Bytes(9);
  return record;
}

std::vector<StoredCalibration> JobStore::ListCalibrations(const std::string& owner,
                                                          int64_t before_seq,
                                                          uint32_t limit) const {
  std::string sql = Select(kCalibrationColumns, " FROM calibrations WHERE owner = ?");
  if (before_seq > 0) sql += " AND seq < ?";
  sql += " ORDER BY seq DESC LIMIT ?";
  std::lock_guard lock(mutex_);
  Statement s(db_, sql);
  int i = 1;
  s.Bind(i++, owner);
  if (before_seq > 0) s.Bind(i++, before_seq);
  s.Bind(i, int64_t{limit});
  std::vector<StoredCalibration> records;
  while (s.Step()) records.push_back(ReadCalibration(s));
  return records;
}

}  // namespace driftlab::server
