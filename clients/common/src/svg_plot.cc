#include "svg_plot.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace driftlab::jobspec {
namespace {

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

}  // namespace

AxisTicks NiceTicks(double lo, double hi, int target) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) lo = hi = 0;
  // A valid result may hold values up to the largest double (issue 15: +-1e308 made the span, the
  // step and the label precision overflow, and fmt aborted). Axes end at +-1e306, so the span, the
  // step and every tick stay finite; larger values are drawn at the edge.
  constexpr double kAxisLimit = 1e306;
  lo = std::clamp(lo, -kAxisLimit, kAxisLimit);
  hi = std::clamp(hi, -kAxisLimit, kAxisLimit);
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
  // Decimals of the step: 0 .. 17 (a double has at most 17 significant decimal digits).
  ticks.decimals = std::clamp(-static_cast<int>(std::floor(std::log10(ticks.step))), 0, 17);
  for (double k = first; k <= last; k += 1) ticks.values.push_back(k * ticks.step);
  return ticks;
}

namespace svg {

std::string Num(double value) { return fmt::format("{:.4g}", value); }

std::string Px(double value) { return fmt::format("{:.2f}", value); }

void Range::Add(double v) {
  if (std::isfinite(v)) {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
}

double Chart::Axis::Map(double v) const { return scale == Scale::kLog10 ? std::log10(v) : v; }

std::string Chart::Axis::Label(double tick) const {
  if (scale == Scale::kLog10) return fmt::format("{:g}", std::pow(10.0, tick));
  // Fixed notation up to 1e9; beyond, the label would be tens to hundreds of digits wide.
  if (std::abs(tick) >= 1e9) return fmt::format("{:.4g}", tick);
  return fmt::format("{:.{}f}", tick + 0.0, ticks.decimals);  // + 0.0: no "-0"
}

Chart::Axis Chart::MakeAxis(Range range, Scale scale) {
  Axis axis;
  axis.scale = scale;
  if (scale == Scale::kLinear) {
    axis.ticks = NiceTicks(range.lo, range.hi);
    return axis;
  }
  // Decades covering the positive part of the range.
  double lo = range.lo > 0 ? range.lo : range.hi;
  double hi = range.hi;
  if (!(lo > 0) || !(hi > 0) || !std::isfinite(lo) || !std::isfinite(hi)) lo = 1, hi = 10;
  double first = std::floor(std::log10(lo));
  double last = std::ceil(std::log10(hi));
  if (last <= first) last = first + 1;
  axis.ticks.lo = first;
  axis.ticks.hi = last;
  axis.ticks.step = 1;
  for (double k = first; k <= last; k += 1) axis.ticks.values.push_back(k);
  return axis;
}

Chart::Chart(double width, double height, Range x, Range y, std::string x_label,
             std::string y_label, Scale x_scale, Scale y_scale)
    : width_(width), height_(height), x_(MakeAxis(x, x_scale)), y_(MakeAxis(y, y_scale)) {
  svg_ = fmt::format(
      "<svg class=\"chart\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\" "
      "role=\"img\">\n",
      width_, height_);
  Axes(x_label, y_label);
}

double Chart::X(double x) const {
  return kLeft +
         (x_.Map(x) - x_.ticks.lo) / (x_.ticks.hi - x_.ticks.lo) * (width_ - kLeft - kRight);
}

double Chart::Y(double y) const {
  return height_ - kBottom -
         (y_.Map(y) - y_.ticks.lo) / (y_.ticks.hi - y_.ticks.lo) * (height_ - kTop - kBottom);
}

double Chart::PixelsPerUnitX() const {
  return (width_ - kLeft - kRight) / (x_.ticks.hi - x_.ticks.lo);
}

bool Chart::Drawable(double x, double y) const {
  if (!std::isfinite(x) || !std::isfinite(y)) return false;
  if (x_.scale == Scale::kLog10 && !(x > 0)) return false;
  if (y_.scale == Scale::kLog10 && !(y > 0)) return false;
  return true;
}

void Chart::Polyline(const Points& points, const char* color, const char* extra) {
  svg_ += "<polyline fill=\"none\" stroke-width=\"1.5\" stroke=\"";
  svg_ += color;
  svg_ += "\" ";
  svg_ += extra;
  svg_ += " points=\"";
  for (const auto& [x, y] : points) {
    if (Drawable(x, y)) svg_ += Px(X(x)) + "," + Px(Y(y)) + " ";
  }
  svg_ += "\"/>\n";
}

void Chart::Band(const Points& upper, const Points& lower, const char* color) {
  svg_ += fmt::format("<polygon fill=\"{}\" fill-opacity=\"0.6\" stroke=\"none\" points=\"", color);
  for (const auto& [x, y] : upper) svg_ += Px(X(x)) + "," + Px(Y(y)) + " ";
  for (auto it = lower.rbegin(); it != lower.rend(); ++it) {
    svg_ += Px(X(it->first)) + "," + Px(Y(it->second)) + " ";
  }
  svg_ += "\"/>\n";
}

void Chart::Dot(double x, double y) {
  svg_ += fmt::format("<circle cx=\"{}\" cy=\"{}\" r=\"1.8\"/>", Px(X(x)), Px(Y(y)));
}

void Chart::Marker(double x, double y, const char* color, const std::string& title) {
  if (!Drawable(x, y)) return;
  svg_ += fmt::format(
      "<circle class=\"marker\" cx=\"{}\" cy=\"{}\" r=\"2.5\" fill=\"{}\"><title>{}"
      "</title></circle>\n",
      Px(X(x)), Px(Y(y)), color, EscapeHtml(title));
}

void Chart::Circle(double x, double y, double r, const char* color) {
  svg_ += fmt::format(
      "<circle cx=\"{}\" cy=\"{}\" r=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"2\"/>\n",
      Px(X(x)), Px(Y(y)), Px(r * PixelsPerUnitX()), color);
}

void Chart::Bar(double x0, double x1, double count, const char* color) {
  svg_ += fmt::format(
      "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"{}\" stroke=\"white\" "
      "stroke-width=\"0.5\"/>",
      Px(X(x0)), Px(Y(count)), Px(std::max(0.0, X(x1) - X(x0))), Px(Y(0) - Y(count)), color);
}

void Chart::VerticalLine(double x, const char* color) {
  svg_ += fmt::format(
      "<line x1=\"{0}\" x2=\"{0}\" y1=\"{1}\" y2=\"{2}\" stroke=\"{3}\" stroke-width=\"2\"/>\n",
      Px(X(x)), Px(kTop), Px(height_ - kBottom), color);
}

void Chart::HorizontalLine(double y, const char* color, const char* extra) {
  svg_ += fmt::format(
      "<line x1=\"{0}\" x2=\"{1}\" y1=\"{2}\" y2=\"{2}\" stroke=\"{3}\" stroke-width=\"1\" {4}/>\n",
      Px(kLeft), Px(width_ - kRight), Px(Y(y)), color, extra);
}

void Chart::ErrorBar(double x, double y_lo, double y_hi, const char* color) {
  if (!Drawable(x, y_lo) || !Drawable(x, y_hi)) return;
  const double px = X(x), top = Y(y_hi), bottom = Y(y_lo);
  svg_ += fmt::format(
      "<path class=\"errorbar\" fill=\"none\" stroke=\"{0}\" stroke-width=\"1\" "
      "d=\"M{1},{3}V{4}M{2},{3}H{5}M{2},{4}H{5}\"/>\n",
      color, Px(px), Px(px - 3), Px(top), Px(bottom), Px(px + 3));
}

void Chart::Legend(const std::vector<LegendEntry>& entries) {
  constexpr double kLine = 14, kSample = 22;
  size_t longest = 0;
  for (const LegendEntry& e : entries) longest = std::max(longest, e.label.size());
  const double w = kSample + 12 + 6.2 * static_cast<double>(longest);
  const double h = kLine * static_cast<double>(entries.size()) + 6;
  const double x0 = width_ - kRight - w - 4, y0 = kTop + 4;
  svg_ += fmt::format(
      "<g class=\"legend\"><rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"white\" "
      "fill-opacity=\"0.85\" stroke=\"#bbb\"/>\n",
      Px(x0), Px(y0), Px(w), Px(h));
  for (size_t i = 0; i < entries.size(); ++i) {
    const LegendEntry& e = entries[i];
    const double y = y0 + 3 + kLine * (static_cast<double>(i) + 0.5);
    svg_ += fmt::format(
        "<line x1=\"{0}\" x2=\"{1}\" y1=\"{2}\" y2=\"{2}\" stroke=\"{3}\" stroke-width=\"2\"{4}/>"
        "<text x=\"{5}\" y=\"{6}\">{7}</text>\n",
        Px(x0 + 4), Px(x0 + 4 + kSample), Px(y), e.color,
        e.dash.empty() ? "" : " stroke-dasharray=\"" + e.dash + "\"", Px(x0 + kSample + 8),
        Px(y + 4), EscapeHtml(e.label));
  }
  svg_ += "</g>\n";
}

void Chart::Raw(const std::string& text) { svg_ += text; }

std::string Chart::Finish() { return svg_ + "</svg>\n"; }

void Chart::Axes(const std::string& x_label, const std::string& y_label) {
  const double x0 = kLeft, x1 = width_ - kRight, y0 = height_ - kBottom, y1 = kTop;
  svg_ += "<g class=\"axes\">\n";
  // Pixel positions of the ticks go through the axis units directly (log ticks are in decades).
  const auto tick_x = [&](double v) {
    return kLeft + (v - x_.ticks.lo) / (x_.ticks.hi - x_.ticks.lo) * (width_ - kLeft - kRight);
  };
  const auto tick_y = [&](double v) {
    return height_ - kBottom -
           (v - y_.ticks.lo) / (y_.ticks.hi - y_.ticks.lo) * (height_ - kTop - kBottom);
  };
  for (const double v : x_.ticks.values) {
    const double x = tick_x(v);
    svg_ += fmt::format(
        "<line class=\"grid\" x1=\"{0}\" x2=\"{0}\" y1=\"{1}\" y2=\"{2}\"/>"
        "<text x=\"{0}\" y=\"{3}\" text-anchor=\"middle\">{4}</text>\n",
        Px(x), Px(y0), Px(y1), Px(y0 + 14), x_.Label(v));
  }
  for (const double v : y_.ticks.values) {
    const double y = tick_y(v);
    svg_ += fmt::format(
        "<line class=\"grid\" x1=\"{0}\" x2=\"{1}\" y1=\"{2}\" y2=\"{2}\"/>"
        "<text x=\"{3}\" y=\"{4}\" text-anchor=\"end\">{5}</text>\n",
        Px(x0), Px(x1), Px(y), Px(x0 - 4), Px(y + 4), y_.Label(v));
  }
  svg_ += fmt::format(
      "<rect class=\"frame\" x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"/>\n"
      "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{}</text>\n"
      "<text transform=\"translate({},{}) rotate(-90)\" text-anchor=\"middle\">{}</text>\n",
      Px(x0), Px(y1), Px(x1 - x0), Px(y0 - y1), Px((x0 + x1) / 2), Px(height_ - 8),
      EscapeHtml(x_label), 14, Px((y0 + y1) / 2), EscapeHtml(y_label));
  svg_ += "</g>\n";
}

std::string Figure(const std::string& svg, const std::string& caption) {
  return "<figure>" + svg + "<figcaption>" + EscapeHtml(caption) + "</figcaption></figure>\n";
}

}  // namespace svg
}  // namespace driftlab::jobspec
