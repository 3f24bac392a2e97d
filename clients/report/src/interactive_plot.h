// Interactive plots for the self-contained HTML reports: the Monte-Carlo report
// (html_report.cc), the calibration and noise-fit reports (calibration_report.cc).
//
// Each plot is a <div> with a toolbar and a dygraphs chart (Debian's libjs-dygraphs 2.2, MIT
// licence, embedded at build time with report_plots.js, clients/report/embed_text.cmake): zoom by
// dragging, pan with shift-drag, reset by double-click; a data cursor (the legend line shows the
// values under the mouse); log/linear toggles per axis; one checkbox per series; PNG export.
// PlotLibrary() inlines the library once per report, so the page opens offline and loads nothing.
// Shaded x intervals (GNSS outages, ZUPTs, static intervals), circles (CEP), vertical lines,
// line segments (slope guides) and labelled markers (read-off points) are drawn under the series
// in data coordinates. Scatter plots carry a text per point shown on hover (the run index).
// Non-finite values are written as null (a gap).
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace driftlab::app::plot {

struct Series {
  std::string label;  // legend text, unique within the plot
  std::string color;  // CSS colour
  std::vector<double> y;
  // Optional band about y (dygraphs custom bars): empty, or the same length as y.
  std::vector<double> lo, hi;
  std::vector<double> dash;  // on/off pattern [px]; empty = solid
  double width = 1.5;
};

struct Shade {
  double x0, x1;
  std::string color;  // with alpha, e.g. rgba(255,0,0,0.12)
};

struct Circle {
  double cx, cy, r;
  std::string color;
};

struct VerticalLine {
  double x;
  std::string color;
};

struct Segment {  // straight in the axes' scale at draw time (guides on log-log axes)
  double x0, y0, x1, y1;
  std::string color, label;
};

struct Marker {
  double x, y;
  std::string color, label;
};

struct Plot {
  std::string name;  // unique in the report: element id "plot-NAME" (other characters than
                     // letters, digits, '-' and '_' become '_') and PNG file name
  std::string x_label, y_label;
  std::vector<double> x;  // ascending (dygraphs needs sorted x)
  std::vector<Series> series;
  bool log_x = false, log_y = false;
  bool points_only = false;         // scatter: points, no lines
  bool equal_axes = false;          // same units per pixel on both axes
  bool step = false, fill = false;  // histogram bars
  std::vector<std::string> info;    // per x: tooltip of the nearest point (scatter)
  std::vector<Shade> shades;
  std::vector<Circle> circles;
  std::vector<VerticalLine> vlines;
  std::vector<Segment> segments;
  std::vector<Marker> markers;
  std::pair<double, double> x_range{0, 0};  // shown x range when lo < hi (default: the data)
  std::pair<double, double> y_range{0, 0};
  int width_px = 520, height_px = 300;
};

// <style> and <script> elements: dygraphs, its style sheet and report_plots.js. Once per report,
// in <head>.
std::string PlotLibrary();

// <figure> holding the plot (div, toolbar, legend, chart script) and the escaped caption.
std::string Figure(const Plot& plot, const std::string& caption);

// JSON string literal of `text` with "<" written as \u003c (safe inside <script>).
std::string JsonString(const std::string& text);

}  // namespace driftlab::app::plot
