// Strapdown INS mechanizations.
//
// A: NedMechanization — full local-level NED mechanization on WGS-84 (or the flat frame): Earth
//    rate, transport rate, Coriolis, normal gravity with height; attitude and specific-force
//    increments with two-sample coning and sculling corrections (Savage, "Strapdown Inertial
//    Navigation Integration Algorithm Design", JGCD 21(1) and 21(2), 1998; Groves section 5.5).
//    The specific-force transformation keeps the second-order terms in the body and n-frame
//    rotations; gravity, Coriolis and the n-frame rotation are taken at the interval midpoint
//    (extrapolated, then one predictor-corrector pass); position by the trapezoidal rule.
//    Truncation: exact for rates and specific force linear in time; one-off O(dt^2) errors at
//    steps of the angular rate (see tests/engine/ins/ins_slow_test.cc). Vertical channel free or
//    aided by truth height.
// B: Seed000Mechanization — seed 000's algorithm exactly: navigation frame = body frame at start;
//    gravity vector and gyro bias = means over an initial static period; first-order quaternion
//    step Q(k+1) = (I + 1/2 Omega(omega_k) dt) Q(k) with the bias-corrected rate at the start of
//    the interval (the seed's Taylor expansion about t_k), and normalisation; specific force
//    rotated to the navigation frame, gravity removed, trapezoidal velocity and position; Euler
//    angles roll = atan2(C32, C33), pitch = -asin(C31), yaw = atan2(C21, C11); optional first-order
//    low-pass filter on the rates and accelerations.
#pragma once

#include <cstdint>

#include "driftlab/earth.h"
#include "driftlab/nav_state.h"

namespace driftlab {

enum class VerticalChannel {
  kFree,         // height and vertical velocity integrated (unstable, time constant sqrt(R/2g))
  kTruthHeight,  // height and vertical velocity reset to the truth after every step (perfect
                 // altimeter), which isolates the horizontal channels
};

struct NedMechanizationOptions {
  VerticalChannel vertical = VerticalChannel::kFree;
  bool coning_sculling = true;  // two-sample corrections; off = single-sample (for comparison)
};

// Mechanization A.
class NedMechanization {
 public:
  NedMechanization(const NavEnvironment& env, const NavState& initial, double dt_s,
                   const NedMechanizationOptions& options);
  // Advances the state by one interval with the increment over that interval.
  void Update(const ImuIncrement& increment);
  // Vertical aiding: overwrite height and vertical velocity (called by the driver with truth
  // values when options.vertical == kTruthHeight).
  void SetVertical(double h_m, double v_D_m_per_s);
  const NavState& state() const { return state_; }
  const NedMechanizationOptions& options() const { return options_; }

 private:
  NavEnvironment env_;
  NavState state_;
  double dt_s_;
  NedMechanizationOptions options_;
  ImuIncrement previous_;     // increment of the previous interval (for the 2-sample terms)
  Vector3d previous_v_eb_n_;  // velocity one step back (midpoint extrapolation)
  bool have_previous_ = false;
  double t0_s_ = 0.0;
  int64_t steps_ = 0;
};

struct Seed000Options {
  // seed 000: 90 s at rest. The samples in [0, T), i.e. t = 0, dt, ..., (N - 1) dt with
  // N = round(T / dt), are averaged; navigation starts at t = N dt = T from zero position and
  // velocity and Q = identity (the sample at T is the first of the trapezoidal rule).
  double static_period_s = 90.0;
  // 0 = no filter; else a first-order RC low-pass with this cutoff on the raw rates and specific
  // forces (before the averaging, so bias and gravity are estimated from what is later used),
  // discretised as exponential smoothing y_k = y_{k-1} + a (x_k - y_{k-1}), a = dt / (RC + dt),
  // RC = 1 / (2 pi cutoff). Must be below the Nyquist frequency.
  double lowpass_cutoff_hz = 0.0;
};

// Mechanization B. Consumes point samples (rates and specific force as the seed's sensors give).
// Its navigation frame is the body frame at t = 0; position and velocity start at zero.
class Seed000Mechanization {
 public:
  Seed000Mechanization(double dt_s, const Seed000Options& options);
  // Feed the sample at t_k (k = 0, 1, ...). During the static period the samples are averaged
  // and the state stays at its initial value; navigation starts at the end of it.
  void Update(const ImuSample& sample);
  bool aligned() const { return aligned_; }
  double t_s() const { return t_s_; }
  // State in the navigation frame (= initial body frame).
  const Vector3d& r_nav_m() const { return r_; }
  const Vector3d& v_nav_m_per_s() const { return v_; }
  const Quaterniond& q_b_nav() const { return q_; }
  EulerAngles euler() const;
  // Estimates from the static period.
  const Vector3d& gravity_nav() const { return g_nav_; }  // mean f_ib_b (sign as measured)
  const Vector3d& gyro_bias_rad_per_s() const { return gyro_bias_; }
  // The state expressed as a NavState in NED, given the truth's initial state (whose attitude
  // defines the navigation frame): r_n = C_b_n(0) r_nav, etc. Position goes through the
  // environment's metre scaling.
  NavState ToNed(const NavEnvironment& env, const NavState& initial_truth) const;

 private:
  double dt_s_;
  Seed000Options options_;
  double t_s_ = 0.0;
  int64_t count_ = 0;
  int64_t static_samples_ = 0;
  bool aligned_ = false;
  Vector3d sum_f_ = Vector3d::Zero(), sum_omega_ = Vector3d::Zero();
  Vector3d carry_f_ = Vector3d::Zero(), carry_omega_ = Vector3d::Zero();
  Vector3d g_nav_ = Vector3d::Zero(), gyro_bias_ = Vector3d::Zero();
  Vector3d r_ = Vector3d::Zero(), v_ = Vector3d::Zero(), a_prev_ = Vector3d::Zero();
  Quaterniond q_ = Quaterniond::Identity();
  Vector3d omega_prev_ = Vector3d::Zero();  // bias-corrected rate at the previous sample
  double lowpass_alpha_ = 0.0;              // 0 = filter off
  ImuSample filtered_;
  bool filter_started_ = false;
};

}  // namespace driftlab
