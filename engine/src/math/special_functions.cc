#include "driftlab/special_functions.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "driftlab/elementary.h"
#include "driftlab/spec_error.h"

namespace driftlab {
namespace {

constexpr double kEps = 1e-15;
constexpr double kTiny = 1e-300;
// Both expansions converge in O(sqrt(a)) terms (NR 6.2); 1e6 terms cover a = 4.5e6 (9 states x
// 1e6 runs / 2) with room to spare. A fixed 1000 would stop early for a above ~6000.
constexpr int kMaxIterations = 1000000;

// P(a, x) by the series gamma(a, x) = e^-x x^a sum_n x^n / (a (a+1) ... (a+n)) (NR 6.2.5).
double GammaSeries(double a, double x) {
  double term = 1.0 / a;
  double sum = term;
  for (int n = 1; n < kMaxIterations; ++n) {
    term *= x / (a + n);
    sum += term;
    if (std::abs(term) < std::abs(sum) * kEps) break;
  }
  return sum * math::Exp(-x + a * math::Log(x) - math::LgammaPositive(a));
}

// Q(a, x) = 1 - P(a, x) by the continued fraction NR 6.2.7, modified Lentz (NR 5.2).
double GammaContinuedFraction(double a, double x) {
  double b = x + 1.0 - a;
  double c = 1.0 / kTiny;
  double d = 1.0 / b;
  double h = d;
  for (int i = 1; i < kMaxIterations; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < kEps) break;
  }
  return math::Exp(-x + a * math::Log(x) - math::LgammaPositive(a)) * h;
}

// Standard normal quantile, Abramowitz & Stegun 26.2.23 (|error| < 4.5e-4); used only as the
// starting point of the chi-square quantile iteration.
double NormalQuantileApprox(double p) {
  const double q = p < 0.5 ? p : 1.0 - p;
  const double t = std::sqrt(-2.0 * math::Log(q));
  const double z = t - (2.515517 + 0.802853 * t + 0.010328 * t * t) /
                           (1.0 + 1.432788 * t + 0.189269 * t * t + 0.001308 * t * t * t);
  return p < 0.5 ? -z : z;
}

}  // namespace

double RegularizedGammaP(double a, double x) {
  if (x <= 0.0) return 0.0;
  if (x < a + 1.0) return GammaSeries(a, x);
  return 1.0 - GammaContinuedFraction(a, x);
}

double RegularizedGammaQ(double a, double x) {
  if (x <= 0.0) return 1.0;
  if (std::isinf(x)) return 0.0;
  if (x < a + 1.0) return 1.0 - GammaSeries(a, x);
  return GammaContinuedFraction(a, x);
}

double NormalCdf(double z) {
  if (!(z == z)) return z;
  const double half_q = 0.5 * RegularizedGammaQ(0.5, 0.5 * z * z);  // P(|Z| > |z|) / 2
  return z < 0.0 ? half_q : 1.0 - half_q;
}

double ChiSquareCdf(double x, double k) { return RegularizedGammaP(0.5 * k, 0.5 * x); }

double ChiSquareQuantile(double p, double nu) {
  if (!(p > 0.0 && p < 1.0)) throw SpecError("chi_square.p", std::to_string(p), "(0, 1)");
  if (!(nu > 0.0 && std::isfinite(nu)))
    throw SpecError("chi_square.nu", std::to_string(nu), "> 0, finite");
  const double a = nu / 2.0;
  auto cdf = [a](double x) { return RegularizedGammaP(a, x / 2.0); };
  // Wilson & Hilferty (1931): chi2_p(nu) ~ nu (1 - 2/(9 nu) + z_p sqrt(2/(9 nu)))^3.
  const double k = 2.0 / (9.0 * nu);
  const double c = std::max(1.0 - k + NormalQuantileApprox(p) * std::sqrt(k), 1e-3);
  double x = nu * (c * c * c);
  // Bracket the root of cdf(x) - p, then safeguarded Newton steps (bisection when a step leaves
  // the bracket). The density is f(x) = exp((a - 1) ln x - x/2 - a ln 2 - lgamma(a)).
  double lo = 0.0, hi = std::max(x, 1.0);
  while (cdf(hi) < p) {
    lo = hi;
    hi *= 2.0;
  }
  if (!(x > lo && x < hi)) x = 0.5 * (lo + hi);
  for (int iter = 0; iter < 200; ++iter) {
    const double f = cdf(x) - p;
    if (f < 0.0) {
      lo = x;
    } else {
      hi = x;
    }
    const double density = math::Exp((a - 1.0) * math::Log(x) - x / 2.0 - a * math::Log(2.0) -
                                     math::LgammaPositive(a));
    double next = density > 0.0 ? x - f / density : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - x) <= 1e-14 * x || hi - lo <= 1e-15 * hi) return next;
    x = next;
  }
  return x;
}

}  // namespace driftlab
