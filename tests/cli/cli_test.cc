// End-to-end tests of the `driftlab` command-line tool, run as a child process: exit status,
// stdout, stderr and the files it writes (or does not write).
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "support/cli_runner.h"

namespace {

namespace fs = std::filesystem;
using driftlab::testing::ReadFile;
using driftlab::testing::Result;
using driftlab::testing::RunDriftlab;
using driftlab::testing::Scratch;

std::vector<fs::path> ExampleJobs() {
  std::vector<fs::path> jobs;
  for (const auto& entry : fs::directory_iterator(kExamples)) {
    const std::string extension = entry.path().extension().string();
    if (extension == ".json" || extension == ".yaml" || extension == ".yml") {
      jobs.push_back(entry.path());
    }
  }
  std::sort(jobs.begin(), jobs.end());
  return jobs;
}

int CountLines(const std::string& text) {
  return static_cast<int>(std::count(text.begin(), text.end(), '\n'));
}

TEST(Cli, VersionPrintsTheProjectVersion) {
  Scratch scratch;
  const Result r = RunDriftlab({"--version"}, scratch);
  EXPECT_EQ(r.exit_status, 0);
  EXPECT_EQ(r.out, std::string("driftlab ") + DRIFTLAB_VERSION + "\n");
}

TEST(Cli, UnknownCommandIsAUsageErrorWithStatus2) {
  Scratch scratch;
  const Result r = RunDriftlab({"fly", "job.json"}, scratch);
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_FALSE(r.err.empty());
}

TEST(Cli, EveryExampleValidates) {
  const std::vector<fs::path> jobs = ExampleJobs();
  ASSERT_GE(jobs.size(), 9u);
  Scratch scratch;
  for (const fs::path& job : jobs) {
    SCOPED_TRACE(job.string());
    const Result r = RunDriftlab({"validate", job.string()}, scratch);
    EXPECT_EQ(r.exit_status, 0) << r.err;
    EXPECT_EQ(r.out, "OK\n");
    EXPECT_EQ(r.err, "");
  }
}

TEST(Cli, EveryExampleSimulatesAndWritesFourCsvFiles) {
  Scratch scratch;
  for (const fs::path& job : ExampleJobs()) {
    SCOPED_TRACE(job.string());
    const fs::path out_dir = scratch.dir() / job.stem();
    const Result r = RunDriftlab({"simulate", job.string(), "--out", out_dir.string()}, scratch);
    ASSERT_EQ(r.exit_status, 0) << r.err;
    EXPECT_EQ(r.err, "");
    EXPECT_NE(r.out.find("final"), std::string::npos) << r.out;
    // One row per output epoch in truth, nav and errors (k = 0..N): same row counts; the IMU file
    // has one row per epoch too (k = 0 carries the zero increment).
    int rows = -1;
    for (const char* name : {"truth.csv", "imu.csv", "nav.csv", "errors.csv"}) {
      SCOPED_TRACE(name);
      const std::string text = ReadFile(out_dir / name);
      ASSERT_FALSE(text.empty());
      const int lines = CountLines(text);
      EXPECT_GT(lines, 2);
      if (rows < 0) rows = lines;
      EXPECT_EQ(lines, rows);
    }
    fs::remove_all(out_dir);  // keep the scratch space small: a 10-minute job writes tens of MB
  }
}

// A bad job: exactly one line on stderr naming the path, the value and the allowed range; status 2;
// nothing written (the output directory is not even created).
struct BadJob {
  std::string file;
  std::string message;
};

class BadJobFile : public ::testing::TestWithParam<BadJob> {};

TEST_P(BadJobFile, IsRejectedWithOneMessageAndNothingWritten) {
  Scratch scratch;
  const fs::path out_dir = scratch.dir() / "out";
  const fs::path job = kCliData / GetParam().file;
  const Result r = RunDriftlab({"simulate", job.string(), "--out", out_dir.string()}, scratch);
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_EQ(r.err, "error: " + GetParam().message + "\n");
  EXPECT_EQ(r.out, "");
  EXPECT_FALSE(fs::exists(out_dir));

  const Result v = RunDriftlab({"validate", job.string()}, scratch);
  EXPECT_EQ(v.exit_status, 2);
  EXPECT_EQ(v.err, r.err);
}

INSTANTIATE_TEST_SUITE_P(
    Cli, BadJobFile,
    ::testing::Values(
        BadJob{"bad_unknown_segment.json",
               "motion.segments[2].spin: unknown field; allowed: static, accelerate, "
               "constant_velocity, turn, climb, zigzag, ship_motion, figure_eight"},
        BadJob{"bad_negative_duration.json",
               "motion.segments[1].static.duration_s: -5 is not allowed; allowed: 0 < duration_s "
               "<= 100000 s"},
        BadJob{"bad_rate.json", "rate_hz: 5000 is not allowed; allowed: 1 <= rate_hz <= 2000 Hz"},
        BadJob{"bad_nan.json",
               "motion.segments[1].turn.duration_s: nan is not allowed; allowed: 0 < duration_s "
               "<= 100000 s"},
        BadJob{"bad_nan.yaml",
               "motion.initial.lon_deg: nan is not allowed; allowed: -180 <= lon_deg <= 360 deg"},
        BadJob{"bad_missing_field.json",
               "motion.initial.lat_deg: missing is not allowed; allowed: -89 <= lat_deg <= 89 deg"},
        BadJob{"bad_enum.yaml",
               "navigation.mechanization: \"INS\" is not allowed; allowed: NED, SEED000"},
        BadJob{"bad_type.json", "rate_hz: \"fast\" is not allowed; allowed: a number"}),
    [](const ::testing::TestParamInfo<BadJob>& info) {
      std::string name = info.param.file;
      for (char& c : name) {
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
      }
      return name;
    });

// Jobs that would write NaN (huge type-1 rate) or aliased output (a roll period far below the
// 0.01 s sample interval) are refused at validation with status 2.
TEST(Cli, HugeGnssInsSimRateAndAliasedShipPeriodAreRefusedWithStatus2) {
  Scratch scratch;
  const Result rate =
      RunDriftlab({"validate", (kCliData / "bad_gnss_ins_sim_huge_rate.json").string()}, scratch);
  EXPECT_EQ(rate.exit_status, 2);
  EXPECT_NE(rate.err.find("bad_gnss_ins_sim_huge_rate.csv:5 (yaw): "), std::string::npos)
      << rate.err;
  EXPECT_NE(rate.err.find("|yaw rate| <= 5729.57"), std::string::npos) << rate.err;
  const Result ship =
      RunDriftlab({"validate", (kCliData / "bad_ship_roll_period.json").string()}, scratch);
  EXPECT_EQ(ship.exit_status, 2);
  EXPECT_NE(ship.err.find("motion.segments[0].ship_motion.roll_period_s: 0.001 is not allowed; "
                          "allowed: roll_period_s >= 0.04 s"),
            std::string::npos)
      << ship.err;
}

TEST(Cli, JsonSyntaxErrorIsOneLineWithStatus2) {
  Scratch scratch;
  const fs::path out_dir = scratch.dir() / "out";
  const Result r = RunDriftlab(
      {"simulate", (kCliData / "bad_syntax.json").string(), "--out", out_dir.string()}, scratch);
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_EQ(CountLines(r.err), 1) << r.err;
  EXPECT_TRUE(r.err.starts_with("error: " + (kCliData / "bad_syntax.json").string() +
                                ": invalid JSON at line 3, column "))
      << r.err;
  EXPECT_FALSE(fs::exists(out_dir));
}

TEST(Cli, EngineRejectionIsReportedBeforeTheOutputDirectoryIsCreated) {
  // A static segment entered at 10 m/s: caught by the trajectory planner, not the field checks.
  Scratch scratch;
  const fs::path out_dir = scratch.dir() / "out";
  const Result r = RunDriftlab(
      {"simulate", (kCliData / "bad_static_at_speed.json").string(), "--out", out_dir.string()},
      scratch);
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_EQ(CountLines(r.err), 1) << r.err;
  EXPECT_TRUE(r.err.starts_with("error: motion.segments[0]")) << r.err;
  EXPECT_FALSE(fs::exists(out_dir));
}

TEST(Cli, MissingJobFileIsReported) {
  Scratch scratch;
  const fs::path out_dir = scratch.dir() / "out";
  const Result r = RunDriftlab(
      {"simulate", (scratch.dir() / "nope.json").string(), "--out", out_dir.string()}, scratch);
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_EQ(CountLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("nope.json: no such file"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out_dir));
}

}  // namespace
