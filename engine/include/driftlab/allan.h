// Allan deviation of inertial-sensor output: the overlapping estimator on an octave (or denser)
// grid of cluster times tau, chi-square confidence intervals, and the read-off of the IEEE Std 952
// noise terms (quantization, angle/velocity random walk, bias instability, rate random walk, rate
// ramp).
//
// Input is a series of per-interval average rates y_k = increment_k / tau0 (rad/s for a gyro,
// m/s^2 for an accelerometer) sampled at rate_hz = 1 / tau0; the Allan deviation has the unit of
// the rate. The integrated series (angle or velocity) x_i = tau0 * sum_{k<i} y_k plays the role of
// the "phase" of frequency-stability analysis and the rates that of the fractional frequency.
//
// References:
//   IEEE Std 952-1997, Annex C (Allan variance method, table C.2 of noise-term slopes).
//   W. J. Riley, "Handbook of Frequency Stability Analysis", NIST SP 1065 (2008): overlapping
//     Allan variance (section 5.2), chi-square confidence intervals (section 5.3), lag-1
//     autocorrelation noise identification (section 5.5, after Riley & Greenhall 2004).
//   D. A. Howe, D. W. Allan, J. A. Barnes, "Properties of signal sources and measurement methods",
//     Proc. 35th Freq. Control Symp. (1981), reprinted in NIST Technical Note 1337 (1990): table
//     12-4 (TN-85), degrees of freedom of the overlapping Allan variance per noise type.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "driftlab/special_functions.h"  // ChiSquareQuantile (interval of each point)

namespace driftlab {

// Power-law noise type of the rate signal at one tau, named in the frequency-stability convention
// (S_y(f) ~ f^alpha) with the inertial meaning in brackets. Slope of ADEV vs tau on log-log axes:
// white/flicker PM -1, white FM -1/2, flicker FM 0, random-walk FM +1/2.
enum class AllanNoiseType {
  kAuto = 100,         // identify per tau (lag-1 autocorrelation, NIST SP 1065 section 5.5)
  kWhitePm = 2,        // alpha = +2: white angle noise [quantization noise]
  kFlickerPm = 1,      // alpha = +1: flicker angle noise
  kWhiteFm = 0,        // alpha =  0: white rate noise [angle random walk N]
  kFlickerFm = -1,     // alpha = -1: flicker rate noise [bias instability B]
  kRandomWalkFm = -2,  // alpha = -2: random-walk rate [rate random walk K]
};

struct AllanOptions {
  // Tau grid m = round(2^(j / points_per_octave)) tau0, j = 0, 1, ..., duplicates removed, up to
  // the largest m with at least two overlapping second differences (m <= (n - 1) / 2).
  int points_per_octave = 1;
  // Two-sided confidence level of [adev_low, adev_high].
  double confidence = 0.95;
  // Noise type assumed for the equivalent degrees of freedom; kAuto identifies it per tau.
  AllanNoiseType noise_type = AllanNoiseType::kAuto;
};

// One point of an Allan-deviation curve. Units: tau_s [s]; adev and its bounds in the unit of the
// input rates (rad/s or m/s^2).
struct AllanPoint {
  double tau_s = 0.0;      // cluster time m * tau0
  double adev = 0.0;       // overlapping Allan deviation sigma_y(tau)
  double adev_low = 0.0;   // lower bound of the two-sided confidence interval
  double adev_high = 0.0;  // upper bound
  double edf = 0.0;        // equivalent degrees of freedom of the variance estimate
  int64_t n_clusters = 0;  // number of overlapping second differences averaged (n + 1 - 2m)
  int64_t m = 0;           // averaging factor, tau = m tau0
  AllanNoiseType noise_type = AllanNoiseType::kWhiteFm;  // noise type used for the EDF
};

// Overlapping Allan deviation of the rate series (NIST SP 1065 eq. (12) on the integrated series
//   x_i = tau0 sum_{k<i} y_k,  i = 0..n):
//   AVAR(m tau0) = 1 / (2 (m tau0)^2 (n + 1 - 2m)) sum_{i=0}^{n-2m} (x_{i+2m} - 2 x_{i+m} + x_i)^2.
// O(n) per tau through the cumulative sum. Throws SpecError for rate_hz <= 0, non-finite samples,
// fewer than 3 samples, points_per_octave outside [1, 64] or a confidence outside (0, 1).
std::vector<AllanPoint> OverlappingAllanDeviation(std::span<const double> rate_samples,
                                                  double rate_hz, const AllanOptions& options);
std::vector<AllanPoint> OverlappingAllanDeviation(std::span<const double> rate_samples,
                                                  double rate_hz, int points_per_octave = 1);

// Equivalent degrees of freedom of the overlapping Allan variance for power-law noise, the
// approximations of Howe, Allan & Barnes (1981), NIST TN 1337 table 12-4, also in NIST SP 1065.
// n_phase = number of integrated (phase) points = number of rate samples + 1; m = averaging factor.
double OverlappingAdevEdf(AllanNoiseType noise_type, int64_t n_phase, int64_t m);

// Noise-term read-off from an Allan curve (IEEE Std 952-1997 Annex C, table C.2). For a gyro the
// rates are rad/s and: N [rad/sqrt(s)], B [rad/s], K [rad/s/sqrt(s)], Q [rad], R [rad/s^2]; for an
// accelerometer replace rad by m/s. A term not identifiable on the curve is NaN.
//   quantization   ADEV = sqrt(3) Q / tau            slope -1   -> Q = ADEV_fit(sqrt(3) s)
//   white noise    ADEV = N / sqrt(tau)              slope -1/2 -> N = ADEV_fit(1 s)
//   bias instab.   ADEV = sqrt(2 ln 2 / pi) B ~ 0.664 B  flat   -> B = min ADEV / 0.664
//   rate RW        ADEV = K sqrt(tau / 3)            slope +1/2 -> K = ADEV_fit(3 s)
//   rate ramp      ADEV = R tau / sqrt(2)            slope +1   -> R = ADEV_fit(sqrt(2) s)
// Each slope fit is a fixed-slope line through the points whose local log-log slope is within
// max(0.05, 2 sigma) of the term's slope (sigma = standard error of that local slope), weighted by
// the EDF (var(ln adev) ~ 1 / (2 edf)); see allan.cc for why 0.05 (<= 5.4 % bias per point).
struct AllanTermFit {
  double value = std::numeric_limits<double>::quiet_NaN();
  double tau_min_s = std::numeric_limits<double>::quiet_NaN();  // range of tau used
  double tau_max_s = std::numeric_limits<double>::quiet_NaN();
  int n_points = 0;
  bool found() const { return n_points > 0; }
};

struct AllanReadOff {
  AllanTermFit quantization;      // Q
  AllanTermFit white_noise;       // N (angle / velocity random walk)
  AllanTermFit bias_instability;  // B; found only for an interior minimum of the curve
  AllanTermFit random_walk;       // K (rate / acceleration random walk)
  AllanTermFit rate_ramp;         // R
};

AllanReadOff ReadOffNoiseTerms(std::span<const AllanPoint> curve);

// Theoretical Allan deviation of the sum of independent noise terms (IEEE Std 952 table C.2;
// the bias-instability term is its flat asymptote):
//   AVAR = 3 Q^2 / tau^2 + N^2 / tau + (2 ln 2 / pi) B^2 + K^2 tau / 3 + R^2 tau^2 / 2.
double AllanCurveModel(double tau_s, double N, double B, double K, double Q, double R);

}  // namespace driftlab
