// In-process tests of result files (result_file.h), the HTML report (html_report.h) and the CI
// gate (gate.h), on JobResult messages built here with known statistics.
#include <google/protobuf/util/message_differencer.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <regex>
#include <sstream>
#include <string>

#include "driftlab/app/gate.h"
#include "driftlab/app/result_file.h"
#include "driftlab/report/html_report.h"
#include "driftlab/spec_error.h"
#include "support/report_html.h"
#include "support/spec_errors.h"

namespace driftlab::app {
namespace {

namespace fs = std::filesystem;

// A synthetic result with known statistics: N runs, epochs every 60 s to 600 s, checkpoints at
// 300 s and 600 s. Component c's statistics at time t are (c + 1) * (t / 600) times fixed base
// values, all multiplied by `scale`; per-run values are scale * (c + 1) * (t / 600) * w_r with
// w_r = sin(2.4 r) (bounded, deterministic). The percentiles are those of the stored per-run
// values (nearest rank), so the message is self-consistent and valid.
v1::JobResult MakeResult(double scale, int runs = 50, const std::string& name = "synthetic") {
  v1::JobResult result;
  result.mutable_job()->set_name(name);
  result.mutable_job()->set_description("built by result_report_gate_lib_test");
  result.mutable_job()->set_rate_hz(100);
  result.set_engine_version("test");
  result.set_seed(42);
  result.set_runs(runs);
  result.set_first_run(0);
  result.set_run_count(runs);
  for (int i = 0; i <= 10; ++i) {
    const double t = 60.0 * i;
    v1::EpochStatistics* epoch = result.add_epochs();
    epoch->set_t_s(t);
    for (int c = 0; c < kErrorComponentCount; ++c) {
      const double k = scale * (c + 1) * t / 600.0;
      v1::ComponentStatistics* s = epoch->add_components();
      s->set_component(static_cast<v1::ErrorComponent>(c + 1));
      s->set_mean(c < 9 ? -0.1 * k : 1.1 * k);  // signed components may have a negative bias
      s->set_std(k);
      s->set_rms(1.005 * k);
      s->set_std_ci95_low(0.8 * k);
      s->set_std_ci95_high(1.25 * k);
      s->set_rms_ci95_low(0.81 * k);
      s->set_rms_ci95_high(1.26 * k);
    }
  }
  for (const double t : {300.0, 600.0}) {
    v1::Checkpoint* checkpoint = result.add_checkpoints();
    checkpoint->set_t_s(t);
    std::vector<std::vector<double>> abs_values(kErrorComponentCount);
    for (int r = 0; r < runs; ++r) {
      v1::RunValues* run = checkpoint->add_runs();
      run->set_run_index(r);
      const double w = std::sin(2.4 * r);
      for (int c = 0; c < kErrorComponentCount; ++c) {
        const double k = scale * (c + 1) * t / 600.0;
        const double value = c < 9 ? k * w : k * std::abs(w);
        run->add_values(value);
        abs_values[c].push_back(std::abs(value));
      }
    }
    for (int c = 0; c < kErrorComponentCount; ++c) {
      std::vector<double>& a = abs_values[c];
      std::sort(a.begin(), a.end());
      const auto rank = [&](double p) { return a[static_cast<size_t>(std::ceil(p * runs)) - 1]; };
      v1::ComponentPercentiles* p = checkpoint->add_components();
      p->set_component(static_cast<v1::ErrorComponent>(c + 1));
      p->set_p50(rank(0.50));
      p->set_p68(rank(0.68));
      p->set_p95(rank(0.95));
      p->set_p99(rank(0.99));
      p->set_max_abs(a.back());
    }
    checkpoint->set_cep50_m(checkpoint->components(9).p50());
    checkpoint->set_cep95_m(checkpoint->components(9).p95());
    checkpoint->set_drms2_m(2.0 * scale * 10 * t / 600.0);
  }
  v1::Timings* timings = result.mutable_timings();
  timings->set_wall_s(1.5);
  timings->set_cpu_s(2.9);
  timings->set_samples(uint64_t{60001} * runs);
  timings->set_samples_per_s(60001.0 * runs / 1.5);
  timings->set_threads(2);
  return result;
}

using testing::ErrorOf;

std::string Slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("driftlab_rg_lib_" + std::to_string(getpid()) + "_" + info->name());
    fs::create_directories(dir_);
  }
  ~TempDir() { fs::remove_all(dir_); }
  fs::path operator/(const std::string& name) const { return dir_ / name; }

 private:
  fs::path dir_;
};

using testing::Count;

double MetricValue(const std::vector<Metric>& metrics, const std::string& name) {
  for (const Metric& m : metrics) {
    if (m.name == name) return m.value;
  }
  ADD_FAILURE() << "no metric " << name;
  return std::numeric_limits<double>::quiet_NaN();
}

// ---------------------------------------------------------------------------------------------
// Result files

TEST(ResultFile, JsonRoundTripIsBitIdentical) {
  v1::JobResult result = MakeResult(1.0);
  // Doubles that need 17 significant digits, the extremes of the format and a subnormal.
  const double awkward[] = {0.1,
                            1.0 / 3.0,
                            M_PI * 1e-300,
                            std::numeric_limits<double>::denorm_min(),
                            std::numeric_limits<double>::max(),
                            -2.0 / 7.0 * 1e5,
                            std::nextafter(1.0, 2.0),
                            123456789.12345678};
  int k = 0;
  for (v1::RunValues& run : *result.mutable_checkpoints(1)->mutable_runs()) {
    for (int c = 0; c < 9; ++c) run.set_values(c, awkward[k++ % std::size(awkward)]);
  }
  result.mutable_epochs(3)->mutable_components(0)->set_mean(1.0 / 3.0);
  result.mutable_epochs(3)->mutable_components(0)->set_rms_ci95_high(
      std::numeric_limits<double>::infinity());
  result.mutable_merge_state()->set_encoding("test");
  for (const v1::EpochStatistics& epoch : result.epochs()) {
    v1::EpochSums* sums = result.mutable_merge_state()->add_epochs();
    sums->set_t_s(epoch.t_s());
    for (int c = 0; c < kErrorComponentCount; ++c) {
      v1::ComponentSums* s = sums->add_components();
      s->set_component(static_cast<v1::ErrorComponent>(c + 1));
      s->mutable_sum()->add_limbs(std::numeric_limits<int64_t>::min());
      s->mutable_sum()->add_limbs(-c);
      s->mutable_sum_of_squares()->add_limbs(std::numeric_limits<int64_t>::max());
    }
  }

  TempDir dir;
  WriteJobResult(dir / "result.json", result);
  const v1::JobResult back = ReadJobResult(dir / "result.json");
  // Bit-identical: the binary serializations agree byte for byte (doubles as raw IEEE bits,
  // so -0.0, the mean at t = 0 of the signed components, must keep its sign).
  ASSERT_TRUE(std::signbit(result.epochs(0).components(0).mean()));
  EXPECT_TRUE(std::signbit(back.epochs(0).components(0).mean()));
  EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(result, back));
  std::string a, b;
  ASSERT_TRUE(result.SerializeToString(&a));
  ASSERT_TRUE(back.SerializeToString(&b));
  EXPECT_TRUE(a == b) << "binary serializations differ";
  EXPECT_EQ(back.checkpoints(1).runs(0).values(3), std::numeric_limits<double>::denorm_min());

  // The file is the JSON mapping with proto field names, zero scalars printed, 0.1 printed short.
  const std::string json = Slurp(dir / "result.json");
  EXPECT_NE(json.find("\"run_count\": 50"), std::string::npos);
  EXPECT_NE(json.find("\"first_run\": 0"), std::string::npos);
  EXPECT_NE(json.find("\"component\": \"HORIZONTAL_POSITION_M\""), std::string::npos);
  EXPECT_NE(json.find("\"rms_ci95_high\": \"Infinity\""), std::string::npos);
  EXPECT_NE(json.find(" 0.1,"), std::string::npos);
  EXPECT_EQ(json.find("0.10000000000000001"), std::string::npos);
  EXPECT_NE(json.find("\"mean\": -0.0,"), std::string::npos);
  EXPECT_NE(json.find("0.33333333333333331"), std::string::npos);  // 17 digits where needed
  EXPECT_FALSE(fs::exists(dir / "result.json.tmp"));
}

TEST(ResultFile, ReadErrorsNameTheFileAndField) {
  TempDir dir;
  const fs::path missing = dir / "missing.json";
  EXPECT_NE(ErrorOf([&] { ReadJobResult(missing); }).find(missing.string() + ": no such file"),
            std::string::npos);

  const fs::path bad_json = dir / "bad.json";
  std::ofstream(bad_json) << "{\"runs\": 3,";
  const std::string syntax = ErrorOf([&] { ReadJobResult(bad_json); });
  EXPECT_NE(syntax.find(bad_json.string() + ": invalid result JSON"), std::string::npos) << syntax;

  const fs::path unknown = dir / "unknown.json";
  std::ofstream(unknown) << "{\"runz\": 3}";
  EXPECT_NE(ErrorOf([&] { ReadJobResult(unknown); }).find("runz"), std::string::npos);

  v1::JobResult result = MakeResult(1.0);
  result.mutable_epochs(2)->set_t_s(60.0);  // equal to epochs[1].t_s
  const std::string text = JobResultToJson(result);
  std::ofstream(dir / "backwards.json") << text;
  const std::string backwards = ErrorOf([&] { ReadJobResult(dir / "backwards.json"); });
  EXPECT_NE(backwards.find("backwards.json: epochs[2].t_s: 60 is not allowed; allowed: > "
                           "epochs[1].t_s = 60"),
            std::string::npos)
      << backwards;
  // Refused at write time too, and no file is left behind.
  EXPECT_NE(ErrorOf([&] { WriteJobResult(dir / "out.json", result); }).find("epochs[2].t_s"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "out.json"));
}

TEST(ResultFile, ValidationNamesTheFieldPath) {
  struct Case {
    void (*mutate)(v1::JobResult&);
    const char* expected;
  };
  const Case cases[] = {
      {[](v1::JobResult& r) { r.set_run_count(0); }, "run_count: 0 is not allowed; allowed: >= 1"},
      {[](v1::JobResult& r) { r.set_first_run(10); }, "run_count: 50 is not allowed"},
      {[](v1::JobResult& r) { r.clear_epochs(); }, "epochs: missing is not allowed"},
      {[](v1::JobResult& r) {
         r.mutable_epochs(4)->mutable_components(2)->set_component(v1::YAW_DEG);
       },
       "epochs[4].components[2].component: YAW_DEG is not allowed; allowed: POSITION_DOWN_M"},
      {[](v1::JobResult& r) { r.mutable_epochs(5)->mutable_components(1)->set_std(-1); },
       "epochs[5].components[1].std: -1 is not allowed"},
      {[](v1::JobResult& r) {
         r.mutable_epochs(5)->mutable_components(1)->set_mean(
             std::numeric_limits<double>::quiet_NaN());
       },
       "epochs[5].components[1].mean: nan is not allowed; allowed: a finite number"},
      {[](v1::JobResult& r) { r.mutable_epochs(5)->mutable_components(1)->set_rms_ci95_high(0.1); },
       "epochs[5].components[1].rms_ci95_high: 0.1 is not allowed; allowed: rms_ci95_high >= "
       "rms_ci95_low"},
      {[](v1::JobResult& r) { r.mutable_checkpoints(0)->mutable_components(3)->set_p95(0); },
       "checkpoints[0].components[3].p95: 0 is not allowed; allowed: >= p68"},
      {[](v1::JobResult& r) { r.mutable_checkpoints(1)->set_t_s(500); },
       "checkpoints[1].t_s: 500 is not allowed; allowed: the final epoch's t_s = 600"},
      {[](v1::JobResult& r) { r.mutable_checkpoints(1)->mutable_runs()->RemoveLast(); },
       "checkpoints[1].runs: 49 entries is not allowed; allowed: none or one per run"},
      {[](v1::JobResult& r) { r.mutable_checkpoints(1)->mutable_runs(7)->set_run_index(8); },
       "checkpoints[1].runs[7].run_index: 8 is not allowed; allowed: 7"},
      {[](v1::JobResult& r) { r.mutable_checkpoints(1)->mutable_runs(7)->add_values(1); },
       "checkpoints[1].runs[7].values: 12 values is not allowed"},
      {[](v1::JobResult& r) { r.mutable_checkpoints(1)->mutable_runs(7)->set_values(9, -1); },
       "checkpoints[1].runs[7].values[9]: -1 is not allowed"},
      {[](v1::JobResult& r) { r.mutable_timings()->set_wall_s(-1); },
       "timings.wall_s: -1 is not allowed"},
  };
  for (const Case& c : cases) {
    v1::JobResult result = MakeResult(1.0);
    c.mutate(result);
    const std::string error = ErrorOf([&] { ValidateJobResult(result); });
    EXPECT_NE(error.find(c.expected), std::string::npos)
        << "expected: " << c.expected << "\ngot: " << error;
  }
  EXPECT_EQ(ErrorOf([] { ValidateJobResult(MakeResult(1.0)); }), "");
  // A result without per-run values is valid (the report then has no scatter).
  v1::JobResult no_runs = MakeResult(1.0);
  for (v1::Checkpoint& checkpoint : *no_runs.mutable_checkpoints()) checkpoint.clear_runs();
  EXPECT_EQ(ErrorOf([&] { ValidateJobResult(no_runs); }), "");
}

TEST(HtmlReport, ExtremeValuesRenderWithoutNonFinite) {
  // A structurally valid result holding means of +-1e308 (the CLI refuses it: its per-run values
  // do not give them; the renderer must still cope): fmt must not see a negative precision, and
  // neither the text nor the plot data hold a non-finite number.
  const std::string json = Slurp(kCliData / "gate_baseline.json");
  const std::regex mean(R"re("mean": [-0-9.eE+]+)re");
  std::string text;
  size_t copied = 0;
  int k = 0;
  for (auto it = std::sregex_iterator(json.begin(), json.end(), mean); it != std::sregex_iterator();
       ++it, ++k) {
    text += json.substr(copied, it->position() - copied);
    text += std::string("\"mean\": ") + (k % 2 ? "-" : "") + "1e308";
    copied = it->position() + it->length();
  }
  text += json.substr(copied);
  const std::string page = RenderHtmlReport(ParseJobResultJson(text, "extreme.json"));
  EXPECT_NE(page.find("</html>"), std::string::npos);
  const std::string markup = ::driftlab::testing::WithoutScriptText(page);
  EXPECT_EQ(markup.find("nan"), std::string::npos);
  EXPECT_EQ(markup.find("inf"), std::string::npos);
  int plots = 0;
  for (size_t at = page.find("<script>driftlabPlot("); at != std::string::npos;
       at = page.find("<script>driftlabPlot(", at + 1)) {
    const std::string call = page.substr(at, page.find("</script>", at) - at);
    // As a value: after ",", "[" or ":" (the key "info" holds "inf").
    for (const char* before : {",", "[", ":", "-"}) {
      for (const char* bad : {"nan", "NaN", "inf", "Infinity"}) {
        EXPECT_EQ(call.find(std::string(before) + bad), std::string::npos)
            << bad << " in " << call.substr(0, 80);
      }
    }
    ++plots;
  }
  EXPECT_GE(plots, 23);
}

TEST(ResultFile, OneRunResultHasUndefinedSigma) {
  // With N = 1 the sample sigma (divisor N - 1) and its interval are undefined: NaN, as the
  // engine's statistics report them; a finite sigma there is refused.
  v1::JobResult result = MakeResult(1.0, 1);
  EXPECT_NE(ErrorOf([&] { ValidateJobResult(result); }).find("std: 0 is not allowed; allowed: NaN"),
            std::string::npos);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (v1::EpochStatistics& epoch : *result.mutable_epochs()) {
    for (v1::ComponentStatistics& s : *epoch.mutable_components()) {
      s.set_std(nan);
      s.set_std_ci95_low(nan);
      s.set_std_ci95_high(nan);
    }
  }
  EXPECT_EQ(ErrorOf([&] { ValidateJobResult(result); }), "");
  // The gate leaves the undefined metrics out; the report renders.
  const std::vector<Metric> metrics = ListMetrics(result);
  for (const Metric& m : metrics) {
    EXPECT_FALSE(std::isnan(m.value)) << m.name;
    EXPECT_EQ(m.name.find(".std"), std::string::npos) << m.name;
  }
  EXPECT_NE(RenderHtmlReport(result).find("</html>"), std::string::npos);
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

// ---------------------------------------------------------------------------------------------
// HTML report

TEST(Report, IsOneSelfContainedFileWithAnInteractivePlotEach) {
  const v1::JobResult result = MakeResult(1.0, 50, "<b>& \"job\"");
  const std::string html = RenderHtmlReport(result);
  // dygraphs and report_plots.js are inline (<script> without src); nothing else loads.
  const std::string markup = ::driftlab::testing::WithoutScriptText(html);
  for (const char* fetch :
       {"http://", "https://", "src=", "<link", "@import", "url(", "<iframe", "<img"}) {
    EXPECT_EQ(markup.find(fetch), std::string::npos) << fetch;
  }
  EXPECT_EQ(Count(html, "<script"), Count(html, "<script>"));
  EXPECT_NE(html.find("Dygraph"), std::string::npos);
  // 11 envelopes, the scatter, the horizontal histogram and 10 other histograms.
  EXPECT_EQ(Count(html, "id=\"plot-envelope-"), 11u);
  EXPECT_EQ(Count(html, "id=\"plot-scatter\""), 1u);
  EXPECT_EQ(Count(html, "id=\"plot-histogram-"), 11u);
  // The job name escaped everywhere (title, heading, job echo), never raw.
  EXPECT_EQ(markup.find("<b>&"), std::string::npos);
  EXPECT_GE(Count(html, "&lt;b&gt;&amp; &quot;job&quot;"), 2u);
  EXPECT_NE(html.find("engine version"), std::string::npos);
  EXPECT_NE(html.find("CEP95"), std::string::npos);
  // One scatter point per run, each with the command that regenerates it.
  EXPECT_EQ(Count(html, "driftlab simulate job.json --run "), 50u);
  EXPECT_NE(html.find("driftlab simulate job.json --run 49 --out run-49"), std::string::npos);
  // The job echo is collapsible.
  EXPECT_NE(html.find("<details><summary>Job as run"), std::string::npos);
  EXPECT_EQ(html.substr(0, 15), "<!DOCTYPE html>");
  EXPECT_EQ(html.substr(html.size() - 8), "</html>\n");

  // Without per-run values: envelopes only, and a note instead of the scatter.
  v1::JobResult no_runs = result;
  for (v1::Checkpoint& checkpoint : *no_runs.mutable_checkpoints()) checkpoint.clear_runs();
  const std::string short_html = RenderHtmlReport(no_runs);
  EXPECT_EQ(Count(short_html, "id=\"plot-envelope-"), 11u);
  EXPECT_EQ(Count(short_html, "id=\"plot-scatter\""), 0u);
  EXPECT_NE(short_html.find("keeps no per-run values"), std::string::npos);
}

// With a covariance analysis, the summary table shows the predicted sigma (RMS for the
// two distances) beside the Monte-Carlo sigma; without one, no such column.
TEST(Report, SummaryTableShowsThePredictedSigmaWhenTheResultHasACovarianceAnalysis) {
  v1::JobResult result = MakeResult(1.0, 50);
  const std::string without = RenderHtmlReport(result);
  EXPECT_EQ(without.find("<th>predicted &sigma;</th>"), std::string::npos);
  v1::CovarianceAnalysis* covariance = result.mutable_covariance();
  covariance->set_filter("NONE");
  for (const v1::EpochStatistics& epoch : result.epochs()) {
    v1::PredictedEpoch* predicted = covariance->add_epochs();
    predicted->set_t_s(epoch.t_s());
    // Distinct, recognisable values: 0.001 (c + 1) * 7 for component c.
    for (int c = 0; c < kErrorComponentCount; ++c) predicted->add_sigma(0.007 * (c + 1));
  }
  const std::string with = RenderHtmlReport(result);
  const size_t header = with.find("<th>predicted &sigma;</th>");
  ASSERT_NE(header, std::string::npos);
  // The column sits between the sigma interval and the RMS in the summary table.
  EXPECT_LT(with.find("<th>&sigma; 95 % CI</th>", header - 40), header);
  EXPECT_EQ(with.find("<th>RMS</th>", header), header + std::strlen("<th>predicted &sigma;</th>"));
  // North position (c = 0) and the 3-D distance (c = 10) rows carry their predicted value.
  const size_t north = with.find("<tr><td>north position", header);
  ASSERT_NE(north, std::string::npos);
  const std::string north_row = with.substr(north, with.find("</tr>", north) - north);
  EXPECT_NE(north_row.find("0.007"), std::string::npos) << north_row;
}

TEST(Report, DataFileResultRendersAndIsWellFormedXml) {
  // The committed synthetic result (tests/cli/data/gate_make_results.py): its markup (script
  // text removed) must be well formed; Python's XML parser reads the report body after the doctype
  // (the report uses only XML-compatible HTML: every element closed, entities escaped).
  std::string html = ::driftlab::testing::WithoutScriptText(
      RenderHtmlReport(ReadJobResult(kCliData / "gate_baseline.json")));
  for (const char* entity : {"&sigma;", "&plusmn;"}) {
    for (size_t at = html.find(entity); at != std::string::npos; at = html.find(entity)) {
      html.replace(at, std::strlen(entity), "s");
    }
  }
  TempDir dir;
  std::ofstream(dir / "report.xml") << html.substr(html.find("<html"));
  const std::string command =
      "/usr/bin/python3 -c \"import sys, xml.etree.ElementTree as E; "
      "E.parse(sys.argv[1])\" " +
      (dir / "report.xml").string();
  EXPECT_EQ(std::system(command.c_str()), 0);
}

TEST(Report, NiceTicksAreOneTwoFiveTimesAPowerOfTenAndCoverTheData) {
  // Heckbert's algorithm by hand for [0, 1], 5 ticks: range 1, step nice(0.25, round) = 0.2.
  const AxisTicks unit = NiceTicks(0, 1);
  EXPECT_DOUBLE_EQ(unit.step, 0.2);
  EXPECT_EQ(unit.decimals, 1);
  EXPECT_EQ(unit.values.size(), 6u);
  // [0, 600] s: range nice(600) = 1000, step nice(250, round) = 200: 0, 200, 400, 600.
  const AxisTicks time = NiceTicks(0, 600);
  EXPECT_DOUBLE_EQ(time.step, 200);
  EXPECT_EQ(time.values.size(), 4u);
  const double ranges[][2] = {{-3.7, 12.2}, {0, 1e-6},   {1234, 1299},  {-1e5, -2e4},
                              {5, 5},       {0.01, 0.3}, {-0.02, 0.02}, {0, 0}};
  for (const auto& r : ranges) {
    const AxisTicks t = NiceTicks(r[0], r[1]);
    EXPECT_LE(t.lo, r[0]);
    EXPECT_GE(t.hi, r[1]);
    EXPECT_LT(t.lo, t.hi);
    const double mantissa = t.step / std::pow(10.0, std::floor(std::log10(t.step)));
    // 1, 2 or 5 up to the rounding of step / 10^k (1e-9 relative).
    EXPECT_TRUE(std::abs(mantissa - 1) < 1e-9 || std::abs(mantissa - 2) < 1e-9 ||
                std::abs(mantissa - 5) < 1e-9)
        << r[0] << " " << r[1] << " step " << t.step;
    // Heckbert with 5 requested: between 3 and 11 ticks.
    EXPECT_GE(t.values.size(), 3u);
    EXPECT_LE(t.values.size(), 11u);
  }
}

}  // namespace
}  // namespace driftlab::app
