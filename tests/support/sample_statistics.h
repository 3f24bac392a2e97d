// Small statistics helpers shared by the tests.
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

namespace driftlab::testing {

// Pearson sample correlation of two equally long series, accumulated in long double.
inline double SampleCorrelation(const std::vector<double>& a, const std::vector<double>& b) {
  long double sab = 0, saa = 0, sbb = 0, sa = 0, sb = 0;
  const size_t n = a.size();
  for (size_t i = 0; i < n; ++i) {
    sa += a[i];
    sb += b[i];
    sab += static_cast<long double>(a[i]) * b[i];
    saa += static_cast<long double>(a[i]) * a[i];
    sbb += static_cast<long double>(b[i]) * b[i];
  }
  const long double cov = sab / n - (sa / n) * (sb / n);
  return static_cast<double>(
      cov / std::sqrt((saa / n - (sa / n) * (sa / n)) * (sbb / n - (sb / n) * (sb / n))));
}

// Standard normal quantile: bisection on erfc (to 1e-12; plenty for test bounds).
inline double NormalQuantile(double p) {
  double lo = -10.0, hi = 10.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (0.5 * std::erfc(-mid / std::sqrt(2.0)) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// Chi-square quantile by Wilson-Hilferty (relative error < 1e-3 for k >= 30; Johnson, Kotz &
// Balakrishnan vol. 1, 18.5).
inline double Chi2Quantile(double k, double p) {
  const double z = NormalQuantile(p);
  const double a = 2.0 / (9.0 * k);
  return k * std::pow(1.0 - a + z * std::sqrt(a), 3);
}

}  // namespace driftlab::testing
