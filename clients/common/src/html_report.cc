#include "driftlab/jobspec/html_report.h"

#include <fmt/format.h>
#include <google/protobuf/util/json_util.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "driftlab/jobspec/consistency_check.h"
#include "driftlab/jobspec/result_file.h"
#include "svg_plot.h"

namespace driftlab::jobspec {
namespace {

using svg::Chart;
using svg::Figure;
using svg::kStyle;
using svg::Num;
using svg::Range;
using svg::Scale;

// At most this many epochs are drawn per envelope (every k-th and the last; the statistics
// tables use all), and this many runs in the scatter (the first by run index; the histograms use
// all): keeps a 1000000-run or 100000-epoch report to a few MB.
constexpr int kMaxDrawnEpochs = 2000;
constexpr int kMaxScatterPoints = 5000;

constexpr const char* kBandColor = "#9ecae1";
constexpr const char* kMeanColor = "#08519c";
constexpr const char* kRmsColor = "#cb181d";
constexpr const char* kCep50Color = "#238b45";
constexpr const char* kCep95Color = "#d94801";
constexpr const char* kBarColor = "#6baed6";
constexpr const char* kPredictedColor = "#252525";

v1::ErrorComponent Component(int c) { return static_cast<v1::ErrorComponent>(c + 1); }

// "north position error [m]" for axis labels and headings.
std::string ComponentLabel(int c) {
  static constexpr const char* kNames[kErrorComponentCount] = {"north position",
                                                               "east position",
                                                               "down position",
                                                               "north velocity",
                                                               "east velocity",
                                                               "down velocity",
                                                               "roll",
                                                               "pitch",
                                                               "yaw",
                                                               "horizontal position",
                                                               "3-D position"};
  return fmt::format("{} error [{}]", kNames[c], ComponentUnit(Component(c)));
}

bool IsDistance(int c) { return c + 1 >= v1::HORIZONTAL_POSITION_M; }

// The result carries a linear covariance analysis with one predicted epoch per epoch.
bool HasPrediction(const v1::JobResult& result) {
  if (!result.has_covariance() || result.covariance().epochs_size() != result.epochs_size()) {
    return false;
  }
  for (const v1::PredictedEpoch& e : result.covariance().epochs()) {
    if (e.sigma_size() != kErrorComponentCount) return false;
  }
  return true;
}

// Average NEES of the filter per epoch against its chi-square 95 % bounds (epochs with runs).
std::string NeesPlot(const v1::JobResult& result) {
  const v1::FilterConsistency& fc = result.filter_consistency();
  std::vector<std::pair<double, double>> nees, lower, upper;
  Range x, y;
  const int n = fc.epochs_size();
  const int stride = (n + kMaxDrawnEpochs - 1) / kMaxDrawnEpochs;
  for (int i = 0; i < n; ++i) {
    const v1::NeesEpoch& e = fc.epochs(i);
    if ((i % stride != 0 && i != n - 1) || e.runs() == 0) continue;
    nees.emplace_back(e.t_s(), e.average_nees());
    lower.emplace_back(e.t_s(), e.chi2_95_low());
    upper.emplace_back(e.t_s(), e.chi2_95_high());
    x.Add(e.t_s());
    for (const double v : {e.average_nees(), e.chi2_95_low(), e.chi2_95_high()}) y.Add(v);
  }
  if (nees.empty()) return "";
  // Log axis (issue 18): an average NEES 40 times its band flattened the band to under a pixel on
  // a linear axis.
  Chart chart(520, 230, x, y, "t [s]", "average NEES (log)", Scale::kLinear, Scale::kLog10);
  chart.Band(upper, lower, kBandColor);
  chart.Polyline(nees, kMeanColor);
  return Figure(
      chart.Finish(),
      fmt::format("average NEES of the {} navigation error states over the runs, with its "
                  "chi-square 95 % band (mean over epochs {})",
                  fc.state_dimension(), Num(fc.mean_average_nees())));
}

// The consistency verdict on the first screen (issue 18): whether the Monte-Carlo spread agrees
// with the filter's covariance (NEES) and with the covariance analysis (sigma ratios).
std::string ConsistencyBox(const v1::JobResult& result) {
  const ConsistencyVerdict v = AssessConsistency(result);
  if (!v.tested()) return "";
  std::string html = fmt::format(
      "<div class=\"verdict\" style=\"border:2px solid {0};padding:6px 10px;margin:8px 0\">"
      "<b style=\"color:{0}\">Consistency: {1}</b><br/>{2}",
      v.consistent() ? "#2a7d2a" : "#b00020", v.consistent() ? "consistent" : "INCONSISTENT",
      EscapeHtml(v.Summary()));
  if (!v.components.empty()) {
    html += "<table><tr><th>component</th><th>MC &sigma; / predicted &sigma;</th><th>interval "
            "(Bonferroni)</th><th></th></tr>\n";
    for (const ComponentConsistency& c : v.components) {
      html += fmt::format("<tr><td>{}</td><td class=\"num\">{:.3g}</td><td class=\"num\">[{:.3g}, "
                          "{:.3g}]</td><td>{}</td></tr>\n",
                          ConsistencyComponentName(c.component), c.ratio.ratio, c.ratio.low,
                          c.ratio.high, c.flagged ? "&#9888; outside" : "ok");
    }
    html += "</table>";
  }
  html += fmt::format(
      "<p style=\"font-size:90%\">Tests at family-wise false-alarm rate {:g} (Bonferroni over the "
      "epochs and components tested): the N-run average NEES of a consistent filter is "
      "&chi;&sup2;(dN)/N; (N&minus;1)s&sup2;/&sigma;&sup2; is &chi;&sup2;(N&minus;1).</p></div>\n",
      v.alpha);
  return html;
}

std::string EnvelopePlot(const v1::JobResult& result, int c) {
  const int n = result.epochs_size();
  const int stride = (n + kMaxDrawnEpochs - 1) / kMaxDrawnEpochs;
  std::vector<std::pair<double, double>> mean, upper, lower, rms, minus_rms;
  std::vector<std::pair<double, double>> predicted_upper, predicted_lower;
  const bool predicted = HasPrediction(result);
  Range x, y;
  y.Add(0);
  for (int i = 0; i < n; ++i) {
    if (i % stride != 0 && i != n - 1) continue;
    const double t = result.epochs(i).t_s();
    const v1::ComponentStatistics& s = result.epochs(i).components(c);
    const double std = std::isnan(s.std()) ? 0.0 : s.std();  // one run: no band
    mean.emplace_back(t, s.mean());
    upper.emplace_back(t, s.mean() + std);
    lower.emplace_back(t, s.mean() - std);
    rms.emplace_back(t, s.rms());
    minus_rms.emplace_back(t, -s.rms());
    x.Add(t);
    for (const double v : {s.mean() + std, s.mean() - std, s.rms()}) y.Add(v);
    if (!IsDistance(c)) y.Add(-s.rms());
    if (predicted) {
      // Linear covariance analysis: sigma about the Monte-Carlo mean for components 1-9 (to
      // compare with the band), the predicted RMS for the distances (to compare with +RMS).
      const double sigma = result.covariance().epochs(i).sigma(c);
      if (IsDistance(c)) {
        predicted_upper.emplace_back(t, sigma);
      } else {
        predicted_upper.emplace_back(t, s.mean() + sigma);
        predicted_lower.emplace_back(t, s.mean() - sigma);
      }
      for (const auto& p : {predicted_upper.back()}) y.Add(p.second);
      if (!predicted_lower.empty()) y.Add(predicted_lower.back().second);
    }
  }
  Chart chart(330, 230, x, y, "t [s]", ComponentLabel(c));
  chart.Band(upper, lower, kBandColor);
  chart.Polyline(mean, kMeanColor);
  chart.Polyline(rms, kRmsColor, "stroke-dasharray=\"5,3\"");
  if (!IsDistance(c)) chart.Polyline(minus_rms, kRmsColor, "stroke-dasharray=\"5,3\"");
  if (predicted) {
    chart.Polyline(predicted_upper, kPredictedColor, "stroke-dasharray=\"1,2\"");
    if (!IsDistance(c))
      chart.Polyline(predicted_lower, kPredictedColor, "stroke-dasharray=\"1,2\"");
  }
  std::string caption = ComponentKey(Component(c));
  if (stride > 1) caption += fmt::format(" (every {}th epoch drawn)", stride);
  return Figure(chart.Finish(), caption);
}

// Histogram of `values` with the square-root rule for the bin count (at least 5, at most 40;
// Freedman & Diaconis would need quartiles for little gain in a report). `marks` are vertical
// lines (value, color).
std::string Histogram(const std::vector<double>& values, const std::string& x_label,
                      const std::string& caption, double width, double height,
                      const std::vector<std::pair<double, const char*>>& marks) {
  Range range;
  for (const double v : values) range.Add(v);
  for (const auto& mark : marks) range.Add(mark.first);
  if (range.hi - range.lo <= 0) {
    const double pad = range.lo != 0 ? std::abs(range.lo) * 0.1 : 1.0;
    range.lo -= pad;
    range.hi += pad;
  }
  const int bins = std::clamp(static_cast<int>(std::ceil(std::sqrt(values.size()))), 5, 40);
  const double bin_width = (range.hi - range.lo) / bins;
  std::vector<double> counts(bins, 0.0);
  for (const double v : values) {
    const int k = std::min(bins - 1, static_cast<int>((v - range.lo) / bin_width));
    counts[std::max(0, k)] += 1;
  }
  Range y;
  y.Add(0);
  y.Add(*std::max_element(counts.begin(), counts.end()));
  if (y.hi <= 0) y.hi = 1;
  Chart chart(width, height, range, y, x_label, "runs");
  for (int k = 0; k < bins; ++k) {
    if (counts[k] > 0) {
      chart.Bar(range.lo + k * bin_width, range.lo + (k + 1) * bin_width, counts[k], kBarColor);
    }
  }
  for (const auto& [x, color] : marks) chart.VerticalLine(x, color);
  return Figure(chart.Finish(), caption);
}

std::string ScatterPlot(const v1::Checkpoint& checkpoint) {
  constexpr int kNorth = v1::POSITION_NORTH_M - 1, kEast = v1::POSITION_EAST_M - 1;
  const int drawn = std::min(checkpoint.runs_size(), kMaxScatterPoints);
  double extent = checkpoint.cep95_m();
  for (int r = 0; r < drawn; ++r) {
    extent = std::max({extent, std::abs(checkpoint.runs(r).values(kNorth)),
                       std::abs(checkpoint.runs(r).values(kEast))});
  }
  if (!(extent > 0)) extent = 1;
  extent *= 1.05;
  // Equal scales: a square plot area over the same range on both axes.
  Range square;
  square.Add(-extent);
  square.Add(extent);
  // Plot area 420 x 420 px inside the margins (left 64, right 14, top 10, bottom 42).
  Chart chart(420 + 64 + 14, 420 + 10 + 42, square, square, "east error [m]", "north error [m]");
  chart.Raw("<g fill=\"#08519c\" fill-opacity=\"0.5\">");
  for (int r = 0; r < drawn; ++r) {
    chart.Dot(checkpoint.runs(r).values(kEast), checkpoint.runs(r).values(kNorth));
  }
  chart.Raw("</g>\n");
  chart.Circle(0, 0, checkpoint.cep50_m(), kCep50Color);
  chart.Circle(0, 0, checkpoint.cep95_m(), kCep95Color);
  std::string caption = fmt::format(
      "horizontal error at t = {} s, one dot per run; circles about the true position: CEP50 = "
      "{} m (green), CEP95 = {} m (orange)",
      Num(checkpoint.t_s()), Num(checkpoint.cep50_m()), Num(checkpoint.cep95_m()));
  if (drawn < checkpoint.runs_size()) {
    caption += fmt::format(" (first {} of {} runs drawn)", drawn, checkpoint.runs_size());
  }
  return Figure(chart.Finish(), caption);
}

std::string Interval(double low, double high) {
  return fmt::format("[{}, {}]", Num(low), Num(high));
}

std::string SummaryTable(const v1::JobResult& result) {
  const v1::EpochStatistics& epoch = *result.epochs().rbegin();
  const v1::Checkpoint& checkpoint = *result.checkpoints().rbegin();
  std::string out = fmt::format(
      "<table><caption>Final epoch, t = {} s, {} runs (95 % confidence intervals in "
      "brackets; percentiles of |error|)</caption>\n<tr><th>component</th><th>unit</th>"
      "<th>mean</th><th>&sigma;</th><th>&sigma; 95 % CI</th><th>RMS</th><th>RMS 95 % CI</th>"
      "<th>p50</th><th>p68</th><th>p95</th><th>p99</th><th>max</th></tr>\n",
      Num(epoch.t_s()), result.run_count());
  for (int c = 0; c < kErrorComponentCount; ++c) {
    const v1::ComponentStatistics& s = epoch.components(c);
    const v1::ComponentPercentiles& p = checkpoint.components(c);
    out += fmt::format(
        "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td>"
        "<td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
        ComponentKey(Component(c)), ComponentUnit(Component(c)), Num(s.mean()), Num(s.std()),
        Interval(s.std_ci95_low(), s.std_ci95_high()), Num(s.rms()),
        Interval(s.rms_ci95_low(), s.rms_ci95_high()), Num(p.p50()), Num(p.p68()), Num(p.p95()),
        Num(p.p99()), Num(p.max_abs()));
  }
  out += "</table>\n";
  out += fmt::format("<p>CEP50 = {} m, CEP95 = {} m, 2DRMS = {} m</p>\n", Num(checkpoint.cep50_m()),
                     Num(checkpoint.cep95_m()), Num(checkpoint.drms2_m()));
  return out;
}

std::string CheckpointTable(const v1::Checkpoint& checkpoint) {
  std::string out = fmt::format(
      "<table><caption>Checkpoint t = {} s: percentiles of |error|; CEP50 = {} m, CEP95 = {} m, "
      "2DRMS = {} m</caption>\n<tr><th>component</th><th>unit</th><th>p50</th><th>p68</th>"
      "<th>p95</th><th>p99</th><th>max</th></tr>\n",
      Num(checkpoint.t_s()), Num(checkpoint.cep50_m()), Num(checkpoint.cep95_m()),
      Num(checkpoint.drms2_m()));
  for (int c = 0; c < kErrorComponentCount; ++c) {
    const v1::ComponentPercentiles& p = checkpoint.components(c);
    out += fmt::format(
        "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
        ComponentKey(Component(c)), ComponentUnit(Component(c)), Num(p.p50()), Num(p.p68()),
        Num(p.p95()), Num(p.p99()), Num(p.max_abs()));
  }
  return out + "</table>\n";
}

std::string RunTable(const v1::JobResult& result) {
  const v1::Timings& t = result.timings();
  std::string rows = fmt::format(
      "<tr><th>engine version</th><td>{}</td></tr>\n<tr><th>seed</th><td>{}</td></tr>\n"
      "<tr><th>runs</th><td>{} (this file: runs {} to {})</td></tr>\n"
      "<tr><th>epochs</th><td>{} (final t = {} s)</td></tr>\n"
      "<tr><th>wall time</th><td>{} s</td></tr>\n",
      EscapeHtml(result.engine_version()), result.seed(), result.runs(), result.first_run(),
      uint64_t{result.first_run()} + result.run_count() - 1, result.epochs_size(),
      Num(result.epochs().rbegin()->t_s()), Num(t.wall_s()));
  if (t.has_cpu_s())
    rows += fmt::format("<tr><th>CPU time</th><td>{} s</td></tr>\n", Num(t.cpu_s()));
  rows += fmt::format(
      "<tr><th>IMU samples</th><td>{} ({} per second)</td></tr>\n"
      "<tr><th>threads</th><td>{}</td></tr>\n",
      t.samples(), Num(t.samples_per_s()), t.threads());
  return "<table class=\"facts\">\n" + rows + "</table>\n";
}

std::string JobJson(const v1::JobResult& result) {
  google::protobuf::util::JsonPrintOptions options;
  options.add_whitespace = true;
  options.preserve_proto_field_names = true;
  std::string json;
  if (!google::protobuf::util::MessageToJsonString(result.job(), &json, options).ok()) {
    json = result.job().DebugString();
  }
  return json;
}

}  // namespace

std::string EscapeHtml(std::string_view text) {
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
        out += "&#39;";
        break;
      default:
        out += ch;
    }
  }
  return out;
}

std::string RenderHtmlReport(const v1::JobResult& result) {
  const v1::Job& job = result.job();
  const std::string name = job.name().empty() ? "(unnamed job)" : job.name();
  std::string html =
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\"/>\n<title>driftlab: " +
      EscapeHtml(name) + "</title>\n" + kStyle + "</head>\n<body>\n";
  html += "<h1>driftlab Monte-Carlo report: " + EscapeHtml(name) + "</h1>\n";
  if (!job.description().empty()) html += "<p>" + EscapeHtml(job.description()) + "</p>\n";
  html += RunTable(result);
  html += ConsistencyBox(result);

  html += "<h2>Summary</h2>\n" + SummaryTable(result);
  for (int i = 0; i + 1 < result.checkpoints_size(); ++i) {
    html += CheckpointTable(result.checkpoints(i));
  }

  html += fmt::format(
      "<h2>Error envelopes</h2>\n<p>Against time, over the runs: <span class=\"key\" "
      "style=\"background:{}\"></span>mean &plusmn; &sigma; <span class=\"key\" "
      "style=\"background:{}\"></span>mean <span class=\"key\" style=\"background:{}\"></span>"
      "&plusmn;RMS (dashed; +RMS only for distances)</p>\n<div class=\"grid\">\n",
      kBandColor, kMeanColor, kRmsColor);
  if (HasPrediction(result)) {
    html += fmt::format(
        "<p>Dotted: the linear covariance analysis ({} filter, every {} IMU samples): mean "
        "&plusmn; predicted &sigma;, predicted RMS for the distances.{}</p>\n",
        EscapeHtml(result.covariance().filter()), result.covariance().step_samples(),
        result.covariance().unrepresented().empty()
            ? std::string()
            : " Terms of the model the prediction leaves out: " +
                  EscapeHtml(
                      fmt::format("{}", fmt::join(result.covariance().unrepresented(), ", "))) +
                  ".");
  }
  for (int c = 0; c < kErrorComponentCount; ++c) html += EnvelopePlot(result, c);
  html += "</div>\n";
  if (result.has_filter_consistency()) {
    html += "<h2>Filter consistency</h2>\n<div class=\"grid\">\n" + NeesPlot(result) + "</div>\n";
  }

  const v1::Checkpoint& final_checkpoint = *result.checkpoints().rbegin();
  html += "<h2>Final errors per run</h2>\n";
  if (final_checkpoint.runs().empty()) {
    html += "<p>This result keeps no per-run values; no scatter plot or histograms.</p>\n";
  } else {
    html += "<div class=\"grid\">\n" + ScatterPlot(final_checkpoint);
    std::vector<std::vector<double>> values(kErrorComponentCount);
    for (const v1::RunValues& run : final_checkpoint.runs()) {
      for (int c = 0; c < kErrorComponentCount; ++c) values[c].push_back(run.values(c));
    }
    constexpr int kHorizontal = v1::HORIZONTAL_POSITION_M - 1;
    html += Histogram(
        values[kHorizontal], ComponentLabel(kHorizontal),
        fmt::format("final horizontal error, {} runs; CEP50 (green), CEP95 (orange)",
                    values[kHorizontal].size()),
        440, 330,
        {{final_checkpoint.cep50_m(), kCep50Color}, {final_checkpoint.cep95_m(), kCep95Color}});
    html += "</div>\n<h2>Histograms of the final errors (signed)</h2>\n<div class=\"grid\">\n";
    for (int c = 0; c < kErrorComponentCount; ++c) {
      if (c == kHorizontal) continue;
      html += Histogram(values[c], ComponentLabel(c), ComponentKey(Component(c)), 330, 230, {});
    }
    html += "</div>\n";
  }

  html += "<h2>Job</h2>\n<pre>" + EscapeHtml(JobJson(result)) + "</pre>\n";
  html += "</body>\n</html>\n";
  return html;
}

}  // namespace driftlab::jobspec
