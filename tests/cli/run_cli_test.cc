// `driftlab run`, `merge` and `gate` end to end, as a child process: result and report files,
// shards merged equal to one process, bad command lines and jobs, and the CI gate catching a
// degraded sensor.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "support/cli_runner.h"
#include "support/report_html.h"

namespace {

namespace fs = std::filesystem;
using driftlab::testing::ReadFile;
using driftlab::testing::Result;
using driftlab::testing::RunDriftlab;
using driftlab::testing::Scratch;

// The result JSON without its "timings" object (wall and CPU time measure the machine, not the
// job) and without "engine_version"-independent parts: everything else must match to the byte.
std::string WithoutTimings(std::string json) {
  const size_t start = json.find("\"timings\"");
  if (start == std::string::npos) return json;
  const size_t end = json.find('}', start);
  json.erase(start, end - start + 1);
  return json;
}

TEST(Run, WritesAResultAndASelfContainedReport) {
  Scratch scratch;
  const fs::path result = scratch.dir() / "out" / "result.json";
  const fs::path report = scratch.dir() / "out" / "report.html";
  const Result r = RunDriftlab({"run", (kCliData / "mc_small.json").string(), "--out",
                                result.string(), "--report", report.string(), "--threads", "2"},
                               scratch);
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("mc_small: runs 0..39 of 40, seed 3"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("CEP50"), std::string::npos);
  // Progress: stderr is a file here, so plain lines, the last at 100 %.
  EXPECT_NE(r.err.find("progress: 100% (40/40 runs"), std::string::npos) << r.err;
  const std::string json = ReadFile(result);
  EXPECT_NE(json.find("\"merge_state\""), std::string::npos);
  // Valid JSON that another tool reads: Python's json module parses it and finds 40 runs.
  const std::string check =
      "/usr/bin/python3 -c \"import json,sys; r=json.load(open(sys.argv[1]));"
      " sys.exit(0 if r['runs']==40 and len(r['checkpoints'][-1]['runs'])==40"
      " else 1)\" " +
      result.string();
  EXPECT_EQ(std::system(check.c_str()), 0);
  const std::string html = ReadFile(report);
  EXPECT_NE(html.find("class=\"dl-plot\""), std::string::npos);
  const std::string markup = ::driftlab::testing::WithoutScriptText(html);
  EXPECT_EQ(markup.find("http://"), std::string::npos);
  EXPECT_EQ(markup.find("https://"), std::string::npos);
}

TEST(Run, ConsistencyVerdictIsPrintedAndOnTheReportsFirstScreen) {
  // With a covariance analysis (or a filter) the run says whether the Monte-Carlo
  // spread agrees with the prediction: one line, on stdout when consistent, as a warning on
  // stderr when not; the report shows the verdict before the summary table.
  Scratch scratch;
  const fs::path result = scratch.dir() / "result.json";
  const fs::path report = scratch.dir() / "report.html";
  // The covariance analysis needs the free vertical channel, and at 20 Hz a propagation interval
  // of at most the tactical preset's shortest flicker state (0.25 s = 5 samples).
  std::string text = ReadFile(kCliData / "mc_small.json");
  text.replace(text.find("TRUTH_HEIGHT"), 12, "FREE");
  text.replace(text.find(R"("runs": 40,)"), 11, R"("runs": 40, "covariance_step_samples": 5,)");
  const fs::path job = scratch.dir() / "mc_small_free.json";
  std::ofstream(job) << text;
  const Result r = RunDriftlab(
      {"run", job.string(), "--covariance", "--out", result.string(), "--report", report.string()},
      scratch);
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const bool consistent =
      r.out.find("consistency: consistent at family-wise level 0.05") != std::string::npos;
  const bool warned = r.err.find("warning: consistency: INCONSISTENT at family-wise level 0.05") !=
                      std::string::npos;
  EXPECT_TRUE(consistent != warned) << r.out << r.err;
  const std::string html = ReadFile(report);
  const size_t verdict = html.find("Consistency: ");
  ASSERT_NE(verdict, std::string::npos);
  EXPECT_LT(verdict, html.find("<h2>Summary"));
  // Without a prediction or a filter there is nothing to judge, and nothing is printed.
  const Result plain = RunDriftlab(
      {"run", (kCliData / "mc_small.json").string(), "--out", result.string()}, scratch);
  ASSERT_EQ(plain.exit_status, 0) << plain.err;
  EXPECT_EQ((plain.out + plain.err).find("consistency:"), std::string::npos);
}

TEST(Run, FourShardsMergedEqualOneProcessAndThreadsDoNotMatter) {
  Scratch scratch;
  const std::string job = (kCliData / "mc_small.json").string();
  auto file = [&scratch](const std::string& name) { return (scratch.dir() / name).string(); };
  ASSERT_EQ(RunDriftlab({"run", job, "--out", file("one.json"), "--threads", "1", "-q"}, scratch)
                .exit_status,
            0);
  ASSERT_EQ(RunDriftlab({"run", job, "--out", file("two.json"), "--threads", "2", "-q"}, scratch)
                .exit_status,
            0);
  std::vector<std::string> merge = {"merge"};
  for (int i = 3; i >= 0; --i) {
    const std::string shard = file("shard" + std::to_string(i) + ".json");
    const Result r = RunDriftlab(
        {"run", job, "--shard", std::to_string(i) + "/4", "--out", shard, "-q"}, scratch);
    ASSERT_EQ(r.exit_status, 0) << r.err;
    merge.push_back(shard);
  }
  merge.insert(merge.end(), {"--out", file("merged.json")});
  const Result m = RunDriftlab(merge, scratch);
  ASSERT_EQ(m.exit_status, 0) << m.err;
  // Byte comparison of the files (EXPECT_TRUE: the files are too long to print).
  const std::string one = WithoutTimings(ReadFile(file("one.json")));
  EXPECT_TRUE(one == WithoutTimings(ReadFile(file("two.json"))));
  EXPECT_TRUE(one == WithoutTimings(ReadFile(file("merged.json"))));
  // A shard alone is not the whole job, and two copies of one shard do not merge.
  EXPECT_FALSE(one == WithoutTimings(ReadFile(file("shard0.json"))));
  const Result twice = RunDriftlab(
      {"merge", file("shard0.json"), file("shard0.json"), "--out", file("bad.json")}, scratch);
  EXPECT_EQ(twice.exit_status, 2);
  EXPECT_FALSE(fs::exists(file("bad.json")));
}

// The result file is the same to the byte on every instruction-set path of the
// lockstep runner (DRIFTLAB_ISA, inherited by the child process) and on the scalar reference.
TEST(Run, EveryInstructionSetPathWritesTheSameResultFile) {
  Scratch scratch;
  const std::string job = (kCliData / "mc_small.json").string();
  auto file = [&scratch](const std::string& name) { return (scratch.dir() / name).string(); };
  std::vector<std::string> paths = {"scalar", "baseline"};
#if defined(__x86_64__)
  if (__builtin_cpu_supports("avx2")) paths.push_back("avx2");
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
      __builtin_cpu_supports("avx512vl")) {
    paths.push_back("avx512");
  }
#endif
  std::string reference;
  for (const std::string& path : paths) {
    SCOPED_TRACE(path);
    setenv("DRIFTLAB_ISA", path.c_str(), 1);
    const Result r = RunDriftlab({"run", job, "--out", file(path + ".json"), "-q"}, scratch);
    unsetenv("DRIFTLAB_ISA");
    ASSERT_EQ(r.exit_status, 0) << r.err;
    const std::string text = WithoutTimings(ReadFile(file(path + ".json")));
    if (reference.empty()) reference = text;
    EXPECT_TRUE(text == reference);  // the files are too long to print
  }
  setenv("DRIFTLAB_ISA", "sse9", 1);
  const Result bad = RunDriftlab({"run", job, "--out", file("bad.json"), "-q"}, scratch);
  unsetenv("DRIFTLAB_ISA");
  EXPECT_EQ(bad.exit_status, 2);
  EXPECT_NE(bad.err.find("DRIFTLAB_ISA"), std::string::npos) << bad.err;
}

TEST(Run, BadCommandLinesAndJobsNameTheField) {
  Scratch scratch;
  const std::string job = (kCliData / "mc_small.json").string();
  const std::string out = (scratch.dir() / "r.json").string();
  struct Case {
    std::vector<std::string> args;
    const char* expected;
  };
  const Case cases[] = {
      {{"run", job, "--out", out, "--runs", "0"}, "--runs: 0 is not allowed; allowed: 1 <= --runs"},
      {{"run", job, "--out", out, "--shard", "4/4"}, "--shard: 4/4 is not allowed"},
      {{"run", job, "--out", out, "--shard", "2"}, "--shard: 2 is not allowed"},
      {{"run", (kCliData / "mc_bad_epochs.json").string(), "--out", out},
       "monte_carlo.epoch_times_s[1]"},
      {{"run", (kCliData / "mc_bad_runs.json").string(), "--out", out},
       "monte_carlo.runs: 0 is not allowed"},
      // The job's memory (2401 IMU increments of 48 bytes alone: 115 kB) over a 1 kB limit:
      // refused before the truth is generated, naming the option that raises the limit.
      {{"run", job, "--out", out, "--max-memory-gb", "0.000001"},
       "raise the limit with driftlab run --max-memory-gb"},
      {{"run", job, "--out", out, "--max-memory-gb", "-1"}, "--max-memory-gb: -1 is not allowed"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args[c.args.size() - 1]);
    const Result r = RunDriftlab(c.args, scratch);
    EXPECT_EQ(r.exit_status, 2);
    EXPECT_NE(r.err.find(c.expected), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
}

TEST(Gate, ADegradedPresetFailsAgainstTheOriginalsBaselineAndTheOriginalPasses) {
  Scratch scratch;
  auto file = [&scratch](const std::string& name) { return (scratch.dir() / name).string(); };
  ASSERT_EQ(
      RunDriftlab({"run", (kCliData / "mc_small.json").string(), "--out", file("base.json"), "-q"},
                  scratch)
          .exit_status,
      0);
  ASSERT_EQ(
      RunDriftlab({"run", (kCliData / "mc_small.json").string(), "--out", file("again.json"), "-q"},
                  scratch)
          .exit_status,
      0);
  ASSERT_EQ(RunDriftlab({"run", (kCliData / "mc_small_degraded.json").string(), "--out",
                         file("degraded.json"), "-q"},
                        scratch)
                .exit_status,
            0);

  const Result pass = RunDriftlab(
      {"gate", file("again.json"), "--baseline", file("base.json"), "--junit", file("pass.xml")},
      scratch);
  EXPECT_EQ(pass.exit_status, 0) << pass.out << pass.err;

  // The degraded sensor (gyro and accelerometer turn-on bias and gyro bias instability doubled)
  // is a different job: the gate says so unless told to compare anyway.
  const Result refused =
      RunDriftlab({"gate", file("degraded.json"), "--baseline", file("base.json")}, scratch);
  EXPECT_EQ(refused.exit_status, 2) << refused.out << refused.err;
  const Result fail = RunDriftlab({"gate", file("degraded.json"), "--baseline", file("base.json"),
                                   "--allow-different-job", "--junit", file("fail.xml")},
                                  scratch);
  EXPECT_EQ(fail.exit_status, 1) << fail.out << fail.err;
  EXPECT_NE(fail.out.find("final.horizontal_position_m.p95"), std::string::npos) << fail.out;
  EXPECT_NE(fail.out.find("FAIL"), std::string::npos);

  // Both JUnit files are XML that Python's parser reads, with failures only in the second.
  const std::string parse =
      "/usr/bin/python3 -c \"import sys, xml.etree.ElementTree as E; "
      "f=[len(E.parse(p).getroot().findall('.//failure')) for p in sys.argv[1:]]; "
      "sys.exit(0 if f[0]==0 and f[1]>0 else 1)\" " +
      file("pass.xml") + " " + file("fail.xml");
  EXPECT_EQ(std::system(parse.c_str()), 0);
}

}  // namespace
