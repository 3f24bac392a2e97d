// The gate's outputs: the plain-text table and the JUnit XML (gate.h).
#include <fmt/format.h>

#include <cmath>
#include <string>
#include <string_view>
#include <vector>

#include "driftlab/app/gate.h"
#include "result/gate_text.h"

namespace driftlab::app {
namespace {

std::string EscapeXml(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char ch : text) {
    switch (ch) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      case '\t':
      case '\n':
      case '\r':
        out += ch;
        break;
      default:
        // Control characters other than tab and line breaks are not allowed in XML 1.0.
        out += static_cast<unsigned char>(ch) < 0x20 ? '?' : ch;
    }
  }
  return out;
}

// "1.04 [0.93, 1.17]" (ratio and its interval); "-" when there is none.
std::string RatioText(const GateRow& row) {
  if (std::isnan(row.ratio)) return "-";
  return fmt::format(
      "{:.3f} [{:.3f}, {}]", row.ratio, row.ratio_low,
      std::isinf(row.ratio_high) ? std::string("inf") : fmt::format("{:.3f}", row.ratio_high));
}

std::string LimitRatioText(const GateRow& row) {
  if (!(row.baseline > 0)) return "-";
  return fmt::format("{:.3f}", row.limit / row.baseline);
}

bool Fails(const GateReport& report, const GateRow& row) {
  return row.decision == GateDecision::kRegression ||
         (report.options.strict && row.decision == GateDecision::kInconclusive);
}

std::string PlanningText(const GateReport& report) {
  if (!(report.detectable_sigma_ratio > 0)) return "";
  return fmt::format(
      "planning: with independent samples of {} and {} runs, a sigma that grew by {:.0f} % (10 % "
      "tolerance) is a regression with 90 % power at alpha {} over {} metrics (paired samples "
      "detect less); `driftlab gate BASELINE --runs-for-change 0.3` gives the runs for a "
      "change\n",
      report.baseline_runs, report.current_runs, 100.0 * (report.detectable_sigma_ratio - 1.0),
      report.options.alpha, report.rows.size());
}

}  // namespace

std::string FormatGateTable(const GateReport& report) {
  size_t width = std::string_view("metric").size();
  size_t test_width = std::string_view("test").size();
  for (const GateRow& row : report.rows) {
    width = std::max(width, row.metric.size());
    test_width = std::max(test_width, row.test.size());
  }
  std::string out;
  if (!report.baseline_file.empty()) {
    out += fmt::format("baseline: {} ({} runs)\ncurrent:  {} ({} runs)\n", report.baseline_file,
                       report.baseline_runs, report.current_file, report.current_runs);
  }
  out += "mode: " + report.mode + "\n";
  for (const std::string& note : report.notes) out += "note: " + note + "\n";
  const std::string header =
      fmt::format("{:<{}}  {:<4}  {:>11}  {:>11}  {:<26}  {:>6}  {:<12}  {}\n", "metric", width,
                  "unit", "baseline", "current", "ratio [interval]", "limit", "decision", "test");
  out += header;
  std::vector<std::string> failed;
  for (const GateRow& row : report.rows) {
    out += fmt::format("{:<{}}  {:<4}  {:>11}  {:>11}  {:<26}  {:>6}  {:<12}  {}\n", row.metric,
                       width, row.unit, GateNumberText(row.baseline), GateNumberText(row.current),
                       RatioText(row), LimitRatioText(row), DecisionName(row.decision), row.test);
    if (Fails(report, row)) failed.push_back(row.metric);
  }
  out += fmt::format(
      "ratio = current / baseline with its {:g} % interval; limit = 1 + tolerance; "
      "alpha {} family-wise (Holm) over {} metrics{}\n",
      100.0 * (1.0 - report.options.alpha), report.options.alpha, report.rows.size(),
      report.options.strict ? "; --strict" : "");
  out += PlanningText(report);
  const size_t passed = report.rows.size() - report.regressions - report.inconclusive;
  if (report.passed()) {
    out += fmt::format(
        "gate: PASS, {} metrics: {} pass or improved, {} inconclusive, no "
        "regression\n",
        report.rows.size(), passed, report.inconclusive);
  } else {
    out += fmt::format("gate: FAIL, {} of {} metrics {}: {}\n", failed.size(), report.rows.size(),
                       report.options.strict ? "regressed or inconclusive (--strict)" : "regressed",
                       fmt::join(failed, ", "));
  }
  return out;
}

std::string RenderJunitXml(const GateReport& report) {
  double total_s = 0;
  for (const GateRow& row : report.rows) total_s += row.wall_s;
  std::string out = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  out += fmt::format(
      "<testsuite name=\"{}\" tests=\"{}\" failures=\"{}\" errors=\"0\" skipped=\"0\" "
      "time=\"{:.6f}\">\n",
      EscapeXml("driftlab gate: " + report.job_name), report.rows.size(), report.failures(),
      total_s);
  out += "  <properties>\n";
  const std::pair<const char*, std::string> properties[] = {
      {"baseline", report.baseline_file},
      {"current", report.current_file},
      {"baseline_runs", std::to_string(report.baseline_runs)},
      {"current_runs", std::to_string(report.current_runs)},
      {"mode", report.mode},
      {"alpha", fmt::format("{}", report.options.alpha)},
      {"strict", report.options.strict ? "true" : "false"}};
  for (const auto& [name, value] : properties) {
    out += fmt::format("    <property name=\"{}\" value=\"{}\"/>\n", name, EscapeXml(value));
  }
  out += "  </properties>\n";
  for (const GateRow& row : report.rows) {
    const std::string detail = fmt::format(
        "{}: baseline {} {unit}, current {} {unit}, ratio {} (interval at {:g} %), limit ratio {}, "
        "p = {:.3g} before Holm; test: {}; baseline file {}, current file {}",
        DecisionName(row.decision), GateNumberText(row.baseline), GateNumberText(row.current),
        RatioText(row), 100.0 * (1.0 - report.options.alpha), LimitRatioText(row), row.p_value,
        row.test, report.baseline_file, report.current_file, fmt::arg("unit", row.unit));
    out += fmt::format("  <testcase classname=\"driftlab.gate\" name=\"{}\" time=\"{:.6f}\"",
                       EscapeXml(row.metric), row.wall_s);
    if (!Fails(report, row)) {
      out += fmt::format(">\n    <system-out>{}</system-out>\n  </testcase>\n", EscapeXml(detail));
    } else {
      out += fmt::format(
          ">\n    <failure message=\"{}\" type=\"{}\">{}</failure>\n  </testcase>\n",
          EscapeXml(row.metric + ": " + (row.note.empty() ? DecisionName(row.decision) : row.note)),
          DecisionName(row.decision), EscapeXml(detail));
    }
  }
  out += "</testsuite>\n";
  return out;
}

}  // namespace driftlab::app
