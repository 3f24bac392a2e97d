// The README's CI recipe for `driftlab gate`, end to end with the `driftlab` binary: plan the run
// count with --runs-for-change, commit a baseline, rerun with another seed (passes), degrade the
// IMU (fails with exit 1 and a JUnit file that a JUnit parser reads).
// Job: tests/cli/data/gate_arw_drive.json (gyro ARW only, 32 s). Seeds fixed before the first run:
// baseline 1, rerun 2, degraded 3.
//
// Error rates of the two single checks, from the gate's guarantees: the rerun fails with
// probability at most alpha = 5 % (measured 0 of 100 seed pairs in gate_slow_test.cc); the
// degraded IMU (ARW x 1.3, +30 % sigma) is missed with probability at most 10 % at the planned run
// count (measured 50 of 50 caught there).
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <string>

#include "support/cli_runner.h"

namespace driftlab::testing {
namespace {

const fs::path kJob = fs::path(DRIFTLAB_CLI_TEST_DATA) / "gate_arw_drive.json";

TEST(GateRecipe, PlannedBaselinePassesAnotherSeedAndFailsADegradedImu) {
  Scratch scratch;
  const std::string probe = (scratch.dir() / "probe.json").string();
  ASSERT_EQ(RunDriftlab({"run", kJob.string(), "--runs", "10", "--out", probe, "-q"}, scratch)
                .exit_status,
            0);
  const Result plan = RunDriftlab({"gate", probe, "--runs-for-change", "0.3"}, scratch);
  ASSERT_EQ(plan.exit_status, 0) << plan.err;
  const size_t colon = plan.out.find("90 % power: ");
  ASSERT_NE(colon, std::string::npos) << plan.out;
  const std::string runs = std::to_string(std::stol(plan.out.substr(colon + 12)));

  const std::string baseline = (scratch.dir() / "baseline.json").string();
  const std::string current = (scratch.dir() / "current.json").string();
  const std::string degraded = (scratch.dir() / "degraded.json").string();
  ASSERT_EQ(
      RunDriftlab({"run", kJob.string(), "--runs", runs, "--seed", "1", "--out", baseline, "-q"},
                  scratch)
          .exit_status,
      0);
  ASSERT_EQ(
      RunDriftlab({"run", kJob.string(), "--runs", runs, "--seed", "2", "--out", current, "-q"},
                  scratch)
          .exit_status,
      0);
  const Result rerun = RunDriftlab({"gate", current, "--baseline", baseline}, scratch);
  EXPECT_EQ(rerun.exit_status, 0) << rerun.out << rerun.err;
  EXPECT_NE(rerun.out.find("mode: independent"), std::string::npos) << rerun.out;

  // The degraded IMU: ARW 0.5 -> 0.65 deg/sqrt(h) in a copy of the job.
  std::string job_text = ReadFile(kJob);
  const size_t at = job_text.find("\"arw_deg_per_sqrt_h\": 0.5");
  ASSERT_NE(at, std::string::npos);
  job_text.replace(at, 25, "\"arw_deg_per_sqrt_h\": 0.65");
  const fs::path degraded_job = scratch.dir() / "degraded_job.json";
  std::ofstream(degraded_job) << job_text;
  ASSERT_EQ(RunDriftlab({"run", degraded_job.string(), "--runs", runs, "--seed", "3", "--out",
                         degraded, "-q"},
                        scratch)
                .exit_status,
            0);
  const Result refused = RunDriftlab({"gate", degraded, "--baseline", baseline}, scratch);
  EXPECT_EQ(refused.exit_status, 2);
  EXPECT_NE(refused.err.find("job.sensor.gyro.arw_deg_per_sqrt_h: differs"), std::string::npos)
      << refused.err;
  const fs::path junit = scratch.dir() / "gate.xml";
  const Result failed = RunDriftlab({"gate", degraded, "--baseline", baseline,
                                     "--allow-different-job", "--junit", junit.string()},
                                    scratch);
  EXPECT_EQ(failed.exit_status, 1) << failed.out << failed.err;
  EXPECT_NE(failed.out.find("final.horizontal_position_m.std"), std::string::npos);
  const std::string command =
      "/usr/bin/python3 -c \"import sys, xml.etree.ElementTree as E; r = E.parse(sys.argv[1])"
      ".getroot(); assert r.tag == 'testsuite'; f = r.findall('testcase/failure'); assert len(f) "
      "== int(r.get('failures')) > 0; assert any(c.get('name') == "
      "'final.horizontal_position_m.std' and c.find('failure') is not None for c in "
      "r.findall('testcase'))\" " +
      junit.string();
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
}

}  // namespace
}  // namespace driftlab::testing
