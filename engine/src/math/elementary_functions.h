// The engine's own elementary functions (DESIGN.md "Same bits everywhere"): ln, sin and cos written
// over the lane width W (lanes/lane.h: W = 1 is the scalar code, e.g. random.cc, earth.cc,
// attitude.cc; W > 1 the lockstep kernels, one copy per instruction set), and the scalar exp,
// expm1, ln, log1p, sin/cos, atan, atan2, asin, acos, hypot and ln Gamma behind
// driftlab/elementary.h. Only IEEE basic operations (+, -, *, /, sqrt: correctly rounded per lane)
// and integer bit operations; the lane functions have no branches, no comparisons and no conversion
// instructions (integers become doubles by the 2^52 magic-number trick, exactly), so every W and
// every instruction set gives the same bits, and the code vectorises on every x86-64 level.
// Files including this header are built with -ffp-contract=off (as the whole engine), so no
// multiply-add is fused. A lane header (lanes/lane.h): internal linkage, no standard-library
// templates.
#pragma once

#include <cstdint>

#include "lanes/lane.h"

namespace driftlab::elementary {
namespace {

using lanes::AsBits;
using lanes::AsDouble;
using lanes::D;
using lanes::GetLane;
using lanes::GreaterMask;
using lanes::Select;
using lanes::Splat;
using lanes::ToDouble;
using lanes::U;

// ln 2 split so that e * kLn2Hi is exact for |e| < 2^11 (the fdlibm split: kLn2Hi has 32
// significant bits). ln 2 = 0.693147180559945309417232121458...
constexpr double kLn2Hi = 6.93147180369123816490e-01;
constexpr double kLn2Lo = 1.90821492927058770002e-10;
constexpr double kSqrt2 = 1.41421356237309504880;
constexpr double kHalfPi = 1.57079632679489661923;

// Natural logarithm of x in [2^-1022, 2^1024), to the precision the Box-Muller transform needs
// (its only user):
// x = 2^e m, m in [sqrt(1/2), sqrt(2)); ln x = e ln 2 + 2 atanh(s), s = (m - 1)/(m + 1),
// atanh(s) = s + s^3/3 + ... + s^11/11 (|s| <= 3 - 2 sqrt 2 = 0.1716; the omitted terms
// 2 s^13/13 (1 + s^2 + ...) are < 5.2e-11 relative to ln m, and less relative to ln x when e != 0).
// Why that is enough: the uniform u1 = (x1 + 1) 2^-32 moves in steps of 2^-32, so the Box-Muller
// radius sqrt(-2 ln u1) moves in relative steps of at least 2^-32 / (2 max u |ln u|) = 2^-32 e / 2
// = 3.2e-10; the series error (2.6e-11 relative in the radius) is below a twelfth of a step.
template <int W>
inline D<W> Log(D<W> x) {
  const U<W> bits = AsBits<W>(x);
  const D<W> biased_exponent = ToDouble<W>(bits >> 52);
  const D<W> m_raw = AsDouble<W>((bits & 0x000fffffffffffffull) | 0x3ff0000000000000ull);  // [1, 2)
  const U<W> big = GreaterMask<W>(AsBits<W>(m_raw), __builtin_bit_cast(uint64_t, kSqrt2) + U<W>{});
  const D<W> m = Select<W>(big, 0.5 * m_raw, m_raw);
  const D<W> ed = biased_exponent - Select<W>(big, Splat<W>(1022.0), Splat<W>(1023.0));
  const D<W> s = (m - 1.0) / (m + 1.0);
  const D<W> s2 = s * s;
  D<W> p = Splat<W>(1.0 / 11.0);
  p = p * s2 + 1.0 / 9.0;
  p = p * s2 + 1.0 / 7.0;
  p = p * s2 + 1.0 / 5.0;
  p = p * s2 + 1.0 / 3.0;
  const D<W> log_m = 2.0 * s + 2.0 * s * s2 * p;
  return ed * kLn2Hi + (ed * kLn2Lo + log_m);
}

// n! for the Taylor coefficients 1/n!; exact in double for n <= 18 (18! < 2^53), so 1.0 / n! is
// correctly rounded at compile time.
constexpr double Factorial(int n) { return n <= 1 ? 1.0 : n * Factorial(n - 1); }

// How far SinCosOfQuadrant sums its Taylor series.
enum class Series {
  kFull,      // navigation: sin to t^17, cos to t^16 (omitted terms < 1e-19, < 2e-18)
  kGaussian,  // Box-Muller angle: sin to t^11, cos to t^12 (omitted < 7.0e-12, < 4.0e-13 at pi/4)
};

// sin and cos of q pi/2 + t for |t| <= pi/4 (plus rounding): Taylor series of sin t and cos t
// (Series), then rotated by the quadrant q mod 4: (sin, cos) -> (c, -s), (-s, -c), (-c, s) for
// q = 1, 2, 3, the signs applied by flipping the sign bit. Only the low two bits of q are used.
// The Gaussian series is enough for the Box-Muller angle 2 pi x2 2^-32: adjacent inputs are
// 1.5e-9 rad apart, 200 times the series error (Log above for the radius).
template <int W, Series kSeries = Series::kFull>
inline void SinCosOfQuadrant(D<W> t, U<W> q, D<W>& sin_out, D<W>& cos_out) {
  const D<W> t2 = t * t;
  D<W> ps;
  if constexpr (kSeries == Series::kFull) {
    ps = Splat<W>(1.0 / Factorial(17));
    ps = -ps * t2 + 1.0 / Factorial(15);
    ps = -ps * t2 + 1.0 / Factorial(13);
    ps = -ps * t2 + 1.0 / Factorial(11);
  } else {
    ps = Splat<W>(1.0 / Factorial(11));
  }
  ps = -ps * t2 + 1.0 / Factorial(9);
  ps = -ps * t2 + 1.0 / Factorial(7);
  ps = -ps * t2 + 1.0 / Factorial(5);
  ps = -ps * t2 + 1.0 / Factorial(3);
  const D<W> s = t - t * t2 * ps;
  D<W> pc;
  if constexpr (kSeries == Series::kFull) {
    pc = Splat<W>(1.0 / Factorial(16));
    pc = -pc * t2 + 1.0 / Factorial(14);
    pc = -pc * t2 + 1.0 / Factorial(12);
  } else {
    pc = Splat<W>(1.0 / Factorial(12));
  }
  pc = -pc * t2 + 1.0 / Factorial(10);
  pc = -pc * t2 + 1.0 / Factorial(8);
  pc = -pc * t2 + 1.0 / Factorial(6);
  pc = -pc * t2 + 1.0 / Factorial(4);
  pc = -pc * t2 + 1.0 / Factorial(2);
  const D<W> c = 1.0 - t2 * pc;
  const U<W> odd = U<W>{} - (q & 1u);
  const D<W> sw = Select<W>(odd, c, s);
  const D<W> cw = Select<W>(odd, s, c);
  const U<W> sin_sign = (q & 2u) << 62;
  const U<W> cos_sign = ((q + 1u) & 2u) << 62;
  sin_out = AsDouble<W>(AsBits<W>(sw) ^ sin_sign);
  cos_out = AsDouble<W>(AsBits<W>(cw) ^ cos_sign);
}

// sin and cos of 2 pi x / 2^32 for 32-bit words x (in 64-bit lanes), the Box-Muller angle (Gaussian
// series). Quadrant and remainder come
// exactly from the integer: n = round(x / 2^30), q = n mod 4 = ((x + 2^29) mod 2^32) >> 30, and
// r = x - n 2^30 in [-2^29, 2^29) (32-bit wrapping arithmetic, read as signed),
// theta = r pi / 2^31 in [-pi/4, pi/4].
template <int W>
inline void SinCosTwoPi(U<W> x, D<W>& sin_out, D<W>& cos_out) {
  const U<W> q = ((x + 0x20000000u) & 0xffffffffu) >> 30;
  const U<W> r_bits = (x - (q << 30)) & 0xffffffffu;  // r mod 2^32
  const D<W> r = ToDouble<W>(r_bits) - 4294967296.0 * ToDouble<W>(r_bits >> 31);
  SinCosOfQuadrant<W, Series::kGaussian>(r * (kHalfPi / 1073741824.0), q, sin_out, cos_out);
}

// pi/2 in three pieces of 33 significant bits (Cody and Waite, "Software Manual for the
// Elementary Functions", 1980, ch. 8; the split of fdlibm's e_rem_pio2.c: pio2_1, pio2_2, pio2_3),
// so that n * piece is exact for |n| < 2^20; together they carry pi/2 to ~2^-151.
constexpr double kPio2Part1 = 1.57079632673412561417e+00;
constexpr double kPio2Part2 = 6.07710050650619224932e-11;
constexpr double kPio2Part3 = 2.02226624871116645580e-21;
constexpr double kTwoOverPi = 6.36619772367581382433e-01;
// 1.5 * 2^52: x + kRoundMagic rounds x to an integer (to nearest) for |x| < 2^51, and the low
// bits of the sum's bit pattern hold that integer modulo 2^52.
constexpr double kRoundMagic = 6755399441055744.0;

// sin x and cos x, to within about 1 ulp for |x| < 1.6e6 rad (beyond, the reduction loses
// accuracy: n = round(2x/pi) must stay below 2^20); NaN or infinite x gives NaN.
// n = round(2x/pi), t = x - n pi/2 by Cody-Waite, then SinCosOfQuadrant(t, n).
template <int W>
inline void SinCos(D<W> x, D<W>& sin_out, D<W>& cos_out) {
  const D<W> k = x * kTwoOverPi + kRoundMagic;
  const U<W> q = AsBits<W>(k);
  const D<W> n = k - kRoundMagic;
  const D<W> t = ((x - n * kPio2Part1) - n * kPio2Part2) - n * kPio2Part3;
  SinCosOfQuadrant<W>(t, q, sin_out, cos_out);
}

// sin x and cos x from s0 = sin x0, c0 = cos x0 of a nearby x0 (a latitude within one step of
// another): the angle-sum rotation s0 cos d + c0 sin d, c0 cos d - s0 sin d, d = x - x0, with the
// Taylor series of sin d to d^7 and cos d to d^6 (|d| <= 0.01: omitted terms < 3e-24 and
// 2.5e-21, below rounding), within ~2 ulp as SinCos is within 1. A lane with |d| > 0.01 takes
// SinCos(x) itself (computed only if some lane needs it, chosen per lane: a lane's bits never
// depend on the other lanes).
template <int W>
inline void SinCosNear(D<W> x, D<W> x0, D<W> s0, D<W> c0, D<W>& sin_out, D<W>& cos_out) {
  const D<W> d = x - x0;
  const D<W> d2 = d * d;
  const D<W> sin_d = d - d * d2 * ((1.0 / 6.0) - d2 * ((1.0 / 120.0) - d2 * (1.0 / 5040.0)));
  const D<W> cos_d = 1.0 - d2 * (0.5 - d2 * ((1.0 / 24.0) - d2 * (1.0 / 720.0)));
  sin_out = s0 * cos_d + c0 * sin_d;
  cos_out = c0 * cos_d - s0 * sin_d;
  // |d| > 0.01, as a mask: d2's bit pattern against 1e-4's (both non-negative or NaN).
  const U<W> far = GreaterMask<W>(AsBits<W>(d2), __builtin_bit_cast(uint64_t, 1e-4) + U<W>{});
  bool any_far = false;
  for (int i = 0; i < W; ++i) any_far = any_far || GetLane<W>(far, i) != 0;
  if (any_far) {
    D<W> s_full, c_full;
    SinCos<W>(x, s_full, c_full);
    sin_out = Select<W>(far, s_full, sin_out);
    cos_out = Select<W>(far, c_full, cos_out);
  }
}

// ---- Scalar elementary functions (DESIGN.md "Same bits everywhere").
// The C library's exp, log, sin, cos, tan, atan, atan2, asin, expm1, lgamma differ from machine to
// machine: glibc on x86-64 picks an FMA or an SSE2 variant by CPU at run time, and arm64's glibc is
// a third build. Measured over 2e6 random arguments each, every one of these functions (and
// hypot between x86-64 and arm64) returns a different last bit for some arguments, so a job's
// results would depend on the CPU it runs on. These use only IEEE basic operations and integer bit
// operations (no contraction: -ffp-contract=off), so they give the same bits everywhere; the
// engine calls them (through driftlab/elementary.h) instead of the C library's. Accuracy within
// a few ulp (tests/engine/math/elementary_test.cc against long double); special values as C's.

constexpr double kInvLn2 = 1.44269504088896338700;  // 1 / ln 2
constexpr double kPiHi = 3.141592653589793;         // pi = kPiHi + kPiLo to ~1e-32
constexpr double kPiLo = 1.2246467991473532e-16;
constexpr double kPio2Hi = 1.5707963267948966;  // pi/2 = kPio2Hi + kPio2Lo
constexpr double kPio2Lo = 6.123233995736766e-17;

inline double Inf() { return __builtin_inf(); }
inline double QuietNaN() { return __builtin_nan(""); }

// 2^n for -1022 <= n <= 1023, exactly.
inline double TwoPow(int64_t n) {
  return __builtin_bit_cast(double, static_cast<uint64_t>(n + 1023) << 52);
}
// y 2^n for y in [0.5, 2] and -1100 <= n <= 1100, rounded once: two factors 2^(n/2) and
// 2^(n - n/2) are normal, the first product is exact, the second rounds (to a subnormal, to
// infinity or in between) once.
inline double ScaleByTwoPow(double y, int64_t n) {
  const int64_t n1 = n / 2;
  return (y * TwoPow(n1)) * TwoPow(n - n1);
}

// e^x - 1 for |x| <= 0.35 (+ rounding): x + x^2 (1/2! + x/3! + ... + x^13/15!); the omitted
// x^16/16! < 2.3e-21 relative to x^2/2.
inline double Expm1Series(double x) {
  double p = 1.0 / Factorial(15);
  for (int k = 14; k >= 2; --k) p = p * x + 1.0 / Factorial(k);  // k! exact: 1/k! rounded once
  return x + x * x * p;
}

// e^x: x = n ln 2 + r with n = round(x / ln 2) and r by Cody-Waite (kLn2Hi times n < 2^11 is
// exact), |r| <= ln 2 / 2; e^x = 2^n (1 + expm1(r)).
inline double Exp(double x) {
  if (!(x == x)) return x;                     // NaN
  if (x > 709.782712893384) return Inf();      // above ln(DBL_MAX)
  if (x < -745.1332191019412) return 0.0;      // below ln(smallest subnormal / 2)
  const double k = x * kInvLn2 + kRoundMagic;  // round(x / ln 2) in its low bits
  const double n = k - kRoundMagic;
  const double r = (x - n * kLn2Hi) - n * kLn2Lo;
  return ScaleByTwoPow(1.0 + Expm1Series(r), static_cast<int64_t>(n));
}

// e^x - 1, accurate near 0: the series for |x| <= ln 2 / 2, else Exp(x) - 1 (>= 0.29 in
// magnitude there, so the subtraction loses at most ~2 ulp).
inline double Expm1(double x) {
  if (!(x == x)) return x;
  if (x > -0.34657359027997264 && x < 0.34657359027997264) return Expm1Series(x);
  if (x < -40.0) return -1.0;  // e^x < 4.3e-18: -1 + e^x rounds to -1
  return Exp(x) - 1.0;
}

// ln x: x = 2^e m, m in [sqrt(1/2), sqrt(2)); ln x = e ln 2 + 2 atanh(s), s = (m - 1)/(m + 1),
// atanh(s) = s + s^3/3 + ... + s^21/21 (|s| <= 0.1716: the omitted terms are < 2.2e-19 of it).
// (The Box-Muller's Log<W> above is the same reduction with a series cut at s^11.)
inline double Ln(double x) {
  if (!(x > 0.0)) return x == 0.0 ? -Inf() : QuietNaN();  // 0, negative, NaN
  if (x == Inf()) return x;
  int64_t e = 0;
  if (x < 0x1p-1022) {  // subnormal: scale into the normal range
    x *= 0x1p54;
    e = -54;
  }
  const uint64_t bits = __builtin_bit_cast(uint64_t, x);
  e += static_cast<int64_t>(bits >> 52) - 1023;
  double m = __builtin_bit_cast(double, (bits & 0x000fffffffffffffull) | 0x3ff0000000000000ull);
  if (m > kSqrt2) {
    m *= 0.5;
    e += 1;
  }
  const double f = m - 1.0;  // exact (Sterbenz)
  const double s = f / (2.0 + f);
  const double s2 = s * s;
  double p = 1.0 / 21.0;
  p = p * s2 + 1.0 / 19.0;
  p = p * s2 + 1.0 / 17.0;
  p = p * s2 + 1.0 / 15.0;
  p = p * s2 + 1.0 / 13.0;
  p = p * s2 + 1.0 / 11.0;
  p = p * s2 + 1.0 / 9.0;
  p = p * s2 + 1.0 / 7.0;
  p = p * s2 + 1.0 / 5.0;
  p = p * s2 + 1.0 / 3.0;
  const double log_m = 2.0 * s + 2.0 * s * s2 * p;
  const double ed = static_cast<double>(e);
  return ed * kLn2Hi + (ed * kLn2Lo + log_m);
}

// sin x and cos x: SinCos for |x| < 1.5e6 (its Cody-Waite reduction is exact there); beyond, the
// C library's (no navigation angle gets there; a documented limit of the same-bits guarantee).
inline void SinCosScalar(double x, double* s, double* c) {
  if (x > -1.5e6 && x < 1.5e6) {
    SinCos<1>(x, *s, *c);
  } else {
    *s = __builtin_sin(x);
    *c = __builtin_cos(x);
  }
}

// atan t for 0 <= t <= 1: t against the nearest of c = 0, 1/4, 1/2, 3/4, 1 (all exact),
// atan t = atan c + atan u with u = (t - c)/(1 + t c) (t - c exact by Sterbenz, |u| <= 1/8);
// atan u = u - u^3/3 + ... - u^19/19 (the omitted u^21/21 < 4.3e-21); atan c as hi + lo
// (hi: atan c rounded; lo: the rest, from 60-digit values: atan 1/4 = 0.24497866312686415417...,
// atan 1/2 = 0.46364760900080611621..., atan 3/4 = 0.64350110879328438680..., atan 1 = pi/4).
// Returns hi and the small rest separately, so that pi/2 - atan and pi - atan keep the precision.
inline void AtanUnit(double t, double* hi, double* rest) {
  static constexpr double kHi[5] = {0.0, 0.24497866312686414, 0.4636476090008061,
                                    0.6435011087932844, 0.7853981633974483};
  static constexpr double kLo[5] = {0.0, 1.0698755618734451e-17, 2.2698777452961687e-17,
                                    1.5834785051444286e-17, 3.061616997868383e-17};
  const int k = t < 0.125 ? 0 : (t < 0.375 ? 1 : (t < 0.625 ? 2 : (t < 0.875 ? 3 : 4)));
  const double c = 0.25 * k;
  const double u = k == 0 ? t : (t - c) / (1.0 + t * c);
  const double u2 = u * u;
  double q = -1.0 / 19.0;
  q = q * u2 + 1.0 / 17.0;
  q = q * u2 - 1.0 / 15.0;
  q = q * u2 + 1.0 / 13.0;
  q = q * u2 - 1.0 / 11.0;
  q = q * u2 + 1.0 / 9.0;
  q = q * u2 - 1.0 / 7.0;
  q = q * u2 + 1.0 / 5.0;
  q = q * u2 - 1.0 / 3.0;
  *hi = kHi[k];
  *rest = kLo[k] + (u + u * u2 * q);
}

// atan x; |x| > 1 as pi/2 - atan(1/|x|).
inline double Atan(double x) {
  if (!(x == x)) return x;
  const double a = __builtin_fabs(x);
  double hi, rest, z;
  if (a <= 1.0) {
    AtanUnit(a, &hi, &rest);
    z = hi + rest;
  } else {
    AtanUnit(1.0 / a, &hi, &rest);
    z = (kPio2Hi - hi) + (kPio2Lo - rest);
  }
  return x < 0.0 ? -z : z;
}

// atan2(y, x) in [-pi, pi], with C's values at zeros and infinities.
inline double Atan2(double y, double x) {
  if (!(x == x) || !(y == y)) return x + y;  // NaN
  const bool y_negative = __builtin_signbit(y) != 0;
  const bool x_negative = __builtin_signbit(x) != 0;
  const double ay = __builtin_fabs(y), ax = __builtin_fabs(x);
  double z;
  if (ay == 0.0) {
    z = x_negative ? kPiHi : 0.0;  // atan2(+-0, -0 or x < 0) = +-pi, (+-0, +0 or x > 0) = +-0
  } else if (ay == Inf() && ax == Inf()) {
    z = x_negative ? 3.0 * (kPio2Hi / 2.0) : kPio2Hi / 2.0;
  } else if (ax == 0.0 || ay == Inf()) {
    z = kPio2Hi;
  } else if (ax == Inf()) {
    z = x_negative ? kPiHi : 0.0;
  } else {
    double hi, rest;
    if (ay <= ax) {
      AtanUnit(ay / ax, &hi, &rest);
      z = x_negative ? (kPiHi - hi) + (kPiLo - rest) : hi + rest;
    } else {
      AtanUnit(ax / ay, &hi, &rest);
      // pi/2 - atan(ax/ay), or pi/2 + atan(ax/ay) when x < 0
      z = x_negative ? (kPio2Hi + hi) + (kPio2Lo + rest) : (kPio2Hi - hi) + (kPio2Lo - rest);
    }
  }
  return y_negative ? -z : z;
}

// asin x = atan2(x, sqrt((1 - x)(1 + x))) for |x| <= 1 (1 - x exact near 1); NaN beyond.
inline double Asin(double x) {
  if (!(x >= -1.0 && x <= 1.0)) return QuietNaN();
  return Atan2(x, __builtin_sqrt((1.0 - x) * (1.0 + x)));
}

// acos x = atan2(sqrt((1 - x)(1 + x)), x) for |x| <= 1; NaN beyond.
inline double Acos(double x) {
  if (!(x >= -1.0 && x <= 1.0)) return QuietNaN();
  return Atan2(__builtin_sqrt((1.0 - x) * (1.0 + x)), x);
}

// ln(1 + x), accurate near 0: with u = 1 + x rounded, ln(1 + x) = ln(u) x / (u - 1) (u - 1 is
// exact, and the factor corrects for the rounding of u: D. Goldberg, "What every computer
// scientist should know about floating-point arithmetic", ACM Computing Surveys 23 (1991),
// Theorem 4).
inline double Log1p(double x) {
  if (!(x == x)) return x;
  const double u = 1.0 + x;
  if (u == 1.0) return x;
  if (u == Inf()) return u;
  return Ln(u) * (x / (u - 1.0));
}

// sqrt(x^2 + y^2) without overflow or underflow: directly where the squares stay normal, else
// after scaling both by the same power of two (exact). C's hypot: infinite if either is.
inline double Hypot(double x, double y) {
  double a = __builtin_fabs(x), b = __builtin_fabs(y);
  if (a == Inf() || b == Inf()) return Inf();
  if (!(a == a) || !(b == b)) return QuietNaN();
  if (a < b) {
    const double t = a;
    a = b;
    b = t;
  }
  if (b == 0.0) return a;
  if (a < 0x1p500 && b > 0x1p-500) return __builtin_sqrt(a * a + b * b);
  // a = 2^ea m: scale by 2^-ea (a into [1, 2)), b alike (it may lose bits below 2^-1074 of a,
  // which are below a's rounding).
  const int64_t ea = static_cast<int64_t>(__builtin_bit_cast(uint64_t, a) >> 52) - 1023;
  const int64_t shift = ea < -1022 ? -1022 : ea;  // a subnormal: scale by 2^1022 first
  const double as = ScaleByTwoPow(a, -shift), bs = ScaleByTwoPow(b, -shift);
  return ScaleByTwoPow(__builtin_sqrt(as * as + bs * bs), shift);
}

// ln Gamma(a) for a > 0: shifted up to z = a + n >= 10 (ln Gamma(a) = ln Gamma(z) -
// ln(a (a+1) ... (a+n-1))), then Stirling's series (Abramowitz and Stegun 6.1.41) to z^-13: the
// omitted 3617/(122400 z^15) < 3e-17 for z >= 10.
inline double LgammaPositive(double a) {
  if (!(a > 0.0)) return QuietNaN();
  if (a == Inf()) return a;
  double z = a, product = 1.0;
  while (z < 10.0) {
    product *= z;
    z += 1.0;
  }
  const double w = 1.0 / z, w2 = w * w;
  double series = -691.0 / 360360.0 + w2 * (1.0 / 156.0);
  series = 1.0 / 1188.0 + w2 * series;
  series = -1.0 / 1680.0 + w2 * series;
  series = 1.0 / 1260.0 + w2 * series;
  series = -1.0 / 360.0 + w2 * series;
  series = w * (1.0 / 12.0 + w2 * series);
  constexpr double kHalfLn2Pi = 0.91893853320467274178;  // ln(2 pi) / 2
  return (((z - 0.5) * Ln(z) - z) + kHalfLn2Pi + series) - Ln(product);
}

}  // namespace
}  // namespace driftlab::elementary
