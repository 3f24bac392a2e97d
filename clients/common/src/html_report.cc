#include "driftlab/jobspec/html_report.h"

#include <fmt/format.h>
#include <google/protobuf/util/json_util.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "driftlab/jobspec/result_file.h"

namespace driftlab::jobspec {
namespace {

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

std::string Num(double value) { return fmt::format("{:.4g}", value); }

// Prints a coordinate in the SVG (0.01 px resolution).
std::string Px(double value) { return fmt::format("{:.2f}", value); }

// Heckbert's nice number: 1, 2, 5 or 10 times a power of ten near x (rounded or at least x).
double NiceNumber(double x, bool round) {
  const double exponent = std::floor(std::log10(x));
  const double power = std::pow(10.0, exponent);
  const double f = x / power;
  double nice = 10;
  if (round) {
    nice = f < 1.5 ? 1 : f < 3 ? 2 : f < 7 ? 5 : 10;
  } else {
    nice = f <= 1 ? 1 : f <= 2 ? 2 : f <= 5 ? 5 : 10;
  }
  return nice * power;
}

// A data range [lo, hi] with some room; degenerate ranges widened.
struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void Add(double v) {
    if (std::isfinite(v)) {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  bool Empty() const { return !(lo <= hi); }
};

// One chart: a plot area with nice-number axes, written as an inline <svg>.
class Chart {
 public:
  Chart(double width, double height, Range x, Range y, std::string x_label, std::string y_label)
      : width_(width), height_(height) {
    x_ticks_ = NiceTicks(x.lo, x.hi);
    y_ticks_ = NiceTicks(y.lo, y.hi);
    svg_ = fmt::format(
        "<svg class=\"chart\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\" "
        "role=\"img\">\n",
        width_, height_);
    Axes(x_label, y_label);
  }

  double X(double x) const {
    return kLeft + (x - x_ticks_.lo) / (x_ticks_.hi - x_ticks_.lo) * (width_ - kLeft - kRight);
  }
  double Y(double y) const {
    return height_ - kBottom -
           (y - y_ticks_.lo) / (y_ticks_.hi - y_ticks_.lo) * (height_ - kTop - kBottom);
  }
  double PixelsPerUnitX() const { return (width_ - kLeft - kRight) / (x_ticks_.hi - x_ticks_.lo); }

  void Polyline(const std::vector<std::pair<double, double>>& points, const char* color,
                const char* extra = "") {
    svg_ += "<polyline fill=\"none\" stroke-width=\"1.5\" stroke=\"";
    svg_ += color;
    svg_ += "\" ";
    svg_ += extra;
    svg_ += " points=\"";
    for (const auto& [x, y] : points) svg_ += Px(X(x)) + "," + Px(Y(y)) + " ";
    svg_ += "\"/>\n";
  }

  // A closed band between `upper` and `lower` (same x values).
  void Band(const std::vector<std::pair<double, double>>& upper,
            const std::vector<std::pair<double, double>>& lower, const char* color) {
    svg_ +=
        fmt::format("<polygon fill=\"{}\" fill-opacity=\"0.6\" stroke=\"none\" points=\"", color);
    for (const auto& [x, y] : upper) svg_ += Px(X(x)) + "," + Px(Y(y)) + " ";
    for (auto it = lower.rbegin(); it != lower.rend(); ++it) {
      svg_ += Px(X(it->first)) + "," + Px(Y(it->second)) + " ";
    }
    svg_ += "\"/>\n";
  }

  void Dot(double x, double y) {
    svg_ += fmt::format("<circle cx=\"{}\" cy=\"{}\" r=\"1.8\"/>", Px(X(x)), Px(Y(y)));
  }

  // Circle of radius r (x units) about (x, y); the chart must have equal scales.
  void Circle(double x, double y, double r, const char* color) {
    svg_ += fmt::format(
        "<circle cx=\"{}\" cy=\"{}\" r=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"2\"/>\n",
        Px(X(x)), Px(Y(y)), Px(r * PixelsPerUnitX()), color);
  }

  void Bar(double x0, double x1, double count) {
    svg_ += fmt::format(
        "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"{}\" stroke=\"white\" "
        "stroke-width=\"0.5\"/>",
        Px(X(x0)), Px(Y(count)), Px(std::max(0.0, X(x1) - X(x0))), Px(Y(0) - Y(count)), kBarColor);
  }

  void VerticalLine(double x, const char* color) {
    svg_ += fmt::format(
        "<line x1=\"{0}\" x2=\"{0}\" y1=\"{1}\" y2=\"{2}\" stroke=\"{3}\" stroke-width=\"2\"/>\n",
        Px(X(x)), Px(kTop), Px(height_ - kBottom), color);
  }

  void Raw(const std::string& text) { svg_ += text; }

  std::string Finish() { return svg_ + "</svg>\n"; }

 private:
  static constexpr double kLeft = 64, kRight = 14, kTop = 10, kBottom = 42;

  std::string TickText(const AxisTicks& ticks, double value) const {
    return fmt::format("{:.{}f}", value + 0.0, ticks.decimals);  // + 0.0: no "-0"
  }

  void Axes(const std::string& x_label, const std::string& y_label) {
    const double x0 = kLeft, x1 = width_ - kRight, y0 = height_ - kBottom, y1 = kTop;
    svg_ += "<g class=\"axes\">\n";
    for (const double v : x_ticks_.values) {
      const double x = X(v);
      svg_ += fmt::format(
          "<line class=\"grid\" x1=\"{0}\" x2=\"{0}\" y1=\"{1}\" y2=\"{2}\"/>"
          "<text x=\"{0}\" y=\"{3}\" text-anchor=\"middle\">{4}</text>\n",
          Px(x), Px(y0), Px(y1), Px(y0 + 14), TickText(x_ticks_, v));
    }
    for (const double v : y_ticks_.values) {
      const double y = Y(v);
      svg_ += fmt::format(
          "<line class=\"grid\" x1=\"{0}\" x2=\"{1}\" y1=\"{2}\" y2=\"{2}\"/>"
          "<text x=\"{3}\" y=\"{4}\" text-anchor=\"end\">{5}</text>\n",
          Px(x0), Px(x1), Px(y), Px(x0 - 4), Px(y + 4), TickText(y_ticks_, v));
    }
    svg_ += fmt::format(
        "<rect class=\"frame\" x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"/>\n"
        "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{}</text>\n"
        "<text transform=\"translate({},{}) rotate(-90)\" text-anchor=\"middle\">{}</text>\n",
        Px(x0), Px(y1), Px(x1 - x0), Px(y0 - y1), Px((x0 + x1) / 2), Px(height_ - 8),
        EscapeHtml(x_label), 14, Px((y0 + y1) / 2), EscapeHtml(y_label));
    svg_ += "</g>\n";
  }

  double width_, height_;
  AxisTicks x_ticks_, y_ticks_;
  std::string svg_;
};

std::string Figure(const std::string& svg, const std::string& caption) {
  return "<figure>" + svg + "<figcaption>" + EscapeHtml(caption) + "</figcaption></figure>\n";
}

std::string EnvelopePlot(const v1::JobResult& result, int c) {
  const int n = result.epochs_size();
  const int stride = (n + kMaxDrawnEpochs - 1) / kMaxDrawnEpochs;
  std::vector<std::pair<double, double>> mean, upper, lower, rms, minus_rms;
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
  }
  Chart chart(330, 230, x, y, "t [s]", ComponentLabel(c));
  chart.Band(upper, lower, kBandColor);
  chart.Polyline(mean, kMeanColor);
  chart.Polyline(rms, kRmsColor, "stroke-dasharray=\"5,3\"");
  if (!IsDistance(c)) chart.Polyline(minus_rms, kRmsColor, "stroke-dasharray=\"5,3\"");
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
      chart.Bar(range.lo + k * bin_width, range.lo + (k + 1) * bin_width, counts[k]);
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

constexpr const char* kStyle = R"(<style>
body { font-family: sans-serif; margin: 1.5em; color: #222; }
h1 { font-size: 1.5em; } h2 { font-size: 1.2em; margin-top: 1.6em; }
.grid { display: flex; flex-wrap: wrap; gap: 0.5em; }
figure { margin: 0.3em; } figcaption { font-size: 0.85em; max-width: 520px; }
svg.chart { font-size: 11px; }
svg.chart text { fill: #222; }
svg.chart line.grid { stroke: #ddd; stroke-width: 1; }
svg.chart rect.frame { fill: none; stroke: #555; stroke-width: 1; }
table { border-collapse: collapse; margin: 0.8em 0; font-size: 0.9em; }
th, td { border: 1px solid #bbb; padding: 0.2em 0.5em; text-align: right; }
th:first-child, td:first-child { text-align: left; }
caption { text-align: left; font-weight: bold; padding: 0.3em 0; }
pre { background: #f4f4f4; padding: 0.8em; overflow-x: auto; font-size: 0.85em; }
.key { display: inline-block; width: 2em; height: 0.6em; margin: 0 0.3em 0 1em; }
</style>
)";

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

AxisTicks NiceTicks(double lo, double hi, int target) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) lo = hi = 0;
  if (lo > hi) std::swap(lo, hi);
  if (hi - lo <= std::abs(hi) * 1e-12) {  // one value: give it a range around itself
    const double pad = hi != 0 ? std::abs(hi) * 0.1 : 1.0;
    lo -= pad;
    hi += pad;
  }
  target = std::max(target, 2);
  AxisTicks ticks;
  const double range = NiceNumber(hi - lo, false);
  ticks.step = NiceNumber(range / (target - 1), true);
  const double first = std::floor(lo / ticks.step);
  const double last = std::ceil(hi / ticks.step);
  ticks.lo = first * ticks.step;
  ticks.hi = last * ticks.step;
  ticks.decimals = std::max(0, -static_cast<int>(std::floor(std::log10(ticks.step))));
  for (double k = first; k <= last; k += 1) ticks.values.push_back(k * ticks.step);
  return ticks;
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
  for (int c = 0; c < kErrorComponentCount; ++c) html += EnvelopePlot(result, c);
  html += "</div>\n";

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
