// Exact fixed-point accumulation of doubles (see exact_sum.h for the representation).
#include "driftlab/exact_sum.h"

#include <bit>
#include <cmath>
#include <limits>
#include <string>

#include "driftlab/spec_error.h"

namespace driftlab {

namespace {

constexpr int64_t kFormatTag = 0x45584131;  // "EXA1"
constexpr uint64_t kChunkMask = 0xFFFFFFFFull;
// Carry propagation every 2^30 additions: a bin then holds at most 2^32 (normalised part) plus
// 2^30 chunks below 2^32 in magnitude, i.e. less than 2^63.
constexpr int64_t kMaxPending = int64_t{1} << 30;
constexpr double kOverflowLimit = 0x1p96;
// Squares of |x| >= 2^48 reach 2^96 (overflow); squares of |x| < 2^-57 are below 2^-112 (their
// contribution truncates to zero, exactly as if added), and skipping them also keeps the
// two-product away from underflow, where it would no longer be exact.
constexpr double kSquareOverflowLimit = 0x1p48;
constexpr double kSquareUnderflowLimit = 0x1p-57;

}  // namespace

void ExactSum::Normalize(std::array<int64_t, kBins>* bins) {
  auto& b = *bins;
  for (int j = 0; j + 1 < kBins; ++j) {
    // Arithmetic right shift = floor division by 2^32 (defined for negative values in C++20).
    const int64_t carry = b[j] >> kChunkBits;
    b[j] -= carry * (int64_t{1} << kChunkBits);
    b[j + 1] += carry;
  }
}

void ExactSum::AddFinite(double x) {
  // |x| = mantissa 2^(E - 1075) with the 53-bit integer mantissa 2^52 + fraction, from the bit
  // fields of a normal double (biased exponent E); a subnormal (E = 0) is fraction 2^-1074, far
  // below 2^-112. (Read from the bits rather than by frexp and ldexp: the same integers, without
  // two library calls per value.)
  const uint64_t bits = std::bit_cast<uint64_t>(x) & ~(uint64_t{1} << 63);
  const int biased_exponent = static_cast<int>(bits >> 52);
  if (biased_exponent == 0) return;  // subnormal: entirely below 2^-112, truncated to zero
  uint64_t mantissa = (bits & ((uint64_t{1} << 52) - 1)) | (uint64_t{1} << 52);
  // Position of the mantissa's bit 0 above the accumulator's bit 0 (weight 2^-112). Below it
  // (shift < 0) the bits under 2^-112 are truncated toward zero: mantissa >> -shift, nothing left
  // from -shift >= 64. Written with selects rather than branches: the sign and the small values
  // (the rounding errors of AddSquare) change from one added value to the next.
  const int shift_raw = biased_exponent - 1075 - kLowestExponent;
  const int down = shift_raw < 0 ? -shift_raw : 0;
  mantissa = down < 64 ? mantissa >> down : 0;
  const int shift = shift_raw < 0 ? 0 : shift_raw;
  // shift <= 96 - 53 + 112 = 155, so j0 <= 4 and the three chunks land in bins j0..j0+2 <= 6.
  const int j0 = shift / kChunkBits;
  const int r = shift % kChunkBits;
  const uint64_t lo = (mantissa & kChunkMask) << r;   // < 2^63
  const uint64_t hi = (mantissa >> kChunkBits) << r;  // < 2^52
  const uint64_t t = (lo >> kChunkBits) + hi;         // < 2^53
  // The sign as 0 or -1: (c ^ sign) - sign is c or -c. (A value truncated to zero adds zeros.)
  const int64_t sign = static_cast<int64_t>(std::bit_cast<uint64_t>(x)) >> 63;
  bins_[j0] += (static_cast<int64_t>(lo & kChunkMask) ^ sign) - sign;
  bins_[j0 + 1] += (static_cast<int64_t>(t & kChunkMask) ^ sign) - sign;
  bins_[j0 + 2] += (static_cast<int64_t>(t >> kChunkBits) ^ sign) - sign;
  if (++pending_ >= kMaxPending) {
    Normalize(&bins_);
    pending_ = 0;
  }
}

void ExactSum::Add(double x) {
  if (std::isnan(x)) {
    ++nans_;
  } else if (!(std::abs(x) < kOverflowLimit)) {
    if (x > 0.0) {
      ++positive_infinities_;
    } else {
      ++negative_infinities_;
    }
  } else if (x != 0.0) {
    AddFinite(x);
  }
}

void ExactSum::AddSquare(double x) {
  const double a = std::abs(x);
  if (std::isnan(x)) {
    ++nans_;
    return;
  }
  if (!(a < kSquareOverflowLimit)) {
    ++positive_infinities_;
    return;
  }
  if (a < kSquareUnderflowLimit) return;
  // Dekker's two-product: p + err = a * a exactly.
  //   Veltkamp split a = ah + al with ah, al of at most 26 significant bits (c = 2^27 + 1);
  //   err = ((ah ah - p) + 2 ah al) + al al.
  constexpr double kSplitter = 134217729.0;
  const double p = a * a;
  const double c = kSplitter * a;
  const double ah = c - (c - a);
  const double al = a - ah;
  const double err = ((ah * ah - p) + 2.0 * ah * al) + al * al;
  AddFinite(p);
  if (err != 0.0) AddFinite(err);
}

void ExactSum::Merge(const ExactSum& other) {
  std::array<int64_t, kBins> theirs = other.bins_;
  Normalize(&theirs);
  Normalize(&bins_);
  for (int j = 0; j < kBins; ++j) bins_[j] += theirs[j];
  pending_ = 2;  // each lower bin now holds less than 2 * 2^32
  positive_infinities_ += other.positive_infinities_;
  negative_infinities_ += other.negative_infinities_;
  nans_ += other.nans_;
}

long double ExactSum::Value() const {
  if (nans_ > 0 || (positive_infinities_ > 0 && negative_infinities_ > 0)) {
    return std::numeric_limits<long double>::quiet_NaN();
  }
  if (positive_infinities_ > 0) return std::numeric_limits<long double>::infinity();
  if (negative_infinities_ > 0) return -std::numeric_limits<long double>::infinity();
  std::array<int64_t, kBins> b = bins_;
  Normalize(&b);
  // After normalisation the sign of the total is the sign of the top bin (the lower bins are
  // non-negative and together below one unit of it). Work with the magnitude so that all terms
  // are non-negative: then the top-down sum of the 7 exactly representable terms has a relative
  // error of at most 7 units of 2^-64.
  const bool negative = b[kBins - 1] < 0;
  if (negative) {
    for (auto& v : b) v = -v;
    Normalize(&b);
  }
  long double sum = 0.0L;
  for (int j = kBins - 1; j >= 0; --j) {
    sum += std::ldexp(static_cast<long double>(b[j]), kChunkBits * j + kLowestExponent);
  }
  return negative ? -sum : sum;
}

std::vector<int64_t> ExactSum::Serialize() const {
  std::array<int64_t, kBins> b = bins_;
  Normalize(&b);
  std::vector<int64_t> out;
  out.reserve(kSerializedSize);
  out.push_back(kFormatTag);
  out.push_back(positive_infinities_);
  out.push_back(negative_infinities_);
  out.push_back(nans_);
  out.insert(out.end(), b.begin(), b.end());
  return out;
}

ExactSum ExactSum::Deserialize(std::span<const int64_t> data, const std::string& field) {
  if (data.size() != static_cast<size_t>(kSerializedSize)) {
    throw SpecError(field, std::to_string(data.size()) + " integers",
                    std::to_string(kSerializedSize) + " integers (an ExactSum state)");
  }
  if (data[0] != kFormatTag) {
    throw SpecError(field + "[0]", std::to_string(data[0]),
                    std::to_string(kFormatTag) + " (ExactSum format tag)");
  }
  ExactSum s;
  for (int i = 1; i <= 3; ++i) {
    if (data[i] < 0) {
      throw SpecError(field + "[" + std::to_string(i) + "]", std::to_string(data[i]),
                      "a count >= 0");
    }
  }
  s.positive_infinities_ = data[1];
  s.negative_infinities_ = data[2];
  s.nans_ = data[3];
  for (int j = 0; j < kBins; ++j) {
    const int64_t v = data[4 + j];
    if (j + 1 < kBins && (v < 0 || v > static_cast<int64_t>(kChunkMask))) {
      throw SpecError(field + "[" + std::to_string(4 + j) + "]", std::to_string(v),
                      "[0, 2^32) (a normalised ExactSum bin)");
    }
    s.bins_[j] = v;
  }
  return s;
}

bool ExactSum::operator==(const ExactSum& other) const { return Serialize() == other.Serialize(); }

}  // namespace driftlab
