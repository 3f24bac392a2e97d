// Probability distributions the CI gate's hypothesis tests need (gate_statistics.h): the
// regularised incomplete gamma and beta functions and, built on them, the CDFs and quantiles of
// the chi-square, Student t, F, binomial and standard normal distributions.
//
// References: W. H. Press et al., "Numerical Recipes", 3rd ed. (2007), sections 6.1-6.4 and 6.14
// ("NR"); M. Abramowitz & I. A. Stegun, "Handbook of Mathematical Functions" (1964) ("A&S").
// Accuracy: about 1e-12 relative for the functions, 1e-10 for the quantiles (bisection), far
// below what a gate decision depends on.
#pragma once

// The incomplete gamma function and the chi-square CDF and quantile are the engine's
// (driftlab::RegularizedGammaP, ChiSquareCdf, ChiSquareQuantile), found from this namespace.
#include "driftlab/special_functions.h"

namespace driftlab::app {

// Regularised incomplete beta I_x(a, b), a, b > 0, 0 <= x <= 1 (A&S 26.5.1; NR 6.4: continued
// fraction 6.4.5 by the modified Lentz method, with the symmetry I_x(a, b) = 1 - I_1-x(b, a)).
double RegularizedBeta(double a, double b, double x);

// Standard normal CDF Phi(z) = erfc(-z / sqrt 2) / 2 (A&S 26.2.29) and its inverse.
double NormalCdf(double z);
double NormalQuantile(double p);

// Student t with nu degrees of freedom: P(T <= t); 1 - P(T <= |t|) = I_{nu/(nu+t^2)}(nu/2, 1/2) / 2
// (A&S 26.7.1 with 26.5.27; NR 6.14.10). nu may be fractional (Welch-Satterthwaite).
double StudentTCdf(double t, double nu);
double StudentTQuantile(double p, double nu);

// F with (d1, d2) degrees of freedom: P(F <= f) = I_{d1 f / (d1 f + d2)}(d1 / 2, d2 / 2)
// (A&S 26.6.2).
double FCdf(double f, double d1, double d2);
double FQuantile(double p, double d1, double d2);

// Binomial(n, p): P(X <= k) = I_{1-p}(n - k, k + 1) for 0 <= k < n (A&S 26.5.24); 0 for k < 0,
// 1 for k >= n. P(X >= k) = 1 - P(X <= k - 1) = I_p(k, n - k + 1) for 1 <= k <= n.
double BinomialCdf(long k, long n, double p);
double BinomialUpperTail(long k, long n, double p);

}  // namespace driftlab::app
