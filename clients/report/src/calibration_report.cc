#include "driftlab/report/calibration_report.h"

#include <fmt/format.h>
#include <google/protobuf/util/json_util.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <regex>
#include <string_view>
#include <vector>

#include "driftlab/units.h"
#include "driftlab/v1/job.pb.h"
#include "interactive_plot.h"
#include "svg_plot.h"

namespace driftlab::app {
namespace {

using svg::Num;

// Colours of the residual series and of the Allan plots (ColorBrewer "Set1").
constexpr const char* kSeriesColors[3] = {"#e41a1c", "#377eb8", "#4daf4a"};
constexpr const char* kResidualRmsColor = "#888888";
constexpr const char* kAdevColor = "#08519c";
constexpr const char* kFitColor = "#d94801";

constexpr const char* kExtraStyle = R"(<style>
td.num { font-family: monospace; }
.flag { color: #b00020; font-size: 0.9em; }
p.model { max-width: 60em; font-size: 0.9em; background: #f4f4f4; padding: 0.5em; }
table.correlation td, table.correlation th { padding: 0.1em 0.3em; font-size: 0.85em; }
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

// Static poses as the detection listed them in the result's messages ("pose P: t A-B s (...),
// mean f [x, y, z] m/s^2", calibration_job.cc), numbered from 0 like that list; the plots use the
// same numbers.
struct Pose {
  int index = 0;
  double t_begin_s = 0, t_end_s = 0;
  double f[3] = {0, 0, 0};
};

std::vector<Pose> PosesOf(const v1::CalibrationResult& result) {
  static const std::regex kPose(
      R"(^pose (\d+): t ([-0-9.eE+]+)-([-0-9.eE+]+) s .*mean f \[([-0-9.eE+]+), ([-0-9.eE+]+), )"
      R"(([-0-9.eE+]+)\])");
  std::vector<Pose> poses;
  for (const std::string& m : result.messages()) {
    std::smatch match;
    if (!std::regex_search(m, match, kPose)) continue;
    Pose p;
    p.index = std::stoi(match[1]);
    p.t_begin_s = std::stod(match[2]);
    p.t_end_s = std::stod(match[3]);
    for (int i = 0; i < 3; ++i) p.f[i] = std::stod(match[4 + i]);
    poses.push_back(p);
  }
  return poses;
}

// Residual series of a fit: what x counts, the residual names, and the x value of each residual
// group (accel: the pose number; gyro: the pose a used rotation starts from; reference: the row).
struct SeriesLayout {
  std::string x_label;
  std::vector<std::string> names;
  std::vector<double> x;
};

SeriesLayout Layout(const v1::CalibrationFitResult& fit, size_t poses) {
  SeriesLayout layout;
  if (fit.kind() == "accel") {
    layout = {"static pose (numbered as in the list)", {"|f| - g"}, {}};
  } else if (fit.kind() == "gyro") {
    layout = {"rotation from pose k to k+1",
              {"down error, perpendicular component 1", "down error, perpendicular component 2"},
              {}};
    // Used rotations: every consecutive pair except the ones the fit's messages skip.
    std::vector<bool> skipped(poses, false);
    static const std::regex kSkipped(R"(^poses (\d+) and \d+ skipped)");
    for (const std::string& m : fit.messages()) {
      std::smatch match;
      if (std::regex_search(m, match, kSkipped)) {
        const size_t k = std::stoul(match[1]);
        if (k < skipped.size()) skipped[k] = true;
      }
    }
    for (size_t k = 0; k + 1 < poses; ++k) {
      if (!skipped[k]) layout.x.push_back(static_cast<double>(k));
    }
  } else {
    // Reference: the full-matrix fit has parameters K.xx ..., three residuals per row.
    const bool matrix = fit.parameters_size() > 0 && fit.parameters(0).name().rfind("K.", 0) == 0;
    if (matrix) {
      layout = {"data row", {"output x", "output y", "output z"}, {}};
    } else {
      std::string axis = fit.parameters_size() > 0 ? fit.parameters(0).name() : "";
      axis = axis.substr(0, axis.find('.'));
      layout = {"data row", {"output " + axis}, {}};
    }
  }
  const int groups = fit.residuals_size() / static_cast<int>(layout.names.size());
  if (static_cast<int>(layout.x.size()) != groups) {
    layout.x.clear();
    const int first = fit.kind() == "reference" ? 1 : 0;
    for (int i = 0; i < groups; ++i) layout.x.push_back(i + first);
  }
  return layout;
}

// `name`: unique in the report (a reference calibration has one fit per axis).
std::string ResidualPlot(const v1::CalibrationFitResult& fit, size_t poses,
                         const std::string& name) {
  const SeriesLayout layout = Layout(fit, poses);
  const int k = static_cast<int>(layout.names.size());
  const int n = fit.residuals_size() / k;
  const std::string unit = fit.residual_unit();
  plot::Plot p;
  p.name = name;
  p.x_label = layout.x_label;
  p.y_label = "residual [" + unit + "]";
  p.width_px = 600;
  p.height_px = 280;
  p.x = layout.x;
  for (int s = 0; s < k; ++s) {
    plot::Series series{layout.names[s], kSeriesColors[s], {}, {}, {}, {}, 1.5};
    for (int i = 0; i < n; ++i) series.y.push_back(fit.residuals(i * k + s));
    p.series.push_back(series);
  }
  plot::Series rms{
      "+RMS", kResidualRmsColor, std::vector<double>(n, fit.residual_rms()), {}, {}, {5, 3}, 1.0};
  plot::Series minus_rms = rms;
  minus_rms.label = "-RMS";
  for (double& v : minus_rms.y) v = -v;
  p.series.push_back(rms);
  p.series.push_back(minus_rms);
  return plot::Figure(p, fmt::format("{} fit residuals: {} per {} ({} residuals, RMS {} {})",
                                     fit.kind(), k == 1 ? "one" : std::to_string(k), layout.x_label,
                                     fit.residuals_size(), Num(fit.residual_rms()), unit));
}

// The recording against time with the detected static intervals shaded and numbered:
// specific force and angular rate, at most kMaxRecordingPoints rows drawn (every k-th).
constexpr size_t kMaxRecordingPoints = 4000;

std::string RecordingPlots(const NumericTable& table, double rate_hz,
                           const std::vector<Pose>& poses) {
  const size_t columns = table.columns.size(), rows = table.rows();
  const bool has_time = rate_hz == 0.0;
  const size_t o = has_time ? 1 : 0;
  if (rows == 0 || columns != 6 + o) return "";
  const size_t stride = std::max<size_t>(1, (rows + kMaxRecordingPoints - 1) / kMaxRecordingPoints);
  std::string out;
  for (const bool gyro : {false, true}) {
    plot::Plot p;
    p.name = gyro ? "recording-rate" : "recording-force";
    p.x_label = "time [s]";
    p.y_label = gyro ? "angular rate [deg/s]" : "specific force [m/s^2]";
    p.width_px = 900;
    p.height_px = 260;
    const double scale = gyro ? 180.0 / M_PI : 1.0;
    const size_t first = o + (gyro ? 0 : 3);
    const char* axes[3] = {"x", "y", "z"};
    std::vector<plot::Series> series;
    for (int i = 0; i < 3; ++i) {
      series.push_back(
          {std::string(gyro ? "omega " : "f ") + axes[i], kSeriesColors[i], {}, {}, {}, {}, 1.0});
    }
    for (size_t k = 0; k < rows; k += stride) {
      const double* row = &table.values[k * columns];
      p.x.push_back(has_time ? row[0] : static_cast<double>(k) / rate_hz);
      for (int i = 0; i < 3; ++i) series[i].y.push_back(scale * row[first + i]);
    }
    p.series = series;
    const std::string shade = "rgba(35,139,69,0.15)";
    for (const Pose& pose : poses) {
      p.shades.push_back(plot::Shade{pose.t_begin_s, pose.t_end_s, shade});
      if (!gyro) {
        const double top = std::max({pose.f[0], pose.f[1], pose.f[2]});
        p.markers.push_back(
            {0.5 * (pose.t_begin_s + pose.t_end_s), top, "#238b45", std::to_string(pose.index)});
      }
    }
    out += plot::Figure(
        p, fmt::format("raw {} against time{}; shaded: the {} detected static poses{}",
                       gyro ? "angular rate" : "specific force",
                       stride > 1 ? fmt::format(" (every {}th sample drawn)", stride) : "",
                       poses.size(), gyro ? "" : ", numbered as in the list"));
  }
  return out;
}

// Where gravity pointed in each pose: the direction of the mean specific force (body "up") as
// azimuth atan2(f_y, f_x) and elevation asin(f_z / |f|) in the sensor frame, a map of the unit
// sphere; a good calibration spreads the poses over it (Tedaldi et al. 2014).
std::string PoseDirectionPlot(const std::vector<Pose>& poses) {
  if (poses.empty()) return "";
  std::vector<std::pair<double, double>> points;
  plot::Plot p;
  p.name = "pose-directions";
  p.x_label = "azimuth of f, atan2(f_y, f_x) [deg]";
  p.y_label = "elevation of f, asin(f_z / |f|) [deg]";
  p.points_only = true;
  p.width_px = 560;
  p.height_px = 320;
  p.x_range = {-185, 185};
  p.y_range = {-95, 95};
  for (const Pose& pose : poses) {
    const double norm =
        std::sqrt(pose.f[0] * pose.f[0] + pose.f[1] * pose.f[1] + pose.f[2] * pose.f[2]);
    if (!(norm > 0)) continue;
    const double az = std::atan2(pose.f[1], pose.f[0]) * 180.0 / M_PI;
    const double el = std::asin(std::clamp(pose.f[2] / norm, -1.0, 1.0)) * 180.0 / M_PI;
    points.emplace_back(az, el);
    p.markers.push_back({az, el, "#08519c", std::to_string(pose.index)});
  }
  std::sort(points.begin(), points.end());
  plot::Series series{"pose", "#08519c", {}, {}, {}, {}, 1.5};
  for (const auto& [az, el] : points) {
    p.x.push_back(az);
    series.y.push_back(el);
  }
  p.series.push_back(series);
  return plot::Figure(p, fmt::format("direction of the mean specific force in each of the {} "
                                     "poses (unit sphere, sensor axes; elevation +90 = z up)",
                                     poses.size()));
}

// Datasheet unit beside a parameter's SI unit: ppm for a dimensionless scale factor,
// mrad for misalignment, mg for an accelerometer bias, deg/h for a gyro bias.
std::string ParameterDatasheetUnit(const v1::CalibrationParameter& p) {
  if (p.unit() == "1") return "ppm";
  if (p.unit() == "rad") return "mrad";
  if (p.unit() == "m/s^2") return "mg";
  if (p.unit() == "rad/s") return "deg/h";
  return "";
}

std::string ModelNote(const v1::CalibrationFitResult& fit) {
  if (fit.kind() == "accel") {
    return "<p class=\"model\">Model (Tedaldi et al., ICRA 2014): f&#771;<sub>s</sub> = "
           "T<sub>a</sub> f<sub>b</sub> + b<sub>a</sub>, T<sub>a</sub> = I + S<sub>a</sub> + "
           "M<sub>a</sub>; S<sub>a</sub> = diag(scale_factor.x, y, z), M<sub>a</sub> strictly "
           "lower triangular (misalignment.yx, zx, zy: row, column). Sign convention: the "
           "parameters are the sensor's errors, raw = (I + S + M) true + b; a positive scale "
           "factor reads too large; correct with f<sub>b</sub> = T<sub>a</sub><sup>-1</sup> "
           "(f&#771;<sub>s</sub> - b<sub>a</sub>). Frame b: x along the accelerometer's x axis, y "
           "in its x-y plane.</p>\n";
  }
  if (fit.kind() == "gyro") {
    return "<p class=\"model\">Model: &omega;&#771;<sub>s</sub> = T<sub>g</sub> "
           "&omega;<sub>b</sub> + b<sub>g</sub>, T<sub>g</sub> = I + S<sub>g</sub> + "
           "M<sub>g</sub>; M<sub>g</sub> any off-diagonal (misalignment.ij: row i, column j), "
           "relative to the accelerometer-defined frame b. Sign convention as for the "
           "accelerometer: raw = (I + S + M) true + b. b<sub>g</sub> is the mean rate of the "
           "initial static period (Earth rate not removed).</p>\n";
  }
  return "<p class=\"model\">Model: output = sensitivity &times; input + offset per axis (or "
         "output = K input + offset with the full matrix K), least squares over the rows.</p>\n";
}

// Correlation matrix of the parameters (when the result carries it), coloured by |rho|.
std::string CorrelationTable(const v1::CalibrationFitResult& fit) {
  const int n = fit.parameters_size();
  if (n == 0 || fit.correlation_size() != n * n) return "";
  std::string out = "<table class=\"correlation\"><caption>" + EscapeHtml(fit.kind()) +
                    " parameter correlations (from the fit's covariance)</caption>\n<tr><th></th>";
  for (int j = 0; j < n; ++j) {
    out += "<th title=\"" + EscapeHtml(fit.parameters(j).name()) + "\">" + std::to_string(j + 1) +
           "</th>";
  }
  out += "</tr>\n";
  for (int i = 0; i < n; ++i) {
    out += fmt::format("<tr><td>{} {}</td>", i + 1, EscapeHtml(fit.parameters(i).name()));
    for (int j = 0; j < n; ++j) {
      const double rho = fit.correlation(i * n + j);
      const double a = std::isfinite(rho) ? std::min(1.0, std::abs(rho)) : 0.0;
      out += fmt::format("<td class=\"num\" style=\"background:rgba({},{:.2f})\">{:.2f}</td>",
                         rho >= 0 ? "203,24,29" : "8,81,156", i == j ? 0.0 : 0.6 * a, rho);
    }
    out += "</tr>\n";
  }
  return out + "</table>\n";
}

std::string FitSection(const v1::CalibrationFitResult& fit, size_t poses, int index) {
  std::string out = "<h2>" + EscapeHtml(fit.kind()) + " fit</h2>\n";
  out += fmt::format(
      "<table class=\"facts\">\n<tr><th>poses / rotations / rows used</th><td>{}</td></tr>\n"
      "<tr><th>Ceres iterations</th><td>{}</td></tr>\n"
      "<tr><th>residual RMS</th><td>{} {}</td></tr>\n"
      "<tr><th>fit time</th><td>{} ms</td></tr>\n</table>\n",
      fit.poses_used(), fit.iterations(), Num(fit.residual_rms()), EscapeHtml(fit.residual_unit()),
      Num(1e3 * fit.fit_time_s()));
  out += ModelNote(fit);
  out += "<table class=\"parameters\"><caption>" + EscapeHtml(fit.kind()) +
         " parameters (1 sigma: ceres::Covariance scaled by the residual variance)</caption>\n"
         "<tr><th>parameter</th><th>value</th><th>&plusmn; 1 &sigma;</th><th>SI unit</th>"
         "<th>value &plusmn; 1 &sigma; (datasheet unit)</th><th></th></tr>\n";
  for (const v1::CalibrationParameter& p : fit.parameters()) {
    const std::string unit = ParameterDatasheetUnit(p);
    std::string datasheet = "-";
    if (!unit.empty()) {
      try {
        datasheet =
            FormatQuantity(p.value(), unit, 4) + " +- " + FormatQuantity(p.sigma(), unit, 2);
      } catch (const std::exception&) {
      }
    }
    // Not distinguishable from zero at 1 sigma.
    const bool zero = std::abs(p.value()) < p.sigma();
    out += "<tr><td>" + EscapeHtml(p.name()) + "</td>" + NumberCell(p.value(), 6) +
           NumberCell(p.sigma(), 3) + "<td>" + EscapeHtml(p.unit()) + "</td><td>" +
           EscapeHtml(datasheet) + "</td><td>" +
           (zero ? "<span class=\"flag\">|value| &lt; 1&sigma;: not distinguishable from 0</span>"
                 : "") +
           "</td></tr>\n";
  }
  out += "</table>\n";
  out += CorrelationTable(fit);
  if (fit.residuals_size() > 0) {
    const std::string name = fit.kind() == "reference"
                                 ? fmt::format("residuals-reference-{}", index + 1)
                                 : "residuals-" + fit.kind();
    out += ResidualPlot(fit, poses, name);
  }
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

// The unit the terms table uses for a curve's ADEV: deg/h for rates, ug for specific force (so
// that the plots match the table); other units unchanged.
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

std::string RenderCalibrationReport(const v1::CalibrationResult& result,
                                    const NumericTable* recording, double rate_hz) {
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
    // The pose list is long (tens of lines): collapsible after its summary line.
    html += std::string("<h2>") + (result.kind() == "reference" ? "Notes" : "Static detection") +
            "</h2>\n<p>" + EscapeHtml(result.messages(0)) + "</p>\n";
    if (result.messages_size() > 1) {
      google::protobuf::RepeatedPtrField<std::string> rest(result.messages().begin() + 1,
                                                           result.messages().end());
      html += fmt::format(
          "<details><summary>{} more lines (the poses, numbered as in the "
          "plots)</summary>\n{}</details>\n",
          rest.size(), MessageList(rest));
    }
  }
  const std::vector<Pose> poses = PosesOf(result);
  if (recording != nullptr || !poses.empty()) {
    html += "<h2>Recording and poses</h2>\n<div class=\"grid\">\n";
    if (recording != nullptr) html += RecordingPlots(*recording, rate_hz, poses);
    html += PoseDirectionPlot(poses) + "</div>\n";
  }
  for (int i = 0; i < result.fits_size(); ++i) {
    html += FitSection(result.fits(i), poses.size(), i);
  }
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

std::string NoiseFitTitle(const v1::NoiseModelFit& fit) {
  std::string title;
  for (const v1::AllanCurve& curve : fit.curves()) {
    if (!title.empty()) title += ", ";
    title += curve.column();
  }
  return title.empty() ? "noise-model fit" : title;
}

}  // namespace driftlab::app
