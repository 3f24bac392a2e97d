// Philox4x32-10 and the Box-Muller transform with the engine's own ln, sin, cos (random.h), as
// internal-linkage inline code: random.cc (RandomStream) includes it, and so does each lockstep
// kernel file (lockstep_ned_kernel.h), which compiles it for its own instruction set. No Eigen or
// standard-library templates (std::bit_cast, std::min): an inline function of an AVX-512 file must
// not be shared with baseline code by the linker. Same source, IEEE operations, no contraction:
// the same bits on every instruction set.
#pragma once

#include <cstddef>
#include <cstdint>

namespace driftlab::random_kernels {
namespace {

// Philox4x32 multipliers and Weyl-sequence key increments, Salmon et al. SC11 section 5.2
// (the same constants as the Random123 reference, PHILOX_M4x32_0/1 and PHILOX_W32_0/1: the
// golden ratio and sqrt(3) - 1 in 32-bit fixed point).
constexpr uint32_t kPhiloxM0 = 0xD2511F53u;
constexpr uint32_t kPhiloxM1 = 0xCD9E8D57u;
constexpr uint32_t kPhiloxW0 = 0x9E3779B9u;
constexpr uint32_t kPhiloxW1 = 0xBB67AE85u;

// 2^-32.
constexpr double kTwoPowMinus32 = 1.0 / 4294967296.0;

// One Philox S-box/permutation round: (hi, lo) = M0 * c0 and M1 * c2 (32 x 32 -> 64 bits);
// c' = (hi1 ^ c1 ^ k0, lo1, hi0 ^ c3 ^ k1, lo0).  Salmon et al. section 5.2, Fig. 2.
inline void PhiloxRound(uint32_t& c0, uint32_t& c1, uint32_t& c2, uint32_t& c3, uint32_t k0,
                        uint32_t k1) {
  const uint64_t p0 = static_cast<uint64_t>(kPhiloxM0) * c0;
  const uint64_t p1 = static_cast<uint64_t>(kPhiloxM1) * c2;
  const uint32_t hi0 = static_cast<uint32_t>(p0 >> 32);
  const uint32_t lo0 = static_cast<uint32_t>(p0);
  const uint32_t hi1 = static_cast<uint32_t>(p1 >> 32);
  const uint32_t lo1 = static_cast<uint32_t>(p1);
  c0 = hi1 ^ c1 ^ k0;
  c1 = lo1;
  c2 = hi0 ^ c3 ^ k1;
  c3 = lo0;
}

// Ten rounds; the key is bumped by the Weyl increments between rounds.
inline void Philox10(uint32_t& c0, uint32_t& c1, uint32_t& c2, uint32_t& c3, uint32_t k0,
                     uint32_t k1) {
  for (int round = 0; round < 10; ++round) {  // kPhiloxRounds (random.h)
    if (round > 0) {
      k0 += kPhiloxW0;
      k1 += kPhiloxW1;
    }
    PhiloxRound(c0, c1, c2, c3, k0, k1);
  }
}

// ln 2 split so that e * kLn2Hi is exact for |e| < 2^11 (the fdlibm split: kLn2Hi has 32
// significant bits). ln 2 = 0.693147180559945309417232121458...
constexpr double kLn2Hi = 6.93147180369123816490e-01;
constexpr double kLn2Lo = 1.90821492927058770002e-10;
constexpr double kSqrt2 = 1.41421356237309504880;
constexpr double kHalfPi = 1.57079632679489661923;

inline double LogInline(double x) {
  // x = 2^e m, m in [sqrt(1/2), sqrt(2)); ln x = e ln 2 + 2 atanh(s), s = (m - 1)/(m + 1),
  // atanh(s) = s + s^3/3 + s^5/5 + ...  (|s| <= 3 - 2 sqrt 2 = 0.1716, s^2 <= 0.02944; the first
  // omitted term 2 s^23 / 23 < 1e-18 relative to ln m).
  // Branch-free and with 64-bit integer operations only (shift, and, or), so that the loops
  // calling it vectorise: the exponent field becomes a double by the 2^52 magic-number trick.
  const uint64_t bits = __builtin_bit_cast(uint64_t, x);
  const double biased_exponent =
      __builtin_bit_cast(double, 0x4330000000000000ull | (bits >> 52)) - 4503599627370496.0;
  const double m_raw =
      __builtin_bit_cast(double, (bits & 0x000fffffffffffffull) | 0x3ff0000000000000ull);  // [1, 2)
  const bool big = m_raw > kSqrt2;
  const double m = big ? 0.5 * m_raw : m_raw;
  const double ed = biased_exponent - (big ? 1022.0 : 1023.0);
  const double s = (m - 1.0) / (m + 1.0);
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
  return ed * kLn2Hi + (ed * kLn2Lo + log_m);
}

// n! for the Taylor coefficients 1/n!; exact in double for n <= 18 (18! < 2^53), so 1.0 / n! is
// correctly rounded at compile time.
constexpr double Factorial(int n) { return n <= 1 ? 1.0 : n * Factorial(n - 1); }

// sin and cos of 2 pi x / 2^32. Quadrant and remainder come exactly from the integer:
// n = round(x / 2^30), q = n mod 4 = ((x + 2^29) mod 2^32) >> 30, and
// r 2^30 = x - n 2^30 in [-2^29, 2^29) (wrapping 32-bit arithmetic), theta = r pi/2 in
// [-pi/4, pi/4]. Only 32/64-bit integer and double operations, no branches: vectorises.
inline void SinCosTwoPiInline(uint32_t x, double& sin_out, double& cos_out) {
  const uint32_t q = (x + 0x20000000u) >> 30;
  const int32_t r = static_cast<int32_t>(x - (q << 30));
  const double t = static_cast<double>(r) * (kHalfPi / 1073741824.0);
  const double t2 = t * t;
  // sin t = t - t^3/3! + ... + t^17/17!  (omitted t^19/19! < 1e-19 at |t| = pi/4)
  double ps = 1.0 / Factorial(17);
  ps = -ps * t2 + 1.0 / Factorial(15);
  ps = -ps * t2 + 1.0 / Factorial(13);
  ps = -ps * t2 + 1.0 / Factorial(11);
  ps = -ps * t2 + 1.0 / Factorial(9);
  ps = -ps * t2 + 1.0 / Factorial(7);
  ps = -ps * t2 + 1.0 / Factorial(5);
  ps = -ps * t2 + 1.0 / Factorial(3);
  const double s = t - t * t2 * ps;
  // cos t = 1 - t^2/2! + ... + t^16/16!  (omitted t^18/18! < 2e-18)
  double pc = 1.0 / Factorial(16);
  pc = -pc * t2 + 1.0 / Factorial(14);
  pc = -pc * t2 + 1.0 / Factorial(12);
  pc = -pc * t2 + 1.0 / Factorial(10);
  pc = -pc * t2 + 1.0 / Factorial(8);
  pc = -pc * t2 + 1.0 / Factorial(6);
  pc = -pc * t2 + 1.0 / Factorial(4);
  pc = -pc * t2 + 1.0 / Factorial(2);
  const double c = 1.0 - t2 * pc;
  // Rotate by the quadrant: (sin, cos) -> (c, -s), (-s, -c), (-c, s) for q = 1, 2, 3; the signs
  // are applied by flipping the sign bit.
  const bool odd = (q & 1u) != 0;
  const double sw = odd ? c : s;
  const double cw = odd ? s : c;
  const uint64_t sin_sign = static_cast<uint64_t>(q & 2u) << 62;
  const uint64_t cos_sign = static_cast<uint64_t>((q + 1u) & 2u) << 62;
  sin_out = __builtin_bit_cast(double, __builtin_bit_cast(uint64_t, sw) ^ sin_sign);
  cos_out = __builtin_bit_cast(double, __builtin_bit_cast(uint64_t, cw) ^ cos_sign);
}

// Deviates of blocks [block0, block0 + nblocks) in index order (4 per block) into out.
constexpr int kChunkBlocks = 32;

inline void PhiloxChunk(const uint32_t* key, uint32_t run_word, uint32_t stream_word,
                        uint64_t block0, int nblocks, uint32_t (&x)[4][kChunkBlocks]) {
  for (int b = 0; b < nblocks; ++b) {
    const uint64_t block = block0 + static_cast<uint64_t>(b);
    uint32_t c0 = static_cast<uint32_t>(block);
    uint32_t c1 = static_cast<uint32_t>(block >> 32);
    uint32_t c2 = run_word;
    uint32_t c3 = stream_word;
    Philox10(c0, c1, c2, c3, key[0], key[1]);
    x[0][b] = c0;
    x[1][b] = c1;
    x[2][b] = c2;
    x[3][b] = c3;
  }
}

inline void GaussianChunk(const uint32_t* key, uint32_t run_word, uint32_t stream_word,
                          uint64_t block0, int nblocks, double* out) {
  uint32_t x[4][kChunkBlocks];
  PhiloxChunk(key, run_word, stream_word, block0, nblocks, x);
  // Box-Muller on the pairs (x0, x1) -> deviates 0, 1 and (x2, x3) -> deviates 2, 3 of a block.
  for (int pair = 0; pair < 2; ++pair) {
    const uint32_t* xr = x[2 * pair];
    const uint32_t* xa = x[2 * pair + 1];
    for (int b = 0; b < nblocks; ++b) {
      const double u1 = (static_cast<double>(xr[b]) + 1.0) * kTwoPowMinus32;  // (0, 1]
      const double radius = __builtin_sqrt(-2.0 * LogInline(u1));
      double s, c;
      SinCosTwoPiInline(xa[b], s, c);  // angle 2 pi u2, u2 = x 2^-32 in [0, 1)
      out[4 * b + 2 * pair] = radius * c;
      out[4 * b + 2 * pair + 1] = radius * s;
    }
  }
}

inline void UniformChunk(const uint32_t* key, uint32_t run_word, uint32_t stream_word,
                         uint64_t block0, int nblocks, double* out) {
  uint32_t x[4][kChunkBlocks];
  PhiloxChunk(key, run_word, stream_word, block0, nblocks, x);
  for (int b = 0; b < nblocks; ++b) {
    for (int lane = 0; lane < 4; ++lane) {
      out[4 * b + lane] = (static_cast<double>(x[lane][b]) + 0.5) * kTwoPowMinus32;
    }
  }
}

// Fills out[i] = deviate first_index + i, i < count, chunk by chunk. Whole chunks are written in
// place; a partial first or last block goes through a small buffer on the stack.
template <typename ChunkFn>
inline void FillByChunks(ChunkFn chunk, uint64_t first_index, double* out, size_t count) {
  double buffer[4 * kChunkBlocks];
  size_t pos = 0;
  uint64_t index = first_index;
  while (pos < count) {
    const uint64_t block0 = index >> 2;
    const size_t offset = static_cast<size_t>(index & 3u);
    const size_t remaining = count - pos;
    const size_t wanted_blocks = (offset + remaining + 3) / 4;
    const int nblocks =
        static_cast<int>(wanted_blocks < kChunkBlocks ? wanted_blocks : size_t{kChunkBlocks});
    const size_t whole = static_cast<size_t>(4 * nblocks) - offset;
    const size_t take = remaining < whole ? remaining : whole;
    if (offset == 0 && take == static_cast<size_t>(4 * nblocks)) {
      chunk(block0, nblocks, out + pos);
    } else {
      chunk(block0, nblocks, buffer);
      for (size_t i = 0; i < take; ++i) out[pos + i] = buffer[offset + i];
    }
    pos += take;
    index += take;
  }
}

// N(0, 1) deviates first_index .. first_index + count - 1 of the stream (key, run_word,
// stream_word) (RandomStream::FillGaussian).
inline void FillGaussianRange(const uint32_t* key, uint32_t run_word, uint32_t stream_word,
                              uint64_t first_index, double* out, size_t count) {
  FillByChunks(
      [&](uint64_t block0, int nblocks, double* dst) {
        GaussianChunk(key, run_word, stream_word, block0, nblocks, dst);
      },
      first_index, out, count);
}

// U(0, 1) deviates (RandomStream::FillUniform).
inline void FillUniformRange(const uint32_t* key, uint32_t run_word, uint32_t stream_word,
                             uint64_t first_index, double* out, size_t count) {
  FillByChunks([&](uint64_t block0, int nblocks,
                   double* dst) { UniformChunk(key, run_word, stream_word, block0, nblocks, dst); },
               first_index, out, count);
}
}  // namespace
}  // namespace driftlab::random_kernels
