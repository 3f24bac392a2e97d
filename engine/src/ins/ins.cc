// Strapdown INS mechanizations A (NED, WGS-84, coning/sculling) and B (seed 000, flat frame).
#include "driftlab/ins.h"

#include <cmath>
#include <string>

#include "driftlab/spec_error.h"
// The step over the lane width (internal linkage: this file's copy at W = 1 shares no inline code
// with the lockstep kernel files built for other instruction sets).
#include "ins/ned_step.h"

namespace driftlab {

namespace {

// What NedStep reads of the job (lockstep::KernelJob's fields of the same names).
struct NedStepJob {
  EarthParams earth;
  double dt_s = 0.0;
  int coning_sculling = 1;
};

// NedMechanization's state as NedStep<1> reads and writes it: lockstep::NavLanes's
// fields with one double per lane.
struct NedStepState {
  double lat_rad, lon_rad, h_m;
  double v_eb_n[3];
  double q_b_n[4];  // w, x, y, z
  double previous_dtheta[3], previous_dv[3];
  double previous_v_eb_n[3];
  int have_previous;
};

// sum += x with Kahan's compensation term carried in `carry`.
void KahanAdd(const Vector3d& x, Vector3d* sum, Vector3d* carry) {
  const Vector3d y = x - *carry;
  const Vector3d t = *sum + y;
  *carry = (t - *sum) - y;
  *sum = t;
}

}  // namespace

// ---- Mechanization A -----------------------------------------------------------------------

NedMechanization::NedMechanization(const NavEnvironment& env, const NavState& initial, double dt_s,
                                   const NedMechanizationOptions& options)
    : env_(env),
      state_(initial),
      dt_s_(dt_s),
      options_(options),
      previous_v_eb_n_(initial.v_eb_n),
      t0_s_(initial.t_s) {
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) {
    throw SpecError("rate_hz", std::to_string(dt_s > 0.0 ? 1.0 / dt_s : 0.0),
                    "a finite rate > 0 Hz");
  }
  state_.q_b_n.normalize();
}

void NedMechanization::SetVertical(double h_m, double v_D_m_per_s) {
  state_.llh.h_m = h_m;
  state_.v_eb_n.z() = v_D_m_per_s;
}

void NedMechanization::Update(const ImuIncrement& increment) {
  // The step at one lane (ins/ned_step.h, which documents the algorithm): the same code for one
  // run here and for W runs at once in the lockstep runs.
  NedStepJob job;
  job.earth = env_.params();
  job.dt_s = dt_s_;
  job.coning_sculling = options_.coning_sculling ? 1 : 0;
  const Vector3d& dtheta = increment.delta_theta_ib_b;
  const Vector3d& dv = increment.delta_v_ib_b;
  const Vector3d& previous_dtheta = previous_.delta_theta_ib_b;
  const Vector3d& previous_dv = previous_.delta_v_ib_b;
  const Quaterniond& q = state_.q_b_n;
  NedStepState s{state_.llh.lat_rad,
                 state_.llh.lon_rad,
                 state_.llh.h_m,
                 {state_.v_eb_n.x(), state_.v_eb_n.y(), state_.v_eb_n.z()},
                 {q.w(), q.x(), q.y(), q.z()},
                 {previous_dtheta.x(), previous_dtheta.y(), previous_dtheta.z()},
                 {previous_dv.x(), previous_dv.y(), previous_dv.z()},
                 {previous_v_eb_n_.x(), previous_v_eb_n_.y(), previous_v_eb_n_.z()},
                 have_previous_ ? 1 : 0};
  ned_step::NedStep<1>(job, s, {dtheta.x(), dtheta.y(), dtheta.z()}, {dv.x(), dv.y(), dv.z()});
  state_.q_b_n = Quaterniond(s.q_b_n[0], s.q_b_n[1], s.q_b_n[2], s.q_b_n[3]);
  previous_v_eb_n_ = Vector3d(s.previous_v_eb_n[0], s.previous_v_eb_n[1], s.previous_v_eb_n[2]);
  previous_ = increment;
  have_previous_ = true;
  ++steps_;
  state_.t_s = t0_s_ + static_cast<double>(steps_) * dt_s_;
  state_.llh.lat_rad = s.lat_rad;
  state_.llh.lon_rad = s.lon_rad;
  state_.llh.h_m = s.h_m;
  state_.v_eb_n = Vector3d(s.v_eb_n[0], s.v_eb_n[1], s.v_eb_n[2]);
}

// ---- Mechanization B -----------------------------------------------------------------------

Seed000Mechanization::Seed000Mechanization(double dt_s, const Seed000Options& options)
    : dt_s_(dt_s), options_(options) {
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) {
    throw SpecError("rate_hz", std::to_string(dt_s > 0.0 ? 1.0 / dt_s : 0.0),
                    "a finite rate > 0 Hz");
  }
  if (!(options.static_period_s >= dt_s) || !std::isfinite(options.static_period_s)) {
    throw SpecError("navigation.seed000.static_period_s", std::to_string(options.static_period_s),
                    "at least one sample interval (" + std::to_string(dt_s) + " s), finite");
  }
  const double nyquist_hz = 0.5 / dt_s;
  if (!(options.lowpass_cutoff_hz >= 0.0) || !(options.lowpass_cutoff_hz < nyquist_hz)) {
    throw SpecError("navigation.seed000.lowpass_cutoff_hz",
                    std::to_string(options.lowpass_cutoff_hz),
                    "0 (no filter) or > 0 and below the Nyquist frequency " +
                        std::to_string(nyquist_hz) + " Hz");
  }
  // The static period covers the samples at t = 0, dt, ..., (N - 1) dt with N = round(T / dt).
  static_samples_ = std::llround(options.static_period_s / dt_s);
  if (options.lowpass_cutoff_hz > 0.0) {
    // First-order RC low-pass, discretised as exponential smoothing:
    //   y_k = y_{k-1} + a (x_k - y_{k-1}),  a = dt / (RC + dt),  RC = 1 / (2 pi f_c)
    // (backward-Euler discretisation of RC y' + y = x).
    const double rc_s = 1.0 / (2.0 * M_PI * options.lowpass_cutoff_hz);
    lowpass_alpha_ = dt_s / (rc_s + dt_s);
  }
}

void Seed000Mechanization::Update(const ImuSample& sample) {
  // Low-pass on the raw rates and accelerations (seed 000 section 5.1), started on the first
  // sample so that it has no start-up transient from zero.
  if (!filter_started_ || lowpass_alpha_ == 0.0) {
    filtered_ = sample;
    filter_started_ = true;
  } else {
    filtered_.omega_ib_b += lowpass_alpha_ * (sample.omega_ib_b - filtered_.omega_ib_b);
    filtered_.f_ib_b += lowpass_alpha_ * (sample.f_ib_b - filtered_.f_ib_b);
  }
  t_s_ = static_cast<double>(count_) * dt_s_;
  ++count_;

  if (!aligned_) {
    if (count_ <= static_samples_) {
      // Blocks 1-2 of seed 000: the vessel is at rest; average rates (gyro bias) and specific
      // force (the gravity model, as measured, in the body frame = navigation frame at t = 0).
      // Compensated (Kahan) sums: a plain sum of 9000 samples of 9.8 m/s^2 rounds the mean by
      // ~1e-12 m/s^2, a spurious acceleration that integrates to 1e-5 m in an hour.
      KahanAdd(filtered_.omega_ib_b, &sum_omega_, &carry_omega_);
      KahanAdd(filtered_.f_ib_b, &sum_f_, &carry_f_);
      return;
    }
    // First sample at t = T_s: alignment ends, navigation starts from rest with C = I.
    const double n = static_cast<double>(static_samples_);
    gyro_bias_ = sum_omega_ / n;
    g_nav_ = sum_f_ / n;
    aligned_ = true;
    q_ = Quaterniond::Identity();
    r_.setZero();
    v_.setZero();
    omega_prev_ = filtered_.omega_ib_b - gyro_bias_;
    a_prev_ = filtered_.f_ib_b - g_nav_;
    return;
  }

  // Block 3: Qdot = 1/2 Q (x) omega, first-order Taylor step about t_{k-1}:
  //   Q(k) = (I + 1/2 Omega(omega_{k-1}) dt) Q(k-1),  then normalisation.     seed 000 (6)-(7)
  const Vector3d half_theta = 0.5 * dt_s_ * omega_prev_;
  const Quaterniond dq(1.0, half_theta.x(), half_theta.y(), half_theta.z());
  q_ = q_ * dq;
  q_.normalize();
  omega_prev_ = filtered_.omega_ib_b - gyro_bias_;

  // Block 4: a_nav = C(Q) f - g; trapezoidal rule for velocity and position.    seed 000 (8)-(10)
  const Vector3d a = q_ * filtered_.f_ib_b - g_nav_;
  const Vector3d v_new = v_ + 0.5 * dt_s_ * (a_prev_ + a);
  r_ += 0.5 * dt_s_ * (v_ + v_new);
  v_ = v_new;
  a_prev_ = a;
}

EulerAngles Seed000Mechanization::euler() const {
  // roll = atan2(C32, C33), pitch = -asin(C31), yaw = atan2(C21, C11)           seed 000 (11)
  return DcmToEuler(q_.toRotationMatrix());
}

NavState Seed000Mechanization::ToNed(const NavEnvironment& env,
                                     const NavState& initial_truth) const {
  // The navigation frame is the body frame at t = 0: x_n = C_b_n(0) x_nav.
  const Quaterniond& q_b0_n = initial_truth.q_b_n;
  NavState s;
  s.t_s = initial_truth.t_s + t_s_;
  const Vector3d r_n = q_b0_n * r_;
  s.v_eb_n = q_b0_n * v_;
  s.q_b_n = (q_b0_n * q_).normalized();
  // Metres to (L, lambda, h) with the environment's curvilinear scaling at the start point (the
  // rate of (L, lambda, h) per unit velocity, applied to a displacement).
  const Vector3d d_llh = env.LlhRate(initial_truth.llh.lat_rad, initial_truth.llh.h_m, r_n);
  s.llh.lat_rad = initial_truth.llh.lat_rad + d_llh.x();
  s.llh.lon_rad = initial_truth.llh.lon_rad + d_llh.y();
  s.llh.h_m = initial_truth.llh.h_m + d_llh.z();
  return s;
}

}  // namespace driftlab
