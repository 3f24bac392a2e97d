// Philox4x32-10 and the Box-Muller transform with the engine's own ln, sin, cos (random.h).
#include "driftlab/random.h"

#include "math/elementary_functions.h"
#include "random/random_kernels.h"

namespace driftlab {

using random_kernels::FillGaussianRange;
using random_kernels::FillUniformRange;
using random_kernels::LogInline;
using random_kernels::Philox10;
using random_kernels::SinCosTwoPiInline;

std::array<uint32_t, 4> Philox4x32(const std::array<uint32_t, 4>& counter,
                                   const std::array<uint32_t, 2>& key) {
  uint32_t c0 = counter[0], c1 = counter[1], c2 = counter[2], c3 = counter[3];
  Philox10(c0, c1, c2, c3, key[0], key[1]);
  return {c0, c1, c2, c3};
}

RandomStream::RandomStream(uint64_t seed, uint32_t run_index, StreamKey key)
    : key_{static_cast<uint32_t>(seed), static_cast<uint32_t>(seed >> 32)},
      run_word_(run_index),
      stream_word_(static_cast<uint32_t>(key.sensor) << 24 | static_cast<uint32_t>(key.axis) << 16 |
                   static_cast<uint32_t>(key.term) << 8 | static_cast<uint32_t>(key.component)) {}

void RandomStream::FillGaussian(uint64_t first_index, std::span<double> out) const {
  FillGaussianRange(key_.data(), run_word_, stream_word_, first_index, out.data(), out.size());
}

void RandomStream::FillUniform(uint64_t first_index, std::span<double> out) const {
  FillUniformRange(key_.data(), run_word_, stream_word_, first_index, out.data(), out.size());
}

double RandomStream::Gaussian(uint64_t index) const {
  double z = 0.0;
  FillGaussian(index, std::span<double>(&z, 1));
  return z;
}

double RandomStream::Uniform(uint64_t index) const {
  double u = 0.0;
  FillUniform(index, std::span<double>(&u, 1));
  return u;
}

double PolyLog(double x) { return LogInline(x); }

void PolySinCosTwoPi(uint32_t x, double* sin_out, double* cos_out) {
  SinCosTwoPiInline(x, *sin_out, *cos_out);
}

void PolySinCos(double x, double* sin_out, double* cos_out) {
  elementary::SinCos<1>(x, *sin_out, *cos_out);
}

}  // namespace driftlab
