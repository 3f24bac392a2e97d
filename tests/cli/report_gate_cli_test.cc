// `driftlab report` and `driftlab gate` run as child processes on the synthetic result files of
// tests/cli/data (written by gate_make_results.py: 100 runs; gate_degraded.json has every error
// 1.5 times the baseline's, gate_other_job.json the baseline's statistics under another job).
#include <gtest/gtest.h>

#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "../support/cli_runner.h"

namespace driftlab::testing {
namespace {

const fs::path kData = DRIFTLAB_CLI_TEST_DATA;
const std::string kBaseline = (kData / "gate_baseline.json").string();
const std::string kDegraded = (kData / "gate_degraded.json").string();
const std::string kOtherJob = (kData / "gate_other_job.json").string();

size_t Count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// Lines of `text` that end in " FAIL" (the gate table's regressions).
std::vector<std::string> FailLines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (line.size() > 5 && line.compare(line.size() - 5, 5, " FAIL") == 0) lines.push_back(line);
  }
  return lines;
}

TEST(ReportCommand, WritesOneSelfContainedHtmlFile) {
  Scratch scratch;
  const fs::path out = scratch.dir() / "report.html";
  const Result r = RunDriftlab({"report", kBaseline, "--out", out.string()}, scratch);
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const std::string html = ReadFile(out);
  EXPECT_EQ(html.find("http://"), std::string::npos);
  EXPECT_EQ(html.find("https://"), std::string::npos);
  EXPECT_EQ(html.find("src="), std::string::npos);
  EXPECT_EQ(html.find("<script"), std::string::npos);
  // 11 error envelopes, the scatter, the horizontal histogram, 10 component histograms.
  EXPECT_EQ(Count(html, "<svg"), 23u);
  EXPECT_NE(html.find("gate_test_static_equator"), std::string::npos);
  // One scatter dot per run of the file.
  EXPECT_EQ(Count(html, "r=\"1.8\""), 100u);
}

TEST(ReportCommand, BadResultFileExitsTwoNamingTheFile) {
  Scratch scratch;
  const std::string not_a_result = (kData / "gate_rules.yaml").string();
  const Result r =
      RunDriftlab({"report", not_a_result, "--out", (scratch.dir() / "r.html").string()}, scratch);
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find(not_a_result + ": invalid result JSON"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(scratch.dir() / "r.html"));
  EXPECT_EQ(RunDriftlab({"report", kBaseline}, scratch).exit_status, 2);  // --out is required
}

TEST(GateCommand, IdenticalResultPasses) {
  Scratch scratch;
  const Result r = RunDriftlab({"gate", kBaseline, "--baseline", kBaseline}, scratch);
  EXPECT_EQ(r.exit_status, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("gate: PASS"), std::string::npos) << r.out;
  EXPECT_TRUE(FailLines(r.out).empty());
}

TEST(GateCommand, DegradedResultFailsWithExitOneAndNamesTheMetric) {
  Scratch scratch;
  const fs::path junit = scratch.dir() / "gate.xml";
  const Result r =
      RunDriftlab({"gate", kDegraded, "--baseline", kBaseline, "--junit", junit.string()}, scratch);
  EXPECT_EQ(r.exit_status, 1) << r.out << r.err;
  // Every default-gated final statistic is 1.5 x its baseline, above the loosest default
  // tolerance (40 %, max_abs): all of them fail, CEP95 among them.
  const std::vector<std::string> failed = FailLines(r.out);
  EXPECT_EQ(failed.size(), 11u * 7 + 3);
  EXPECT_NE(r.out.find("gate: FAIL"), std::string::npos);
  bool cep95 = false;
  for (const std::string& line : failed) {
    cep95 = cep95 || line.rfind("final.horizontal_position_m.cep95 ", 0) == 0;
  }
  EXPECT_TRUE(cep95) << r.out;
  // The JUnit file is XML that Python's parser (as CI tools) reads: one suite, one failure per
  // regression.
  const std::string command =
      "/usr/bin/python3 -c \"import sys, xml.etree.ElementTree as E; r = E.parse(sys.argv[1])"
      ".getroot(); assert r.tag == 'testsuite'; assert len(r.findall('testcase/failure')) == " +
      std::to_string(failed.size()) +
      "; assert int(r.get('tests')) == " + std::to_string(failed.size()) + "\" " + junit.string();
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
  // The improved direction passes: errors, larger is worse.
  EXPECT_EQ(RunDriftlab({"gate", kBaseline, "--baseline", kDegraded}, scratch).exit_status, 0);
}

TEST(GateCommand, DifferentJobIsRefusedUnlessAllowed) {
  Scratch scratch;
  const Result refused = RunDriftlab({"gate", kOtherJob, "--baseline", kBaseline}, scratch);
  EXPECT_EQ(refused.exit_status, 2);
  EXPECT_NE(refused.err.find("different job"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("rate_hz: 100 -> 200"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("--allow-different-job"), std::string::npos) << refused.err;
  const Result allowed =
      RunDriftlab({"gate", kOtherJob, "--baseline", kBaseline, "--allow-different-job"}, scratch);
  EXPECT_EQ(allowed.exit_status, 0) << allowed.out << allowed.err;
  EXPECT_NE(allowed.out.find("note: different jobs compared"), std::string::npos);
}

TEST(GateCommand, RulesFileDecidesWhatIsGatedAndHowTightly) {
  Scratch scratch;
  // 60 % everywhere: 1.5 x passes.
  const Result loose = RunDriftlab(
      {"gate", kDegraded, "--baseline", kBaseline, "--rules", (kData / "gate_rules.yaml").string()},
      scratch);
  EXPECT_EQ(loose.exit_status, 0) << loose.out << loose.err;
  EXPECT_NE(loose.out.find("epoch[t=600].velocity_down_m_per_s.std"), std::string::npos);
  // One metric at 20 % (JSON rules): exactly that one fails.
  const Result strict = RunDriftlab({"gate", kDegraded, "--baseline", kBaseline, "--rules",
                                     (kData / "gate_rules_strict.yaml").string()},
                                    scratch);
  EXPECT_EQ(strict.exit_status, 1) << strict.out << strict.err;
  const std::vector<std::string> failed = FailLines(strict.out);
  ASSERT_EQ(failed.size(), 1u) << strict.out;
  EXPECT_EQ(failed[0].rfind("epoch[t=300].yaw_deg.std ", 0), 0u) << failed[0];
}

TEST(GateCommand, BadRulesAndBadArgumentsExitTwoNamingTheField) {
  Scratch scratch;
  const std::string bad_rules = (kData / "gate_bad_rules.yaml").string();
  const Result r =
      RunDriftlab({"gate", kBaseline, "--baseline", kBaseline, "--rules", bad_rules}, scratch);
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find(bad_rules + ": rules[1].rel_tol: -0.1 is not allowed; allowed: 0 <= "
                                   "rel_tol <= 100"),
            std::string::npos)
      << r.err;
  const Result no_baseline = RunDriftlab({"gate", kBaseline}, scratch);
  EXPECT_EQ(no_baseline.exit_status, 2);
  EXPECT_NE(no_baseline.err.find("--baseline: missing"), std::string::npos) << no_baseline.err;
  const std::string missing = (scratch.dir() / "nope.json").string();
  const Result no_file = RunDriftlab({"gate", missing, "--baseline", kBaseline}, scratch);
  EXPECT_EQ(no_file.exit_status, 2);
  EXPECT_NE(no_file.err.find(missing + ": no such file"), std::string::npos) << no_file.err;
}

TEST(GateCommand, ListMetricsPrintsEveryNameWithItsValue) {
  Scratch scratch;
  const Result r = RunDriftlab({"gate", kBaseline, "--list-metrics"}, scratch);
  ASSERT_EQ(r.exit_status, 0) << r.err;
  // final: 11 x 12 + 3; 11 epochs x 11 x 7; 2 checkpoints x (11 x 5 + 3).
  EXPECT_EQ(Count(r.out, "\n"), 11u * 12 + 3 + 11u * 11 * 7 + 2u * (11 * 5 + 3));
  EXPECT_NE(r.out.find("\nfinal.horizontal_position_m.cep95 "), std::string::npos);
  EXPECT_NE(r.out.find("\nepoch[t=600].velocity_down_m_per_s.std "), std::string::npos);
  EXPECT_NE(r.out.find("\ncheckpoint[t=300].yaw_deg.p95 "), std::string::npos);
}

}  // namespace
}  // namespace driftlab::testing
