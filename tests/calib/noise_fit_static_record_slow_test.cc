// Noise fit of 2-hour static recordings at 100 Hz made through the library path `driftlab export`
// uses (RunSimulation with a SensorRun: the measured point samples that export writes to imu.csv
// as omega_*_rad_per_s and f_*_m_per_s2), from the stim300, adis16470 and tactical presets at 10
// seeds fixed before the first run. The triad fit (three axes, one parameter set: what
// `driftlab allan --fit` writes to the model) uses the model class the presets are simulated with,
// the engine's band-limited flicker over the preset's band (CLI: --bias-model flicker-band
// --flicker-tau-min 1 --flicker-tau-max 1000).
//
// Asserted per preset, triad and seed:
//  * every term the preset has (white noise N, bias instability B) is kept by the selection test
//    (noise_fit.h) and the preset value lies inside the fit's 99.9 % interval (z = 3.29 on the
//    variance coefficient, as the 95 % interval is built) -- except a B whose flicker floor no
//    record can show (FloorCase::floor_visible): kept and inside, or "not determined" with a 95 %
//    upper bound that covers the preset value (at most the binomial 99.9 % quantile of seeds may
//    not);
//  * no term the preset lacks (quantization, random walk, rate ramp) is reported present.
// Asserted over all seeds: the number of preset values outside their 95 % interval is at most
// the binomial(n, 0.05) 99.9 % quantile (n = 2 terms x 2 triads x seeds x presets).
// Run time: the simulation dominates (7.2e5 steps per record); under DRIFTLAB_SANITIZE 3 seeds.
//
// Measured with the catalogue figures (stim300 = TS1524 rev. 31, adis16470 = Rev. C Table 1
// ARW/VRW; default confidence 0.999, generalised least squares; the 30 records,
// --gtest_filter='*StaticRecord*'):
//   preset / triad     N/preset mean  B/preset mean (range)   B not kept  spurious term kept
//   stim300 gyro       1.0002         -- (floor invisible)    9 of 10     0 (max D 8.37)
//                      (bound / preset 1.27-1.77, below the preset in 0 of 9; kept once, 1.44)
//   stim300 accel      1.0000         0.991 (0.844-1.092)     0           0 (max D 8.69)
//   adis16470 gyro     1.0002         0.992 (0.949-1.026)     0           0 (max D 4.68)
//   adis16470 accel    1.0000         0.985 (0.883-1.026)     0           0 (max D 8.22)
//   tactical gyro      1.0002         0.990 (0.936-1.030)     0           0 (max D 4.52)
//   tactical accel     1.0007         0.999 (0.996-1.003)     0           0 (max D 8.02)
//   preset values outside their 95 % interval: 6 of 120 (expected 6, binomial 99.9 % bound 14).
// The adis16470 accelerometer passes since its white noise is the datasheet's VRW 0.037
// m/s/sqrt(h) (a white noise of 230 ug/sqrt(Hz) = 0.135 m/s/sqrt(h) would hide the floor until
// ~700 s).
// DISABLED_LateFloorTriadsBiasInstabilityRecovered keeps the known limit: the revision-9 STIM300
// gyro (B 0.5 deg/h) meets its floor only at ~700 s (floor 0.664 B reached at
// tau ~ (N / 0.664 B)^2), so a 2-hour record shows the floor in its last 2-3 octaves (edf 2-15),
// where the band-limited flicker (1-1000 s) bends down and a random walk K fits that realisation
// as well or better; B is then dropped (with its upper bound) or replaced by K (measured: B/preset
// 0.726, range 0.000-1.242; K kept with D 24.3 in one seed). The whitening uses the white-FM
// correlation, a lower bound where flicker dominates, so D there is still somewhat overstated.
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "driftlab/allan.h"
#include "driftlab/calib/noise_fit.h"
#include "driftlab/presets.h"
#include "driftlab/simulate.h"

namespace driftlab::calib {
namespace {

#ifdef DRIFTLAB_SANITIZE
constexpr int kSeeds = 3;
#else
constexpr int kSeeds = 10;
#endif
// Fixed before the first run.
constexpr std::array<uint64_t, 10> kSeedList = {11, 23, 37, 41, 59, 61, 73, 89, 97, 101};
constexpr double kRateHz = 100.0;
constexpr double kDurationS = 7200.0;

struct StaticRecord {
  std::array<std::vector<double>, 3> gyro;   // omega_ib_b [rad/s]
  std::array<std::vector<double>, 3> accel;  // f_ib_b [m/s^2]
};

StaticRecord SimulateStatic(const ImuErrorModel& model, uint64_t seed) {
  SimulationSpec spec;
  spec.rate_hz = kRateHz;
  spec.motion.initial.llh = {45.0 * M_PI / 180.0, 0.0, 0.0};
  spec.motion.segments.push_back(StaticSegment{kDurationS});
  const SensorRun sensor{model, seed, 0};
  StaticRecord r;
  RunSimulation(spec, &sensor, [&](const SimulationStep& step) {
    for (int a = 0; a < 3; ++a) {
      r.gyro[a].push_back(step.measured_sample->omega_ib_b[a]);
      r.accel[a].push_back(step.measured_sample->f_ib_b[a]);
    }
  });
  return r;
}

// Amplitude interval at z sigmas of the variance coefficient a = c^2 (noise_fit.h).
bool Inside(const NoiseTermEstimate& t, double truth, double z) {
  const double a = t.value * t.value, sigma_a = 2.0 * t.value * t.sigma;
  return truth >= std::sqrt(std::max(0.0, a - z * sigma_a)) && truth <= std::sqrt(a + z * sigma_a);
}

int BinomialQuantile(int n, double p, double q) {
  double term = std::pow(1.0 - p, n), cdf = term;
  int k = 0;
  while (cdf < q && k < n) {
    term *= static_cast<double>(n - k) / (k + 1) * p / (1.0 - p);
    cdf += term;
    ++k;
  }
  return k;
}

struct FloorCase {
  const char* preset;
  bool gyro;
  bool accel;
  // false: the preset's flicker floor 0.664 B lies below the white noise N / sqrt(tau) at every
  // tau of its band (tau_max 1000 s), so no record length shows its signature; B must then be
  // either kept (and inside its interval) or reported "not determined" with a 95 % upper bound
  // that covers the preset value (at most the binomial(seeds, 0.05) 99.9 % quantile may not).
  bool floor_visible = true;
};

void CheckPresets(const std::vector<FloorCase>& cases) {
  const auto start = std::chrono::steady_clock::now();
  int checks = 0, outside_95 = 0;
  for (const FloorCase& c : cases) {
    const char* name = c.preset;
    const ImuErrorModel& preset = FindImuPreset(name);
    struct Summary {
      double n_sum = 0, b_sum = 0, b_min = INFINITY, b_max = 0, d_b_min = INFINITY;
      double d_absent_max = 0;
      double b_bound_min = INFINITY, b_bound_max = 0;  // upper bound / preset, B not determined
      int n_out = 0, b_out = 0, warned = 0, b_undetermined = 0, bound_below_truth = 0;
    };
    std::array<Summary, 2> summary;  // gyro, accel
    for (int s = 0; s < kSeeds; ++s) {
      const StaticRecord record = SimulateStatic(preset, kSeedList[s]);
      for (const bool gyro : {true, false}) {
        if (!(gyro ? c.gyro : c.accel)) continue;
        const TriadErrorParams& truth = gyro ? preset.gyro : preset.accel;
        Summary& sum = summary[gyro ? 0 : 1];
        NoiseFitOptions options;
        options.bias_model = BiasModel::kFlickerBand;
        options.flicker_tau_min_s = truth.bias_flicker.tau_min_s;
        options.flicker_tau_max_s = truth.bias_flicker.tau_max_s;
        const auto& axes = gyro ? record.gyro : record.accel;
        std::vector<std::vector<AllanPoint>> curves;
        for (int a = 0; a < 3; ++a) curves.push_back(OverlappingAllanDeviation(axes[a], kRateHz));
        const NoiseFitResult fit = FitAllanNoiseModel(curves, options);
        const std::string where = std::string(name) + (gyro ? " gyro" : " accel") + " seed " +
                                  std::to_string(kSeedList[s]);
        EXPECT_TRUE(fit.white_noise.determined) << where;
        const double b_true = truth.bias_flicker.bias_instability;
        if (c.floor_visible) {
          EXPECT_TRUE(fit.bias_instability.determined)
              << where << ": D " << fit.bias_instability.lr_statistic << " < "
              << fit.bias_instability.lr_threshold;
        }
        // 99.9 %: 3.29 sigma (two-sided normal quantile).
        EXPECT_TRUE(Inside(fit.white_noise, truth.white_noise_density, 3.29))
            << where << ": N " << fit.white_noise.value << " +- " << fit.white_noise.sigma
            << ", preset " << truth.white_noise_density;
        if (fit.bias_instability.determined) {
          EXPECT_TRUE(Inside(fit.bias_instability, b_true, 3.29))
              << where << ": B " << fit.bias_instability.value << " +- "
              << fit.bias_instability.sigma << ", preset " << b_true;
        } else if (!c.floor_visible) {
          EXPECT_TRUE(std::isfinite(fit.bias_instability.upper_bound)) << where;
          sum.bound_below_truth += fit.bias_instability.upper_bound < b_true ? 1 : 0;
          sum.b_bound_max = std::max(sum.b_bound_max, fit.bias_instability.upper_bound / b_true);
          sum.b_bound_min = std::min(sum.b_bound_min, fit.bias_instability.upper_bound / b_true);
          ++sum.b_undetermined;
        }
        for (const NoiseTermEstimate* absent :
             {&fit.quantization, &fit.random_walk, &fit.rate_ramp}) {
          EXPECT_FALSE(absent->determined)
              << where << ": a term the preset lacks, D " << absent->lr_statistic;
          if (std::isfinite(absent->lr_statistic)) {
            sum.d_absent_max = std::max(sum.d_absent_max, absent->lr_statistic);
          }
        }
        const bool n_in = Inside(fit.white_noise, truth.white_noise_density, 1.96);
        // Not determined: "inside" when the 95 % upper bound covers the preset value.
        const bool b_in = fit.bias_instability.determined
                              ? Inside(fit.bias_instability, b_true, 1.96)
                              : fit.bias_instability.upper_bound >= b_true;
        sum.n_out += n_in ? 0 : 1;
        sum.b_out += b_in ? 0 : 1;
        checks += 2;
        outside_95 += (n_in ? 0 : 1) + (b_in ? 0 : 1);
        sum.warned += fit.warnings.empty() ? 0 : 1;
        const double b_ratio = fit.bias_instability.value / truth.bias_flicker.bias_instability;
        sum.n_sum += fit.white_noise.value / truth.white_noise_density;
        sum.b_sum += b_ratio;
        sum.b_min = std::min(sum.b_min, b_ratio);
        sum.b_max = std::max(sum.b_max, b_ratio);
        sum.d_b_min = std::min(sum.d_b_min, fit.bias_instability.lr_statistic);
      }
    }
    for (const bool gyro : {true, false}) {
      if (!(gyro ? c.gyro : c.accel)) continue;
      const Summary& sum = summary[gyro ? 0 : 1];
      std::printf(
          "%-9s %s: %d seeds: N/preset mean %.4f (%d outside 95 %% CI), B/preset mean %.3f "
          "range %.3f-%.3f (%d outside 95 %% CI), min D(B) %.1f, max D(absent) %.2f, fits with a "
          "warning %d\n",
          name, gyro ? "gyro " : "accel", kSeeds, sum.n_sum / kSeeds, sum.n_out, sum.b_sum / kSeeds,
          sum.b_min, sum.b_max, sum.b_out, sum.d_b_min, sum.d_absent_max, sum.warned);
      if (sum.b_undetermined > 0) {
        std::printf(
            "%-9s %s: B not determined in %d seeds, 95 %% upper bound / preset %.2f-%.2f, below "
            "the preset in %d\n",
            name, gyro ? "gyro " : "accel", sum.b_undetermined, sum.b_bound_min, sum.b_bound_max,
            sum.bound_below_truth);
      }
      EXPECT_LE(sum.bound_below_truth, BinomialQuantile(kSeeds, 0.05, 0.999)) << name;
    }
  }
  const int allowed = BinomialQuantile(checks, 0.05, 0.999);
  std::printf(
      "preset values outside their 95 %% interval: %d of %d (expected %.1f, allowed %d); "
      "%.1f s\n",
      outside_95, checks, 0.05 * checks, allowed,
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  EXPECT_LE(outside_95, allowed);
}

// Every triad of the three presets. The STIM300 gyro (TS1524 rev. 31: N 0.15 deg/sqrt(h),
// B 0.3 deg/h) has its floor 0.664 B = 0.20 deg/h below its white noise at every tau of the
// simulated band (N / sqrt(1000 s) = 0.28 deg/h at tau_max), so its B is checked as an upper bound.
TEST(NoiseFitStaticRecordSlowTest, PresetTermsRecoveredAndNoAbsentTermReported) {
  CheckPresets(
      {{"stim300", true, true, false}, {"adis16470", true, true}, {"tactical", true, true}});
}

// The revision-9 STIM300 gyro (N 0.15 deg/sqrt(h), B 0.5 deg/h) meets its floor only at ~700 s:
// a 2-hour record shows it in its last 2-3 octaves (see the header comment), and B is dropped
// or replaced by a random walk in 3 of 10 seeds; kept disabled as the known limit.
TEST(NoiseFitStaticRecordSlowTest, DISABLED_LateFloorTriadsBiasInstabilityRecovered) {
  CheckPresets({{"stim300-rev9", true, false}});
}

}  // namespace
}  // namespace driftlab::calib
