// In-process tests of result files (result_file.h) on JobResult messages built with known
// statistics (result_test_util.h): the JSON round trip, read and validation errors, one-run
// results.
#include "driftlab/app/result_file.h"

#include <google/protobuf/util/message_differencer.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "driftlab/app/gate.h"
#include "driftlab/report/html_report.h"
#include "driftlab/spec_error.h"
#include "result_test_util.h"

namespace driftlab::app::result_test {
namespace {

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

}  // namespace
}  // namespace driftlab::app::result_test
