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
// O((9 + m)^3) operations. With kVanLoan (exact Phi = exp(F dt) and Q_d) the same structure gives
// the exact step from the power series of the blocks (covariance.cc), O(K^2 9 m) for K terms
// (~10 at 0.1 s), instead of the exponential of a 2(9 + m)-square matrix; steps too long for the
// series (||F_nn dt||_1 > 2 or |D dt| > 2) use that exponential.
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
  NavEnvironment env_;
  ErrorStateNoise noise_;
  ErrorStateLayout layout_;
  ErrorStateMatrix Q_c_;
  Discretization method_;
  ErrorStateMatrix P_;
  // The exact structured step; false when F lacks the structure or dt is too long for the series.
  bool PropagateExactSeries(const ErrorStateMatrix& F, double dt_s);
  // P <- Phi P Phi^T + Q_d from Phi = [[A_, B_], [0, diag(d_)]] and the blocks of Q_d.
  void ApplyStructuredStep(const Eigen::MatrixXd& Qd_nn, const Eigen::MatrixXd& Qd_ns,
                           const Eigen::VectorXd& Qd_ss, ErrorStateMatrix* P);
  // The sources' steps with the Phi of the step just taken (A_, B_, d_; Phi_ for the dense one).
  void PropagateSourcesSecondOrder(double dt_s);
  void PropagateSourcesSeries(double h);
  void PropagateSourcesDense(const ErrorStateMatrix& F, double dt_s);
  // Work space of the structured step (allocated once).
  Eigen::MatrixXd A_, B_, BPss_, Pnn_, Pns_;
  Eigen::VectorXd d_, q_s_;
  // The budget's sources: covariance, share of diag(Q_c), and the indices where the share is > 0.
  std::vector<ErrorStateMatrix> source_P_;
  std::vector<Eigen::VectorXd> source_q_;
  std::vector<std::vector<int>> source_support_;
  // The series terms of the last exact step (PropagateExactSeries), kept for the sources:
  // N_k, U_k, and the weighted sums sum_j T_j / (i + j + 1) (N_sum, U_sum, G).
  std::vector<Eigen::Matrix<double, kNumNavErrorStates, kNumNavErrorStates>> series_N_,
      series_Nsum_;
  std::vector<Eigen::MatrixXd> series_U_, series_Usum_;
  std::vector<Eigen::VectorXd> series_G_;
  Eigen::VectorXd series_Dh_;  // D h
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
