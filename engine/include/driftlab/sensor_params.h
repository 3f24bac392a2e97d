// Parameters of an IMU's error model, in SI units (DESIGN.md invariant 1). Datasheet units
// (deg/sqrt(h), deg/h, ug/sqrt(Hz), ppm, ...) are converted by the units module at the edges.
//
// Measurement model for a triad (seed 001; IEEE Std 952-1997 / IEEE Std 1293-1998 terms):
//   m~ = (I + S + M) m + b_fixed + b_turn_on + b_instability(t) + b_random_walk(t) + G f + n(t)
// then quantization (remainder carried between samples) and saturation at the range.
// S = diag(scale-factor errors), M = off-diagonal misalignment / non-orthogonality,
// G = gyro g-sensitivity (gyro only), n = white noise.
//
// Units below: for gyros "u" = rad/s, for accelerometers "u" = m/s^2.
#pragma once

#include <Eigen/Core>
#include <string>

namespace driftlab {

// First-order Gauss-Markov process b' = -b / tau + w, steady-state standard deviation sigma.
// Autocorrelation sigma^2 exp(-|dt| / tau) (seed 001).
// Its state at t = 0 is drawn from the stationary distribution N(0, sigma^2) (the default: the
// bias of an instrument that has been running), or is 0 (start_at_zero: gnss-ins-sim's
// pathgen.bias_drift() starts every run there, so its bias variance grows as
// sigma^2 (1 - exp(-2 t / tau)); set it to reproduce that tool's Monte-Carlo statistics).
struct GaussMarkovParams {
  double sigma = 0.0;  // [u]
  double tau_s = 0.0;  // [s] correlation time
  bool start_at_zero = false;
};

// Flicker (1/f) bias instability, rate PSD S(f) = B^2 / (2 pi f), approximated by a sum of
// Gauss-Markov processes (sensors.h, DesignFlickerApproximation) whose Allan deviation is flat at
// the flicker floor sqrt(2 ln 2 / pi) B = 0.664 B (IEEE Std 952-1997 Annex C, table C.1) over
// [tau_min_s, tau_max_s] (averaging times). B = `bias_instability` is the datasheet figure.
struct FlickerParams {
  double bias_instability = 0.0;  // [u] B
  double tau_min_s = 1.0;
  double tau_max_s = 1000.0;
};

struct TriadErrorParams {
  Eigen::Vector3d fixed_bias = Eigen::Vector3d::Zero();  // [u] deterministic, per axis
  double turn_on_bias_sigma = 0.0;                       // [u] constant per run, per axis
  GaussMarkovParams bias_gauss_markov;                   // [u], [s]
  FlickerParams bias_flicker;                            // [u]
  double white_noise_density = 0.0;  // [u/sqrt(Hz)] = ARW [rad/sqrt(s)] or VRW [m/s/sqrt(s)]
  double random_walk = 0.0;          // [u*sqrt(Hz)] = rate random walk [rad/s/sqrt(s)] or
                                     //   acceleration random walk [m/s^2/sqrt(s)]
  Eigen::Vector3d scale_factor_fixed = Eigen::Vector3d::Zero();  // [-] (ppm * 1e-6)
  double scale_factor_sigma = 0.0;                               // [-] random per run, per axis
  // Scale-factor asymmetry [-], per axis: (K+ - K-) / K, the difference between the scale
  // factors for positive and negative inputs relative to the nominal one (IEEE Std 528-2001
  // "scale factor asymmetry"). The error for an input of sign s is S_ii + s a_i / 2.
  Eigen::Vector3d scale_factor_asymmetry = Eigen::Vector3d::Zero();
  Eigen::Matrix3d misalignment_fixed = Eigen::Matrix3d::Zero();  // [rad] off-diagonal used only
  double misalignment_sigma_rad = 0.0;                           // [rad] random per run, each
                                                                 //   off-diagonal element
  // [u*s] LSB of the increment output (rad or m/s); 0 = off. Point samples use the LSB
  // quantization * rate_hz [u]. Remainders are carried to the next sample.
  double quantization = 0.0;
  double range = 0.0;  // [u] saturation (full scale) of the rate / specific force; 0 = unlimited
};

struct ImuErrorModel {
  std::string name;
  std::string description;  // datasheet, revision, and the assumptions made
  TriadErrorParams gyro;
  TriadErrorParams accel;
  // Gyro g-sensitivity: rate error [rad/s] per specific force [m/s^2], full 3x3.
  Eigen::Matrix3d gyro_g_sensitivity = Eigen::Matrix3d::Zero();
};

}  // namespace driftlab
