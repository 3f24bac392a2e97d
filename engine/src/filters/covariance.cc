#include "driftlab/covariance.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "driftlab/elementary.h"
#include "driftlab/spec_error.h"

namespace driftlab {

namespace {

// Coefficients of the scalar series of the exact step (PropagateExactSeries), in powers x^n of
// x = D h for n < kSeriesDegree, for the powers k < kSeriesPowers of F_nn h:
//   phi[k][n]     = 1 / (n + k + 1)!
//   rho[k][n]     = sum_(l=0..n) 1 / ((l + k + 1)! (n - l)!) / (k + n + 2)
//   beta[i][j][n] = sum_(l=0..n) 1 / ((l + i + 1)! (n - l + j + 1)!) / (i + j + n + 3)
// (beta is symmetric in i, j). Computed once.
constexpr int kSeriesPowers = 32;
constexpr int kSeriesDegree = 40;
struct SeriesCoefficients {
  std::vector<double> phi, rho, beta;
  SeriesCoefficients()
      : phi(kSeriesPowers * kSeriesDegree),
        rho(kSeriesPowers * kSeriesDegree),
        beta(kSeriesPowers * kSeriesPowers * kSeriesDegree) {
    std::vector<double> inv_fact(2 * (kSeriesPowers + kSeriesDegree) + 4, 1.0);
    for (size_t k = 1; k < inv_fact.size(); ++k) inv_fact[k] = inv_fact[k - 1] / k;
    for (int k = 0; k < kSeriesPowers; ++k) {
      for (int n = 0; n < kSeriesDegree; ++n) {
        phi[k * kSeriesDegree + n] = inv_fact[n + k + 1];
        double r = 0.0;
        for (int l = 0; l <= n; ++l) r += inv_fact[l + k + 1] * inv_fact[n - l];
        rho[k * kSeriesDegree + n] = r / (k + n + 2);
      }
    }
    for (int i = 0; i < kSeriesPowers; ++i) {
      for (int j = 0; j < kSeriesPowers; ++j) {
        for (int n = 0; n < kSeriesDegree; ++n) {
          double b = 0.0;
          for (int l = 0; l <= n; ++l) b += inv_fact[l + i + 1] * inv_fact[n - l + j + 1];
          beta[(i * kSeriesPowers + j) * kSeriesDegree + n] = b / (i + j + n + 3);
        }
      }
    }
  }
};

const SeriesCoefficients& Coefficients() {
  static const SeriesCoefficients c;
  return c;
}

// sum_(n < degree) c[n] x^n (Horner).
double Polynomial(const double* c, int degree, double x) {
  double v = c[degree - 1];
  for (int n = degree - 2; n >= 0; --n) v = v * x + c[n];
  return v;
}

// The channel of a coupled sensor state: 0..2 the accelerometer axes (velocity rows), 3..5 the
// gyro axes (attitude rows), the columns of G = [[0, 0], [C_b_n, 0], [0, C_b_n]].
int Channel(const SensorStateCoupling& c) { return (c.nav_rows == kErrVelocity ? 0 : 3) + c.axis; }

}  // namespace

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
  q_c_ = Q_c_.diagonal();
  q_s_ = q_c_.tail(m);
  for (int i = 0; i < layout_.size; ++i) {
    if (q_c_[i] != 0.0) q_support_.push_back(i);
  }
}

void ErrorCovariancePropagator::Propagate(const NavState& reference, const Vector3d& f_ib_b,
                                          double dt_s, const Vector3d& omega_ib_b) {
  const ErrorStateMatrix F = ErrorStateSystemMatrix(env_, reference, f_ib_b, noise_, omega_ib_b);
  if (method_ == Discretization::kVanLoan) {
    ErrorStateSensorCoupling(layout_, f_ib_b, omega_ib_b, &coupling_);
    if (PropagateExactSeries(F, reference.C_b_n(), dt_s)) {
      step_ = Step::kSeries;
      ProcessNoise(q_c_, q_support_, dt_s, &Qd_nn_, &Qd_ns_, &Qd_ss_);
      ApplyStructuredStep(Qd_nn_, Qd_ns_, Qd_ss_, &P_);
      PropagateSources(dt_s);
      return;
    }
    step_ = Step::kDense;
    ErrorStateMatrix Phi, Q_d;
    DiscretizeErrorModel(F, Q_c_, dt_s, method_, &Phi, &Q_d);
    P_ = (Phi * P_ * Phi.transpose()).eval() + Q_d;
    P_ = 0.5 * (P_ + P_.transpose()).eval();
    PropagateSourcesDense(F, dt_s);
    return;
  }
  // Structured second-order step (see the header): nav block n = 9, sensor block m.
  step_ = Step::kSecondOrder;
  constexpr int n = kNumNavErrorStates;
  const int m = layout_.size - n;
  const auto F_nn = F.topLeftCorner(n, n);
  const auto F_ns = F.topRightCorner(n, m);
  const Eigen::VectorXd D = F.bottomRightCorner(m, m).diagonal();
  const Eigen::Matrix<double, n, n> Fnn_dt = F_nn * dt_s;
  A_ = Eigen::Matrix<double, n, n>::Identity() + Fnn_dt + 0.5 * Fnn_dt * Fnn_dt;
  B_ = F_ns * dt_s + 0.5 * dt_s * dt_s * (F_nn * F_ns + F_ns * D.asDiagonal());
  d_ = (Eigen::VectorXd::Ones(m) + D * dt_s + 0.5 * (D * dt_s).cwiseAbs2());
  // Q_d = dt / 2 (Phi Q_c Phi^T + Q_c), Q_c = diag(q_n, q_s), as dense block products: the
  // arithmetic of the Monte-Carlo runs' filter (InsGnssFilter), whose results are reproducible bit
  // for bit; ProcessNoise sums the same terms state by state for the budget's sources.
  const Eigen::Matrix<double, n, 1> q_n = Q_c_.diagonal().head(n);
  const Eigen::MatrixXd BQ = B_ * q_s_.asDiagonal();  // n x m
  const Eigen::MatrixXd Qd_nn = 0.5 * dt_s *
                                (A_ * q_n.asDiagonal() * A_.transpose() + BQ * B_.transpose() +
                                 Eigen::Matrix<double, n, n>(q_n.asDiagonal()));
  const Eigen::MatrixXd Qd_ns = 0.5 * dt_s * BQ * d_.asDiagonal();
  const Eigen::VectorXd Qd_ss = 0.5 * dt_s * (d_.cwiseAbs2().cwiseProduct(q_s_) + q_s_);
  ApplyStructuredStep(Qd_nn, Qd_ns, Qd_ss, &P_);
  PropagateSources(dt_s);
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

void ErrorCovariancePropagator::ProcessNoise(const Eigen::VectorXd& q,
                                             const std::vector<int>& support, double dt_s,
                                             Eigen::MatrixXd* Qd_nn, Eigen::MatrixXd* Qd_ns,
                                             Eigen::VectorXd* Qd_ss) {
  constexpr int n = kNumNavErrorStates;
  const int m = layout_.size - n;
  Qd_nn->setZero(n, n);
  Qd_ns->setZero(n, m);
  Qd_ss->setZero(m);
  if (step_ == Step::kSecondOrder) {
    // Q_d = dt / 2 (Phi Q_c Phi^T + Q_c) in blocks (Propagate), summed over the states j where
    // q_j is nonzero: Phi Q_c Phi^T = sum_j q_j Phi_(:,j) Phi_(:,j)^T.
    for (const int j : support) {
      const double w = 0.5 * dt_s * q[j];
      if (j < n) {
        Qd_nn->noalias() += w * A_.col(j) * A_.col(j).transpose();
        (*Qd_nn)(j, j) += w;
      } else {
        const int c = j - n;
        Qd_nn->noalias() += w * B_.col(c) * B_.col(c).transpose();
        Qd_ns->col(c) += w * d_(c) * B_.col(c);
        (*Qd_ss)(c) += w * (d_(c) * d_(c) + 1.0);
      }
    }
    return;
  }
  // The exact Q_d = int_0^h Phi(s) diag(q) Phi(s)^T ds (Van Loan 1978) of the series step
  // (PropagateExactSeries), with u = s / h, Ah = F_nn h, N_k = Ah^k / k!, G_k = Ah^k G h and, for a
  // sensor state c on channel a with weight w_c and x = D_c h:
  //   nn: h sum_(i,j) N_i diag(q_n) N_j^T / (i + j + 1)           (navigation white noise)
  //       + h sum_(i,j) G_i diag(lambda_ij) G_j^T, lambda_ij[a] = sum_(c on a) q_c w_c^2
  //       beta_ij(x_c)
  //   ns: column c = h q_c w_c sum_k rho_k(x_c) G_k(:, a)
  //   ss: q_c int_0^h exp(2 D_c s) ds = q_c h expm1(2 x) / (2 x)  (-> q_c h as x -> 0),
  // from Phi_ns(s) e_c = sum_k Ah^k (F_ns e_c h) u^(k+1) phi_(k+1)(x u), phi_p(y) = sum_l y^l /
  // (l + p)!, so that rho_k(x) = int_0^1 u^(k+1) phi_(k+1)(x u) exp(x u) du and beta_ij(x) =
  // int_0^1 u^(i+j+2) phi_(i+1)(x u) phi_(j+1)(x u) du (coefficients: SeriesCoefficients).
  const double h = dt_s;
  const int J = series_terms_;
  bool nav_noise = false;
  Eigen::MatrixXd lambda = Eigen::MatrixXd::Zero(J * J, 6);
  for (const int j : support) {
    if (j < n) {
      nav_noise = true;
      continue;
    }
    const int c = j - n;
    (*Qd_ss)(c) = q[j] * h * series_ss_(c);
    const SensorStateCoupling& k = coupling_[static_cast<size_t>(c)];
    if (!k.coupled) continue;
    const int a = Channel(k);
    auto ns = Qd_ns->col(c);
    for (int p = 0; p < J; ++p) ns += series_rho_(p, c) * series_G_[p].col(a);
    ns *= h * q[j] * k.weight;
    lambda.col(a) += (q[j] * k.weight * k.weight) * series_beta_.col(c);
  }
  if (nav_noise) {
    const Eigen::Matrix<double, n, 1> q_n = q.head(n);
    for (int i = 0; i < J; ++i) {
      Eigen::Matrix<double, n, n> N_sum = Eigen::Matrix<double, n, n>::Zero();
      for (int j = 0; j < J; ++j) N_sum += series_N_[j] / (i + j + 1);
      const Eigen::Matrix<double, n, n> Nq = series_N_[i] * q_n.asDiagonal();
      Qd_nn->noalias() += Nq.lazyProduct(N_sum.transpose());
    }
  }
  if (!lambda.isZero(0.0)) {
    // sum_i G_i R_i^T with R_i = sum_j G_j diag(lambda_ij).
    for (int i = 0; i < J; ++i) {
      Eigen::Matrix<double, n, 6> R = Eigen::Matrix<double, n, 6>::Zero();
      for (int j = 0; j < J; ++j) R += series_G_[j] * lambda.row(i * J + j).asDiagonal();
      Qd_nn->noalias() += series_G_[i].lazyProduct(R.transpose());
    }
  }
  *Qd_nn *= h;
}

void ErrorCovariancePropagator::PropagateSources(double dt_s) {
  Eigen::MatrixXd Qd_nn, Qd_ns;
  Eigen::VectorXd Qd_ss;
  for (size_t s = 0; s < source_P_.size(); ++s) {
    ProcessNoise(source_q_[s], source_support_[s], dt_s, &Qd_nn, &Qd_ns, &Qd_ss);
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
  // P_ss]]:
  //   nn: A P_nn A^T + A P_ns B^T + (A P_ns B^T)^T + B P_ss B^T + Q_nn
  //   ns: (A P_ns + B P_ss) diag(d) + Q_ns,   ss: diag(d) P_ss diag(d) + diag(Q_ss).
  // B P_ss costs 9 m^2 operations, or 9 m while P_ss is diagonal (no update has correlated the
  // sensor states, as in a free-inertial analysis); the product with the zero off-diagonal terms
  // has the same value.
  constexpr int n = kNumNavErrorStates;
  const int m = layout_.size - n;
  const auto P_nn = P_.topLeftCorner(n, n);
  const auto P_ns = P_.topRightCorner(n, m);
  const auto P_ss = P_.bottomRightCorner(m, m);
  bool ss_diagonal = true;
  for (int j = 0; j < m && ss_diagonal; ++j) {
    for (int i = 0; i < m; ++i) {
      if (i != j && P_ss(i, j) != 0.0) {
        ss_diagonal = false;
        break;
      }
    }
  }
  if (ss_diagonal) {
    BPss_ = B_ * P_ss.diagonal().asDiagonal();
  } else {
    BPss_ = B_ * P_ss;  // n x m
  }
  if (step_ == Step::kSeries) {
    // The exact step (the covariance analysis) with fixed-size coefficient products and one
    // product fewer: (Phi P)_nn = A P_nn + B P_ns^T, (Phi P)_ns = A P_ns + B P_ss, and
    // nn = (Phi P)_nn A^T + (Phi P)_ns B^T.
    const Eigen::Matrix<double, n, n> A = A_;
    Pns_ = A.lazyProduct(P_ns) + BPss_;
    const Eigen::Matrix<double, n, n> X = A.lazyProduct(P_nn) + B_.lazyProduct(P_ns.transpose());
    Pnn_ = X.lazyProduct(A.transpose()) + Pns_.lazyProduct(B_.transpose());
  } else {
    // The second-order step in the product order of the Monte-Carlo runs' filter (InsGnssFilter),
    // whose results are reproducible bit for bit.
    Pns_ = A_ * P_ns + BPss_;  // (Phi P)_ns before the diag(d) on the right
    APnsBt_ = A_ * P_ns * B_.transpose();
    Pnn_ = A_ * P_nn * A_.transpose() + APnsBt_ + APnsBt_.transpose() + BPss_ * B_.transpose();
  }
  P_.topLeftCorner(n, n) = Pnn_ + Qd_nn;
  P_.topRightCorner(n, m) = Pns_ * d_.asDiagonal();
  P_.topRightCorner(n, m) += Qd_ns;
  if (ss_diagonal) {
    // The zero off-diagonal terms stay zero (d > 0).
    P_.bottomRightCorner(m, m).diagonal() = d_.cwiseProduct(P_ss.diagonal()).cwiseProduct(d_);
  } else {
    P_.bottomRightCorner(m, m) = d_.asDiagonal() * P_ss * d_.asDiagonal();
  }
  P_.bottomRightCorner(m, m).diagonal() += Qd_ss;
  P_.bottomLeftCorner(m, n) = P_.topRightCorner(n, m).transpose();
  P_.topLeftCorner(n, n) =
      0.5 * (P_.topLeftCorner(n, n) + P_.topLeftCorner(n, n).transpose()).eval();
}

bool ErrorCovariancePropagator::PropagateExactSeries(const ErrorStateMatrix& F,
                                                     const Matrix3d& C_b_n, double h) {
  // Van Loan's exact Phi = exp(F h) for the structured model F = [[F_nn, F_ns], [0, D]] (header)
  // whose sensor column c is F_ns e_c = w_c G e_a (ErrorStateSensorCoupling: channel a, weight
  // w_c; G = [[0, 0], [C_b_n, 0], [0, C_b_n]], 9 x 6). With Ah = F_nn h and x_c = D_c h, the
  // blocks of (F h)^k / k! give
  //   Phi_nn = sum_k N_k, N_k = Ah^k / k!,
  //   Phi_ns e_c = sum_k Ah^k (F_ns e_c h) phi_(k+1)(x_c) = w_c sum_k phi_(k+1)(x_c) G_k e_a,
  //     G_k = Ah^k G h,  phi_p(x) = sum_l x^l / (l + p)!
  //   (the (F h)^k block ns is sum_(j<k) Ah^j (F_ns h) x^(k-1-j), summed over k for each j),
  //   Phi_ss = diag(exp(x)).
  // The powers of Ah are summed until a term adds less than 1e-17 of the sum, allowing for the
  // factor exp(2 |x|) <= e^4 of the scalar series (J terms, at most kSeriesPowers); the scalar
  // series in x to degree n with (2 |x|)^n / n! < 1e-18 (each coefficient is at most 2^n / n!).
  // Q_d: ProcessNoise. For ||F_nn h||_1 > 2 or |D h| > 2 (long steps) the dense exponential is
  // used instead.
  // F comes from ErrorStateSystemMatrix: F_sn = 0 and D diagonal by construction. The small
  // fixed-size products are coefficient-based (lazyProduct) rather than blocked.
  constexpr int n = kNumNavErrorStates;
  const int m = layout_.size - n;
  if (m <= 0) return false;
  const Eigen::Matrix<double, n, n> Ah = F.topLeftCorner(n, n) * h;
  const Eigen::VectorXd Dh = F.bottomRightCorner(m, m).diagonal() * h;
  const double x_max = Dh.cwiseAbs().maxCoeff();
  if (Ah.cwiseAbs().colwise().sum().maxCoeff() > 2.0 || x_max > 2.0) return false;
  series_N_.assign(1, Eigen::Matrix<double, n, n>::Identity());
  Eigen::Matrix<double, n, n> A = series_N_[0];
  const double scalar_factor = math::Exp(2.0 * x_max);
  for (int k = 1; k < kSeriesPowers; ++k) {
    series_N_.push_back(Ah.lazyProduct(series_N_[k - 1]) / k);
    A += series_N_[k];
    if (series_N_[k].cwiseAbs().maxCoeff() * scalar_factor < 1e-17 * A.cwiseAbs().maxCoeff()) {
      break;
    }
  }
  const int J = static_cast<int>(series_N_.size());
  Eigen::Matrix<double, n, 6> G = Eigen::Matrix<double, n, 6>::Zero();
  G.block<3, 3>(kErrVelocity, 0) = C_b_n * h;
  G.block<3, 3>(kErrAttitude, 3) = C_b_n * h;
  series_G_.assign(1, G);
  for (int k = 1; k < J; ++k) series_G_.push_back(Ah.lazyProduct(series_G_[k - 1]));
  if (J != series_terms_ || series_Dh_.size() != m || series_Dh_ != Dh) {
    // The scalar functions of every sensor state (the states of one process share x: evaluated
    // once per distinct x).
    series_terms_ = J;
    series_Dh_ = Dh;
    const SeriesCoefficients& co = Coefficients();
    series_phi_.resize(J, m);
    series_rho_.resize(J, m);
    series_beta_.resize(J * J, m);
    series_exp_.resize(m);
    series_ss_.resize(m);
    std::vector<int> done;
    for (int c = 0; c < m; ++c) {
      const double x = Dh(c);
      const auto same = std::find_if(done.begin(), done.end(), [&](int e) { return Dh(e) == x; });
      if (same != done.end()) {
        series_phi_.col(c) = series_phi_.col(*same);
        series_rho_.col(c) = series_rho_.col(*same);
        series_beta_.col(c) = series_beta_.col(*same);
        series_exp_(c) = series_exp_(*same);
        series_ss_(c) = series_ss_(*same);
        continue;
      }
      done.push_back(c);
      int degree = 1;
      for (double t = 2.0 * std::abs(x); degree < kSeriesDegree && t >= 1e-18; ++degree) {
        t *= 2.0 * std::abs(x) / (degree + 1);
      }
      for (int i = 0; i < J; ++i) {
        series_phi_(i, c) = Polynomial(&co.phi[i * kSeriesDegree], degree, x);
        series_rho_(i, c) = Polynomial(&co.rho[i * kSeriesDegree], degree, x);
        for (int j = i; j < J; ++j) {
          const double b = Polynomial(&co.beta[(i * kSeriesPowers + j) * kSeriesDegree], degree, x);
          series_beta_(i * J + j, c) = b;
          series_beta_(j * J + i, c) = b;
        }
      }
      series_exp_(c) = math::Exp(x);  // the engine's exp (elementary.h)
      // int_0^h exp(2 D_c s) ds / h = expm1(2 x) / (2 x), -> 1 as x -> 0.
      series_ss_(c) = x == 0.0 ? 1.0 : math::Expm1(2.0 * x) / (2.0 * x);
    }
  }
  A_ = A;
  d_ = series_exp_;
  B_.setZero(n, m);
  for (int c = 0; c < m; ++c) {
    const SensorStateCoupling& k = coupling_[static_cast<size_t>(c)];
    if (!k.coupled) continue;
    const int a = Channel(k);
    auto col = B_.col(c);
    for (int i = 0; i < J; ++i) col += series_phi_(i, c) * series_G_[i].col(a);
    col *= k.weight;
  }
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
