#include "driftlab/app/gate_statistics.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

#include "driftlab/app/gate_distributions.h"
#include "driftlab/elementary.h"

namespace driftlab::app {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Upper tail 1 - F(f; d1, d2) = I_{d2/(d2 + d1 f)}(d2/2, d1/2) (A&S 26.6.2 with the symmetry
// 26.5.2): computed directly, so that p-values far below 1e-16 keep their digits.
double FUpperTail(double f, double d1, double d2) {
  if (f <= 0.0) return 1.0;
  if (std::isinf(f)) return 0.0;
  return RegularizedBeta(0.5 * d2, 0.5 * d1, d2 / (d2 + d1 * f));
}

// P(T > t) for t(nu).
double TUpperTail(double t, double nu) {
  if (std::isnan(t)) return 1.0;
  if (t == kInf) return 0.0;
  if (t == -kInf) return 1.0;
  return 1.0 - StudentTCdf(t, nu);
}

// The R where a decreasing function stat(R) crosses `target`, by bisection in log R starting
// from `start` > 0; 0 or +inf when it does not cross inside [start 2^-200, start 2^200].
template <typename Stat>
double Crossing(Stat stat, double target, double start) {
  double lo = start, hi = start;
  for (int i = 0; stat(lo) < target; ++i) {
    if (i == 200) return 0.0;
    hi = lo;
    lo *= 0.5;
  }
  for (int i = 0; stat(hi) > target; ++i) {
    if (i == 200) return kInf;
    lo = hi;
    hi *= 2.0;
  }
  for (int i = 0; i < 100 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = std::sqrt(lo * hi);
    (stat(mid) > target ? lo : hi) = mid;
  }
  return std::sqrt(lo * hi);
}

double Mean(const std::vector<double>& v) {
  return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
}

// One-sample t statistic of d (mean / standard error); +-inf when the d are all equal and not 0.
double TStatistic(const std::vector<double>& d) {
  const double n = static_cast<double>(d.size());
  const double m = Mean(d);
  double ss = 0.0;
  for (const double v : d) ss += (v - m) * (v - m);
  const double se = std::sqrt(ss / (n - 1.0) / n);
  if (se == 0.0) return m > 0.0 ? kInf : (m < 0.0 ? -kInf : 0.0);
  return m / se;
}

// Sample standard deviation (divisor n - 1).
double Sd(const std::vector<double>& v) {
  const double m = Mean(v);
  double ss = 0.0;
  for (const double x : v) ss += (x - m) * (x - m);
  return std::sqrt(ss / (static_cast<double>(v.size()) - 1.0));
}

// Pitman-Morgan t of H0 var(y / r) = var(x): r_SD sqrt((n - 2) / (1 - r_SD^2)) with
// S = x + y / r, D = y / r - x; decreasing in r.
double PitmanMorganT(const std::vector<double>& x, const std::vector<double>& y, double r) {
  const size_t n = x.size();
  double ms = 0.0, md = 0.0;
  for (size_t i = 0; i < n; ++i) {
    ms += x[i] + y[i] / r;
    md += y[i] / r - x[i];
  }
  ms /= static_cast<double>(n);
  md /= static_cast<double>(n);
  double sss = 0.0, sdd = 0.0, ssd = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const double s = x[i] + y[i] / r - ms, d = y[i] / r - x[i] - md;
    sss += s * s;
    sdd += d * d;
    ssd += s * d;
  }
  if (sss == 0.0 || sdd == 0.0) return 0.0;  // var(y / r) = var(x) exactly, or no spread at all
  const double corr = std::clamp(ssd / std::sqrt(sss * sdd), -1.0, 1.0);
  if (corr >= 1.0) return kInf;
  if (corr <= -1.0) return -kInf;
  return corr * std::sqrt((static_cast<double>(n) - 2.0) / (1.0 - corr * corr));
}

// Binomial(n, p) probabilities as cumulative sums of the mass function, each tail summed from its
// small end (so small tail probabilities keep their relative accuracy):
// lower[k] = P(X <= k - 1) for k = 0..n+1, upper[k] = P(X >= k) for k = 0..n+1.
struct BinomialTails {
  std::vector<double> lower, upper;
};

BinomialTails Tails(long n, double p) {
  std::vector<double> pmf(static_cast<size_t>(n) + 1);
  const double log_n = math::LgammaPositive(n + 1.0);
  for (long i = 0; i <= n; ++i) {
    pmf[static_cast<size_t>(i)] =
        math::Exp(log_n - math::LgammaPositive(i + 1.0) - math::LgammaPositive(n - i + 1.0) +
                  i * math::Log(p) + (n - i) * math::Log1p(-p));
  }
  BinomialTails t;
  t.lower.assign(static_cast<size_t>(n) + 2, 0.0);
  t.upper.assign(static_cast<size_t>(n) + 2, 0.0);
  for (long k = 1; k <= n + 1; ++k) {
    t.lower[static_cast<size_t>(k)] =
        std::min(1.0, t.lower[static_cast<size_t>(k - 1)] + pmf[static_cast<size_t>(k - 1)]);
  }
  for (long k = n; k >= 0; --k) {
    t.upper[static_cast<size_t>(k)] =
        std::min(1.0, t.upper[static_cast<size_t>(k + 1)] + pmf[static_cast<size_t>(k)]);
  }
  return t;
}

// Distribution-free bounds of the p-quantile from sorted values, each wrong with probability at
// most `a`: lower = X_(k), k the largest with P(Bin <= k - 1) <= a (0 when none: the values are
// >= 0); upper = X_(k), k the smallest with P(Bin >= k) <= a (+inf when none).
struct QuantileBounds {
  double lower = 0.0, upper = kInf;
};

QuantileBounds Bounds(const std::vector<double>& sorted, const BinomialTails& t, double a) {
  const long n = static_cast<long>(sorted.size());
  QuantileBounds b;
  for (long k = 1; k <= n && t.lower[static_cast<size_t>(k)] <= a; ++k) {
    b.lower = sorted[static_cast<size_t>(k - 1)];
  }
  for (long k = n; k >= 1 && t.upper[static_cast<size_t>(k)] <= a; --k) {
    b.upper = sorted[static_cast<size_t>(k - 1)];
  }
  return b;
}

}  // namespace

TestOutcome TestSigmaIndependent(double s_b, double n_b, double s_c, double n_c, double limit_ratio,
                                 double alpha) {
  TestOutcome out;
  const double nu_c = n_c - 1.0, nu_b = n_b - 1.0;
  out.ratio = s_c / s_b;
  const double r2 = out.ratio * out.ratio;
  out.p_value = FUpperTail(r2 / (limit_ratio * limit_ratio), nu_c, nu_b);
  // (s_c^2 / s_b^2) / R^2 ~ F(nu_c, nu_b): R in ratio / sqrt(F_{1-a/2}), ratio / sqrt(F_{a/2}).
  out.ratio_low = out.ratio / std::sqrt(FQuantile(1.0 - alpha / 2.0, nu_c, nu_b));
  out.ratio_high = out.ratio / std::sqrt(FQuantile(alpha / 2.0, nu_c, nu_b));
  out.test = fmt::format("F({:g}, {:g}) variance ratio", nu_c, nu_b);
  return out;
}

TestOutcome TestRmsIndependent(double rms_b, double n_b, double rms_c, double n_c,
                               double limit_ratio, double alpha) {
  TestOutcome out = TestSigmaIndependent(rms_b, n_b + 1.0, rms_c, n_c + 1.0, limit_ratio, alpha);
  out.test = fmt::format("F({:g}, {:g}) mean-square ratio (chi2 of N rms^2)", n_c, n_b);
  return out;
}

TestOutcome TestAbsMeanWelch(double mean_b, double s_b, double n_b, double mean_c, double s_c,
                             double n_c, double limit_ratio, double alpha) {
  TestOutcome out;
  const double a = s_c * s_c / n_c;
  const auto welch = [&](double rho, double* df) {
    const double b = rho * rho * s_b * s_b / n_b;
    *df = (a + b) * (a + b) / (a * a / (n_c - 1.0) + b * b / (n_b - 1.0));
    return std::sqrt(a + b);
  };
  double df = 0.0;
  const double se = welch(limit_ratio, &df);
  const double diff = std::abs(mean_c) - limit_ratio * std::abs(mean_b);
  out.p_value = se > 0.0 ? TUpperTail(diff / se, df) : (diff > 0.0 ? 0.0 : 1.0);
  out.ratio = std::abs(mean_c) / std::abs(mean_b);
  // Interval of |mu_c| - |mu_b| by Welch, divided by |m_b| (the baseline's own noise in the
  // denominator is left out: an approximation for display; the decision uses the test above).
  double df1 = 0.0;
  const double se1 = welch(1.0, &df1);
  const double half =
      (se1 > 0.0 ? StudentTQuantile(1.0 - alpha / 2.0, df1) * se1 : 0.0) / std::abs(mean_b);
  out.ratio_low = std::max(0.0, out.ratio - half);
  out.ratio_high = out.ratio + half;
  out.test = fmt::format("Welch t (df {:.1f})", df);
  return out;
}

TestOutcome TestQuantile(std::vector<double> baseline, std::vector<double> current, double p,
                         double limit_ratio, double alpha) {
  std::sort(baseline.begin(), baseline.end());
  std::sort(current.begin(), current.end());
  const long n_b = static_cast<long>(baseline.size()), n_c = static_cast<long>(current.size());
  const BinomialTails tb = Tails(n_b, p), tc = Tails(n_c, p);
  TestOutcome out;
  // p-value: the smallest total error probability of a pair of bounds (lower bound X_c(k) of the
  // current quantile, upper bound X_b(j) of the baseline's) with X_c(k) > rho X_b(j). For each k
  // the largest such j is best (the upper tail falls with j).
  double p_value = 1.0;
  long j = 0;
  for (long k = 1; k <= n_c; ++k) {
    const double y = current[static_cast<size_t>(k - 1)];
    while (j < n_b && limit_ratio * baseline[static_cast<size_t>(j)] < y) ++j;
    if (j == 0) continue;
    p_value =
        std::min(p_value, tc.lower[static_cast<size_t>(k)] + tb.upper[static_cast<size_t>(j)]);
  }
  out.p_value = p_value;
  // Hyndman & Fan definition 7, as the result file's percentiles.
  const auto quantile = [p](const std::vector<double>& v) {
    const double h = (static_cast<double>(v.size()) - 1.0) * p;
    const size_t lo = static_cast<size_t>(std::floor(h));
    const size_t hi = std::min(lo + 1, v.size() - 1);
    return v[lo] + (h - std::floor(h)) * (v[hi] - v[lo]);
  };
  out.ratio = quantile(current) / quantile(baseline);
  // Four bounds at alpha / 4 each: the interval holds with probability >= 1 - alpha (Bonferroni).
  const QuantileBounds bb = Bounds(baseline, tb, alpha / 4.0);
  const QuantileBounds bc = Bounds(current, tc, alpha / 4.0);
  out.ratio_low = std::isinf(bb.upper) ? 0.0 : bc.lower / bb.upper;
  out.ratio_high = bb.lower > 0.0 ? bc.upper / bb.lower : kInf;
  out.test = fmt::format("order statistics (distribution-free), n {} / {}", n_b, n_c);
  return out;
}

TestOutcome TestNees(double nees_b, double dof_b, double nees_c, double dof_c, double limit_ratio,
                     double alpha) {
  TestOutcome out;
  out.ratio = nees_c / nees_b;
  out.p_value = FUpperTail(out.ratio / limit_ratio, dof_c, dof_b);
  out.ratio_low = out.ratio / FQuantile(1.0 - alpha / 2.0, dof_c, dof_b);
  out.ratio_high = out.ratio / FQuantile(alpha / 2.0, dof_c, dof_b);
  out.test = fmt::format("F({:g}, {:g}) NEES ratio (chi2 band)", dof_c, dof_b);
  return out;
}

TestOutcome TestSigmaPaired(const std::vector<double>& x, const std::vector<double>& y,
                            double limit_ratio, double alpha) {
  TestOutcome out;
  const double nu = static_cast<double>(x.size()) - 2.0;
  out.ratio = Sd(y) / Sd(x);
  const auto stat = [&](double r) { return PitmanMorganT(x, y, r); };
  out.p_value = TUpperTail(stat(limit_ratio), nu);
  const double t = StudentTQuantile(1.0 - alpha / 2.0, nu);
  const double start = out.ratio > 0.0 && std::isfinite(out.ratio) ? out.ratio : 1.0;
  out.ratio_low = Crossing(stat, t, start);
  out.ratio_high = Crossing(stat, -t, start);
  out.test = fmt::format("Pitman-Morgan paired t({:g})", nu);
  return out;
}

TestOutcome TestRmsPaired(const std::vector<double>& x, const std::vector<double>& y,
                          double limit_ratio, double alpha) {
  TestOutcome out;
  const double nu = static_cast<double>(x.size()) - 1.0;
  double xx = 0.0, yy = 0.0;
  for (size_t i = 0; i < x.size(); ++i) {
    xx += x[i] * x[i];
    yy += y[i] * y[i];
  }
  out.ratio = std::sqrt(yy / xx);
  std::vector<double> d(x.size());
  const auto stat = [&](double r) {
    for (size_t i = 0; i < x.size(); ++i) d[i] = y[i] * y[i] - r * r * x[i] * x[i];
    return TStatistic(d);
  };
  out.p_value = TUpperTail(stat(limit_ratio), nu);
  const double t = StudentTQuantile(1.0 - alpha / 2.0, nu);
  const double start = out.ratio > 0.0 && std::isfinite(out.ratio) ? out.ratio : 1.0;
  out.ratio_low = Crossing(stat, t, start);
  out.ratio_high = Crossing(stat, -t, start);
  out.test = fmt::format("paired t({:g}) on squared errors", nu);
  return out;
}

TestOutcome TestAbsMeanPaired(const std::vector<double>& x, const std::vector<double>& y,
                              double limit_ratio, double alpha) {
  TestOutcome out;
  const double nu = static_cast<double>(x.size()) - 1.0;
  const double mx = Mean(x), my = Mean(y);
  const double sx = mx < 0.0 ? -1.0 : 1.0, sy = my < 0.0 ? -1.0 : 1.0;
  out.ratio = std::abs(my) / std::abs(mx);
  std::vector<double> d(x.size());
  const auto stat = [&](double r) {
    for (size_t i = 0; i < x.size(); ++i) d[i] = sy * y[i] - r * sx * x[i];
    return TStatistic(d);
  };
  out.p_value = TUpperTail(stat(limit_ratio), nu);
  const double t = StudentTQuantile(1.0 - alpha / 2.0, nu);
  const double start = out.ratio > 0.0 && std::isfinite(out.ratio) ? out.ratio : 1.0;
  out.ratio_low = Crossing(stat, t, start);
  out.ratio_high = Crossing(stat, -t, start);
  out.test = fmt::format("paired t({:g}) on signed errors", nu);
  return out;
}

TestOutcome TestQuantilePaired(const std::vector<double>& x, const std::vector<double>& y, double p,
                               double limit_ratio, double alpha) {
  const size_t n = x.size();
  // Hyndman & Fan definition 7 by two partial sorts (the result file's percentiles).
  const auto quantile = [p](std::vector<double>& v) {
    const double h = (static_cast<double>(v.size()) - 1.0) * p;
    const size_t lo = static_cast<size_t>(std::floor(h));
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(lo), v.end());
    const double a = v[lo];
    if (lo + 1 >= v.size()) return a;
    const double b = *std::min_element(v.begin() + static_cast<std::ptrdiff_t>(lo) + 1, v.end());
    return a + (h - std::floor(h)) * (b - a);
  };
  std::vector<double> xs = x, ys = y;
  TestOutcome out;
  out.ratio = quantile(ys) / quantile(xs);
  // One fixed seed: the same files give the same decision on every machine (libstdc++'s
  // mt19937_64 is specified by the standard; the index is taken by plain modulo, whose
  // bias n / 2^64 is negligible).
  std::mt19937_64 rng(20260416);
  std::vector<double> ratios;
  ratios.reserve(kBootstrapResamples);
  int at_or_below = 0;
  for (int b = 0; b < kBootstrapResamples; ++b) {
    for (size_t i = 0; i < n; ++i) {
      const size_t r = static_cast<size_t>(rng() % n);
      xs[i] = x[r];
      ys[i] = y[r];
    }
    const double qx = quantile(xs), qy = quantile(ys);
    const double ratio = qx > 0.0 ? qy / qx : (qy > 0.0 ? kInf : 1.0);
    ratios.push_back(ratio);
    at_or_below += ratio <= limit_ratio ? 1 : 0;
  }
  out.p_value = (1.0 + at_or_below) / (kBootstrapResamples + 1.0);
  std::sort(ratios.begin(), ratios.end());
  const auto at = [&](double q) {
    const size_t i = static_cast<size_t>(std::floor(q * (kBootstrapResamples - 1) + 0.5));
    return ratios[std::min(i, ratios.size() - 1)];
  };
  out.ratio_low = at(alpha / 2.0);
  out.ratio_high = at(1.0 - alpha / 2.0);
  out.test = fmt::format("paired bootstrap ({} resamples)", kBootstrapResamples);
  return out;
}

std::vector<bool> HolmReject(const std::vector<double>& p_values, double alpha) {
  const size_t m = p_values.size();
  std::vector<size_t> order(m);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return p_values[a] < p_values[b]; });
  std::vector<bool> rejected(m, false);
  for (size_t i = 0; i < m; ++i) {
    // Step i compares the i-th smallest p with alpha / (m - i); the first that passes stops it.
    if (!(p_values[order[i]] <= alpha / static_cast<double>(m - i))) break;
    rejected[order[i]] = true;
  }
  return rejected;
}

double DetectableSigmaRatio(double n_b, double n_c, double limit_ratio, double alpha_per_test,
                            double power) {
  const double nu_c = n_c - 1.0, nu_b = n_b - 1.0;
  return limit_ratio * std::sqrt(FQuantile(1.0 - alpha_per_test, nu_c, nu_b) /
                                 FQuantile(1.0 - power, nu_c, nu_b));
}

long RunsToDetectSigmaRatio(double true_ratio, double limit_ratio, double alpha_per_test,
                            double power) {
  constexpr long kMaxRuns = 10000000;
  const auto detects = [&](long n) {
    const double nd = static_cast<double>(n);
    return DetectableSigmaRatio(nd, nd, limit_ratio, alpha_per_test, power) <= true_ratio;
  };
  if (!(true_ratio > limit_ratio) || !detects(kMaxRuns)) return 0;
  long lo = 2, hi = 4;  // detects(lo) is false (one degree of freedom each), detects(hi) true
  while (!detects(hi)) {
    lo = hi;
    hi *= 2;
  }
  while (hi - lo > 1) {
    const long mid = lo + (hi - lo) / 2;
    (detects(mid) ? hi : lo) = mid;
  }
  return hi;
}

}  // namespace driftlab::app
