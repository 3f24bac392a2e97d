// Tests of the counter-based random streams (random.h): Philox known answers, the engine's own
// ln / sin / cos, the N(0, 1) distribution of the deviates, and independence of streams.
#include "driftlab/random.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "support/sample_statistics.h"

namespace driftlab {
namespace {

// Two-sided normal quantile for a false-alarm probability of 6.3e-5 per check: with the ~30
// statistical checks in this file the chance that any fails for a correct generator is < 0.2 %.
constexpr double kZ30Checks = 4.0;

TEST(PhiloxTest, MatchesRandom123KnownAnswerVectors) {
  // Random123 1.09 kat_vectors, "philox4x32 10": counter[4] key[2] -> output[4].
  EXPECT_EQ(Philox4x32({0, 0, 0, 0}, {0, 0}),
            (std::array<uint32_t, 4>{0x6627e8d5u, 0xe169c58du, 0xbc57ac4cu, 0x9b00dbd8u}));
  EXPECT_EQ(
      Philox4x32({0xffffffffu, 0xffffffffu, 0xffffffffu, 0xffffffffu}, {0xffffffffu, 0xffffffffu}),
      (std::array<uint32_t, 4>{0x408f276du, 0x41c83b0eu, 0xa20bc7c6u, 0x6d5451fdu}));
  EXPECT_EQ(
      Philox4x32({0x243f6a88u, 0x85a308d3u, 0x13198a2eu, 0x03707344u}, {0xa4093822u, 0x299f31d0u}),
      (std::array<uint32_t, 4>{0xd16cfe09u, 0x94fdccebu, 0x5001e420u, 0x24126ea1u}));
}

TEST(PolynomialMathTest, LogMatchesLongDoubleWithinItsSeriesBound) {
  // The series stops at s^11 (math/elementary_functions.h): the omitted 2 s^13/13 (1 + s^2 + ...)
  // is at most 5.2e-11 of ln m (|s| <= 0.1716), and at most 1.8e-11 absolute, i.e. below 5.2e-11
  // |ln x| for every x (|ln x| >= ln 2 / 2 when the exponent is not 0); rounding adds ~2 ulp. Over
  // the 32-bit uniforms the Box-Muller uses, and at the ends of the double range.
  double worst = 0.0;
  for (uint64_t i = 1; i <= (uint64_t{1} << 32); i += 65537) {
    const double x = static_cast<double>(i) / 4294967296.0;
    const long double expected = std::log(static_cast<long double>(x));
    const double got = PolyLog(x);
    const double bound = 5.2e-11 * std::fabs(static_cast<double>(expected)) + 1e-300;
    EXPECT_NEAR(got, static_cast<double>(expected), bound) << "x = " << x;
    worst = std::max(worst, std::fabs(got - static_cast<double>(expected)) / bound);
  }
  // The bound is not loose by orders of magnitude (the series does stop at s^11): near
  // m = sqrt(2) the error reaches a fair part of it.
  EXPECT_GT(worst, 0.05);
  EXPECT_EQ(PolyLog(1.0), 0.0);
  EXPECT_NEAR(PolyLog(1e-300), std::log(1e-300), 5.2e-11 * 690.8);
  EXPECT_NEAR(PolyLog(3.0e10), std::log(3.0e10), 5.2e-11 * 24.1);
}

TEST(PolynomialMathTest, SinCosOfTwoPiUMatchLongDoubleWithinTheirSeriesBound) {
  // The Box-Muller angle's series (math/elementary_functions.h, Series::kGaussian) stop at theta^11
  // (sin) and theta^12 (cos): omitted terms <= (pi/4)^13/13! = 7.0e-12 and (pi/4)^14/14! = 4.0e-13
  // for |theta| <= pi/4, plus a few 1e-17 of rounding: 7.1e-12 absolute. Adjacent inputs are 2 pi
  // 2^-32 = 1.5e-9 rad apart.
  const long double two_pi = 2.0L * std::numbers::pi_v<long double>;
  double max_error = 0.0;
  for (uint64_t i = 0; i < (uint64_t{1} << 32); i += 40009) {  // includes the top quadrant
    const double u = static_cast<double>(i) / 4294967296.0;
    double s = 0.0, c = 0.0;
    PolySinCosTwoPi(static_cast<uint32_t>(i), &s, &c);
    const long double angle = two_pi * static_cast<long double>(u);
    max_error = std::max(max_error, std::fabs(s - static_cast<double>(std::sin(angle))));
    max_error = std::max(max_error, std::fabs(c - static_cast<double>(std::cos(angle))));
  }
  EXPECT_LT(max_error, 7.1e-12);
  EXPECT_GT(max_error, 1e-13);  // the short series is the one in use
  double s = 0.0, c = 0.0;
  PolySinCosTwoPi(0x40000000u, &s, &c);  // u = 1/4
  EXPECT_EQ(s, 1.0);
  EXPECT_EQ(c, 0.0);
  PolySinCosTwoPi(0xa0000000u, &s, &c);  // u = 5/8: sin = cos = -sqrt(1/2)
  EXPECT_NEAR(s, -std::numbers::sqrt2 / 2, 7.1e-12);
  EXPECT_NEAR(c, -std::numbers::sqrt2 / 2, 7.1e-12);
}

TEST(GaussianTest, DeviatesAreTheBoxMullerTransformOfTheirPhiloxWordsWithinTheSeriesBounds) {
  // Deviates 4b .. 4b + 3 of a stream are Box-Muller of the words (x0, x1) and (x2, x3) of Philox
  // block b (random.h): z = sqrt(-2 ln u1) (cos, sin)(2 pi u2), u1 = (x0 + 1) 2^-32,
  // u2 = x1 2^-32. Against that formula in long double: the radius within 2.6e-11 relative (half
  // the log's 5.2e-11) and sin/cos within 7.1e-12 absolute (tests above), so
  // |z - z_exact| <= 2.6e-11 |z| + 7.1e-12 r + rounding (1e-15 r). 4e5 deviates, seed fixed.
  const uint64_t seed = 0x5eedULL;
  const uint32_t run = 3;
  const RandomStream stream(seed, run, {SensorId::kAccel, 2, ErrorTerm::kRandomWalk, 0});
  const int blocks = 100'000;
  std::vector<double> z(4 * blocks);
  stream.FillGaussian(0, z);
  const long double two_pi = 2.0L * std::numbers::pi_v<long double>;
  for (int b = 0; b < blocks; ++b) {
    const std::array<uint32_t, 4> x = Philox4x32(
        {static_cast<uint32_t>(b), 0u, stream.run_word(), stream.stream_word()}, stream.key());
    for (int pair = 0; pair < 2; ++pair) {
      const long double u1 = (static_cast<long double>(x[2 * pair]) + 1) / 4294967296.0L;
      const long double u2 = static_cast<long double>(x[2 * pair + 1]) / 4294967296.0L;
      const long double r = std::sqrt(-2 * std::log(u1));
      const long double exact[2] = {r * std::cos(two_pi * u2), r * std::sin(two_pi * u2)};
      for (int k = 0; k < 2; ++k) {
        const double got = z[static_cast<size_t>(4 * b + 2 * pair + k)];
        const double bound = 2.6e-11 * std::fabs(static_cast<double>(exact[k])) +
                             (7.1e-12 + 1e-15) * static_cast<double>(r);
        ASSERT_NEAR(got, static_cast<double>(exact[k]), bound) << "block " << b;
      }
    }
  }
}

TEST(PolynomialMathTest, SinCosOfGeneralArgumentMatchLongDoubleWithinFewUlp) {
  // Cody-Waite reduction with pi/2 to ~2^-151 leaves t within ~1e-16 ulp of exact for
  // |x| < 1.6e6; the Taylor sums then add the same few 1e-17 as above: 3e-16 absolute.
  // Latitudes, angles up to 4 rad, and large arguments up to 1e5 rad.
  double max_error = 0.0;
  for (int range = 0; range < 3; ++range) {
    const double half_width = range == 0 ? 1.6 : (range == 1 ? 4.0 : 1e5);
    for (int i = -50000; i <= 50000; ++i) {
      const double x = half_width * (static_cast<double>(i) / 50000.0) + 1e-7 * (i % 7);
      double s = 0.0, c = 0.0;
      PolySinCos(x, &s, &c);
      const long double xl = x;
      max_error = std::max(max_error, std::fabs(s - static_cast<double>(std::sin(xl))));
      max_error = std::max(max_error, std::fabs(c - static_cast<double>(std::cos(xl))));
    }
  }
  EXPECT_LT(max_error, 3e-16);
  // Small arguments keep their relative accuracy (sin x = x - x^3/6 to 1 ulp).
  for (double x : {1e-300, -3e-20, 1e-9, 2.5e-5}) {
    double s = 0.0, c = 0.0;
    PolySinCos(x, &s, &c);
    EXPECT_NEAR(s, x - x * x * x / 6.0, 2.3e-16 * std::fabs(x)) << x;
    EXPECT_NEAR(c, 1.0 - x * x / 2.0, 1.2e-16) << x;
  }
  double s = 0.0, c = 0.0;
  PolySinCos(0.0, &s, &c);
  EXPECT_EQ(s, 0.0);
  EXPECT_EQ(c, 1.0);
  PolySinCos(std::numeric_limits<double>::quiet_NaN(), &s, &c);
  EXPECT_TRUE(std::isnan(s) && std::isnan(c));
  PolySinCos(std::numeric_limits<double>::infinity(), &s, &c);
  EXPECT_TRUE(std::isnan(s) && std::isnan(c));
}

std::vector<double> Draw(const RandomStream& stream, uint64_t first, size_t n) {
  std::vector<double> z(n);
  stream.FillGaussian(first, z);
  return z;
}

TEST(GaussianTest, MomentsMatchStandardNormal) {
  // n = 1e7: standard errors of mean, variance, skewness, excess kurtosis are sqrt(1/n),
  // sqrt(2/n), sqrt(6/n), sqrt(24/n) (normal theory); each is checked at kZ30Checks standard
  // errors.
  const size_t n = 10'000'000;
  const std::vector<double> z =
      Draw(RandomStream(2024, 7, {SensorId::kGyro, 1, ErrorTerm::kWhiteNoise, 0}), 0, n);
  long double m1 = 0, m2 = 0, m3 = 0, m4 = 0;
  for (double v : z) {
    const long double v2 = static_cast<long double>(v) * v;
    m1 += v;
    m2 += v2;
    m3 += v2 * v;
    m4 += v2 * v2;
  }
  const double nd = static_cast<double>(n);
  const double mean = static_cast<double>(m1 / nd);
  const double var = static_cast<double>(m2 / nd) - mean * mean;
  const double skew = static_cast<double>(m3 / nd) / std::pow(var, 1.5);
  const double kurt = static_cast<double>(m4 / nd) / (var * var) - 3.0;
  EXPECT_NEAR(mean, 0.0, kZ30Checks * std::sqrt(1.0 / nd));
  EXPECT_NEAR(var, 1.0, kZ30Checks * std::sqrt(2.0 / nd));
  EXPECT_NEAR(skew, 0.0, kZ30Checks * std::sqrt(6.0 / nd));
  EXPECT_NEAR(kurt, 0.0, kZ30Checks * std::sqrt(24.0 / nd));
}

// 1e7 deviates of one stream, sorted, with their standard normal CDF values (the KS and
// Anderson-Darling tests share them: drawing, sorting and evaluating erfc are the costly part).
struct SortedDraws {
  std::vector<double> z, lower_cdf, upper_cdf;  // F(z_i) and 1 - F(z_i), each accurate in its tail
};
const SortedDraws& TenMillionSorted() {
  static const SortedDraws draws = [] {
    SortedDraws d;
    d.z = Draw(RandomStream(99, 0, {SensorId::kAccel, 2, ErrorTerm::kRandomWalk, 0}), 12345,
               10'000'000);
    std::sort(d.z.begin(), d.z.end());
    d.lower_cdf.resize(d.z.size());
    d.upper_cdf.resize(d.z.size());
    for (size_t i = 0; i < d.z.size(); ++i) {
      d.lower_cdf[i] = 0.5 * std::erfc(-d.z[i] / std::numbers::sqrt2);
      d.upper_cdf[i] = 0.5 * std::erfc(d.z[i] / std::numbers::sqrt2);
    }
    return d;
  }();
  return draws;
}

TEST(GaussianTest, KolmogorovSmirnovAgainstStandardNormal) {
  // Asymptotic Kolmogorov critical value sqrt(-ln(alpha/2) / 2) / sqrt(n) = 1.949 / sqrt(n) at
  // alpha = 1e-3 (n = 1e7: 6.16e-4).
  const SortedDraws& d = TenMillionSorted();
  const size_t n = d.z.size();
  double stat = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const double cdf = d.lower_cdf[i];
    stat = std::max({stat, cdf - static_cast<double>(i) / n, static_cast<double>(i + 1) / n - cdf});
  }
  EXPECT_LT(stat, 1.949 / std::sqrt(static_cast<double>(n)));
}

TEST(GaussianTest, AndersonDarlingAgainstStandardNormal) {
  // A^2 = -n - (1/n) sum_i (2i - 1) [ln F(z_(i)) + ln(1 - F(z_(n+1-i)))] for the fully specified
  // N(0, 1) (case 0). Its asymptotic upper 1 % point is 3.857 (M. A. Stephens, "EDF statistics
  // for goodness of fit and some comparisons", JASA 69 (1974) 730, Table 1A, case 0); A^2 weighs
  // the tails, where the Box-Muller log and the 32-bit uniforms matter. Seed fixed in advance.
  const SortedDraws& d = TenMillionSorted();
  const size_t n = d.z.size();
  long double sum = 0.0L;
  for (size_t i = 0; i < n; ++i) {
    sum += static_cast<long double>(2 * i + 1) *
           (std::log(static_cast<long double>(d.lower_cdf[i])) +
            std::log(static_cast<long double>(d.upper_cdf[n - 1 - i])));
  }
  const double a2 = static_cast<double>(-static_cast<long double>(n) - sum / n);
  EXPECT_LT(a2, 3.857);
  EXPECT_GT(a2, 0.0);
}

TEST(GaussianTest, TailProbabilitiesMatchStandardNormal) {
  // Counts beyond |z| > 3 and > 4 are binomial(n, p) with p = erfc(3/sqrt2) = 2.700e-3 and
  // erfc(4/sqrt2) = 6.334e-5; checked at kZ30Checks binomial standard deviations. Exercises the log
  // in Box-Muller where u1 is small. Also |z| <= 6.67, the bound set by 32-bit uniforms.
  const size_t n = 10'000'000;
  const std::vector<double> z =
      Draw(RandomStream(5, 3, {SensorId::kGyro, 0, ErrorTerm::kGaussMarkov, 0}), 0, n);
  for (double threshold : {3.0, 4.0}) {
    const double p = std::erfc(threshold / std::numbers::sqrt2);
    const double count = static_cast<double>(
        std::count_if(z.begin(), z.end(), [&](double v) { return std::fabs(v) > threshold; }));
    const double nd = static_cast<double>(n);
    EXPECT_NEAR(count, nd * p, kZ30Checks * std::sqrt(nd * p * (1 - p)))
        << "threshold " << threshold;
  }
  for (double v : z) ASSERT_LE(std::fabs(v), 6.67);
}

TEST(RandomStreamTest, BlockFillIsIndependentOfSplitAndOrder) {
  // Deviate i of a stream must not depend on how it is requested (DESIGN.md invariant 3).
  const RandomStream stream(42, 17, {SensorId::kGyro, 2, ErrorTerm::kFlicker, 5});
  const std::vector<double> whole = Draw(stream, 1000, 1000);
  for (uint64_t first : {1000u, 1001u, 1003u, 1128u, 1999u}) {
    for (size_t n : {1u, 3u, 4u, 5u, 127u, 129u}) {
      if (first + n > 2000) continue;
      const std::vector<double> part = Draw(stream, first, n);
      for (size_t i = 0; i < n; ++i) ASSERT_EQ(part[i], whole[first - 1000 + i]);
    }
  }
  for (uint64_t i = 1999; i >= 1000; --i) ASSERT_EQ(stream.Gaussian(i), whole[i - 1000]);
  // Far indices (block counter above 2^32) work and are reproducible.
  const uint64_t far = (uint64_t{1} << 40) + 3;
  EXPECT_EQ(Draw(stream, far, 8)[5], stream.Gaussian(far + 5));
}

using driftlab::testing::SampleCorrelation;

TEST(RandomStreamTest, DifferentKeysGiveUncorrelatedStreams) {
  // Sample correlation of independent streams: sd 1/sqrt(n); bound kZ30Checks / sqrt(n) per pair.
  const size_t n = 200'000;
  const StreamKey base{SensorId::kGyro, 0, ErrorTerm::kWhiteNoise, 0};
  const std::vector<double> a = Draw(RandomStream(1, 0, base), 0, n);
  std::vector<RandomStream> others = {
      RandomStream(2, 0, base),                                              // seed
      RandomStream(uint64_t{1} << 32 | 1, 0, base),                          // seed high word
      RandomStream(1, 1, base),                                              // run
      RandomStream(1, 0, {SensorId::kAccel, 0, ErrorTerm::kWhiteNoise, 0}),  // sensor
      RandomStream(1, 0, {SensorId::kGyro, 1, ErrorTerm::kWhiteNoise, 0}),   // axis
      RandomStream(1, 0, {SensorId::kGyro, 0, ErrorTerm::kRandomWalk, 0}),   // term
      RandomStream(1, 0, {SensorId::kGyro, 0, ErrorTerm::kWhiteNoise, 1}),   // component
  };
  const double bound = kZ30Checks / std::sqrt(static_cast<double>(n));
  for (size_t s = 0; s < others.size(); ++s) {
    EXPECT_LT(std::fabs(SampleCorrelation(a, Draw(others[s], 0, n))), bound) << "pair " << s;
  }
  // Within one stream: lags 1 (same Box-Muller pair), 2, 4 (next block) are uncorrelated.
  for (size_t lag : {1u, 2u, 4u}) {
    std::vector<double> x(a.begin(), a.end() - lag), y(a.begin() + lag, a.end());
    EXPECT_LT(std::fabs(SampleCorrelation(x, y)), bound) << "lag " << lag;
  }
  // The pair (z0, z1) of one Box-Muller draw: z0^2 and z1^2 are independent (sd of the
  // correlation estimate is again 1/sqrt(n') for n' pairs).
  std::vector<double> q0, q1;
  for (size_t i = 0; i + 1 < n; i += 2) {
    q0.push_back(a[i] * a[i]);
    q1.push_back(a[i + 1] * a[i + 1]);
  }
  EXPECT_LT(std::fabs(SampleCorrelation(q0, q1)),
            kZ30Checks / std::sqrt(static_cast<double>(q0.size())));
}

TEST(RandomStreamTest, UniformDeviatesAreInOpenUnitIntervalWithMeanOneHalf) {
  // Mean of U(0,1): sd sqrt(1/12 / n).
  const size_t n = 1'000'000;
  std::vector<double> u(n);
  RandomStream(8, 8, {SensorId::kGnss, 0, ErrorTerm::kWhiteNoise, 0}).FillUniform(3, u);
  long double sum = 0;
  for (double v : u) {
    ASSERT_GT(v, 0.0);
    ASSERT_LT(v, 1.0);
    sum += v;
  }
  EXPECT_NEAR(static_cast<double>(sum / n), 0.5, kZ30Checks * std::sqrt(1.0 / 12.0 / n));
}

}  // namespace
}  // namespace driftlab
