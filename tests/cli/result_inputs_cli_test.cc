// The gate, merge and report check what they read (result_check.h, gate.h), through the binary:
// a result of one run is refused by the gate naming the file and the minimum, a result gated
// against itself passes --strict, a result whose summary statistics were edited is refused by
// the gate and the report, and a shard whose exact sums disagree with its statistics is refused
// by merge. The results come from `driftlab run` of a 32 s car job (tests/cli/data).
#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "support/cli_runner.h"

namespace driftlab::testing {
namespace {

const fs::path kData = DRIFTLAB_CLI_TEST_DATA;
const std::string kJob = (kData / "gate_arw_drive.json").string();

// `driftlab run` of the test job with extra arguments; the result path.
std::string RunJob(const Scratch& scratch, const std::string& name,
                   const std::vector<std::string>& extra) {
  const std::string out = (scratch.dir() / name).string();
  std::vector<std::string> args = {"run", kJob, "--out", out, "-q"};
  args.insert(args.end(), extra.begin(), extra.end());
  const Result r = RunDriftlab(args, scratch);
  EXPECT_EQ(r.exit_status, 0) << r.err;
  return out;
}

// Replaces the number after the first `key` that follows `anchor` in the file's text.
void SetNumber(const std::string& path, const std::string& anchor, const std::string& key,
               const std::string& value) {
  std::string text = ReadFile(path);
  const size_t at = text.find(key, text.find(anchor));
  ASSERT_NE(at, std::string::npos) << key;
  const size_t begin = at + key.size();
  const size_t end = text.find_first_of(",\n}", begin);
  text.replace(begin, end - begin, value);
  std::ofstream(path, std::ios::binary) << text;
}

TEST(ResultInputs, GateRefusesAOneRunResultNamingTheFileAndTheMinimum) {
  Scratch scratch;
  const std::string six = RunJob(scratch, "six.json", {"--runs", "6"});
  const std::string one = RunJob(scratch, "one.json", {"--runs", "1"});
  const Result r = RunDriftlab({"gate", one, "--baseline", six}, scratch);
  EXPECT_EQ(r.exit_status, 2) << r.out;
  EXPECT_NE(r.err.find(one + ": run_count: 1 is not allowed; allowed: >= 2 runs"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.out.find("regress"), std::string::npos) << r.out;
}

TEST(ResultInputs, AResultGatedAgainstItselfPassesStrict) {
  Scratch scratch;
  // 6 runs: too few for the paired tests to bound a ratio of identical values away from 0 and
  // infinity; identical per-run values are ratio 1 exactly.
  const std::string six = RunJob(scratch, "six.json", {"--runs", "6"});
  const Result r = RunDriftlab({"gate", six, "--baseline", six, "--strict"}, scratch);
  EXPECT_EQ(r.exit_status, 0) << r.out << r.err;
  EXPECT_EQ(r.out.find("inconclusive  "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("identical per-run values"), std::string::npos) << r.out;
}

TEST(ResultInputs, EditedSummaryStatisticsAreRefusedByGateAndReport) {
  Scratch scratch;
  const std::string baseline = RunJob(scratch, "baseline.json", {"--runs", "20"});
  const std::string edited = RunJob(scratch, "edited.json", {"--runs", "20"});
  // Epoch 1 (t = 4 s): its first component's sigma set to 1e308.
  SetNumber(edited, "\"t_s\": 4", "\"std\": ", "1e308");
  const Result gate = RunDriftlab({"gate", edited, "--baseline", baseline}, scratch);
  EXPECT_EQ(gate.exit_status, 2) << gate.out;
  EXPECT_NE(gate.err.find(edited + ": epochs[1].components[0].std: 1e+308 is not allowed"),
            std::string::npos)
      << gate.err;
  EXPECT_NE(gate.err.find("exact sums merge_state.epochs[1]"), std::string::npos) << gate.err;
  const Result report =
      RunDriftlab({"report", edited, "--out", (scratch.dir() / "r.html").string()}, scratch);
  EXPECT_EQ(report.exit_status, 2);
  EXPECT_FALSE(fs::exists(scratch.dir() / "r.html"));
}

TEST(ResultInputs, MergeRefusesAShardWhoseSumsDisagreeWithItsStatistics) {
  Scratch scratch;
  const std::string a = RunJob(scratch, "a.json", {"--runs", "8", "--shard", "0/2"});
  const std::string b = RunJob(scratch, "b.json", {"--runs", "8", "--shard", "1/2"});
  const std::string merged = (scratch.dir() / "m.json").string();
  ASSERT_EQ(RunDriftlab({"merge", a, b, "--out", merged}, scratch).exit_status, 0);
  // One limb of the last epoch's first sum changed: the statistics no longer follow.
  std::string text = ReadFile(a);
  const size_t last_epoch = text.rfind("\"sum\": {");
  ASSERT_NE(last_epoch, std::string::npos);
  const size_t limb = text.find("\"limbs\": [", last_epoch) + 10;
  const size_t digit = text.find_first_of("0123456789", limb);
  text.insert(digit, "7");
  std::ofstream(a, std::ios::binary) << text;
  fs::remove(merged);
  const Result r = RunDriftlab({"merge", a, b, "--out", merged}, scratch);
  EXPECT_EQ(r.exit_status, 2) << r.out;
  EXPECT_NE(r.err.find(a + ": "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("merge_state"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(merged));
}

}  // namespace
}  // namespace driftlab::testing
