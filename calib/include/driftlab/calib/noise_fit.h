// Noise-model fit of Allan-deviation curves: a weighted least-squares fit, with Ceres, of the
// IEEE Std 952-1997 Annex C noise terms to one or more overlapping Allan-deviation curves of a
// sensor (allan.h), giving each term with its 1-sigma uncertainty and a triad error model
// (sensor_params.h) that the engine can simulate.
//
// Model (Allan variance [u^2] at averaging time t [s]; u = rad/s for a gyro, m/s^2 for an
// accelerometer; IEEE Std 952-1997 Annex C, table C.2):
//   AVAR(t) = 3 Q^2 / t^2 + N^2 / t + B^2 F(t) + K^2 t / 3 + R^2 t^2 / 2
//   Q quantization [u s] (rad or m/s), N white noise [u/sqrt(Hz)] (ARW / VRW), B bias instability
//   [u], K rate / acceleration random walk [u sqrt(Hz)], R rate ramp [u/s];
//   F(t) = 2 ln 2 / pi (flat flicker floor, 0.664^2; BiasModel::kFlickerFlat), or the Allan
//   variance per unit B^2 of the engine's band-limited flicker approximation over
//   [flicker_tau_min_s, flicker_tau_max_s] (DesignFlickerApproximation; kFlickerBand), or instead
//   of B^2 F(t) a first-order Gauss-Markov bias sigma^2 A_GM(t; tau) (GaussMarkovAllanVariance;
//   kGaussMarkov).
//
// Fit: the model is linear in the variance coefficients a = (Q^2, N^2, B^2 or sigma_GM^2, K^2,
// R^2), each kept >= 0 by a Ceres lower bound (so a term can sit at 0 with a finite Jacobian and a
// finite covariance); the Gauss-Markov correlation time enters as ln tau. The residual of point i
//   r_i = (ln AVAR_model(t_i) - [ln AVAR_i - b(edf_i)]) / s_i,   s_i = sqrt(2 / edf_i)
// weights every tau by its confidence: AVAR_i edf_i / AVAR is chi-square with edf_i degrees of
// freedom, so var(ln AVAR_i) = psi'(edf/2) ~ 2 / edf and E[ln AVAR_i] - ln AVAR = psi(edf/2) -
// ln(edf/2) = b(edf) ~ -1/edf (bias removed; NIST SP 1065 section 5.3 for the chi-square model).
// The points of one curve are not independent: overlapping estimates at neighbouring tau share
// data. The fit is a generalised least squares: the r_i of one curve are whitened with the
// Cholesky factor of their correlation matrix, rho(m_i, m_j) of the overlapping Allan variance of
// white rate noise (computed exactly from the estimator's weights, noise_fit.cc
// WhiteFmAvarCorrelation; points without m, e.g. synthetic curves, count as independent), so
// chi2 = r^T C^-1 r. Curves (axes) are independent of each other.
// Uncertainties: ceres::Covariance of the coefficients, scaled by the reduced chi-square when it
// exceeds 1; a term's amplitude c = sqrt(a) has sigma_c = sigma_a / (2 c).
//
// Term selection (which terms the data support), a nested-model likelihood-ratio test by backward
// elimination: with chi2(M) the (whitened) chi-square of the best fit of model M (the whitened
// residuals are approximately independent standard normal, so -2 ln L = chi2 + const), dropping
// term k from the current model M gives
//   D_k = [chi2(M without k) - chi2(M)] / max(1, chi2(M) / dof(M)),
// the likelihood-ratio statistic (Wilks 1938; Casella & Berger, Statistical Inference, 2nd ed.,
// section 10.3.1), scaled by the residual variance when the fit is worse than its weights say
// (the usual F-type correction). The other terms are refitted in M without k, so the test uses
// the correlations between terms: a term is not lost because another term with an overlapping
// signature (e.g. B beside K and R at the few long-tau points) shares its variance. Because a >= 0
// the null value a_k = 0 lies on the boundary, where D_k is distributed as the mixture
// 1/2 chi2_0 + 1/2 chi2_1 (Chernoff 1954; Self & Liang, JASA 82 (1987) 605, case 1), so the test
// at false-inclusion rate alpha = 1 - confidence keeps k when D_k >= chi2_1 quantile(1 - 2 alpha)
// (9.55 at the default confidence 0.999; 5.41 at 0.99). The Gauss-Markov bias (sigma and tau leave
// together) uses chi2_2 quantile(confidence). The term with the smallest D_k is dropped and the
// test repeated until every remaining term passes. Kept terms ("determined") carry sigma and a
// two-sided 95 % interval of the amplitude from the final fit's covariance (all correlations
// included, scaled by the reduced chi-square when > 1): [sqrt(max(0, a - 1.96 sigma_a)), sqrt(a
// + 1.96 sigma_a)]. Dropped terms carry an upper bound c_up = sqrt(max(a, 0) + 1.645 sigma_a) (95 %
// one-sided) from the last fit that included them.
//
// Goodness of fit: the fitted curve is compared with each point's 95 % chi-square interval
// [adev_low, adev_high] (allan.h, NIST SP 1065 section 5.3); a correct model leaves about 5 % of
// the points outside, so any point outside is counted and reported, and the fit is flagged when the
// count exceeds the binomial(n, 0.05) 99 % quantile. chi2 = sum r_i^2 is compared with the chi2_dof
// distribution: outside its [0.1 %, 99.9 %] quantiles the fit is flagged as implausible (too poor:
// the model misses a feature of the data; too good: the weights are wrong).
// Known limit: the whitening uses the white-FM correlation everywhere; where flicker dominates the
// points are more correlated, so D is overstated there. On 2-hour records of sensors whose floor
// appears only in the last octaves, B is sometimes dropped or replaced by K (measured rates in
// tests/calib/noise_fit_static_record_slow_test.cc).
#pragma once

#include <limits>
#include <span>
#include <string>
#include <vector>

#include "driftlab/allan.h"
#include "driftlab/sensor_params.h"

namespace driftlab::calib {

enum class BiasModel {
  kFlickerFlat,  // IEEE flat floor (2 ln 2 / pi) B^2 at every tau
  kFlickerBand,  // the engine's flicker approximation over [flicker_tau_min_s, flicker_tau_max_s]
  kGaussMarkov,  // first-order Gauss-Markov bias, sigma and tau fitted
  kNone,         // no bias-instability term
};

struct NoiseFitOptions {
  BiasModel bias_model = BiasModel::kFlickerFlat;
  // Flicker band [s]: kFlickerBand uses it in the fit; both flicker models write it into the
  // triad model (FlickerParams). 0 = the first / last tau of the curves.
  double flicker_tau_min_s = 0.0;
  double flicker_tau_max_s = 0.0;
  bool fit_quantization = true;
  bool fit_white_noise = true;
  bool fit_random_walk = true;
  bool fit_rate_ramp = true;
  // Confidence of the term-selection test (above): a term absent from the data is kept with
  // probability about 1 - confidence per test.
  double confidence = 0.999;
  int max_iterations = 200;
};

// One fitted term in SI units (see the model above for each term's unit).
struct NoiseTermEstimate {
  bool fitted = false;                                         // the term was part of the model
  bool determined = false;                                     // the data determine it (see above)
  double value = 0.0;                                          // amplitude; 0 when not determined
  double sigma = std::numeric_limits<double>::quiet_NaN();     // 1 sigma of value
  double lower_95 = std::numeric_limits<double>::quiet_NaN();  // 95 % interval (determined)
  double upper_95 = std::numeric_limits<double>::quiet_NaN();
  double upper_bound = std::numeric_limits<double>::quiet_NaN();  // 95 % bound (not determined)
  // Likelihood-ratio statistic D_k of the term (above) when it was last tested, and the threshold.
  double lr_statistic = std::numeric_limits<double>::quiet_NaN();
  double lr_threshold = std::numeric_limits<double>::quiet_NaN();
};

struct NoiseFitResult {
  NoiseTermEstimate quantization;        // Q [rad] or [m/s] (IEEE Q = LSB / sqrt(12))
  NoiseTermEstimate white_noise;         // N
  NoiseTermEstimate bias_instability;    // B (flicker) or sigma (Gauss-Markov)
  NoiseTermEstimate gauss_markov_tau_s;  // Gauss-Markov correlation time [s] (kGaussMarkov only)
  NoiseTermEstimate random_walk;         // K
  NoiseTermEstimate rate_ramp;           // R (no term in the engine's model; reported only)
  BiasModel bias_model = BiasModel::kFlickerFlat;
  double flicker_tau_min_s = 0.0;  // band written into the triad model
  double flicker_tau_max_s = 0.0;
  int n_points = 0;           // ADEV points used (all curves)
  int n_parameters = 0;       // in the final fit
  double residual_rms = 0.0;  // RMS of the normalised residuals r_i (~1 for a good fit)
  double chi2_per_dof = 0.0;  // sum r_i^2 / (n_points - n_parameters)
  int iterations = 0;         // Ceres iterations, all passes
  int passes = 0;             // fits run (selection included)
  double fit_time_s = 0.0;
  // Goodness of fit (above).
  int points_outside_95 = 0;         // points whose 95 % interval excludes the fitted curve
  double expected_outside_95 = 0.0;  // 0.05 n_points
  int max_plausible_outside_95 = 0;  // binomial(n_points, 0.05) 99 % quantile
  double chi2 = 0.0;
  double chi2_low = 0.0;  // chi2_dof 0.1 % and 99.9 % quantiles
  double chi2_high = 0.0;
  std::vector<double> tau_outside_95_s;  // the taus of the points outside
  std::vector<std::string> warnings;     // one sentence each; empty for a plausible fit
};

// Fits the model to the curves (all of one sensor kind, e.g. the three axes of a triad: one
// parameter set for all). Points with edf <= 0 or adev <= 0 are skipped. Throws SpecError for
// no usable points, fewer points than parameters, an invalid option or a failed covariance.
NoiseFitResult FitAllanNoiseModel(std::span<const std::vector<AllanPoint>> curves,
                                  const NoiseFitOptions& options = {});
NoiseFitResult FitAllanNoiseModel(std::span<const AllanPoint> curve,
                                  const NoiseFitOptions& options = {});

// Allan deviation [u] of the fitted model at t (determined terms only).
double FittedAllanDeviation(const NoiseFitResult& fit, double tau_s);

// The noise terms of the fit as a triad model: white_noise_density = N, random_walk = K,
// quantization (LSB) = sqrt(12) Q, bias_flicker = {B, band} or bias_gauss_markov = {sigma, tau};
// all other fields zero. The rate ramp has no term in TriadErrorParams and is left out.
TriadErrorParams ToTriadErrorParams(const NoiseFitResult& fit);

// Text table of the fitted terms (value +- 1 sigma [95 % interval], or "not determined (< upper
// bound)"), the selection rule, the goodness-of-fit line and the warnings, in
// datasheet units, next to `reference` (e.g. a datasheet's or preset's triad) when given.
// gyro selects the units: deg/sqrt(h), deg/h, deg/h/sqrt(h), urad, deg/h/h; else m/s/sqrt(h), ug,
// ug/sqrt(s), mm/s, ug/h.
std::string FormatNoiseFit(const NoiseFitResult& fit, bool gyro,
                           const TriadErrorParams* reference = nullptr,
                           const std::string& reference_name = "");

const char* BiasModelName(BiasModel model);

}  // namespace driftlab::calib
