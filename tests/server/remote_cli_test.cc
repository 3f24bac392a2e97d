// `driftlab --server ...` end to end: the CLI as a child process against a driftlab-server child
// process on 127.0.0.1 (ephemeral port, SQLite in a scratch directory).
// A remote run writes the local run's result file byte for byte (but for the timings); submit,
// status, watch, cancel, result and jobs round-trip; Ctrl-C during `run --server` cancels the
// job; a wrong or missing token, an unreachable server and a bad job give the documented exit
// statuses and messages; `export --server` writes the local export's files and `score` of the
// engine's own solution reproduces the in-process statistics of that run.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "cli_runner.h"
#include "driftlab/app/result_file.h"
#include "server_runner.h"

namespace {

namespace fs = std::filesystem;
using driftlab::testing::ReadFile;
using driftlab::testing::Result;
using driftlab::testing::RunDriftlab;
using driftlab::testing::Scratch;
using driftlab::testing::ServerProcess;

const fs::path kSmallJob = fs::path(DRIFTLAB_SOURCE_DIR) / "tests/cli/data/mc_small.json";

// The result JSON without its "timings" object (wall and CPU time measure the machine and the
// process, not the job); everything else must match to the byte. "timings" holds no nested
// object, so its closing brace is the first one after the key.
std::string WithoutTimings(std::string json) {
  const size_t start = json.find("\"timings\"");
  if (start == std::string::npos) return json;
  const size_t end = json.find('}', start);
  json.erase(start, end - start + 1);
  return json;
}

void WriteText(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
}

// The small job with one top-level field's value replaced (text edit of the JSON file).
std::string SmallJobWith(const std::string& key, const std::string& value) {
  std::string json = ReadFile(kSmallJob);
  const size_t at = json.find("\"" + key + "\":");
  EXPECT_NE(at, std::string::npos) << key;
  const size_t begin = at + key.size() + 3;
  const size_t end = json.find_first_of(",\n}", begin);
  json.replace(begin, end - begin, " " + value);
  return json;
}

// The first line of `text` that starts with `prefix`, without the newline.
std::string LineStartingWith(const std::string& text, const std::string& prefix) {
  size_t at = 0;
  while (at < text.size()) {
    const size_t end = text.find('\n', at);
    const std::string line = text.substr(at, end == std::string::npos ? end : end - at);
    if (line.rfind(prefix, 0) == 0) return line;
    if (end == std::string::npos) break;
    at = end + 1;
  }
  return "";
}

std::string Trim(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  return text;
}

TEST(RemoteRun, ResultFileEqualsTheLocalRunByteForByteButTimings) {
  Scratch scratch;
  ServerProcess server(scratch.dir() / "data");
  ASSERT_TRUE(server.running()) << server.Log();
  const fs::path local = scratch.dir() / "local.json";
  const fs::path remote = scratch.dir() / "remote.json";
  const fs::path report = scratch.dir() / "remote.html";
  const Result l = RunDriftlab(
      {"run", kSmallJob.string(), "--runs", "12", "--out", local.string(), "-q"}, scratch);
  ASSERT_EQ(l.exit_status, 0) << l.err;
  const Result r = RunDriftlab({"run", kSmallJob.string(), "--runs", "12", "--out", remote.string(),
                                "--report", report.string(), "--server", server.address()},
                               scratch);
  ASSERT_EQ(r.exit_status, 0) << r.err << server.Log();
  // Invariant 3: the statistics are exact sums, independent of threads and process, so the
  // files are equal to the byte (no tolerance), timings aside.
  EXPECT_TRUE(WithoutTimings(ReadFile(local)) == WithoutTimings(ReadFile(remote)));
  // The printed summary is the local one too (its last line is the timings line).
  EXPECT_NE(r.out.find("mc_small: runs 0..11 of 12, seed 3"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("CEP50"), std::string::npos);
  // The progress follows Watch: stderr is a file, so plain lines, the last at 100 %.
  EXPECT_NE(r.err.find("progress: 100% (12/12 runs"), std::string::npos) << r.err;
  EXPECT_NE(ReadFile(report).find("class=\"dl-plot\""), std::string::npos);
}

TEST(RemoteCommands, SubmitStatusWatchResultAndJobsRoundTrip) {
  Scratch scratch;
  ServerProcess server(scratch.dir() / "data");
  ASSERT_TRUE(server.running()) << server.Log();
  const std::string address = server.address();

  const Result submitted = RunDriftlab(
      {"submit", kSmallJob.string(), "--runs", "6", "--seed", "11", "--server", address}, scratch);
  ASSERT_EQ(submitted.exit_status, 0) << submitted.err;
  const std::string id = Trim(submitted.out);
  ASSERT_FALSE(id.empty());
  EXPECT_EQ(id.find('\n'), std::string::npos) << "submit prints only the id: " << submitted.out;

  const Result watched = RunDriftlab({"watch", id, "--server", address}, scratch);
  ASSERT_EQ(watched.exit_status, 0) << watched.err;
  EXPECT_NE(watched.out.find(id), std::string::npos);
  EXPECT_NE(watched.out.find("SUCCEEDED"), std::string::npos) << watched.out;

  const Result status = RunDriftlab({"status", id, "--server", address}, scratch);
  ASSERT_EQ(status.exit_status, 0) << status.err;
  EXPECT_NE(status.out.find("SUCCEEDED"), std::string::npos) << status.out;
  EXPECT_NE(status.out.find("6/6 runs"), std::string::npos) << status.out;

  const fs::path fetched = scratch.dir() / "fetched.json";
  const fs::path report = scratch.dir() / "fetched.html";
  const Result result = RunDriftlab(
      {"result", id, "--out", fetched.string(), "--report", report.string(), "--server", address},
      scratch);
  ASSERT_EQ(result.exit_status, 0) << result.err;
  EXPECT_TRUE(fs::exists(report));
  // The fetched result is the local run with the same overrides (exact sums: byte-equal).
  const fs::path local = scratch.dir() / "local.json";
  ASSERT_EQ(RunDriftlab({"run", kSmallJob.string(), "--runs", "6", "--seed", "11", "--out",
                         local.string(), "-q"},
                        scratch)
                .exit_status,
            0);
  EXPECT_TRUE(WithoutTimings(ReadFile(local)) == WithoutTimings(ReadFile(fetched)));

  const Result jobs = RunDriftlab({"jobs", "--server", address}, scratch);
  ASSERT_EQ(jobs.exit_status, 0) << jobs.err;
  EXPECT_NE(jobs.out.find(id), std::string::npos) << jobs.out;
  const Result succeeded =
      RunDriftlab({"jobs", "--state", "SUCCEEDED", "--server", address}, scratch);
  EXPECT_NE(succeeded.out.find(id), std::string::npos) << succeeded.out;
  const Result queued = RunDriftlab({"jobs", "--state", "QUEUED", "--server", address}, scratch);
  EXPECT_EQ(queued.out.find(id), std::string::npos) << queued.out;
  const Result bad_state = RunDriftlab({"jobs", "--state", "DONE", "--server", address}, scratch);
  EXPECT_EQ(bad_state.exit_status, 2);
  EXPECT_NE(bad_state.err.find("--state: DONE"), std::string::npos) << bad_state.err;

  const Result unknown = RunDriftlab({"status", "no-such-job", "--server", address}, scratch);
  EXPECT_EQ(unknown.exit_status, 1);
  EXPECT_NE(unknown.err.find("not found"), std::string::npos) << unknown.err;
}

TEST(RemoteCommands, CancelEndsALongJobAndResultIsThenRefused) {
  Scratch scratch;
  ServerProcess server(scratch.dir() / "data");
  ASSERT_TRUE(server.running()) << server.Log();
  const std::string address = server.address();
  // 100 000 runs x 2 401 samples: minutes of work, cancelled long before it ends.
  const Result submitted =
      RunDriftlab({"submit", kSmallJob.string(), "--runs", "100000", "--server", address}, scratch);
  ASSERT_EQ(submitted.exit_status, 0) << submitted.err;
  const std::string id = Trim(submitted.out);

  const Result cancelled = RunDriftlab({"cancel", id, "--server", address}, scratch);
  ASSERT_EQ(cancelled.exit_status, 0) << cancelled.err;
  EXPECT_NE(cancelled.out.find("CANCELLED"), std::string::npos) << cancelled.out;

  // Watching a cancelled job returns its final state at once: exit 1, "cancelled".
  const Result watched = RunDriftlab({"watch", id, "--server", address}, scratch);
  EXPECT_EQ(watched.exit_status, 1);
  EXPECT_NE(watched.err.find("was cancelled"), std::string::npos) << watched.err;

  const Result result = RunDriftlab(
      {"result", id, "--out", (scratch.dir() / "r.json").string(), "--server", address}, scratch);
  EXPECT_EQ(result.exit_status, 1);
  EXPECT_FALSE(fs::exists(scratch.dir() / "r.json"));
}

TEST(RemoteRun, CtrlCWhileWatchingCancelsTheRemoteJob) {
  Scratch scratch;
  ServerProcess server(scratch.dir() / "data");
  ASSERT_TRUE(server.running()) << server.Log();
  const fs::path out_file = scratch.dir() / "run.out";
  const fs::path err_file = scratch.dir() / "run.err";
  std::vector<std::string> args = {DRIFTLAB_CLI,
                                   "run",
                                   kSmallJob.string(),
                                   "--runs",
                                   "100000",
                                   "--out",
                                   (scratch.dir() / "never.json").string(),
                                   "--server",
                                   server.address()};
  std::vector<char*> argv;
  for (std::string& s : args) argv.push_back(s.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, out_file.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, err_file.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = 0;
  ASSERT_EQ(posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&actions);

  // The client catches SIGINT from before it submits; wait (bounded, polling its stderr) until
  // the job exists so that the interrupt has a job to cancel.
  std::string id;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (id.empty() && std::chrono::steady_clock::now() < deadline) {
    const std::string line = LineStartingWith(ReadFile(err_file), "submitted job ");
    if (!line.empty() && line.find(" to ") != std::string::npos) {
      id = line.substr(14, line.find(" to ") - 14);
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));  // polling interval
    }
  }
  ASSERT_FALSE(id.empty()) << ReadFile(err_file);
  kill(pid, SIGINT);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status)) << "the client died of the signal instead of handling it";
  EXPECT_EQ(WEXITSTATUS(status), 130);
  const std::string err = ReadFile(err_file);
  EXPECT_NE(err.find("cancelled job " + id), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(scratch.dir() / "never.json"));

  const Result state = RunDriftlab({"status", id, "--server", server.address()}, scratch);
  ASSERT_EQ(state.exit_status, 0) << state.err;
  EXPECT_NE(state.out.find("CANCELLED"), std::string::npos) << state.out;
}

// Seed 003's rate-table form: known rates [deg/s] in, gyro voltages out. `calibrate --server`
// streams the rows to Calibration.Calibrate; the result file equals the local fit's to the byte
// except the measured fit time (same code, same doubles), and the report is written.
TEST(RemoteCalibrate, ReferenceFitOnTheServerEqualsTheLocalFit) {
  Scratch scratch;
  ServerProcess server(scratch.dir() / "data");
  ASSERT_TRUE(server.running()) << server.Log();
  const fs::path data = scratch.dir() / "rate_table.csv";
  WriteText(data,
            "in_x,in_y,in_z,out_x,out_y,out_z\n0,0,0,2.5,2.4,2.4\n100,0,0,3.0,2.41,2.39\n"
            "-100,0,0,2.0,2.39,2.41\n0,100,0,2.5,2.91,2.4\n0,-100,0,2.5,1.89,2.4\n"
            "0,0,100,2.49,2.4,2.9\n0,0,-100,2.51,2.4,1.9\n50,50,50,2.76,2.66,2.65\n");
  const fs::path local = scratch.dir() / "local.json";
  const fs::path remote = scratch.dir() / "remote.json";
  const fs::path report = scratch.dir() / "remote.html";
  const Result l = RunDriftlab(
      {"calibrate", "reference", data.string(), "--input-unit", "deg/s", "--out", local.string()},
      scratch);
  ASSERT_EQ(l.exit_status, 0) << l.err;
  const Result r =
      RunDriftlab({"calibrate", "reference", data.string(), "--input-unit", "deg/s", "--out",
                   remote.string(), "--report", report.string(), "--server", server.address()},
                  scratch);
  ASSERT_EQ(r.exit_status, 0) << r.err << server.Log();
  auto without_fit_time = [](const std::string& json) {
    std::string out;
    size_t at = 0;
    while (at < json.size()) {
      const size_t end = json.find('\n', at);
      const std::string line = json.substr(at, end == std::string::npos ? end : end - at + 1);
      if (line.find("\"fit_time_s\"") == std::string::npos) out += line;
      if (end == std::string::npos) break;
      at = end + 1;
    }
    return out;
  };
  EXPECT_EQ(without_fit_time(ReadFile(local)), without_fit_time(ReadFile(remote)));
  EXPECT_NE(ReadFile(remote).find("x.sensitivity"), std::string::npos);
  EXPECT_NE(ReadFile(report).find("class=\"dl-plot\""), std::string::npos);
  // A bad setting is the server's INVALID_ARGUMENT: exit 2 naming the field.
  const Result bad = RunDriftlab({"calibrate", "gyro", data.string(), "--lat", "95", "--rate",
                                  "100", "--out", remote.string(), "--server", server.address()},
                                 scratch);
  EXPECT_EQ(bad.exit_status, 2) << bad.err;
  EXPECT_NE(bad.err.find("lat"), std::string::npos) << bad.err;
}

TEST(RemoteAuth, WrongOrMissingTokenExitsOneNamingTheToken) {
  Scratch scratch;
  // The tokens file holds SHA-256 hashes; the server's own hash-token prints one.
  const std::string hash_command = std::string(DRIFTLAB_SERVER_BINARY) + " hash-token s3cret";
  FILE* pipe = popen(hash_command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  char buffer[256] = {};
  const size_t n = fread(buffer, 1, sizeof(buffer) - 1, pipe);
  ASSERT_EQ(pclose(pipe), 0);
  const std::string hash = Trim(std::string(buffer, n));
  ASSERT_EQ(hash.size(), 64u) << hash;
  const fs::path tokens = scratch.dir() / "tokens";
  WriteText(tokens, "alice " + hash + "\n");
  ServerProcess server(scratch.dir() / "data", {"--tokens", tokens.string()});
  ASSERT_TRUE(server.running()) << server.Log();
  const std::string address = server.address();

  const Result wrong = RunDriftlab({"jobs", "--server", address, "--token", "guess"}, scratch);
  EXPECT_EQ(wrong.exit_status, 1);
  EXPECT_NE(wrong.err.find("did not accept the credentials"), std::string::npos) << wrong.err;
  EXPECT_NE(wrong.err.find("--token"), std::string::npos) << wrong.err;
  const Result missing = RunDriftlab({"jobs", "--server", address}, scratch);
  EXPECT_EQ(missing.exit_status, 1);
  EXPECT_NE(missing.err.find("did not accept the credentials"), std::string::npos);
  const Result run_wrong =
      RunDriftlab({"run", kSmallJob.string(), "--runs", "2", "--out",
                   (scratch.dir() / "x.json").string(), "--server", address, "--token", "guess"},
                  scratch);
  EXPECT_EQ(run_wrong.exit_status, 1);
  EXPECT_FALSE(fs::exists(scratch.dir() / "x.json"));

  const Result right = RunDriftlab({"jobs", "--server", address, "--token", "s3cret"}, scratch);
  EXPECT_EQ(right.exit_status, 0) << right.err;
  // The token also comes from the environment (the child inherits it).
  setenv("DRIFTLAB_TOKEN", "s3cret", 1);
  const Result from_env =
      RunDriftlab({"submit", kSmallJob.string(), "--runs", "2", "--server", address}, scratch);
  unsetenv("DRIFTLAB_TOKEN");
  EXPECT_EQ(from_env.exit_status, 0) << from_env.err;
}

TEST(RemoteTls, CaFileGivesATlsRoundTripAndPlaintextIsRefused) {
  Scratch scratch;
  // A test CA and a server certificate for 127.0.0.1 signed by it, made with the openssl tool.
  const fs::path d = scratch.dir();
  WriteText(d / "ext", "subjectAltName=IP:127.0.0.1,DNS:localhost\n");
  const std::string openssl =
      "cd '" + d.string() +
      "' && openssl req -x509 -newkey rsa:2048 -nodes -keyout ca.key -out ca.pem -days 1 "
      "-subj '/CN=driftlab test CA' && openssl req -newkey rsa:2048 -nodes -keyout server.key "
      "-out server.csr -subj '/CN=localhost' && openssl x509 -req -in server.csr -CA ca.pem "
      "-CAkey ca.key -CAcreateserial -out server.pem -days 1 -extfile ext";
  ASSERT_EQ(std::system((openssl + " > openssl.log 2>&1").c_str()), 0)
      << ReadFile(d / "openssl.log");
  ServerProcess server(d / "data", {"--tls-cert", (d / "server.pem").string(), "--tls-key",
                                    (d / "server.key").string()});
  ASSERT_TRUE(server.running()) << server.Log();

  const fs::path out = d / "tls.json";
  const Result tls =
      RunDriftlab({"run", kSmallJob.string(), "--runs", "2", "--out", out.string(), "-q",
                   "--server", server.address(), "--tls-ca", (d / "ca.pem").string()},
                  scratch);
  EXPECT_EQ(tls.exit_status, 0) << tls.err << server.Log();
  EXPECT_TRUE(fs::exists(out));
  // A plaintext client cannot talk to a TLS server: the handshake fails, UNAVAILABLE.
  const Result plain = RunDriftlab({"jobs", "--server", server.address()}, scratch);
  EXPECT_EQ(plain.exit_status, 1);
  EXPECT_NE(plain.err.find("cannot reach " + server.address()), std::string::npos) << plain.err;
}

TEST(RemoteErrors, UnreachableServerExitsOneNamingTheAddress) {
  Scratch scratch;
  // Port 1 on loopback: nothing listens there (tcpmux, never run on test machines).
  const Result r = RunDriftlab({"status", "any", "--server", "127.0.0.1:1"}, scratch);
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find("cannot reach 127.0.0.1:1"), std::string::npos) << r.err;
  const Result ca = RunDriftlab(
      {"status", "any", "--server", "127.0.0.1:1", "--tls-ca", "/nonexistent/ca.pem"}, scratch);
  EXPECT_EQ(ca.exit_status, 2);
  EXPECT_NE(ca.err.find("--tls-ca"), std::string::npos) << ca.err;
}

TEST(RemoteErrors, BadJobExitsTwoWithTheLocalValidationMessage) {
  Scratch scratch;
  ServerProcess server(scratch.dir() / "data");
  ASSERT_TRUE(server.running()) << server.Log();
  const fs::path bad = scratch.dir() / "bad_rate.json";
  WriteText(bad, SmallJobWith("rate_hz", "-5"));
  const std::string out = (scratch.dir() / "r.json").string();
  const Result local = RunDriftlab({"run", bad.string(), "--out", out}, scratch);
  ASSERT_EQ(local.exit_status, 2);
  const Result remote =
      RunDriftlab({"run", bad.string(), "--out", out, "--server", server.address()}, scratch);
  EXPECT_EQ(remote.exit_status, 2);
  // One validator for the CLI and the server (DESIGN.md): the same message, naming the field.
  EXPECT_NE(remote.err.find("rate_hz"), std::string::npos) << remote.err;
  EXPECT_EQ(LineStartingWith(remote.err, "error:"), LineStartingWith(local.err, "error:"));
  const Result submit =
      RunDriftlab({"submit", bad.string(), "--server", server.address()}, scratch);
  EXPECT_EQ(submit.exit_status, 2);
  EXPECT_NE(submit.err.find("rate_hz"), std::string::npos) << submit.err;
  // A shard override out of range is refused by the server, naming the request field `shard`
  // with the CLI's rule (i/K with 0 <= i < K).
  const Result shard = RunDriftlab(
      {"submit", kSmallJob.string(), "--shard", "4/4", "--server", server.address()}, scratch);
  EXPECT_EQ(shard.exit_status, 2);
  EXPECT_NE(shard.err.find("shard: \"4/4\""), std::string::npos) << shard.err;
  EXPECT_NE(shard.err.find("0 <= i < K"), std::string::npos) << shard.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST(RemoteExport, ImuAndTruthFilesEqualTheLocalExportAndScoreMatchesTheRun) {
  Scratch scratch;
  ServerProcess server(scratch.dir() / "data");
  ASSERT_TRUE(server.running()) << server.Log();
  const fs::path local = scratch.dir() / "local";
  const fs::path remote = scratch.dir() / "remote";
  const Result l = RunDriftlab({"export", kSmallJob.string(), "--out", local.string()}, scratch);
  ASSERT_EQ(l.exit_status, 0) << l.err;
  const Result r = RunDriftlab({"export", kSmallJob.string(), "--out", remote.string(),
                                "--navigation", "--server", server.address()},
                               scratch);
  ASSERT_EQ(r.exit_status, 0) << r.err << server.Log();
  // Same seeded run, numbers printed as the shortest exact text: equal to the byte.
  EXPECT_TRUE(ReadFile(local / "imu.csv") == ReadFile(remote / "imu.csv"));
  EXPECT_TRUE(ReadFile(local / "truth.csv") == ReadFile(remote / "truth.csv"));
  ASSERT_TRUE(fs::exists(remote / "navigation.csv"));

  // The engine's own solution of run 0 scored against its truth gives the statistics of a
  // one-run Monte-Carlo job (run 0 of the same seed).
  const fs::path scored = scratch.dir() / "score.json";
  const Result s = RunDriftlab({"score", kSmallJob.string(), (remote / "navigation.csv").string(),
                                "--out", scored.string(), "--server", server.address()},
                               scratch);
  ASSERT_EQ(s.exit_status, 0) << s.err << server.Log();
  const fs::path one = scratch.dir() / "one.json";
  ASSERT_EQ(
      RunDriftlab({"run", kSmallJob.string(), "--runs", "1", "--out", one.string(), "-q"}, scratch)
          .exit_status,
      0);
  const driftlab::v1::JobResult a = driftlab::app::ReadJobResult(scored);
  const driftlab::v1::JobResult b = driftlab::app::ReadJobResult(one);
  ASSERT_EQ(a.epochs_size(), b.epochs_size());
  for (int e = 0; e < a.epochs_size(); ++e) {
    ASSERT_EQ(a.epochs(e).t_s(), b.epochs(e).t_s());
    for (int c = 0; c < a.epochs(e).components_size(); ++c) {
      // navigation.csv carries latitude and longitude in degrees: the deg -> rad conversion
      // adds a few ulp (~1e-15 relative) of the angle, i.e. ~1e-8 m on the Earth's radius;
      // 1e-6 (m, m/s, deg) bounds it with margin and is far below any error it compares.
      EXPECT_NEAR(a.epochs(e).components(c).mean(), b.epochs(e).components(c).mean(), 1e-6)
          << "epoch " << e << " component " << c;
    }
  }
}

}  // namespace
