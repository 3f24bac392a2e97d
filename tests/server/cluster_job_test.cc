// The job manager's cluster path without a cluster (job_manager.h, cluster.h): which jobs go to
// the cluster, the job file the shards run, and a submission that fails. The real Slurm path is
// tests/deploy/slurm_server_test.py (ctest slurm_server).
#include <gtest/gtest.h>
#include <stdlib.h>

#include <fstream>
#include <sstream>

#include "cli_runner.h"
#include "driftlab/app/job_file.h"
#include "driftlab/server/job_manager.h"
#include "driftlab/server/job_store.h"
#include "jobs_test_util.h"

namespace driftlab::testing {
namespace {

// Polls Get until the job is final, at most 60 s (a bounded loop; the jobs here are small).
v1::JobStatus WaitFinal(server::JobManager& manager, const std::string& id) {
  v1::JobStatus status;
  for (int i = 0; i < 6000; ++i) {
    EXPECT_TRUE(manager.Get("alice", id, &status).ok());
    if (status.state() != v1::QUEUED && status.state() != v1::RUNNING) return status;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ADD_FAILURE() << "job " << id << " did not finish within 60 s";
  return status;
}

server::ClusterOptions SlurmOptions(const fs::path& dir, uint64_t threshold_samples) {
  server::ClusterOptions options;
  options.kind = server::ClusterKind::kSlurm;
  options.threshold_samples = threshold_samples;
  options.work_dir = dir;
  options.driftlab_binary = DRIFTLAB_CLI;
  return options;
}

TEST(ClusterJobTest, FailedSubmissionFailsTheJobNamingSbatchAndWritesTheJobFile) {
  Scratch scratch;
  // A Slurm configuration sbatch refuses at once ("ClusterName needs to be specified"); without
  // the Slurm packages sbatch cannot start: either way the submission fails.
  const fs::path conf = scratch.dir() / "slurm.conf";
  std::ofstream(conf).close();
  setenv("SLURM_CONF", conf.c_str(), 1);
  server::JobStore store(scratch.dir() / "data");
  server::ServerLimits limits;
  server::JobManager manager(&store, limits, DRIFTLAB_VERSION,
                             SlurmOptions(scratch.dir() / "cluster", /*threshold_samples=*/0));
  manager.Start();
  v1::SubmitJobRequest request = Request(StaticJob(1.0, 4));
  request.set_runs(3);
  v1::JobStatus status;
  ASSERT_TRUE(manager.Submit("alice", request, &status).ok());
  const v1::JobStatus final_status = WaitFinal(manager, status.job_id());
  EXPECT_EQ(final_status.state(), v1::FAILED);
  EXPECT_EQ(final_status.error().rfind("cluster: sbatch failed", 0), 0u) << final_status.error();
  // The job the shards would have run: the request's job, read back equal field for field.
  const fs::path job_file = scratch.dir() / "cluster" / status.job_id() / "job.json";
  std::ifstream in(job_file);
  ASSERT_TRUE(in) << job_file;
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(Deterministic(app::ParseJobJson(text.str(), job_file.string())),
            Deterministic(request.job()));
  EXPECT_EQ(store.Get(status.job_id())->cluster, "");  // nothing was submitted
  manager.Shutdown(std::chrono::milliseconds(0));
  unsetenv("SLURM_CONF");
}

TEST(ClusterJobTest, JobsAtOrBelowTheThresholdRunInProcess) {
  Scratch scratch;
  server::JobStore store(scratch.dir() / "data");
  const v1::SubmitJobRequest request = Request(StaticJob(1.0, 4));  // 4 runs x 100 samples
  server::JobManager manager(&store, server::ServerLimits{}, DRIFTLAB_VERSION,
                             SlurmOptions(scratch.dir() / "cluster", /*threshold_samples=*/400));
  manager.Start();
  v1::JobStatus status;
  ASSERT_TRUE(manager.Submit("alice", request, &status).ok());
  ASSERT_LE(status.samples_total(), 400u);
  EXPECT_EQ(WaitFinal(manager, status.job_id()).state(), v1::SUCCEEDED);
  v1::JobResult result;
  ASSERT_TRUE(manager.GetResult("alice", status.job_id(), &result).ok());
  EXPECT_EQ(WithoutTimings(result), WithoutTimings(InProcessResult(request)));
  EXPECT_FALSE(fs::exists(scratch.dir() / "cluster" / status.job_id()));
  EXPECT_EQ(store.Get(status.job_id())->cluster, "");
  manager.Shutdown(std::chrono::milliseconds(0));
}

}  // namespace
}  // namespace driftlab::testing
