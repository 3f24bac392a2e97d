// Durability of driftlab-server (child process, SQLite in a scratch directory): kill -9 in the
// middle of a job and a restart on the same data directory; graceful shutdown on SIGTERM.
#include <gtest/gtest.h>

#include <csignal>

#include "jobs_test_util.h"
#include "server_runner.h"

namespace driftlab::testing {
namespace {

const std::vector<std::string> kOneWorker = {"--max-concurrent-jobs", "1", "--threads-per-job",
                                             "1"};

TEST(ServerRestartTest, KillMinus9MidJobThenRestartKeepsResultsAndRerunsIdentically) {
  Scratch scratch;
  const fs::path data = scratch.dir() / "data";
  const v1::SubmitJobRequest small = Request(StaticJob(60.0, 4, 3));
  // 40 runs x 300 s x 100 Hz = 1.2e6 samples: long enough to be killed after its first progress
  // message.
  const v1::SubmitJobRequest medium = Request(StaticJob(300.0, 40, 5));
  std::string finished_id, interrupted_id, finished_bytes;
  {
    ServerProcess server(data, kOneWorker);
    ASSERT_TRUE(server.running()) << server.Log();
    JobsClient client(server.address());
    v1::JobStatus status;
    ASSERT_TRUE(client.Submit(small, &status).ok());
    finished_id = status.job_id();
    ASSERT_EQ(client.WaitFinal(finished_id).state(), v1::SUCCEEDED);
    v1::JobResult result;
    ASSERT_TRUE(client.GetResult(finished_id, &result).ok());
    finished_bytes = Deterministic(result);

    ASSERT_TRUE(client.Submit(medium, &status).ok());
    interrupted_id = status.job_id();
    std::vector<v1::JobStatus> seen;
    client.Watch(interrupted_id, &seen, std::chrono::seconds(60),
                 [](const v1::JobStatus& s) { return s.samples_done() == 0; });
    ASSERT_FALSE(seen.empty());
    ASSERT_EQ(seen.back().state(), v1::RUNNING);
    ASSERT_LT(seen.back().samples_done(), seen.back().samples_total());
    server.Kill(SIGKILL);
    EXPECT_EQ(server.Wait(), 128 + SIGKILL);
  }
  ServerProcess server(data, kOneWorker);
  ASSERT_TRUE(server.running()) << server.Log();
  JobsClient client(server.address());
  v1::JobStatus status;
  ASSERT_TRUE(client.Get(finished_id, &status).ok());
  EXPECT_EQ(status.state(), v1::SUCCEEDED);
  v1::JobResult result;
  ASSERT_TRUE(client.GetResult(finished_id, &result).ok());
  EXPECT_EQ(Deterministic(result), finished_bytes);  // stored bytes, timings included

  const v1::JobStatus final_status = client.WaitFinal(interrupted_id);
  EXPECT_EQ(final_status.state(), v1::SUCCEEDED) << final_status.error();
  EXPECT_EQ(final_status.attempts(), 2u);  // started before the kill and after the restart
  ASSERT_TRUE(client.GetResult(interrupted_id, &result).ok());
  EXPECT_EQ(WithoutTimings(result), WithoutTimings(InProcessResult(medium)));
  EXPECT_NE(server.Log().find("recovered 1 queued job"), std::string::npos) << server.Log();
}

TEST(ServerRestartTest, SigtermLetsARunningJobFinishWithinTheGracePeriod) {
  Scratch scratch;
  const fs::path data = scratch.dir() / "data";
  std::vector<std::string> args = kOneWorker;
  // Grace long enough for the job at any build speed (an ASan build at -O0 included).
  args.insert(args.end(), {"--shutdown-grace-s", "600"});
  ServerProcess server(data, args);
  ASSERT_TRUE(server.running()) << server.Log();
  JobsClient client(server.address());
  const v1::SubmitJobRequest medium = Request(StaticJob(300.0, 20, 5));
  v1::JobStatus status;
  ASSERT_TRUE(client.Submit(medium, &status).ok());
  const std::string id = status.job_id();
  std::vector<v1::JobStatus> seen;
  client.Watch(id, &seen, std::chrono::seconds(60),
               [](const v1::JobStatus& s) { return s.state() != v1::RUNNING; });
  server.Kill(SIGTERM);
  EXPECT_EQ(server.Wait(), 0) << server.Log();

  ServerProcess restarted(data, kOneWorker);
  ASSERT_TRUE(restarted.running()) << restarted.Log();
  JobsClient again(restarted.address());
  ASSERT_TRUE(again.Get(id, &status).ok());
  EXPECT_EQ(status.state(), v1::SUCCEEDED);  // drained, not interrupted
  EXPECT_EQ(status.attempts(), 1u);
}

TEST(ServerRestartTest, SigtermAfterTheGracePeriodRequeuesTheJobForTheNextStart) {
  Scratch scratch;
  const fs::path data = scratch.dir() / "data";
  std::vector<std::string> args = kOneWorker;
  args.insert(args.end(), {"--shutdown-grace-s", "0.1"});
  ServerProcess server(data, args);
  ASSERT_TRUE(server.running()) << server.Log();
  JobsClient client(server.address());
  v1::JobStatus status;
  ASSERT_TRUE(client.Submit(Request(LongJob()), &status).ok());
  const std::string id = status.job_id();
  std::vector<v1::JobStatus> seen;
  client.Watch(id, &seen, std::chrono::seconds(60),
               [](const v1::JobStatus& s) { return s.state() != v1::RUNNING; });
  server.Kill(SIGTERM);
  EXPECT_EQ(server.Wait(std::chrono::seconds(20)), 0) << server.Log();
  EXPECT_NE(server.Log().find("stopped by shutdown"), std::string::npos) << server.Log();

  ServerProcess restarted(data, kOneWorker);
  ASSERT_TRUE(restarted.running()) << restarted.Log();
  JobsClient again(restarted.address());
  seen.clear();
  again.Watch(id, &seen, std::chrono::seconds(60),
              [](const v1::JobStatus& s) { return s.state() != v1::RUNNING; });
  ASSERT_FALSE(seen.empty());
  EXPECT_EQ(seen.back().state(), v1::RUNNING);
  EXPECT_EQ(seen.back().attempts(), 2u);
  ASSERT_TRUE(again.Cancel(id, &status).ok());
  EXPECT_EQ(status.state(), v1::CANCELLED);
}

}  // namespace
}  // namespace driftlab::testing
