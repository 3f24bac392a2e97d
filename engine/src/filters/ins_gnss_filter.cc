#include "driftlab/ins_gnss_filter.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>
#include <string>

#include "driftlab/attitude.h"
#include "driftlab/elementary.h"
#include "driftlab/spec_error.h"
#include "driftlab/trajectory.h"

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
      propagator_(env, options.imu_noise, P0, options.discretization) {
  const ErrorStateLayout& layout = propagator_.layout();
  const int m = layout.size - kNumNavErrorStates;
  sensor_estimate_ = Eigen::VectorXd::Zero(m);
  inverse_tau_ = Eigen::VectorXd::Zero(m);
  const ErrorStateNoise& noise = options_.imu_noise;
  auto set_tau = [&](int first, int count, double tau_s) {
    if (first < 0 || !(tau_s > 0.0)) return;
    inverse_tau_.segment(first - kNumNavErrorStates, count).setConstant(1.0 / tau_s);
  };
  set_tau(kErrAccelBias, 3, noise.accel_bias.tau_s);
  set_tau(kErrGyroBias, 3, noise.gyro_bias.tau_s);
  for (size_t i = 0; i < layout.accel_bias_extra.size(); ++i) {
    set_tau(layout.accel_bias_extra[i], 3, noise.accel_bias_extra[i].tau_s);
  }
  for (size_t i = 0; i < layout.gyro_bias_extra.size(); ++i) {
    set_tau(layout.gyro_bias_extra[i], 3, noise.gyro_bias_extra[i].tau_s);
  }
  set_tau(layout.gnss_position, 3, noise.gnss_position_gm_tau_s);
  set_tau(layout.barometer_bias, 1, noise.barometer_bias_tau_s);
}

void InsGnssFilter::RefreshCorrections() {
  const ErrorStateLayout& layout = propagator_.layout();
  auto est3 = [this](int first) -> Vector3d {
    return sensor_estimate_.segment<3>(first - kNumNavErrorStates);
  };
  accel_bias_ = est3(kErrAccelBias);
  gyro_bias_ = est3(kErrGyroBias);
  for (int first : layout.accel_bias_extra) accel_bias_ += est3(first);
  for (int first : layout.gyro_bias_extra) gyro_bias_ += est3(first);
  auto correction = [this](int scale, int mis) {
    Matrix3d S = Matrix3d::Zero();
    if (scale >= 0) {
      for (int i = 0; i < 3; ++i) S(i, i) = sensor_estimate_[scale - kNumNavErrorStates + i];
      for (int k = 0; k < 6; ++k) {
        S(kMisalignmentRow[k], kMisalignmentCol[k]) =
            sensor_estimate_[mis - kNumNavErrorStates + k];
      }
    }
    return Matrix3d(Matrix3d::Identity() - S);
  };
  gyro_correction_ = correction(layout.gyro_scale, layout.gyro_misalignment);
  accel_correction_ = correction(layout.accel_scale, layout.accel_misalignment);
}

void InsGnssFilter::Predict(const ImuIncrement& measured) {
  ImuIncrement corrected = measured;
  corrected.delta_v_ib_b = accel_correction_ * (measured.delta_v_ib_b - accel_bias_ * dt_s_);
  corrected.delta_theta_ib_b = gyro_correction_ * (measured.delta_theta_ib_b - gyro_bias_ * dt_s_);
  const Matrix3d C_before = ins_.state().C_b_n();
  ins_.Update(corrected);
  // Increment resolved with the interval's mean attitude (second order in the rotation).
  f_n_sum_ += 0.5 * (C_before + ins_.state().C_b_n()) * corrected.delta_v_ib_b;
  theta_sum_ += corrected.delta_theta_ib_b;
  if (++pending_ >= options_.propagation_step_samples) SyncCovariance();
}

void InsGnssFilter::SyncCovariance() {
  if (pending_ == 0) return;
  const double T = pending_ * dt_s_;
  const NavState& ref = ins_.state();
  const Vector3d f_b = ref.C_b_n().transpose() * (f_n_sum_ / T);
  propagator_.Propagate(ref, f_b, T, theta_sum_ / T);
  // Gauss-Markov estimates decay as their conditional mean.
  if (inverse_tau_.size() > 0 && inverse_tau_.any()) {
    sensor_estimate_.array() *=
        (-T * inverse_tau_.array()).unaryExpr([](double v) { return math::Exp(v); });
    RefreshCorrections();
  }
  f_n_sum_.setZero();
  theta_sum_.setZero();
  pending_ = 0;
}

GnssUpdateModel MakeGnssUpdateModel(const NavEnvironment& env, const GnssConfig& g,
                                    const NavState& s, const Vector3d& omega_ib_b,
                                    const ErrorStateLayout& layout) {
  GnssUpdateModel m;
  m.H = Eigen::Matrix<double, 6, Eigen::Dynamic>::Zero(6, layout.size);
  const Matrix3d C = s.C_b_n();
  const Vector3d& l = g.lever_arm_b_m;
  m.lever_n = C * l;
  m.dim = g.use_velocity ? 6 : 3;
  // Position rows: H_r = [I, 0, -[(C_b_n l_b) x], 0, 0] (Groves section 14.3.1, x = est - truth).
  m.H.block<3, 3>(0, kErrPosition) = Matrix3d::Identity();
  m.H.block<3, 3>(0, kErrAttitude) = -Skew(m.lever_n);
  const bool gm_state = layout.gnss_position >= 0;
  // The Gauss-Markov error state x_e = e - e^: z = est - (fix - e^) = dr - x_e - noise.
  if (gm_state) m.H.block<3, 3>(0, layout.gnss_position) = -Matrix3d::Identity();
  for (int i = 0; i < 3; ++i) {
    const double gm = gm_state ? 0.0 : g.position_gauss_markov_sigma_ned_m[i];
    m.R(i, i) = g.position_sigma_ned_m[i] * g.position_sigma_ned_m[i] + gm * gm;
  }
  if (m.dim == 6) {
    // The lever arm's velocity also depends on the gyro scale factor / misalignment (|l| sigma_s
    // omega, second order for lever arms of a metre): not modelled.
    const Vector3d w_x_l = C * omega_ib_b.cross(l);
    m.lever_velocity_n = w_x_l - env.EarthRate(s.llh.lat_rad).cross(m.lever_n);
    m.H.block<3, 3>(3, kErrVelocity) = Matrix3d::Identity();
    m.H.block<3, 3>(3, kErrAttitude) = -Skew(w_x_l);
    m.H.block<3, 3>(3, kErrGyroBias) = -C * Skew(l);
    for (int first : layout.gyro_bias_extra) m.H.block<3, 3>(3, first) = -C * Skew(l);
    for (int i = 0; i < 3; ++i) {
      m.R(3 + i, 3 + i) = g.velocity_sigma_ned_m_per_s[i] * g.velocity_sigma_ned_m_per_s[i];
    }
  }
  return m;
}

template <int M>
void InsGnssFilter::Correct(const Eigen::Matrix<double, M, Eigen::Dynamic>& H,
                            const Eigen::Matrix<double, M, M>& R,
                            const Eigen::Matrix<double, M, 1>& z) {
  Eigen::LLT<Eigen::Matrix<double, M, M>> llt;
  const Eigen::Matrix<double, Eigen::Dynamic, M> K =
      JosephUpdate<M>(H, R, &propagator_.mutable_P(), &llt);
  const ErrorStateVector x = K * z;
  last_nis_ = z.dot(llt.solve(z));
  last_dim_ = M;

  // Closed-loop correction (truth = estimate - error).
  NavState c = ins_.state();
  const Matrix3d C = c.C_b_n();
  const double L = c.llh.lat_rad, h = c.llh.h_m;
  c.llh.lat_rad -= x[0] / (env_.MeridianRadiusAt(L) + h);
  c.llh.lon_rad -= x[1] / ((env_.TransverseRadiusAt(L) + h) * math::Cos(L));
  c.llh.h_m += x[2];
  c.v_eb_n -= x.segment<3>(kErrVelocity);
  c.q_b_n = Quaterniond(RotationVectorToDcm(-x.segment<3>(kErrAttitude)) * C);
  c.q_b_n.normalize();
  // Sensor and aiding error states are truth minus estimate: the estimate takes x.
  sensor_estimate_ += x.tail(x.size() - kNumNavErrorStates);
  RefreshCorrections();
  ins_ = NedMechanization(env_, c, dt_s_, options_.mechanization);
}

void InsGnssFilter::Update(const GnssMeasurement& fix, const Vector3d& omega_ib_b) {
  SyncCovariance();
  const NavState& s = ins_.state();
  const ErrorStateLayout& layout = propagator_.layout();
  const GnssUpdateModel m = MakeGnssUpdateModel(
      env_, options_.gnss, s, gyro_correction_ * (omega_ib_b - gyro_bias_), layout);
  // Innovation: estimated antenna minus fix (position in metres NED at the fix), the fix
  // corrected by the estimated Gauss-Markov error.
  Eigen::Matrix<double, 6, 1> z;
  z.head<3>() = env_.PositionErrorNed(s.llh, fix.llh) + m.lever_n;
  if (layout.gnss_position >= 0) {
    z.head<3>() += sensor_estimate_.segment<3>(layout.gnss_position - kNumNavErrorStates);
  }
  if (m.dim == 6) {
    z.tail<3>() = s.v_eb_n + m.lever_velocity_n - fix.v_eb_n;
    Correct<6>(m.H, m.R, z);
  } else {
    const Eigen::Matrix<double, 3, Eigen::Dynamic> H3 = m.H.topRows<3>();
    const Eigen::Matrix3d R3 = m.R.topLeftCorner<3, 3>();
    const Eigen::Vector3d z3 = z.head<3>();
    Correct<3>(H3, R3, z3);
  }
}

void InsGnssFilter::UpdateHeight(double h_m, double sigma_m) {
  SyncCovariance();
  const ErrorStateLayout& layout = propagator_.layout();
  Eigen::Matrix<double, 1, Eigen::Dynamic> H =
      Eigen::Matrix<double, 1, Eigen::Dynamic>::Zero(1, layout.size);
  H(0, kErrPosition + 2) = 1.0;
  double bias_estimate_m = 0.0;
  if (layout.barometer_bias >= 0) {
    H(0, layout.barometer_bias) = 1.0;
    bias_estimate_m = sensor_estimate_[layout.barometer_bias - kNumNavErrorStates];
  }
  // z = (estimated down) - (measured down) = (h_baro - b^) - h^ = dr_D + x_b + noise.
  const Eigen::Matrix<double, 1, 1> z(h_m - bias_estimate_m - ins_.state().llh.h_m);
  const Eigen::Matrix<double, 1, 1> R(sigma_m * sigma_m);
  Correct<1>(H, R, z);
}

void InsGnssFilter::UpdateZeroVelocity(double sigma_m_per_s, const Vector3d& v_measured_n) {
  SyncCovariance();
  Eigen::Matrix<double, 3, Eigen::Dynamic> H =
      Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, propagator_.layout().size);
  H.block<3, 3>(0, kErrVelocity) = Matrix3d::Identity();
  const Eigen::Matrix3d R = Matrix3d::Identity() * (sigma_m_per_s * sigma_m_per_s);
  const Eigen::Vector3d z = ins_.state().v_eb_n - v_measured_n;
  Correct<3>(H, R, z);
}

std::vector<CovarianceEpoch> FilterCovarianceAnalysis(
    const MotionSpec& motion, double rate_hz, const ErrorStateNoise& noise,
    const ErrorStateMatrix& P0, const AidingSpec* aiding, const std::vector<int64_t>& zupt_epochs,
    const std::vector<int64_t>& epoch_samples, int64_t step_samples, Discretization method) {
  if (step_samples < 1 || step_samples > 10000) {
    throw SpecError("monte_carlo.covariance_step_samples", std::to_string(step_samples),
                    "[1, 10000]");
  }
  TrajectoryGenerator generator(motion, rate_hz);
  const NavEnvironment& env = generator.environment();
  const double dt = generator.dt_s();
  ErrorCovariancePropagator prop(env, noise, P0, method);
  const GnssConfig* gnss = aiding != nullptr && aiding->gnss ? &*aiding->gnss : nullptr;
  const BarometerConfig* baro =
      aiding != nullptr && aiding->barometer ? &*aiding->barometer : nullptr;
  const ZuptConfig* zupt = aiding != nullptr && aiding->zupt ? &*aiding->zupt : nullptr;
  const int64_t gnss_dec =
      gnss ? AidingDecimation(gnss->rate_hz, rate_hz, "aiding.gnss.rate_hz") : 0;
  const int64_t baro_dec =
      baro ? AidingDecimation(baro->rate_hz, rate_hz, "aiding.barometer.rate_hz") : 0;
  const ErrorStateLayout& layout = prop.layout();
  Eigen::Matrix<double, 1, Eigen::Dynamic> H_baro =
      Eigen::Matrix<double, 1, Eigen::Dynamic>::Zero(1, layout.size);
  H_baro(0, kErrPosition + 2) = 1.0;
  if (layout.barometer_bias >= 0) H_baro(0, layout.barometer_bias) = 1.0;
  Eigen::Matrix<double, 1, 1> R_baro = Eigen::Matrix<double, 1, 1>::Zero();
  if (baro) {
    // As the Monte-Carlo runs call UpdateHeight: the bias in R only when it is not a state.
    const double bias_sigma = layout.barometer_bias >= 0 ? 0.0 : baro->bias.sigma;
    R_baro(0, 0) = baro->noise_sigma_m * baro->noise_sigma_m + bias_sigma * bias_sigma;
  }
  Eigen::Matrix<double, 3, Eigen::Dynamic> H_zupt =
      Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, layout.size);
  H_zupt.block<3, 3>(0, kErrVelocity) = Matrix3d::Identity();
  const double zupt_var = zupt ? zupt->velocity_sigma_m_per_s * zupt->velocity_sigma_m_per_s : 0.0;
  const Eigen::Matrix3d R_zupt = Matrix3d::Identity() * zupt_var;
  auto in_outage = [gnss](double t_s) {
    for (const GnssOutage& o : gnss->outages) {
      if (t_s >= o.start_s && t_s < o.start_s + o.duration_s) return true;
    }
    return false;
  };

  std::vector<CovarianceEpoch> out;
  out.reserve(epoch_samples.size());
  size_t next_epoch = 0, next_zupt = 0;
  const NavState& truth0 = generator.initial_state();
  if (next_epoch < epoch_samples.size() && epoch_samples[next_epoch] == 0) {
    out.push_back(MakeCovarianceEpoch(truth0.t_s, prop.P(), truth0.euler()));
    ++next_epoch;
  }
  Matrix3d C_prev = truth0.C_b_n();
  Vector3d f_n_sum = Vector3d::Zero();
  Vector3d theta_sum = Vector3d::Zero();
  int64_t pending = 0;
  TrajectorySample sample;
  while (generator.Next(&sample)) {
    const int64_t k = generator.step();
    const NavState& truth = sample.truth;
    const Matrix3d C = truth.C_b_n();
    f_n_sum += 0.5 * (C_prev + C) * sample.increment.delta_v_ib_b;
    theta_sum += sample.increment.delta_theta_ib_b;
    C_prev = C;
    ++pending;
    const bool epoch = next_epoch < epoch_samples.size() && epoch_samples[next_epoch] == k;
    while (next_zupt < zupt_epochs.size() && zupt_epochs[next_zupt] < k) ++next_zupt;
    const bool gnss_now = gnss && k % gnss_dec == 0 && !in_outage(truth.t_s);
    const bool baro_now = baro && k % baro_dec == 0;
    const bool zupt_now = zupt && next_zupt < zupt_epochs.size() && zupt_epochs[next_zupt] == k;
    if (pending >= step_samples || epoch || gnss_now || baro_now || zupt_now) {
      // As InsGnssFilter::SyncCovariance: F at the state at the end of the interval with the
      // interval's mean specific force resolved in its body frame.
      const double T = static_cast<double>(pending) * dt;
      prop.Propagate(truth, C.transpose() * (f_n_sum / T), T, theta_sum / T);
      f_n_sum.setZero();
      theta_sum.setZero();
      pending = 0;
    }
    if (epoch) {
      out.push_back(MakeCovarianceEpoch(truth.t_s, prop.P(), truth.euler()));
      ++next_epoch;
    }
    if (gnss_now) {
      const Vector3d omega_ib_b = sample.increment.delta_theta_ib_b / dt;
      const GnssUpdateModel m = MakeGnssUpdateModel(env, *gnss, truth, omega_ib_b, layout);
      if (m.dim == 6) {
        JosephUpdate<6>(m.H, m.R, &prop.mutable_P());
      } else {
        const Eigen::Matrix<double, 3, Eigen::Dynamic> H3 = m.H.topRows<3>();
        const Eigen::Matrix3d R3 = m.R.topLeftCorner<3, 3>();
        JosephUpdate<3>(H3, R3, &prop.mutable_P());
      }
    }
    if (baro_now) JosephUpdate<1>(H_baro, R_baro, &prop.mutable_P());
    if (zupt_now) JosephUpdate<3>(H_zupt, R_zupt, &prop.mutable_P());
  }
  return out;
}

double Nees(const ErrorStateVector& error, const ErrorStateMatrix& P) {
  return error.dot(P.ldlt().solve(error));
}

void Chi2MeanBounds95(int dof, int n, double* low, double* high) {
  const double k = static_cast<double>(dof) * n;
  const double z = 1.959963984540054;  // standard normal 97.5 % quantile
  const double a = 2.0 / (9.0 * k);
  const double lo = 1.0 - a - z * std::sqrt(a), hi = 1.0 - a + z * std::sqrt(a);
  *low = k * (lo * lo * lo) / n;
  *high = k * (hi * hi * hi) / n;
}

}  // namespace driftlab
