// Inline-SVG charts for the self-contained HTML reports (html_report.cc: Monte-Carlo result;
// calibration_report.cc: calibration and Allan noise fit). No script, no external resource.
//
// A Chart is a plot area with grid lines, tick labels, a frame and axis labels, drawn in pixels;
// data are mapped through linear axes at "nice" ticks (NiceTicks, Heckbert 1990) or logarithmic
// axes with ticks at the decades (log10 mapping; the Allan-deviation plots, IEEE Std 952-1997
// Annex C draws sigma(tau) on log-log axes). Coordinates are printed at 0.01 px.
#pragma once

#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "driftlab/jobspec/html_report.h"

namespace driftlab::jobspec::svg {

using Points = std::vector<std::pair<double, double>>;

// "{:.4g}" of a value (tables, captions).
std::string Num(double value);

// A coordinate in the SVG (0.01 px resolution).
std::string Px(double value);

// A data range [lo, hi] of the finite values added.
struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void Add(double v);
  bool Empty() const { return !(lo <= hi); }
};

enum class Scale { kLinear, kLog10 };

// One entry of a legend: a line sample in `color` (dash pattern `dash`, "" = solid) and a label.
struct LegendEntry {
  std::string color;
  std::string dash;
  std::string label;
};

class Chart {
 public:
  // Linear axes over x and y. For kLog10 only the positive values of the range count; an empty or
  // non-positive range becomes [1, 10].
  Chart(double width, double height, Range x, Range y, std::string x_label, std::string y_label,
        Scale x_scale = Scale::kLinear, Scale y_scale = Scale::kLinear);

  double X(double x) const;  // data -> pixel
  double Y(double y) const;
  double PixelsPerUnitX() const;  // linear x only

  // Open polyline through the points (non-finite or, on a log axis, non-positive points skipped).
  void Polyline(const Points& points, const char* color, const char* extra = "");
  // Closed band between `upper` and `lower` (same x values).
  void Band(const Points& upper, const Points& lower, const char* color);
  void Dot(double x, double y);
  // Dot of radius 2.5 px in `color` with a <title> tooltip.
  void Marker(double x, double y, const char* color, const std::string& title);
  // Circle of radius r (x units) about (x, y); the chart must have equal linear scales.
  void Circle(double x, double y, double r, const char* color);
  void Bar(double x0, double x1, double count, const char* color);
  void VerticalLine(double x, const char* color);
  void HorizontalLine(double y, const char* color, const char* extra = "");
  // Vertical error bar from y_lo to y_hi at x with 6 px caps (class "errorbar").
  void ErrorBar(double x, double y_lo, double y_hi, const char* color);
  // Legend box in the plot area's top-right corner.
  void Legend(const std::vector<LegendEntry>& entries);
  void Raw(const std::string& text);

  std::string Finish();

 private:
  static constexpr double kLeft = 64, kRight = 14, kTop = 10, kBottom = 42;

  struct Axis {
    Scale scale = Scale::kLinear;
    AxisTicks ticks;             // for kLog10: lo, hi, values in log10 units
    double Map(double v) const;  // value -> axis units (v or log10 v)
    std::string Label(double tick) const;
  };
  static Axis MakeAxis(Range range, Scale scale);
  bool Drawable(double x, double y) const;
  void Axes(const std::string& x_label, const std::string& y_label);

  double width_, height_;
  Axis x_, y_;
  std::string svg_;
};

// The reports' style sheet (a <style> element).
inline constexpr const char* kStyle = R"(<style>
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

// <figure> with the chart and an escaped caption.
std::string Figure(const std::string& svg, const std::string& caption);

}  // namespace driftlab::jobspec::svg
