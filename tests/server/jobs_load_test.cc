// driftlab-server under load (child process): many concurrent clients, and the configured limits
// answering RESOURCE_EXHAUSTED while everything accepted still finishes.
#include <gtest/gtest.h>

#include <atomic>
#include <fstream>
#include <mutex>
#include <thread>

#include "driftlab/server/auth.h"
#include "jobs_test_util.h"
#include "server_runner.h"

namespace driftlab::testing {
namespace {

TEST(JobsLoadTest, ThirtyTwoClientsWithFiveJobsEachAllSucceed) {
  Scratch scratch;
  constexpr int kClients = 32, kJobsPerClient = 5;
  // One token (owner) per client; the default --max-queued-jobs (100 per owner) is not reached.
  const fs::path tokens = scratch.dir() / "tokens";
  {
    std::ofstream out(tokens);
    for (int c = 0; c < kClients; ++c) {
      out << "client" << c << " " << server::Sha256Hex("token-" + std::to_string(c)) << "\n";
    }
  }
  ServerProcess server(scratch.dir() / "data", {"--max-concurrent-jobs", "2", "--threads-per-job",
                                                "1", "--tokens", tokens.string()});
  ASSERT_TRUE(server.running()) << server.Log();
  std::atomic<int> succeeded{0};
  std::mutex failures_mutex;
  std::vector<std::string> failures;
  std::vector<std::thread> clients;
  for (int c = 0; c < kClients; ++c) {
    clients.emplace_back([&, c] {
      // Each client its own channel (connection), token and seeds.
      const JobsClient client(server.address(), "token-" + std::to_string(c));
      std::vector<std::string> ids;
      for (int j = 0; j < kJobsPerClient; ++j) {
        v1::JobStatus status;
        const grpc::Status s = client.Submit(Request(StaticJob(10.0, 3, 100 * c + j)), &status);
        if (!s.ok()) {
          std::lock_guard lock(failures_mutex);
          failures.push_back("submit: " + s.error_message());
          continue;
        }
        ids.push_back(status.job_id());
      }
      for (const std::string& id : ids) {
        const v1::JobStatus final_status = client.WaitFinal(id, std::chrono::seconds(300));
        if (final_status.state() == v1::SUCCEEDED) {
          ++succeeded;
        } else {
          std::lock_guard lock(failures_mutex);
          failures.push_back(id + ": " + final_status.error());
        }
      }
    });
  }
  for (std::thread& t : clients) t.join();
  EXPECT_EQ(succeeded.load(), kClients * kJobsPerClient);
  EXPECT_TRUE(failures.empty()) << failures.front();
  v1::ServerMetrics metrics;
  ASSERT_TRUE(JobsClient(server.address(), "token-0").Metrics(&metrics).ok());
  EXPECT_EQ(metrics.jobs_by_state().at("SUCCEEDED"), uint32_t{kClients * kJobsPerClient});
  // 160 jobs x 3 runs x 10 s x 100 Hz.
  EXPECT_EQ(metrics.samples_total(), uint64_t{kClients * kJobsPerClient * 3 * 1000});
}

TEST(JobsLoadTest, LimitsAnswerResourceExhaustedAndEverythingAcceptedFinishes) {
  Scratch scratch;
  // Job cost limit 50,000 samples; at most 2 queued jobs per owner (all clients are "anonymous").
  ServerProcess server(scratch.dir() / "data",
                       {"--max-concurrent-jobs", "1", "--threads-per-job", "1", "--max-queued-jobs",
                        "2", "--max-job-samples", "50000"});
  ASSERT_TRUE(server.running()) << server.Log();
  constexpr int kClients = 8, kJobsPerClient = 6;
  std::mutex mutex;
  int accepted = 0, too_costly = 0, queue_full = 0, succeeded = 0;
  std::vector<std::string> unexpected;
  std::vector<std::thread> clients;
  for (int c = 0; c < kClients; ++c) {
    clients.emplace_back([&, c] {
      const JobsClient client(server.address());
      std::vector<std::string> ids;
      for (int j = 0; j < kJobsPerClient; ++j) {
        // Every third job costs 6 runs x 10,000 samples = 60,000 > 50,000.
        const bool costly = j % 3 == 0;
        const v1::SubmitJobRequest request =
            Request(costly ? StaticJob(100.0, 6, c) : StaticJob(20.0, 4, 10 * c + j));
        v1::JobStatus status;
        const grpc::Status s = client.Submit(request, &status);
        std::lock_guard lock(mutex);
        if (s.ok() && !costly) {
          ++accepted;
          ids.push_back(status.job_id());
        } else if (s.error_code() == grpc::StatusCode::RESOURCE_EXHAUSTED &&
                   s.error_message().find("--max-job-samples") != std::string::npos && costly) {
          ++too_costly;
        } else if (s.error_code() == grpc::StatusCode::RESOURCE_EXHAUSTED &&
                   s.error_message().find("--max-queued-jobs") != std::string::npos) {
          ++queue_full;
        } else {
          unexpected.push_back(std::to_string(s.error_code()) + " " + s.error_message());
        }
      }
      for (const std::string& id : ids) {
        const bool ok = client.WaitFinal(id, std::chrono::seconds(300)).state() == v1::SUCCEEDED;
        std::lock_guard lock(mutex);
        if (ok) ++succeeded;
      }
    });
  }
  for (std::thread& t : clients) t.join();
  EXPECT_TRUE(unexpected.empty()) << unexpected.front();
  EXPECT_EQ(too_costly, kClients * 2);  // jobs 0 and 3 of every client
  EXPECT_GT(queue_full, 0);             // 32 cheap submissions in a burst, 2 queue slots
  EXPECT_GT(accepted, 0);
  EXPECT_EQ(succeeded, accepted);
  std::printf("accepted %d, too costly %d, queue full %d\n", accepted, too_costly, queue_full);
  EXPECT_TRUE(server.running());
}

}  // namespace
}  // namespace driftlab::testing
