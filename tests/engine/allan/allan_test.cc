// Overlapping Allan deviation: the estimator against a hand-derived example, the chi-square
// quantile against closed forms and tables, the confidence intervals against their nominal
// coverage, and the IEEE Std 952 read-off against synthetic noise of known level.
#include "driftlab/allan.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "driftlab/spec_error.h"

namespace driftlab {
namespace {

// Standard normal deviates for the tests: mt19937_64 + Box-Muller (Box & Muller, Ann. Math.
// Stat. 29, 1958), both outputs used.
class Gaussian {
 public:
  explicit Gaussian(uint64_t seed) : engine_(seed) {}
  double operator()() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double u1 = Uniform01();  // (0, 1]: log(u1) finite
    const double u2 = Uniform01();
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(2.0 * M_PI * u2);
    has_spare_ = true;
    return r * std::cos(2.0 * M_PI * u2);
  }
  double Uniform01() { return (static_cast<double>(engine_() >> 11) + 1.0) * 0x1p-53; }

 private:
  std::mt19937_64 engine_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

// Interval-average rates of white rate noise with density N [rad/sqrt(s)]: the average of white
// noise of PSD N^2 over tau0 has variance N^2 / tau0, independent between intervals, so the true
// ADEV is N / sqrt(tau) at every m (IEEE Std 952 table C.2).
std::vector<double> WhiteRateNoise(double N, double rate_hz, int64_t n, uint64_t seed) {
  Gaussian gauss(seed);
  std::vector<double> y(n);
  const double sigma = N * std::sqrt(rate_hz);
  for (auto& v : y) v = sigma * gauss();
  return y;
}

// Interval averages of a continuous rate random walk b' = w, PSD(w) = K^2: with q = K^2 tau0,
// b_{k+1} = b_k + sqrt(q) n_k and the average over [t_k, t_k+1] is (b_k + b_{k+1}) / 2 plus the
// Brownian-bridge mean, independent of the endpoints with variance q / 12. Sampling the averages
// exactly makes the true ADEV K sqrt(tau / 3) at every m, down to m = 1.
std::vector<double> RateRandomWalk(double K, double rate_hz, int64_t n, uint64_t seed) {
  Gaussian gauss(seed);
  std::vector<double> y(n);
  const double sqrt_q = K / std::sqrt(rate_hz);
  double b = 0.0;
  for (auto& v : y) {
    const double b_next = b + sqrt_q * gauss();
    v = 0.5 * (b + b_next) + sqrt_q / std::sqrt(12.0) * gauss();
    b = b_next;
  }
  return y;
}

const AllanPoint& NearestPoint(const std::vector<AllanPoint>& curve, double tau_s) {
  size_t best = 0;
  for (size_t i = 1; i < curve.size(); ++i) {
    if (std::abs(std::log(curve[i].tau_s / tau_s)) < std::abs(std::log(curve[best].tau_s / tau_s)))
      best = i;
  }
  return curve[best];
}

TEST(AllanTest, OverlappingEstimatorMatchesHandComputedSeries) {
  // y = 1, 2, 4, 7, 11 at 2 Hz (tau0 = 0.5 s). By hand, AVAR(m) = 1 / (2 (n + 1 - 2m)) * sum of
  // squared differences of adjacent overlapping m-averages:
  //   m = 1: differences 1, 2, 3, 4 -> (1 + 4 + 9 + 16) / (2 * 4) = 3.75
  //   m = 2: averages (1.5 | 5.5), (3 | 9): differences 4, 6 -> (16 + 36) / (2 * 2) = 13
  // m = 2 is the largest with two differences ((n - 1) / 2 = 2). Tolerance: a few ulps.
  const std::vector<double> y = {1.0, 2.0, 4.0, 7.0, 11.0};
  const auto curve = OverlappingAllanDeviation(y, 2.0, 1);
  ASSERT_EQ(curve.size(), 2u);
  EXPECT_DOUBLE_EQ(curve[0].tau_s, 0.5);
  EXPECT_DOUBLE_EQ(curve[0].adev, std::sqrt(3.75));
  EXPECT_EQ(curve[0].n_clusters, 4);
  EXPECT_DOUBLE_EQ(curve[1].tau_s, 1.0);
  EXPECT_DOUBLE_EQ(curve[1].adev, std::sqrt(13.0));
  EXPECT_EQ(curve[1].n_clusters, 2);
  // A constant offset does not change the Allan deviation (second differences of a linear phase
  // vanish); checks the mean removal. Tolerance: rounding of 1e6 + small integers, ~1e-10.
  std::vector<double> shifted = y;
  for (auto& v : shifted) v += 1e6;
  const auto curve_shifted = OverlappingAllanDeviation(shifted, 2.0, 1);
  EXPECT_NEAR(curve_shifted[0].adev, std::sqrt(3.75), 1e-9);
  EXPECT_NEAR(curve_shifted[1].adev, std::sqrt(13.0), 1e-9);
}

TEST(AllanTest, LinearRateRampGivesRTauOverSqrtTwo) {
  // y_k = R t_k: adjacent tau-averages differ by exactly R tau, so ADEV = R tau / sqrt(2) at
  // every tau (IEEE Std 952 table C.2), and the read-off returns R. Tolerance 1e-9: rounding in the
  // cumulative sum of 4096 terms.
  const double R = 2e-5, rate_hz = 10.0;
  std::vector<double> y(4096);
  for (size_t k = 0; k < y.size(); ++k) y[k] = R * (static_cast<double>(k) + 0.5) / rate_hz;
  const auto curve = OverlappingAllanDeviation(y, rate_hz, 2);
  for (const auto& p : curve) EXPECT_NEAR(p.adev / (R * p.tau_s / std::sqrt(2.0)), 1.0, 1e-9);
  const AllanReadOff r = ReadOffNoiseTerms(curve);
  ASSERT_TRUE(r.rate_ramp.found());
  EXPECT_NEAR(r.rate_ramp.value / R, 1.0, 1e-9);
  EXPECT_FALSE(r.white_noise.found());
}

TEST(AllanTest, ChiSquareQuantileMatchesClosedFormsAndTables) {
  // nu = 2: the chi-square is exponential with mean 2, quantile -2 ln(1 - p) exactly.
  for (double p : {0.025, 0.5, 0.975}) {
    EXPECT_NEAR(ChiSquareQuantile(p, 2.0), -2.0 * std::log1p(-p), 1e-12 * (1.0 - std::log1p(-p)));
  }
  // nu = 1: chi2 = z^2, so the 0.95 quantile is z_0.975^2 = 1.959963984540054^2.
  EXPECT_NEAR(ChiSquareQuantile(0.95, 1.0), 3.841458820694124, 1e-11);
  // Tables (NIST/SEMATECH e-Handbook 1.3.6.7.4), printed to 3 decimals: tolerance 5e-4.
  EXPECT_NEAR(ChiSquareQuantile(0.975, 10.0), 20.483, 5e-4);
  EXPECT_NEAR(ChiSquareQuantile(0.025, 10.0), 3.247, 5e-4);
  EXPECT_NEAR(ChiSquareQuantile(0.975, 100.0), 129.561, 5e-4);
  EXPECT_NEAR(ChiSquareQuantile(0.025, 100.0), 74.222, 5e-4);
  EXPECT_THROW(ChiSquareQuantile(1.0, 3.0), SpecError);
}

TEST(AllanTest, EdfMatchesHandEvaluatedHoweAllanBarnesFormulas) {
  // NIST TN 1337 table 12-4, evaluated by hand (N phase points, m):
  //   white FM,  N = 6,  m = 1: (3 * 5 / 2 - 2 * 4 / 6) * 4 / 9 = (37/6)(4/9) = 148/54
  //   RW FM,     N = 10, m = 2: (8 / 2) (81 - 54 + 16) / 49 = 172 / 49
  //   white PM,  N = 10, m = 2: 11 * 6 / (2 * 8) = 66 / 16
  //   flicker FM N = 10, m = 2: 5 * 100 / (8 * 16) = 500 / 128
  EXPECT_DOUBLE_EQ(OverlappingAdevEdf(AllanNoiseType::kWhiteFm, 6, 1), 148.0 / 54.0);
  EXPECT_DOUBLE_EQ(OverlappingAdevEdf(AllanNoiseType::kRandomWalkFm, 10, 2), 172.0 / 49.0);
  EXPECT_DOUBLE_EQ(OverlappingAdevEdf(AllanNoiseType::kWhitePm, 10, 2), 66.0 / 16.0);
  EXPECT_DOUBLE_EQ(OverlappingAdevEdf(AllanNoiseType::kFlickerFm, 10, 2), 500.0 / 128.0);
}

// Coverage of the 95 % interval over 200 independent realisations: the count inside is
// Binomial(200, 0.95), mean 190, sigma sqrt(200 * 0.95 * 0.05) = 3.08, so a correct interval
// gives 181..199 inside except with probability ~0.3 % (3 sigma; the seeds are fixed, so the test
// is deterministic). Checked at m = 1, 8, 64, 512 of 8192 samples; m = 512 has 16 averages, too
// few for noise identification (128), so it also checks the type carried over from m = 64.
void ExpectCoverage(bool random_walk) {
  constexpr int kRealisations = 200;
  constexpr int64_t kSamples = 8192;
  const double rate_hz = 100.0, level = 1e-3;
  const std::vector<int64_t> ms = {1, 8, 64, 512};
  std::vector<int> inside(ms.size(), 0);
  for (int r = 0; r < kRealisations; ++r) {
    const auto y = random_walk ? RateRandomWalk(level, rate_hz, kSamples, 1000 + r)
                               : WhiteRateNoise(level, rate_hz, kSamples, 5000 + r);
    const auto curve = OverlappingAllanDeviation(y, rate_hz, 1);
    for (size_t j = 0; j < ms.size(); ++j) {
      const AllanPoint& p = curve[static_cast<size_t>(std::log2(ms[j]))];
      ASSERT_EQ(p.m, ms[j]);
      const double truth =
          random_walk ? level * std::sqrt(p.tau_s / 3.0) : level / std::sqrt(p.tau_s);
      if (p.adev_low <= truth && truth <= p.adev_high) ++inside[j];
    }
  }
  for (size_t j = 0; j < ms.size(); ++j) {
    EXPECT_GE(inside[j], 181) << "m = " << ms[j];
    EXPECT_LE(inside[j], 199) << "m = " << ms[j];
  }
}

TEST(AllanTest, ConfidenceIntervalCovers95PercentOfWhiteNoiseRealisations) {
  ExpectCoverage(false);
}

TEST(AllanTest, ConfidenceIntervalCovers95PercentOfRateRandomWalkRealisations) {
  ExpectCoverage(true);
}

void ExpectArwRecovered(double rate_hz, double duration_s, uint64_t seed) {
  const double N = 2.9e-4;  // rad/sqrt(s) = 1 deg/sqrt(h)
  const auto y = WhiteRateNoise(N, rate_hz, static_cast<int64_t>(duration_s * rate_hz), seed);
  const auto curve = OverlappingAllanDeviation(y, rate_hz, 1);
  const AllanPoint& p1 = NearestPoint(curve, 1.0);
  // The true ADEV at the point nearest 1 s lies in its 95 % CI (a 95 % event, seeded).
  const double truth = N / std::sqrt(p1.tau_s);
  EXPECT_GE(truth, p1.adev_low);
  EXPECT_LE(truth, p1.adev_high);
  // The read-off pools every white-noise point (edf-weighted), so its error is below that of the
  // single point: N within the relative 95 % CI of the point nearest 1 s.
  const AllanReadOff r = ReadOffNoiseTerms(curve);
  ASSERT_TRUE(r.white_noise.found());
  EXPECT_GE(r.white_noise.value, N * p1.adev_low / p1.adev);
  EXPECT_LE(r.white_noise.value, N * p1.adev_high / p1.adev);
  // Noise identified as white FM (at long tau: carried from the last tau with 128 averages).
  for (const auto& p : curve) {
    EXPECT_EQ(p.noise_type, AllanNoiseType::kWhiteFm) << "tau " << p.tau_s;
  }
}

TEST(AllanTest, ArwRecoveredFromAllanAtOneSecondAt100Hz) { ExpectArwRecovered(100.0, 2000.0, 11); }

TEST(AllanTest, ArwRecoveredFromAllanAtOneSecondAt1kHz) { ExpectArwRecovered(1000.0, 400.0, 12); }

TEST(AllanTest, RateRandomWalkRecoveredFromAllanAtThreeSeconds) {
  const double K = 1e-5, rate_hz = 100.0;  // rad/s/sqrt(s)
  const auto y = RateRandomWalk(K, rate_hz, 360000, 21);
  const auto curve = OverlappingAllanDeviation(y, rate_hz, 1);
  const AllanPoint& p3 = NearestPoint(curve, 3.0);
  const double truth = K * std::sqrt(p3.tau_s / 3.0);
  EXPECT_GE(truth, p3.adev_low);  // 95 % event, seeded
  EXPECT_LE(truth, p3.adev_high);
  // As for N: the pooled fit is tighter than the single point's 95 % CI.
  const AllanReadOff r = ReadOffNoiseTerms(curve);
  ASSERT_TRUE(r.random_walk.found());
  EXPECT_GE(r.random_walk.value, K * p3.adev_low / p3.adev);
  EXPECT_LE(r.random_walk.value, K * p3.adev_high / p3.adev);
  EXPECT_EQ(p3.noise_type, AllanNoiseType::kRandomWalkFm);
  EXPECT_FALSE(r.white_noise.found());
}

TEST(AllanTest, QuantizationNoiseRecoveredAsWhiteAngleNoise) {
  // Quantization with carried remainder leaves an angle error uniform over one LSB S, white
  // between samples (IEEE Std 952 C.1.1): y_k = (e_{k+1} - e_k) / tau0, e ~ U(-S/2, S/2). Its
  // ADEV is sqrt(3) Q / tau with Q = S / sqrt(12): AVAR = 6 var(e) / (2 tau^2) = 3 (S^2/12)/tau^2.
  const double S = 1e-4, rate_hz = 200.0;  // rad
  const double Q = S / std::sqrt(12.0);
  Gaussian rng(31);
  std::vector<double> e(200001);
  for (auto& v : e) v = S * (rng.Uniform01() - 0.5);
  std::vector<double> y(e.size() - 1);
  for (size_t k = 0; k < y.size(); ++k) y[k] = (e[k + 1] - e[k]) * rate_hz;
  const auto curve = OverlappingAllanDeviation(y, rate_hz, 1);
  const AllanPoint& p = NearestPoint(curve, std::sqrt(3.0));
  const double truth = std::sqrt(3.0) * Q / p.tau_s;
  EXPECT_GE(truth, p.adev_low);  // 95 % event, seeded
  EXPECT_LE(truth, p.adev_high);
  const AllanReadOff r = ReadOffNoiseTerms(curve);
  ASSERT_TRUE(r.quantization.found());
  EXPECT_GE(r.quantization.value, Q * p.adev_low / p.adev);  // pooled fit tighter than one point
  EXPECT_LE(r.quantization.value, Q * p.adev_high / p.adev);
  EXPECT_EQ(curve.front().noise_type, AllanNoiseType::kWhitePm);
}

TEST(AllanTest, ReadOffRecoversAllFiveTermsFromTheoreticalCurve) {
  // A noise-free curve from AllanCurveModel with well-separated terms (gyro, SI):
  //   Q = 1e-4 rad, N = 1e-4 rad/sqrt(s), B = 1e-6 rad/s, K = 1e-10 rad/s/sqrt(s), R = 1e-16
  //   rad/s^2.
  // Slope-fit points have |local slope - s| <= 0.05, i.e. at most 10 % of the variance from a
  // neighbouring term (slopes 1/2 apart), so each fitted term is biased by at most
  // 1/sqrt(0.9) - 1 = 5.4 %. B: at the minimum (tau ~ sqrt(3) N / K) the N and K terms add
  // 2 N K / sqrt(3) = 1.2e-14 to 0.441 B^2 = 4.4e-13 of variance, i.e. +1.3 % of ADEV, plus
  // the octave grid missing the exact minimum (the curve is within 1 % over 0.5x..2x of it):
  // tolerance 2.5 %.
  const double Q = 1e-4, N = 1e-4, B = 1e-6, K = 1e-10, R = 1e-16;
  std::vector<AllanPoint> curve;
  for (int j = 0; j <= 55; ++j) {
    AllanPoint p;
    p.tau_s = 0.01 * std::exp2(j);
    p.adev = AllanCurveModel(p.tau_s, N, B, K, Q, R);
    p.edf = 1e9;  // noise-free
    curve.push_back(p);
  }
  const AllanReadOff r = ReadOffNoiseTerms(curve);
  EXPECT_NEAR(r.quantization.value / Q, 1.0, 0.054);
  EXPECT_NEAR(r.white_noise.value / N, 1.0, 0.054);
  EXPECT_NEAR(r.bias_instability.value / B, 1.0, 0.025);
  EXPECT_GE(r.bias_instability.value, B);  // the other terms only add variance
  EXPECT_NEAR(r.random_walk.value / K, 1.0, 0.054);
  EXPECT_NEAR(r.rate_ramp.value / R, 1.0, 0.054);
}

TEST(AllanTest, CurveModelMatchesIeee952TermsAlone) {
  // Each term alone reproduces its table C.2 expression; exact up to rounding.
  const double tau = 7.0;
  EXPECT_DOUBLE_EQ(AllanCurveModel(tau, 0.3, 0, 0, 0, 0), 0.3 / std::sqrt(tau));
  EXPECT_DOUBLE_EQ(AllanCurveModel(tau, 0, 0.3, 0, 0, 0), 0.3 * std::sqrt(2 * std::log(2) / M_PI));
  EXPECT_NEAR(AllanCurveModel(tau, 0, 0.3, 0, 0, 0) / 0.3, 0.664, 5e-4);  // IEEE 952 rounding
  EXPECT_DOUBLE_EQ(AllanCurveModel(tau, 0, 0, 0.3, 0, 0), 0.3 * std::sqrt(tau / 3.0));
  EXPECT_DOUBLE_EQ(AllanCurveModel(tau, 0, 0, 0, 0.3, 0), std::sqrt(3.0) * 0.3 / tau);
  EXPECT_DOUBLE_EQ(AllanCurveModel(tau, 0, 0, 0, 0, 0.3), 0.3 * tau / std::sqrt(2.0));
}

TEST(AllanTest, BadInputRaisesSpecErrorNamingTheField) {
  const std::vector<double> y = {1.0, 2.0, 3.0, 4.0};
  try {
    OverlappingAllanDeviation(y, 0.0, 1);
    FAIL() << "no throw";
  } catch (const SpecError& e) {
    EXPECT_EQ(e.field(), "allan.rate_hz");
  }
  EXPECT_THROW(OverlappingAllanDeviation(std::vector<double>{1.0, 2.0}, 100.0, 1), SpecError);
  EXPECT_THROW(OverlappingAllanDeviation(y, 100.0, 0), SpecError);
  std::vector<double> bad = y;
  bad[2] = std::nan("");
  try {
    OverlappingAllanDeviation(bad, 100.0, 1);
    FAIL() << "no throw";
  } catch (const SpecError& e) {
    EXPECT_EQ(e.field(), "allan.samples[2]");
  }
}

TEST(AllanTest, DenserGridHasDistinctIncreasingTaus) {
  const auto y = WhiteRateNoise(1e-3, 100.0, 10000, 41);
  const auto curve = OverlappingAllanDeviation(y, 100.0, 4);
  ASSERT_GT(curve.size(), 40u);  // 4 per octave over log2(4999) = 12.3 octaves, minus duplicates
  for (size_t i = 1; i < curve.size(); ++i) EXPECT_GT(curve[i].m, curve[i - 1].m);
  EXPECT_LE(curve.back().m, (10000 - 1) / 2);
}

TEST(AllanTest, ValuesNearTheLargestDoubleGiveTheScaledDeviationNotInf) {
  // Values near 1e308 must not overflow the sums and squares (nor make `allan` print ADEV = inf).
  // Power-of-two scaling is exact in binary floating point (no rounding without overflow or
  // underflow), so the deviation of y * 2^1000 must be exactly 2^1000 times the deviation of y,
  // bit for bit, at every tau: tolerance zero. y: the hand-computed series above, 1e6 offset
  // (mean removal) and 1e307-scale values.
  std::vector<double> y = {1.0, 2.0, 4.0, 7.0, 11.0, 3.0, 5.0, 8.0, 2.0};
  for (auto& v : y) v += 1e6;
  std::vector<double> huge = y;
  for (auto& v : huge) v = std::ldexp(v, 1000);  // ~1.07e307
  const auto curve = OverlappingAllanDeviation(y, 2.0, 1);
  const auto curve_huge = OverlappingAllanDeviation(huge, 2.0, 1);
  ASSERT_EQ(curve.size(), curve_huge.size());
  for (size_t j = 0; j < curve.size(); ++j) {
    EXPECT_TRUE(std::isfinite(curve_huge[j].adev_high));
    EXPECT_EQ(curve_huge[j].adev, std::ldexp(curve[j].adev, 1000)) << "tau index " << j;
    EXPECT_EQ(curve_huge[j].adev_low, std::ldexp(curve[j].adev_low, 1000));
  }
  // A deviation beyond the double range (alternating +-1e308: ADEV(tau0) = sqrt(2) 1e308) is
  // refused, naming the samples, instead of printing inf.
  std::vector<double> alternating(64);
  for (size_t k = 0; k < alternating.size(); ++k) alternating[k] = k % 2 ? -1e308 : 1e308;
  EXPECT_THROW(OverlappingAllanDeviation(alternating, 2.0, 1), SpecError);
}

}  // namespace
}  // namespace driftlab
