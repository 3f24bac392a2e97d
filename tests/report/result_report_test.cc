// In-process tests of the HTML report (html_report.h) on JobResult messages built with known
// statistics (result_test_util.h) and on the committed synthetic result.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <regex>
#include <string>

#include "driftlab/app/result_file.h"
#include "driftlab/report/html_report.h"
#include "result_test_util.h"
#include "support/report_html.h"

namespace driftlab::app::result_test {
namespace {

using testing::Count;

// ---------------------------------------------------------------------------------------------
// HTML report

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
}  // namespace driftlab::app::result_test
