// The lane primitives: a value of W lanes (W runs, or W arguments, at once) and the lane-wise
// operations the physics is written with. W = 1 is plain double / uint64_t (the scalar code);
// W > 1 a GCC vector of W doubles / W uint64_t (the lockstep kernels, one copy per instruction
// set). The physics written over W (earth/earth_lanes.h, ins/ned_step.h, sensors/triad_step.h,
// math/vector_lanes.h, math/elementary_functions.h, stats/nav_error_lanes.h, random/
// random_kernels.h) uses only these and IEEE basic operations (+, -, *, /, sqrt: correctly rounded
// per lane), so every W and every instruction set gives the same bits; files including this header
// are built with -ffp-contract=off (as the whole engine), so no multiply-add is fused.
//
// Constraints of every lane header: internal linkage (an anonymous namespace) and no Eigen or
// standard-library templates. The per-instruction-set kernel files (lockstep/lockstep_ned_*.cc)
// include them and are compiled with their own instruction-set options; an inline function with
// external linkage emitted by the AVX-512 file could be picked by the linker for every caller
// (lockstep/lockstep_lanes.h).
#pragma once

#include <cstdint>

namespace driftlab::lanes {
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

// W doubles; W 64-bit masks or integers.
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
// All-ones lanes where a comparison of two D<W> holds (the comparison's own result: a bool for
// W = 1, a vector of 0 / -1 for W > 1).
template <int W>
inline U<W> MaskOf(decltype(D<W>{} < D<W>{}) m) {
  if constexpr (W == 1) {
    return m ? ~uint64_t{0} : uint64_t{0};
  } else {
    return __builtin_bit_cast(U<W>, m);
  }
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
// x in every lane.
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

// u as a double, exactly, for u < 2^52 (the 2^52 magic-number trick: no conversion instruction,
// which SSE2 and AVX2 lack for unsigned or 64-bit integers).
template <int W>
inline D<W> ToDouble(U<W> u) {
  return AsDouble<W>(u | kTwoPow52Bits) - kTwoPow52;
}

// W consecutive doubles from memory, and back.
template <int W>
inline D<W> Load(const double* p) {
  D<W> v;
  __builtin_memcpy(&v, p, sizeof(v));
  return v;
}
template <int W>
inline void Store(double* p, D<W> v) {
  __builtin_memcpy(p, &v, sizeof(v));
}

// A state field of W lanes: an array x[lane] (the lockstep groups' structure of arrays, at least W
// long) or, for W = 1, a plain double (the scalar code's state); read and written alike, so one
// step function serves both.
template <int W, int N>
inline D<W> Get(const double (&a)[N]) {
  static_assert(N >= W, "a lane array holds at least W lanes");
  return Load<W>(a);
}
template <int W>
inline D<W> Get(const double& x) requires(W == 1) {
  return x;
}
template <int W, int N>
inline void Put(double (&a)[N], D<W> v) {
  static_assert(N >= W, "a lane array holds at least W lanes");
  Store<W>(a, v);
}
template <int W>
inline void Put(double& x, D<W> v) requires(W == 1) {
  x = v;
}

}  // namespace
}  // namespace driftlab::lanes
