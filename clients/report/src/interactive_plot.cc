#include "interactive_plot.h"

#include <fmt/format.h>

#include <cctype>
#include <cmath>

#include "driftlab/report/html_report.h"

namespace driftlab::app {
namespace embedded {
extern const char kDygraphsJs[];
extern const char kDygraphsCss[];
extern const char kReportPlotsJs[];
}  // namespace embedded

namespace plot {
namespace {

constexpr const char* kPlotStyle = R"(
.dl-plot { display: inline-block; vertical-align: top; }
.dl-toolbar { font-size: 11px; margin: 2px 0; }
.dl-toolbar label { margin-right: 0.7em; white-space: nowrap; }
.dl-toolbar button { font-size: 11px; margin-right: 0.4em; }
.dl-legend { font-size: 11px; min-height: 1.3em; }
.dl-graph { position: relative; }
.dl-graph .dygraph-axis-label { font-size: 11px; }
.dl-graph .dygraph-label { font-size: 12px; }
.dl-tip { position: absolute; display: none; z-index: 20; background: #fff; border: 1px solid #888;
  padding: 3px 6px; font: 11px monospace; white-space: pre; pointer-events: none; }
@media print { .dl-toolbar { display: none; } }
)";

// Shortest round-trip text of a double ("null" for NaN/inf).
std::string Number(double v) {
  if (!std::isfinite(v)) return "null";
  return fmt::format("{}", v);
}

std::string NumberArray(const std::vector<double>& values) {
  std::string out = "[";
  for (size_t i = 0; i < values.size(); ++i) out += (i ? "," : "") + Number(values[i]);
  return out + "]";
}

std::string Data(const Plot& p) {
  bool bars = false;
  for (const Series& s : p.series) bars |= !s.lo.empty();
  std::string out = "[";
  for (size_t i = 0; i < p.x.size(); ++i) {
    out += (i ? ",[" : "[") + Number(p.x[i]);
    for (const Series& s : p.series) {
      const double y = i < s.y.size() ? s.y[i] : NAN;
      if (!bars) {
        out += "," + Number(y);
      } else if (!std::isfinite(y)) {
        out += ",null";
      } else {
        const double lo = s.lo.empty() ? y : s.lo[i], hi = s.hi.empty() ? y : s.hi[i];
        out += ",[" + Number(lo) + "," + Number(y) + "," + Number(hi) + "]";
      }
    }
    out += "]";
  }
  return out + "]";
}

std::string Spec(const Plot& p) {
  bool bars = false;
  for (const Series& s : p.series) bars |= !s.lo.empty();
  std::string labels = "[" + JsonString(p.x_label), colors = "[", dashes = "{", widths = "{";
  for (size_t k = 0; k < p.series.size(); ++k) {
    const Series& s = p.series[k];
    labels += "," + JsonString(s.label);
    colors += (k ? "," : "") + JsonString(s.color);
    if (!s.dash.empty()) {
      dashes += (dashes.size() > 1 ? "," : "") + JsonString(s.label) + ":" + NumberArray(s.dash);
    }
    widths += (k ? "," : "") + JsonString(s.label) + ":" + Number(s.width);
  }
  std::string out = fmt::format(
      "{{\"name\":{},\"labels\":{}],\"colors\":{}],\"dashes\":{}}},\"widths\":{}}},"
      "\"xlabel\":{},\"ylabel\":{},\"logx\":{},\"logy\":{},\"bars\":{},\"points_only\":{},"
      "\"equal_axes\":{},\"step\":{},\"fill\":{},\"data\":{}",
      JsonString(p.name), labels, colors, dashes, widths, JsonString(p.x_label),
      JsonString(p.y_label), p.log_x, p.log_y, bars, p.points_only, p.equal_axes, p.step, p.fill,
      Data(p));
  if (p.x_range.first < p.x_range.second) {
    out += ",\"xrange\":" + NumberArray({p.x_range.first, p.x_range.second});
  }
  if (p.y_range.first < p.y_range.second) {
    out += ",\"yrange\":" + NumberArray({p.y_range.first, p.y_range.second});
  }
  if (!p.info.empty()) {
    out += ",\"info\":[";
    for (size_t i = 0; i < p.info.size(); ++i) out += (i ? "," : "") + JsonString(p.info[i]);
    out += "]";
  }
  const auto list = [&out](const char* key, const std::vector<std::string>& items) {
    if (items.empty()) return;
    out += fmt::format(",\"{}\":[{}]", key, fmt::join(items, ","));
  };
  std::vector<std::string> items;
  for (const Shade& s : p.shades) {
    items.push_back(fmt::format("[{},{},{}]", Number(s.x0), Number(s.x1), JsonString(s.color)));
  }
  list("shades", items);
  items.clear();
  for (const Circle& c : p.circles) {
    items.push_back(
        fmt::format("[{},{},{},{}]", Number(c.cx), Number(c.cy), Number(c.r), JsonString(c.color)));
  }
  list("circles", items);
  items.clear();
  for (const VerticalLine& v : p.vlines) {
    items.push_back(fmt::format("[{},{}]", Number(v.x), JsonString(v.color)));
  }
  list("vlines", items);
  items.clear();
  for (const Segment& s : p.segments) {
    items.push_back(fmt::format("[{},{},{},{},{},{}]", Number(s.x0), Number(s.y0), Number(s.x1),
                                Number(s.y1), JsonString(s.color), JsonString(s.label)));
  }
  list("segments", items);
  items.clear();
  for (const Marker& m : p.markers) {
    items.push_back(fmt::format("[{},{},{},{}]", Number(m.x), Number(m.y), JsonString(m.color),
                                JsonString(m.label)));
  }
  list("markers", items);
  return out + "}";
}

}  // namespace

std::string JsonString(const std::string& text) {
  std::string out = "\"";
  for (const char ch : text) {
    switch (ch) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '<':
        out += "\\u003c";
        break;
      case '>':
        out += "\\u003e";
        break;
      case '&':
        out += "\\u0026";
        break;
      default:
        if (static_cast<unsigned char>(ch) < 0x20) {
          out += fmt::format("\\u{:04x}", static_cast<unsigned>(static_cast<unsigned char>(ch)));
        } else {
          out += ch;
        }
    }
  }
  return out + "\"";
}

std::string PlotLibrary() {
  return std::string("<style>\n") + embedded::kDygraphsCss + kPlotStyle + "</style>\n<script>\n" +
         embedded::kDygraphsJs + "\n</script>\n<script>\n" + embedded::kReportPlotsJs +
         "\n</script>\n";
}

std::string Figure(const Plot& plot, const std::string& caption) {
  // Letters, digits, '-' and '_' only: a column name from a CSV header may hold anything.
  std::string id = "plot-" + plot.name;
  for (char& c : id) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
  }
  return fmt::format(
      "<figure><div class=\"dl-plot\" id=\"{0}\"><div class=\"dl-toolbar\"></div>"
      "<div class=\"dl-graph\" style=\"width:{1}px;height:{2}px\"></div>"
      "<div class=\"dl-legend\"></div></div>\n<script>driftlabPlot({3},{4});</script>\n"
      "<figcaption>{5}</figcaption></figure>\n",
      EscapeHtml(id), plot.width_px, plot.height_px, JsonString(id), Spec(plot),
      EscapeHtml(caption));
}

}  // namespace plot
}  // namespace driftlab::app
