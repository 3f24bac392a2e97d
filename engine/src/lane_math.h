// The engine's own elementary functions (DESIGN.md "Same bits everywhere"), written once over a
// lane type: W = 1 is plain double / uint64_t (the scalar code: random.cc, earth.cc,
// attitude.cc), W > 1 a GCC vector of W doubles / W uint64_t (the lockstep kernels, one copy per
// instruction set). Only IEEE basic operations (+, -, *, /, sqrt: correctly rounded per lane) and
// integer bit operations; no branches, no comparisons, no conversion instructions (integers become
// doubles by the 2^52 magic-number trick, exactly), so every W and every instruction set gives the
// same bits, and the code vectorises on every x86-64 level (SSE2 and AVX2 have no unsigned or
// 64-bit integer -> double conversion). Files including this header are built with
// -ffp-contract=off (as the whole engine), so no multiply-add is fused.
// Internal linkage and no standard-library templates: an inline function of an AVX-512 file must
// not be shared with baseline code by the linker (lockstep_lanes.h).
#pragma once

#include <cstdint>

namespace driftlab::lane_math {
namespace {

template <int W>
struct Lanes {
  typedef double D __attribute__((vector_size(W * sizeof(double))));
  typedef uint64_t U __attribute__((vector_size(W * sizeof(uint64_t))));
};
template <>
struct Lanes<1> {
  typedef double D;
  typedef uint64_t U;
};

template <int W>
using D = typename Lanes<W>::D;
template <int W>
using U = typename Lanes<W>::U;

template <int W>
inline D<W> AsDouble(U<W> u) {
  return __builtin_bit_cast(D<W>, u);
}
template <int W>
inline U<W> AsBits(D<W> d) {
  return __builtin_bit_cast(U<W>, d);
}
// mask ? a : b, lane by lane, for a mask of all-ones or all-zeros lanes.
template <int W>
inline D<W> Select(U<W> mask, D<W> a, D<W> b) {
  return AsDouble<W>((AsBits<W>(a) & mask) | (AsBits<W>(b) & ~mask));
}
// All-ones where a > b, for a, b < 2^63 (bit patterns of non-negative doubles compare as the
// doubles do): the borrow of b - a is its top bit.
template <int W>
inline U<W> GreaterMask(U<W> a, U<W> b) {
  return U<W>{} - ((b - a) >> 63);
}
// Lane i of a mask (W = 1: the value itself).
template <int W>
inline uint64_t GetLane(U<W> v, int i) {
  if constexpr (W == 1) {
    (void)i;
    return v;
  } else {
    return v[i];
  }
}
// x clamped to [lo, hi] lane by lane (lo <= hi; a NaN lane stays NaN).
template <int W>
inline D<W> Clamp(D<W> x, double lo, double hi) {
  if constexpr (W == 1) {
    return x < lo ? lo : (hi < x ? hi : x);
  } else {
    for (int i = 0; i < W; ++i) x[i] = x[i] < lo ? lo : (hi < x[i] ? hi : x[i]);
    return x;
  }
}
// floor, lane by lane.
template <int W>
inline D<W> Floor(D<W> x) {
  if constexpr (W == 1) {
    return __builtin_floor(x);
  } else {
    for (int i = 0; i < W; ++i) x[i] = __builtin_floor(x[i]);
    return x;
  }
}
template <int W>
inline D<W> Splat(double x) {
  if constexpr (W == 1) {
    return x;
  } else {
    return D<W>{} + x;
  }
}
template <int W>
inline D<W> Sqrt(D<W> x) {
  if constexpr (W == 1) {
    return __builtin_sqrt(x);
  } else {
    for (int i = 0; i < W; ++i) x[i] = __builtin_sqrt(x[i]);
    return x;
  }
}

constexpr double kTwoPow52 = 4503599627370496.0;
constexpr uint64_t kTwoPow52Bits = 0x4330000000000000ull;  // the double 2^52

// u as a double, exactly, for u < 2^52.
template <int W>
inline D<W> ToDouble(U<W> u) {
  return AsDouble<W>(u | kTwoPow52Bits) - kTwoPow52;
}

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
// Until issue 17 this series ran to s^21 (1e-18); the cheaper one changed every deviate's last
// ~10 digits once.
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

}  // namespace
}  // namespace driftlab::lane_math
