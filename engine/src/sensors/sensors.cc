// Inertial sensor triad error simulation (sensors.h).
//
// Per-run constants (exp, expm1, sqrt of the step's coefficients) use std:: functions at
// construction only; the hot path (Apply) uses + - * / sqrt floor and the engine's Gaussian
// streams, so its bits depend only on those constants.
#include "driftlab/sensors.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "driftlab/elementary.h"
#include "driftlab/spec_error.h"
// The step over the lane width (internal linkage: this file's copy at W = 1 shares no inline code
// with the lockstep kernel files built for other instruction sets).
#include "sensors/triad_step.h"

namespace driftlab {
namespace {

void RequireFinite(double v, const std::string& field) {
  if (!std::isfinite(v)) throw SpecError(field, ValueText(v), "a finite number");
}

void RequireNonNegative(double v, const std::string& field) {
  if (!std::isfinite(v) || v < 0.0) throw SpecError(field, ValueText(v), "finite value >= 0");
}

void RequirePositive(double v, const std::string& field, const std::string& why) {
  if (!std::isfinite(v) || v <= 0.0) {
    throw SpecError(field, ValueText(v), "finite value > 0" + why);
  }
}

void RequireOpenUnit(double v, const std::string& field) {
  if (!std::isfinite(v) || v <= -1.0 || v >= 1.0) {
    throw SpecError(field, ValueText(v), "-1 < value < 1 (dimensionless, e.g. 100 ppm = 1e-4)");
  }
}

std::string Index(const std::string& field, int i) { return field + "[" + std::to_string(i) + "]"; }

// x - 2 (1 - e^-x) + (1 - e^-2x) / 2 = sum_{n>=3} (-1)^n (2 - 2^(n-1)) x^n / n!
//   = x^3/3 - x^4/4 + 7 x^5/60 - ...
// (the normalised variance of the part of a Gauss-Markov increment integral that is independent of
// the start value; see the derivation in TriadErrorSimulator's constructor). The closed form
// cancels x to x^3 for small x, so the series is used for x < 0.1.
double GaussMarkovIntegralShape(double x) {
  if (x >= 0.1) return x + 2.0 * math::Expm1(-x) - 0.5 * math::Expm1(-2.0 * x);
  double sum = 0.0;
  double power_over_factorial = x * x / 2.0;  // x^n / n! at n = 2
  double two_pow = 2.0;                       // 2^(n-1) at n = 2
  for (int n = 3; n <= 30; ++n) {
    power_over_factorial *= x / n;
    two_pow *= 2.0;
    const double term = ((n % 2 == 0) ? 1.0 : -1.0) * (2.0 - two_pow) * power_over_factorial;
    sum += term;
    if (std::fabs(term) < 1e-18 * std::fabs(sum)) break;
  }
  return sum;
}

// g(x) = AVAR / sigma^2 of a Gauss-Markov process at t = x tau:
//   g(x) = (2x - (3 - 4 e^-x + e^-2x)) / x^2 = sum_{n>=3} (-1)^(n+1) (2^n - 4) x^(n-2) / n!
double GaussMarkovAllanShape(double x) {
  if (x >= 0.1) {
    const double h = -4.0 * math::Expm1(-x) + math::Expm1(-2.0 * x);  // 3 - 4 e^-x + e^-2x
    return (2.0 * x - h) / (x * x);
  }
  double sum = 0.0;
  double power_over_factorial = 0.5;  // x^(n-2) / n! at n = 2
  double two_pow = 4.0;               // 2^n at n = 2
  for (int n = 3; n <= 30; ++n) {
    power_over_factorial *= x / n;
    two_pow *= 2.0;
    const double term = ((n % 2 == 0) ? -1.0 : 1.0) * (two_pow - 4.0) * power_over_factorial;
    sum += term;
    if (std::fabs(term) <= 1e-18 * std::fabs(sum)) break;
  }
  return sum;
}

}  // namespace

void ValidateTriadErrorParams(const TriadErrorParams& p, const std::string& path) {
  for (int i = 0; i < 3; ++i) RequireFinite(p.fixed_bias[i], Index(path + ".fixed_bias", i));
  RequireNonNegative(p.turn_on_bias_sigma, path + ".turn_on_bias_sigma");

  RequireNonNegative(p.bias_gauss_markov.sigma, path + ".bias_gauss_markov.sigma");
  RequireNonNegative(p.bias_gauss_markov.tau_s, path + ".bias_gauss_markov.tau_s");
  if (p.bias_gauss_markov.sigma > 0.0) {
    RequirePositive(p.bias_gauss_markov.tau_s, path + ".bias_gauss_markov.tau_s",
                    " when bias_gauss_markov.sigma > 0");
  }

  const FlickerParams& f = p.bias_flicker;
  RequireNonNegative(f.bias_instability, path + ".bias_flicker.bias_instability");
  RequireNonNegative(f.tau_min_s, path + ".bias_flicker.tau_min_s");
  RequireNonNegative(f.tau_max_s, path + ".bias_flicker.tau_max_s");
  if (f.bias_instability > 0.0) {
    RequirePositive(f.tau_min_s, path + ".bias_flicker.tau_min_s",
                    " when bias_flicker.bias_instability > 0");
    if (!(f.tau_max_s > f.tau_min_s) || f.tau_max_s > kMaxFlickerRangeRatio * f.tau_min_s) {
      throw SpecError(
          path + ".bias_flicker.tau_max_s", ValueText(f.tau_max_s),
          "tau_min_s < tau_max_s <= 1e9 tau_min_s (tau_min_s = " + ValueText(f.tau_min_s) + ")");
    }
  }

  RequireNonNegative(p.white_noise_density, path + ".white_noise_density");
  RequireNonNegative(p.random_walk, path + ".random_walk");
  for (int i = 0; i < 3; ++i) {
    RequireOpenUnit(p.scale_factor_fixed[i], Index(path + ".scale_factor_fixed", i));
    RequireOpenUnit(p.scale_factor_asymmetry[i], Index(path + ".scale_factor_asymmetry", i));
  }
  RequireNonNegative(p.scale_factor_sigma, path + ".scale_factor_sigma");
  if (p.scale_factor_sigma > 0.1 * (1.0 + 1e-12)) {  // 1e5 ppm, whatever its rounding
    throw SpecError(path + ".scale_factor_sigma", ValueText(p.scale_factor_sigma),
                    "0 <= value <= 0.1 (10 %; dimensionless)");
  }
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      const std::string field = Index(Index(path + ".misalignment_fixed", r), c);
      const double m = p.misalignment_fixed(r, c);
      if (r == c) {
        if (m != 0.0) {
          throw SpecError(field, ValueText(m),
                          "0 (diagonal: use scale_factor_fixed for scale-factor errors)");
        }
      } else if (!std::isfinite(m) || std::fabs(m) >= 0.5) {
        throw SpecError(field, ValueText(m), "|value| < 0.5 rad (small misalignment)");
      }
    }
  }
  RequireNonNegative(p.misalignment_sigma_rad, path + ".misalignment_sigma_rad");
  if (p.misalignment_sigma_rad > 0.1 * (1.0 + 1e-12)) {  // 100 mrad, whatever its rounding
    throw SpecError(path + ".misalignment_sigma_rad", ValueText(p.misalignment_sigma_rad),
                    "0 <= value <= 0.1 rad");
  }
  RequireNonNegative(p.quantization, path + ".quantization");
  RequireNonNegative(p.range, path + ".range");
}

void ValidateImuErrorModel(const ImuErrorModel& model, const std::string& path) {
  ValidateTriadErrorParams(model.gyro, path + ".gyro");
  ValidateTriadErrorParams(model.accel, path + ".accel");
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      RequireFinite(model.gyro_g_sensitivity(r, c),
                    Index(Index(path + ".gyro_g_sensitivity", r), c));
    }
  }
}

double GaussMarkovAllanVariance(double sigma, double tau_s, double tau_avg_s) {
  return sigma * sigma * GaussMarkovAllanShape(tau_avg_s / tau_s);
}

std::vector<GaussMarkovComponent> DesignFlickerApproximation(const FlickerParams& params) {
  std::vector<GaussMarkovComponent> components;
  if (!(params.bias_instability > 0.0)) return components;
  const double log_lo = math::Log(params.tau_min_s / 4.0);
  const double log_hi = math::Log(2.0 * params.tau_max_s);
  const double max_log_ratio = 0.5 * math::Log(10.0);  // two components per decade
  const int n = static_cast<int>(std::ceil((log_hi - log_lo) / max_log_ratio - 1e-9)) + 1;
  const double log_ratio = (log_hi - log_lo) / (n - 1);
  const double variance =
      params.bias_instability * params.bias_instability * log_ratio / std::numbers::pi;
  const double end_variance = variance * (1.0 + 1.0 / log_ratio);
  components.resize(static_cast<size_t>(n));
  for (int j = 0; j < n; ++j) {
    const bool end = (j == 0 || j == n - 1);
    components[j].sigma = std::sqrt(end ? end_variance : variance);
    components[j].tau_s = math::Exp(log_lo + j * log_ratio);
  }
  return components;
}

double SumOfGaussMarkovAllanDeviation(const std::vector<GaussMarkovComponent>& components,
                                      double tau_avg_s) {
  double avar = 0.0;
  for (const GaussMarkovComponent& c : components) {
    avar += GaussMarkovAllanVariance(c.sigma, c.tau_s, tau_avg_s);
  }
  return std::sqrt(avar);
}

void TriadErrorSimulator::Channel::Refill(uint64_t index) {
  base = index & ~static_cast<uint64_t>(kDeviateBlock - 1);
  stream.FillGaussian(base, std::span<double>(buffer));
}

TriadJobConstants ComposeTriadJobConstants(const TriadErrorParams& params, double rate_hz,
                                           const std::string& path) {
  ValidateTriadErrorParams(params, path);
  if (!std::isfinite(rate_hz) || rate_hz <= 0.0) {
    throw SpecError("rate_hz", ValueText(rate_hz), "finite value > 0 [Hz]");
  }
  TriadJobConstants job;
  job.dt_s = 1.0 / rate_hz;
  const double dt = job.dt_s;
  job.half_asymmetry = 0.5 * params.scale_factor_asymmetry;
  job.has_asymmetry = !params.scale_factor_asymmetry.isZero(0.0);

  if (params.white_noise_density > 0.0) {
    job.white_noise = true;
    job.white_increment = params.white_noise_density * std::sqrt(dt);
    job.white_sample = params.white_noise_density / std::sqrt(dt);
  }

  if (params.bias_gauss_markov.sigma > 0.0) {
    // Ornstein-Uhlenbeck process b' = -b / T + q w(t), q^2 = 2 sigma^2 / T, over one step h = dt,
    // x = h / T, a = e^-x. Given b_k (Gardiner, "Stochastic Methods", 4th ed., section 3.8.4):
    //   b_{k+1} = a b_k + eta,          eta = q int_0^h e^{-(h-u)/T} dW(u)
    //   I_k = int b = T (1 - a) b_k + eps,  eps = q T int_0^h (1 - e^{-(h-u)/T}) dW(u)
    // Ito isometry: Var eta = sigma^2 (1 - a^2); Cov(eps, eta) = sigma^2 T (1 - a)^2;
    //   Var eps = 2 sigma^2 T^2 [x - 2 (1 - a) + (1 - a^2) / 2].
    // Hence eta = drive w1, eps = c w1 + d w2 with drive = sigma sqrt(1 - a^2),
    // c = Cov / drive, d = sqrt(Var eps - c^2): exact in distribution for any dt / T.
    const double sigma = params.bias_gauss_markov.sigma;
    const double T = params.bias_gauss_markov.tau_s;
    const double x = dt / T;
    const double one_minus_a = -math::Expm1(-x);
    const double one_minus_a2 = -math::Expm1(-2.0 * x);
    job.gauss_markov = true;
    job.gm_decay = math::Exp(-x);
    job.gm_drive_sigma = sigma * std::sqrt(one_minus_a2);
    job.gm_mean_gain = T * one_minus_a;
    job.gm_integral_w1_gain = sigma * sigma * T * one_minus_a * one_minus_a / job.gm_drive_sigma;
    const double var_eps = 2.0 * sigma * sigma * T * T * GaussMarkovIntegralShape(x);
    job.gm_integral_w2_gain =
        std::sqrt(std::max(0.0, var_eps - job.gm_integral_w1_gain * job.gm_integral_w1_gain));
  }

  if (params.random_walk > 0.0) {
    // b_{k+1} = b_k + K W(h); I_k = b_k h + K int_0^h (h - u) dW(u). Given the step, the integral
    // is b_k h + (h/2) (b_{k+1} - b_k) + a Brownian-bridge term of variance K^2 h^3 / 12
    // (Var int (h-u) dW = h^3/3, Cov with W(h) = h^2/2: h^3/3 - (h^2/2)^2 / h = h^3/12).
    job.random_walk = true;
    job.rw_step_sigma = params.random_walk * std::sqrt(dt);
    job.rw_bridge_sigma = params.random_walk * dt * std::sqrt(dt / 12.0);
  }

  if (job.white_noise || job.gauss_markov || job.random_walk) {
    // One deviate for the three independent parts (TriadJobConstants::independent_sigma). With
    // white noise alone the scale is white_increment itself (not the sqrt of its square).
    job.independent = true;
    job.independent_sigma = !job.gauss_markov && !job.random_walk
                                ? job.white_increment
                                : std::sqrt(job.white_increment * job.white_increment +
                                            job.gm_integral_w2_gain * job.gm_integral_w2_gain +
                                            job.rw_bridge_sigma * job.rw_bridge_sigma);
  }

  job.flicker = DesignFlickerApproximation(params.bias_flicker);
  // Component j is advanced exactly every h_j = 2^m dt, the largest such h_j <= tau_j / 32
  // (m = 0 when tau_j < 32 dt), and held between updates. Holding changes the component's
  // Allan variance by < 0.1 % at t >= tau_j and less at longer t (zero-order hold of the exact
  // AR(1) sequence; checked numerically at h = tau / 32), while slow components then cost a
  // deviate only every 2^m samples.
  for (size_t j = 0; j < job.flicker.size(); ++j) {
    const double T = job.flicker[j].tau_s;
    int m = 0;
    while (m < 40 && std::ldexp(dt, m + 1) <= T / 32.0) ++m;
    const double h = std::ldexp(dt, m);
    job.flicker_period_log2[j] = m;
    job.flicker_decay[j] = math::Exp(-h / T);
    job.flicker_drive_sigma[j] = job.flicker[j].sigma * std::sqrt(-math::Expm1(-2.0 * h / T));
  }
  job.range = params.range;
  job.quantization = params.quantization;
  return job;
}

TriadRunConstants DrawTriadRunConstants(const TriadErrorParams& params,
                                        const TriadJobConstants& job, SensorId sensor,
                                        uint64_t seed, uint32_t run_index) {
  auto stream = [&](ErrorTerm term, int axis, int component) {
    return RandomStream(
        seed, run_index,
        StreamKey{sensor, static_cast<uint8_t>(axis), term, static_cast<uint8_t>(component)});
  };
  TriadRunConstants run;
  for (int i = 0; i < 3; ++i) {
    double s = params.scale_factor_fixed[i];
    if (params.scale_factor_sigma > 0.0) {
      s += params.scale_factor_sigma * stream(ErrorTerm::kScaleFactor, i, 0).Gaussian(0);
    }
    run.scale_misalignment(i, i) = 1.0 + s;
    for (int c = 0; c < 3; ++c) {
      if (c == i) continue;
      double m = params.misalignment_fixed(i, c);
      if (params.misalignment_sigma_rad > 0.0) {
        m += params.misalignment_sigma_rad * stream(ErrorTerm::kMisalignment, i, c).Gaussian(0);
      }
      run.scale_misalignment(i, c) = m;
    }
    double b = params.fixed_bias[i];
    if (params.turn_on_bias_sigma > 0.0) {
      b += params.turn_on_bias_sigma * stream(ErrorTerm::kTurnOnBias, i, 0).Gaussian(0);
    }
    run.constant_bias[i] = b;
  }
  // Stationary start N(0, sigma^2), or 0 (GaussMarkovParams::start_at_zero). The start draw has
  // its own stream, so skipping it changes no other deviate of the run.
  if (job.gauss_markov && !params.bias_gauss_markov.start_at_zero) {
    for (int i = 0; i < 3; ++i) {
      run.gm_state[i] =
          params.bias_gauss_markov.sigma * stream(ErrorTerm::kInitialState, i, 0).Gaussian(0);
    }
  }
  for (size_t j = 0; j < job.flicker.size(); ++j) {
    for (int i = 0; i < 3; ++i) {
      run.flicker_state[i][j] =
          job.flicker[j].sigma *
          stream(ErrorTerm::kInitialState, i, 1 + static_cast<int>(j)).Gaussian(0);
    }
  }
  return run;
}

TriadStepParams TriadStepParamsOf(const TriadJobConstants& c) {
  TriadStepParams p;
  p.independent = c.independent;
  p.independent_sigma = c.independent_sigma;
  p.gauss_markov = c.gauss_markov;
  p.gm_decay = c.gm_decay;
  p.gm_drive_sigma = c.gm_drive_sigma;
  p.gm_mean_gain = c.gm_mean_gain;
  p.gm_integral_w1_gain = c.gm_integral_w1_gain;
  p.random_walk = c.random_walk;
  p.rw_step_sigma = c.rw_step_sigma;
  p.asymmetry = c.has_asymmetry;
  for (int i = 0; i < 3; ++i) p.half_asymmetry[i] = c.half_asymmetry[i];
  p.n_flicker = static_cast<int>(c.flicker.size());
  for (int j = 0; j < p.n_flicker; ++j) {
    p.flicker_decay[j] = c.flicker_decay[static_cast<size_t>(j)];
    p.flicker_drive_sigma[j] = c.flicker_drive_sigma[static_cast<size_t>(j)];
    p.flicker_period_log2[j] = c.flicker_period_log2[static_cast<size_t>(j)];
  }
  p.range = c.range;
  p.quantization = c.quantization;
  return p;
}

TriadErrorSimulator::TriadErrorSimulator(const TriadErrorParams& params, SensorId sensor,
                                         uint64_t seed, uint32_t run_index, double rate_hz,
                                         const std::string& path) {
  const TriadJobConstants job = ComposeTriadJobConstants(params, rate_hz, path);
  const TriadRunConstants run = DrawTriadRunConstants(params, job, sensor, seed, run_index);
  dt_s_ = job.dt_s;
  auto add_channels = [&](ErrorTerm term, int count_per_axis) {
    const int first = static_cast<int>(channels_.size());
    for (int axis = 0; axis < 3; ++axis) {
      for (int component = 0; component < count_per_axis; ++component) {
        channels_.emplace_back();
        channels_.back().stream = RandomStream(
            seed, run_index,
            StreamKey{sensor, static_cast<uint8_t>(axis), term, static_cast<uint8_t>(component)});
      }
    }
    return first;
  };
  scale_misalignment_ = run.scale_misalignment;
  constant_bias_ = run.constant_bias;
  half_asymmetry_ = job.half_asymmetry;
  has_asymmetry_ = job.has_asymmetry;
  white_noise_ = job.white_noise;
  white_sample_ = job.white_sample;
  if (job.independent) independent_ch_ = add_channels(ErrorTerm::kWhiteNoise, 1);
  if (job.gauss_markov) {
    gm_a_ = job.gm_decay;
    gm_drive_ = job.gm_drive_sigma;
    gm_ch_ = add_channels(ErrorTerm::kGaussMarkov, 1);
    for (int i = 0; i < 3; ++i) state_.gm_state[i] = run.gm_state[i];
  }
  if (job.random_walk) {
    rw_step_ = job.rw_step_sigma;
    rw_ch_ = add_channels(ErrorTerm::kRandomWalk, 1);
  }
  flicker_ = job.flicker;
  n_flicker_ = static_cast<int>(flicker_.size());
  if (n_flicker_ > 0) {
    flicker_a_ = job.flicker_decay;
    flicker_drive_ = job.flicker_drive_sigma;
    flicker_period_log2_ = job.flicker_period_log2;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < n_flicker_; ++j) state_.flicker_state[i][j] = run.flicker_state[i][j];
    }
    flicker_ch_ = add_channels(ErrorTerm::kFlicker, n_flicker_);
  }
  range_ = job.range;
  quantization_ = job.quantization;

  step_params_ = TriadStepParamsOf(job);
  for (int i = 0; i < 3; ++i) {
    state_.constant_bias[i] = constant_bias_[i];
    for (int c = 0; c < 3; ++c) state_.scale_misalignment[i][c] = scale_misalignment_(i, c);
  }
}

Eigen::Vector3d TriadErrorSimulator::ApplyIncrement(const Eigen::Vector3d& ideal,
                                                    const Eigen::Vector3d& additive) {
  const double dt = dt_s_;
  const uint64_t k = static_cast<uint64_t>(step_);
  // The triad's error step at one lane (sensors/triad_step.h), its deviates from this run's
  // channels.
  struct Deviates {
    TriadErrorSimulator* s;
    uint64_t k;
    double At(int first, int axis) const { return s->channels_[first + axis].At(k); }
    double Independent(int i) const { return At(s->independent_ch_, i); }
    double GmW1(int i) const { return At(s->gm_ch_, i); }
    double RwW1(int i) const { return At(s->rw_ch_, i); }
    double Flicker(int i, int j, uint64_t step, int m) const {
      return s->channels_[s->flicker_ch_ + i * s->n_flicker_ + j].At((step >> m) - 1);
    }
  };
  const Deviates dev{this, k};
  const auto out =
      triad_step::TriadStep<1>(step_params_, state_, dev, ideal.data(), additive.data(), k, dt);
  ++step_;
  return Eigen::Vector3d(out.x, out.y, out.z);
}

// A point sample: the increment step's terms as rates (weight 1 instead of dt), the Gauss-Markov
// and random-walk states as they are at the instant, white noise N / sqrt(dt), the quantization
// LSB divided by dt.
Eigen::Vector3d TriadErrorSimulator::ApplySample(const Eigen::Vector3d& ideal,
                                                 const Eigen::Vector3d& additive) {
  const double dt = dt_s_;
  const uint64_t k = static_cast<uint64_t>(step_);
  Eigen::Vector3d y = scale_misalignment_ * ideal + additive;
  if (has_asymmetry_) y += half_asymmetry_.cwiseProduct(ideal.cwiseAbs());  // sign(x) a/2 x
  for (int i = 0; i < 3; ++i) {
    double e = constant_bias_[i];
    if (white_noise_) e += white_sample_ * channels_[independent_ch_ + i].At(k);
    if (gm_ch_ >= 0) {
      const double w1 = channels_[gm_ch_ + i].At(k);
      double& b = state_.gm_state[i];
      e += b;
      b = gm_a_ * b + gm_drive_ * w1;
    }
    if (rw_ch_ >= 0) {
      const double step = rw_step_ * channels_[rw_ch_ + i].At(k);
      double& b = state_.rw_state[i];
      e += b;
      b += step;
    }
    if (n_flicker_ > 0) {
      double sum = 0.0;
      Channel* ch = &channels_[flicker_ch_ + i * n_flicker_];
      double* x = state_.flicker_state[i];
      for (int j = 0; j < n_flicker_; ++j) {
        const int m = flicker_period_log2_[j];
        const uint64_t mask = (uint64_t{1} << m) - 1;
        if (k != 0 && (k & mask) == 0) {
          x[j] = flicker_a_[j] * x[j] + flicker_drive_[j] * ch[j].At((k >> m) - 1);
        }
        sum += x[j];
      }
      e += sum;
    }
    double v = y[i] + e;
    if (range_ > 0.0) v = std::clamp(v, -range_, range_);
    if (quantization_ > 0.0) {
      const double lsb = quantization_ / dt;
      const double carried = v + state_.remainder[i];
      const double out = lsb * std::floor(carried / lsb + 0.5);
      state_.remainder[i] = carried - out;
      v = out;
    }
    y[i] = v;
  }
  ++step_;
  return y;
}

namespace {
const ImuErrorModel& Validated(const ImuErrorModel& model) {
  ValidateImuErrorModel(model, "sensor");
  return model;
}
}  // namespace

ImuErrorSimulator::ImuErrorSimulator(const ImuErrorModel& model, uint64_t seed, uint32_t run_index,
                                     double rate_hz)
    : gyro_g_sensitivity_(Validated(model).gyro_g_sensitivity),
      has_g_sensitivity_(!model.gyro_g_sensitivity.isZero(0.0)),
      gyro_(model.gyro, SensorId::kGyro, seed, run_index, rate_hz, "sensor.gyro"),
      accel_(model.accel, SensorId::kAccel, seed, run_index, rate_hz, "sensor.accel") {}

void ImuErrorSimulator::Apply(const ImuIncrement& ideal, ImuIncrement* measured) {
  const Eigen::Vector3d g_term = has_g_sensitivity_
                                     ? Eigen::Vector3d(gyro_g_sensitivity_ * ideal.delta_v_ib_b)
                                     : Eigen::Vector3d::Zero();
  measured->delta_theta_ib_b = gyro_.ApplyIncrement(ideal.delta_theta_ib_b, g_term);
  measured->delta_v_ib_b = accel_.ApplyIncrement(ideal.delta_v_ib_b, Eigen::Vector3d::Zero());
}

void ImuErrorSimulator::Apply(const ImuSample& ideal, ImuSample* measured) {
  const Eigen::Vector3d g_term = has_g_sensitivity_
                                     ? Eigen::Vector3d(gyro_g_sensitivity_ * ideal.f_ib_b)
                                     : Eigen::Vector3d::Zero();
  measured->omega_ib_b = gyro_.ApplySample(ideal.omega_ib_b, g_term);
  measured->f_ib_b = accel_.ApplySample(ideal.f_ib_b, Eigen::Vector3d::Zero());
}

}  // namespace driftlab
