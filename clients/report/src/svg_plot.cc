#include "svg_plot.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace driftlab::app {
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
  // A valid result may hold values up to the largest double (+-1e308 would overflow the span, the
  // step and the label precision, and fmt would abort). Axes end at +-1e306, so the span, the
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

}  // namespace svg
}  // namespace driftlab::app
