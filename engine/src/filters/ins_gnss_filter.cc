#include "driftlab/ins_gnss_filter.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>
#include <string>

#include "driftlab/attitude.h"
#include "driftlab/elementary.h"
#include "driftlab/error_budget.h"
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
  for (size_t b = 0; b < noise.aiding_states.size(); ++b) {
    set_tau(layout.aiding[b], static_cast<int>(noise.aiding_states[b].sigma.size()),
            noise.aiding_states[b].tau_s);
  }
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

void InsGnssFilter::Correct(const AidingUpdate& u) {
  switch (u.dim) {
    case 1:
      Correct<1>(u.H.topRows<1>(), u.R.topLeftCorner<1, 1>(), u.z.head<1>());
      return;
    case 2:
      Correct<2>(u.H.topRows<2>(), u.R.topLeftCorner<2, 2>(), u.z.head<2>());
      return;
    case 3:
      Correct<3>(u.H.topRows<3>(), u.R.topLeftCorner<3, 3>(), u.z.head<3>());
      return;
    case 6:
      Correct<6>(u.H, u.R, u.z);
      return;
    default:
      throw SpecError("aiding", std::to_string(u.dim) + " measurement rows", "1, 2, 3 or 6");
  }
}

AidingEstimate InsGnssFilter::Estimate(const Vector3d& omega_ib_b, int first_state) const {
  AidingEstimate e;
  e.env = &env_;
  e.state = &ins_.state();
  e.omega_ib_b = gyro_correction_ * (omega_ib_b - gyro_bias_);
  e.layout = &propagator_.layout();
  e.first_state = first_state;
  if (first_state >= 0) e.own_states = sensor_estimate_.data() + (first_state - kNumNavErrorStates);
  return e;
}

void InsGnssFilter::Update(const AidingRun& aid, const Vector3d& omega_ib_b, int first_state) {
  SyncCovariance();
  AidingUpdate u;
  aid.Innovation(Estimate(omega_ib_b, first_state), &u);
  Correct(u);
}

void InsGnssFilter::Update(const GnssMeasurement& fix, const Vector3d& omega_ib_b) {
  SyncCovariance();
  const ErrorStateLayout& layout = propagator_.layout();
  int first_state = -1;
  for (size_t b = 0; b < options_.imu_noise.aiding_states.size(); ++b) {
    if (options_.imu_noise.aiding_states[b].owner == "aiding.gnss") first_state = layout.aiding[b];
  }
  AidingUpdate u;
  GnssUpdate(options_.gnss, Estimate(omega_ib_b, first_state), &fix, &u);
  Correct(u);
}

std::vector<CovarianceEpoch> FilterCovarianceAnalysis(const MotionSpec& motion, double rate_hz,
                                                      const ErrorStateNoise& noise,
                                                      const ErrorStateMatrix& P0,
                                                      const AidingSchedule* schedule,
                                                      const std::vector<int64_t>& epoch_samples,
                                                      int64_t step_samples, Discretization method,
                                                      ErrorBudgetRecord* budget) {
  if (step_samples < 1 || step_samples > 10000) {
    throw SpecError("monte_carlo.covariance_step_samples", std::to_string(step_samples),
                    "[1, 10000]");
  }
  TrajectoryGenerator generator(motion, rate_hz);
  const NavEnvironment& env = generator.environment();
  const double dt = generator.dt_s();
  ErrorCovariancePropagator prop(env, noise, P0, method);
  const ErrorStateLayout& layout = prop.layout();
  // The budget's sources: their P0 and Q_c shares, and per aid the rows of R each owns.
  std::vector<std::vector<uint32_t>> source_rows;  // [aid][source]
  if (budget != nullptr) {
    std::vector<ErrorStateMatrix> source_P0;
    std::vector<Eigen::VectorXd> source_q;
    for (const ErrorSource& s : budget->sources) {
      source_P0.push_back(s.P0);
      source_q.push_back(s.q_c);
    }
    prop.SetSources(std::move(source_P0), std::move(source_q));
    budget->variances.clear();
    if (schedule != nullptr) {
      for (const auto& sensor : schedule->sensors()) {
        std::vector<uint32_t> rows;
        for (const ErrorSource& s : budget->sources) {
          uint32_t mask = 0;
          for (int r = 0; s.aid == sensor->path() && r < AidingUpdate::kMaxDim; ++r) {
            if (sensor->NoiseTerm(r) == s.aid_term) mask |= 1u << r;
          }
          rows.push_back(mask);
        }
        source_rows.push_back(std::move(rows));
      }
    }
  }
  std::vector<CovarianceEpoch> out;
  out.reserve(epoch_samples.size());
  auto record = [&](const NavState& truth) {
    out.push_back(MakeCovarianceEpoch(truth.t_s, prop.P(), truth.euler()));
    if (budget == nullptr) return;
    std::vector<ComponentVariances> v;
    v.reserve(prop.source_P().size());
    for (const ErrorStateMatrix& P_s : prop.source_P()) {
      v.push_back(ComponentVariancesOf(P_s, truth.euler()));
    }
    budget->variances.push_back(std::move(v));
  };
  std::vector<int> first_state;
  if (schedule != nullptr) {
    for (const auto& sensor : schedule->sensors()) {
      first_state.push_back(layout.AidingFirst(noise, sensor->path()));
    }
  }

  size_t next_epoch = 0;
  const NavState& truth0 = generator.initial_state();
  if (next_epoch < epoch_samples.size() && epoch_samples[next_epoch] == 0) {
    record(truth0);
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
    const uint32_t due = schedule != nullptr ? schedule->Due(k, truth.t_s) : 0;
    if (pending >= step_samples || epoch || due != 0) {
      // As InsGnssFilter::SyncCovariance: F at the state at the end of the interval with the
      // interval's mean specific force resolved in its body frame.
      const double T = static_cast<double>(pending) * dt;
      prop.Propagate(truth, C.transpose() * (f_n_sum / T), T, theta_sum / T);
      f_n_sum.setZero();
      theta_sum.setZero();
      pending = 0;
    }
    if (epoch) {
      record(truth);
      ++next_epoch;
    }
    for (size_t i = 0; due != 0 && i < first_state.size(); ++i) {
      if ((due >> i & 1u) == 0) continue;
      AidingEstimate e;
      e.env = &env;
      e.state = &truth;
      e.omega_ib_b = sample.increment.delta_theta_ib_b / dt;
      e.layout = &layout;
      e.first_state = first_state[i];
      AidingUpdate u;
      schedule->sensors()[i]->Model(e, &u);
      Eigen::MatrixXd K;
      switch (u.dim) {
        case 1:
          K = JosephUpdate<1>(u.H.topRows<1>(), u.R.topLeftCorner<1, 1>(), &prop.mutable_P());
          break;
        case 2:
          K = JosephUpdate<2>(u.H.topRows<2>(), u.R.topLeftCorner<2, 2>(), &prop.mutable_P());
          break;
        case 3:
          K = JosephUpdate<3>(u.H.topRows<3>(), u.R.topLeftCorner<3, 3>(), &prop.mutable_P());
          break;
        case 6:
          K = JosephUpdate<6>(u.H, u.R, &prop.mutable_P());
          break;
        default:
          throw SpecError(schedule->sensors()[i]->path(), std::to_string(u.dim) + " rows",
                          "1, 2, 3 or 6 measurement rows");
      }
      if (budget != nullptr) {
        // The sources' updates with the full filter's gain K (computed before P was updated).
        const Eigen::MatrixXd H = u.H.topRows(u.dim);
        const Eigen::MatrixXd R = u.R.topLeftCorner(u.dim, u.dim);
        for (size_t s = 0; s < prop.source_P().size(); ++s) {
          SourceJosephUpdate(H, R, K, source_rows[i][s], &prop.mutable_source_P()[s]);
        }
      }
    }
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
