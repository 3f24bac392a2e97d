#include "driftlab/allan.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <span>
#include <string>

#include "driftlab/elementary.h"
#include "driftlab/spec_error.h"

namespace driftlab {
namespace {

// %g of a number, for messages.
std::string G6(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

// Integrated series x_i = sum_{k<i} (y_k - mean(y)), i = 0..n, in units of rate * sample.
// Removing the mean first leaves every second difference unchanged (it annihilates a linear
// phase) and keeps x small, so the second differences lose fewer digits to cancellation. Both
// sums are Kahan-compensated (Higham, "Accuracy and Stability of Numerical Algorithms", 4.3).
std::vector<double> IntegratedSeries(std::span<const double> y) {
  double sum = 0.0, c = 0.0;
  for (const double v : y) {
    const double t = sum + (v - c);
    c = (t - sum) - (v - c);
    sum = t;
  }
  const double mean = sum / static_cast<double>(y.size());
  std::vector<double> x(y.size() + 1);
  x[0] = 0.0;
  sum = 0.0;
  c = 0.0;
  for (size_t k = 0; k < y.size(); ++k) {
    const double v = (y[k] - mean) - c;
    const double t = sum + v;
    c = (t - sum) - v;
    sum = t;
    x[k + 1] = sum;
  }
  return x;
}

// Sum over i of (x_{i+2m} - 2 x_{i+m} + x_i)^2, i = 0..n_phase-2m-1. Four interleaved partial
// sums in a fixed order (deterministic, independent of threads).
double SecondDifferenceSumOfSquares(const std::vector<double>& x, int64_t m) {
  const int64_t terms = static_cast<int64_t>(x.size()) - 2 * m;
  const double* p = x.data();
  double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
  int64_t i = 0;
  for (; i + 4 <= terms; i += 4) {
    const double d0 = p[i + 2 * m] - 2.0 * p[i + m] + p[i];
    const double d1 = p[i + 1 + 2 * m] - 2.0 * p[i + 1 + m] + p[i + 1];
    const double d2 = p[i + 2 + 2 * m] - 2.0 * p[i + 2 + m] + p[i + 2];
    const double d3 = p[i + 3 + 2 * m] - 2.0 * p[i + 3 + m] + p[i + 3];
    s0 += d0 * d0;
    s1 += d1 * d1;
    s2 += d2 * d2;
    s3 += d3 * d3;
  }
  for (; i < terms; ++i) {
    const double d = p[i + 2 * m] - 2.0 * p[i + m] + p[i];
    s0 += d * d;
  }
  return (s0 + s1) + (s2 + s3);
}

// Lag-1 autocorrelation of z (mean removed).
double Lag1Autocorrelation(const std::vector<double>& z) {
  double mean = 0.0;
  for (const double v : z) mean += v;
  mean /= static_cast<double>(z.size());
  double num = 0.0, den = 0.0;
  for (size_t i = 0; i < z.size(); ++i) {
    const double a = z[i] - mean;
    den += a * a;
    if (i + 1 < z.size()) num += a * (z[i + 1] - mean);
  }
  return den > 0.0 ? num / den : 0.0;
}

// Minimum number of averaged points for the lag-1 autocorrelation identification. Riley & Greenhall
// (2004) report it works from about 30 points, but the estimate of alpha = -2 r1 / (1 + r1) has a
// standard error of about 2 / sqrt(n) (var(r1) ~ 1 / n for white noise), so with 30 points it
// lands on the wrong side of the +-0.5 rounding boundary ~16 % of the time, and the EDF of white
// FM mistaken for flicker PM is 10x too large at long tau. With 128 points the standard error is
// 0.18 and a misidentification a 2.8-sigma (0.5 %) event.
constexpr int64_t kMinPointsForNoiseId = 128;

// Power-law noise identification by the lag-1 autocorrelation of the m-averaged rate series
// (Riley & Greenhall, "Power law noise identification using the lag 1 autocorrelation", Proc.
// 18th EFTF 2004; NIST SP 1065 section 5.5). For discrete power-law (fractionally differenced)
// noise with spectrum ~ f^p the lag-1 autocorrelation is rho = -p / (2 + p), so
// delta = rho / (1 + rho) = -p / 2. The series is differenced d times (each raises p by 2) until
// delta < 0.25 (stationary) or d = 2, and then alpha = -2 (delta + d) for rate ("frequency") data.
// Rounded to the nearest integer in [-2, 2]. Returns false when fewer than kMinPointsForNoiseId
// averages exist.
bool IdentifyNoiseType(const std::vector<double>& x, int64_t m, AllanNoiseType* type) {
  const int64_t n_avg = (static_cast<int64_t>(x.size()) - 1) / m;
  if (n_avg < kMinPointsForNoiseId) return false;
  std::vector<double> z(static_cast<size_t>(n_avg));
  for (int64_t j = 0; j < n_avg; ++j) z[j] = x[(j + 1) * m] - x[j * m];  // m * block mean
  constexpr int kMaxDifferences = 2;
  double alpha = 0.0;
  for (int d = 0;; ++d) {
    const double rho = Lag1Autocorrelation(z);
    const double delta = rho / (1.0 + rho);
    if (delta < 0.25 || d >= kMaxDifferences) {
      alpha = -2.0 * (delta + d);
      break;
    }
    for (size_t i = 0; i + 1 < z.size(); ++i) z[i] = z[i + 1] - z[i];
    z.pop_back();
  }
  const int alpha_int = static_cast<int>(std::clamp(std::lround(alpha), -2L, 2L));
  *type = static_cast<AllanNoiseType>(alpha_int);
  return true;
}

// Tau grid: m_j = round(2^(j / ppo)), distinct, 1 <= m <= (n - 1) / 2.
std::vector<int64_t> AveragingFactors(int64_t n, int points_per_octave) {
  std::vector<int64_t> ms;
  const int64_t m_max = (n - 1) / 2;
  for (int j = 0;; ++j) {
    const auto m =
        static_cast<int64_t>(std::llround(std::exp2(static_cast<double>(j) / points_per_octave)));
    if (m > m_max) break;
    if (ms.empty() || m != ms.back()) ms.push_back(m);
  }
  return ms;
}

}  // namespace

double OverlappingAdevEdf(AllanNoiseType noise_type, int64_t n_phase, int64_t m) {
  // Howe, Allan & Barnes, "Properties of signal sources and measurement methods", Proc. 35th
  // Annual Symposium on Frequency Control (1981), reprinted as NIST Technical Note 1337 (1990)
  // table 12-4; N = phase points, m = averaging factor, tau = m tau0.
  const double N = static_cast<double>(n_phase);
  const double M = static_cast<double>(m);
  double edf = 1.0;
  switch (noise_type) {
    case AllanNoiseType::kWhitePm:  // (N + 1)(N - 2m) / (2 (N - m))
      edf = (N + 1.0) * (N - 2.0 * M) / (2.0 * (N - M));
      break;
    case AllanNoiseType::kFlickerPm:  // exp(sqrt(ln((N - 1) / 2m) ln((2m + 1)(N - 1) / 4)))
      edf = math::Exp(std::sqrt(std::max(
          0.0, math::Log((N - 1.0) / (2.0 * M)) * math::Log((2.0 * M + 1.0) * (N - 1.0) / 4.0))));
      break;
    case AllanNoiseType::kWhiteFm:  // (3 (N - 1) / 2m - 2 (N - 2) / N) 4 m^2 / (4 m^2 + 5)
      edf = (3.0 * (N - 1.0) / (2.0 * M) - 2.0 * (N - 2.0) / N) * 4.0 * M * M / (4.0 * M * M + 5.0);
      break;
    case AllanNoiseType::kFlickerFm:  // m = 1: 2 (N - 2) / (2.3 N - 4.9); m >= 2: 5 N^2 / (4m (N +
                                      // 3m))
      edf = m == 1 ? 2.0 * (N - 2.0) / (2.3 * N - 4.9) : 5.0 * N * N / (4.0 * M * (N + 3.0 * M));
      break;
    case AllanNoiseType::kRandomWalkFm:  // (N - 2)/m ((N - 1)^2 - 3m (N - 1) + 4 m^2) / (N - 3)^2
      edf = (N - 2.0) / M * ((N - 1.0) * (N - 1.0) - 3.0 * M * (N - 1.0) + 4.0 * M * M) /
            ((N - 3.0) * (N - 3.0));
      break;
    case AllanNoiseType::kAuto:
      throw SpecError("allan.noise_type", "auto", "a power-law noise type (white PM .. RW FM)");
  }
  // At the largest tau (m ~ (N - 2) / 2) all the approximations tend to ~1; keep a floor so that
  // the chi-square quantile is defined for small N where the formulas can dip below it.
  return std::max(edf, 1.0);
}

std::vector<AllanPoint> OverlappingAllanDeviation(std::span<const double> rate_samples,
                                                  double rate_hz, const AllanOptions& options) {
  if (!(rate_hz > 0.0 && std::isfinite(rate_hz)))
    throw SpecError("allan.rate_hz", std::to_string(rate_hz), "> 0, finite");
  if (rate_samples.size() < 3)
    throw SpecError("allan.samples", std::to_string(rate_samples.size()) + " samples",
                    ">= 3 samples");
  if (options.points_per_octave < 1 || options.points_per_octave > 64)
    throw SpecError("allan.points_per_octave", std::to_string(options.points_per_octave),
                    "1 .. 64");
  if (!(options.confidence > 0.0 && options.confidence < 1.0))
    throw SpecError("allan.confidence", std::to_string(options.confidence), "(0, 1)");
  for (size_t k = 0; k < rate_samples.size(); ++k) {
    if (!std::isfinite(rate_samples[k]))
      throw SpecError("allan.samples[" + std::to_string(k) + "]", std::to_string(rate_samples[k]),
                      "finite numbers");
  }

  // Values of huge magnitude (a corrupt recording, or ~1e308 on purpose) would overflow the squares
  // of the second differences to inf. Such data are scaled by a power of two first: power-of-two
  // scaling is exact in binary floating point (IEEE 754: no rounding without overflow or
  // underflow), so the scaled computation gives the same deviation, times the scale. Ordinary data
  // (below 2^500 ~ 3e150) are not scaled and give bit-identical results.
  double max_abs = 0.0;
  for (const double v : rate_samples) max_abs = std::max(max_abs, std::abs(v));
  double scale = 1.0;
  std::vector<double> scaled;
  std::span<const double> samples = rate_samples;
  if (max_abs > 0x1p500) {
    scale = std::ldexp(1.0, std::ilogb(max_abs) + 1);
    scaled.resize(rate_samples.size());
    for (size_t k = 0; k < rate_samples.size(); ++k) scaled[k] = rate_samples[k] / scale;
    samples = scaled;
  }

  const int64_t n = static_cast<int64_t>(rate_samples.size());
  const double tau0_s = 1.0 / rate_hz;
  const std::vector<double> x = IntegratedSeries(samples);
  const std::vector<int64_t> ms = AveragingFactors(n, options.points_per_octave);

  std::vector<AllanPoint> curve(ms.size());
  std::vector<char> identified(ms.size(), 0);
  // Each tau is independent and its sum has a fixed order, so the result does not depend on the
  // thread count or the scheduling.
  tbb::parallel_for(size_t{0}, ms.size(), [&](size_t j) {
    const int64_t m = ms[j];
    const int64_t terms = n + 1 - 2 * m;
    AllanPoint& point = curve[j];
    point.m = m;
    point.tau_s = static_cast<double>(m) * tau0_s;
    point.n_clusters = terms;
    // x is in rate * sample units: AVAR = sum / (2 m^2 terms) in rate^2.
    const double avar = SecondDifferenceSumOfSquares(x, m) /
                        (2.0 * static_cast<double>(m) * static_cast<double>(m) * terms);
    point.adev = std::sqrt(avar) * scale;
    if (options.noise_type == AllanNoiseType::kAuto) {
      identified[j] = IdentifyNoiseType(x, m, &point.noise_type) ? 1 : 0;
    } else {
      point.noise_type = options.noise_type;
    }
  });

  // Too few averages to identify the noise at the longest taus: carry the type identified at the
  // longest tau that had enough (white FM if none did).
  if (options.noise_type == AllanNoiseType::kAuto) {
    AllanNoiseType last = AllanNoiseType::kWhiteFm;
    for (size_t j = 0; j < curve.size(); ++j) {
      if (identified[j]) {
        last = curve[j].noise_type;
      } else {
        curve[j].noise_type = last;
      }
    }
  }

  // Chi-square interval for the variance: edf s^2 / sigma^2 ~ chi2(edf) (NIST SP 1065 section
  // 5.3, eq. for the chi-square confidence interval), so
  //   sigma in [s sqrt(edf / chi2_{(1+c)/2}), s sqrt(edf / chi2_{(1-c)/2})].
  const double p_low = 0.5 * (1.0 - options.confidence);
  const double p_high = 0.5 * (1.0 + options.confidence);
  for (AllanPoint& point : curve) {
    point.edf = OverlappingAdevEdf(point.noise_type, n + 1, point.m);
    point.adev_low = point.adev * std::sqrt(point.edf / ChiSquareQuantile(p_high, point.edf));
    point.adev_high = point.adev * std::sqrt(point.edf / ChiSquareQuantile(p_low, point.edf));
    if (!std::isfinite(point.adev_high))
      throw SpecError("allan.samples",
                      "values up to " + G6(max_abs) + " (Allan deviation at tau " +
                          G6(point.tau_s) + " s beyond the range of double)",
                      "samples whose Allan deviation and its confidence bound are below " +
                          G6(std::numeric_limits<double>::max()));
  }
  return curve;
}

std::vector<AllanPoint> OverlappingAllanDeviation(std::span<const double> rate_samples,
                                                  double rate_hz, int points_per_octave) {
  AllanOptions options;
  options.points_per_octave = points_per_octave;
  return OverlappingAllanDeviation(rate_samples, rate_hz, options);
}

double AllanCurveModel(double tau_s, double N, double B, double K, double Q, double R) {
  // IEEE Std 952-1997 table C.2; 2 ln 2 / pi = 0.4413 is the flat flicker level (0.664 B)^2.
  const double avar = 3.0 * Q * Q / (tau_s * tau_s) + N * N / tau_s +
                      2.0 * math::Log(2.0) / M_PI * B * B + K * K * tau_s / 3.0 +
                      R * R * tau_s * tau_s / 2.0;
  return std::sqrt(avar);
}

namespace {

// Fixed-slope fit ln adev = ln c + s ln tau through the points where the term dominates, weighted
// by edf (var(ln adev) ~ 1 / (2 edf) for a chi-square variance with edf degrees of freedom).
// A point is used when its local log-log slope is within max(kSlopeTolerance, 2 sigma_slope) of s,
// sigma_slope being the slope's own standard error from the edf of its neighbours (capped at
// kMaxSlopeTolerance, half the 1/2 step between terms). Why 0.05: where two terms with slopes
// 1/2 apart mix, the local slope is s + 0.5 f with f the other term's share of the variance, so
// |slope - s| <= 0.05 bounds f <= 0.1 and the bias of that point's ADEV to 1/sqrt(0.9) - 1 = 5.4 %.
constexpr double kSlopeTolerance = 0.05;
constexpr double kMaxSlopeTolerance = 0.25;

AllanTermFit FitSlope(std::span<const AllanPoint> curve, const std::vector<double>& local_slope,
                      const std::vector<double>& slope_sigma, double slope, double tau_ref_s) {
  AllanTermFit fit;
  double sum_w = 0.0, sum_wy = 0.0;
  for (size_t i = 0; i < curve.size(); ++i) {
    const double tolerance =
        std::min(kMaxSlopeTolerance, std::max(kSlopeTolerance, 2.0 * slope_sigma[i]));
    if (!(std::abs(local_slope[i] - slope) <= tolerance) || !(curve[i].adev > 0.0)) continue;
    const double w = curve[i].edf;
    sum_w += w;
    sum_wy += w * (math::Log(curve[i].adev) - slope * math::Log(curve[i].tau_s));
    if (fit.n_points == 0) fit.tau_min_s = curve[i].tau_s;
    fit.tau_max_s = curve[i].tau_s;
    ++fit.n_points;
  }
  if (fit.n_points > 0 && sum_w > 0.0) {
    fit.value = math::Exp(sum_wy / sum_w + slope * math::Log(tau_ref_s));
  } else {
    fit = AllanTermFit();
  }
  return fit;
}

}  // namespace

AllanReadOff ReadOffNoiseTerms(std::span<const AllanPoint> curve) {
  AllanReadOff out;
  if (curve.size() < 2) return out;
  // Local log-log slope: central difference, one-sided at the ends.
  // Its standard error treats the two neighbours as independent, each with
  // var(ln adev) = 1 / (2 edf); overlapping estimates are positively correlated, so this errs on
  // the large side.
  std::vector<double> slope(curve.size()), slope_sigma(curve.size());
  for (size_t i = 0; i < curve.size(); ++i) {
    const size_t a = i == 0 ? 0 : i - 1;
    const size_t b = i + 1 == curve.size() ? i : i + 1;
    const double d_ln_tau = math::Log(curve[b].tau_s) - math::Log(curve[a].tau_s);
    const bool valid = curve[a].adev > 0.0 && curve[b].adev > 0.0 && d_ln_tau > 0.0 &&
                       curve[a].edf > 0.0 && curve[b].edf > 0.0;
    slope[i] = valid ? (math::Log(curve[b].adev) - math::Log(curve[a].adev)) / d_ln_tau
                     : std::numeric_limits<double>::quiet_NaN();
    slope_sigma[i] =
        valid ? std::sqrt(0.5 / curve[a].edf + 0.5 / curve[b].edf) / d_ln_tau : kMaxSlopeTolerance;
  }
  // ADEV = sqrt(3) Q / tau -> Q = ADEV(sqrt(3)); N / sqrt(tau) -> N = ADEV(1);
  // K sqrt(tau / 3) -> K = ADEV(3); R tau / sqrt(2) -> R = ADEV(sqrt(2)).
  out.quantization = FitSlope(curve, slope, slope_sigma, -1.0, std::sqrt(3.0));
  out.white_noise = FitSlope(curve, slope, slope_sigma, -0.5, 1.0);
  out.random_walk = FitSlope(curve, slope, slope_sigma, 0.5, 3.0);
  out.rate_ramp = FitSlope(curve, slope, slope_sigma, 1.0, std::sqrt(2.0));
  // Bias instability: the flat minimum, B = min ADEV / sqrt(2 ln 2 / pi). Only an interior
  // minimum is a floor; a minimum at either end of the curve means the floor was not reached.
  size_t i_min = 0;
  for (size_t i = 1; i < curve.size(); ++i) {
    if (curve[i].adev < curve[i_min].adev) i_min = i;
  }
  if (i_min > 0 && i_min + 1 < curve.size()) {
    out.bias_instability.value = curve[i_min].adev / std::sqrt(2.0 * math::Log(2.0) / M_PI);
    out.bias_instability.tau_min_s = curve[i_min].tau_s;
    out.bias_instability.tau_max_s = curve[i_min].tau_s;
    out.bias_instability.n_points = 1;
  }
  return out;
}

}  // namespace driftlab
