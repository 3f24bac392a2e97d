// The consistency verdict (DESIGN.md invariant 9): its bands against published
// chi-square tables, and its error rates — the false-alarm rate of the whole verdict under the
// null hypothesis (a consistent filter, a right prediction) and its power against a filter whose
// covariance is too small — measured over many synthetic results drawn with a fixed seed.
#include "driftlab/app/consistency_check.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>

namespace driftlab::app {
namespace {

TEST(ConsistencyCheck, BandsMatchChiSquareTables) {
  // Chi-square table (e.g. NIST/SEMATECH e-Handbook 1.3.6.7.4), 3 decimals: chi2_0.025(9) = 2.700,
  // chi2_0.975(9) = 19.023; chi2_0.025(10) = 3.247, chi2_0.975(10) = 20.483. Tolerance: half a unit
  // of the table's last digit.
  const NeesBand band = AverageNeesBand(9, 1, 0.05);
  EXPECT_NEAR(band.low, 2.700, 5e-4);
  EXPECT_NEAR(band.high, 19.023, 5e-4);
  // 11 runs: 10 degrees of freedom; s equal to the prediction.
  const RatioInterval r = SigmaRatioInterval(2.0, 2.0, 11, 0.05);
  EXPECT_DOUBLE_EQ(r.ratio, 1.0);
  EXPECT_NEAR(r.low * r.low, 10.0 / 20.483, 2e-5);
  EXPECT_NEAR(r.high * r.high, 10.0 / 3.247, 5e-4);
}

// A result with K NEES epochs of N runs each (average NEES drawn from chi2(9 N) / N times
// `nees_scale`) and a final epoch whose 9 sample sigmas are drawn for true sigma = `sigma_scale`
// times the prediction (1).
v1::JobResult SyntheticResult(std::mt19937_64& rng, int epochs, uint32_t runs, double nees_scale,
                              double sigma_scale) {
  v1::JobResult result;
  result.set_runs(runs);
  result.set_run_count(runs);
  v1::FilterConsistency* fc = result.mutable_filter_consistency();
  fc->set_state_dimension(9);
  // chi2(k) = Gamma(k / 2, scale 2).
  std::gamma_distribution<double> nees_sum(0.5 * 9.0 * runs, 2.0);
  std::gamma_distribution<double> variance_sum(0.5 * (runs - 1.0), 2.0);
  for (int e = 0; e < epochs; ++e) {
    v1::NeesEpoch* n = fc->add_epochs();
    n->set_t_s(e + 1.0);
    n->set_runs(runs);
    n->set_average_nees(nees_scale * nees_sum(rng) / runs);
    v1::EpochStatistics* stats = result.add_epochs();
    stats->set_t_s(e + 1.0);
    v1::PredictedEpoch* predicted = result.mutable_covariance()->add_epochs();
    predicted->set_t_s(e + 1.0);
    for (int c = 0; c < 11; ++c) {
      v1::ComponentStatistics* s = stats->add_components();
      const bool last = e + 1 == epochs;
      s->set_std(last ? sigma_scale * std::sqrt(variance_sum(rng) / (runs - 1.0)) : 1.0);
      predicted->add_sigma(1.0);
    }
  }
  result.mutable_covariance()->add_unrepresented("sensor.gyro.bias_flicker");
  return result;
}

// Binomial bounds for a rate p over n trials: p +- 3.1 sqrt(p (1 - p) / n) (99.8 % two-sided).
double Margin(double p, int n) { return 3.1 * std::sqrt(p * (1.0 - p) / n); }

TEST(ConsistencyCheck, FalseAlarmRateOfTheVerdictIsItsAlpha) {
  // Null hypothesis: NEES and sigmas drawn exactly as a consistent filter and a right prediction
  // give them. 60 NEES epochs (independent here: Bonferroni's least conservative case) and 9
  // sigma components, each family at alpha = 0.05: each family's false-alarm rate is
  // 1 - (1 - 0.05 / K)^K (0.04877 for K = 60, 0.04889 for K = 9); the verdict fails when either
  // family does: 1 - (1 - 0.04877)(1 - 0.04889) = 0.0953. Seed fixed before the first run.
  std::mt19937_64 rng(20261125);
#ifdef DRIFTLAB_SANITIZE
  const int trials = 1000;  // the same check, smaller, under the sanitizers
#else
  const int trials = 4000;
#endif
  int nees_alarms = 0, sigma_alarms = 0, alarms = 0;
  for (int t = 0; t < trials; ++t) {
    const ConsistencyVerdict v = AssessConsistency(SyntheticResult(rng, 60, 50, 1.0, 1.0));
    ASSERT_TRUE(v.has_nees && v.has_prediction);
    ASSERT_EQ(v.nees_epochs, 60);
    ASSERT_EQ(v.components.size(), 9u);
    const bool nees_alarm = v.nees_above + v.nees_below > 0;
    bool sigma_alarm = false;
    for (const ComponentConsistency& c : v.components) sigma_alarm = sigma_alarm || c.flagged;
    nees_alarms += nees_alarm;
    sigma_alarms += sigma_alarm;
    alarms += !v.consistent();
  }
  const double p_nees = 1.0 - std::pow(1.0 - 0.05 / 60, 60);
  const double p_sigma = 1.0 - std::pow(1.0 - 0.05 / 9, 9);
  const double p_any = 1.0 - (1.0 - p_nees) * (1.0 - p_sigma);
  std::printf(
      "false alarms in %d trials: NEES %d (expected %.1f), sigma %d (%.1f), verdict %d (%.1f)\n",
      trials, nees_alarms, p_nees * trials, sigma_alarms, p_sigma * trials, alarms, p_any * trials);
  EXPECT_NEAR(static_cast<double>(nees_alarms) / trials, p_nees, Margin(p_nees, trials));
  EXPECT_NEAR(static_cast<double>(sigma_alarms) / trials, p_sigma, Margin(p_sigma, trials));
  EXPECT_NEAR(static_cast<double>(alarms) / trials, p_any, Margin(p_any, trials));
}

TEST(ConsistencyCheck, PowerAgainstAnOverconfidentFilter) {
  // A filter whose covariance is 1.3 times too small in NEES (average NEES 1.3 x its expectation),
  // 60 epochs of 50 runs: the per-epoch upper bound at 0.05 / 120 is about chi2(450) / 50 ~ 11.1,
  // the scaled average is ~ N(11.7, 0.78): each epoch exceeds it with probability ~0.78, so at
  // least one of 60 does with probability ~1. Required: power >= 0.99 (200 trials, seed fixed).
  // And a Monte-Carlo sigma 1.3 x the prediction with 200 runs: s/sigma_p has a relative standard
  // error 1/sqrt(2 x 199) = 0.05, the Bonferroni interval (z ~ 2.77) excludes 1 when s/sigma_p >
  // ~1.14: with probability ~1 per component. Required: every trial flags >= 5 of 9 components.
  std::mt19937_64 rng(7);
  int detected = 0;
  for (int t = 0; t < 200; ++t) {
    detected += AssessConsistency(SyntheticResult(rng, 60, 50, 1.3, 1.0)).nees_above > 0;
  }
  EXPECT_GE(detected, 198);
  for (int t = 0; t < 50; ++t) {
    const ConsistencyVerdict v = AssessConsistency(SyntheticResult(rng, 5, 200, 1.0, 1.3));
    int flagged = 0;
    for (const ComponentConsistency& c : v.components) flagged += c.flagged;
    EXPECT_GE(flagged, 5);
    EXPECT_FALSE(v.consistent());
  }
}

TEST(ConsistencyCheck, SummaryNamesTheWorstEpochAndTheTermsLeftOut) {
  std::mt19937_64 rng(3);
  const ConsistencyVerdict bad = AssessConsistency(SyntheticResult(rng, 20, 50, 40.0, 3.0));
  EXPECT_FALSE(bad.consistent());
  EXPECT_EQ(bad.nees_above, 20);
  const std::string text = bad.Summary();
  EXPECT_EQ(text.rfind("INCONSISTENT", 0), 0u) << text;
  EXPECT_NE(text.find("20 of 20 epochs"), std::string::npos) << text;
  EXPECT_NE(text.find("sensor.gyro.bias_flicker"), std::string::npos) << text;
  EXPECT_NE(text.find("north position"), std::string::npos) << text;
  // A result with neither a filter nor a prediction is not tested.
  EXPECT_FALSE(AssessConsistency(v1::JobResult()).tested());
}

}  // namespace
}  // namespace driftlab::app
