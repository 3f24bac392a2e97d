// The CI gate's hypothesis tests (gate.h): one test per kind of statistic, each deciding
//   H0: current <= limit_ratio * baseline   against   H1: current > limit_ratio * baseline
// (limit_ratio = 1 + tolerance) from the two samples, and giving a two-sided (1 - alpha) interval
// of the ratio current / baseline. A small p-value means the data show a regression beyond the
// tolerance; the gate combines the p-values of all gated metrics with Holm's procedure.
//
// Independent samples (different seeds, run counts or random streams):
//   sigma     variance ratio: s_c^2 / (rho^2 s_b^2) ~ F(n_c - 1, n_b - 1) under H0 (normal errors;
//             A&S 26.6; Snedecor & Cochran, Statistical Methods, 8th ed., sec. 6.12)
//   RMS       the same with n degrees of freedom: N rms^2 / sigma^2 ~ chi2(N) for zero-mean normal
//             errors, and the ratio of two scaled chi-squares is F(n_c, n_b)
//   |mean|    Welch's t on |m_c| - rho |m_b| with Welch-Satterthwaite degrees of freedom
//             (Welch, Biometrika 34, 1947)
//   quantile  distribution-free: order statistics X_(k) of n values bound the p-quantile q with
//             P(X_(k) > q) = P(Bin(n, p) <= k - 1) and P(X_(k) < q) = P(Bin(n, p) >= k)
//             (David & Nagaraja, Order Statistics, 3rd ed., sec. 7.1); a lower bound of the current
//             quantile above rho times an upper bound of the baseline's rejects H0, with the two
//             error probabilities added (Bonferroni), so no assumption on the distribution, and
//             valid for paired samples as well
//   NEES      each run's NEES is chi2(d) for a consistent filter, the N-run average chi2(d N) / N
//             (Bar-Shalom et al. 5.4.2): the ratio of two averages is F(d n_c, d n_b)
// Paired samples (same seed and runs, per-run values of both results):
//   sigma     Pitman-Morgan: with Y' = Y / rho, var(Y') - var(X) = cov(X + Y', Y' - X), so H0 is
//             corr(X + Y', Y' - X) <= 0, tested by t = r sqrt((n - 2) / (1 - r^2)) ~ t(n - 2)
//             (Pitman, Biometrika 31, 1939; Morgan, Biometrika 31, 1939)
//   RMS       paired t on d_i = y_i^2 - rho^2 x_i^2 (t(n - 1), large-sample)
//   |mean|    paired t on d_i = s_c y_i - rho s_b x_i, s = the sign of each sample mean
//   quantile  paired bootstrap of the ratio of the two quantiles (runs resampled together, B =
//             kBootstrapResamples, fixed seed): p = (1 + #{ratio* <= rho}) / (B + 1), percentile
//             interval (Efron & Tibshirani, An Introduction to the Bootstrap, 1993, ch. 13, 16)
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace driftlab::app {

struct TestOutcome {
  double p_value = 1.0;    // one-sided, of H0: current <= limit_ratio * baseline
  double ratio = 1.0;      // current / baseline estimate
  double ratio_low = 0.0;  // two-sided (1 - alpha) interval of the population ratio
  double ratio_high = 0.0;
  std::string test;  // e.g. "F(199, 199) variance ratio"
};

TestOutcome TestSigmaIndependent(double s_b, double n_b, double s_c, double n_c, double limit_ratio,
                                 double alpha);
TestOutcome TestRmsIndependent(double rms_b, double n_b, double rms_c, double n_c,
                               double limit_ratio, double alpha);
TestOutcome TestAbsMeanWelch(double mean_b, double s_b, double n_b, double mean_c, double s_c,
                             double n_c, double limit_ratio, double alpha);
// `baseline`, `current`: the per-run values whose p-quantile is compared (|error|), any order.
TestOutcome TestQuantile(std::vector<double> baseline, std::vector<double> current, double p,
                         double limit_ratio, double alpha);
// Average NEES with d * N degrees of freedom each.
TestOutcome TestNees(double nees_b, double dof_b, double nees_c, double dof_c, double limit_ratio,
                     double alpha);

// Paired: x[i] and y[i] are run i of the baseline and of the current result (same random
// numbers), x.size() == y.size() >= 3.
TestOutcome TestSigmaPaired(const std::vector<double>& x, const std::vector<double>& y,
                            double limit_ratio, double alpha);
TestOutcome TestRmsPaired(const std::vector<double>& x, const std::vector<double>& y,
                          double limit_ratio, double alpha);
inline constexpr int kBootstrapResamples = 3999;
// Above this run count the gate uses TestQuantile for paired samples too (cost B x n per metric).
inline constexpr size_t kMaxBootstrapRuns = 2000;
// x, y: |error| of the runs, paired.
TestOutcome TestQuantilePaired(const std::vector<double>& x, const std::vector<double>& y, double p,
                               double limit_ratio, double alpha);
TestOutcome TestAbsMeanPaired(const std::vector<double>& x, const std::vector<double>& y,
                              double limit_ratio, double alpha);

// Holm's step-down procedure (Holm, Scand. J. Statist. 6, 1979): rejected[i] when p[i] is
// among the hypotheses rejected at family-wise error rate alpha.
std::vector<bool> HolmReject(const std::vector<double>& p_values, double alpha);

// Planning, for the variance-ratio test (sigma) at one-sided level `alpha_per_test`:
// the smallest true ratio sigma_c / sigma_b detected with probability `power` by samples of
// n_b and n_c runs when the limit is limit_ratio: rho sqrt(F_{1-a}(nu_c, nu_b) / F_{1-power}(...))
// (the rejection region s_c^2 / s_b^2 > rho^2 F_{1-a}, with s_c^2 / s_b^2 = R^2 F).
double DetectableSigmaRatio(double n_b, double n_c, double limit_ratio, double alpha_per_test,
                            double power);
// The smallest equal run count n (both files) for which DetectableSigmaRatio(n, n, ...) <=
// true_ratio; 0 when none up to 1e7 (true_ratio <= limit_ratio).
long RunsToDetectSigmaRatio(double true_ratio, double limit_ratio, double alpha_per_test,
                            double power);

}  // namespace driftlab::app
