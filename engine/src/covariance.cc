#include "driftlab/covariance.h"

#include <cmath>
#include <string>

#include "driftlab/spec_error.h"

namespace driftlab {

ErrorCovariancePropagator::ErrorCovariancePropagator(const NavEnvironment& env,
                                                     const ErrorStateNoise& noise,
                                                     const ErrorStateMatrix& P0,
                                                     Discretization method)
    : env_(env),
      noise_(noise),
      Q_c_(ErrorStateProcessNoise(noise)),
      method_(method),
      P_(P0),
      Phi_(ErrorStateMatrix::Identity()),
      Q_d_(ErrorStateMatrix::Zero()) {}

const ErrorStateMatrix& ErrorCovariancePropagator::Propagate(const NavState& reference,
                                                             const Vector3d& f_ib_b, double dt_s) {
  const ErrorStateMatrix F = ErrorStateSystemMatrix(env_, reference, f_ib_b, noise_);
  DiscretizeErrorModel(F, Q_c_, dt_s, method_, &Phi_, &Q_d_);
  P_ = (Phi_ * P_ * Phi_.transpose()).eval() + Q_d_;
  P_ = 0.5 * (P_ + P_.transpose()).eval();
  return Phi_;
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
    prop.Propagate(mid, mid.C_b_n().transpose() * f_n, s * trajectory.dt_s);
    k += s;
    if (k % options.epoch_every_samples == 0 || k == n) {
      out.push_back(MakeCovarianceEpoch(truth[k].t_s, prop.P(), truth[k].euler()));
    }
  }
  return out;
}

}  // namespace driftlab
