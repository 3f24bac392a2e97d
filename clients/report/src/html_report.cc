#include "driftlab/report/html_report.h"

#include <fmt/format.h>
#include <google/protobuf/util/json_util.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include "driftlab/app/consistency_check.h"
#include "driftlab/app/result_file.h"
#include "driftlab/app/sensor_model.h"
#include "driftlab/app/translate.h"
#include "driftlab/earth.h"
#include "driftlab/trajectory.h"
#include "driftlab/units.h"
#include "interactive_plot.h"
#include "report_scenario.h"
#include "report_style.h"
#include "svg_plot.h"

namespace driftlab::app {
namespace {

using svg::kStyle;
using svg::Num;

constexpr const char* kReportStyle = R"(<style>
.headline { display: flex; flex-wrap: wrap; gap: 1.5em; align-items: flex-start; }
.headline > div { flex: 1 1 460px; max-width: 660px; min-width: 0; }
.setup td { max-width: 420px; }
.answer { border: 2px solid #08519c; padding: 6px 12px; margin: 8px 0; }
.answer .big { font-size: 1.15em; font-weight: bold; }
table.facts th { text-align: left; font-weight: normal; color: #555; }
table.facts td { text-align: left; }
td.num { font-family: monospace; }
details { margin: 1em 0; } summary { cursor: pointer; font-weight: bold; }
</style>
)";

v1::ErrorComponent Component(int c) { return static_cast<v1::ErrorComponent>(c + 1); }

constexpr const char* kComponentNames[kErrorComponentCount] = {"north position",
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

// "north position error [m]" for axis labels and headings.
std::string ComponentLabel(int c) {
  return fmt::format("{} error [{}]", kComponentNames[c], ComponentUnit(Component(c)));
}

bool IsDistance(int c) { return c + 1 >= v1::HORIZONTAL_POSITION_M; }

// One number format per table row (never "6437" beside "1.32e+04"): fixed notation with the
// decimals that give the row's largest magnitude 4 significant digits (0 decimals from 1000 up).
class RowFormat {
 public:
  explicit RowFormat(std::initializer_list<double> values) {
    double largest = 0;
    for (const double v : values) {
      if (std::isfinite(v)) largest = std::max(largest, std::abs(v));
    }
    decimals_ =
        largest > 0 ? std::clamp(3 - static_cast<int>(std::floor(std::log10(largest))), 0, 9) : 0;
  }
  std::string operator()(double v) const {
    if (!std::isfinite(v)) return "-";
    return fmt::format("{:.{}f}", v + 0.0, decimals_);
  }

 private:
  int decimals_ = 0;
};

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

// Distribution-free 95 % interval of the p-quantile from the order statistics of n values:
// ranks np -+ 1.96 sqrt(n p (1 - p)) (normal approximation of the binomial; Conover, Practical
// Nonparametric Statistics, 3rd ed., section 3.2).
std::pair<double, double> QuantileInterval(std::vector<double> values, double p) {
  const double n = static_cast<double>(values.size());
  if (values.size() < 10) return {NAN, NAN};
  std::sort(values.begin(), values.end());
  const double half = 1.96 * std::sqrt(n * p * (1 - p));
  const auto at = [&](double rank) {
    const auto k = static_cast<size_t>(std::clamp(rank, 1.0, n));
    return values[k - 1];
  };
  return {at(std::floor(n * p - half)), at(std::ceil(n * p + half))};
}

std::string HeadlineBox(const v1::JobResult& result) {
  const v1::Checkpoint& checkpoint = *result.checkpoints().rbegin();
  const v1::EpochStatistics& epoch = *result.epochs().rbegin();
  constexpr int kHorizontal = v1::HORIZONTAL_POSITION_M - 1;
  std::vector<double> horizontal;
  for (const v1::RunValues& run : checkpoint.runs()) horizontal.push_back(run.values(kHorizontal));
  const auto cep = [&](double value, double p) {
    const auto [lo, hi] = QuantileInterval(horizontal, p);
    return std::isfinite(lo)
               ? fmt::format("{} m <small>(95 %: {} - {})</small>", Num(value), Num(lo), Num(hi))
               : fmt::format("{} m", Num(value));
  };
  std::string html = fmt::format(
      "<div class=\"answer\"><div class=\"big\">After {} s: CEP50 {}, CEP95 {}</div>\n",
      Num(epoch.t_s()), cep(checkpoint.cep50_m(), 0.5), cep(checkpoint.cep95_m(), 0.95));
  // Final sigma over the runs with its 95 % interval, a 3 x 3 block: position, velocity and
  // attitude by axis (north/east/down; roll/pitch/yaw).
  html +=
      "<table><tr><th>final &sigma; (95 % interval)</th><th>north / roll</th>"
      "<th>east / pitch</th><th>down / yaw</th></tr>\n";
  constexpr const char* kGroups[3] = {"position", "velocity", "attitude"};
  for (int g = 0; g < 3; ++g) {
    html += fmt::format("<tr><td>{} [{}]</td>", kGroups[g], ComponentUnit(Component(3 * g)));
    for (int axis = 0; axis < 3; ++axis) {
      const v1::ComponentStatistics& s = epoch.components(3 * g + axis);
      const RowFormat f{s.std(), s.std_ci95_low(), s.std_ci95_high()};
      html += fmt::format("<td class=\"num\">{} <small>[{}, {}]</small></td>", f(s.std()),
                          f(s.std_ci95_low()), f(s.std_ci95_high()));
    }
    html += "</tr>\n";
  }
  html += fmt::format(
      "</table><small>{} runs; CEP intervals from the order statistics of the "
      "runs' horizontal errors</small></div>\n",
      result.run_count());
  return html;
}

// Average NEES of the filter per epoch against its chi-square 95 % bounds (epochs with runs).
std::string NeesPlot(const v1::JobResult& result, const Scenario& scenario) {
  const v1::FilterConsistency& fc = result.filter_consistency();
  plot::Plot p;
  p.name = "nees";
  p.x_label = "time [s]";
  p.y_label = "average NEES";
  p.log_y = true;  // an average NEES far above its band would flatten the band on a linear axis
  p.width_px = 640;
  p.shades = Shades(scenario);
  plot::Series nees{"average NEES", kMeanColor, {}, {}, {}, {}, 1.5};
  plot::Series band{"chi-square 95 % band", kBandColor, {}, {}, {}, {}, 0.5};
  const int n = fc.epochs_size();
  const int stride = (n + kMaxDrawnEpochs - 1) / kMaxDrawnEpochs;
  for (int i = 0; i < n; ++i) {
    const v1::NeesEpoch& e = fc.epochs(i);
    if ((i % stride != 0 && i != n - 1) || e.runs() == 0) continue;
    p.x.push_back(e.t_s());
    nees.y.push_back(e.average_nees());
    const double mid = std::sqrt(e.chi2_95_low() * e.chi2_95_high());
    band.y.push_back(mid);
    band.lo.push_back(e.chi2_95_low());
    band.hi.push_back(e.chi2_95_high());
  }
  if (p.x.empty()) return "";
  nees.lo = nees.y;
  nees.hi = nees.y;
  p.series = {band, nees};
  return plot::Figure(
      p, fmt::format("average NEES of the {} navigation error states over the runs, with its "
                     "chi-square 95 % band (mean over epochs {})",
                     fc.state_dimension(), Num(fc.mean_average_nees())));
}

// The consistency verdict on the first screen: whether the Monte-Carlo spread agrees
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
    html +=
        "<table><tr><th>component</th><th>MC &sigma; / predicted &sigma;</th><th>interval "
        "(Bonferroni)</th><th></th></tr>\n";
    for (const ComponentConsistency& c : v.components) {
      html += fmt::format(
          "<tr><td>{}</td><td class=\"num\">{:.3f}</td><td class=\"num\">[{:.3f}, "
          "{:.3f}]</td><td>{}</td></tr>\n",
          ConsistencyComponentName(c.component), c.ratio.ratio, c.ratio.low, c.ratio.high,
          c.flagged ? "&#9888; outside" : "ok");
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

std::string EnvelopePlot(const v1::JobResult& result, int c, const Scenario& scenario) {
  const int n = result.epochs_size();
  const int stride = (n + kMaxDrawnEpochs - 1) / kMaxDrawnEpochs;
  const bool predicted = HasPrediction(result);
  plot::Plot p;
  p.name = "envelope-" + ComponentKey(Component(c));
  p.x_label = "time [s]";
  p.y_label = ComponentLabel(c);
  p.width_px = 440;
  p.height_px = 260;
  p.shades = Shades(scenario);
  plot::Series band{"mean ± σ", kMeanColor, {}, {}, {}, {}, 1.5};
  plot::Series rms{"RMS", kRmsColor, {}, {}, {}, {5, 3}, 1.5};
  plot::Series minus_rms{"−RMS", kRmsColor, {}, {}, {}, {5, 3}, 1.5};
  plot::Series pred_hi{IsDistance(c) ? "predicted RMS" : "mean + predicted σ",
                       kPredictedColor,
                       {},
                       {},
                       {},
                       {1, 2},
                       1.5};
  plot::Series pred_lo{"mean − predicted σ", kPredictedColor, {}, {}, {}, {1, 2}, 1.5};
  for (int i = 0; i < n; ++i) {
    if (i % stride != 0 && i != n - 1) continue;
    const double t = result.epochs(i).t_s();
    const v1::ComponentStatistics& s = result.epochs(i).components(c);
    const double std = std::isnan(s.std()) ? 0.0 : s.std();  // one run: no band
    p.x.push_back(t);
    band.y.push_back(s.mean());
    band.lo.push_back(s.mean() - std);
    band.hi.push_back(s.mean() + std);
    rms.y.push_back(s.rms());
    minus_rms.y.push_back(-s.rms());
    if (predicted) {
      // Linear covariance analysis: sigma about the Monte-Carlo mean for components 1-9 (to
      // compare with the band), the predicted RMS for the distances (to compare with +RMS).
      const double sigma = result.covariance().epochs(i).sigma(c);
      pred_hi.y.push_back(IsDistance(c) ? sigma : s.mean() + sigma);
      pred_lo.y.push_back(s.mean() - sigma);
    }
  }
  p.series.push_back(band);
  p.series.push_back(rms);
  if (!IsDistance(c)) p.series.push_back(minus_rms);
  if (predicted) {
    p.series.push_back(pred_hi);
    if (!IsDistance(c)) p.series.push_back(pred_lo);
  }
  std::string caption = kComponentNames[c];
  if (stride > 1) caption += fmt::format(" (every {}th epoch drawn)", stride);
  return plot::Figure(p, caption);
}

// Histogram of `values` with the square-root rule for the bin count (at least 5, at most 40;
// Freedman & Diaconis would need quartiles for little gain in a report). `marks` are vertical
// lines (value, color).
std::string Histogram(const std::string& name, const std::vector<double>& values,
                      const std::string& x_label, const std::string& caption, int width, int height,
                      const std::vector<std::pair<double, const char*>>& marks) {
  double lo = INFINITY, hi = -INFINITY;
  for (const double v : values) {
    if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
  }
  for (const auto& mark : marks) lo = std::min(lo, mark.first), hi = std::max(hi, mark.first);
  if (!(lo <= hi)) lo = hi = 0;
  if (hi - lo <= 0) {
    const double pad = lo != 0 ? std::abs(lo) * 0.1 : 1.0;
    lo -= pad;
    hi += pad;
  }
  const int bins = std::clamp(static_cast<int>(std::ceil(std::sqrt(values.size()))), 5, 40);
  const double bin_width = (hi - lo) / bins;
  std::vector<double> counts(bins + 1, 0.0);  // the last entry closes the step plot
  for (const double v : values) {
    if (!std::isfinite(v)) continue;
    const int k = std::min(bins - 1, static_cast<int>((v - lo) / bin_width));
    counts[std::max(0, k)] += 1;
  }
  counts[bins] = counts[bins - 1];
  plot::Plot p;
  p.name = name;
  p.x_label = x_label;
  p.y_label = "runs";
  p.step = true;
  p.fill = true;
  p.width_px = width;
  p.height_px = height;
  for (int k = 0; k <= bins; ++k) p.x.push_back(lo + k * bin_width);
  p.series.push_back({"runs", kBarColor, counts, {}, {}, {}, 1.0});
  p.y_range = {0, *std::max_element(counts.begin(), counts.end()) * 1.08 + 0.5};
  for (const auto& [x, color] : marks) p.vlines.push_back({x, color});
  return plot::Figure(p, caption);
}

std::string ScatterPlot(const v1::Checkpoint& checkpoint) {
  constexpr int kNorth = v1::POSITION_NORTH_M - 1, kEast = v1::POSITION_EAST_M - 1;
  const int drawn = std::min(checkpoint.runs_size(), kMaxScatterPoints);
  std::vector<int> order(drawn);
  for (int r = 0; r < drawn; ++r) order[r] = r;
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return checkpoint.runs(a).values(kEast) < checkpoint.runs(b).values(kEast);
  });
  plot::Plot p;
  p.name = "scatter";
  p.x_label = "east error [m]";
  p.y_label = "north error [m]";
  p.points_only = true;
  p.equal_axes = true;
  p.width_px = 470;
  p.height_px = 420;
  plot::Series runs{"run", kMeanColor, {}, {}, {}, {}, 1.5};
  double extent = checkpoint.cep95_m();
  for (const int r : order) {
    const v1::RunValues& run = checkpoint.runs(r);
    p.x.push_back(run.values(kEast));
    runs.y.push_back(run.values(kNorth));
    extent = std::max({extent, std::abs(run.values(kEast)), std::abs(run.values(kNorth))});
    p.info.push_back(
        fmt::format("run {0}: east {1} m, north {2} m, horizontal {3} m\n"
                    "driftlab simulate job.json --run {0} --out run-{0}",
                    run.run_index(), Num(run.values(kEast)), Num(run.values(kNorth)),
                    Num(run.values(v1::HORIZONTAL_POSITION_M - 1))));
  }
  if (!(extent > 0)) extent = 1;
  extent *= 1.05;
  p.x_range = {-extent, extent};
  p.y_range = {-extent, extent};
  p.series.push_back(runs);
  p.circles.push_back({0, 0, checkpoint.cep50_m(), kCep50Color});
  p.circles.push_back({0, 0, checkpoint.cep95_m(), kCep95Color});
  std::string caption = fmt::format(
      "horizontal error at t = {} s, one dot per run (hover: its run index and the command that "
      "regenerates it, job.json being the job echo at the end of this report); circles about the "
      "true position: CEP50 = {} m (green), CEP95 = {} m "
      "(orange)",
      Num(checkpoint.t_s()), Num(checkpoint.cep50_m()), Num(checkpoint.cep95_m()));
  if (drawn < checkpoint.runs_size()) {
    caption += fmt::format(" (first {} of {} runs drawn)", drawn, checkpoint.runs_size());
  }
  return plot::Figure(p, caption);
}

std::string SummaryTable(const v1::JobResult& result) {
  const v1::EpochStatistics& epoch = *result.epochs().rbegin();
  const v1::Checkpoint& checkpoint = *result.checkpoints().rbegin();
  // The covariance analysis' prediction at the same epoch, when the result has one:
  // sigma for the 9 components, RMS for the two distances.
  const v1::PredictedEpoch* predicted = nullptr;
  if (result.has_covariance() && result.covariance().epochs_size() > 0) {
    const v1::PredictedEpoch& last = *result.covariance().epochs().rbegin();
    if (last.t_s() == epoch.t_s() && last.sigma_size() >= kErrorComponentCount) predicted = &last;
  }
  std::string out = fmt::format(
      "<table><caption>Final epoch, t = {} s, {} runs (95 % confidence intervals in "
      "brackets; percentiles of |error|; each row in one fixed format{})</caption>\n<tr>"
      "<th>component</th><th>unit</th><th>mean</th><th>&sigma;</th><th>&sigma; 95 % CI</th>{}"
      "<th>RMS</th><th>RMS 95 % CI</th><th>p50</th><th>p68</th><th>p95</th><th>p99</th>"
      "<th>max</th></tr>\n",
      Num(epoch.t_s()), result.run_count(),
      predicted ? "; predicted: the covariance analysis' sigma, its RMS for the distances" : "",
      predicted ? "<th>predicted &sigma;</th>" : "");
  for (int c = 0; c < kErrorComponentCount; ++c) {
    const v1::ComponentStatistics& s = epoch.components(c);
    const v1::ComponentPercentiles& p = checkpoint.components(c);
    const RowFormat f{s.mean(),          s.std(),           s.rms(),
                      s.rms_ci95_high(), s.std_ci95_high(), p.max_abs()};
    const std::string predicted_cell =
        predicted ? fmt::format("<td class=\"num\">{}</td>", f(predicted->sigma(c))) : "";
    out += fmt::format(
        "<tr><td>{}</td><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>"
        "<td class=\"num\">[{}, {}]</td>{}<td class=\"num\">{}</td><td class=\"num\">[{}, {}]</td>"
        "<td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>"
        "<td class=\"num\">{}</td><td class=\"num\">{}</td></tr>\n",
        kComponentNames[c], ComponentUnit(Component(c)), f(s.mean()), f(s.std()),
        f(s.std_ci95_low()), f(s.std_ci95_high()), predicted_cell, f(s.rms()), f(s.rms_ci95_low()),
        f(s.rms_ci95_high()), f(p.p50()), f(p.p68()), f(p.p95()), f(p.p99()), f(p.max_abs()));
  }
  out += "</table>\n";
  const RowFormat f{checkpoint.cep50_m(), checkpoint.cep95_m(), checkpoint.drms2_m()};
  out += fmt::format("<p>CEP50 = {} m, CEP95 = {} m, 2DRMS = {} m</p>\n", f(checkpoint.cep50_m()),
                     f(checkpoint.cep95_m()), f(checkpoint.drms2_m()));
  return out;
}

std::string CheckpointTable(const v1::Checkpoint& checkpoint) {
  const RowFormat cf{checkpoint.cep50_m(), checkpoint.cep95_m(), checkpoint.drms2_m()};
  std::string out = fmt::format(
      "<table><caption>Checkpoint t = {} s: percentiles of |error|; CEP50 = {} m, CEP95 = {} m, "
      "2DRMS = {} m</caption>\n<tr><th>component</th><th>unit</th><th>p50</th><th>p68</th>"
      "<th>p95</th><th>p99</th><th>max</th></tr>\n",
      Num(checkpoint.t_s()), cf(checkpoint.cep50_m()), cf(checkpoint.cep95_m()),
      cf(checkpoint.drms2_m()));
  for (int c = 0; c < kErrorComponentCount; ++c) {
    const v1::ComponentPercentiles& p = checkpoint.components(c);
    const RowFormat f{p.p50(), p.max_abs()};
    out += fmt::format(
        "<tr><td>{}</td><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>"
        "<td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td></tr>\n",
        kComponentNames[c], ComponentUnit(Component(c)), f(p.p50()), f(p.p68()), f(p.p95()),
        f(p.p99()), f(p.max_abs()));
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
      EscapeHtml(name) + "</title>\n" + kStyle + kReportStyle + plot::PlotLibrary() +
      "</head>\n<body>\n";
  html += "<h1>driftlab Monte-Carlo report: " + EscapeHtml(name) + "</h1>\n";
  if (!job.description().empty()) html += "<p>" + EscapeHtml(job.description()) + "</p>\n";
  const Scenario scenario = RegenerateScenario(result);
  html += "<div class=\"headline\">\n<div class=\"setup\">" + HeadlineBox(result) +
          SetupTable(result, scenario) + "</div>\n<div>" + TrajectoryPlot(scenario) +
          ConsistencyBox(result) + "</div>\n</div>\n";

  html += "<h2>Summary</h2>\n" + SummaryTable(result);
  if (result.checkpoints_size() > 1) {
    html += fmt::format("<details><summary>Percentiles at the {} earlier checkpoints</summary>\n",
                        result.checkpoints_size() - 1);
    for (int i = 0; i + 1 < result.checkpoints_size(); ++i) {
      html += CheckpointTable(result.checkpoints(i));
    }
    html += "</details>\n";
  }

  html += fmt::format(
      "<h2>Error envelopes</h2>\n<p>Against time, over the runs: <span class=\"key\" "
      "style=\"background:{}\"></span>mean &plusmn; &sigma; (band) <span class=\"key\" "
      "style=\"background:{}\"></span>&plusmn;RMS (dashed; +RMS only for distances) {}</p>\n",
      kBandColor, kRmsColor, ShadeKey(scenario));
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
  html += "<div class=\"grid\">\n";
  for (int c = 0; c < kErrorComponentCount; ++c) html += EnvelopePlot(result, c, scenario);
  html += "</div>\n";
  if (result.has_filter_consistency()) {
    html += "<h2>Filter consistency</h2>\n<div class=\"grid\">\n" + NeesPlot(result, scenario) +
            "</div>\n";
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
        "histogram-horizontal", values[kHorizontal], ComponentLabel(kHorizontal),
        fmt::format("final horizontal error, {} runs; CEP50 (green), CEP95 (orange)",
                    values[kHorizontal].size()),
        440, 330,
        {{final_checkpoint.cep50_m(), kCep50Color}, {final_checkpoint.cep95_m(), kCep95Color}});
    html += "</div>\n<h2>Histograms of the final errors (signed)</h2>\n<div class=\"grid\">\n";
    for (int c = 0; c < kErrorComponentCount; ++c) {
      if (c == kHorizontal) continue;
      html += Histogram("histogram-" + ComponentKey(Component(c)), values[c], ComponentLabel(c),
                        kComponentNames[c], 330, 230, {});
    }
    html += "</div>\n";
  }

  html += "<h2>Run</h2>\n" + RunTable(result);
  html += "<details><summary>Job as run (JSON)</summary>\n<pre>" + EscapeHtml(JobJson(result)) +
          "</pre></details>\n";
  html += "</body>\n</html>\n";
  return html;
}

}  // namespace driftlab::app
