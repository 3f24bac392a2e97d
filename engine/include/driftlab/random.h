// Reproducible random streams (DESIGN.md invariant 3): every random number of a job is a pure
// function of (job seed, run index, sensor, axis, error term, component, sample index), so any
// run's numbers can be regenerated alone, in any order, on any thread, in any shard.
//
// Generator: Philox4x32-10, the counter-based generator of J. K. Salmon, M. A. Moraes, R. O. Dror
// and D. E. Shaw, "Parallel random numbers: as easy as 1, 2, 3", SC11 (2011), section 5.
// It is a keyed bijection of a 128-bit counter (4 x 32 bits) under a 64-bit key (2 x 32 bits):
// distinct counters under one key never give the same output block, so streams cannot overlap.
//
// Layout of key and counter (fixed; changing it changes every job's numbers):
//   key     = (seed low 32 bits, seed high 32 bits)
//   counter = (block low 32, block high 32, run index, sensor << 24 | axis << 16 | term << 8 |
//              component)
// where block = sample index / 4: one Philox call yields 4 x 32 random bits = 4 deviates.
//
// Gaussian transform: Box-Muller (G. E. P. Box, M. E. Muller, Ann. Math. Stat. 29 (1958) 610):
//   z0 = sqrt(-2 ln u1) cos(2 pi u2),  z1 = sqrt(-2 ln u1) sin(2 pi u2)
// with u1 = (x1 + 1) 2^-32 in (0, 1] and u2 = x2 2^-32 in [0, 1) from two 32-bit words: 32 random
// bits per deviate, no rejection (branch-free, so it vectorises), and ln, sin, cos are the engine's
// own polynomials (random.cc) so every build, scalar or SIMD, produces the same bits. sqrt is
// IEEE-754 correctly rounded and therefore identical everywhere. Consequence of 32-bit uniforms:
// |z| <= sqrt(-2 ln 2^-32) = 6.66, i.e. the tails beyond 6.66 sigma (probability 2.7e-11) are
// absent, and adjacent inputs give radii >= 3.2e-10 (relative) and angles 1.5e-9 rad apart. The
// polynomials are summed only as far as that resolution needs: each deviate is within
// 2.6e-11 |z| + 7.1e-12 r of the exact transform of its two words (r = sqrt(-2 ln u1)), a twelfth
// of the input's own step; tests/engine/random/random_test.cc checks it.
// Vectorisation: deviates are produced in chunks of 32 Philox blocks (SoA). The Box-Muller code
// (engine/src/math/elementary_functions.h) has no branches, comparisons or conversion instructions,
// so GCC vectorises it on every x86-64 level (baseline, AVX2, AVX-512); Philox runs 4 blocks per
// AVX2 vector with VPMULUDQ where GCC leaves it scalar. The lockstep kernels draw the same deviates
// across the runs of a group instead (random_kernels.h GaussianAcrossRuns: one vector lane per
// run, the same block index). All operations are IEEE basic ones or integer: the same bits on
// every path.
#pragma once

#include <array>
#include <cstdint>
#include <span>

namespace driftlab {

// The Philox4x32 round count recommended by Salmon et al. (10 rounds: "Crush-resistant" with a
// safety margin; Table 2 of the paper).
inline constexpr int kPhiloxRounds = 10;

// One Philox4x32-10 block: the 4 x 32-bit output for `counter` under `key`.
// Known-answer vectors: Random123 kat_vectors (tests/engine/random/random_test.cc).
std::array<uint32_t, 4> Philox4x32(const std::array<uint32_t, 4>& counter,
                                   const std::array<uint32_t, 2>& key);

// Which sensor a stream belongs to. The numbers are fixed (kOdometer is reserved), so adding a
// sensor does not change the numbers of the others.
enum class SensorId : uint8_t {
  kGyro = 0,
  kAccel = 1,
  kMagnetometer = 2,
  kBarometer = 3,
  kGnss = 4,
  kOdometer = 5,
  kInitialConditions = 6,  // per-run initial navigation errors
  kZeroVelocity = 7,       // residual motion of a standing vehicle (ZUPT measurement noise)
};

// Which error term a stream drives. `component` (StreamKey) distinguishes several streams of one
// term, e.g. the Gauss-Markov components of the flicker approximation.
enum class ErrorTerm : uint8_t {
  // Per sample. For an inertial triad's increments: the one deviate of the error's part that no
  // state carries on (white noise + GM integral's independent part + random walk's bridge part,
  // TriadJobConstants::independent_sigma, sensors.h); for point samples and aiding sensors: the
  // white noise.
  kWhiteNoise = 0,
  kRandomWalk = 1,           // per sample: the walk's step
  kRandomWalkIntegral = 2,   // not drawn (folded into kWhiteNoise); reserved
  kGaussMarkov = 3,          // per sample: the process' driving noise
  kGaussMarkovIntegral = 4,  // not drawn (folded into kWhiteNoise); reserved
  kFlicker = 5,              // per update of flicker component `component`
  kInitialState = 6,         // stationary initial states (component 0 = GM, 1 + j = flicker j)
  kTurnOnBias = 7,           // per run, index 0
  kScaleFactor = 8,          // per run, index 0
  kMisalignment = 9,         // per run, index 0; axis = row, component = column
  kQuantizationDither = 10,  // reserved
  kInitialError = 11,        // per run: initial navigation errors
};

// Identity of one stream within a run.
struct StreamKey {
  SensorId sensor = SensorId::kGyro;
  uint8_t axis = 0;  // 0, 1, 2 = x, y, z of the sensor triad
  ErrorTerm term = ErrorTerm::kWhiteNoise;
  uint8_t component = 0;
};

// One stream of independent N(0, 1) (or U(0, 1)) deviates indexed by a 64-bit sample index.
// A small value type (24 bytes): copy it freely; it has no state, so the same index always gives
// the same number. Thread-safe (const).
class RandomStream {
 public:
  RandomStream() = default;
  RandomStream(uint64_t seed, uint32_t run_index, StreamKey key);

  // out[i] = deviate number first_index + i of this stream, N(0, 1). No allocation.
  void FillGaussian(uint64_t first_index, std::span<double> out) const;
  // out[i] = uniform deviate number first_index + i in (0, 1): (x + 0.5) 2^-32.
  void FillUniform(uint64_t first_index, std::span<double> out) const;
  // Single deviates (convenience for per-run constants; use the Fill functions in loops).
  double Gaussian(uint64_t index) const;
  double Uniform(uint64_t index) const;

  // The Philox key and the counter's run and stream words (layout above), for kernels that
  // produce a stream's deviates themselves (engine/src/random/random_kernels.h, the same code).
  const std::array<uint32_t, 2>& key() const { return key_; }
  uint32_t run_word() const { return run_word_; }
  uint32_t stream_word() const { return stream_word_; }

 private:
  std::array<uint32_t, 2> key_{};
  uint32_t run_word_ = 0;
  uint32_t stream_word_ = 0;
};

// The engine's own elementary functions for the Gaussian transform (exposed for tests).
// Natural logarithm of x in [2^-1022, 2^1024): exponent/mantissa split, then
// ln m = 2 atanh(s), s = (m - 1)/(m + 1), Taylor series to s^11 (|s| <= 0.172: within 5.2e-11
// relative; engine/src/math/elementary_functions.h says why that is enough for 32-bit uniforms).
double PolyLog(double x);
// sin(2 pi u) and cos(2 pi u) for u = x 2^-32 in [0, 1): reduced exactly (integer arithmetic) to
// a quadrant and theta in [-pi/4, pi/4], Taylor series to theta^11 (sin) and theta^12 (cos)
// (within 7.1e-12), then rotated by the quadrant.
void PolySinCosTwoPi(uint32_t x, double* sin_out, double* cos_out);
// sin x and cos x as the navigation code computes them (earth.cc, attitude.cc and the lockstep
// kernels, engine/src/math/elementary_functions.h): n = round(2x/pi), t = x - n pi/2 by Cody-Waite
// with pi/2 in three 33-bit pieces (exact for |x| < 1.6e6 rad), the same Taylor series on t,
// rotated by n mod 4.
void PolySinCos(double x, double* sin_out, double* cos_out);

}  // namespace driftlab
