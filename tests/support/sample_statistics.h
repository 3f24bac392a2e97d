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

}  // namespace driftlab::testing
