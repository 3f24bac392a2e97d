// Tests of the exact accumulator (exact_sum.h) and the Monte-Carlo statistics summaries and merge
// (mc_statistics.h).
#include "driftlab/mc_statistics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "driftlab/exact_sum.h"
#include "driftlab/spec_error.h"

namespace driftlab {
namespace {

// Values spread over 2^-100 .. 2^60 with random signs: every ordering of a float sum of these
// gives a different double, so only an exact accumulator is order-independent.
std::vector<double> WideValues(int n, uint32_t seed, bool positive_only) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> mant(1.0, 2.0);
  std::uniform_int_distribution<int> expo(-100, 60);
  std::vector<double> v(n);
  for (double& x : v) {
    x = std::ldexp(mant(rng), expo(rng));
    if (!positive_only && (rng() & 1)) x = -x;
  }
  return v;
}

ExactSum SumOf(const std::vector<double>& v) {
  ExactSum s;
  for (double x : v) s.Add(x);
  return s;
}

TEST(ExactSumTest, SumIsIndependentOfOrderAndGrouping) {
  std::vector<double> v = WideValues(5000, 1, false);
  const std::vector<int64_t> reference = SumOf(v).Serialize();
  std::mt19937_64 rng(2);
  for (int trial = 0; trial < 5; ++trial) {
    std::shuffle(v.begin(), v.end(), rng);
    EXPECT_EQ(SumOf(v).Serialize(), reference);
    // The same values added by three "threads" and merged in two groupings.
    ExactSum a, b, c;
    for (size_t i = 0; i < v.size(); ++i) (i % 3 == 0 ? a : i % 3 == 1 ? b : c).Add(v[i]);
    ExactSum ab = a;
    ab.Merge(b);
    ab.Merge(c);
    ExactSum cb = c;
    cb.Merge(b);
    cb.Merge(a);
    EXPECT_EQ(ab.Serialize(), reference);
    EXPECT_EQ(cb.Serialize(), reference);
  }
}

TEST(ExactSumTest, MatchesNeumaierLongDoubleSumOfPositiveValues) {
  std::vector<double> v = WideValues(5000, 3, true);
  std::sort(v.begin(), v.end());
  // Neumaier (improved Kahan) summation in long double, ascending: error <= 2u |S| + O(n u^2)
  // sum |x| with u = 2^-64 for positive terms (Higham, "Accuracy and Stability of Numerical
  // Algorithms", 2nd ed., section 4.3).
  long double s = 0.0L, comp = 0.0L;
  for (double x : v) {
    const long double t = s + x;
    comp += std::abs(s) >= std::abs(static_cast<long double>(x)) ? (s - t) + x : (x - t) + s;
    s = t;
  }
  const long double reference = s + comp;
  // Both within ~2^-62 relative of the exact sum (ExactSum's Value: <= 6 x 2^-64), so they agree
  // to 1e-18 relative.
  EXPECT_LE(std::abs(SumOf(v).Value() - reference) / reference, 1e-18L);
}

TEST(ExactSumTest, RecoversSmallTermUnderHeavyCancellation) {
  std::vector<double> v = WideValues(2000, 4, false);
  const std::vector<double> copy = v;
  for (double x : copy) v.push_back(-x);
  v.push_back(0.1);
  std::shuffle(v.begin(), v.end(), std::mt19937_64(5));
  // All large terms cancel exactly; 0.1 (lowest bit 2^-56, far above 2^-112) survives exactly.
  EXPECT_EQ(SumOf(v).Value(), static_cast<long double>(0.1));
  double naive = 0.0;
  for (double x : v) naive += x;
  EXPECT_NE(naive, 0.1);  // the cancellation does destroy a plain double sum
}

TEST(ExactSumTest, SquaresAreAddedExactly) {
  // (1 + 2^-30)^2 = 1 + 2^-29 + 2^-60: the last bit is lost by a double product and kept by the
  // two-product; a long double (64-bit mantissa) holds the exact value.
  const double x = 1.0 + 0x1p-30;
  ExactSum s;
  s.AddSquare(x);
  EXPECT_EQ(s.Value(), 1.0L + 0x1p-29L + 0x1p-60L);
  EXPECT_NE(static_cast<long double>(x * x), 1.0L + 0x1p-29L + 0x1p-60L);
  ExactSum neg;
  neg.AddSquare(-x);
  EXPECT_EQ(neg.Serialize(), s.Serialize());
}

TEST(ExactSumTest, TruncatesBelowLowestBinAndCountsOverflow) {
  ExactSum tiny, lowest;
  for (int i = 0; i < 1000; ++i) {
    tiny.Add(0x1p-113);    // below the 2^-112 bin: truncated per value (documented)
    lowest.Add(0x1p-112);  // exactly one unit of bin 0
  }
  EXPECT_EQ(tiny.Value(), 0.0L);
  EXPECT_EQ(lowest.Value(), 1000.0L * 0x1p-112L);

  ExactSum big;
  big.Add(1.0);
  big.Add(1e30);  // >= 2^96: counted as +inf
  EXPECT_EQ(big.Value(), std::numeric_limits<long double>::infinity());
  EXPECT_EQ(big.non_finite_count(), 1);
  big.Add(-std::numeric_limits<double>::infinity());
  EXPECT_TRUE(std::isnan(big.Value()));
  ExactSum square;
  square.AddSquare(1e15);  // 1e30 >= 2^96
  EXPECT_EQ(square.Value(), std::numeric_limits<long double>::infinity());
}

// Values below 2^-60 keep only their bits from 2^-112 up, truncated toward zero whatever the
// sign (exact_sum.h); the expected sums are exact dyadic numbers, computed by hand.
TEST(ExactSumTest, TruncatesBitsBelowLowestBinTowardZeroForBothSigns) {
  const double x = 0x1p-100 + 0x1p-152;  // 2^-100 (1 + 2^-52): its last bit is below 2^-112
  ExactSum s;
  for (int i = 0; i < 3; ++i) s.Add(x);
  EXPECT_EQ(s.Value(), 3.0L * 0x1p-100L);
  s.Add(-x);  // -(2^-100), not -(2^-100 + 2^-112)
  EXPECT_EQ(s.Value(), 2.0L * 0x1p-100L);
  s.Add(-0x1p-176);  // 64 binades below 2^-112 and lower: nothing left
  s.Add(0x1p-1000);
  EXPECT_EQ(s.Value(), 2.0L * 0x1p-100L);
  ExactSum mixed;  // bits at 2^-111 >= 2^-112 are kept exactly, for either sign
  mixed.Add(-(0x1p-70 + 0x1p-111));
  mixed.Add(0x1p-111);
  EXPECT_EQ(mixed.Value(), -0x1p-70L);
  mixed.Add(1.5 * 0x1p-70);
  EXPECT_EQ(mixed.Value(), 0x1p-71L);
  ExactSum neg;  // the same magnitudes with every sign flipped give the negated state
  for (int i = 0; i < 3; ++i) neg.Add(-x);
  neg.Add(x);
  neg.Add(0x1p-176);
  EXPECT_EQ(neg.Value(), -2.0L * 0x1p-100L);
}

TEST(ExactSumTest, SerializationRoundTripsAndRejectsMalformedState) {
  const ExactSum s = SumOf(WideValues(100, 6, false));
  const std::vector<int64_t> data = s.Serialize();
  ASSERT_EQ(data.size(), static_cast<size_t>(ExactSum::kSerializedSize));
  const ExactSum back = ExactSum::Deserialize(data, "x");
  EXPECT_TRUE(back == s);
  EXPECT_EQ(back.Value(), s.Value());

  std::vector<int64_t> bad = data;
  bad[4] = -1;  // bins 0..5 must be normalised
  try {
    ExactSum::Deserialize(bad, "epochs[0].sum");
    FAIL() << "no SpecError";
  } catch (const SpecError& e) {
    EXPECT_EQ(e.field(), "epochs[0].sum[4]");
  }
  EXPECT_THROW(ExactSum::Deserialize(std::vector<int64_t>(3, 0), "x"), SpecError);
}

// Statistics with one epoch and one checkpoint built from given per-run values.
MonteCarloStatistics MakeStatistics(uint32_t first, const std::vector<ErrorComponentValues>& v,
                                    uint32_t job_runs) {
  MonteCarloStatisticsData d;
  d.seed = 9;
  d.job_runs = job_runs;
  d.runs = {RunRange{first, first + static_cast<uint32_t>(v.size())}};
  d.epoch_times_s = {1.0};
  d.epochs.resize(1);
  CheckpointValues cp;
  cp.t_s = 1.0;
  for (size_t i = 0; i < v.size(); ++i) {
    for (int c = 0; c < kNumErrorComponents; ++c) {
      d.epochs[0].sum[c].Add(v[i][c]);
      d.epochs[0].sum_squares[c].AddSquare(v[i][c]);
    }
    cp.run_index.push_back(first + static_cast<uint32_t>(i));
    cp.values.push_back(v[i]);
  }
  d.checkpoints.push_back(cp);
  return MonteCarloStatistics(d);
}

ErrorComponentValues Values(double north, double east) {
  NavError e;
  e.r_ned_m = Vector3d(north, east, 0.0);
  return ErrorComponentsOf(e);
}

TEST(MonteCarloStatisticsTest, SummariesFollowTheirDefinitions) {
  // North errors 1, 2, 3, 4 and east errors 0: mean 2.5, std sqrt(5/3), rms sqrt(7.5).
  const MonteCarloStatistics stats =
      MakeStatistics(0, {Values(1, 0), Values(2, 0), Values(3, 0), Values(4, 0)}, 4);
  const EpochSummary e = stats.SummarizeEpoch(0);
  const ComponentEpochSummary& n = e.components[0];
  EXPECT_EQ(e.runs, 4u);
  EXPECT_DOUBLE_EQ(n.mean, 2.5);
  EXPECT_DOUBLE_EQ(n.std, std::sqrt(5.0 / 3.0));
  EXPECT_DOUBLE_EQ(n.rms, std::sqrt(7.5));
  // Chi-square table values (3 dof: 0.2158, 9.348; 4 dof: 0.4844, 11.14), 4 significant digits,
  // hence 1e-3 relative.
  EXPECT_NEAR(n.std_ci95_low / n.std, std::sqrt(3.0 / 9.348), 1e-3);
  EXPECT_NEAR(n.std_ci95_high / n.std, std::sqrt(3.0 / 0.2158), 1e-3);
  EXPECT_NEAR(n.rms_ci95_low / n.rms, std::sqrt(4.0 / 11.14), 1e-3);
  EXPECT_NEAR(n.rms_ci95_high / n.rms, std::sqrt(4.0 / 0.4844), 1e-3);

  // Percentiles, Hyndman-Fan 7 on |x| = 1, 2, 3, 4: h = 3p -> p50 = 2.5, p68 = 3.04, p95 = 3.85.
  const CheckpointSummary cp = stats.SummarizeCheckpoint(0);
  EXPECT_DOUBLE_EQ(cp.abs[0].p50, 2.5);
  EXPECT_DOUBLE_EQ(cp.abs[0].p68, 3.04);
  EXPECT_DOUBLE_EQ(cp.abs[0].p95, 3.85);
  EXPECT_DOUBLE_EQ(cp.abs[0].max, 4.0);
  EXPECT_DOUBLE_EQ(cp.cep50_m, 2.5);  // horizontal = |north| here
  EXPECT_DOUBLE_EQ(cp.drms2_m, 2.0 * std::sqrt(7.5));
}

TEST(MonteCarloStatisticsTest, MergeOfShardsEqualsWholeAndRejectsOverlap) {
  std::vector<ErrorComponentValues> all;
  for (int i = 0; i < 9; ++i) all.push_back(Values(0.1 * i * i - 1.0, std::sin(i)));
  const MonteCarloStatistics whole = MakeStatistics(0, all, 9);
  MonteCarloStatistics a = MakeStatistics(6, {all[6], all[7], all[8]}, 9);
  a.Merge(MakeStatistics(0, {all[0], all[1], all[2]}, 9));
  a.Merge(MakeStatistics(3, {all[3], all[4], all[5]}, 9));
  EXPECT_EQ(a.run_count(), 9u);
  ASSERT_EQ(a.data().runs.size(), 1u);  // [0, 9) after joining adjacent ranges
  EXPECT_EQ(a.data().checkpoints[0].run_index, whole.data().checkpoints[0].run_index);
  EXPECT_EQ(a.data().checkpoints[0].values, whole.data().checkpoints[0].values);
  for (int c = 0; c < kNumErrorComponents; ++c) {
    EXPECT_EQ(a.data().epochs[0].sum[c].Serialize(), whole.data().epochs[0].sum[c].Serialize());
    EXPECT_EQ(a.data().epochs[0].sum_squares[c].Serialize(),
              whole.data().epochs[0].sum_squares[c].Serialize());
  }
  try {
    a.Merge(MakeStatistics(2, {all[2]}, 9));
    FAIL() << "overlapping runs merged";
  } catch (const SpecError& e) {
    EXPECT_EQ(e.field(), "statistics.runs");
  }
  try {
    a.Merge(MakeStatistics(0, {all[0]}, 10));
    FAIL() << "different jobs merged";
  } catch (const SpecError& e) {
    EXPECT_EQ(e.field(), "statistics.job_runs");
  }
}

TEST(MonteCarloStatisticsTest, InconsistentDataIsRejectedWithFieldPath) {
  MonteCarloStatisticsData d = MakeStatistics(0, {Values(1, 1), Values(2, 2)}, 2).data();
  d.checkpoints[0].run_index[1] = 5;
  try {
    MonteCarloStatistics s(d, "result.statistics");
    FAIL() << "accepted";
  } catch (const SpecError& e) {
    EXPECT_EQ(e.field(), "result.statistics.checkpoints[0].run_index[1]");
  }
  d = MakeStatistics(0, {Values(1, 1)}, 2).data();
  d.runs[0].end = 3;  // beyond job_runs
  EXPECT_THROW(MonteCarloStatistics s(d), SpecError);
}

}  // namespace
}  // namespace driftlab
