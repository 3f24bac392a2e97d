#include "driftlab/ins_gnss_filter.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>
#include <string>

#include "driftlab/attitude.h"
#include "driftlab/spec_error.h"

namespace driftlab {
namespace {

const InsGnssFilterOptions& Validated(const InsGnssFilterOptions& o, double imu_rate_hz) {
  ValidateGnssConfig(o.gnss, imu_rate_hz);
  if (o.propagation_step_samples < 1 || o.propagation_step_samples > 10000) {
    throw SpecError("filter.propagation_step_samples", std::to_string(o.propagation_step_samples),
                    "[1, 10000]");
  }
  return o;
}

}  // namespace

InsGnssFilter::InsGnssFilter(const NavEnvironment& env, const NavState& initial,
                             const ErrorStateMatrix& P0, double imu_rate_hz,
                             const InsGnssFilterOptions& options)
    : env_(env),
      dt_s_(1.0 / imu_rate_hz),
      options_(Validated(options, imu_rate_hz)),
      ins_(env, initial, 1.0 / imu_rate_hz, options.mechanization),
      propagator_(env, options.imu_noise, P0, options.discretization) {}

void InsGnssFilter::Predict(const ImuIncrement& measured) {
  ImuIncrement corrected = measured;
  corrected.delta_v_ib_b -= accel_bias_ * dt_s_;
  corrected.delta_theta_ib_b -= gyro_bias_ * dt_s_;
  const Matrix3d C_before = ins_.state().C_b_n();
  ins_.Update(corrected);
  // Increment resolved with the interval's mean attitude (second order in the rotation).
  f_n_sum_ += 0.5 * (C_before + ins_.state().C_b_n()) * corrected.delta_v_ib_b;
  if (++pending_ >= options_.propagation_step_samples) SyncCovariance();
}

void InsGnssFilter::SyncCovariance() {
  if (pending_ == 0) return;
  const double T = pending_ * dt_s_;
  const NavState& ref = ins_.state();
  const Vector3d f_b = ref.C_b_n().transpose() * (f_n_sum_ / T);
  propagator_.Propagate(ref, f_b, T);
  f_n_sum_.setZero();
  pending_ = 0;
}

void InsGnssFilter::Update(const GnssMeasurement& fix, const Vector3d& omega_ib_b) {
  SyncCovariance();
  const NavState& s = ins_.state();
  const Matrix3d C = s.C_b_n();
  const Vector3d& l = options_.gnss.lever_arm_b_m;
  const Vector3d l_n = C * l;
  const int m = options_.gnss.use_velocity ? 6 : 3;
  Eigen::Matrix<double, 6, 1> z = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, kNumErrorStates> H = Eigen::Matrix<double, 6, kNumErrorStates>::Zero();
  Eigen::Matrix<double, 6, 6> R = Eigen::Matrix<double, 6, 6>::Zero();
  // Position: estimated antenna minus fix, metres NED at the fix.
  z.head<3>() = env_.PositionErrorNed(s.llh, fix.llh) + l_n;
  H.block<3, 3>(0, kErrPosition) = Matrix3d::Identity();
  H.block<3, 3>(0, kErrAttitude) = -Skew(l_n);
  const GnssConfig& g = options_.gnss;
  for (int i = 0; i < 3; ++i) {
    R(i, i) = g.position_sigma_ned_m[i] * g.position_sigma_ned_m[i] +
              g.position_gauss_markov_sigma_ned_m[i] * g.position_gauss_markov_sigma_ned_m[i];
  }
  if (m == 6) {
    const Vector3d w = omega_ib_b - gyro_bias_;
    const Vector3d v_lever = C * w.cross(l) - env_.EarthRate(s.llh.lat_rad).cross(l_n);
    z.tail<3>() = s.v_eb_n + v_lever - fix.v_eb_n;
    H.block<3, 3>(3, kErrVelocity) = Matrix3d::Identity();
    H.block<3, 3>(3, kErrAttitude) = -Skew(C * w.cross(l));
    H.block<3, 3>(3, kErrGyroBias) = -C * Skew(l);
    for (int i = 0; i < 3; ++i) {
      R(3 + i, 3 + i) = g.velocity_sigma_ned_m_per_s[i] * g.velocity_sigma_ned_m_per_s[i];
    }
  }
  ErrorStateMatrix& P = propagator_.mutable_P();
  ErrorStateVector x;
  if (m == 6) {
    const Eigen::Matrix<double, 6, 6> S = H * P * H.transpose() + R;
    const Eigen::LLT<Eigen::Matrix<double, 6, 6>> llt(S);
    const Eigen::Matrix<double, kNumErrorStates, 6> K =
        llt.solve(H * P.transpose()).transpose();  // P H^T S^-1 (P, S symmetric)
    x = K * z;
    last_nis_ = z.dot(llt.solve(z));
    const ErrorStateMatrix IKH = ErrorStateMatrix::Identity() - K * H;
    P = IKH * P * IKH.transpose() + K * R * K.transpose();
  } else {
    const Eigen::Matrix<double, 3, kNumErrorStates> H3 = H.topRows<3>();
    const Eigen::Matrix3d R3 = R.topLeftCorner<3, 3>();
    const Eigen::Vector3d z3 = z.head<3>();
    const Eigen::Matrix3d S = H3 * P * H3.transpose() + R3;
    const Eigen::LLT<Eigen::Matrix3d> llt(S);
    const Eigen::Matrix<double, kNumErrorStates, 3> K = llt.solve(H3 * P).transpose();
    x = K * z3;
    last_nis_ = z3.dot(llt.solve(z3));
    const ErrorStateMatrix IKH = ErrorStateMatrix::Identity() - K * H3;
    P = IKH * P * IKH.transpose() + K * R3 * K.transpose();
  }
  P = 0.5 * (P + P.transpose()).eval();
  last_dim_ = m;

  // Closed-loop correction (truth = estimate - error).
  NavState c = s;
  const double L = c.llh.lat_rad, h = c.llh.h_m;
  c.llh.lat_rad -= x[0] / (env_.MeridianRadiusAt(L) + h);
  c.llh.lon_rad -= x[1] / ((env_.TransverseRadiusAt(L) + h) * std::cos(L));
  c.llh.h_m += x[2];
  c.v_eb_n -= x.segment<3>(kErrVelocity);
  c.q_b_n = Quaterniond(RotationVectorToDcm(-x.segment<3>(kErrAttitude)) * C);
  c.q_b_n.normalize();
  accel_bias_ += x.segment<3>(kErrAccelBias);
  gyro_bias_ += x.segment<3>(kErrGyroBias);
  ins_ = NedMechanization(env_, c, dt_s_, options_.mechanization);
}

double Nees(const ErrorStateVector& error, const ErrorStateMatrix& P) {
  return error.dot(P.ldlt().solve(error));
}

void Chi2MeanBounds95(int dof, int n, double* low, double* high) {
  const double k = static_cast<double>(dof) * n;
  const double z = 1.959963984540054;  // standard normal 97.5 % quantile
  const double a = 2.0 / (9.0 * k);
  *low = k * std::pow(1.0 - a - z * std::sqrt(a), 3) / n;
  *high = k * std::pow(1.0 - a + z * std::sqrt(a), 3) / n;
}

}  // namespace driftlab
