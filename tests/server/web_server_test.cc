// The web pages of driftlab-server (server/src/web, docs/web.md): an in-process server with two
// tokens and --http-port 0 on 127.0.0.1, driven over raw sockets (http_test_client.h). Sign-in,
// the owner checks on every route, CSRF, the content served (the report the CLI renders from the
// result file, the result file itself), and hostile clients: path traversal, oversized and slow
// requests, which must neither crash the server nor stop its gRPC service. The connection limits
// are set small (1 s per request) so that each test takes a few seconds.
#include <gtest/gtest.h>
#include <openssl/err.h>
#include <openssl/ssl.h>
#include <signal.h>

#include <atomic>
#include <fstream>
#include <latch>
#include <regex>
#include <thread>

#include "driftlab/app/result_file.h"
#include "driftlab/report/html_report.h"
#include "driftlab/server/auth.h"
#include "driftlab/server/job_store.h"
#include "driftlab/server/server.h"
#include "http_test_client.h"
#include "jobs_test_util.h"
#include "server_runner.h"

namespace driftlab::testing {
namespace {

using Clock = std::chrono::steady_clock;

constexpr const char* kAliceToken = "alice-web-secret";
constexpr const char* kBobToken = "bob-web-secret";

server::ServerOptions WebServerOptions(const fs::path& dir) {
  std::ofstream(dir / "tokens.txt") << "alice " << server::Sha256Hex(kAliceToken) << "\n"
                                    << "bob " << server::Sha256Hex(kBobToken) << "\n";
  server::ServerOptions options;
  options.listen = "127.0.0.1:0";
  options.data_dir = dir / "data";
  options.tokens_file = dir / "tokens.txt";
  options.limits.threads_per_job = 1;
  options.shutdown_grace = std::chrono::milliseconds(0);
  options.web.port = 0;
  options.web.threads = 8;
  options.web.queue = 16;
  options.web.max_connections_per_client = 4;
  options.web.request_timeout = std::chrono::milliseconds(1000);
  options.web.keep_alive_timeout = std::chrono::milliseconds(1000);
  options.web.write_timeout = std::chrono::milliseconds(5000);
  return options;
}

class WebTest : public ::testing::Test {
 protected:
  void SetUp() override {
    signal(SIGPIPE, SIG_IGN);  // as driftlab-server's main: a client may close first
    server_ = std::make_unique<server::Server>(WebServerOptions(scratch_.dir()));
    port_ = server_->http_port();
    ASSERT_GT(port_, 0);
    address_ = "127.0.0.1:" + std::to_string(server_->port());
  }
  void TearDown() override { server_->Shutdown(); }

  // Submits a job as alice over gRPC and waits for its final state.
  std::string FinishedJob(double duration_s = 10.0, uint32_t runs = 4) {
    const JobsClient alice(address_, kAliceToken);
    v1::JobStatus status;
    EXPECT_TRUE(alice.Submit(Request(StaticJob(duration_s, runs)), &status).ok());
    EXPECT_EQ(alice.WaitFinal(status.job_id()).state(), v1::SUCCEEDED);
    return status.job_id();
  }

  // Submits LongJob() as alice and returns once a Watch has seen it make progress.
  std::string RunningJob() {
    const JobsClient alice(address_, kAliceToken);
    v1::JobStatus status;
    EXPECT_TRUE(alice.Submit(Request(LongJob()), &status).ok());
    alice.Watch(status.job_id(), nullptr, std::chrono::seconds(60),
                [](const v1::JobStatus& s) { return s.samples_done() == 0; });
    return status.job_id();
  }

  Scratch scratch_;
  std::unique_ptr<server::Server> server_;
  int port_ = 0;
  std::string address_;
};

TEST_F(WebTest, WithoutASessionEveryPageLeadsToTheSignInPage) {
  for (const std::string path : {"/", "/jobs", "/jobs/job-000000000000000000000000",
                                 "/jobs/job-000000000000000000000000/result.json", "/calibrations",
                                 "/catalog", "/catalog/tactical"}) {
    const HttpResponse r = HttpRequest(port_, "GET", path);
    EXPECT_EQ(r.status, 303) << path;
    EXPECT_EQ(r.Header("location"), "/signin") << path;
  }
  // The fragments the page script polls answer 401 (the script then goes to the sign-in page).
  EXPECT_EQ(HttpRequest(port_, "GET", "/jobs/rows").status, 401);
  const HttpResponse signin = HttpRequest(port_, "GET", "/signin");
  EXPECT_EQ(signin.status, 200);
  EXPECT_NE(signin.body.find("name=\"token\""), std::string::npos);
  // A made-up session cookie is no session.
  EXPECT_EQ(HttpRequest(port_, "GET", "/jobs",
                        "Cookie: driftlab_session=" + std::string(64, 'a') + "\r\n")
                .status,
            303);
}

TEST_F(WebTest, WrongTokensAreRefusedAfterABoundedNumberOfTriesPerClient) {
  // sign_in_burst = 5 tries per client address; one comes back per 60 s (none during the test).
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(HttpRequest(port_, "POST", "/signin", "", "token=guess" + std::to_string(i)).status,
              401)
        << "try " << i;
  }
  const HttpResponse refused = HttpRequest(port_, "POST", "/signin", "", "token=guess5");
  EXPECT_EQ(refused.status, 429);
  EXPECT_GT(std::atoi(refused.Header("retry-after").c_str()), 0);
  // Once refused, the right token is refused too: guessing stays bounded.
  EXPECT_EQ(HttpRequest(port_, "POST", "/signin", "", std::string("token=") + kAliceToken).status,
            429);
  // Another client address is not affected.
  const WebSession other = SignIn(port_, kAliceToken, "127.0.0.2");
  EXPECT_FALSE(other.cookie.empty());
  EXPECT_EQ(HttpRequest(port_, "GET", "/jobs", other.Head(), "", "127.0.0.2").status, 200);
}

TEST_F(WebTest, SignedInOwnerGetsTheJobPagesTheReportAndTheResultFile) {
  const std::string id = FinishedJob();
  const WebSession alice = SignIn(port_, kAliceToken);
  ASSERT_FALSE(alice.cookie.empty());
  ASSERT_EQ(alice.csrf.size(), 64u);

  const HttpResponse list = HttpRequest(port_, "GET", "/jobs", alice.Head());
  EXPECT_EQ(list.status, 200);
  EXPECT_NE(list.body.find(id), std::string::npos);
  EXPECT_NE(list.body.find("SUCCEEDED"), std::string::npos);
  EXPECT_NE(list.body.find("driftlab submit JOB.json --server " + address_), std::string::npos);

  const HttpResponse page = HttpRequest(port_, "GET", "/jobs/" + id, alice.Head());
  EXPECT_EQ(page.status, 200);
  EXPECT_NE(page.body.find("driftlab result " + id + " --server " + address_), std::string::npos)
      << page.body;
  EXPECT_NE(page.body.find("/jobs/" + id + "/report.html"), std::string::npos);

  const JobsClient grpc(address_, kAliceToken);
  v1::JobResult stored;
  ASSERT_TRUE(grpc.GetResult(id, &stored).ok());
  // The download is the file `driftlab result ID --out` writes.
  const HttpResponse json = HttpRequest(port_, "GET", "/jobs/" + id + "/result.json", alice.Head());
  EXPECT_EQ(json.status, 200);
  EXPECT_EQ(json.body, app::JobResultToJson(stored));
  EXPECT_NE(json.Header("content-disposition").find("attachment"), std::string::npos);
  // The report is the one `driftlab report result.json` renders from that file: the same bytes.
  const HttpResponse report =
      HttpRequest(port_, "GET", "/jobs/" + id + "/report.html", alice.Head());
  EXPECT_EQ(report.status, 200);
  EXPECT_EQ(report.body, app::RenderHtmlReport(app::ParseJobResultJson(json.body)));
  EXPECT_NE(report.Header("content-security-policy").find("sandbox"), std::string::npos);

  // The job file reads back as the submitted job.
  const HttpResponse job = HttpRequest(port_, "GET", "/jobs/" + id + "/job.json", alice.Head());
  EXPECT_EQ(job.status, 200);
  EXPECT_EQ(Deterministic(app::ParseJobJson(job.body, "job.json")),
            Deterministic(StaticJob(10.0, 4)));
}

TEST_F(WebTest, AnotherOwnersJobAndCalibrationAreNotFoundOnEveryRoute) {
  const std::string id = FinishedJob();
  // A calibration record of alice's, written to the same store file through a second connection.
  server::StoredCalibration record;
  record.id = server::NewStoreId("cal-");
  record.owner = "alice";
  record.kind = "calibrate";
  record.settings = v1::CalibrateSettings().SerializeAsString();
  record.result = v1::CalibrationResult().SerializeAsString();
  server::JobStore(scratch_.dir() / "data").InsertCalibration(&record);

  const WebSession alice = SignIn(port_, kAliceToken);
  const WebSession bob = SignIn(port_, kBobToken);
  ASSERT_FALSE(bob.csrf.empty());
  const std::string unknown = "job-0123456789abcdef01234567";
  const std::vector<std::string> routes = {"/jobs/" + id,
                                           "/jobs/" + id + "/status",
                                           "/jobs/" + id + "/report.html",
                                           "/jobs/" + id + "/result.json",
                                           "/jobs/" + id + "/job.json",
                                           "/calibrations/" + record.id,
                                           "/calibrations/" + record.id + "/report.html",
                                           "/calibrations/" + record.id + "/result.json",
                                           "/calibrations/" + record.id + "/settings.json"};
  for (const std::string& route : routes) {
    EXPECT_EQ(HttpRequest(port_, "GET", route, alice.Head()).status, 200) << route;
    const HttpResponse r = HttpRequest(port_, "GET", route, bob.Head());
    EXPECT_EQ(r.status, 404) << route;
    EXPECT_EQ(r.body.find(alice.csrf), std::string::npos);
  }
  // Bob's 404 for alice's job reads exactly as his 404 for a job that does not exist.
  EXPECT_EQ(HttpRequest(port_, "GET", "/jobs/" + id, bob.Head()).body,
            HttpRequest(port_, "GET", "/jobs/" + unknown, bob.Head()).body);
  EXPECT_EQ(
      HttpRequest(port_, "POST", "/jobs/" + id + "/cancel", bob.Head(), "csrf=" + bob.csrf).status,
      404);
  // Neither list shows the other's records.
  EXPECT_EQ(HttpRequest(port_, "GET", "/jobs", bob.Head()).body.find(id), std::string::npos);
  EXPECT_EQ(HttpRequest(port_, "GET", "/calibrations", bob.Head()).body.find(record.id),
            std::string::npos);
  EXPECT_NE(HttpRequest(port_, "GET", "/calibrations", alice.Head()).body.find(record.id),
            std::string::npos);
}

TEST_F(WebTest, CancelWithoutTheFormTokenOrFromAnotherSiteIsRefused) {
  const std::string id = RunningJob();
  const WebSession alice = SignIn(port_, kAliceToken);
  const std::string cancel = "/jobs/" + id + "/cancel";
  EXPECT_EQ(HttpRequest(port_, "POST", cancel, alice.Head(), "").status, 403);
  EXPECT_EQ(HttpRequest(port_, "POST", cancel, alice.Head(), "csrf=" + std::string(64, '0')).status,
            403);
  EXPECT_EQ(HttpRequest(port_, "POST", cancel, alice.Head() + "Origin: http://evil.example\r\n",
                        "csrf=" + alice.csrf)
                .status,
            403);
  EXPECT_EQ(HttpRequest(port_, "POST", cancel, alice.Head() + "Sec-Fetch-Site: cross-site\r\n",
                        "csrf=" + alice.csrf)
                .status,
            403);
  // A token in the query string is not the form's.
  EXPECT_EQ(HttpRequest(port_, "POST", cancel + "?csrf=" + alice.csrf, alice.Head(), "").status,
            403);
  const JobsClient grpc(address_, kAliceToken);
  v1::JobStatus status;
  ASSERT_TRUE(grpc.Get(id, &status).ok());
  EXPECT_EQ(status.state(), v1::RUNNING);

  const HttpResponse done = HttpRequest(port_, "POST", cancel, alice.Head(), "csrf=" + alice.csrf);
  EXPECT_EQ(done.status, 303);
  EXPECT_EQ(done.Header("location"), "/jobs/" + id);
  ASSERT_TRUE(grpc.Get(id, &status).ok());
  EXPECT_EQ(status.state(), v1::CANCELLED);
}

TEST_F(WebTest, PathTraversalFindsNothing) {
  const WebSession alice = SignIn(port_, kAliceToken);
  for (const std::string path :
       {"/static/../../../../etc/passwd", "/static/..%2f..%2f..%2f..%2fetc%2fpasswd",
        "/static/app.css/../../../etc/passwd", "/%2e%2e/%2e%2e/%2e%2e/etc/passwd",
        "/jobs/..%2F..%2F..%2Fetc%2Fpasswd", "/jobs/job-0123456789abcdef01234567/../../etc/passwd",
        "/catalog/..%2F..%2F..%2Fetc%2Fpasswd/sensor.json", "//etc/passwd",
        "/calibrations/..%2f..%2fetc%2fpasswd", "/static/%00app.css",
        "http://127.0.0.1/etc/passwd"}) {
    const HttpResponse r = HttpRequest(port_, "GET", path, alice.Head());
    EXPECT_TRUE(r.status == 400 || r.status == 404) << path << ": " << r.status;
    EXPECT_EQ(r.body.find("root:"), std::string::npos) << path;
  }
  EXPECT_EQ(HttpRequest(port_, "GET", "/static/app.css", alice.Head()).status, 200);
}

// Abuse: requests over the byte budget or the header limits are cut off; the server answers the
// next client as before.
TEST_F(WebTest, HugeRequestsAreCutOffAndTheServerGoesOn) {
  const WebSession alice = SignIn(port_, kAliceToken);
  const auto cut_off = [&](const std::string& request) {
    const int fd = ConnectHttp(port_);
    const bool sent = SendAll(fd, request, std::chrono::seconds(5));
    std::string raw;
    // The server closes the connection within its request deadline (1 s) and some slack.
    const bool closed = ReadToClose(fd, &raw, std::chrono::seconds(5));
    ::close(fd);
    const int status = ParseHttpResponse(raw).status;
    return std::make_tuple(sent, closed, status);
  };
  // 10 MB of header lines (each within httplib's 8 KB line limit): cut at the 64 KiB budget.
  std::string many = "GET /jobs HTTP/1.1\r\nHost: x\r\n";
  for (int i = 0; i < 100000; ++i)
    many += "X-Filler-" + std::to_string(i) + ": " + std::string(80, 'a') + "\r\n";
  many += "\r\n";
  auto [sent, closed, status] = cut_off(many);
  EXPECT_FALSE(sent);  // the server stopped reading long before 10 MB
  EXPECT_TRUE(closed);
  EXPECT_TRUE(status == 0 || status == 400) << status;
  // One header line of 100 KB, a request line of 20 KB, a 1 MB form.
  std::tie(sent, closed, status) =
      cut_off("GET /jobs HTTP/1.1\r\nHost: x\r\nX-Big: " + std::string(100000, 'b') + "\r\n\r\n");
  EXPECT_TRUE(closed);
  EXPECT_TRUE(status == 0 || status == 400) << status;
  std::tie(sent, closed, status) =
      cut_off("GET /" + std::string(20000, 'p') + " HTTP/1.1\r\nHost: x\r\n\r\n");
  EXPECT_TRUE(closed);
  EXPECT_TRUE(status == 0 || status == 414) << status;
  std::tie(sent, closed, status) = cut_off(
      "POST /signin HTTP/1.1\r\nHost: x\r\nContent-Type: application/x-www-form-urlencoded"
      "\r\nContent-Length: 1000000\r\n\r\n" +
      std::string(1000000, 't'));
  EXPECT_TRUE(closed);
  EXPECT_TRUE(status == 0 || status == 413) << status;
  // A Range header of 8 KB (httplib parses ranges with std::regex before any handler runs).
  std::string ranges = "bytes=0-1";
  while (ranges.size() < 8000) ranges += ",0-1";
  const HttpResponse ranged =
      HttpRequest(port_, "GET", "/static/app.css", alice.Head() + "Range: " + ranges + "\r\n");
  EXPECT_TRUE(ranged.status == 200 || ranged.status == 416 || ranged.status == 400)
      << ranged.status;
  // Afterwards the server answers as before, on both services.
  EXPECT_EQ(HttpRequest(port_, "GET", "/jobs", alice.Head()).status, 200);
  v1::ServerMetrics metrics;
  EXPECT_TRUE(JobsClient(address_, kAliceToken).Metrics(&metrics).ok());
}

// Slow clients (connections that send nothing, or one byte at a time) hold a worker for at most
// the request deadline and at most max_connections_per_client workers per address: another
// client is served meanwhile, and a gRPC Watch keeps its rate.
TEST_F(WebTest, SlowClientsBlockNeitherOtherClientsNorTheGrpcWatch) {
  const std::string id = RunningJob();
  const JobsClient grpc(address_, kAliceToken);
  // Watch messages and the longest gap between two, over a window of `window`.
  const auto watch = [&](std::chrono::milliseconds window, double* longest_gap_s) {
    int messages = 0;
    const Clock::time_point end = Clock::now() + window;
    Clock::time_point last = Clock::now();
    *longest_gap_s = 0;
    grpc.Watch(id, nullptr, window + std::chrono::seconds(5), [&](const v1::JobStatus&) {
      const Clock::time_point now = Clock::now();
      *longest_gap_s = std::max(*longest_gap_s, std::chrono::duration<double>(now - last).count());
      last = now;
      ++messages;
      return now < end;
    });
    return messages;
  };
  double gap_before = 0, gap_during = 0;
  const int before = watch(std::chrono::milliseconds(2000), &gap_before);

  // 40 slow connections from 127.0.0.1: silent, or dripping a request head one byte per 100 ms.
  // Each waits (at most 5 s) for the server to answer or close it.
  constexpr int kSlow = 40;
  std::atomic<int> closed_by_server{0};
  std::latch connected(kSlow);
  std::vector<std::thread> slow;
  for (int i = 0; i < kSlow; ++i) {
    slow.emplace_back([&, i] {
      const int fd = ConnectHttp(port_);
      connected.count_down();
      const std::string head = "GET /jobs HTTP/1.1\r\nHost: x\r\nX-Slow: " + std::string(200, 's');
      const Clock::time_point give_up = Clock::now() + std::chrono::seconds(5);
      for (size_t at = 0; Clock::now() < give_up; ++at) {
        if (i % 2 == 1 && at < head.size()) SendAll(fd, head.substr(at, 1));
        pollfd p{fd, POLLIN, 0};
        if (::poll(&p, 1, 100) > 0) {  // an answer (503) or the close
          ++closed_by_server;
          break;
        }
      }
      ::close(fd);
    });
  }
  connected.wait();
  // Meanwhile another client address is served well within the slow ones' 1 s deadline, and the
  // Watch goes on.
  std::thread other([&] {
    for (int i = 0; i < 5; ++i) {
      const Clock::time_point t0 = Clock::now();
      HttpResponse r = HttpRequest(port_, "GET", "/signin", "", "", "127.0.0.3");
      // 503 + Retry-After is the designed answer while the accept queue is full: retry once.
      if (r.status == 503) r = HttpRequest(port_, "GET", "/signin", "", "", "127.0.0.3");
      EXPECT_EQ(r.status, 200) << "request " << i << " of another client during the abuse";
      EXPECT_LT(std::chrono::duration<double>(Clock::now() - t0).count(), 0.9) << "request " << i;
    }
  });
  const int during = watch(std::chrono::milliseconds(2000), &gap_during);
  other.join();
  // Every slow connection is answered or closed by the server: silent and dripping ones at the
  // request deadline (1 s), those over the per-client limit or the queue at once (503).
  for (std::thread& t : slow) t.join();
  EXPECT_EQ(closed_by_server.load(), kSlow);

  // The engine reports progress every 100 ms (monte_carlo.h): ~10 messages per second. A blocked
  // gRPC service would send none; under the shared CI load the rate is kept within a factor 3.
  EXPECT_GE(during, before / 3) << "Watch messages: " << before << " before, " << during
                                << " during the HTTP abuse";
  EXPECT_LT(gap_during, 1.0) << "longest gap between Watch messages during the abuse";
  // The figures, in the test's XML output (--gtest_output=xml), for the record of a run.
  RecordProperty("watch_messages_2s_before", before);
  RecordProperty("watch_messages_2s_during", during);
  RecordProperty("watch_longest_gap_ms_before", static_cast<int>(gap_before * 1000));
  RecordProperty("watch_longest_gap_ms_during", static_cast<int>(gap_during * 1000));
  v1::JobStatus status;
  EXPECT_TRUE(grpc.Cancel(id, &status).ok());
  EXPECT_EQ(HttpRequest(port_, "GET", "/signin").status, 200);
}

TEST_F(WebTest, PagesCarryTheSecurityHeadersAndLoadNothingFromElsewhere) {
  const HttpResponse signin =
      HttpRequest(port_, "POST", "/signin", "", std::string("token=") + kAliceToken);
  const std::string cookie = signin.Header("set-cookie");
  EXPECT_NE(cookie.find("HttpOnly"), std::string::npos);
  EXPECT_NE(cookie.find("SameSite=Lax"), std::string::npos);
  EXPECT_EQ(cookie.find("Secure"), std::string::npos);  // no TLS here
  const WebSession alice = SignIn(port_, kAliceToken);
  for (const std::string path : {"/jobs", "/calibrations", "/catalog", "/catalog/tactical"}) {
    const HttpResponse r = HttpRequest(port_, "GET", path, alice.Head());
    EXPECT_EQ(r.status, 200) << path;
    EXPECT_NE(r.Header("content-security-policy").find("default-src 'none'"), std::string::npos);
    EXPECT_NE(r.Header("content-security-policy").find("script-src 'self'"), std::string::npos);
    EXPECT_EQ(r.Header("x-content-type-options"), "nosniff");
    EXPECT_EQ(r.Header("x-frame-options"), "DENY");
    static const std::regex kExternal(R"((src|href|action)="(https?:)?//)");
    EXPECT_FALSE(std::regex_search(r.body, kExternal)) << path << ": an external resource";
    EXPECT_EQ(r.body.find("<script>"), std::string::npos) << path << ": inline script";
  }
  // A page that reflects the filter text next to the form token is not compressed (BREACH).
  const HttpResponse list = HttpRequest(port_, "GET", "/jobs?name=abc",
                                        alice.Head() +
                                            "Accept-Encoding: gzip, "
                                            "br\r\n");
  EXPECT_EQ(list.Header("content-encoding"), "");
}

TEST_F(WebTest, TheJobListFiltersByStateAndName) {
  const std::string done = FinishedJob();
  const std::string running = RunningJob();
  const WebSession alice = SignIn(port_, kAliceToken);
  const auto listed = [&](const std::string& query) {
    const std::string body = HttpRequest(port_, "GET", "/jobs/rows" + query, alice.Head()).body;
    return std::make_pair(body.find(done) != std::string::npos,
                          body.find(running) != std::string::npos);
  };
  EXPECT_EQ(listed(""), std::make_pair(true, true));
  EXPECT_EQ(listed("?state=RUNNING"), std::make_pair(false, true));
  EXPECT_EQ(listed("?state=SUCCEEDED&state=FAILED"), std::make_pair(true, false));
  EXPECT_EQ(listed("?name=SERVER_STATIC"), std::make_pair(true, true));  // ASCII case ignored
  EXPECT_EQ(listed("?name=no-such-name"), std::make_pair(false, false));
  EXPECT_EQ(HttpRequest(port_, "GET", "/jobs?state=BOGUS", alice.Head()).status, 400);
  EXPECT_EQ(HttpRequest(port_, "GET", "/jobs?name=" + std::string(300, 'n'), alice.Head()).status,
            400);
  // The rows fragment says whether a listed job is still active (the page polls faster then).
  EXPECT_EQ(HttpRequest(port_, "GET", "/jobs/rows", alice.Head()).Header("x-driftlab-active"), "1");
  v1::JobStatus status;
  EXPECT_TRUE(JobsClient(address_, kAliceToken).Cancel(running, &status).ok());
  EXPECT_EQ(HttpRequest(port_, "GET", "/jobs/rows", alice.Head()).Header("x-driftlab-active"), "0");
}

// ---------------------------------------------------------------------------------------------
// TLS: the web pages use the server's certificate; the cookie is Secure with the __Host- prefix.

void MakeCertificates(const fs::path& dir) {
  const std::string commands =
      "cd " + dir.string() +
      " && openssl req -x509 -newkey rsa:2048 -nodes -keyout server.key -out server.pem -days 1 "
      "-subj /CN=127.0.0.1 -addext subjectAltName=IP:127.0.0.1 2>/dev/null";
  ASSERT_EQ(std::system(commands.c_str()), 0);
}

// One HTTPS request (the certificate is not verified: the test checks the server side).
std::string HttpsRequest(int port, const std::string& request) {
  SSL_CTX* ctx = SSL_CTX_new(TLS_client_method());
  SSL* ssl = SSL_new(ctx);
  const int fd = ConnectHttp(port);
  std::string raw;
  SSL_set_fd(ssl, fd);
  if (SSL_connect(ssl) == 1 &&
      SSL_write(ssl, request.data(), static_cast<int>(request.size())) > 0) {
    char buffer[16384];
    int n = 0;
    while ((n = SSL_read(ssl, buffer, sizeof(buffer))) > 0)
      raw.append(buffer, static_cast<size_t>(n));
  }
  SSL_free(ssl);
  SSL_CTX_free(ctx);
  ::close(fd);
  ERR_clear_error();
  return raw;
}

TEST(WebTlsTest, HttpsWithTheServersCertificateAndASecureHostCookie) {
  signal(SIGPIPE, SIG_IGN);
  Scratch scratch;
  MakeCertificates(scratch.dir());
  server::ServerOptions options = WebServerOptions(scratch.dir());
  options.tls_cert = scratch.dir() / "server.pem";
  options.tls_key = scratch.dir() / "server.key";
  server::Server server(options);
  const int port = server.http_port();
  const std::string form = std::string("token=") + kAliceToken;
  const HttpResponse signin = ParseHttpResponse(
      HttpsRequest(port,
                   "POST /signin HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\nContent-Type: "
                   "application/x-www-form-urlencoded\r\nContent-Length: " +
                       std::to_string(form.size()) + "\r\n\r\n" + form));
  EXPECT_EQ(signin.status, 303);
  const std::string cookie = signin.Header("set-cookie");
  EXPECT_EQ(cookie.rfind("__Host-driftlab_session=", 0), 0u) << cookie;
  EXPECT_NE(cookie.find("; Secure"), std::string::npos) << cookie;
  const HttpResponse jobs = ParseHttpResponse(
      HttpsRequest(port, "GET /jobs HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\nCookie: " +
                             cookie.substr(0, cookie.find(';')) + "\r\n\r\n"));
  EXPECT_EQ(jobs.status, 200);
  EXPECT_NE(jobs.body.find("--tls-ca CA.pem"), std::string::npos);
  // Plain HTTP on the TLS port gets no HTTP answer.
  EXPECT_EQ(HttpRequest(port, "GET", "/signin").status, 0);
  server.Shutdown();
}

}  // namespace
}  // namespace driftlab::testing
