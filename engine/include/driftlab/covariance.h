// Linear covariance analysis: the covariance P of the 15-state error model (error_state.h)
// propagated along the truth trajectory, P(k+1) = Phi P(k) Phi^T + Q_d, giving the predicted
// 1-sigma of every navigation error component against time: the number a Monte-Carlo run of the
// same IMU model must reproduce (for the terms the model represents; MakeErrorStateNoise lists the
// others). Reference: Maybeck, "Stochastic Models, Estimation and Control", vol. 1, ch. 4 and 6
// (covariance propagation); Groves 2nd ed. section 3.2.2 (system propagation), 14.2.
#pragma once

#include <Eigen/Cholesky>
#include <cstdint>
#include <vector>

#include "driftlab/error_state.h"
#include "driftlab/trajectory.h"

namespace driftlab {

// Propagates P over intervals; the same step serves the INS/GNSS filter's prediction.
// With kSecondOrder the step uses the structure of F: x = [nav (9); sensor (m)] with
// F = [[F_nn, F_ns], [0, D]], D diagonal (every sensor and aiding error state is a random
// constant, random walk or first-order Gauss-Markov), so
//   Phi = [[A, B], [0, diag(d)]],  A = I + F_nn dt + (F_nn dt)^2 / 2,
//   B = F_ns dt + (F_nn F_ns + F_ns D) dt^2 / 2 (the second-order terms of (F dt)^2 / 2),
//   d = 1 + D dt + (D dt)^2 / 2,
// the same Phi and trapezoidal Q_d as the dense second-order formula, in O(9 m^2) instead of
// O((9 + m)^3) operations. With kVanLoan (exact Phi = exp(F dt) and Q_d) the same structure and
// the sensor columns of F_ns (ErrorStateSensorCoupling: each a column of C_b_n times a weight)
// give the exact step from power series in F_nn dt and scalar series in D dt (covariance.cc),
// O(J^2 m) for J powers of F_nn dt (~7 at 0.1 s), plus O(9 m^2) for Phi P Phi^T (O(9 m)
// while P_ss is diagonal, as in a free-inertial analysis), instead of the exponential of a
// 2(9 + m)-square matrix; steps too long for the series (||F_nn dt||_1 > 2 or |D dt| > 2) use
// that exponential.
class ErrorCovariancePropagator {
 public:
  ErrorCovariancePropagator(const NavEnvironment& env, const ErrorStateNoise& noise,
                            const ErrorStateMatrix& P0,
                            Discretization method = Discretization::kVanLoan);
  // P <- Phi P Phi^T + Q_d over dt_s with F at `reference` (the state at the middle of the
  // interval), the mean specific force over the interval f_ib_b [m/s^2] and the mean body rate
  // omega_ib_b [rad/s] (for the gyro scale-factor / misalignment states).
  void Propagate(const NavState& reference, const Vector3d& f_ib_b, double dt_s,
                 const Vector3d& omega_ib_b = Vector3d::Zero());
  const ErrorStateLayout& layout() const { return layout_; }
  const ErrorStateNoise& noise() const { return noise_; }
  const ErrorStateMatrix& P() const { return P_; }
  ErrorStateMatrix& mutable_P() { return P_; }

  // Independent error sources for the error budget (Gelb, "Applied Optimal Estimation", 1974,
  // section 7.3): source s has its own covariance P_s (started at P0[s]) and its share q_c[s] of
  // the diagonal of Q_c (the shares sum to the diagonal). Propagate then also steps every P_s with
  // the same Phi and the Q_d of its share, P_s <- Phi P_s Phi^T + Q_d,s; Q_d is linear in Q_c, so
  // sum_s P_s = P when sum_s P0[s] = P0 (to rounding). P itself is stepped as without sources.
  void SetSources(std::vector<ErrorStateMatrix> P0, std::vector<Eigen::VectorXd> q_c);
  const std::vector<ErrorStateMatrix>& source_P() const { return source_P_; }
  std::vector<ErrorStateMatrix>& mutable_source_P() { return source_P_; }

 private:
  // The discretisation of the step just taken (its terms are kept for the sources' steps).
  enum class Step { kSecondOrder, kSeries, kDense };
  NavEnvironment env_;
  ErrorStateNoise noise_;
  ErrorStateLayout layout_;
  ErrorStateMatrix Q_c_;
  Discretization method_;
  ErrorStateMatrix P_;
  Step step_ = Step::kSecondOrder;
  // The exact structured step; false when dt is too long for the series.
  bool PropagateExactSeries(const ErrorStateMatrix& F, const Matrix3d& C_b_n, double h);
  // P <- Phi P Phi^T + Q_d from Phi = [[A_, B_], [0, diag(d_)]] and the blocks of Q_d.
  void ApplyStructuredStep(const Eigen::MatrixXd& Qd_nn, const Eigen::MatrixXd& Qd_ns,
                           const Eigen::VectorXd& Qd_ss, ErrorStateMatrix* P);
  // The blocks of Q_d of the step just taken (step_) for the continuous white-noise PSDs q (the
  // diagonal of a Q_c, or a source's share of it), nonzero only at the indices `support`.
  void ProcessNoise(const Eigen::VectorXd& q, const std::vector<int>& support, double dt_s,
                    Eigen::MatrixXd* Qd_nn, Eigen::MatrixXd* Qd_ns, Eigen::VectorXd* Qd_ss);
  // The sources' steps with the transition of the step just taken.
  void PropagateSources(double dt_s);
  void PropagateSourcesDense(const ErrorStateMatrix& F, double dt_s);
  // Work space of the structured step (allocated once).
  Eigen::MatrixXd A_, B_, BPss_, Pnn_, Pns_, APnsBt_, Qd_nn_, Qd_ns_;
  Eigen::VectorXd d_, q_s_, q_c_, Qd_ss_;
  std::vector<int> q_support_;  // indices where diag(Q_c) > 0
  std::vector<SensorStateCoupling> coupling_;
  // The budget's sources: covariance, share of diag(Q_c), and the indices where the share is > 0.
  std::vector<ErrorStateMatrix> source_P_;
  std::vector<Eigen::VectorXd> source_q_;
  std::vector<std::vector<int>> source_support_;
  // Terms of the last exact step (PropagateExactSeries), J powers of F_nn h: N_k = (F_nn h)^k /
  // k!, G_k = (F_nn h)^k G h with G the 9 x 6 map of the sensor channels (C_b_n into the velocity
  // and attitude rows); and the scalar functions of x = D h per sensor state c (columns):
  // phi_(k+1)(x) of Phi_ns, rho_k(x) and beta_ij(x) (row i * J + j) of Q_d, exp(x), and
  // expm1(2 x) / (2 x). The scalar functions depend on D h and J only: kept while they repeat.
  int series_terms_ = 0;
  std::vector<Eigen::Matrix<double, kNumNavErrorStates, kNumNavErrorStates>> series_N_;
  std::vector<Eigen::Matrix<double, kNumNavErrorStates, 6>> series_G_;
  Eigen::MatrixXd series_phi_, series_rho_, series_beta_;
  Eigen::VectorXd series_Dh_, series_exp_, series_ss_;
};

// Predicted 1-sigma errors at one epoch, in the components the Monte-Carlo statistics report.
struct CovarianceEpoch {
  double t_s = 0.0;
  ErrorStateVector sigma;  // sqrt(diag P): r [m], v [m/s], psi [rad], b_a [m/s^2], b_g [rad/s],
                           //   then the augmented states (ErrorStateLayout)
  Vector3d euler_sigma_rad = Vector3d::Zero();  // roll, pitch, yaw: sqrt(diag(T P_psi T^T))
  double horizontal_sigma_m = 0.0;              // sqrt(P_NN + P_EE) (RMS horizontal error)
  ErrorStateMatrix P;
};

struct CovarianceAnalysisOptions {
  int64_t step_samples = 1;           // propagation interval in IMU samples, >= 1
  int64_t epoch_every_samples = 100;  // output every this many samples (and the final one), >= 1
  Discretization discretization = Discretization::kVanLoan;
};

// Free-inertial covariance along the truth: P0 at truth[0], propagated over the whole
// trajectory (reference = truth at the interval's midpoint sample, f from the ideal increments:
// f_ib_b = C_b_n(mid)^T sum_i C_b_n(i) delta_v_i / T). Epochs at samples 0, e, 2e, ... and the
// final sample. Throws SpecError ("covariance.step_samples", "covariance.epoch_every_samples")
// for values < 1, and when epoch_every_samples is not a multiple of step_samples.
std::vector<CovarianceEpoch> FreeInertialCovariance(const Trajectory& trajectory,
                                                    const ErrorStateNoise& noise,
                                                    const ErrorStateMatrix& P0,
                                                    const CovarianceAnalysisOptions& options);

// Kalman measurement update of the covariance in Joseph form (Bucy & Joseph 1968; Groves 2nd ed.
// (3.58)): S = H P H^T + R, K = P H^T S^-1, P <- (I - K H) P (I - K H)^T + K R K^T, symmetrised.
// Returns K; *S_llt (optional) receives the Cholesky factor of S (for the innovation's NIS).
template <int M>
Eigen::Matrix<double, Eigen::Dynamic, M> JosephUpdate(
    const Eigen::Matrix<double, M, Eigen::Dynamic>& H, const Eigen::Matrix<double, M, M>& R,
    ErrorStateMatrix* P, Eigen::LLT<Eigen::Matrix<double, M, M>>* S_llt = nullptr) {
  const Eigen::Matrix<double, M, Eigen::Dynamic> HP = H * (*P);
  const Eigen::Matrix<double, M, M> S = HP * H.transpose() + R;
  const Eigen::LLT<Eigen::Matrix<double, M, M>> llt(S);
  // K = P H^T S^-1 = (S^-1 H P)^T for symmetric P and S.
  const Eigen::Matrix<double, Eigen::Dynamic, M> K = llt.solve(HP).transpose();
  // (I - K H) P (I - K H)^T + K R K^T expanded, O(n^2 M) instead of O(n^3):
  //   P - K HP - (K HP)^T + K (H P H^T) K^T + K R K^T = P - K HP - (K HP)^T + K S K^T.
  const ErrorStateMatrix KHP = K * HP;
  *P = (*P - KHP - KHP.transpose() + K * S * K.transpose()).eval();
  *P = 0.5 * (*P + P->transpose()).eval();
  if (S_llt != nullptr) *S_llt = llt;
  return K;
}

// The epoch record of P at time t_s with the truth attitude `attitude` (for the Euler sigmas).
CovarianceEpoch MakeCovarianceEpoch(double t_s, const ErrorStateMatrix& P,
                                    const EulerAngles& attitude);

}  // namespace driftlab
