// Bonferroni-corrected acceptance checks of Monte-Carlo statistics against a prediction, shared by
// the covariance-analysis and INS/GNSS filter tests (engine and job path).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "driftlab/allan.h"
#include "driftlab/covariance.h"
#include "driftlab/mc_statistics.h"

namespace driftlab::testing {

// Acceptance criterion of the Monte-Carlo vs covariance comparisons (family-wise, not per epoch).
// Epochs of one run are strongly correlated (one turn-on bias draw drives every later epoch), so a
// criterion "inside at >= 90 % of epochs" fails far more often than its nominal level. Instead m =
// 5 epochs per component are chosen by rule (EvenlySpacedPicks below: evenly spaced among the
// epochs after the start, ending at the last one) and EVERY check must pass at the
// Bonferroni-corrected two-sided level alpha = 0.05 / (m x components): the family-wise false-alarm
// probability is then <= 5 % whatever the correlation between epochs (Bonferroni needs no
// independence). A check: for N independent Gaussian runs (N - 1) s^2 / sigma^2 ~ chi2(N - 1)
// (Papoulis & Pillai, 4th ed., 8.3), so the MC / predicted variance ratio s^2 / p^2 must lie in
// [chi2_{alpha/2}(N - 1), chi2_{1 - alpha/2}(N - 1)] / (N - 1) (quantiles by ChiSquareQuantile,
// allan.h).
inline constexpr int kChecksPerComponent = 5;
inline constexpr double kFamilyAlpha = 0.05;

// m indices into a list of n candidates, evenly spaced and ending at the last: ceil(j n / m) - 1
// for j = 1..m (fixed by rule before looking at any result).
inline std::vector<size_t> EvenlySpacedPicks(size_t n, int m) {
  std::vector<size_t> picks;
  for (int j = 1; j <= m; ++j) {
    picks.push_back(static_cast<size_t>(std::ceil(static_cast<double>(j) * n / m)) - 1);
  }
  return picks;
}

// Bonferroni check of the MC sigma of the 9 position, velocity and attitude components against
// the prediction (criterion above); prints the min / max variance ratio per component.
inline void ExpectMonteCarloSigmaMatchesPrediction(const MonteCarloStatistics& stats,
                                                   const std::vector<CovarianceEpoch>& predicted) {
  constexpr int kComponents = 9;
  const std::vector<EpochSummary> epochs = stats.SummarizeEpochs();
  ASSERT_EQ(epochs.size(), predicted.size());
  const double runs = static_cast<double>(stats.run_count());
  const double alpha = kFamilyAlpha / (kChecksPerComponent * kComponents);
  const double low = ChiSquareQuantile(alpha / 2.0, runs - 1.0) / (runs - 1.0);
  const double high = ChiSquareQuantile(1.0 - alpha / 2.0, runs - 1.0) / (runs - 1.0);
  std::printf(
      "%d runs, %d checks per component, per-check level %.3g: variance ratio in "
      "[%.4f, %.4f]\n",
      static_cast<int>(runs), kChecksPerComponent, alpha, low, high);
  for (int c = 0; c < kComponents; ++c) {
    auto sigma = [&](size_t e) {
      return c < 6 ? predicted[e].sigma[c] : predicted[e].euler_sigma_rad[c - 6];
    };
    std::vector<size_t> candidates;  // epochs after the start with a positive prediction
    for (size_t e = 0; e < epochs.size(); ++e) {
      EXPECT_NEAR(epochs[e].t_s, predicted[e].t_s, 1e-9);
      if (epochs[e].t_s > epochs[0].t_s && sigma(e) > 0.0) candidates.push_back(e);
    }
    ASSERT_GE(candidates.size(), static_cast<size_t>(kChecksPerComponent));
    const std::string name(ErrorComponentName(static_cast<ErrorComponent>(c)));
    double min_ratio = 1e300, max_ratio = 0.0;
    for (size_t pick : EvenlySpacedPicks(candidates.size(), kChecksPerComponent)) {
      const size_t e = candidates[pick];
      const double s = epochs[e].components[c].std;
      const double ratio = s * s / (sigma(e) * sigma(e));
      min_ratio = std::min(min_ratio, ratio);
      max_ratio = std::max(max_ratio, ratio);
      EXPECT_GE(ratio, low) << name << " at " << epochs[e].t_s << " s";
      EXPECT_LE(ratio, high) << name << " at " << epochs[e].t_s << " s";
    }
    std::printf("%-22s MC / predicted variance %.4f .. %.4f; final sigma predicted %.4g MC %.4g\n",
                name.c_str(), min_ratio, max_ratio, sigma(epochs.size() - 1),
                epochs.back().components[c].std);
  }
}

}  // namespace driftlab::testing
