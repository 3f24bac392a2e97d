// `driftlab report` and `driftlab gate` run as child processes on the synthetic result files of
// tests/cli/data (written by gate_make_results.py: 100 runs; gate_degraded.json has every error
// 1.5 times the baseline's, gate_other_job.json the baseline's statistics under another job).
#include <gtest/gtest.h>

#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "support/cli_runner.h"
#include "support/report_html.h"

namespace driftlab::testing {
namespace {

const std::string kBaseline = (kCliData / "gate_baseline.json").string();
const std::string kDegraded = (kCliData / "gate_degraded.json").string();
const std::string kOtherJob = (kCliData / "gate_other_job.json").string();

size_t Count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// Lines of the gate table whose decision is "regression".
std::vector<std::string> FailLines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (line.find("  regression  ") != std::string::npos) lines.push_back(line);
  }
  return lines;
}

TEST(ReportCommand, WritesOneSelfContainedHtmlFileWithInteractivePlots) {
  Scratch scratch;
  const fs::path out = scratch.dir() / "report.html";
  const Result r = RunDriftlab({"report", kBaseline, "--out", out.string()}, scratch);
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const std::string html = ReadFile(out);
  // Nothing loaded from outside: the only scripts are the inline plotting library.
  const std::string markup = ::driftlab::testing::WithoutScriptText(html);
  EXPECT_EQ(markup.find("http://"), std::string::npos);
  EXPECT_EQ(markup.find("https://"), std::string::npos);
  EXPECT_EQ(markup.find("src="), std::string::npos);
  EXPECT_EQ(Count(html, "<script"), Count(html, "<script>"));
  // 11 error envelopes, the scatter, the horizontal histogram, 10 component histograms.
  EXPECT_EQ(Count(html, "class=\"dl-plot\""),
            23u + (html.find("id=\"plot-trajectory\"") != std::string::npos));
  EXPECT_NE(html.find("gate_test_static_equator"), std::string::npos);
  // One scatter point per run of the file, each with the command that regenerates it.
  EXPECT_EQ(Count(html, "driftlab simulate job.json --run "), 100u);
}

TEST(ReportCommand, BadResultFileExitsTwoNamingTheFile) {
  Scratch scratch;
  const std::string not_a_result = (kCliData / "gate_rules.yaml").string();
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
  // Same seed and runs: paired. Every run's error is 1.5 x the baseline's, so the paired tests
  // of sigma and RMS see the ratio 1.5 without noise against the 10 % limit, and so does the
  // paired bootstrap of the percentiles (every resampled ratio is 1.5): all 11 x 5 default
  // metrics regress, p95 of the horizontal error (CEP95) among them.
  EXPECT_NE(r.out.find("mode: paired"), std::string::npos) << r.out;
  const std::vector<std::string> failed = FailLines(r.out);
  EXPECT_EQ(failed.size(), 11u * 5) << r.out;
  EXPECT_NE(r.out.find("gate: FAIL"), std::string::npos);
  bool p95 = false;
  for (const std::string& line : failed) {
    p95 = p95 || line.rfind("final.horizontal_position_m.p95 ", 0) == 0;
  }
  EXPECT_TRUE(p95) << r.out;
  EXPECT_NE(r.out.find("unit"), std::string::npos);
  EXPECT_NE(r.out.find("1.500 [1.500, 1.500]"), std::string::npos) << r.out;
  // The JUnit file is XML that Python's parser (as CI tools) reads: one suite naming both files,
  // one failure per regression, each case with its test and time.
  const std::string command =
      "/usr/bin/python3 -c \"import sys, xml.etree.ElementTree as E; r = E.parse(sys.argv[1])"
      ".getroot(); assert r.tag == 'testsuite'; assert len(r.findall('testcase/failure')) == " +
      std::to_string(failed.size()) +
      "; assert int(r.get('tests')) == " + std::to_string(failed.size()) +
      "; p = {q.get('name'): q.get('value') for q in r.findall('properties/property')}"
      "; assert p['baseline'].endswith('gate_baseline.json'), p"
      "; assert p['current'].endswith('gate_degraded.json'), p"
      "; assert all('test: ' in c.find('failure').text for c in r.findall('testcase'))"
      "; assert all(float(c.get('time')) >= 0 for c in r.findall('testcase'))\" " +
      junit.string();
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
  // The improved direction passes: errors, larger is worse.
  const Result better = RunDriftlab({"gate", kBaseline, "--baseline", kDegraded}, scratch);
  EXPECT_EQ(better.exit_status, 0) << better.out;
  EXPECT_EQ(Count(better.out, "  improved  "), 11u * 5) << better.out;
}

TEST(GateCommand, DifferentJobIsRefusedUnlessAllowed) {
  Scratch scratch;
  const Result refused = RunDriftlab({"gate", kOtherJob, "--baseline", kBaseline}, scratch);
  EXPECT_EQ(refused.exit_status, 2);
  EXPECT_NE(refused.err.find("job.rate_hz: differs"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("rate_hz: 100 -> 200"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("--allow-different-job"), std::string::npos) << refused.err;
  const Result allowed =
      RunDriftlab({"gate", kOtherJob, "--baseline", kBaseline, "--allow-different-job"}, scratch);
  EXPECT_EQ(allowed.exit_status, 0) << allowed.out << allowed.err;
  EXPECT_NE(allowed.out.find("note: different jobs compared"), std::string::npos);
}

TEST(GateCommand, StrictFailsOnInconclusiveAndAlphaIsChecked) {
  Scratch scratch;
  // The baseline against itself: every paired test sees ratio 1 exactly; nothing inconclusive,
  // so --strict passes too.
  const Result same =
      RunDriftlab({"gate", kBaseline, "--baseline", kBaseline, "--strict"}, scratch);
  EXPECT_EQ(same.exit_status, 0) << same.out << same.err;
  const Result bad_alpha =
      RunDriftlab({"gate", kBaseline, "--baseline", kBaseline, "--alpha", "1.5"}, scratch);
  EXPECT_EQ(bad_alpha.exit_status, 2);
  EXPECT_NE(bad_alpha.err.find("--alpha: 1.5 is not allowed; allowed: 0 < alpha < 1"),
            std::string::npos)
      << bad_alpha.err;
}

TEST(GateCommand, RunsForChangePlansTheRunCount) {
  Scratch scratch;
  const Result r = RunDriftlab({"gate", kBaseline, "--runs-for-change", "0.3"}, scratch);
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("runs per file (baseline and current) for a sigma grown by 30 %"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("over 55 gated metrics"), std::string::npos) << r.out;
  const Result inside = RunDriftlab({"gate", kBaseline, "--runs-for-change", "0.05"}, scratch);
  EXPECT_EQ(inside.exit_status, 0);
  EXPECT_NE(inside.out.find("within the 10 % tolerance"), std::string::npos) << inside.out;
  const Result bad = RunDriftlab({"gate", kBaseline, "--runs-for-change", "-1"}, scratch);
  EXPECT_EQ(bad.exit_status, 2);
  EXPECT_NE(bad.err.find("--runs-for-change: -1 is not allowed"), std::string::npos) << bad.err;
}

TEST(GateCommand, RulesFileDecidesWhatIsGatedAndHowTightly) {
  Scratch scratch;
  // 60 % everywhere: 1.5 x passes (paired, exact ratios).
  const Result loose = RunDriftlab({"gate", kDegraded, "--baseline", kBaseline, "--rules",
                                    (kCliData / "gate_rules.yaml").string()},
                                   scratch);
  EXPECT_EQ(loose.exit_status, 0) << loose.out << loose.err;
  EXPECT_NE(loose.out.find("epoch[t=600].velocity_down_m_per_s.std"), std::string::npos);
  // One metric at 20 % (JSON rules): exactly that one fails.
  const Result strict = RunDriftlab({"gate", kDegraded, "--baseline", kBaseline, "--rules",
                                     (kCliData / "gate_rules_strict.yaml").string()},
                                    scratch);
  EXPECT_EQ(strict.exit_status, 1) << strict.out << strict.err;
  const std::vector<std::string> failed = FailLines(strict.out);
  ASSERT_EQ(failed.size(), 1u) << strict.out;
  EXPECT_EQ(failed[0].rfind("epoch[t=300].yaw_deg.std ", 0), 0u) << failed[0];
}

TEST(GateCommand, BadRulesAndBadArgumentsExitTwoNamingTheField) {
  Scratch scratch;
  const std::string bad_rules = (kCliData / "gate_bad_rules.yaml").string();
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
  // final: 11 x 7; 11 epochs x 11 x 3; 2 checkpoints x 11 x 4.
  EXPECT_EQ(Count(r.out, "\n"), 11u * 7 + 11u * 11 * 3 + 2u * 11 * 4);
  EXPECT_NE(r.out.find("\nfinal.horizontal_position_m.p95 "), std::string::npos);
  EXPECT_NE(r.out.find("\nepoch[t=600].velocity_down_m_per_s.std "), std::string::npos);
  EXPECT_NE(r.out.find("\ncheckpoint[t=300].yaw_deg.p95 "), std::string::npos);
}

}  // namespace
}  // namespace driftlab::testing
