#include "driftlab/jobspec/calibration_report.h"

#include <fmt/format.h>
#include <google/protobuf/util/json_util.h>

#include <cmath>
#include <map>
#include <string_view>
#include <vector>

#include "driftlab/units.h"
#include "driftlab/v1/job.pb.h"
#include "interactive_plot.h"
#include "svg_plot.h"

namespace driftlab::jobspec {
namespace {

using svg::Chart;
using svg::Figure;
using svg::Num;
using svg::Points;
using svg::Range;

// Colours of the residual series and of the Allan plots (ColorBrewer "Set1").
constexpr const char* kSeriesColors[3] = {"#e41a1c", "#377eb8", "#4daf4a"};
constexpr const char* kRmsColor = "#888888";
constexpr const char* kAdevColor = "#08519c";
constexpr const char* kFitColor = "#d94801";

constexpr const char* kExtraStyle = R"(<style>
svg.chart g.legend text { font-size: 10px; }
td.num { font-family: monospace; }
ul.messages { font-size: 0.9em; }
</style>
)";

std::string Head(const std::string& title) {
  return "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\"/>\n<title>" +
         EscapeHtml(title) + "</title>\n" + svg::kStyle + kExtraStyle + plot::PlotLibrary() +
         "</head>\n<body>\n";
}

std::string Full(double v) { return fmt::format("{:.17g}", v); }

// A table cell holding a number: shown with `shown` digits, exact in data-value.
std::string NumberCell(double v, int shown) {
  return fmt::format("<td class=\"num\" data-value=\"{}\">{:.{}g}</td>", Full(v), v, shown);
}

std::string MessageList(const google::protobuf::RepeatedPtrField<std::string>& messages) {
  if (messages.empty()) return "";
  std::string out = "<ul class=\"messages\">\n";
  for (const std::string& m : messages) out += "<li>" + EscapeHtml(m) + "</li>\n";
  return out + "</ul>\n";
}

// Residual series of a fit: how many residuals each pose / rotation / row has, and their names.
struct SeriesLayout {
  std::string x_label;
  std::vector<std::string> names;
};

SeriesLayout Layout(const v1::CalibrationFitResult& fit) {
  if (fit.kind() == "accel") return {"static pose", {"|f| - g"}};
  if (fit.kind() == "gyro") {
    return {"rotation (pose k to k+1, used pairs)",
            {"down error, perpendicular component 1", "down error, perpendicular component 2"}};
  }
  // Reference: the full-matrix fit has parameters K.xx ..., three residuals per row.
  const bool matrix = fit.parameters_size() > 0 && fit.parameters(0).name().rfind("K.", 0) == 0;
  if (matrix) return {"data row", {"output x", "output y", "output z"}};
  std::string axis = fit.parameters_size() > 0 ? fit.parameters(0).name() : "";
  axis = axis.substr(0, axis.find('.'));
  return {"data row", {"output " + axis}};
}

std::string ResidualPlot(const v1::CalibrationFitResult& fit) {
  const SeriesLayout layout = Layout(fit);
  const int k = static_cast<int>(layout.names.size());
  const int n = fit.residuals_size() / k;
  Range x, y;
  x.Add(1);
  x.Add(std::max(n, 2));
  y.Add(fit.residual_rms());
  y.Add(-fit.residual_rms());
  for (double r : fit.residuals()) y.Add(r);
  const std::string unit = fit.residual_unit();
  Chart chart(560, 300, x, y, layout.x_label, "residual [" + unit + "]");
  chart.HorizontalLine(0.0, "#555555");
  chart.HorizontalLine(fit.residual_rms(), kRmsColor, "stroke-dasharray=\"5,3\"");
  chart.HorizontalLine(-fit.residual_rms(), kRmsColor, "stroke-dasharray=\"5,3\"");
  std::vector<svg::LegendEntry> legend;
  for (int s = 0; s < k; ++s) {
    Points points;
    for (int i = 0; i < n; ++i) points.emplace_back(i + 1, fit.residuals(i * k + s));
    chart.Polyline(points, kSeriesColors[s]);
    for (const auto& [xi, r] : points) {
      chart.Marker(xi, r, kSeriesColors[s],
                   fmt::format("{} {}: {} {}", layout.x_label, xi, Num(r), unit));
    }
    legend.push_back({kSeriesColors[s], "", layout.names[s]});
  }
  legend.push_back({kRmsColor, "5,3", "+-RMS " + Num(fit.residual_rms()) + " " + unit});
  chart.Legend(legend);
  return Figure(chart.Finish(), fmt::format("{} fit residuals: {} per {} ({} residuals)",
                                            fit.kind(), k == 1 ? "one" : std::to_string(k),
                                            layout.x_label, fit.residuals_size()));
}

std::string FitSection(const v1::CalibrationFitResult& fit) {
  std::string out = "<h2>" + EscapeHtml(fit.kind()) + " fit</h2>\n";
  out += fmt::format(
      "<table class=\"facts\">\n<tr><th>poses / rotations / rows used</th><td>{}</td></tr>\n"
      "<tr><th>Ceres iterations</th><td>{}</td></tr>\n"
      "<tr><th>residual RMS</th><td>{} {}</td></tr>\n"
      "<tr><th>fit time</th><td>{} ms</td></tr>\n</table>\n",
      fit.poses_used(), fit.iterations(), Num(fit.residual_rms()), EscapeHtml(fit.residual_unit()),
      Num(1e3 * fit.fit_time_s()));
  out += "<table class=\"parameters\"><caption>" + EscapeHtml(fit.kind()) +
         " parameters (1 sigma: ceres::Covariance scaled by the residual variance)</caption>\n"
         "<tr><th>parameter</th><th>value</th><th>&plusmn; 1 &sigma;</th><th>unit</th></tr>\n";
  for (const v1::CalibrationParameter& p : fit.parameters()) {
    out += "<tr><td>" + EscapeHtml(p.name()) + "</td>" + NumberCell(p.value(), 6) +
           NumberCell(p.sigma(), 3) + "<td>" + EscapeHtml(p.unit()) + "</td></tr>\n";
  }
  out += "</table>\n";
  if (fit.residuals_size() > 0) out += ResidualPlot(fit);
  out += MessageList(fit.messages());
  return out;
}

// Datasheet unit of a noise term (as `driftlab allan --fit` prints them, noise_fit.h).
std::string DatasheetUnit(const v1::NoiseTerm& t) {
  static const std::map<std::string, std::pair<const char*, const char*>> kUnits = {
      {"white_noise", {"deg/sqrt(h)", "m/s/sqrt(h)"}},
      {"bias_instability", {"deg/h", "ug"}},
      {"gauss_markov_sigma", {"deg/h", "ug"}},
      {"gauss_markov_tau", {"s", "s"}},
      {"random_walk", {"deg/h/sqrt(h)", "ug/sqrt(s)"}},
      {"quantization", {"urad", "mm/s"}},
      {"rate_ramp", {"deg/h/h", "ug/h"}},
  };
  const auto it = kUnits.find(t.name());
  if (it == kUnits.end()) return t.unit();
  return t.triad() == "gyro" ? it->second.first : it->second.second;
}

std::string InDatasheetUnits(double si, const std::string& unit) {
  try {
    return FormatQuantity(si, unit, 4);
  } catch (const std::exception&) {
    return Num(si);
  }
}

std::string TermsTable(const v1::NoiseModelFit& fit) {
  bool any_datasheet = false;
  for (const v1::NoiseTerm& t : fit.terms()) any_datasheet |= t.has_datasheet_value();
  std::string out =
      "<table class=\"terms\"><caption>Fitted noise terms (IEEE Std 952-1997 Annex C), value "
      "&plusmn; 1 &sigma; (ceres::Covariance); \"triad\" rows are the model written</caption>\n"
      "<tr><th>triad</th><th>axis</th><th>term</th><th>value</th><th>&plusmn; 1 &sigma;</th>"
      "<th>SI unit</th><th>datasheet units</th>";
  if (any_datasheet) out += "<th>datasheet</th>";
  out += "</tr>\n";
  for (const v1::NoiseTerm& t : fit.terms()) {
    const bool determined = std::isfinite(t.sigma());
    const std::string unit = DatasheetUnit(t);
    out += "<tr><td>" + EscapeHtml(t.triad()) + "</td><td>" + EscapeHtml(t.axis()) + "</td><td>" +
           EscapeHtml(t.name()) + "</td>" + NumberCell(t.value(), 6);
    out += determined ? NumberCell(t.sigma(), 3) : "<td>not determined</td>";
    out += "<td>" + EscapeHtml(t.unit()) + "</td><td>" +
           (determined ? EscapeHtml(InDatasheetUnits(t.value(), unit) + " +- " +
                                    InDatasheetUnits(t.sigma(), unit))
                       : "-") +
           "</td>";
    if (any_datasheet) {
      out += t.has_datasheet_value()
                 ? "<td class=\"num\" data-value=\"" + Full(t.datasheet_value()) + "\">" +
                       EscapeHtml(InDatasheetUnits(t.datasheet_value(), unit)) + "</td>"
                 : "<td>-</td>";
    }
    out += "</tr>\n";
  }
  return out + "</table>\n";
}

// The unit the terms table uses for a curve's ADEV: deg/h for rates, ug for specific force
// (issue 20: the plots in rad/s and m/s^2 did not match the table); other units unchanged.
std::string PlotUnit(const std::string& si_unit) {
  if (si_unit == "rad/s") return "deg/h";
  if (si_unit == "m/s^2") return "ug";
  return si_unit;
}

double ScaleTo(const std::string& unit, const std::string& si_unit) {
  if (unit == si_unit) return 1.0;
  try {
    return FromSi(1.0, unit);
  } catch (const std::exception&) {
    return 1.0;
  }
}

// Log-log ADEV plot in the table's units with the -1/2, 0 and +1/2 slope guides and the read-off
// points of the kept terms (IEEE Std 952-1997 Annex C, C.1-C.5): N is the -1/2 line at tau = 1 s,
// K the +1/2 line at tau = 3 s, Q the -1 line at tau = sqrt(3) s, R the +1 line at tau = sqrt(2) s,
// B the flat floor at 0.664 B (sqrt(2 ln 2 / pi) B) where the fitted curve is lowest.
std::string AllanPlot(const v1::AllanCurve& curve, const std::vector<const v1::NoiseTerm*>& terms) {
  const std::string unit = PlotUnit(curve.unit());
  const double k = ScaleTo(unit, curve.unit());
  plot::Plot p;
  p.name = "allan-" + curve.column();
  p.x_label = "tau [s]";
  p.y_label = "Allan deviation [" + unit + "]";
  p.log_x = p.log_y = true;
  p.width_px = 520;
  p.height_px = 360;
  plot::Series adev{"ADEV, 95 % CI", kAdevColor, {}, {}, {}, {}, 1.5};
  plot::Series fitted{"fitted model", kFitColor, {}, {}, {}, {6, 3}, 1.5};
  const int n = curve.tau_s_size();
  double min_fit = INFINITY, tau_min_fit = NAN;
  for (int i = 0; i < n; ++i) {
    p.x.push_back(curve.tau_s(i));
    adev.y.push_back(k * curve.adev(i));
    adev.lo.push_back(k * curve.adev_lower(i));
    adev.hi.push_back(k * curve.adev_upper(i));
    fitted.y.push_back(k * curve.adev_fit(i));
    if (curve.adev_fit(i) > 0 && curve.adev_fit(i) < min_fit) {
      min_fit = curve.adev_fit(i);
      tau_min_fit = curve.tau_s(i);
    }
  }
  p.series = {adev, fitted};
  if (n >= 2 && curve.adev(0) > 0 && curve.adev(n - 1) > 0) {
    const double t0 = curve.tau_s(0), t1 = curve.tau_s(n - 1);
    const double y0 = k * curve.adev(0), y1 = k * curve.adev(n - 1);
    // Guides: -1/2 through the first point, +1/2 through the last, 0 at the fitted minimum; the
    // sloped ones end where they leave the data's range (y_lo), so their labels stay visible.
    double y_lo = INFINITY;
    for (int i = 0; i < n; ++i) {
      if (curve.adev_lower(i) > 0) y_lo = std::min(y_lo, k * curve.adev_lower(i));
    }
    if (!std::isfinite(y_lo)) y_lo = std::min(y0, y1);
    const double t_minus = std::min(t1, t0 * (y0 / y_lo) * (y0 / y_lo));
    const double t_plus = std::max(t0, t1 * (y_lo / y1) * (y_lo / y1));
    p.segments.push_back({t0, y0, t_minus, y0 * std::sqrt(t0 / t_minus), "#777777", "-1/2"});
    p.segments.push_back({t_plus, y1 * std::sqrt(t_plus / t1), t1, y1, "#777777", "+1/2"});
    if (std::isfinite(tau_min_fit)) {
      p.segments.push_back({t0, k * min_fit, t1, k * min_fit, "#777777", "0"});
    }
  }
  for (const v1::NoiseTerm* t : terms) {
    if (!t->determined() || !(t->value() > 0)) continue;
    const std::string value = InDatasheetUnits(t->value(), DatasheetUnit(*t));
    if (t->name() == "white_noise") {
      p.markers.push_back({1.0, k * t->value(), kFitColor, "N = " + value});
    } else if (t->name() == "random_walk") {
      p.markers.push_back({3.0, k * t->value(), kFitColor, "K = " + value});
    } else if (t->name() == "quantization") {
      p.markers.push_back({std::sqrt(3.0), k * t->value(), kFitColor, "Q = " + value});
    } else if (t->name() == "rate_ramp") {
      p.markers.push_back({std::sqrt(2.0), k * t->value(), kFitColor, "R = " + value});
    } else if (t->name() == "bias_instability" && std::isfinite(tau_min_fit)) {
      p.markers.push_back({tau_min_fit, k * 0.6643 * t->value(), kFitColor, "B = " + value});
    }
  }
  return plot::Figure(p, fmt::format("{}: {} taus; guides of slope -1/2 (white noise), 0 (bias "
                                     "instability), +1/2 (random walk); dots: read-off points of "
                                     "the kept terms",
                                     curve.column(), n));
}

std::string SensorJson(const v1::NoiseModelFit& fit) {
  v1::Job job;
  *job.mutable_sensor() = fit.sensor();
  google::protobuf::util::JsonPrintOptions options;
  options.add_whitespace = true;
  options.preserve_proto_field_names = true;
  std::string json;
  if (!google::protobuf::util::MessageToJsonString(job, &json, options).ok()) {
    json = fit.sensor().DebugString();
  }
  return json;
}

}  // namespace

std::string RenderCalibrationReport(const v1::CalibrationResult& result) {
  const std::string title = "driftlab calibration report: " + result.kind() + ", " +
                            (result.data_file().empty() ? "(data)" : result.data_file());
  std::string html = Head(title) + "<h1>" + EscapeHtml(title) + "</h1>\n";
  html += fmt::format(
      "<table class=\"facts\">\n<tr><th>kind</th><td>{}</td></tr>\n"
      "<tr><th>data</th><td>{}</td></tr>\n<tr><th>latitude</th><td>{} deg</td></tr>\n"
      "<tr><th>height</th><td>{} m</td></tr>\n<tr><th>fits</th><td>{}</td></tr>\n</table>\n",
      EscapeHtml(result.kind()), EscapeHtml(result.data_file()), Num(result.lat_deg()),
      Num(result.height_m()), result.fits_size());
  if (!result.messages().empty()) {
    html += std::string("<h2>") + (result.kind() == "reference" ? "Notes" : "Static detection") +
            "</h2>\n" + MessageList(result.messages());
  }
  for (const v1::CalibrationFitResult& fit : result.fits()) html += FitSection(fit);
  return html + "</body>\n</html>\n";
}

std::string RenderNoiseFitReport(const v1::NoiseModelFit& fit, const std::string& data_name) {
  const std::string title = "driftlab noise-model fit: " + data_name;
  std::string html = Head(title) + "<h1>" + EscapeHtml(title) + "</h1>\n";
  html += fmt::format(
      "<table class=\"facts\">\n<tr><th>columns</th><td>{}</td></tr>\n"
      "<tr><th>fit time</th><td>{} s</td></tr>\n</table>\n",
      fit.curves_size(), Num(fit.fit_time_s()));
  html += "<h2>Allan deviation and fitted model</h2>\n<div class=\"grid\">\n";
  for (const v1::AllanCurve& curve : fit.curves()) {
    std::vector<const v1::NoiseTerm*> terms;
    for (const v1::NoiseTerm& t : fit.terms()) {
      if (t.axis() == curve.column()) terms.push_back(&t);
    }
    html += AllanPlot(curve, terms);
  }
  html += "</div>\n<h2>Fitted terms</h2>\n" + TermsTable(fit);
  html += "<h2>Fit tables</h2>\n";
  for (const std::string& m : fit.messages()) {
    if (m.find('\n') != std::string::npos) html += "<pre>" + EscapeHtml(m) + "</pre>\n";
  }
  std::vector<std::string> notes;
  for (const std::string& m : fit.messages()) {
    if (m.find('\n') == std::string::npos) notes.push_back(m);
  }
  if (!notes.empty()) {
    html += "<ul class=\"messages\">\n";
    for (const std::string& m : notes) html += "<li>" + EscapeHtml(m) + "</li>\n";
    html += "</ul>\n";
  }
  html += "<h2>Sensor model (job schema)</h2>\n<pre>" + EscapeHtml(SensorJson(fit)) + "</pre>\n";
  return html + "</body>\n</html>\n";
}

}  // namespace driftlab::jobspec
