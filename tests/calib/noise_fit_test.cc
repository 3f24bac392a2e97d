// Noise-model fit of Allan curves (calib/noise_fit.h), fast cases: analytic curves (exact data)
// and a short simulated record. The long per-preset records are in noise_fit_slow_test.cc.
#include "driftlab/calib/noise_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "driftlab/allan.h"
#include "driftlab/presets.h"
#include "driftlab/sensors.h"
#include "driftlab/spec_error.h"

namespace driftlab::calib {
namespace {

// An exact curve on an octave grid from tau0 to tau_max with a common edf. With exact data the
// fit's optimum is the truth up to the bias correction b(edf) ~ -1/edf applied to every point
// (noise_fit.h), a common AVAR factor 1 + 1/edf, i.e. 1/(2 edf) in every amplitude.
template <typename Avar>
std::vector<AllanPoint> ExactCurve(Avar avar, double tau0, double tau_max, double edf) {
  std::vector<AllanPoint> curve;
  for (double tau = tau0; tau <= tau_max; tau *= 2.0) {
    AllanPoint p;
    p.tau_s = tau;
    p.adev = std::sqrt(avar(tau));
    p.edf = edf;
    p.adev_low = p.adev * (1.0 - 2.0 / std::sqrt(2.0 * edf));
    p.adev_high = p.adev * (1.0 + 2.0 / std::sqrt(2.0 * edf));
    curve.push_back(p);
  }
  return curve;
}

constexpr double kDegPerH = std::numbers::pi / 180.0 / 3600.0;    // rad/s
constexpr double kDegPerSqrtH = std::numbers::pi / 180.0 / 60.0;  // rad/sqrt(s)

TEST(NoiseFitTest, AllFiveIeeeTermsRecoveredFromExactCurve) {
  // Terms chosen so that each dominates somewhere on 1e-3 .. 1e6 s: Q below 0.01 s, N to 20 s,
  // B to 500 s, K to 6e4 s, R beyond (ADEV crossovers of the table C.2 terms).
  const double Q = 2e-6, N = 0.15 * kDegPerSqrtH, B = 3.0 * kDegPerH, K = 0.5 * kDegPerH / 60.0,
               R = 0.1 * kDegPerH / 3600.0;
  const auto curve = ExactCurve(
      [&](double t) {
        return AllanCurveModel(t, N, B, K, Q, R) * AllanCurveModel(t, N, B, K, Q, R);
      },
      1e-3, 1e6, 1e6);
  NoiseFitOptions options;
  options.bias_model = BiasModel::kFlickerFlat;
  const NoiseFitResult fit = FitAllanNoiseModel(curve, options);
  // edf 1e6: bias 1/(2 edf) = 5e-7 per amplitude; 1e-5 leaves room for solver tolerance.
  const double tol = 1e-5;
  ASSERT_TRUE(fit.quantization.determined);
  ASSERT_TRUE(fit.white_noise.determined);
  ASSERT_TRUE(fit.bias_instability.determined);
  ASSERT_TRUE(fit.random_walk.determined);
  ASSERT_TRUE(fit.rate_ramp.determined);
  EXPECT_NEAR(fit.quantization.value / Q, 1.0, tol);
  EXPECT_NEAR(fit.white_noise.value / N, 1.0, tol);
  EXPECT_NEAR(fit.bias_instability.value / B, 1.0, tol);
  EXPECT_NEAR(fit.random_walk.value / K, 1.0, tol);
  EXPECT_NEAR(fit.rate_ramp.value / R, 1.0, tol);
  // Exact data: normalised residuals ~ 0 (only the tiny common bias).
  EXPECT_LT(fit.residual_rms, 1e-3);
  EXPECT_NEAR(FittedAllanDeviation(fit, 100.0) / AllanCurveModel(100.0, N, B, K, Q, R), 1.0, tol);
}

TEST(NoiseFitTest, TermsAbsentFromTheCurveAreReportedNotDetermined) {
  // White noise and flicker only, edf of a 1 h, 100 Hz record per point (white FM, TN 1337).
  const double N = 0.15 * kDegPerSqrtH, B = 3.0 * kDegPerH;
  const int64_t n_phase = 360001;
  std::vector<AllanPoint> curve;
  for (int64_t m = 1; 2 * m <= n_phase - 2; m *= 2) {
    AllanPoint p;
    p.tau_s = m / 100.0;
    p.adev = AllanCurveModel(p.tau_s, N, B, 0, 0, 0);
    p.edf = OverlappingAdevEdf(AllanNoiseType::kFlickerFm, n_phase, m);
    curve.push_back(p);
  }
  const NoiseFitResult fit = FitAllanNoiseModel(curve);
  EXPECT_TRUE(fit.white_noise.determined);
  EXPECT_TRUE(fit.bias_instability.determined);
  for (const NoiseTermEstimate* t : {&fit.quantization, &fit.random_walk, &fit.rate_ramp}) {
    EXPECT_TRUE(t->fitted);
    EXPECT_FALSE(t->determined);
    EXPECT_EQ(t->value, 0.0);
    EXPECT_GT(t->upper_bound, 0.0);  // a finite bound, not a value
  }
  // The smallest edf here (last points, ~1-3) gives b(edf) up to ~-1: the fitted amplitudes carry
  // a bias of order sum-weighted 1/edf, below 1 % for N (edf ~ 1e5 at short tau) and a few % for B
  // (edf 10-100 on the floor).
  EXPECT_NEAR(fit.white_noise.value / N, 1.0, 0.01);
  EXPECT_NEAR(fit.bias_instability.value / B, 1.0, 0.05);
  const TriadErrorParams triad = ToTriadErrorParams(fit);
  EXPECT_EQ(triad.white_noise_density, fit.white_noise.value);
  EXPECT_EQ(triad.bias_flicker.bias_instability, fit.bias_instability.value);
  EXPECT_EQ(triad.random_walk, 0.0);
  EXPECT_EQ(triad.quantization, 0.0);
  EXPECT_DOUBLE_EQ(triad.bias_flicker.tau_min_s, 0.01);  // the curve's tau range
}

TEST(NoiseFitTest, GaussMarkovSigmaAndTauRecovered) {
  const double N = 1e-4, sigma = 2e-4, tau = 300.0;
  const auto curve =
      ExactCurve([&](double t) { return N * N / t + GaussMarkovAllanVariance(sigma, tau, t); },
                 0.01, 1e5, 1e6);
  NoiseFitOptions options;
  options.bias_model = BiasModel::kGaussMarkov;
  const NoiseFitResult fit = FitAllanNoiseModel(curve, options);
  ASSERT_TRUE(fit.bias_instability.determined);
  ASSERT_TRUE(fit.gauss_markov_tau_s.determined);
  // edf 1e6 bias 5e-7; the GM tau derivative is a central difference (~1e-9): 1e-5.
  EXPECT_NEAR(fit.bias_instability.value / sigma, 1.0, 1e-5);
  EXPECT_NEAR(fit.gauss_markov_tau_s.value / tau, 1.0, 1e-5);
  EXPECT_NEAR(fit.white_noise.value / N, 1.0, 1e-5);
  EXPECT_GT(fit.gauss_markov_tau_s.sigma, 0.0);
  const TriadErrorParams triad = ToTriadErrorParams(fit);
  EXPECT_EQ(triad.bias_gauss_markov.tau_s, fit.gauss_markov_tau_s.value);
  EXPECT_EQ(triad.bias_flicker.bias_instability, 0.0);
}

TEST(NoiseFitTest, BandLimitedFlickerOfTheEngineRecovered) {
  // The engine's flicker approximation rolls off outside its band (like random walk below, like
  // white noise above); the kFlickerBand model is that same curve, so B comes back exactly.
  const double N = 1e-3, B = 3e-4;
  const FlickerParams band{B, 1.0, 1000.0};
  const auto components = DesignFlickerApproximation(band);
  const auto curve = ExactCurve(
      [&](double t) {
        const double f = SumOfGaussMarkovAllanDeviation(components, t);
        return N * N / t + f * f;
      },
      0.01, 1e5, 1e6);
  NoiseFitOptions options;
  options.bias_model = BiasModel::kFlickerBand;
  options.flicker_tau_min_s = 1.0;
  options.flicker_tau_max_s = 1000.0;
  const NoiseFitResult fit = FitAllanNoiseModel(curve, options);
  ASSERT_TRUE(fit.bias_instability.determined);
  EXPECT_NEAR(fit.bias_instability.value / B, 1.0, 1e-5);  // edf 1e6, as above
  EXPECT_NEAR(fit.white_noise.value / N, 1.0, 1e-5);
  EXPECT_FALSE(fit.random_walk.determined);
}

// Simulated tactical gyro, 20 min at 100 Hz (short enough for the sanitizer build): the white
// noise dominates up to ~20 s (N / sqrt(t) = 0.664 B at t = 20 s) with edf ~ 1e4-1e5 there, so N
// is determined to < 1 %; 5 % is the required accuracy.
TEST(NoiseFitTest, ArwOfSimulatedTacticalGyroWithinFivePercent) {
  const ImuErrorModel& preset = FindImuPreset("tactical");
  const double rate_hz = 100.0;
  const int n = 20 * 60 * 100;
  ImuErrorSimulator sim(preset, 7, 0, rate_hz);
  std::vector<double> x(n), y(n);
  ImuSample ideal, measured;
  for (int i = 0; i < n; ++i) {
    sim.Apply(ideal, &measured);
    x[i] = measured.omega_ib_b.x();
    y[i] = measured.omega_ib_b.y();
  }
  const std::vector<std::vector<AllanPoint>> curves = {OverlappingAllanDeviation(x, rate_hz),
                                                       OverlappingAllanDeviation(y, rate_hz)};
  NoiseFitOptions options;
  options.bias_model = BiasModel::kFlickerBand;
  options.flicker_tau_min_s = preset.gyro.bias_flicker.tau_min_s;
  options.flicker_tau_max_s = preset.gyro.bias_flicker.tau_max_s;
  const NoiseFitResult fit = FitAllanNoiseModel(curves, options);
  const double N = preset.gyro.white_noise_density;
  ASSERT_TRUE(fit.white_noise.determined);
  EXPECT_NEAR(fit.white_noise.value / N, 1.0, 0.05);
  // The reported sigma is honest: the error is within 4 sigma.
  EXPECT_LT(std::fabs(fit.white_noise.value - N), 4.0 * fit.white_noise.sigma);
  EXPECT_FALSE(fit.random_walk.determined);  // the preset has none
}

TEST(NoiseFitTest, UnusableCurvesAreRejectedWithAMessage) {
  EXPECT_THROW(FitAllanNoiseModel(std::vector<AllanPoint>{}), SpecError);
  std::vector<AllanPoint> flat(3);
  for (int i = 0; i < 3; ++i) flat[i] = {.tau_s = 1.0 + i, .adev = 1e-3, .edf = 10.0};
  try {
    FitAllanNoiseModel(flat);  // 3 points, 5 parameters
    FAIL() << "expected SpecError";
  } catch (const SpecError& e) {
    EXPECT_NE(std::string(e.what()).find("more points than fitted parameters"), std::string::npos)
        << e.what();
  }
  NoiseFitOptions options;
  options.bias_model = BiasModel::kFlickerBand;
  options.flicker_tau_min_s = 10.0;
  options.flicker_tau_max_s = 1.0;
  EXPECT_THROW(FitAllanNoiseModel(flat, options), SpecError);
}

TEST(NoiseFitTest, SelectionThresholdIsTheBoundaryMixtureQuantile) {
  // Default confidence 0.999: chi2_1 quantile at 1 - 2 (0.001) = z_0.999^2 = 3.090232^2 = 9.5495
  // (normal table); the tolerance covers the 4 printed digits of z.
  const double N = 0.15 * kDegPerSqrtH, B = 3.0 * kDegPerH;
  const auto curve = ExactCurve(
      [&](double t) {
        return AllanCurveModel(t, N, B, 0, 0, 0) * AllanCurveModel(t, N, B, 0, 0, 0);
      },
      0.01, 1e4, 1e3);
  const NoiseFitResult fit = FitAllanNoiseModel(curve);
  for (const NoiseTermEstimate* t : {&fit.quantization, &fit.white_noise, &fit.bias_instability,
                                     &fit.random_walk, &fit.rate_ramp}) {
    ASSERT_TRUE(std::isfinite(t->lr_threshold));
    EXPECT_NEAR(t->lr_threshold, 9.5495, 1e-3);
    // A kept term's test passed, a dropped term's failed.
    EXPECT_EQ(t->determined, t->lr_statistic >= t->lr_threshold);
  }
  EXPECT_TRUE(fit.white_noise.determined);
  EXPECT_TRUE(fit.bias_instability.determined);
  // Kept terms carry a 95 % interval around the value.
  EXPECT_LE(fit.bias_instability.lower_95, fit.bias_instability.value);
  EXPECT_GE(fit.bias_instability.upper_95, fit.bias_instability.value);
}

TEST(NoiseFitTest, CurveLeavingItsIntervalsIsFlagged) {
  // White noise plus a rate random walk that dominates from ~100 s, fitted with white noise only:
  // at the long taus the model lies far below the data (edf 1e3: bars +-9 %), so more points
  // fall outside than the binomial 99 % bound and chi2 exceeds its 99.9 % quantile.
  const double N = 0.15 * kDegPerSqrtH, K = 20.0 * kDegPerH / 60.0;
  const auto curve = ExactCurve(
      [&](double t) {
        return AllanCurveModel(t, N, 0, K, 0, 0) * AllanCurveModel(t, N, 0, K, 0, 0);
      },
      0.01, 1e4, 1e3);
  NoiseFitOptions options;
  options.bias_model = BiasModel::kNone;
  options.fit_quantization = false;
  options.fit_random_walk = false;
  options.fit_rate_ramp = false;
  const NoiseFitResult fit = FitAllanNoiseModel(curve, options);
  EXPECT_GT(fit.points_outside_95, fit.max_plausible_outside_95);
  EXPECT_GT(fit.chi2, fit.chi2_high);
  EXPECT_EQ(fit.warnings.size(), 2u);
  // With the random walk allowed the same curve fits: no point outside (exact data).
  options.fit_random_walk = true;
  const NoiseFitResult good = FitAllanNoiseModel(curve, options);
  EXPECT_TRUE(good.random_walk.determined);
  EXPECT_EQ(good.points_outside_95, 0);
}

}  // namespace
}  // namespace driftlab::calib
