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

// The first column (t_s) of a CSV text's data rows.
std::vector<double> FirstColumn(const std::string& text) {
  std::vector<double> values;
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) values.push_back(std::stod(line.substr(0, line.find(','))));
  return values;
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
    // One row per output epoch in truth and imu (k = 0..N; k = 0 carries the zero increment),
    // and in nav and errors from the navigation start on: the truth's rows from the end of a
    // static alignment window (static_alignment_navigation: 300 s) or of seed 000's static
    // period (the ship examples: 90 s), else all of them.
    const std::string stem = job.stem().string();
    const double start_s = stem == "static_alignment_navigation" ? 300.0
                           : stem.rfind("ship_", 0) == 0         ? 90.0
                                                                 : 0.0;
    const std::string truth = ReadFile(out_dir / "truth.csv");
    const std::vector<double> truth_t = FirstColumn(truth);
    ASSERT_GT(truth_t.size(), 2u);
    EXPECT_EQ(CountLines(ReadFile(out_dir / "imu.csv")), CountLines(truth));
    // Output epochs are multiples of 1 / rate_hz (nav.csv prints the navigator's own time, which
    // differs from the truth's in the last bits): half a 1 kHz sample tells them apart.
    const auto navigating = std::count_if(truth_t.begin(), truth_t.end(),
                                          [&](double t) { return t >= start_s - 5e-4; });
    for (const char* name : {"nav.csv", "errors.csv"}) {
      SCOPED_TRACE(name);
      const std::vector<double> t = FirstColumn(ReadFile(out_dir / name));
      ASSERT_FALSE(t.empty());
      EXPECT_NEAR(t.front(), start_s, 5e-4);
      EXPECT_EQ(static_cast<long>(t.size()), static_cast<long>(navigating));
      EXPECT_NEAR(t.back(), truth_t.back(), 5e-4);
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
