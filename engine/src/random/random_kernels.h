// Philox4x32-10 and the Box-Muller transform with the engine's own ln, sin, cos (random.h), as
// internal-linkage inline code: random.cc (RandomStream) includes it, and so does each lockstep
// kernel file (lockstep_ned_kernel.h), which compiles it for its own instruction set. No Eigen or
// standard-library templates (std::bit_cast, std::min): an inline function of an AVX-512 file must
// not be shared with baseline code by the linker. Same source, IEEE operations, no contraction:
// the same bits on every instruction set.
#pragma once

#include <cstddef>
#include <cstdint>

#include "lanes/lane.h"
#include "math/elementary_functions.h"

#if defined(__SSE2__)
#include <immintrin.h>
#endif

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

inline double LogInline(double x) { return elementary::Log<1>(x); }

inline void SinCosTwoPiInline(uint32_t x, double& sin_out, double& cos_out) {
  elementary::SinCosTwoPi<1>(x, sin_out, cos_out);
}

// Deviates of blocks [block0, block0 + nblocks) in index order (4 per block) into out.
constexpr int kChunkBlocks = 32;

// Philox blocks per explicit vector (64-bit lanes) where that beats the compiler's own
// vectorisation of the scalar loop: AVX2 (GCC 12 -O2 leaves that loop scalar); GCC vectorises it
// for AVX-512 itself (better than the explicit form), and SSE2's two lanes gain nothing.
#if defined(__AVX2__) && !defined(__AVX512F__)
constexpr int kPhiloxLanes = 4;
#else
constexpr int kPhiloxLanes = 1;
#endif

// a * m for lanes a < 2^32: the 32 x 32 -> 64-bit product Philox needs, by the instruction that
// multiplies the low 32 bits of each 64-bit lane (VPMULUDQ). Integer arithmetic: exact, the
// same on every path.
template <int W>
inline lanes::U<W> MulLow32(lanes::U<W> a, uint32_t m) {
#if defined(__AVX512F__)
  if constexpr (W == 8) {
    // GCC 12's _mm512_mul_epu32 passes an undefined merge operand that -Wmaybe-uninitialized
    // reports; the instruction does not read it.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
    return reinterpret_cast<lanes::U<W>>(
        _mm512_mul_epu32(reinterpret_cast<__m512i>(a), _mm512_set1_epi64(m)));
#pragma GCC diagnostic pop
  }
#endif
#if defined(__AVX2__)
  if constexpr (W == 4) {
    return reinterpret_cast<lanes::U<W>>(
        _mm256_mul_epu32(reinterpret_cast<__m256i>(a), _mm256_set1_epi64x(m)));
  }
#endif
#if defined(__SSE2__)
  if constexpr (W == 2) {
    return reinterpret_cast<lanes::U<W>>(
        _mm_mul_epu32(reinterpret_cast<__m128i>(a), _mm_set1_epi64x(m)));
  } else if constexpr (W > 2) {  // the two halves, each by the widest instruction above
    lanes::U<W / 2> half[2];
    __builtin_memcpy(half, &a, sizeof(a));
    half[0] = MulLow32<W / 2>(half[0], m);
    half[1] = MulLow32<W / 2>(half[1], m);
    lanes::U<W> r;
    __builtin_memcpy(&r, half, sizeof(r));
    return r;
  }
#endif
  return a * static_cast<uint64_t>(m);
}

// The ten Philox rounds of Philox10 above on W counters at once, in 64-bit lanes holding 32-bit
// words.
template <int W>
inline void PhiloxRoundsLanes(const uint32_t* key, lanes::U<W>& c0, lanes::U<W>& c1,
                              lanes::U<W>& c2, lanes::U<W>& c3) {
  using lanes::U;
  uint32_t k0 = key[0], k1 = key[1];
#pragma GCC unroll 10
  for (int round = 0; round < 10; ++round) {  // kPhiloxRounds (random.h)
    if (round > 0) {
      k0 += kPhiloxW0;
      k1 += kPhiloxW1;
    }
    const U<W> p0 = MulLow32<W>(c0, kPhiloxM0);
    const U<W> p1 = MulLow32<W>(c2, kPhiloxM1);
    c0 = (p1 >> 32) ^ c1 ^ static_cast<uint64_t>(k0);
    c1 = p1 & 0xffffffffu;
    c2 = (p0 >> 32) ^ c3 ^ static_cast<uint64_t>(k1);
    c3 = p0 & 0xffffffffu;
  }
}

// Philox4x32-10 of the counters (block, run_word, stream_word) for W consecutive blocks, in
// 64-bit lanes holding 32-bit words; the rounds of Philox10 above.
template <int W>
inline void PhiloxLanes(const uint32_t* key, uint32_t run_word, uint32_t stream_word,
                        uint64_t block, uint32_t (&x)[4][kChunkBlocks], int b) {
  using lanes::U;
  U<W> blocks;
  if constexpr (W == 1) {
    blocks = block;
  } else {
    for (int i = 0; i < W; ++i) blocks[i] = block + static_cast<uint64_t>(i);
  }
  U<W> c0 = blocks & 0xffffffffu;
  U<W> c1 = blocks >> 32;
  U<W> c2 = U<W>{} + run_word;
  U<W> c3 = U<W>{} + stream_word;
  PhiloxRoundsLanes<W>(key, c0, c1, c2, c3);
  if constexpr (W == 1) {
    x[0][b] = static_cast<uint32_t>(c0);
    x[1][b] = static_cast<uint32_t>(c1);
    x[2][b] = static_cast<uint32_t>(c2);
    x[3][b] = static_cast<uint32_t>(c3);
  } else {
    for (int i = 0; i < W; ++i) {
      x[0][b + i] = static_cast<uint32_t>(c0[i]);
      x[1][b + i] = static_cast<uint32_t>(c1[i]);
      x[2][b + i] = static_cast<uint32_t>(c2[i]);
      x[3][b + i] = static_cast<uint32_t>(c3[i]);
    }
  }
}

inline void PhiloxChunk(const uint32_t* key, uint32_t run_word, uint32_t stream_word,
                        uint64_t block0, int nblocks, uint32_t (&x)[4][kChunkBlocks]) {
  int b = 0;
  if constexpr (kPhiloxLanes > 1) {
    for (; b + kPhiloxLanes <= nblocks; b += kPhiloxLanes) {
      PhiloxLanes<kPhiloxLanes>(key, run_word, stream_word, block0 + static_cast<uint64_t>(b), x,
                                b);
    }
  }
  for (; b < nblocks; ++b) {
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
  // Box-Muller on the pairs (x0, x1) -> deviates 0, 1 and (x2, x3) -> deviates 2, 3 of a block:
  // z = sqrt(-2 ln u1) (cos, sin)(2 pi u2), u1 = (x0 + 1) 2^-32 in (0, 1], u2 = x1 2^-32.
  // Branch-free scalar code (math/elementary_functions.h, W = 1) that the compiler vectorises
  // across blocks.
  for (int pair = 0; pair < 2; ++pair) {
    const uint32_t* xr = x[2 * pair];
    const uint32_t* xa = x[2 * pair + 1];
    for (int b = 0; b < nblocks; ++b) {
      const double u1 = (lanes::ToDouble<1>(xr[b]) + 1.0) * kTwoPowMinus32;
      const double radius = __builtin_sqrt(-2.0 * elementary::Log<1>(u1));
      double s, c;
      elementary::SinCosTwoPi<1>(xa[b], s, c);
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

// Deviates of several runs at once (the lockstep kernels): the streams (key, run_words[lane],
// stream_word) of kLanes runs that differ only in their run word, blocks [block0, block0 +
// nblocks), deviate 4 b + i of lane l into out[(4 (b - block0) + i) * kRowStride + l], i.e. rows
// of one sample for all lanes, the layout the kernels read (kRowStride = kMaxLanes). W lanes per
// vector: Philox and Box-Muller across runs rather than across blocks, so each row is one vector
// store (no interleaving of the four words of a block, no copy). The same operations on each lane
// as GaussianChunk: the same bits.
template <int W, int kLanes, int kRowStride>
inline void GaussianAcrossRuns(const uint32_t* key, const uint32_t* run_words, uint32_t stream_word,
                               uint64_t block0, int nblocks, double* out) {
  using lanes::D;
  using lanes::U;
  static_assert(kLanes % W == 0, "whole vectors of lanes");
  constexpr int kG = kLanes / W;
  U<W> run[kG];
  for (int g = 0; g < kG; ++g) {
    if constexpr (W == 1) {
      run[g] = run_words[g];
    } else {
      for (int i = 0; i < W; ++i) run[g][i] = run_words[g * W + i];
    }
  }
  // Philox for a chunk of blocks, then Box-Muller on its words: each loop's iterations are
  // independent and short, so the processor overlaps them (a block's ten rounds are one chain).
  for (int b0 = 0; b0 < nblocks; b0 += kChunkBlocks) {
    const int n = nblocks - b0 < kChunkBlocks ? nblocks - b0 : kChunkBlocks;
    U<W> words[kChunkBlocks][kG][4];
    for (int b = 0; b < n; ++b) {
      const uint64_t block = block0 + static_cast<uint64_t>(b0 + b);
#pragma GCC unroll 4
      for (int g = 0; g < kG; ++g) {
        U<W> c0 = U<W>{} + (block & 0xffffffffu);
        U<W> c1 = U<W>{} + (block >> 32);
        U<W> c2 = run[g];
        U<W> c3 = U<W>{} + stream_word;
        PhiloxRoundsLanes<W>(key, c0, c1, c2, c3);
        words[b][g][0] = c0;
        words[b][g][1] = c1;
        words[b][g][2] = c2;
        words[b][g][3] = c3;
      }
    }
    for (int b = 0; b < n; ++b) {
#pragma GCC unroll 4
      for (int g = 0; g < kG; ++g) {
        double* row = out + static_cast<size_t>(4 * (b0 + b)) * kRowStride + g * W;
#pragma GCC unroll 2
        for (int pair = 0; pair < 2; ++pair) {
          const D<W> u1 = (lanes::ToDouble<W>(words[b][g][2 * pair]) + 1.0) * kTwoPowMinus32;
          const D<W> radius = lanes::Sqrt<W>(-2.0 * elementary::Log<W>(u1));
          D<W> s, c;
          elementary::SinCosTwoPi<W>(words[b][g][2 * pair + 1], s, c);
          const D<W> z0 = radius * c, z1 = radius * s;
          __builtin_memcpy(row + (2 * pair) * kRowStride, &z0, sizeof(z0));
          __builtin_memcpy(row + (2 * pair + 1) * kRowStride, &z1, sizeof(z1));
        }
      }
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
