// The model the noise fit (noise_fit.cc) fits and its output (noise_fit_output.cc) evaluates:
// the Allan variance of each noise term per unit coefficient at averaging time t (IEEE Std
// 952-1997 Annex C, table C.2), AVAR(t) = sum_k a_k^2 f_k(t), and the term index <-> result field.
#pragma once

#include <array>
#include <numbers>

#include "driftlab/calib/noise_fit.h"
#include "driftlab/sensors.h"

namespace driftlab::calib::noise_fit_model {

// Term indices: quantization Q, white noise N, bias instability B (flicker or Gauss-Markov), random
// walk K, rate ramp R.
inline constexpr int kQ = 0, kN = 1, kB = 2, kK = 3, kR = 4, kTerms = 5;
// IEEE Std 952-1997 table C.2: flicker floor AVAR = (2 ln 2 / pi) B^2.
inline const double kFlickerFloor = 2.0 * std::numbers::ln2 / std::numbers::pi;

// AVAR of a unit-sigma Gauss-Markov process of correlation time tau_gm_s.
inline double GaussMarkovShape(double tau_gm_s, double t) {
  return GaussMarkovAllanVariance(1.0, tau_gm_s, t);
}

// AVAR of unit flicker B: the IEEE flat floor, or the engine's band-limited design.
inline double FlickerShape(BiasModel model, double tau_min_s, double tau_max_s, double t) {
  if (model == BiasModel::kFlickerFlat) return kFlickerFloor;
  const double adev =
      SumOfGaussMarkovAllanDeviation(DesignFlickerApproximation({1.0, tau_min_s, tau_max_s}), t);
  return adev * adev;
}

// f_k(t) of every term (the Gauss-Markov slot is 0: its shape depends on the fitted tau).
inline std::array<double, kTerms> Basis(BiasModel model, double tau_min_s, double tau_max_s,
                                        double t) {
  std::array<double, kTerms> f{};
  f[kQ] = 3.0 / (t * t);
  f[kN] = 1.0 / t;
  f[kB] = (model == BiasModel::kFlickerFlat || model == BiasModel::kFlickerBand)
              ? FlickerShape(model, tau_min_s, tau_max_s, t)
              : 0.0;
  f[kK] = t / 3.0;
  f[kR] = t * t / 2.0;
  return f;
}

// The result field of term k.
inline NoiseTermEstimate* Term(NoiseFitResult& r, int k) {
  switch (k) {
    case kQ:
      return &r.quantization;
    case kN:
      return &r.white_noise;
    case kB:
      return &r.bias_instability;
    case kK:
      return &r.random_walk;
    default:
      return &r.rate_ramp;
  }
}

}  // namespace driftlab::calib::noise_fit_model
