// Output of the noise fit (noise_fit.h): the bias model's name, the fitted Allan deviation, the
// fitted terms as sensor-model parameters and as a text table in datasheet units.
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "driftlab/calib/noise_fit.h"
#include "driftlab/units.h"
#include "noise_fit_model.h"

namespace driftlab::calib {

using noise_fit_model::Basis;
using noise_fit_model::GaussMarkovShape;
using noise_fit_model::kB;
using noise_fit_model::kTerms;
using noise_fit_model::Term;

const char* BiasModelName(BiasModel model) {
  switch (model) {
    case BiasModel::kFlickerFlat:
      return "flicker (IEEE flat floor)";
    case BiasModel::kFlickerBand:
      return "flicker (engine band)";
    case BiasModel::kGaussMarkov:
      return "Gauss-Markov";
    case BiasModel::kNone:
      break;
  }
  return "none";
}

double FittedAllanDeviation(const NoiseFitResult& fit, double tau_s) {
  std::array<double, kTerms> f =
      Basis(fit.bias_model, fit.flicker_tau_min_s, fit.flicker_tau_max_s, tau_s);
  if (fit.bias_model == BiasModel::kGaussMarkov && fit.gauss_markov_tau_s.determined) {
    f[kB] = GaussMarkovShape(fit.gauss_markov_tau_s.value, tau_s);
  }
  NoiseFitResult copy = fit;
  double avar = 0.0;
  for (int k = 0; k < kTerms; ++k) {
    const double c = Term(copy, k)->value;
    avar += c * c * f[k];
  }
  return std::sqrt(avar);
}

TriadErrorParams ToTriadErrorParams(const NoiseFitResult& fit) {
  TriadErrorParams p;
  p.white_noise_density = fit.white_noise.value;
  p.random_walk = fit.random_walk.value;
  // IEEE Std 952-1997 C.1: quantization noise coefficient Q = S / sqrt(12), S the LSB.
  p.quantization = std::sqrt(12.0) * fit.quantization.value;
  if (fit.bias_instability.value > 0.0) {
    if (fit.bias_model == BiasModel::kGaussMarkov) {
      p.bias_gauss_markov = {fit.bias_instability.value, fit.gauss_markov_tau_s.value};
    } else {
      p.bias_flicker = {fit.bias_instability.value, fit.flicker_tau_min_s, fit.flicker_tau_max_s};
    }
  }
  return p;
}

std::string FormatNoiseFit(const NoiseFitResult& fit, bool gyro, const TriadErrorParams* reference,
                           const std::string& reference_name) {
  struct Row {
    const char* label;
    const NoiseTermEstimate* term;
    const char* unit;
    double reference;  // SI, NaN = none
  };
  const bool gm = fit.bias_model == BiasModel::kGaussMarkov;
  const double nan = NAN;
  auto ref = [&](double v) { return reference != nullptr ? v : nan; };
  const std::vector<Row> rows = {
      {gyro ? "white noise N (ARW)" : "white noise N (VRW)", &fit.white_noise,
       gyro ? "deg/sqrt(h)" : "m/s/sqrt(h)", ref(reference ? reference->white_noise_density : 0)},
      {gm ? "Gauss-Markov sigma" : "bias instability B", &fit.bias_instability,
       gyro ? "deg/h" : "ug",
       ref(reference ? (gm ? reference->bias_gauss_markov.sigma
                           : reference->bias_flicker.bias_instability)
                     : 0)},
      {"Gauss-Markov tau", gm ? &fit.gauss_markov_tau_s : nullptr, "s",
       ref(reference ? reference->bias_gauss_markov.tau_s : 0)},
      {gyro ? "rate random walk K" : "accel random walk K", &fit.random_walk,
       gyro ? "deg/h/sqrt(h)" : "ug/sqrt(s)", ref(reference ? reference->random_walk : 0)},
      {"quantization Q", &fit.quantization, gyro ? "urad" : "mm/s",
       ref(reference ? reference->quantization / std::sqrt(12.0) : 0)},
      {"rate ramp R", &fit.rate_ramp, gyro ? "deg/h/h" : "ug/h", nan},
  };
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "  %-22s %-58s %s\n", "term",
                "fitted (+- 1 sigma) [95 % interval]; LR test D",
                reference != nullptr ? reference_name.c_str() : "");
  out += line;
  for (const Row& row : rows) {
    if (row.term == nullptr || !row.term->fitted) continue;
    std::string fitted;
    if (row.term->determined) {
      fitted = FormatQuantity(row.term->value, row.unit, 4) + " +- " +
               FormatQuantity(row.term->sigma, row.unit, 2);
      if (std::isfinite(row.term->lower_95)) {
        char interval[160];
        std::snprintf(interval, sizeof interval, " [%s, %s]",
                      FormatQuantity(row.term->lower_95, row.unit, 3).c_str(),
                      FormatQuantity(row.term->upper_95, row.unit, 3).c_str());
        fitted += interval;
      }
    } else if (std::isfinite(row.term->upper_bound)) {
      fitted =
          "not determined (< " + FormatQuantity(row.term->upper_bound, row.unit, 3) + ", 95 %)";
    } else {
      fitted = "not determined";
    }
    if (std::isfinite(row.term->lr_statistic)) {
      char d[64];
      std::snprintf(d, sizeof d, "; D %.3g %s %.3g", row.term->lr_statistic,
                    row.term->determined ? ">=" : "<", row.term->lr_threshold);
      fitted += d;
    }
    std::string ref_text;
    if (std::isfinite(row.reference)) {
      ref_text = row.reference > 0.0 ? FormatQuantity(row.reference, row.unit, 4) : "-";
      if (row.reference > 0.0 && row.term->determined) {
        char diff[64];
        std::snprintf(diff, sizeof diff, "  (fit %+.1f %%)",
                      100.0 * (row.term->value / row.reference - 1.0));
        ref_text += diff;
      }
    }
    std::snprintf(line, sizeof line, "  %-22s %-58s %s\n", row.label, fitted.c_str(),
                  ref_text.c_str());
    out += line;
  }
  if (fit.quantization.fitted) {
    out +=
        gyro
            ? "  quantization Q is the IEEE Std 952 angle quantization coefficient (ADEV = sqrt(3) "
              "Q / tau); the angle LSB of a quantizer is sqrt(12) Q (urad)\n"
            : "  quantization Q is the IEEE Std 952 velocity quantization coefficient (ADEV = "
              "sqrt(3) Q / tau); the velocity LSB of a quantizer is sqrt(12) Q (mm/s)\n";
  }
  const NoiseTermEstimate* any = &fit.white_noise;
  for (const NoiseTermEstimate* t : {&fit.quantization, &fit.white_noise, &fit.bias_instability,
                                     &fit.random_walk, &fit.rate_ramp}) {
    if (std::isfinite(t->lr_threshold)) any = t;
  }
  if (std::isfinite(any->lr_threshold)) {
    std::snprintf(
        line, sizeof line,
        "  selection: a term is kept when the likelihood-ratio statistic D of dropping it "
        "is >= %.3g (chi2_1 mixture at the chosen confidence)\n",
        any->lr_threshold);
    out += line;
  }
  std::snprintf(line, sizeof line,
                "  bias model: %s; %d points, %d parameters, residual RMS %.3g, chi2/dof %.3g "
                "(plausible chi2 %.3g-%.3g), %d of %d points outside their 95 %% interval "
                "(expected ~%.1f), %d iterations\n",
                BiasModelName(fit.bias_model), fit.n_points, fit.n_parameters, fit.residual_rms,
                fit.chi2_per_dof, fit.chi2_low, fit.chi2_high, fit.points_outside_95, fit.n_points,
                fit.expected_outside_95, fit.iterations);
  out += line;
  for (const std::string& w : fit.warnings) out += "  WARNING: " + w + "\n";
  return out;
}

}  // namespace driftlab::calib
