// The engine's own elementary functions (driftlab/elementary.h,
// engine/src/math/elementary_functions.h) against long double references (x87: 64-bit significands,
// within ~1 ulp of long double, i.e. 2^-11 of a double ulp) and C's special values. Tolerances in
// units in the last place of the double result (ulp = 2^(floor(log2 |ref|) - 52)), from the error
// analysis of each function (the series' truncation is far below 1 ulp; what remains is the
// rounding of the basic operations):
//   Exp: reduction r (exact n ln2_hi, one rounding of n ln2_lo) + Horner series + 1 + em1 + one
//        scaling: <= 1 ulp; bound 1.5.
//   Expm1: the series alone <= 1 ulp; beyond |x| > ln2/2 Exp(x) - 1 multiplies Exp's error by
//        e^x / |e^x - 1| <= 3.5: bound 4.
//   Log: s = f/(2+f) rounded (0.5 ulp of log m), the series, e ln2 in two pieces: bound 2.
//   Atan, Atan2, Asin: u = (t - c)/(1 + tc) rounded (<= 0.25 ulp of the result, |u| <= 1/8 of
//        it), the series and the hi + lo sums (~1 ulp): bound 2 for Atan; Atan2 also rounds
//        y/x, 0.5 ulp of the ratio, which is up to 1 ulp of the result when the ratio is in the
//        binade above it (t just above 1/8, atan t just below): bound 2.5; Asin adds the square
//        root of (1 - x)(1 + x) (1.5 ulp relative in it, which moves asin by |x| of that): 3.
//   Sin, Cos, Tan: SinCos within ~1.5 ulp (PolynomialMathTest); Tan = sin/cos carries both
//        relative errors (up to 1.5 x 2^-52 each) and its rounding: 3.5 x 2^-52 relative, 3.5 ulp
//        of a tan just below a power of two: bound 4 where |sin| and |cos| > 0.1 (nearer their
//        zeros the long double reference itself, x87 fsin/fcos with its 66-bit pi, is off by up to
//        ~1e-18 absolute at |x| ~ 1000).
//   Hypot: one sum of two rounded squares and a square root: bound 1.5.
//   Log1p: ln(u) x/(u - 1) with u = 1 + x rounded: Log's 2 ulp (relative <= 2 x 2^-52), the
//        quotient's and the product's roundings (<= 2^-52 relative each): 4.
//   Acos: as Asin, the square root now in the numerator: 3.
//   LgammaPositive: Stirling at z >= 10 plus ln of the shift product (<= 10 factors, each a
//        rounding): absolute 1e-14 + 8 ulp relative.
#include "driftlab/elementary.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>

#include "driftlab/special_functions.h"

namespace driftlab {
namespace {

double Ulp(long double ref) {
  const double r = std::fabs(static_cast<double>(ref));
  if (r < std::numeric_limits<double>::min()) return std::numeric_limits<double>::denorm_min();
  return std::ldexp(1.0, std::ilogb(r) - 52);
}

// Largest |got - ref| in ulp over the calls.
struct WorstUlp {
  double worst = 0.0;
  void Check(double got, long double ref, double bound, const std::string& what) {
    const double err =
        static_cast<double>(std::fabs(static_cast<long double>(got) - ref)) / Ulp(ref);
    worst = std::max(worst, err);
    EXPECT_LE(err, bound) << what << ": got " << got << ", reference " << static_cast<double>(ref);
  }
};

TEST(ElementaryTest, ExpAndExpm1WithinTheirUlpBounds) {
  std::mt19937_64 g(11);
  std::uniform_real_distribution<double> wide(-745.0, 709.7), narrow(-1.0, 1.0);
  WorstUlp e, m;
  for (int i = 0; i < 200000; ++i) {
    const double x = wide(g);
    const long double ref = std::exp(static_cast<long double>(x));
    if (ref >= std::numeric_limits<double>::min()) {
      e.Check(math::Exp(x), ref, 1.5, "Exp(" + std::to_string(x) + ")");
    } else {  // subnormal results: 1 + em1's error (<= 1 ulp relative), then one rounding at
              // the subnormal spacing
      EXPECT_LE(std::fabs(static_cast<long double>(math::Exp(x)) - ref),
                0.5L * std::numeric_limits<double>::denorm_min() + 0x1p-52L * ref)
          << x;
    }
    const double y = narrow(g) * (i % 2 == 0 ? 1.0 : 1e-6);
    m.Check(math::Expm1(y), std::expm1(static_cast<long double>(y)), 4.0,
            "Expm1(" + std::to_string(y) + ")");
    const double z = wide(g) / 10.0;
    m.Check(math::Expm1(z), std::expm1(static_cast<long double>(z)), 4.0,
            "Expm1(" + std::to_string(z) + ")");
  }
  EXPECT_EQ(math::Exp(0.0), 1.0);
  EXPECT_EQ(math::Exp(-std::numeric_limits<double>::infinity()), 0.0);
  EXPECT_EQ(math::Exp(710.0), std::numeric_limits<double>::infinity());
  EXPECT_EQ(math::Exp(-746.0), 0.0);
  EXPECT_TRUE(std::isnan(math::Exp(std::nan(""))));
  EXPECT_EQ(math::Expm1(0.0), 0.0);
  EXPECT_EQ(math::Expm1(-50.0), -1.0);
  EXPECT_EQ(math::Expm1(1e-300), 1e-300);
}

TEST(ElementaryTest, LogWithinItsUlpBound) {
  std::mt19937_64 g(12);
  std::uniform_real_distribution<double> exponent(-1070.0, 1023.0), mant(1.0, 2.0);
  WorstUlp w;
  for (int i = 0; i < 200000; ++i) {
    const double x = std::ldexp(mant(g), static_cast<int>(exponent(g)));
    if (!(x > 0.0) || std::isinf(x)) continue;
    w.Check(math::Log(x), std::log(static_cast<long double>(x)), 2.0,
            "Log(" + std::to_string(x) + ")");
    const double near1 = 1.0 + (mant(g) - 1.5) * 1e-3;  // ln close to 0: relative accuracy
    w.Check(math::Log(near1), std::log(static_cast<long double>(near1)), 2.0, "Log near 1");
  }
  for (int i = 0; i < 100000; ++i) {
    const double x = (mant(g) - 1.5) * std::exp2(-static_cast<double>(i % 60));  // |x| <= 0.5
    w.Check(math::Log1p(x), std::log1p(static_cast<long double>(x)), 4.0,
            "Log1p(" + std::to_string(x) + ")");
  }
  EXPECT_EQ(math::Log1p(1e-300), 1e-300);
  EXPECT_EQ(math::Log1p(-1.0), -std::numeric_limits<double>::infinity());
  EXPECT_EQ(math::Log(1.0), 0.0);
  EXPECT_EQ(math::Log(0.0), -std::numeric_limits<double>::infinity());
  EXPECT_TRUE(std::isnan(math::Log(-1.0)));
  EXPECT_EQ(math::Log(std::numeric_limits<double>::infinity()),
            std::numeric_limits<double>::infinity());
  EXPECT_EQ(math::Log(2.0), 0.6931471805599453);  // ln 2 rounded (0.69314718055994530942...)
}

TEST(ElementaryTest, AtanAtan2AsinWithinTheirUlpBounds) {
  std::mt19937_64 g(13);
  std::uniform_real_distribution<double> u(-1.0, 1.0), e(-30.0, 30.0);
  WorstUlp w;
  for (int i = 0; i < 200000; ++i) {
    const double x = u(g) * std::exp2(e(g));
    w.Check(math::Atan(x), std::atan(static_cast<long double>(x)), 2.0,
            "Atan(" + std::to_string(x) + ")");
    const double a = u(g) * std::exp2(e(g) / 3.0), b = u(g) * std::exp2(e(g) / 3.0);
    w.Check(math::Atan2(a, b), std::atan2(static_cast<long double>(a), static_cast<long double>(b)),
            2.5, "Atan2(" + std::to_string(a) + ", " + std::to_string(b) + ")");
    const double s = u(g);
    w.Check(math::Asin(s), std::asin(static_cast<long double>(s)), 3.0,
            "Asin(" + std::to_string(s) + ")");
    w.Check(math::Acos(s), std::acos(static_cast<long double>(s)), 3.0,
            "Acos(" + std::to_string(s) + ")");
  }
  const double inf = std::numeric_limits<double>::infinity();
  // C's values at zeros and infinities (C17 F.10.1.4), signs included.
  EXPECT_EQ(std::signbit(math::Atan2(-0.0, 1.0)), true);
  EXPECT_EQ(math::Atan2(0.0, -0.0), M_PI);
  EXPECT_EQ(math::Atan2(-0.0, -1.0), -M_PI);
  EXPECT_EQ(math::Atan2(1.0, 0.0), M_PI / 2.0);
  EXPECT_EQ(math::Atan2(-1.0, -0.0), -M_PI / 2.0);
  EXPECT_EQ(math::Atan2(inf, inf), M_PI / 4.0);
  EXPECT_EQ(math::Atan2(-inf, -inf), -3.0 * M_PI / 4.0);
  EXPECT_EQ(math::Atan2(1.0, -inf), M_PI);
  EXPECT_EQ(std::signbit(math::Atan2(-1.0, inf)), true);
  EXPECT_EQ(math::Atan2(inf, 5.0), M_PI / 2.0);
  EXPECT_TRUE(std::isnan(math::Atan2(std::nan(""), 1.0)));
  EXPECT_EQ(math::Atan(inf), M_PI / 2.0);
  EXPECT_EQ(math::Atan(1.0), M_PI / 4.0);
  EXPECT_EQ(math::Asin(1.0), M_PI / 2.0);
  EXPECT_EQ(math::Asin(-1.0), -M_PI / 2.0);
  EXPECT_TRUE(std::isnan(math::Asin(1.0000001)));
  EXPECT_EQ(math::Acos(1.0), 0.0);
  EXPECT_EQ(math::Acos(-1.0), M_PI);
}

TEST(ElementaryTest, SinCosTanHypotWithinTheirUlpBounds) {
  std::mt19937_64 g(14);
  std::uniform_real_distribution<double> u(-1.0, 1.0), e(-40.0, 40.0);
  WorstUlp w;
  for (int i = 0; i < 200000; ++i) {
    const double x = u(g) * 1000.0;
    const long double s = std::sin(static_cast<long double>(x)),
                      c = std::cos(static_cast<long double>(x));
    // Absolute within 1.5 ulp of 1 near the zeros, relative elsewhere (the reduction's rounding
    // is absolute).
    const double abs_bound = 1.5 * std::ldexp(1.0, -52);
    EXPECT_LE(std::fabs(static_cast<long double>(math::Sin(x)) - s),
              std::max<long double>(abs_bound, 1.5L * Ulp(s)))
        << x;
    EXPECT_LE(std::fabs(static_cast<long double>(math::Cos(x)) - c),
              std::max<long double>(abs_bound, 1.5L * Ulp(c)))
        << x;
    if (std::fabs(static_cast<double>(c)) > 0.1 && std::fabs(static_cast<double>(s)) > 0.1) {
      w.Check(math::Tan(x), s / c, 4.0, "Tan(" + std::to_string(x) + ")");
    }
    const double a = u(g) * std::exp2(e(g) * 25.0), b = u(g) * std::exp2(e(g) * 25.0);
    w.Check(math::Hypot(a, b),
            std::sqrt(static_cast<long double>(a) * a + static_cast<long double>(b) * b), 1.5,
            "Hypot(" + std::to_string(a) + ", " + std::to_string(b) + ")");
  }
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(math::Hypot(inf, std::nan("")), inf);
  EXPECT_EQ(math::Hypot(3.0, 4.0), 5.0);
  EXPECT_EQ(math::Hypot(3e300, 4e300), 5e300);
  EXPECT_EQ(math::Hypot(3e-320, 4e-320), 5e-320);
  EXPECT_EQ(math::Hypot(0.0, -2.0), 2.0);
}

TEST(ElementaryTest, LgammaOfPositiveArgumentsWithinItsBound) {
  for (double a = 1e-3; a < 1e6; a *= 1.0137) {
    const long double ref = std::lgamma(static_cast<long double>(a));
    const double got = math::LgammaPositive(a);
    EXPECT_LE(std::fabs(static_cast<long double>(got) - ref), 1e-14L + 8.0L * Ulp(ref))
        << "a = " << a;
  }
  // Gamma(1/2) = sqrt(pi); the bound above (its absolute part: (z - 1/2) ln z ~ 20 at z = 10.5
  // rounds at 3.6e-15).
  EXPECT_NEAR(math::LgammaPositive(0.5), 0.5 * std::log(M_PI), 1e-14);
  EXPECT_NEAR(math::LgammaPositive(1.0), 0.0, 1e-14);
  EXPECT_TRUE(std::isnan(math::LgammaPositive(0.0)));
  EXPECT_TRUE(std::isnan(math::LgammaPositive(-1.5)));
}

}  // namespace
}  // namespace driftlab

namespace driftlab {
namespace {

// Phi from the regularised gamma functions (special_functions.h, ~1e-12 relative as they are),
// against long double erfc, tails included (Phi(-37) ~ 6e-300).
TEST(ElementaryTest, NormalCdfFromTheGammaFunctionsWithinTheirAccuracy) {
  for (double z = -37.0; z <= 8.0; z += 0.0173) {
    const long double ref = 0.5L * std::erfc(-static_cast<long double>(z) / std::sqrt(2.0L));
    EXPECT_LE(std::fabs(static_cast<long double>(NormalCdf(z)) - ref), 1e-12L * ref) << "z = " << z;
  }
  EXPECT_EQ(NormalCdf(0.0), 0.5);
  EXPECT_EQ(NormalCdf(-std::numeric_limits<double>::infinity()), 0.0);
  EXPECT_EQ(NormalCdf(std::numeric_limits<double>::infinity()), 1.0);
}

}  // namespace
}  // namespace driftlab
