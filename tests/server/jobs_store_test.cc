// In-process tests of the server's store (SQLite), its start-up recovery, the request checks done
// by reflection, and the tokens file.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <cmath>
#include <fstream>
#include <limits>

#include "driftlab/app/schema_check.h"
#include "driftlab/server/auth.h"
#include "driftlab/server/job_manager.h"
#include "driftlab/server/job_store.h"
#include "driftlab/spec_error.h"
#include "jobs_test_util.h"
#include "server_runner.h"

namespace driftlab::testing {
namespace {

server::StoredJob NewJob(const std::string& id, const std::string& owner) {
  server::StoredJob job;
  job.id = id;
  job.owner = owner;
  job.request = "request-bytes";
  job.name = id;
  job.runs_total = 2;
  job.samples_total = 20;
  job.submitted_unix_s = 1.7e9;
  return job;
}

// Runs SQL on a second connection to the store's file; returns the SQLite result code.
int ExecOnFile(const fs::path& db, const std::string& sql) {
  sqlite3* handle = nullptr;
  sqlite3_open(db.c_str(), &handle);
  const int rc = sqlite3_exec(handle, sql.c_str(), nullptr, nullptr, nullptr);
  sqlite3_close(handle);
  return rc;
}

TEST(JobStoreTest, StoredResultIsNeverOverwrittenOrDeleted) {
  Scratch scratch;
  server::JobStore store(scratch.dir());
  server::StoredJob job = NewJob("a", "alice");
  store.Insert(&job);
  EXPECT_EQ(store.MarkRunning("a", 1.7e9 + 1), 1u);
  store.StoreResult("a", "result-1", 1.7e9 + 2);
  EXPECT_EQ(store.Get("a")->state, v1::SUCCEEDED);
  EXPECT_THROW(store.StoreResult("a", "result-2", 1.7e9 + 3), std::runtime_error);
  EXPECT_FALSE(store.MarkFinished("a", v1::FAILED, "late", 1.7e9 + 3));
  // Even direct SQL cannot change or delete a stored result (triggers).
  const fs::path db = scratch.dir() / "driftlab.db";
  EXPECT_NE(ExecOnFile(db, "UPDATE jobs SET result = x'00' WHERE id = 'a'"), SQLITE_OK);
  EXPECT_NE(ExecOnFile(db, "DELETE FROM jobs WHERE id = 'a'"), SQLITE_OK);
  EXPECT_EQ(*store.GetResult("a"), "result-1");
  EXPECT_EQ(store.Get("a")->state, v1::SUCCEEDED);
}

TEST(JobStoreTest, ClusterHandleSurvivesRecoveryAndOldStoresGetTheColumn) {
  Scratch scratch;
  const fs::path db = scratch.dir() / "driftlab.db";
  // A store whose jobs table has no `cluster` column.
  ASSERT_EQ(
      ExecOnFile(db,
                 "CREATE TABLE jobs (seq INTEGER PRIMARY KEY AUTOINCREMENT, id TEXT NOT NULL "
                 "UNIQUE, owner TEXT NOT NULL, state INTEGER NOT NULL, request BLOB NOT NULL, "
                 "name TEXT NOT NULL, runs_total INTEGER NOT NULL, samples_total INTEGER NOT "
                 "NULL, error TEXT NOT NULL DEFAULT '', submitted_unix_s REAL NOT NULL, "
                 "started_unix_s REAL, finished_unix_s REAL, deadline_unix_s REAL, attempts "
                 "INTEGER NOT NULL DEFAULT 0, result BLOB)"),
      SQLITE_OK);
  {
    server::JobStore store(scratch.dir());
    server::StoredJob job = NewJob("a", "alice");
    store.Insert(&job);
    EXPECT_EQ(store.Get("a")->cluster, "");
    store.MarkRunning("a", 1.7e9 + 1);
    store.SetCluster("a", "slurm 12 15");
  }
  server::JobStore reopened(scratch.dir());  // as after a crash: RUNNING goes back to QUEUED
  const std::vector<server::StoredJob> queued = reopened.RecoverQueued();
  ASSERT_EQ(queued.size(), 1u);
  EXPECT_EQ(queued[0].cluster, "slurm 12 15");
  EXPECT_EQ(queued[0].attempts, 1u);
}

TEST(JobStoreTest, RecoveryReturnsRunningJobsToTheQueueInSubmissionOrderWithAttemptsKept) {
  Scratch scratch;
  {
    server::JobStore store(scratch.dir());
    for (const char* id : {"first", "second", "third"}) {
      server::StoredJob job = NewJob(id, "alice");
      store.Insert(&job);
    }
    store.MarkRunning("second", 1.7e9);  // interrupted: the process dies while it runs
    store.MarkRunning("first", 1.7e9);
    store.StoreResult("first", "r", 1.7e9 + 1);
  }
  server::JobStore reopened(scratch.dir());
  const std::vector<server::StoredJob> queued = reopened.RecoverQueued();
  ASSERT_EQ(queued.size(), 2u);
  EXPECT_EQ(queued[0].id, "second");
  EXPECT_EQ(queued[0].attempts, 1u);
  EXPECT_EQ(queued[0].state, v1::QUEUED);
  EXPECT_EQ(queued[1].id, "third");
  EXPECT_EQ(reopened.Get("first")->state, v1::SUCCEEDED);
}

TEST(JobStoreTest, ListIsPerOwnerNewestFirstAndPaged) {
  Scratch scratch;
  server::JobStore store(scratch.dir());
  std::vector<int64_t> seqs;
  for (int i = 0; i < 5; ++i) {
    server::StoredJob job = NewJob("alice-" + std::to_string(i), "alice");
    store.Insert(&job);
    seqs.push_back(job.seq);
    server::StoredJob other = NewJob("bob-" + std::to_string(i), "bob");
    store.Insert(&other);
  }
  const auto page1 = store.List("alice", {}, 0, 2);
  ASSERT_EQ(page1.size(), 2u);
  EXPECT_EQ(page1[0].id, "alice-4");
  EXPECT_EQ(page1[1].id, "alice-3");
  const auto page2 = store.List("alice", {}, page1[1].seq, 10);
  ASSERT_EQ(page2.size(), 3u);
  EXPECT_EQ(page2[2].id, "alice-0");
  store.MarkRunning("alice-1", 1.7e9);
  const auto running = store.List("alice", {v1::RUNNING}, 0, 10);
  ASSERT_EQ(running.size(), 1u);
  EXPECT_EQ(running[0].id, "alice-1");
  EXPECT_EQ(store.CountByState().at(v1::QUEUED), 9u);
}

TEST(JobRequestCheckTest, UnknownEnumNonFiniteNumberAndUnknownFieldNameTheirPath) {
  v1::Job job = StaticJob(10.0, 2);
  job.mutable_navigation()->set_mechanization(static_cast<v1::Navigation::Mechanization>(7));
  try {
    app::CheckMessageValues(job);
    ADD_FAILURE() << "unknown enum accepted";
  } catch (const SpecError& e) {
    EXPECT_EQ(e.field(), "navigation.mechanization");
    EXPECT_NE(std::string(e.what()).find("NED, SEED000"), std::string::npos) << e.what();
  }
  job = StaticJob(10.0, 2);
  job.mutable_monte_carlo()->add_epoch_times_s(1.0);
  job.mutable_monte_carlo()->add_epoch_times_s(-std::numeric_limits<double>::infinity());
  try {
    app::CheckMessageValues(job);
    ADD_FAILURE() << "infinite value accepted";
  } catch (const SpecError& e) {
    EXPECT_EQ(e.field(), "monte_carlo.epoch_times_s[1]");
  }
  job = StaticJob(10.0, 2);
  job.mutable_motion()
      ->mutable_initial()
      ->GetReflection()
      ->MutableUnknownFields(job.mutable_motion()->mutable_initial())
      ->AddVarint(999, 1);
  try {
    app::CheckMessageValues(job);
    ADD_FAILURE() << "unknown field accepted";
  } catch (const SpecError& e) {
    EXPECT_EQ(e.field(), "motion.initial");
    EXPECT_NE(std::string(e.what()).find("999"), std::string::npos);
  }
  EXPECT_NO_THROW(app::CheckMessageValues(StaticJob(10.0, 2)));
}

TEST(JobRequestCheckTest, CostIsRunsTimesTheEnginesSamplesPerRun) {
  v1::SubmitJobRequest request = Request(StaticJob(12.5, 8, 1, 200.0));
  request.set_shard("1/4");  // runs [2, 4) of 8
  const server::ValidatedJob job = server::ValidateSubmitRequest(request, 1);
  EXPECT_EQ(job.runs_total, 2u);
  EXPECT_EQ(job.samples_total, 2u * 2500u);  // 12.5 s x 200 Hz per run
  EXPECT_EQ(job.spec.threads, 1);
}

TEST(TokensFileTest, ReadsOwnersAndHashesAndAuthenticatesBearerTokens) {
  Scratch scratch;
  const fs::path path = scratch.dir() / "tokens";
  std::ofstream(path) << "# comment\n\nalice " << server::Sha256Hex("s3cret") << "\n"
                      << "bob " << server::Sha256Hex("other") << "  \n";
  const server::TokenAuthenticator auth = server::TokenAuthenticator::FromFile(path);
  EXPECT_EQ(auth.size(), 2u);
  std::string owner;
  EXPECT_TRUE(auth.AuthenticateHeader("Bearer s3cret", &owner).ok());
  EXPECT_EQ(owner, "alice");
  EXPECT_EQ(auth.AuthenticateHeader("Bearer s3cre", &owner).error_code(),
            grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_EQ(auth.AuthenticateHeader("s3cret", &owner).error_code(),
            grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_EQ(auth.AuthenticateHeader("", &owner).error_code(), grpc::StatusCode::UNAUTHENTICATED);
  const server::TokenAuthenticator open;
  EXPECT_TRUE(open.AuthenticateHeader("", &owner).ok());
  EXPECT_EQ(owner, "anonymous");
}

}  // namespace
}  // namespace driftlab::testing
