// In-process tests of the CI gate (gate.h) on JobResult messages built with known statistics
// (result_test_util.h): metric names, comparisons, rules, JUnit output.
#include <google/protobuf/util/message_differencer.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "driftlab/app/gate.h"
#include "driftlab/app/result_file.h"
#include "driftlab/spec_error.h"
#include "result_test_util.h"

namespace driftlab::app::result_test {
namespace {

double MetricValue(const std::vector<Metric>& metrics, const std::string& name) {
  for (const Metric& m : metrics) {
    if (m.name == name) return m.value;
  }
  ADD_FAILURE() << "no metric " << name;
  return std::numeric_limits<double>::quiet_NaN();
}

// ---------------------------------------------------------------------------------------------
// Gate: metric names

TEST(Gate, MetricNamesFollowTheGrammarAndReadTheRightField) {
  const v1::JobResult result = MakeResult(1.0);
  const std::vector<Metric> metrics = ListMetrics(result);
  // One metric per quantity: final 11 x (3 moments + 4 percentiles); each of the 11 epochs 11 x 3;
  // each of the 2 checkpoints 11 x 4. No CEP (= p50, p95 of horizontal_position_m), 2DRMS (=
  // 2 x its rms), interval bounds or maxima.
  EXPECT_EQ(metrics.size(), 11u * 7 + 11u * 11 * 3 + 2u * 11 * 4);
  for (const Metric& m : metrics) {
    for (const char* gone : {"cep", "drms", "ci95", "max_abs"}) {
      EXPECT_EQ(m.name.find(gone), std::string::npos) << m.name;
    }
  }
  const v1::Checkpoint& last = result.checkpoints(1);
  EXPECT_EQ(MetricValue(metrics, "final.horizontal_position_m.p95"), last.components(9).p95());
  EXPECT_EQ(MetricValue(metrics, "final.position_north_m.p95"), last.components(0).p95());
  EXPECT_EQ(MetricValue(metrics, "final.yaw_deg.rms"), result.epochs(10).components(8).rms());
  // abs_mean is |mean|: the synthetic north bias is negative.
  EXPECT_EQ(MetricValue(metrics, "final.position_north_m.abs_mean"),
            -result.epochs(10).components(0).mean());
  EXPECT_EQ(MetricValue(metrics, "epoch[t=600].velocity_down_m_per_s.std"),
            result.epochs(10).components(5).std());
  EXPECT_EQ(MetricValue(metrics, "checkpoint[t=300].position_3d_m.p99"),
            result.checkpoints(0).components(10).p99());
  for (const Metric& m : metrics) {
    if (m.name == "final.velocity_east_m_per_s.std") {
      EXPECT_EQ(m.unit, "m/s");
    }
    if (m.name == "final.yaw_deg.p50") {
      EXPECT_EQ(m.unit, "deg");
    }
  }
  // A fractional time prints in the shortest form that reads back.
  v1::JobResult half = MakeResult(1.0);
  half.mutable_epochs(1)->set_t_s(0.5);
  EXPECT_EQ(MetricValue(ListMetrics(half), "epoch[t=0.5].pitch_deg.std"),
            half.epochs(1).components(7).std());
  // NEES: final.nees from the final epoch of the filter consistency.
  v1::JobResult filtered = MakeResult(1.0);
  filtered.mutable_filter_consistency()->set_state_dimension(9);
  for (int e = 0; e < filtered.epochs_size(); ++e) {
    v1::NeesEpoch* nees = filtered.mutable_filter_consistency()->add_epochs();
    nees->set_t_s(filtered.epochs(e).t_s());
    nees->set_runs(50);
    nees->set_average_nees(9.0 + e);
  }
  EXPECT_EQ(MetricValue(ListMetrics(filtered), "final.nees"), 19.0);
}

TEST(Gate, GlobMatchesStarAndQuestionMarkAndTakesBracketsLiterally) {
  EXPECT_TRUE(MetricMatches("final.*", "final.yaw_deg.rms"));
  EXPECT_TRUE(MetricMatches("final.*.p9?", "final.yaw_deg.p95"));
  EXPECT_FALSE(MetricMatches("final.*.p9?", "final.yaw_deg.p50"));
  EXPECT_TRUE(MetricMatches("*.cep95", "checkpoint[t=300].horizontal_position_m.cep95"));
  EXPECT_TRUE(MetricMatches("epoch[t=600].*", "epoch[t=600].yaw_deg.std"));
  EXPECT_FALSE(MetricMatches("epoch[t=6].*", "epoch[t=600].yaw_deg.std"));
  EXPECT_FALSE(MetricMatches("final.yaw_deg.rms", "final.yaw_deg.rms_ci95_low"));
  EXPECT_TRUE(MetricMatches("*", ""));
  EXPECT_FALSE(MetricMatches("?", ""));
}

// ---------------------------------------------------------------------------------------------
// Gate: comparisons. MakeResult(s) with the same seed and runs is paired (run r of both files
// drew the same random numbers; here the current per-run values are exactly s times the
// baseline's, so the paired tests see the ratio without noise); a different seed makes the samples
// independent, decided from the files' moments and run counts.

// GateOptions with allow_different_job set as given.
GateOptions Allow(bool allow_different_job) {
  GateOptions options;
  options.allow_different_job = allow_different_job;
  return options;
}

v1::JobResult WithSeed(v1::JobResult result, uint64_t seed) {
  result.set_seed(seed);
  return result;
}

TEST(Gate, IdenticalResultPassesInPairedMode) {
  const v1::JobResult result = MakeResult(1.0);
  const GateReport report = RunGate(result, result, DefaultGateRules(), Allow(false));
  EXPECT_TRUE(report.paired);
  EXPECT_EQ(report.mode.rfind("paired", 0), 0u) << report.mode;
  EXPECT_TRUE(report.passed());
  EXPECT_EQ(report.regressions, 0);
  // Default rules: final.* less abs_mean and p99: 11 x (2 moments + 3 percentiles).
  EXPECT_EQ(report.rows.size(), 11u * 5);
  for (const GateRow& row : report.rows) {
    EXPECT_EQ(row.metric.rfind("final.", 0), 0u);
    // Paired moments of identical runs: the ratio is 1 exactly, interval [1, 1] to bisection.
    if (row.metric.find(".std") != std::string::npos) {
      EXPECT_EQ(row.decision, GateDecision::kPass) << row.metric;
      EXPECT_NEAR(row.ratio_high, 1.0, 1e-9) << row.metric;
    }
  }
}

TEST(Gate, ErrorsFiftyPercentLargerAreRegressionsForIndependentSamplesOfEnoughRuns) {
  // 1000 runs each, independent seeds: sigma ratio 1.5 against the limit 1.1 is F = (1.5 / 1.1)^2
  // = 1.86 with (999, 999) degrees of freedom, p ~ 1e-21, far below alpha / 55 after Holm; the
  // percentiles' order-statistic bounds at n = 1000 are within a few % of the quantile.
  const v1::JobResult baseline = MakeResult(1.0, 1000);
  const v1::JobResult degraded = WithSeed(MakeResult(1.5, 1000), 7);
  const GateReport report = RunGate(baseline, degraded, DefaultGateRules(), Allow(false));
  EXPECT_FALSE(report.paired);
  EXPECT_EQ(report.mode.rfind("independent", 0), 0u) << report.mode;
  EXPECT_EQ(report.regressions, static_cast<int>(report.rows.size()));
  const std::string table = FormatGateTable(report);
  EXPECT_NE(table.find("final.horizontal_position_m.p95"), std::string::npos);
  EXPECT_NE(table.find("regression"), std::string::npos);
  EXPECT_NE(table.find("gate: FAIL"), std::string::npos);
  EXPECT_NE(table.find("F(999, 999) variance ratio"), std::string::npos) << table;
  // The improved direction never fails: errors, larger is worse; every interval lies below 1.
  const GateReport better = RunGate(degraded, baseline, DefaultGateRules(), Allow(false));
  EXPECT_TRUE(better.passed());
  for (const GateRow& row : better.rows) {
    EXPECT_EQ(row.decision, GateDecision::kImproved) << row.metric;
  }
}

TEST(Gate, FiftyRunsCannotTellAFiftyPercentChangeFromNoiseAndSaySo) {
  // 50 runs each, independent: the 95 % interval of a sigma ratio is about x/÷ 1.76 (F(49, 49)
  // 2.5 % and 97.5 % points 0.57 and 1.76), so 1.5 against a limit of 1.1 is not shown at
  // alpha / 55: inconclusive, which fails only with --strict.
  const v1::JobResult baseline = MakeResult(1.0, 50);
  const v1::JobResult degraded = WithSeed(MakeResult(1.5, 50), 7);
  GateOptions options;
  GateReport report = RunGate(baseline, degraded, DefaultGateRules(), options);
  EXPECT_EQ(report.regressions, 0);
  EXPECT_GT(report.inconclusive, 0);
  EXPECT_TRUE(report.passed());
  options.strict = true;
  report = RunGate(baseline, degraded, DefaultGateRules(), options);
  EXPECT_FALSE(report.passed());
  EXPECT_EQ(report.failures(), report.inconclusive);
  // The planning line states the smallest change these run counts detect: > 50 %.
  EXPECT_GT(report.detectable_sigma_ratio, 1.5);
  EXPECT_NE(FormatGateTable(report).find("planning: with independent samples of 50 and 50 runs"),
            std::string::npos);
}

TEST(Gate, LimitIsBaselinePlusLargerOfAbsoluteAndRelativeTolerance) {
  const v1::JobResult baseline = MakeResult(1.0);
  // final.yaw_deg.rms baseline = 1.005 * 9 = 9.045 deg.
  const std::string metric = "final.yaw_deg.rms";
  const double b = 1.005 * 9;
  // Paired runs scaled by 1.05 pass a 10 % rule, by 1.15 fail it: the paired t on y^2 - rho^2 x^2
  // has the sign of s^2 - rho^2 for every run, |t| = mean(x^2) / (sd(x^2) / sqrt(50)) ~ 10.
  const std::vector<GateRule> rel = {{metric, 0, 0.10, false}};
  GateReport report = RunGate(baseline, MakeResult(1.05), rel, Allow(false));
  ASSERT_EQ(report.rows.size(), 1u);
  EXPECT_DOUBLE_EQ(report.rows[0].limit, 1.1 * b);  // 1-ulp products: tolerance 4 ulp
  EXPECT_NEAR(report.rows[0].ratio, 1.05, 1e-12);
  EXPECT_TRUE(report.passed());
  EXPECT_EQ(report.rows[0].decision, GateDecision::kPass);
  EXPECT_FALSE(RunGate(baseline, MakeResult(1.15), rel, Allow(false)).passed());
  // abs_tol 2 deg > 0.10 * 9.045: limit b + 2 = 1.221 b, so 1.15 b passes, 1.25 b fails.
  const std::vector<GateRule> both = {{metric, 2.0, 0.10, false}};
  report = RunGate(baseline, MakeResult(1.15), both, Allow(false));
  EXPECT_DOUBLE_EQ(report.rows[0].limit, b + 2.0);
  EXPECT_TRUE(report.passed());
  EXPECT_FALSE(RunGate(baseline, MakeResult(1.25), both, Allow(false)).passed());
}

TEST(Gate, LastMatchingRuleDecidesAndSkipRemovesMetrics) {
  const v1::JobResult baseline = MakeResult(1.0);
  const v1::JobResult degraded = MakeResult(1.5);
  const std::vector<GateRule> rules = ParseGateRules(
      "rules:\n"
      "  - {metric: 'final.*', rel_tol: 0.1}\n"
      "  - {metric: 'final.yaw_deg.*', rel_tol: 0.6}\n"
      "  - {metric: 'final.*.p*', skip: true}\n"
      "  - {metric: 'final.*.abs_mean', skip: true}\n");
  const GateReport report = RunGate(baseline, degraded, rules, Allow(false));
  for (const GateRow& row : report.rows) {
    const std::string statistic = row.metric.substr(row.metric.rfind('.') + 1);
    EXPECT_TRUE(statistic == "std" || statistic == "rms") << row.metric;
    // Paired, exact ratios: yaw within 60 % (1.5 <= 1.6) passes, everything else at 10 % fails.
    EXPECT_EQ(row.decision == GateDecision::kRegression, row.metric.rfind("final.yaw_deg.", 0) != 0)
        << row.metric;
  }
  EXPECT_EQ(report.rows.size(), 11u * 2);
}

TEST(Gate, EpochTimeInARuleMayBeWrittenInAnyForm) {
  const v1::JobResult result = MakeResult(1.0);
  for (const char* written : {"600", "600.0", "6e2", "6.0E+02"}) {
    const std::string pattern = std::string("epoch[t=") + written + "].velocity_down_m_per_s.std";
    const std::vector<GateRule> rules = ParseGateRules("rules: [{metric: '" + pattern + "'}]");
    const GateReport report = RunGate(result, result, rules, Allow(false));
    ASSERT_EQ(report.rows.size(), 1u) << written;
    EXPECT_EQ(report.rows[0].metric, "epoch[t=600].velocity_down_m_per_s.std");
  }
}

TEST(Gate, SeedAndRunCountAreNotPartOfTheJobButTheSensorIs) {
  const v1::JobResult baseline = MakeResult(1.0);
  // Another seed and run count of the same job: compared, in independent mode.
  v1::JobResult other_sample = WithSeed(MakeResult(1.0, 80), 7);
  other_sample.mutable_job()->mutable_monte_carlo()->set_seed(7);
  other_sample.mutable_job()->mutable_monte_carlo()->set_runs(80);
  const GateReport sampled = RunGate(baseline, other_sample, DefaultGateRules(), Allow(false));
  EXPECT_FALSE(sampled.paired);
  EXPECT_NE(sampled.mode.find("current seed 7 with 80 runs"), std::string::npos) << sampled.mode;
  // A different rate or sensor model is another job: refused, naming the field.
  v1::JobResult other = MakeResult(1.0);
  other.mutable_job()->set_rate_hz(200);
  std::string error = ErrorOf([&] { RunGate(baseline, other, DefaultGateRules(), Allow(false)); });
  EXPECT_EQ(error.rfind("job.rate_hz: differs between the baseline and the current", 0), 0u)
      << error;
  EXPECT_NE(error.find("rate_hz: 100 -> 200"), std::string::npos) << error;
  EXPECT_NE(error.find("--allow-different-job"), std::string::npos) << error;
  v1::JobResult imu = MakeResult(1.0);
  imu.mutable_job()->mutable_sensor()->mutable_gyro()->set_arw_deg_per_sqrt_h(0.13);
  error = ErrorOf([&] { RunGate(baseline, imu, DefaultGateRules(), Allow(false)); });
  EXPECT_EQ(error.rfind("job.sensor: differs", 0), 0u) << error;
  const GateReport report = RunGate(baseline, other, DefaultGateRules(), Allow(true));
  EXPECT_TRUE(report.passed());
  ASSERT_FALSE(report.notes.empty());
  EXPECT_NE(report.notes[0].find("different jobs compared"), std::string::npos);
}

// The result with a filter consistency whose final average NEES over `runs` runs is `final_nees`
// (9 states; earlier epochs 9).
v1::JobResult WithNees(v1::JobResult result, double final_nees) {
  v1::FilterConsistency* consistency = result.mutable_filter_consistency();
  consistency->set_state_dimension(9);
  for (int e = 0; e < result.epochs_size(); ++e) {
    v1::NeesEpoch* nees = consistency->add_epochs();
    nees->set_t_s(result.epochs(e).t_s());
    nees->set_runs(result.run_count());
    nees->set_average_nees(e + 1 == result.epochs_size() ? final_nees : 9.0);
  }
  return result;
}

TEST(Gate, NeesIsTestedWithItsChiSquareDegreesOfFreedom) {
  // 1000 runs x 9 states: each average is chi2(9000) / 1000, whose ratio of two is F(9000, 9000)
  // with 95 % interval x/÷ 1.042. 12 / 9 = 1.33 against the limit 1.1 is a regression
  // (p ~ 1e-40); 9.2 / 9 = 1.022 has its interval's upper end 1.065 within the limit: pass.
  const std::vector<GateRule> rules = {{"final.nees", 0, 0.1, false}};
  const v1::JobResult baseline = WithNees(MakeResult(1.0, 1000), 9.0);
  GateReport report =
      RunGate(baseline, WithSeed(WithNees(MakeResult(1.0, 1000), 12.0), 7), rules, Allow(false));
  ASSERT_EQ(report.rows.size(), 1u);
  EXPECT_EQ(report.rows[0].decision, GateDecision::kRegression);
  EXPECT_EQ(report.rows[0].test, "F(9000, 9000) NEES ratio (chi2 band)");
  report =
      RunGate(baseline, WithSeed(WithNees(MakeResult(1.0, 1000), 9.2), 7), rules, Allow(false));
  EXPECT_EQ(report.rows[0].decision, GateDecision::kPass);
  EXPECT_NEAR(report.rows[0].ratio_high, 9.2 / 9.0 * 1.042, 0.002);
}

TEST(Gate, MetricMissingFromTheCurrentResultFails) {
  const v1::JobResult baseline = MakeResult(1.0);
  v1::JobResult fewer = MakeResult(1.0);
  fewer.mutable_epochs()->DeleteSubrange(1, 1);  // no epoch at t = 60 s
  fewer.mutable_job()->set_description("x");     // a different job, as it would be
  const std::vector<GateRule> rules = {{"epoch[t=60].*.std", 0, 0.1, false}};
  const GateReport report = RunGate(baseline, fewer, rules, Allow(true));
  EXPECT_EQ(report.regressions, 11);
  EXPECT_EQ(report.rows[0].note, "missing in the current result");
}

TEST(Gate, RuleErrorsNameTheField) {
  struct Case {
    const char* text;
    const char* expected;
  };
  const Case cases[] = {
      {"rules: [{metric: 'final.*', rel_tol: -0.1}]",
       "rules[0].rel_tol: -0.1 is not allowed; allowed: 0 <= rel_tol <= 100"},
      {"rules:\n  - metric: final.*\n  - metric: final.yaw_deg.rms\n    abs_tol: lots\n",
       "rules[1].abs_tol: \"lots\" is not allowed; allowed: a number, 0 <= abs_tol"},
      {"rules: [{metric: 'final.*', abs_tol: .nan}]", "rules[0].abs_tol: nan is not allowed"},
      {"rules: [{metric: 'final.*', tolerance: 1}]",
       "rules[0].tolerance: unknown field; allowed: metric, abs_tol, rel_tol, skip"},
      {"rules: [{rel_tol: 1}]", "rules[0].metric: missing is not allowed"},
      {"rules: [{metric: 'final.*', skip: maybe}]",
       "rules[0].skip: \"maybe\" is not allowed; allowed: true or false"},
      {"rules: []", "rules: an empty list is not allowed; allowed: a non-empty list"},
      {"rulez: []", "rulez: unknown field; allowed: defaults, rules"},
      {"defaults: {rel_tol: 200}\nrules: [{metric: 'final.*'}]",
       "defaults.rel_tol: 200 is not allowed; allowed: 0 <= rel_tol <= 100"},
      {"rules: [1, 2]", "rules[0]: \"1\" is not allowed; allowed: a mapping"},
      {"{\"rules\": [{\"metric\": \"final.*\"", "rules: invalid YAML/JSON at line"},
  };
  for (const Case& c : cases) {
    const std::string error = ErrorOf([&] { ParseGateRules(c.text); });
    EXPECT_NE(error.find(c.expected), std::string::npos)
        << "rules: " << c.text << "\nexpected: " << c.expected << "\ngot: " << error;
  }
  // JSON is YAML: the same rules in either syntax; defaults apply to rules that omit a field.
  const std::vector<GateRule> json = ParseGateRules(
      R"({"defaults": {"abs_tol": 0.5, "rel_tol": 0.2}, "rules": [{"metric": "final.*"}]})");
  ASSERT_EQ(json.size(), 1u);
  EXPECT_EQ(json[0].abs_tol, 0.5);
  EXPECT_EQ(json[0].rel_tol, 0.2);
  // A rule that matches no metric is a typo, reported with its index.
  const v1::JobResult result = MakeResult(1.0);
  const std::string typo = ErrorOf([&] {
    RunGate(result, result, ParseGateRules("rules: [{metric: final.*}, {metric: final.yaw.rms}]"),
            Allow(false));
  });
  EXPECT_NE(typo.find("rules[1].metric: \"final.yaw.rms\" is not allowed"), std::string::npos)
      << typo;
  // A quantity that is no metric of its own (CEP95) points to the metrics that are.
  const std::string cep = ErrorOf([&] {
    RunGate(result, result, ParseGateRules("rules: [{metric: final.*.cep95}]"), Allow(false));
  });
  EXPECT_NE(cep.find("use p50, p95, rms"), std::string::npos) << cep;
}

TEST(Gate, JunitXmlIsValidAndEscaped) {
  const v1::JobResult baseline = MakeResult(1.0, 50, "<b>&\"quoted\"'");
  const v1::JobResult degraded = MakeResult(1.5, 50, "<b>&\"quoted\"'");
  GateReport report = RunGate(baseline, degraded, DefaultGateRules(), Allow(false));
  report.baseline_file = "base<line>.json";
  report.current_file = "current.json";
  ASSERT_GT(report.regressions, 0);
  const std::string xml = RenderJunitXml(report);
  EXPECT_EQ(xml.find("<b>"), std::string::npos);
  EXPECT_NE(xml.find("driftlab gate: &lt;b&gt;&amp;&quot;quoted&quot;&apos;"), std::string::npos);
  TempDir dir;
  std::ofstream(dir / "junit.xml") << xml;
  // Parsed by Python's XML parser (what CI tools use): one suite, one case per row, one failure
  // per regression naming its metric, and the suite name reads back unescaped.
  std::ofstream(dir / "check.py")
      << "import sys, xml.etree.ElementTree as E\n"
         "r = E.parse(sys.argv[1]).getroot()\n"
         "assert r.tag == 'testsuite', r.tag\n"
         "cases = r.findall('testcase')\n"
         "assert len(cases) == "
      << report.rows.size() << ", len(cases)\n"
      << "failures = r.findall('testcase/failure')\n"
         "assert len(failures) == "
      << report.failures() << ", len(failures)\n"
      << "assert int(r.get('failures')) == len(failures)\n"
         "for case in cases:\n"
         "    for failure in case.findall('failure'):\n"
         "        assert failure.get('message').startswith(case.get('name') + ': current')\n"
         "        assert 'test: ' in failure.text and 'current file current.json' in failure.text\n"
         "    assert float(case.get('time')) >= 0\n"
         "p = {q.get('name'): q.get('value') for q in r.findall('properties/property')}\n"
         "assert p['baseline'] == 'base<line>.json' and p['current'] == 'current.json', p\n"
         "assert p['mode'].startswith('paired'), p\n"
         "assert r.get('name') == \"\"\"driftlab gate: <b>&\"quoted\"'\"\"\", r.get('name')\n";
  const std::string command =
      "/usr/bin/python3 " + (dir / "check.py").string() + " " + (dir / "junit.xml").string();
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
}

TEST(Gate, DataFileDegradedCopyIsTheBaselineTimesOnePointFive) {
  // gate_make_results.py scales every run's errors by 1.5; every statistic (moments, intervals,
  // interpolated percentiles, CEP, 2DRMS) is positively homogeneous of degree 1, so each metric
  // is 1.5 x the baseline's up to the rounding of numpy's few operations per value (1e-12
  // relative is ~5000 ulp, far above them and far below the 10 % the gate resolves).
  const v1::JobResult baseline = ReadJobResult(kCliData / "gate_baseline.json");
  const v1::JobResult degraded = ReadJobResult(kCliData / "gate_degraded.json");
  EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(baseline.job(), degraded.job()));
  const std::vector<Metric> a = ListMetrics(baseline);
  const std::vector<Metric> b = ListMetrics(degraded);
  ASSERT_EQ(a.size(), b.size());
  int non_zero = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].name, b[i].name);
    EXPECT_NEAR(b[i].value, 1.5 * a[i].value, 1e-12 * std::abs(a[i].value)) << a[i].name;
    non_zero += a[i].value != 0 ? 1 : 0;
  }
  // Only the t = 0 epoch is all zero: 11 x 3 metrics.
  EXPECT_EQ(non_zero, static_cast<int>(a.size()) - 11 * 3);
}

}  // namespace
}  // namespace driftlab::app::result_test
