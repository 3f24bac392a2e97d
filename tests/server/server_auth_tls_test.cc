// Security of driftlab-server (child process): bearer tokens from a file of SHA-256 hashes, each
// token owning its jobs; TLS with a CA and a server certificate the test makes with `openssl`.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>

#include "driftlab/server/auth.h"
#include "jobs_test_util.h"
#include "server_runner.h"

namespace driftlab::testing {
namespace {

// FIPS 180-2, appendix B.1: SHA-256("abc").
TEST(ServerAuthTest, Sha256MatchesTheFipsTestVector) {
  EXPECT_EQ(server::Sha256Hex("abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

TEST(ServerAuthTest, HashTokenCommandPrintsTheSha256OfTheToken) {
  Scratch scratch;
  const std::string out = (scratch.dir() / "hash.txt").string();
  const std::string command = std::string(DRIFTLAB_SERVER_BINARY) + " hash-token abc > " + out;
  ASSERT_EQ(std::system(command.c_str()), 0);
  EXPECT_EQ(ReadFile(out), server::Sha256Hex("abc") + "\n");
}

class ServerAuthServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const fs::path tokens = scratch_.dir() / "tokens.txt";
    std::ofstream(tokens) << "# owner sha256(token)\n"
                          << "alice " << server::Sha256Hex("alice-secret") << "\n"
                          << "bob " << server::Sha256Hex("bob-secret") << "\n";
    server_ = std::make_unique<ServerProcess>(
        scratch_.dir() / "data", std::vector<std::string>{"--tokens", tokens.string()});
    ASSERT_TRUE(server_->running()) << server_->Log();
  }
  Scratch scratch_;
  std::unique_ptr<ServerProcess> server_;
};

TEST_F(ServerAuthServerTest, NoOrWrongTokenIsUnauthenticatedAndOtherOwnersJobsAreNotFound) {
  const v1::SubmitJobRequest request = Request(StaticJob(10.0, 2));
  v1::JobStatus status;
  EXPECT_EQ(JobsClient(server_->address()).Submit(request, &status).error_code(),
            grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_EQ(JobsClient(server_->address(), "guess").Submit(request, &status).error_code(),
            grpc::StatusCode::UNAUTHENTICATED);
  v1::ServerMetrics metrics;
  EXPECT_EQ(JobsClient(server_->address()).Metrics(&metrics).error_code(),
            grpc::StatusCode::UNAUTHENTICATED);

  const JobsClient alice(server_->address(), "alice-secret");
  const JobsClient bob(server_->address(), "bob-secret");
  ASSERT_TRUE(alice.Submit(request, &status).ok());
  const std::string id = status.job_id();
  EXPECT_EQ(alice.WaitFinal(id).state(), v1::SUCCEEDED);

  EXPECT_EQ(bob.Get(id, &status).error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(bob.Cancel(id, &status).error_code(), grpc::StatusCode::NOT_FOUND);
  v1::JobResult result;
  EXPECT_EQ(bob.GetResult(id, &result).error_code(), grpc::StatusCode::NOT_FOUND);
  std::vector<v1::JobStatus> statuses;
  EXPECT_EQ(bob.Watch(id, &statuses).error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_TRUE(statuses.empty());
  v1::ListJobsResponse list;
  ASSERT_TRUE(bob.List(v1::ListJobsRequest(), &list).ok());
  EXPECT_EQ(list.jobs_size(), 0);
  ASSERT_TRUE(alice.List(v1::ListJobsRequest(), &list).ok());
  ASSERT_EQ(list.jobs_size(), 1);
  EXPECT_EQ(list.jobs(0).job_id(), id);
  EXPECT_TRUE(alice.GetResult(id, &result).ok());
}

TEST(ServerAuthTest, MalformedTokensFileStopsTheServerNamingTheLine) {
  Scratch scratch;
  const fs::path tokens = scratch.dir() / "tokens.txt";
  std::ofstream(tokens) << "alice " << server::Sha256Hex("a") << "\nbob not-a-hash\n";
  ServerProcess server(scratch.dir() / "data", {"--tokens", tokens.string()});
  EXPECT_FALSE(server.running());
  EXPECT_EQ(server.Wait(), 2);
  EXPECT_NE(server.Log().find("tokens.txt:2"), std::string::npos) << server.Log();
}

// A CA, and a server certificate for 127.0.0.1 signed by it, made with the openssl command line.
void MakeCertificates(const fs::path& dir) {
  const std::string d = dir.string();
  const std::string commands =
      "cd " + d + " && " +
      "openssl req -x509 -newkey rsa:2048 -nodes -keyout ca.key -out ca.pem -days 1 "
      "-subj /CN=driftlab-test-ca 2>/dev/null && "
      "openssl req -newkey rsa:2048 -nodes -keyout server.key -out server.csr "
      "-subj /CN=127.0.0.1 2>/dev/null && "
      "printf 'subjectAltName=IP:127.0.0.1,DNS:localhost\\n' > san.ext && "
      "openssl x509 -req -in server.csr -CA ca.pem -CAkey ca.key -CAcreateserial -out server.pem "
      "-days 1 -extfile san.ext 2>/dev/null && "
      "openssl req -x509 -newkey rsa:2048 -nodes -keyout other.key -out other.pem -days 1 "
      "-subj /CN=other-ca 2>/dev/null";
  ASSERT_EQ(std::system(commands.c_str()), 0);
}

TEST(ServerTlsTest, TlsRoundTripWithATestCaAndNoPlaintextOrForeignCa) {
  Scratch scratch;
  MakeCertificates(scratch.dir());
  ServerProcess server(scratch.dir() / "data",
                       {"--tls-cert", (scratch.dir() / "server.pem").string(), "--tls-key",
                        (scratch.dir() / "server.key").string()});
  ASSERT_TRUE(server.running()) << server.Log();

  grpc::SslCredentialsOptions trusted;
  trusted.pem_root_certs = ReadFile(scratch.dir() / "ca.pem");
  const JobsClient client(grpc::CreateChannel(server.address(), grpc::SslCredentials(trusted)));
  const v1::SubmitJobRequest request = Request(StaticJob(10.0, 2));
  v1::JobStatus status;
  ASSERT_TRUE(client.Submit(request, &status).ok());
  EXPECT_EQ(client.WaitFinal(status.job_id()).state(), v1::SUCCEEDED);
  v1::JobResult result;
  ASSERT_TRUE(client.GetResult(status.job_id(), &result).ok());
  EXPECT_EQ(WithoutTimings(result), WithoutTimings(InProcessResult(request)));

  // A plaintext client and a client trusting another CA cannot talk to it.
  v1::ServerMetrics metrics;
  EXPECT_EQ(JobsClient(server.address()).Metrics(&metrics).error_code(),
            grpc::StatusCode::UNAVAILABLE);
  grpc::SslCredentialsOptions foreign;
  foreign.pem_root_certs = ReadFile(scratch.dir() / "other.pem");
  EXPECT_EQ(JobsClient(grpc::CreateChannel(server.address(), grpc::SslCredentials(foreign)))
                .Metrics(&metrics)
                .error_code(),
            grpc::StatusCode::UNAVAILABLE);
}

}  // namespace
}  // namespace driftlab::testing
