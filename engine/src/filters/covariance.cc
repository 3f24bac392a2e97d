#include "driftlab/covariance.h"

#include <cmath>
#include <string>
#include <vector>

#include "driftlab/elementary.h"
#include "driftlab/spec_error.h"

namespace driftlab {

ErrorCovariancePropagator::ErrorCovariancePropagator(const NavEnvironment& env,
                                                     const ErrorStateNoise& noise,
                                                     const ErrorStateMatrix& P0,
                                                     Discretization method)
    : env_(env),
      noise_(noise),
      layout_(noise),
      Q_c_(ErrorStateProcessNoise(noise)),
      method_(method),
      P_(P0) {
  if (P0.rows() != layout_.size || P0.cols() != layout_.size) {
    throw SpecError("covariance.P0", std::to_string(P0.rows()) + " x " + std::to_string(P0.cols()),
                    std::to_string(layout_.size) + " x " + std::to_string(layout_.size) +
                        " (the error state of the noise model)");
  }
  const int m = layout_.size - kNumNavErrorStates;
  q_s_ = Q_c_.diagonal().tail(m);
}

void ErrorCovariancePropagator::Propagate(const NavState& reference, const Vector3d& f_ib_b,
                                          double dt_s, const Vector3d& omega_ib_b) {
  const ErrorStateMatrix F = ErrorStateSystemMatrix(env_, reference, f_ib_b, noise_, omega_ib_b);
  if (method_ == Discretization::kVanLoan) {
    if (PropagateExactSeries(F, dt_s)) {
      PropagateSourcesSeries(dt_s);
      return;
    }
    ErrorStateMatrix Phi, Q_d;
    DiscretizeErrorModel(F, Q_c_, dt_s, method_, &Phi, &Q_d);
    P_ = (Phi * P_ * Phi.transpose()).eval() + Q_d;
    P_ = 0.5 * (P_ + P_.transpose()).eval();
    PropagateSourcesDense(F, dt_s);
    return;
  }
  // Structured second-order step (see the header): nav block n = 9, sensor block m.
  constexpr int n = kNumNavErrorStates;
  const int m = layout_.size - n;
  const auto F_nn = F.topLeftCorner(n, n);
  const auto F_ns = F.topRightCorner(n, m);
  const Eigen::VectorXd D = F.bottomRightCorner(m, m).diagonal();
  const Eigen::Matrix<double, n, n> Fnn_dt = F_nn * dt_s;
  A_ = Eigen::Matrix<double, n, n>::Identity() + Fnn_dt + 0.5 * Fnn_dt * Fnn_dt;
  B_ = F_ns * dt_s + 0.5 * dt_s * dt_s * (F_nn * F_ns + F_ns * D.asDiagonal());
  d_ = (Eigen::VectorXd::Ones(m) + D * dt_s + 0.5 * (D * dt_s).cwiseAbs2());
  const Eigen::Matrix<double, n, 1> q_n = Q_c_.diagonal().head(n);
  // Q_d = dt / 2 (Phi Q_c Phi^T + Q_c), Q_c = diag(q_n, q_s).
  const Eigen::MatrixXd BQ = B_ * q_s_.asDiagonal();  // n x m
  const Eigen::MatrixXd Qd_nn = 0.5 * dt_s *
                                (A_ * q_n.asDiagonal() * A_.transpose() + BQ * B_.transpose() +
                                 Eigen::Matrix<double, n, n>(q_n.asDiagonal()));
  const Eigen::MatrixXd Qd_ns = 0.5 * dt_s * BQ * d_.asDiagonal();
  const Eigen::VectorXd Qd_ss = 0.5 * dt_s * (d_.cwiseAbs2().cwiseProduct(q_s_) + q_s_);
  ApplyStructuredStep(Qd_nn, Qd_ns, Qd_ss, &P_);
  PropagateSourcesSecondOrder(dt_s);
}

void ErrorCovariancePropagator::SetSources(std::vector<ErrorStateMatrix> P0,
                                           std::vector<Eigen::VectorXd> q_c) {
  if (P0.size() != q_c.size()) {
    throw SpecError(
        "covariance.sources",
        std::to_string(P0.size()) + " P0, " + std::to_string(q_c.size()) + " Q_c shares",
        "one share of each per source");
  }
  source_support_.clear();
  for (size_t s = 0; s < P0.size(); ++s) {
    if (P0[s].rows() != layout_.size || P0[s].cols() != layout_.size ||
        q_c[s].size() != layout_.size) {
      throw SpecError("covariance.sources", "source " + std::to_string(s) + " of the wrong size",
                      std::to_string(layout_.size) + " states");
    }
    std::vector<int> support;
    for (int i = 0; i < layout_.size; ++i) {
      if (q_c[s][i] != 0.0) support.push_back(i);
    }
    source_support_.push_back(std::move(support));
  }
  source_P_ = std::move(P0);
  source_q_ = std::move(q_c);
}

void ErrorCovariancePropagator::PropagateSourcesSecondOrder(double dt_s) {
  // Q_d,s = dt / 2 (Phi Q_c,s Phi^T + Q_c,s) in blocks (Propagate), summed over the states j where
  // the share q_j of source s is nonzero: Phi Q_c,s Phi^T = sum_j q_j Phi_(:,j) Phi_(:,j)^T.
  constexpr int n = kNumNavErrorStates;
  const int m = layout_.size - n;
  Eigen::MatrixXd Qd_nn(n, n), Qd_ns(n, m);
  Eigen::VectorXd Qd_ss(m);
  for (size_t s = 0; s < source_P_.size(); ++s) {
    Qd_nn.setZero();
    Qd_ns.setZero();
    Qd_ss.setZero();
    for (const int j : source_support_[s]) {
      const double w = 0.5 * dt_s * source_q_[s][j];
      if (j < n) {
        Qd_nn.noalias() += w * A_.col(j) * A_.col(j).transpose();
        Qd_nn(j, j) += w;
      } else {
        const int c = j - n;
        Qd_nn.noalias() += w * B_.col(c) * B_.col(c).transpose();
        Qd_ns.col(c) += w * d_(c) * B_.col(c);
        Qd_ss(c) += w * (d_(c) * d_(c) + 1.0);
      }
    }
    ApplyStructuredStep(Qd_nn, Qd_ns, Qd_ss, &source_P_[s]);
  }
}

void ErrorCovariancePropagator::PropagateSourcesSeries(double h) {
  // Q_d,s of the exact step (PropagateExactSeries) for the share q of source s, per state j with
  // q_j != 0: nn += h q_j sum_i N_i(:,j) N_sum_i(:,j)^T (j < 9), or for a sensor state c = j - 9
  // nn += h q_j sum_i U_i(:,c) U_sum_i(:,c)^T, ns(:,c) = h q_j sum_i U_i(:,c) G_i(c),
  // ss(c) = q_j h expm1(2 D_c h) / (2 D_c h).
  constexpr int n = kNumNavErrorStates;
  const int m = layout_.size - n;
  const int K = static_cast<int>(series_N_.size());
  Eigen::MatrixXd Qd_nn(n, n), Qd_ns(n, m);
  Eigen::VectorXd Qd_ss(m);
  for (size_t s = 0; s < source_P_.size(); ++s) {
    Qd_nn.setZero();
    Qd_ns.setZero();
    Qd_ss.setZero();
    for (const int j : source_support_[s]) {
      const double w = h * source_q_[s][j];
      if (j < n) {
        for (int i = 0; i < K; ++i) {
          Qd_nn.noalias() += w * series_N_[i].col(j) * series_Nsum_[i].col(j).transpose();
        }
      } else {
        const int c = j - n;
        for (int i = 1; i < K; ++i) {
          Qd_nn.noalias() += w * series_U_[i].col(c) * series_Usum_[i].col(c).transpose();
          Qd_ns.col(c) += w * series_G_[i](c) * series_U_[i].col(c);
        }
        const double x = 2.0 * series_Dh_(c);
        Qd_ss(c) = w * (x == 0.0 ? 1.0 : math::Expm1(x) / x);
      }
    }
    ApplyStructuredStep(Qd_nn, Qd_ns, Qd_ss, &source_P_[s]);
  }
}

void ErrorCovariancePropagator::PropagateSourcesDense(const ErrorStateMatrix& F, double dt_s) {
  for (size_t s = 0; s < source_P_.size(); ++s) {
    ErrorStateMatrix Phi, Q_d;
    DiscretizeErrorModel(F, ErrorStateMatrix(source_q_[s].asDiagonal()), dt_s, method_, &Phi, &Q_d);
    ErrorStateMatrix& P = source_P_[s];
    P = (Phi * P * Phi.transpose()).eval() + Q_d;
    P = 0.5 * (P + P.transpose()).eval();
  }
}

void ErrorCovariancePropagator::ApplyStructuredStep(const Eigen::MatrixXd& Qd_nn,
                                                    const Eigen::MatrixXd& Qd_ns,
                                                    const Eigen::VectorXd& Qd_ss,
                                                    ErrorStateMatrix* P) {
  ErrorStateMatrix& P_ = *P;
  // P <- Phi P Phi^T + Q_d with Phi = [[A, B], [0, diag(d)]] and P = [[P_nn, P_ns], [P_ns^T,
  // P_ss]].
  constexpr int n = kNumNavErrorStates;
  const int m = layout_.size - n;
  const auto P_nn = P_.topLeftCorner(n, n);
  const auto P_ns = P_.topRightCorner(n, m);
  const auto P_ss = P_.bottomRightCorner(m, m);
  BPss_ = B_ * P_ss;         // n x m
  Pns_ = A_ * P_ns + BPss_;  // (Phi P)_ns before the diag(d) on the right
  Pnn_ = A_ * P_nn * A_.transpose() + A_ * P_ns * B_.transpose() +
         (A_ * P_ns * B_.transpose()).transpose() + BPss_ * B_.transpose();
  P_.topLeftCorner(n, n) = Pnn_ + Qd_nn;
  P_.topRightCorner(n, m) = Pns_ * d_.asDiagonal();
  P_.topRightCorner(n, m) += Qd_ns;
  P_.bottomRightCorner(m, m) = d_.asDiagonal() * P_ss * d_.asDiagonal();
  P_.bottomRightCorner(m, m).diagonal() += Qd_ss;
  P_.bottomLeftCorner(m, n) = P_.topRightCorner(n, m).transpose();
  P_.topLeftCorner(n, n) =
      0.5 * (P_.topLeftCorner(n, n) + P_.topLeftCorner(n, n).transpose()).eval();
}

bool ErrorCovariancePropagator::PropagateExactSeries(const ErrorStateMatrix& F, double h) {
  // Van Loan's exact Phi = exp(F h) and Q_d = int_0^h Phi(s) Q_c Phi(s)^T ds for the structured
  // model F = [[F_nn, F_ns], [0, D]] (header), by the power series instead of the exponential of
  // the 2N x 2N matrix: with T_k = (F h)^k / k! = [[N_k, U_k], [0, diag(E_k)]],
  //   N_k = (F_nn h) N_(k-1) / k,  E_k = (D h)^k / k!,
  //   U_k = ((F_nn h) U_(k-1) + (F_ns h) diag(E_(k-1))) / k,  U_0 = 0,
  // Phi = sum_k T_k (Phi_ss = exp(D h) exactly), and, since Phi(s) = sum_k T_k (s/h)^k,
  //   Q_d = h sum_(i,j) T_i Q_c T_j^T / (i + j + 1),
  // whose sensor block is diag(q_s (exp(2 D h) - 1) / (2 D)) in closed form. The series is summed
  // until a term adds less than 1e-17 of the sum (at most 40 terms); for ||F_nn h||_1 > 2 or
  // |D h| > 2 (long steps) the dense exponential is used instead.
  constexpr int n = kNumNavErrorStates;
  const int m = layout_.size - n;
  if (m <= 0 || !F.bottomLeftCorner(m, n).isZero(0.0)) return false;
  const Eigen::VectorXd D = F.bottomRightCorner(m, m).diagonal();
  for (int j = 0; j < m; ++j) {
    for (int i = 0; i < m; ++i) {
      if (i != j && F(n + i, n + j) != 0.0) return false;
    }
  }
  const Eigen::Matrix<double, n, n> Ah = F.topLeftCorner(n, n) * h;
  const Eigen::MatrixXd Bh = F.topRightCorner(n, m) * h;
  const Eigen::VectorXd Dh = D * h;
  if (Ah.cwiseAbs().colwise().sum().maxCoeff() > 2.0 || Dh.cwiseAbs().maxCoeff() > 2.0) {
    return false;
  }
  constexpr int kMaxTerms = 40;
  std::vector<Eigen::Matrix<double, n, n>> N{Eigen::Matrix<double, n, n>::Identity()};
  std::vector<Eigen::MatrixXd> U{Eigen::MatrixXd::Zero(n, m)};
  std::vector<Eigen::VectorXd> E{Eigen::VectorXd::Ones(m)};
  A_ = N[0];
  B_ = U[0];
  for (int k = 1; k < kMaxTerms; ++k) {
    N.push_back(Ah * N[k - 1] / k);
    U.push_back((Ah * U[k - 1] + Bh * E[k - 1].asDiagonal()) / k);
    E.push_back(E[k - 1].cwiseProduct(Dh) / k);
    A_ += N[k];
    B_ += U[k];
    const double added =
        N[k].cwiseAbs().maxCoeff() + U[k].cwiseAbs().maxCoeff() + E[k].cwiseAbs().maxCoeff();
    const double total = A_.cwiseAbs().maxCoeff() + B_.cwiseAbs().maxCoeff() + 1.0;
    if (added < 1e-17 * total) break;
  }
  const int K = static_cast<int>(N.size());
  d_ = Dh.unaryExpr([](double v) { return math::Exp(v); });  // the engine's exp (elementary.h)
  const Eigen::Matrix<double, n, 1> q_n = Q_c_.diagonal().head(n);
  // Q_d blocks: nn = h sum_(i,j) (N_i Q_n N_j^T + U_i Q_s U_j^T) / (i + j + 1);
  // ns = h sum_i U_i diag(q_s G_i), G_i = sum_j E_j / (i + j + 1) = int_0^1 s^i exp(D h s) ds.
  Eigen::MatrixXd Qd_nn = Eigen::MatrixXd::Zero(n, n);
  Eigen::MatrixXd Qd_ns = Eigen::MatrixXd::Zero(n, m);
  if (!source_P_.empty()) {
    series_N_ = N;
    series_U_ = U;
    series_Dh_ = Dh;
    series_Nsum_.resize(K);
    series_Usum_.resize(K);
    series_G_.resize(K);
  }
  for (int i = 0; i < K; ++i) {
    Eigen::Matrix<double, n, n> N_sum = Eigen::Matrix<double, n, n>::Zero();
    Eigen::MatrixXd U_sum = Eigen::MatrixXd::Zero(n, m);
    Eigen::VectorXd G = Eigen::VectorXd::Zero(m);
    for (int j = 0; j < K; ++j) {
      const double w = 1.0 / (i + j + 1);
      N_sum += w * N[j];
      if (j > 0) U_sum += w * U[j];
      G += w * E[j];
    }
    Qd_nn += N[i] * q_n.asDiagonal() * N_sum.transpose();
    if (!source_P_.empty()) {
      series_Nsum_[i] = N_sum;
      series_Usum_[i] = U_sum;
      series_G_[i] = G;
    }
    if (i > 0) {
      Qd_nn += U[i] * q_s_.asDiagonal() * U_sum.transpose();
      Qd_ns += U[i] * q_s_.cwiseProduct(G).asDiagonal();
    }
  }
  Qd_nn = (h * Qd_nn).eval();
  Qd_ns = (h * Qd_ns).eval();
  Eigen::VectorXd Qd_ss(m);
  for (int j = 0; j < m; ++j) {
    // int_0^h exp(2 d s) ds = h expm1(2 d h) / (2 d h), -> h as d h -> 0.
    const double x = 2.0 * Dh(j);
    Qd_ss(j) = q_s_(j) * h * (x == 0.0 ? 1.0 : math::Expm1(x) / x);
  }
  ApplyStructuredStep(Qd_nn, Qd_ns, Qd_ss, &P_);
  return true;
}

CovarianceEpoch MakeCovarianceEpoch(double t_s, const ErrorStateMatrix& P,
                                    const EulerAngles& attitude) {
  CovarianceEpoch e;
  e.t_s = t_s;
  e.P = P;
  e.sigma = P.diagonal().cwiseMax(0.0).cwiseSqrt();
  const Matrix3d T = EulerErrorFromAttitudeError(attitude);
  const Matrix3d P_euler = T * P.block<3, 3>(kErrAttitude, kErrAttitude) * T.transpose();
  e.euler_sigma_rad = P_euler.diagonal().cwiseMax(0.0).cwiseSqrt();
  e.horizontal_sigma_m = std::sqrt(std::max(0.0, P(0, 0) + P(1, 1)));
  return e;
}

std::vector<CovarianceEpoch> FreeInertialCovariance(const Trajectory& trajectory,
                                                    const ErrorStateNoise& noise,
                                                    const ErrorStateMatrix& P0,
                                                    const CovarianceAnalysisOptions& options) {
  if (options.step_samples < 1) {
    throw SpecError("covariance.step_samples", std::to_string(options.step_samples), ">= 1");
  }
  if (options.epoch_every_samples < 1 || options.epoch_every_samples % options.step_samples != 0) {
    throw SpecError("covariance.epoch_every_samples", std::to_string(options.epoch_every_samples),
                    "a positive multiple of covariance.step_samples (" +
                        std::to_string(options.step_samples) + ")");
  }
  const auto& truth = trajectory.truth;
  const auto& inc = trajectory.increments;
  const int64_t n = static_cast<int64_t>(inc.size());
  ErrorCovariancePropagator prop(trajectory.environment, noise, P0, options.discretization);
  std::vector<CovarianceEpoch> out;
  out.push_back(MakeCovarianceEpoch(truth[0].t_s, P0, truth[0].euler()));
  int64_t k = 0;
  while (k < n) {
    const int64_t s = std::min(options.step_samples, n - k);
    // Mean specific force over (t_k, t_{k+s}] resolved in n, then in the midpoint body frame.
    Vector3d f_n = Vector3d::Zero();
    for (int64_t i = 0; i < s; ++i) {
      // Increment i covers (t_{k+i}, t_{k+i+1}]; its attitude at the interval midpoint is taken
      // as the mean of the two ends' DCMs (second order in the rotation over one sample).
      const Matrix3d C = 0.5 * (truth[k + i].C_b_n() + truth[k + i + 1].C_b_n());
      f_n += C * inc[k + i].delta_v_ib_b;
    }
    f_n /= s * trajectory.dt_s;
    // Midpoint reference: the truth sample at k + s/2 (exact midpoint for even s).
    const NavState& mid = truth[k + s / 2];
    Vector3d omega_b = Vector3d::Zero();
    for (int64_t i = 0; i < s; ++i) omega_b += inc[k + i].delta_theta_ib_b;
    omega_b /= s * trajectory.dt_s;
    prop.Propagate(mid, mid.C_b_n().transpose() * f_n, s * trajectory.dt_s, omega_b);
    k += s;
    if (k % options.epoch_every_samples == 0 || k == n) {
      out.push_back(MakeCovarianceEpoch(truth[k].t_s, prop.P(), truth[k].euler()));
    }
  }
  return out;
}

}  // namespace driftlab
