// Strapdown INS mechanizations A (NED, WGS-84, coning/sculling) and B (seed 000, flat frame).
#include "driftlab/ins.h"

#include <cmath>
#include <string>

#include "driftlab/spec_error.h"

namespace driftlab {

namespace {

// Position update by the trapezoidal rule on (L, lambda, h), Groves (5.56)-style: the rate of
// (L, lambda, h) is evaluated with the old velocity at the old position (rate_old) and with the new
// velocity at the new position. The new latitude inside the second evaluation only scales R_N, R_E
// and cos L, so a predicted value (error O(dt^2)) is enough: it enters the step at O(dt^3 v / R^2).
Llh TrapezoidPosition(const NavEnvironment& env, const Llh& llh, const Vector3d& rate_old,
                      const Vector3d& v_old, const Vector3d& v_new, double L_new_predicted,
                      double dt_s) {
  const double h_new = llh.h_m - 0.5 * dt_s * (v_old.z() + v_new.z());
  const Vector3d rate_new = env.LlhRate(L_new_predicted, h_new, v_new);
  Llh out;
  out.lat_rad = llh.lat_rad + 0.5 * dt_s * (rate_old.x() + rate_new.x());
  out.lon_rad = llh.lon_rad + 0.5 * dt_s * (rate_old.y() + rate_new.y());
  out.h_m = h_new;
  return out;
}

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

NedMechanization::Step NedMechanization::Propagate(const Vector3d& delta_v_b,
                                                   const Vector3d& alpha_cross_dv,
                                                   const Vector3d& second_order_b,
                                                   const Vector3d& llh_rate_old, double L_mid,
                                                   double h_mid, const Vector3d& v_mid) const {
  const Vector3d& v_old = state_.v_eb_n;
  // Navigation-frame rotation over the interval, rotation rate taken at the midpoint:
  //   zeta = (omega_ie_n + omega_en_n)(mid) dt                               Groves (5.73)-(5.76)
  Step s;
  const Vector3d omega_ie_n = env_.EarthRate(L_mid);
  const Vector3d omega_en_n = env_.TransportRate(L_mid, h_mid, v_mid);
  const Vector3d& zeta = s.zeta = (omega_ie_n + omega_en_n) * dt_s_;

  // Specific-force velocity increment resolved in n, delta_v_sf_n = integral of
  // C_n(k)^n(t) C_b_n(k) C_b(t)^b(k) f_ib_b dt, expanded to second order in the body rotation
  // alpha and the n-frame rotation zeta (rates constant over the interval; the linear variation
  // is the sculling term already in delta_v_b):
  //   integral = x + 1/2 w + 1/6 C alpha x (alpha x dv) - 1/2 zeta x x - 1/3 zeta x w
  //              + 1/6 zeta x (zeta x x),        x = C_b_n(k) dv, w = C_b_n(k) (alpha x dv)
  // (the -1/3 from integrating s^2 over the cross term of the two rotations). With
  // u = x + 1/2 w = C_b_n(k) delta_v_b (delta_v_b holding dv + 1/2 alpha x dv + sculling):
  //   delta_v_sf_n = u + 1/6 C alpha x (alpha x dv) - 1/2 zeta x u - 1/12 zeta x w
  //                  + 1/6 zeta x (zeta x u)               + O(3rd order)
  // Savage (1998) part 2 section 3 (the first-order form is his eq. 24).
  // The second-order terms matter: at 10 Hz a stationary body otherwise drifts by
  // 1/4 zeta x (zeta x g dt) ~ 1e-11 m/s per step, and in a 0.5 rad/s turn 1/6 alpha^2 dv reaches
  // 2e-7 m/s per step at 100 Hz.
  const Vector3d u = state_.q_b_n * delta_v_b;
  const Vector3d delta_v_sf_n = u + state_.q_b_n * second_order_b - 0.5 * zeta.cross(u) -
                                zeta.cross(state_.q_b_n * alpha_cross_dv) / 12.0 +
                                zeta.cross(zeta.cross(u)) / 6.0;
  // Gravity and Coriolis at the midpoint:
  //   v(k+1) = v(k) + delta_v_sf_n + (g_b_n - (omega_en_n + 2 omega_ie_n) x v_eb_n)(mid) dt
  //                                                                                 Groves (5.54)
  const Vector3d g_b_n = env_.Gravity(L_mid, h_mid);
  s.v_eb_n = v_old + delta_v_sf_n + (g_b_n - (omega_en_n + 2.0 * omega_ie_n).cross(v_mid)) * dt_s_;

  // 2 L_mid - L_k is the midpoint-rule prediction of L_k+1 (exactly the predicted L_k+1 in the
  // corrector, whose L_mid is the average of the two).
  s.llh = TrapezoidPosition(env_, state_.llh, llh_rate_old, v_old, s.v_eb_n,
                            2.0 * L_mid - state_.llh.lat_rad, dt_s_);
  return s;
}

void NedMechanization::Update(const ImuIncrement& increment) {
  const Vector3d& dtheta = increment.delta_theta_ib_b;
  const Vector3d& dv = increment.delta_v_ib_b;

  // Body attitude increment and specific-force increment in the body frame at t_k.
  //   alpha = dtheta_k + 1/12 dtheta_{k-1} x dtheta_k                     (two-sample coning)
  //   dv_b = dv_k + 1/2 dtheta_k x dv_k + 1/12 (dtheta_{k-1} x dv_k + dv_{k-1} x dtheta_k)
  //                                      (rotation compensation + two-sample sculling)
  // Savage (1998) part 1 (eqs. 15, 28), part 2 (eqs. 19, 20); Groves (5.97)-(5.98). Both are exact
  // for angular rate and specific force linear in time (to first order in the rotation; the
  // second-order term follows in Propagate). On the first step no previous increment
  // exists; the constant-rate assumption (previous = current) makes the 1/12 terms vanish.
  Vector3d alpha = dtheta;
  Vector3d delta_v_b = dv;
  Vector3d alpha_cross_dv = Vector3d::Zero();
  Vector3d second_order_b = Vector3d::Zero();
  if (options_.coning_sculling) {
    alpha_cross_dv = dtheta.cross(dv);
    // Second-order rotation compensation 1/6 alpha x (alpha x dv) (exact integral of
    // exp([omega t x]) f for constant omega and f, Savage (1998) part 2).
    second_order_b = dtheta.cross(alpha_cross_dv) / 6.0;
    delta_v_b += 0.5 * alpha_cross_dv;
    if (have_previous_) {
      alpha += previous_.delta_theta_ib_b.cross(dtheta) / 12.0;
      delta_v_b +=
          (previous_.delta_theta_ib_b.cross(dv) + previous_.delta_v_ib_b.cross(dtheta)) / 12.0;
    }
  }

  // Predictor: midpoint velocity extrapolated from the last two epochs, midpoint position by half
  // an Euler step with it.
  const Vector3d v_mid_predicted =
      have_previous_ ? Vector3d(1.5 * state_.v_eb_n - 0.5 * previous_v_eb_n_) : state_.v_eb_n;
  const Vector3d llh_rate_old = env_.LlhRate(state_.llh.lat_rad, state_.llh.h_m, state_.v_eb_n);
  const Vector3d llh_rate_mid = env_.LlhRate(state_.llh.lat_rad, state_.llh.h_m, v_mid_predicted);
  const Step predicted =
      Propagate(delta_v_b, alpha_cross_dv, second_order_b, llh_rate_old,
                state_.llh.lat_rad + 0.5 * dt_s_ * llh_rate_mid.x(),
                state_.llh.h_m + 0.5 * dt_s_ * llh_rate_mid.z(), v_mid_predicted);
  // Corrector: midpoint quantities as averages of the old and the predicted new state.
  const Step corrected = Propagate(delta_v_b, alpha_cross_dv, second_order_b, llh_rate_old,
                                   0.5 * (state_.llh.lat_rad + predicted.llh.lat_rad),
                                   0.5 * (state_.llh.h_m + predicted.llh.h_m),
                                   0.5 * (state_.v_eb_n + predicted.v_eb_n));

  // Attitude: C_b_n(k+1) = C_n(k)_n(k+1) C_b_n(k) C_b(k+1)_b(k), each factor the exact rotation of
  // its rotation vector:  q_b_n(k+1) = q(-zeta) q_b_n(k) q(alpha).                Groves (5.75)
  state_.q_b_n = (RotationVectorToQuaternion(-corrected.zeta) * state_.q_b_n *
                  RotationVectorToQuaternion(alpha))
                     .normalized();
  previous_v_eb_n_ = state_.v_eb_n;
  previous_ = increment;
  have_previous_ = true;
  ++steps_;
  state_.t_s = t0_s_ + static_cast<double>(steps_) * dt_s_;
  state_.llh = corrected.llh;
  state_.v_eb_n = corrected.v_eb_n;
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
