// Special functions shared by the engine (Allan-deviation intervals, Monte-Carlo statistics
// intervals) and by the clients (the CI gate's tests, the filter-consistency verdict): the
// regularised lower incomplete gamma function and the chi-square distribution built on it.
//
// References: W. H. Press et al., "Numerical Recipes", 3rd ed. (2007), section 6.2 ("NR");
// M. Abramowitz & I. A. Stegun, "Handbook of Mathematical Functions" (1964) ("A&S").
#pragma once

namespace driftlab {

// Regularised lower incomplete gamma P(a, x) = gamma(a, x) / Gamma(a), a > 0, x >= 0
// (A&S 6.5.1; NR 6.2: series 6.2.5 for x < a + 1, continued fraction 6.2.7 by the modified Lentz
// method otherwise). Both converge in O(sqrt(a)) terms; up to 1e6 are allowed, enough for the
// 9 N or more degrees of freedom of a NEES average over N = 1e6 runs. About 1e-12 relative.
double RegularizedGammaP(double a, double x);

// Q(a, x) = 1 - P(a, x), computed directly (the continued fraction for x >= a + 1, where 1 - P
// would lose the tail's relative precision).
double RegularizedGammaQ(double a, double x);

// Standard normal distribution function Phi(z) = erfc(-z / sqrt 2) / 2 = P or Q(1/2, z^2/2) / 2
// (A&S 26.2.30, 6.5.17), from the functions above (the engine's own exp and log inside, so the
// same bits on every machine, which the C library's erfc is not); ~1e-12 relative, tails
// included.
double NormalCdf(double z);

// Chi-square with k (real, > 0) degrees of freedom: P(X <= x) = P(k / 2, x / 2) (A&S 26.4.19).
double ChiSquareCdf(double x, double k);

// Quantile of the chi-square distribution with nu (real, > 0) degrees of freedom:
// x such that P(chi2_nu <= x) = p. Wilson-Hilferty start refined by Newton/bisection on
// P(nu/2, x/2) to ~1e-12 relative accuracy. Throws SpecError for p outside (0, 1) or nu <= 0.
double ChiSquareQuantile(double p, double nu);

}  // namespace driftlab
