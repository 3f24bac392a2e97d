// `driftlab simulate --run N` is run N of `driftlab run`: the final row of its errors.csv equals
// the per-run values the result file keeps at the final checkpoint for run N, bit for bit for
// the position and velocity components (both files print each double as the shortest text that
// reads back exactly; the result's attitude is in degrees, errors.csv's in radians: compared
// after the conversion to 1e-12 relative), for a job with initial errors, GNSS aiding and the EKF
// and for a free-inertial job with initial errors and static alignment.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "cli_test_util.h"

namespace driftlab::cli_test {
namespace {

// The last errors.csv row against run `run` of the result's final checkpoint (python3: exact
// float parsing of both files).
int CompareFinalRow(const fs::path& result, const fs::path& errors, int run) {
  const std::string script =
      "import json,math,sys\n"
      "r=json.load(open(sys.argv[1]))\n"
      "run=int(sys.argv[3])\n"
      "cp=r[\"checkpoints\"][-1]\n"
      "v=[x for x in cp[\"runs\"] if x.get(\"run_index\",0)==run][0][\"values\"]\n"
      "rows=open(sys.argv[2]).read().split()\n"
      "head=rows[0].split(\",\"); last=[float(x) for x in rows[-1].split(\",\")]\n"
      "row=dict(zip(head,last))\n"
      "assert abs(row[\"t_s\"]-cp[\"t_s\"])<1e-9, (row[\"t_s\"],cp[\"t_s\"])\n"
      "csv=[row[h] for h in head[1:7]]\n"
      "for a,b in zip(csv,v[:6]):\n"
      "  assert a==b,(a,b)\n"
      "for a,b in zip([row[h] for h in head[7:10]],v[6:9]):\n"
      "  assert abs(math.degrees(a)-b)<=1e-12*max(abs(b),1e-300),(a,b)\n";
  const std::string command = "/usr/bin/python3 -c '" + script + "' " + result.string() + " " +
                              errors.string() + " " + std::to_string(run);
  return std::system(command.c_str());
}

void ExpectSimulateRunIsRunOfTheMonteCarlo(const std::string& job_file) {
  Scratch scratch;
  const fs::path job = kCliData / job_file;
  const fs::path result = scratch.dir() / "result.json";
  const Result r = RunDriftlab({"run", job.string(), "--out", result.string(), "-q"}, scratch);
  ASSERT_EQ(r.exit_status, 0) << r.err;
  for (const int run : {0, 4}) {
    SCOPED_TRACE(run);
    const fs::path out = scratch.dir() / ("run" + std::to_string(run));
    const Result s = RunDriftlab(
        {"simulate", job.string(), "--run", std::to_string(run), "--out", out.string()}, scratch);
    ASSERT_EQ(s.exit_status, 0) << s.err;
    EXPECT_NE(s.out.find("run " + std::to_string(run) + " of 6"), std::string::npos) << s.out;
    EXPECT_EQ(CompareFinalRow(result, out / "errors.csv", run), 0);
  }
}

TEST(SimulateRun, EkfWithInitialErrorsAndGnssIsRunNOfTheMonteCarlo) {
  ExpectSimulateRunIsRunOfTheMonteCarlo("mc_small_gnss.json");
  // The EKF's estimates beside the navigation.
  Scratch scratch;
  const fs::path out = scratch.dir() / "out";
  const Result s = RunDriftlab(
      {"simulate", (kCliData / "mc_small_gnss.json").string(), "--out", out.string()}, scratch);
  ASSERT_EQ(s.exit_status, 0) << s.err;
  EXPECT_NE(ReadFile(out / "filter.csv").find("accel_bias_x_m_per_s2"), std::string::npos);
}

TEST(SimulateRun, StaticAlignmentWithInitialErrorsIsRunNOfTheMonteCarlo) {
  ExpectSimulateRunIsRunOfTheMonteCarlo("mc_small_aligned.json");
}

// A run index outside the job's runs is refused with the field named, nothing written.
TEST(SimulateRun, RunIndexBeyondTheJobsRunsIsRefused) {
  Scratch scratch;
  const fs::path out = scratch.dir() / "out";
  const Result s = RunDriftlab(
      {"simulate", (kCliData / "mc_small_gnss.json").string(), "--run", "6", "--out", out.string()},
      scratch);
  EXPECT_EQ(s.exit_status, 2);
  EXPECT_NE(s.err.find("--run: 6"), std::string::npos) << s.err;
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace driftlab::cli_test
