#include "driftlab/app/gate_distributions.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "driftlab/elementary.h"
#include "driftlab/special_functions.h"

namespace driftlab::app {
namespace {

constexpr double kEps = 1e-15;
constexpr double kTiny = 1e-300;
// The beta continued fraction converges in O(sqrt(max(a, b))) terms (NR 6.4); 1e6 terms cover
// the degrees of freedom of runs up to 1e6 with room to spare.
constexpr int kMaxIterations = 1000000;

// Continued fraction of I_x(a, b) (NR 6.4.5, coefficients 6.4.6), modified Lentz.
double BetaContinuedFraction(double a, double b, double x) {
  const double qab = a + b, qap = a + 1.0, qam = a - 1.0;
  double c = 1.0;
  double d = 1.0 - qab * x / qap;
  if (std::abs(d) < kTiny) d = kTiny;
  d = 1.0 / d;
  double h = d;
  for (int m = 1; m < kMaxIterations; ++m) {
    const int m2 = 2 * m;
    double aa = m * (b - m) * x / ((qam + m2) * (a + m2));
    d = 1.0 + aa * d;
    if (std::abs(d) < kTiny) d = kTiny;
    c = 1.0 + aa / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    h *= d * c;
    aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
    d = 1.0 + aa * d;
    if (std::abs(d) < kTiny) d = kTiny;
    c = 1.0 + aa / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < kEps) break;
  }
  return h;
}

// The x with cdf(x) = p for an increasing cdf on [lo, hi): the bracket grows until it holds p,
// then bisection (in log space for positive variables, so that tiny and huge quantiles converge
// in relative terms).
template <typename Cdf>
double InvertPositive(Cdf cdf, double p) {
  double lo = 1.0, hi = 1.0;
  while (cdf(lo) > p && lo > 1e-300) lo *= 0.5;
  while (cdf(hi) < p && hi < 1e300) hi *= 2.0;
  for (int i = 0; i < 200 && hi - lo > 1e-13 * hi; ++i) {
    const double mid = std::sqrt(lo * hi);
    (cdf(mid) < p ? lo : hi) = mid;
  }
  return std::sqrt(lo * hi);
}

}  // namespace

double RegularizedBeta(double a, double b, double x) {
  if (x <= 0.0) return 0.0;
  if (x >= 1.0) return 1.0;
  // Prefactor x^a (1-x)^b / (a B(a, b)) (NR 6.4.5), in logs for large a, b.
  const double log_front = math::LgammaPositive(a + b) - math::LgammaPositive(a) -
                           math::LgammaPositive(b) + a * math::Log(x) + b * math::Log1p(-x);
  // The fraction converges fast for x < (a + 1) / (a + b + 2); else use the symmetry (NR 6.4).
  if (x < (a + 1.0) / (a + b + 2.0)) {
    return math::Exp(log_front) * BetaContinuedFraction(a, b, x) / a;
  }
  return 1.0 - math::Exp(log_front) * BetaContinuedFraction(b, a, 1.0 - x) / b;
}

double NormalCdf(double z) { return driftlab::NormalCdf(z); }  // the engine's (special_functions.h)

double NormalQuantile(double p) {
  if (p <= 0.0) return -std::numeric_limits<double>::infinity();
  if (p >= 1.0) return std::numeric_limits<double>::infinity();
  double lo = -40.0, hi = 40.0;
  for (int i = 0; i < 200 && hi - lo > 1e-14; ++i) {
    const double mid = 0.5 * (lo + hi);
    (NormalCdf(mid) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

double StudentTCdf(double t, double nu) {
  const double tail = 0.5 * RegularizedBeta(0.5 * nu, 0.5, nu / (nu + t * t));
  return t >= 0.0 ? 1.0 - tail : tail;
}

double StudentTQuantile(double p, double nu) {
  if (p == 0.5) return 0.0;
  // Symmetric: invert the upper half on (0, inf).
  const double upper = p > 0.5 ? p : 1.0 - p;
  const double t = InvertPositive([nu](double x) { return StudentTCdf(x, nu); }, upper);
  return p > 0.5 ? t : -t;
}

double FCdf(double f, double d1, double d2) {
  if (f <= 0.0) return 0.0;
  return RegularizedBeta(0.5 * d1, 0.5 * d2, d1 * f / (d1 * f + d2));
}

double FQuantile(double p, double d1, double d2) {
  return InvertPositive([d1, d2](double f) { return FCdf(f, d1, d2); }, p);
}

double BinomialCdf(long k, long n, double p) {
  if (k < 0) return 0.0;
  if (k >= n) return 1.0;
  return RegularizedBeta(static_cast<double>(n - k), static_cast<double>(k + 1), 1.0 - p);
}

double BinomialUpperTail(long k, long n, double p) {
  if (k <= 0) return 1.0;
  if (k > n) return 0.0;
  return RegularizedBeta(static_cast<double>(k), static_cast<double>(n - k + 1), p);
}

}  // namespace driftlab::app
