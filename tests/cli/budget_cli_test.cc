// `driftlab budget` end to end, as a child process: the budget file and report, the Monte-Carlo
// check's verdict, and bad command lines and jobs (exit status 2, the field named).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "support/cli_runner.h"

namespace {

namespace fs = std::filesystem;
using driftlab::testing::ReadFile;
using driftlab::testing::Result;
using driftlab::testing::RunDriftlab;
using driftlab::testing::Scratch;

// A 40 s free-inertial drive at 100 Hz: white noise, a turn-on bias and initial errors.
std::string Job(const std::string& gyro = R"({"arw_deg_per_sqrt_h": 0.3,
                                              "turn_on_bias_deg_per_h": 5})") {
  return R"({"name": "budget_cli", "rate_hz": 100,
  "motion": {"initial": {"lat_deg": 45, "lon_deg": 7, "height_m": 300, "yaw_deg": 30},
             "segments": [{"static": {"duration_s": 5}},
                          {"accelerate": {"acceleration_m_per_s2": 2, "target_speed_m_per_s": 10}},
                          {"constant_velocity": {"duration_s": 30}}]},
  "navigation": {"mechanization": "NED", "ned": {"vertical_channel": "FREE"}},
  "sensor": {"gyro": )" +
         gyro + R"(, "accel": {"vrw_m_per_s_per_sqrt_h": 0.1}},
  "monte_carlo": {"runs": 10, "seed": 5, "epoch_interval_s": 1.0,
                  "initial_errors": {"position_ned_m": [1, 1, 2]}}})";
}

fs::path WriteJob(const Scratch& scratch, const std::string& text) {
  const fs::path path = scratch.dir() / "job.json";
  std::ofstream(path) << text;
  return path;
}

TEST(BudgetCli, WritesTheBudgetAndItsReport) {
  Scratch scratch;
  const fs::path out = scratch.dir() / "budget.json";
  const fs::path report = scratch.dir() / "budget.html";
  const Result r = RunDriftlab({"budget", WriteJob(scratch, Job()).string(), "--out", out.string(),
                                "--report", report.string()},
                               scratch);
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const std::string json = ReadFile(out);
  for (const char* name : {"\"gyro.arw\"", "\"gyro.turn_on_bias\"", "\"accel.vrw\"",
                           "\"initial.position\"", "\"max_relative_sum_error\"", "\"total\""}) {
    EXPECT_NE(json.find(name), std::string::npos) << name;
  }
  EXPECT_NE(r.out.find("error budget of budget_cli"), std::string::npos) << r.out;
  const std::string html = ReadFile(report);
  EXPECT_NE(html.find("driftlab error budget: budget_cli"), std::string::npos);
  EXPECT_NE(html.find("gyro.turn_on_bias"), std::string::npos);
}

TEST(BudgetCli, MonteCarloCheckGivesAVerdict) {
  Scratch scratch;
  const fs::path out = scratch.dir() / "budget.json";
  const Result r = RunDriftlab({"budget", WriteJob(scratch, Job()).string(), "--out", out.string(),
                                "--mc-check", "50", "--top", "2", "-q"},
                               scratch);
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE((r.out + r.err).find("check: "), std::string::npos) << r.out << r.err;
  const std::string json = ReadFile(out);
  EXPECT_NE(json.find("\"checks\""), std::string::npos);
  EXPECT_NE(json.find("\"ratio_low\""), std::string::npos);
}

TEST(BudgetCli, BadJobFieldIsNamedWithExitStatus2) {
  Scratch scratch;
  const Result r =
      RunDriftlab({"budget", WriteJob(scratch, Job(R"({"arw_deg_per_sqrt_h": -1})")).string(),
                   "--out", (scratch.dir() / "b.json").string()},
                  scratch);
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("sensor.gyro.arw_deg_per_sqrt_h"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("-1"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(scratch.dir() / "b.json"));
}

TEST(BudgetCli, BadOptionsAndMissingFilesExitWith2) {
  Scratch scratch;
  const std::string job = WriteJob(scratch, Job()).string();
  const std::string out = (scratch.dir() / "b.json").string();
  Result r = RunDriftlab({"budget", job, "--out", out, "--mc-check", "1"}, scratch);
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("--mc-check"), std::string::npos) << r.err;
  r = RunDriftlab({"budget", job, "--out", out, "--top", "0"}, scratch);
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("--top"), std::string::npos) << r.err;
  r = RunDriftlab({"budget", (scratch.dir() / "missing.json").string(), "--out", out}, scratch);
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("missing.json"), std::string::npos) << r.err;
  r = RunDriftlab({"budget", job}, scratch);  // --out is required
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
