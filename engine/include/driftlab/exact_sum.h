// Exact, order-independent and mergeable sum of doubles (DESIGN.md invariants 3 and 5).
//
// Why: Monte-Carlo statistics are sums over runs. Floating-point addition is not associative, so
// a sum accumulated by several threads, or by shards merged in some grouping, would depend on the
// grouping. ExactSum accumulates every value as an exact integer multiple of 2^-112 in
// fixed-point bins (a small "long accumulator", U. Kulisch, "Computer Arithmetic and Validity",
// de Gruyter 2008, ch. 7; the chunked-bin layout is the one of Neal, "Fast exact summation using
// small and large superaccumulators", arXiv:1505.05571, 2015). Integer addition is associative,
// so the state after adding a set of values is the same whatever the order, thread count or
// merge grouping: statistics computed from it are bit-identical.
//
// Representation: 7 signed 64-bit bins; bin j holds a multiple of 2^(32 j - 112), so the bins
// cover bit weights 2^-112 .. 2^95 (plus carry headroom). Each finite value with |x| < 2^96 is
// split exactly (integer operations on its 53-bit mantissa) into at most three 32-bit chunks.
// Range and rounding:
//   * |x| >= 2^96 (~7.9e28) or +-inf: counted as +inf / -inf; NaN counted as NaN. Value() is then
//     +inf, -inf or NaN (NaN if both infinities or any NaN were added). Counting keeps this
//     order-independent too.
//   * bits of x below 2^-112 (~1.9e-34) are truncated toward zero, per value, before adding: the
//     absolute error is < 2^-112 per added value, deterministically. Navigation errors and their
//     squares are far above this.
//   * carries are propagated after at most 2^30 additions, so no bin overflows for any number of
//     values; the total itself must stay below 2^142 (2^46 values of the maximum size).
// Value() converts the exact sum to long double (64-bit mantissa on x86-64) with a relative error
// of at most 6 x 2^-64 (< 2^-61): good enough to form a variance (S2 - S1^2 / N) / (N - 1) unless
// |mean| / sigma exceeds ~1e8.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace driftlab {

class ExactSum {
 public:
  static constexpr int kBins = 7;
  static constexpr int kChunkBits = 32;
  // Weight of the least significant bit of bin 0.
  static constexpr int kLowestExponent = -112;
  // Finite values with |x| >= 2^kOverflowExponent count as infinities.
  static constexpr int kOverflowExponent = 96;
  // Length of Serialize()'s output.
  static constexpr int kSerializedSize = 4 + kBins;

  // Adds x (exactly, up to the truncation below 2^-112).
  void Add(double x);
  // Adds x * x exactly: the product is split into a rounded product and its exact rounding error
  // (Dekker's two-product with Veltkamp splitting, T. J. Dekker, Numer. Math. 18 (1971) 224-242;
  // exact without FMA contraction, which the build disables) and both parts are added.
  void AddSquare(double x);
  // Adds everything `other` holds.
  void Merge(const ExactSum& other);

  // The sum, rounded to long double (see above for non-finite inputs).
  long double Value() const;
  // Number of values added since construction that were non-finite or out of range.
  int64_t non_finite_count() const { return positive_infinities_ + negative_infinities_ + nans_; }

  // Exact state as kSerializedSize integers: {format tag, +inf count, -inf count, NaN count,
  // bins 0..6 with carries propagated (bins 0..5 in [0, 2^32), bin 6 signed)}. Equal sums give
  // equal vectors.
  std::vector<int64_t> Serialize() const;
  // Inverse of Serialize(); throws SpecError naming `field` for a malformed vector.
  static ExactSum Deserialize(std::span<const int64_t> data, const std::string& field);

  // True if both hold the same exact sum (and the same non-finite counts).
  bool operator==(const ExactSum& other) const;

 private:
  // Propagates carries so that bins 0..kBins-2 are in [0, 2^32).
  static void Normalize(std::array<int64_t, kBins>* bins);
  void AddFinite(double x);

  std::array<int64_t, kBins> bins_{};
  int64_t pending_ = 0;  // additions since the last carry propagation
  int64_t positive_infinities_ = 0;
  int64_t negative_infinities_ = 0;
  int64_t nans_ = 0;
};

}  // namespace driftlab
