// The server validates with the one validator of the CLI: every job that an earlier driftlab
// validated and then failed on (or stored with NaN statistics as SUCCEEDED) is refused at
// Jobs.Submit and by the Datasets service with exactly the message `driftlab validate` prints,
// nothing is queued or stored; initial errors stated as fixed rotations about the navigation axes
// run as stated on the server too.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "driftlab/app/job_file.h"
#include "driftlab/server/data_services.h"
#include "in_process_server.h"
#include "jobs_test_util.h"
#include "server_runner.h"
#include "support/bad_jobs.h"

namespace driftlab::testing {
namespace {

// What `driftlab validate` prints for `json` on stderr, without "error: " and the newline.
std::string CliMessage(const std::string& json, const Scratch& scratch) {
  const fs::path path = scratch.dir() / "job.json";
  std::ofstream(path, std::ios::binary) << json;
  const Result r = RunDriftlab({"validate", path.string()}, scratch);
  EXPECT_EQ(r.exit_status, 2) << r.err;
  std::string message = r.err;
  if (message.rfind("error: ", 0) == 0) message = message.substr(7);
  if (!message.empty() && message.back() == '\n') message.pop_back();
  return message;
}

class JobValidationServerTest : public ::testing::Test {
 protected:
  JobValidationServerTest()
      : server_(scratch_.dir() / "data", {"--max-concurrent-jobs", "1", "--threads-per-job", "1"}),
        client_(server_.address()) {}
  void SetUp() override { ASSERT_TRUE(server_.running()) << server_.Log(); }

  // Submits `json`; expects INVALID_ARGUMENT with the CLI's message and nothing queued.
  void ExpectRefusedLikeTheCli(const BadJob& bad) {
    SCOPED_TRACE(bad.name);
    const std::string cli = CliMessage(bad.json, scratch_);
    EXPECT_EQ(cli.rfind(bad.field + ": ", 0), 0u) << cli;
    v1::JobStatus status;
    const grpc::Status submitted =
        client_.Submit(Request(app::ParseJobJson(bad.json, "job")), &status);
    EXPECT_EQ(submitted.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_EQ(submitted.error_message(), cli);
    EXPECT_TRUE(status.job_id().empty());
  }

  Scratch scratch_;
  ServerProcess server_;
  JobsClient client_;
};

TEST_F(JobValidationServerTest, JobsThatValidatedThenFailedAreRefusedAtSubmitLikeTheCli) {
  for (const BadJob& bad : ValidatedThenFailedJobs()) ExpectRefusedLikeTheCli(bad);
  v1::ListJobsResponse listed;
  ASSERT_TRUE(client_.List(v1::ListJobsRequest(), &listed).ok());
  EXPECT_EQ(listed.jobs_size(), 0) << "a refused job was stored";
}

TEST_F(JobValidationServerTest, MessagesNameFieldsOfTheJobSchemaLikeTheCli) {
  for (const BadJob& bad : WrongFieldNameJobs()) ExpectRefusedLikeTheCli(bad);
}

TEST_F(JobValidationServerTest, FixedInitialAttitudeErrorIsARotationAboutTheNavigationAxes) {
  // Heading east (yaw 90 deg), a fixed 0.1 deg rotation about north: the nose drops, a pitch
  // error of -0.1 deg (d pitch = -psi_N at yaw 90 deg, error_state.h), no roll error. The old
  // Euler perturbation attitude_deg [0.1, 0, 0] would have been a roll error at any heading.
  const v1::Job job = app::ParseJobJson(R"({"name": "fixed", "rate_hz": 20,
      "motion": {"initial": {"lat_deg": 45, "lon_deg": 7, "yaw_deg": 90},
                 "segments": [{"static": {"duration_s": 5}}]},
      "monte_carlo": {"runs": 2, "epoch_interval_s": 1,
                      "initial_errors": {"fixed_attitude_ned_deg": [0.1, 0, 0]}}})");
  v1::JobStatus status;
  ASSERT_TRUE(client_.Submit(Request(job), &status).ok());
  ASSERT_EQ(client_.WaitFinal(status.job_id()).state(), v1::SUCCEEDED);
  v1::JobResult result;
  ASSERT_TRUE(client_.GetResult(status.job_id(), &result).ok());
  const v1::EpochStatistics& start = result.epochs(0);
  ASSERT_EQ(start.t_s(), 0.0);
  // Exact, not to first order: Rx(d) Rz(90 deg) = Rz(90 deg) Ry(-d), so the Euler angles are yaw
  // 90 deg, pitch -d, roll 0; only rounding of the degree conversions remains (1e-12 deg).
  EXPECT_NEAR(start.components(v1::PITCH_DEG - 1).mean(), -0.1, 1e-9);
  EXPECT_NEAR(start.components(v1::ROLL_DEG - 1).mean(), 0.0, 1e-9);
  EXPECT_NEAR(start.components(v1::YAW_DEG - 1).mean(), 0.0, 1e-9);
  EXPECT_EQ(start.components(v1::PITCH_DEG - 1).std(), 0.0);  // fixed: the same in every run
}

TEST(JobValidationDatasetsTest, ExportAndScoreRefuseLikeTheCli) {
  Scratch scratch;
  TestAuthenticator accept(true);
  const server::ServerLimits limits;
  std::unique_ptr<v1::Datasets::Service> service = server::MakeDatasetsService(&accept, limits);
  InProcessServer server({service.get()});
  std::unique_ptr<v1::Datasets::Stub> stub = v1::Datasets::NewStub(server.channel());
  for (const BadJob& bad : ValidatedThenFailedJobs()) {
    SCOPED_TRACE(bad.name);
    const std::string cli = CliMessage(bad.json, scratch);
    v1::ExportRunRequest request;
    *request.mutable_run()->mutable_job() = app::ParseJobJson(bad.json, "job");
    grpc::ClientContext context;
    auto reader = stub->ExportRun(&context, request);
    v1::ExportRunResponse response;
    EXPECT_FALSE(reader->Read(&response)) << "rows streamed for a refused job";
    const grpc::Status status = reader->Finish();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_EQ(status.error_message(), cli);
  }
}

}  // namespace
}  // namespace driftlab::testing
