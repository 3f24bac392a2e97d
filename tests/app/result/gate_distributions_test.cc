// The distribution functions of the CI gate (gate_distributions.h) against published tables and
// closed forms. Table values are printed to 3-4 significant decimals, so the tolerance is half a
// unit of the table's last digit; closed forms are checked to 1e-12.
#include "driftlab/app/gate_distributions.h"

#include <gtest/gtest.h>

#include <cmath>

namespace driftlab::app {
namespace {

TEST(GateDistributions, IncompleteGammaAndBetaMatchClosedForms) {
  for (const double x : {0.01, 0.5, 1.0, 3.0, 30.0}) {
    EXPECT_NEAR(RegularizedGammaP(1.0, x), 1.0 - std::exp(-x), 1e-12) << x;  // A&S 6.5.13
    // P(1/2, x) = erf(sqrt x) (A&S 6.5.17).
    EXPECT_NEAR(RegularizedGammaP(0.5, x), std::erf(std::sqrt(x)), 1e-12) << x;
  }
  for (const double x : {0.0, 0.1, 0.5, 0.9, 1.0}) {
    EXPECT_NEAR(RegularizedBeta(1.0, 1.0, x), x, 1e-12);               // uniform
    EXPECT_NEAR(RegularizedBeta(3.0, 1.0, x), std::pow(x, 3), 1e-12);  // I_x(a, 1) = x^a
    EXPECT_NEAR(RegularizedBeta(2.5, 4.0, x), 1.0 - RegularizedBeta(4.0, 2.5, 1.0 - x), 1e-12);
  }
}

TEST(GateDistributions, QuantilesMatchPublishedTables) {
  // A&S table 26.5 (F), 26.10 (t), 26.8 (chi-square); 3 decimals: tolerance 5e-4.
  EXPECT_NEAR(FQuantile(0.95, 10, 20), 2.348, 5e-4);
  EXPECT_NEAR(FQuantile(0.99, 5, 10), 5.636, 5e-4);
  EXPECT_NEAR(FQuantile(0.95, 1, 1), 161.448, 5e-3);
  EXPECT_NEAR(StudentTQuantile(0.975, 10), 2.228, 5e-4);
  EXPECT_NEAR(StudentTQuantile(0.995, 30), 2.750, 5e-4);
  EXPECT_NEAR(StudentTQuantile(0.95, 1), 6.314, 5e-4);
  EXPECT_NEAR(StudentTQuantile(0.025, 10), -2.228, 5e-4);
  EXPECT_NEAR(ChiSquareQuantile(0.95, 10), 18.307, 5e-4);
  EXPECT_NEAR(ChiSquareQuantile(0.05, 10), 3.940, 5e-4);
  EXPECT_NEAR(ChiSquareQuantile(0.975, 1), 5.024, 5e-4);
  EXPECT_NEAR(ChiSquareQuantile(0.99, 100), 135.807, 5e-4);
  EXPECT_NEAR(NormalQuantile(0.975), 1.959964, 5e-7);  // A&S 26.2 table, 6 decimals
  // CDF and quantile are inverse to the bisection's 1e-10.
  EXPECT_NEAR(FCdf(FQuantile(0.1, 199, 199), 199, 199), 0.1, 1e-10);
  EXPECT_NEAR(StudentTCdf(StudentTQuantile(0.999, 17.3), 17.3), 0.999, 1e-10);
}

TEST(GateDistributions, LargeDegreesOfFreedomApproachTheNormalLimit) {
  // chi2(k) for k = 9e5 (a NEES average of 1e5 runs): Wilson-Hilferty is accurate to O(1/k)
  // relative there (Johnson, Kotz & Balakrishnan vol. 1, 18.5); tolerance 1e-5 relative.
  // Also k = 9e6 (1e6 runs, the largest job): the series then needs ~2e4 terms, which an
  // incomplete gamma stopped at 1000 terms would not reach.
  // Both tails: the lower one is where a truncated series goes wrong.
  for (const double k : {9e5, 9e6}) {
    for (const double p : {0.025, 0.975}) {
      const double a = 2.0 / (9.0 * k), z = NormalQuantile(p);
      EXPECT_NEAR(ChiSquareQuantile(p, k) / (k * std::pow(1.0 - a + z * std::sqrt(a), 3)), 1.0,
                  1e-5)
          << k << " " << p;
    }
  }
  // F(d, d) has median 1 exactly (reciprocal symmetry); t(1e6) is within 1e-5 of the normal.
  EXPECT_NEAR(FCdf(1.0, 2e5, 2e5), 0.5, 1e-9);
  EXPECT_NEAR(StudentTQuantile(0.975, 1e6), 1.959964, 1e-5);
}

TEST(GateDistributions, BinomialTailsEqualTheDirectSums) {
  // Direct sums of C(n, i) p^i (1-p)^(n-i): exact to rounding; tolerance 1e-12.
  for (const int n : {1, 10, 37}) {
    for (const double p : {0.05, 0.5, 0.95}) {
      double cdf = 0.0;
      for (int k = 0; k <= n; ++k) {
        cdf += std::exp(std::lgamma(n + 1.0) - std::lgamma(k + 1.0) - std::lgamma(n - k + 1.0) +
                        k * std::log(p) + (n - k) * std::log1p(-p));
        EXPECT_NEAR(BinomialCdf(k, n, p), std::min(cdf, 1.0), 1e-12) << n << " " << p << " " << k;
        EXPECT_NEAR(BinomialUpperTail(k + 1, n, p), 1.0 - std::min(cdf, 1.0), 1e-12);
      }
    }
  }
  EXPECT_NEAR(BinomialCdf(5, 10, 0.5), 638.0 / 1024.0, 1e-12);
  EXPECT_EQ(BinomialCdf(-1, 10, 0.5), 0.0);
  EXPECT_EQ(BinomialUpperTail(0, 10, 0.5), 1.0);
}

}  // namespace
}  // namespace driftlab::app
