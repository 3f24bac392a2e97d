// The CI gate's hypothesis tests (gate_statistics.h) on seeded simulated samples whose true
// ratio is known: the rejection rate at the H0 boundary (true ratio = limit) is at most alpha, the
// (1 - alpha) interval covers the true ratio at its nominal rate, and the planning formula's
// power is what simulation gives. Every rate is over R = 2000 repetitions (seeds fixed before the
// first run): its binomial standard deviation is sqrt(q (1 - q) / R) <= 0.0112, so a bound of
// 4 standard deviations (a false failure once in ~30000 runs of this test) is used throughout.
#include "driftlab/app/gate_statistics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "driftlab/app/gate_distributions.h"

namespace driftlab::app {
namespace {

// The sanitizer build runs a quarter of the repetitions (the slack below follows).
#ifdef DRIFTLAB_SANITIZE
constexpr int kRepetitions = 500;
#else
constexpr int kRepetitions = 2000;
#endif
constexpr double kAlpha = 0.05;

// 4 binomial standard deviations of a rate q over kRepetitions.
double Slack(double q) { return 4.0 * std::sqrt(q * (1.0 - q) / kRepetitions); }

std::vector<double> Normal(std::mt19937_64& rng, int n, double sigma, double mean = 0.0) {
  std::normal_distribution<double> normal(mean, sigma);
  std::vector<double> v(n);
  for (double& x : v) x = normal(rng);
  return v;
}

double SampleSd(const std::vector<double>& v) {
  double m = 0, ss = 0;
  for (const double x : v) m += x;
  m /= v.size();
  for (const double x : v) ss += (x - m) * (x - m);
  return std::sqrt(ss / (v.size() - 1.0));
}

double SampleMean(const std::vector<double>& v) {
  double m = 0;
  for (const double x : v) m += x;
  return m / v.size();
}

double SampleRms(const std::vector<double>& v) {
  double ss = 0;
  for (const double x : v) ss += x * x;
  return std::sqrt(ss / v.size());
}

struct Rates {
  double rejected = 0;  // p <= alpha
  double covered = 0;   // true ratio inside [low, high]
};

template <typename Trial>
Rates Simulate(uint64_t seed, double true_ratio, Trial trial) {
  std::mt19937_64 rng(seed);
  Rates rates;
  for (int r = 0; r < kRepetitions; ++r) {
    const TestOutcome out = trial(rng);
    rates.rejected += out.p_value <= kAlpha ? 1 : 0;
    rates.covered += out.ratio_low <= true_ratio && true_ratio <= out.ratio_high ? 1 : 0;
  }
  rates.rejected /= kRepetitions;
  rates.covered /= kRepetitions;
  return rates;
}

TEST(GateStatistics, IndependentSigmaAndRmsTestsHoldAlphaAtTheLimit) {
  // Current sigma = 1.1 x baseline = the limit: H0 true at its boundary; exact for normal errors,
  // so the rate is alpha and the coverage 1 - alpha.
  const double rho = 1.1;
  const Rates sigma = Simulate(11, rho, [&](std::mt19937_64& rng) {
    const auto b = Normal(rng, 60, 1.0), c = Normal(rng, 90, rho, 0.3);
    return TestSigmaIndependent(SampleSd(b), 60, SampleSd(c), 90, rho, kAlpha);
  });
  EXPECT_NEAR(sigma.rejected, kAlpha, Slack(kAlpha));
  EXPECT_NEAR(sigma.covered, 1 - kAlpha, Slack(kAlpha));
  const Rates rms = Simulate(12, rho, [&](std::mt19937_64& rng) {
    const auto b = Normal(rng, 40, 1.0), c = Normal(rng, 25, rho);
    return TestRmsIndependent(SampleRms(b), 40, SampleRms(c), 25, rho, kAlpha);
  });
  EXPECT_NEAR(rms.rejected, kAlpha, Slack(kAlpha));
  EXPECT_NEAR(rms.covered, 1 - kAlpha, Slack(kAlpha));
  // Far inside H0 (true ratio 1) the test rejects far less often than alpha.
  const Rates inside = Simulate(13, 1.0, [&](std::mt19937_64& rng) {
    const auto b = Normal(rng, 200, 1.0), c = Normal(rng, 200, 1.0);
    return TestSigmaIndependent(SampleSd(b), 200, SampleSd(c), 200, rho, kAlpha);
  });
  EXPECT_LT(inside.rejected, 0.01);
}

TEST(GateStatistics, WelchTestOfTheAbsoluteMeanHoldsAlphaAtTheLimit) {
  // |mean| 2 -> 2.2 (= 1.1 x), unequal sigmas and run counts: Welch's t is close to exact; the
  // interval is an approximation (baseline noise left out of the denominator): coverage only
  // checked to be at least 1 - 2 alpha.
  const double rho = 1.1;
  const Rates welch = Simulate(21, rho, [&](std::mt19937_64& rng) {
    const auto b = Normal(rng, 50, 1.0, -2.0), c = Normal(rng, 80, 2.0, -2.0 * rho);
    return TestAbsMeanWelch(SampleMean(b), SampleSd(b), 50, SampleMean(c), SampleSd(c), 80, rho,
                            kAlpha);
  });
  EXPECT_NEAR(welch.rejected, kAlpha, Slack(kAlpha));
  EXPECT_GT(welch.covered, 1 - 2 * kAlpha);
}

TEST(GateStatistics, QuantileTestIsConservativeForAnyDistribution) {
  // Exponential |errors| (far from normal): the distribution-free test rejects at most alpha at
  // the boundary, and the interval covers at least 1 - alpha (Bonferroni makes both
  // conservative).
  const double rho = 1.1;
  for (const double p : {0.5, 0.95}) {
    const Rates rates = Simulate(31, rho, [&](std::mt19937_64& rng) {
      std::exponential_distribution<double> e(1.0);
      std::vector<double> b(300), c(200);
      for (double& x : b) x = e(rng);
      for (double& x : c) x = rho * e(rng);
      return TestQuantile(b, c, p, rho, kAlpha);
    });
    EXPECT_LE(rates.rejected, kAlpha + Slack(kAlpha)) << p;
    EXPECT_GE(rates.covered, 1 - kAlpha - Slack(kAlpha)) << p;
  }
}

TEST(GateStatistics, PairedTestsHoldAlphaOnCorrelatedRuns) {
  // Pairs that share most of their random numbers (correlation ~0.95), current = the limit.
  const double rho = 1.02;
  const auto pairs = [&](std::mt19937_64& rng, std::vector<double>& x, std::vector<double>& y) {
    const auto common = Normal(rng, 200, 1.0), own_x = Normal(rng, 200, 0.3),
               own_y = Normal(rng, 200, 0.3);
    x.resize(200);
    y.resize(200);
    for (int i = 0; i < 200; ++i) {
      x[i] = common[i] + own_x[i] + 0.5;
      y[i] = rho * (common[i] + own_y[i] + 0.5);
    }
  };
  const Rates pm = Simulate(41, rho, [&](std::mt19937_64& rng) {
    std::vector<double> x, y;
    pairs(rng, x, y);
    return TestSigmaPaired(x, y, rho, kAlpha);
  });
  EXPECT_NEAR(pm.rejected, kAlpha, Slack(kAlpha));  // exact for bivariate normal pairs
  EXPECT_NEAR(pm.covered, 1 - kAlpha, Slack(kAlpha));
  // Paired t on squares and on signed values: large-sample (n = 200) tests, within the slack.
  const Rates rms = Simulate(42, rho, [&](std::mt19937_64& rng) {
    std::vector<double> x, y;
    pairs(rng, x, y);
    return TestRmsPaired(x, y, rho, kAlpha);
  });
  EXPECT_NEAR(rms.rejected, kAlpha, Slack(kAlpha));
  EXPECT_NEAR(rms.covered, 1 - kAlpha, Slack(kAlpha));
  const Rates mean = Simulate(43, rho, [&](std::mt19937_64& rng) {
    std::vector<double> x, y;
    pairs(rng, x, y);
    return TestAbsMeanPaired(x, y, rho, kAlpha);
  });
  EXPECT_NEAR(mean.rejected, kAlpha, Slack(kAlpha));
  EXPECT_NEAR(mean.covered, 1 - kAlpha, Slack(kAlpha));
}

TEST(GateStatistics, PairedBootstrapOfAQuantileRatio) {
  // Identical runs: every resampled ratio is 1, so the interval is [1, 1] and p = 1; runs scaled
  // by 1.5 against a limit of 1.1: every resampled ratio is 1.5, p = 1 / (B + 1), the smallest a
  // bootstrap p can be.
  std::mt19937_64 rng(71);
  std::vector<double> x = Normal(rng, 200, 1.0);
  for (double& v : x) v = std::abs(v);
  const TestOutcome same = TestQuantilePaired(x, x, 0.95, 1.1, kAlpha);
  EXPECT_EQ(same.ratio_low, 1.0);
  EXPECT_EQ(same.ratio_high, 1.0);
  EXPECT_EQ(same.p_value, 1.0);
  std::vector<double> y = x;
  for (double& v : y) v *= 1.5;
  const TestOutcome scaled = TestQuantilePaired(x, y, 0.5, 1.1, kAlpha);
  EXPECT_NEAR(scaled.ratio, 1.5, 1e-12);
  EXPECT_EQ(scaled.p_value, 1.0 / (kBootstrapResamples + 1));
  // Its rejection rate at the H0 boundary: gate_slow_test.cc (a slow test).
}

TEST(GateStatistics, NeesTestHoldsAlphaForChiSquareAverages) {
  // Average NEES of N runs of a consistent 9-state filter: chi2(9 N) / N; the current filter's
  // NEES 1.1 x (the limit).
  const double rho = 1.1;
  const Rates nees = Simulate(51, rho, [&](std::mt19937_64& rng) {
    std::chi_squared_distribution<double> b(9 * 100), c(9 * 150);
    return TestNees(b(rng) / 100, 900, rho * c(rng) / 150, 1350, rho, kAlpha);
  });
  EXPECT_NEAR(nees.rejected, kAlpha, Slack(kAlpha));
  EXPECT_NEAR(nees.covered, 1 - kAlpha, Slack(kAlpha));
}

TEST(GateStatistics, HolmRejectsStepDown) {
  // Sorted 0.005 <= 0.05/4, 0.01 <= 0.05/3, 0.03 > 0.05/2: stop (Holm 1979, the procedure).
  const std::vector<bool> rejected = HolmReject({0.01, 0.04, 0.03, 0.005}, 0.05);
  EXPECT_EQ(rejected, (std::vector<bool>{true, false, false, true}));
  EXPECT_EQ(HolmReject({0.2, 0.001}, 0.05), (std::vector<bool>{false, true}));
  EXPECT_TRUE(HolmReject({}, 0.05).empty());
}

TEST(GateStatistics, PlanningPowerMatchesSimulation) {
  // The run count the planning formula gives for sigma x 1.3 at a 10 % tolerance and alpha / 50
  // (50 gated metrics) detects the change with 90 % power: simulated rate 0.9 within the slack.
  const double alpha_per_test = kAlpha / 50;
  const long n = RunsToDetectSigmaRatio(1.3, 1.1, alpha_per_test, 0.9);
  ASSERT_GT(n, 10);
  EXPECT_LE(DetectableSigmaRatio(n, n, 1.1, alpha_per_test, 0.9), 1.3);
  EXPECT_GT(DetectableSigmaRatio(n - 1, n - 1, 1.1, alpha_per_test, 0.9), 1.3);
  std::mt19937_64 rng(61);
  int detected = 0;
  for (int r = 0; r < kRepetitions; ++r) {
    const auto b = Normal(rng, n, 1.0), c = Normal(rng, n, 1.3);
    detected +=
        TestSigmaIndependent(SampleSd(b), n, SampleSd(c), n, 1.1, kAlpha).p_value <= alpha_per_test
            ? 1
            : 0;
  }
  EXPECT_NEAR(detected / double(kRepetitions), 0.9, Slack(0.9));
  // No run count detects a change inside the tolerance.
  EXPECT_EQ(RunsToDetectSigmaRatio(1.05, 1.1, alpha_per_test, 0.9), 0);
}

}  // namespace
}  // namespace driftlab::app
