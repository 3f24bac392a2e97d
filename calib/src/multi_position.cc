#include "driftlab/calib/multi_position.h"

#include <ceres/ceres.h>
#include <fmt/format.h>

#include <Eigen/Dense>
#include <Eigen/SVD>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "driftlab/attitude.h"
#include "driftlab/earth.h"
#include "driftlab/elementary.h"
#include "driftlab/spec_error.h"

namespace driftlab::calib {
namespace {

// Residual of one pose (Tedaldi eq. 10): |T_a^-1 (f~ - b_a)| - g, T_a lower triangular.
// x = [s_x, s_y, s_z, m_yx, m_zx, m_zy, b_x, b_y, b_z].
struct AccelPoseResidual {
  Eigen::Vector3d f;
  double g;
  template <typename T>
  bool operator()(const T* x, T* r) const {
    const T y0 = T(f[0]) - x[6];
    const T y1 = T(f[1]) - x[7];
    const T y2 = T(f[2]) - x[8];
    const T a0 = y0 / (T(1.0) + x[0]);  // forward substitution of the lower-triangular T_a
    const T a1 = (y1 - x[3] * a0) / (T(1.0) + x[1]);
    const T a2 = (y2 - x[4] * a0 - x[5] * a1) / (T(1.0) + x[2]);
    r[0] = sqrt(a0 * a0 + a1 * a1 + a2 * a2) - T(g);
    return true;
  }
};

// T_g from x = [s_x, s_y, s_z, m_xy, m_xz, m_yx, m_yz, m_zx, m_zy].
template <typename T>
Eigen::Matrix<T, 3, 3> GyroMatrix(const T* x) {
  Eigen::Matrix<T, 3, 3> m;
  m << T(1.0) + x[0], x[3], x[4], x[5], T(1.0) + x[1], x[6], x[7], x[8], T(1.0) + x[2];
  return m;
}

// Residual of one rotation between poses k and k+1 (Tedaldi eq. 12-15): the down direction d_k
// carried by the attitude change integrated from the calibrated rates, minus d_{k+1}, resolved
// along two unit vectors e1, e2 perpendicular to d_{k+1}.
struct GyroRotationResidual {
  const std::vector<Eigen::Vector3d>* rates;  // raw rate per sample [rad/s]
  const std::vector<double>* dt;              // sample interval of each sample [s]
  size_t begin, end;
  Eigen::Vector3d d_k, e1, e2;

  template <typename T>
  bool operator()(const T* x, const T* b, T* r) const {
    const Eigen::Matrix<T, 3, 3> T_inv = GyroMatrix(x).inverse();
    const Eigen::Matrix<T, 3, 1> bias(b[0], b[1], b[2]);
    Eigen::Quaternion<T> q(T(1.0), T(0.0), T(0.0), T(0.0));  // C_{b(t)}^{b(t_k)}
    for (size_t i = begin; i < end; ++i) {
      const Eigen::Matrix<T, 3, 1> phi = T_inv * ((*rates)[i].cast<T>() - bias) * T((*dt)[i]);
      const T theta2 = phi.squaredNorm();
      Eigen::Quaternion<T> dq;
      if (theta2 > T(1e-24)) {  // exact rotation-vector step (Groves (5.73) in quaternion form)
        const T theta = sqrt(theta2);
        const T k = sin(T(0.5) * theta) / theta;
        dq = Eigen::Quaternion<T>(cos(T(0.5) * theta), k * phi[0], k * phi[1], k * phi[2]);
      } else {
        dq = Eigen::Quaternion<T>(T(1.0), T(0.5) * phi[0], T(0.5) * phi[1], T(0.5) * phi[2]);
      }
      q = q * dq;
    }
    const Eigen::Matrix<T, 3, 1> d_pred = q.conjugate() * d_k.cast<T>();  // d in b(t_{k+1})
    r[0] = e1.cast<T>().dot(d_pred);
    r[1] = e2.cast<T>().dot(d_pred);
    return true;
  }
};

}  // namespace

const FitParameter& CalibrationFit::Find(const std::string& name) const {
  for (const FitParameter& p : parameters) {
    if (p.name == name) return p;
  }
  throw std::out_of_range("no fitted parameter " + name);
}

const std::vector<std::string>& AccelParameterNames() {
  static const std::vector<std::string> kNames = {
      "accel.scale_factor.x",  "accel.scale_factor.y",  "accel.scale_factor.z",
      "accel.misalignment.yx", "accel.misalignment.zx", "accel.misalignment.zy",
      "accel.bias.x",          "accel.bias.y",          "accel.bias.z"};
  return kNames;
}

const std::vector<std::string>& GyroParameterNames() {
  static const std::vector<std::string> kNames = {
      "gyro.scale_factor.x",  "gyro.scale_factor.y",  "gyro.scale_factor.z",
      "gyro.misalignment.xy", "gyro.misalignment.xz", "gyro.misalignment.yx",
      "gyro.misalignment.yz", "gyro.misalignment.zx", "gyro.misalignment.zy"};
  return kNames;
}

namespace detail {

void SolveAndReport(ceres::Problem* problem, double* x, int n,
                    const std::vector<std::string>& names, const std::vector<std::string>& units,
                    CalibrationFit* fit, Eigen::MatrixXd* covariance) {
  const auto start = std::chrono::steady_clock::now();
  const int m = problem->NumResiduals();
  if (m <= n) {
    throw SpecError("data",
                    fmt::format("{} residuals cannot determine {} parameters ({}); need more than "
                                "{} independent measurements",
                                m, n, fit->kind, n),
                    0);
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 200;
  options.function_tolerance = 1e-14;
  options.gradient_tolerance = 1e-14;
  options.parameter_tolerance = 1e-14;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(options, problem, &summary);
  if (!summary.IsSolutionUsable()) {
    throw SpecError("data", "the " + fit->kind + " fit failed: " + summary.message, 0);
  }
  // Rank check on the column-scaled Jacobian (unscaled residuals, without robust loss weights).
  ceres::CRSMatrix crs;
  std::vector<double> residuals;
  ceres::Problem::EvaluateOptions eval;
  eval.apply_loss_function = false;
  problem->Evaluate(eval, nullptr, &residuals, nullptr, &crs);
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int r = 0; r < crs.num_rows; ++r) {
    for (int i = crs.rows[r]; i < crs.rows[r + 1]; ++i) J(r, crs.cols[i]) = crs.values[i];
  }
  Eigen::VectorXd col_norm = J.colwise().norm();
  for (int c = 0; c < n; ++c) {
    if (col_norm[c] > 0.0) J.col(c) /= col_norm[c];
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeThinV);
  const Eigen::VectorXd sv = svd.singularValues();
  if (!(sv[n - 1] > 1e-10 * sv[0])) {
    Eigen::Index worst = 0;
    svd.matrixV().col(n - 1).cwiseAbs().maxCoeff(&worst);
    throw SpecError("data",
                    fmt::format("the data cannot determine {} (the {} fit's Jacobian is rank "
                                "deficient: reciprocal condition number {:.2g} < 1e-10); record "
                                "poses / motions that excite this parameter",
                                names[worst], fit->kind, sv[n - 1] / sv[0]),
                    0);
  }
  ceres::Covariance::Options cov_options;
  cov_options.algorithm_type = ceres::DENSE_SVD;
  cov_options.null_space_rank = -1;  // fail on rank deficiency (already excluded above)
  ceres::Covariance ceres_covariance(cov_options);
  std::vector<std::pair<const double*, const double*>> blocks = {{x, x}};
  if (!ceres_covariance.Compute(blocks, problem)) {
    throw SpecError("data", "the " + fit->kind + " covariance cannot be computed (rank deficient)",
                    0);
  }
  std::vector<double> cov(static_cast<size_t>(n) * n);
  ceres_covariance.GetCovarianceBlock(x, x, cov.data());
  double rss = 0.0;
  for (double r : residuals) rss += r * r;
  const double s2 = rss / static_cast<double>(m - n);  // residual variance
  const Eigen::MatrixXd scaled = Eigen::Map<Eigen::MatrixXd>(cov.data(), n, n) * s2;
  if (covariance != nullptr) *covariance = scaled;
  fit->parameters.clear();
  for (int i = 0; i < n; ++i) {
    fit->parameters.push_back({names[i], x[i], units[i], std::sqrt(cov[i * n + i] * s2)});
  }
  fit->SetCorrelation(scaled);
  fit->residuals = residuals;
  fit->residual_rms = std::sqrt(rss / static_cast<double>(m));
  fit->iterations = static_cast<int>(summary.iterations.size()) - 1;
  fit->fit_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace detail

Eigen::Vector3d AccelCalibration::Apply(const Eigen::Vector3d& f_raw) const {
  return T_a.triangularView<Eigen::Lower>().solve(f_raw - b_a);
}

Eigen::Vector3d GyroCalibration::Apply(const Eigen::Vector3d& omega_raw) const {
  return T_g.lu().solve(omega_raw - b_g);
}

AccelCalibration CalibrateAccelerometers(const std::vector<StaticInterval>& poses,
                                         const AccelCalibrationOptions& options) {
  if (!std::isfinite(options.lat_rad) || std::abs(options.lat_rad) > 0.5 * M_PI) {
    throw SpecError("--lat", fmt::format("{} deg", options.lat_rad * 180.0 / M_PI),
                    "[-90, 90] deg");
  }
  if (!std::isfinite(options.h_m) || options.h_m < -1000.0 || options.h_m > 10000.0) {
    throw SpecError("--height", fmt::format("{} m", options.h_m), "[-1000, 10000] m");
  }
  if (!(options.loss_scale_m_per_s2 > 0.0)) {
    throw SpecError("options.loss_scale_m_per_s2", fmt::format("{}", options.loss_scale_m_per_s2),
                    "> 0");
  }
  const int n_poses = static_cast<int>(poses.size());
  if (n_poses < 9) {
    throw SpecError("data",
                    fmt::format("too few poses: {} static pose{} found; the 9 accelerometer "
                                "parameters need at least 9 poses (Tedaldi recommend 36-50)",
                                n_poses, n_poses == 1 ? "" : "s"),
                    0);
  }
  Eigen::MatrixXd D(n_poses, 3);
  for (int k = 0; k < n_poses; ++k) {
    const double norm = poses[k].mean_f_ib_s.norm();
    if (!(norm > 0.0))
      throw SpecError("data", fmt::format("pose {} has zero specific force", k), 0);
    D.row(k) = poses[k].mean_f_ib_s.transpose() / norm;
  }
  const double spread =
      Eigen::JacobiSVD<Eigen::MatrixXd>(D).singularValues()[2] / std::sqrt(double(n_poses));
  if (spread < options.min_direction_spread) {
    throw SpecError(
        "data",
        fmt::format("poses do not span the sphere: the smallest singular value of the "
                    "{} x 3 pose-direction matrix, over sqrt({}), is {:.3g} < {} (1/sqrt(3)"
                    " = 0.577 for an even spread); turn the IMU so that gravity "
                    "points along +-x, +-y, +-z and in between",
                    n_poses, n_poses, spread, options.min_direction_spread),
        0);
  }
  AccelCalibration out;
  out.gravity_m_per_s2 = GravityNed(options.lat_rad, options.h_m).norm();
  out.fit.kind = "accel";
  out.fit.residual_unit = "m/s^2";
  out.fit.poses_used = n_poses;
  double x[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
  ceres::Problem problem;
  for (const StaticInterval& pose : poses) {
    ceres::LossFunction* loss = nullptr;
    if (options.loss == RobustLoss::kHuber)
      loss = new ceres::HuberLoss(options.loss_scale_m_per_s2);
    if (options.loss == RobustLoss::kCauchy) {
      loss = new ceres::CauchyLoss(options.loss_scale_m_per_s2);
    }
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<AccelPoseResidual, 1, 9>(
                                 new AccelPoseResidual{pose.mean_f_ib_s, out.gravity_m_per_s2}),
                             loss, x);
  }
  const std::vector<std::string> unit_names = {"1",   "1",     "1",     "rad",  "rad",
                                               "rad", "m/s^2", "m/s^2", "m/s^2"};
  detail::SolveAndReport(&problem, x, 9, AccelParameterNames(), unit_names, &out.fit,
                         &out.covariance);
  out.T_a << 1.0 + x[0], 0.0, 0.0, x[3], 1.0 + x[1], 0.0, x[4], x[5], 1.0 + x[2];
  out.b_a << x[6], x[7], x[8];
  out.fit.messages.push_back(fmt::format(
      "local gravity {:.6f} m/s^2 (WGS-84 normal gravity at {:.4f} deg, {:.1f} m); pose-direction "
      "spread {:.3f}",
      out.gravity_m_per_s2, options.lat_rad * 180.0 / M_PI, options.h_m, spread));
  return out;
}

GyroCalibration CalibrateGyros(const RawImuRecording& recording,
                               const std::vector<StaticInterval>& poses,
                               const AccelCalibration& accel,
                               const GyroCalibrationOptions& options) {
  if (poses.size() < 2) {
    throw SpecError("data",
                    fmt::format("too few poses: {} static pose(s); the gyro fit needs rotations "
                                "between poses",
                                poses.size()),
                    0);
  }
  GyroCalibration out;
  out.fit.kind = "gyro";
  out.fit.residual_unit = "rad";
  const StaticInterval& init = poses[0];
  out.b_g = init.mean_omega_ib_s;
  const int n = static_cast<int>(recording.size());
  std::vector<Eigen::Vector3d> rates(n);
  std::vector<double> dt(n);
  for (int i = 0; i < n; ++i) {
    rates[i] = recording.omega_ib_s[i];
    // Rectangle rule: sample i stands for the interval of length dt around it.
    dt[i] = i + 1 < n ? recording.t_s[i + 1] - recording.t_s[i]
                      : recording.t_s[i] - recording.t_s[i - 1];
  }
  double x[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
  double bias[3] = {out.b_g[0], out.b_g[1], out.b_g[2]};
  ceres::Problem problem;
  int used = 0;
  std::vector<size_t> used_pairs;
  for (size_t k = 0; k + 1 < poses.size(); ++k) {
    const Eigen::Vector3d d_k = -accel.Apply(poses[k].mean_f_ib_s).normalized();
    const Eigen::Vector3d d_next = -accel.Apply(poses[k + 1].mean_f_ib_s).normalized();
    // Nominal rotation angle (uncalibrated rates) for the no-motion check.
    Eigen::Vector3d angle = Eigen::Vector3d::Zero();
    for (int64_t i = poses[k].end; i < poses[k + 1].begin; ++i)
      angle += (rates[i] - out.b_g) * dt[i];
    const double moved = std::max(angle.norm(), math::Acos(std::clamp(d_k.dot(d_next), -1.0, 1.0)));
    if (moved < options.min_rotation_rad) {
      out.fit.messages.push_back(
          fmt::format("poses {} and {} skipped: no motion between them ({:.3g} deg < {:.3g} deg)",
                      k, k + 1, moved * 180.0 / M_PI, options.min_rotation_rad * 180.0 / M_PI));
      continue;
    }
    Eigen::Vector3d e1 = d_next.unitOrthogonal();
    Eigen::Vector3d e2 = d_next.cross(e1);
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<GyroRotationResidual, 2, 9, 3>(
            new GyroRotationResidual{&rates, &dt, static_cast<size_t>(poses[k].end),
                                     static_cast<size_t>(poses[k + 1].begin), d_k, e1, e2}),
        nullptr, x, bias);
    used_pairs.push_back(k);
    ++used;
  }
  if (used < 5) {
    throw SpecError("data",
                    fmt::format("no motion between poses: only {} of {} consecutive pose pairs "
                                "rotate by more than {:.3g} deg; the 9 gyro parameters need at "
                                "least 5 rotations about different axes",
                                used, poses.size() - 1, options.min_rotation_rad * 180.0 / M_PI),
                    0);
  }
  out.fit.poses_used = used + 1;
  std::vector<std::string> units(9, "1");
  for (int i = 3; i < 9; ++i) units[i] = "rad";
  problem.SetParameterBlockConstant(bias);
  Eigen::MatrixXd cov_x, full_covariance;
  detail::SolveAndReport(&problem, x, 9, GyroParameterNames(), units, &out.fit, &cov_x);
  out.T_g = GyroMatrix(x);
  // Propagate the bias error: Cov_x += A Cov_b A^T, A = -(J_x^T J_x)^-1 J_x^T J_b.
  {
    problem.SetParameterBlockVariable(bias);
    ceres::Problem::EvaluateOptions eval;
    eval.parameter_blocks = {x, bias};
    ceres::CRSMatrix crs;
    problem.Evaluate(eval, nullptr, nullptr, nullptr, &crs);
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
    for (int r = 0; r < crs.num_rows; ++r) {
      for (int i = crs.rows[r]; i < crs.rows[r + 1]; ++i) J(r, crs.cols[i]) = crs.values[i];
    }
    const Eigen::MatrixXd Jx = J.leftCols(9), Jb = J.rightCols(3);
    const Eigen::MatrixXd A = -(Jx.transpose() * Jx).ldlt().solve(Jx.transpose() * Jb);
    const Eigen::Vector3d var_b =
        init.std_omega_ib_s.cwiseAbs2() / static_cast<double>(init.count());
    cov_x += A * var_b.asDiagonal() * A.transpose();
    // Accelerometer calibration error: J_a by central differences of the residuals.
    if (accel.covariance.rows() == 9) {
      const int m = static_cast<int>(Jx.rows());
      auto residuals_with = [&](const AccelCalibration& a) {
        Eigen::VectorXd r(m);
        for (size_t j = 0; j < used_pairs.size(); ++j) {
          const size_t k = used_pairs[j];
          const Eigen::Vector3d d_k = -a.Apply(poses[k].mean_f_ib_s).normalized();
          const Eigen::Vector3d d_next = -a.Apply(poses[k + 1].mean_f_ib_s).normalized();
          const Eigen::Vector3d e1 = d_next.unitOrthogonal();
          const GyroRotationResidual f{&rates,
                                       &dt,
                                       static_cast<size_t>(poses[k].end),
                                       static_cast<size_t>(poses[k + 1].begin),
                                       d_k,
                                       e1,
                                       d_next.cross(e1)};
          f(x, bias, r.data() + 2 * j);
        }
        return r;
      };
      Eigen::MatrixXd Ja(m, 9);
      for (int p = 0; p < 9; ++p) {
        const double h = 1e-6 * (p < 6 ? 1.0 : 10.0);  // [-] or [rad]; [m/s^2] for biases
        AccelCalibration plus = accel, minus = accel;
        auto perturb = [&](AccelCalibration* a, double d) {
          static constexpr int kRow[6] = {0, 1, 2, 1, 2, 2}, kCol[6] = {0, 1, 2, 0, 0, 1};
          if (p < 6)
            a->T_a(kRow[p], kCol[p]) += d;
          else
            a->b_a[p - 6] += d;
        };
        perturb(&plus, h);
        perturb(&minus, -h);
        Ja.col(p) = (residuals_with(plus) - residuals_with(minus)) / (2.0 * h);
      }
      const Eigen::MatrixXd Aa = -(Jx.transpose() * Jx).ldlt().solve(Jx.transpose() * Ja);
      cov_x += Aa * accel.covariance * Aa.transpose();
    }
    for (int i = 0; i < 9; ++i) out.fit.parameters[i].sigma = std::sqrt(cov_x(i, i));
    // Covariance of (S, M, b_g) for the correlation matrix: Cov(x, b) = A Cov_b.
    full_covariance = Eigen::MatrixXd::Zero(12, 12);
    full_covariance.topLeftCorner(9, 9) = cov_x;
    full_covariance.topRightCorner(9, 3) = A * var_b.asDiagonal();
    full_covariance.bottomLeftCorner(3, 9) = full_covariance.topRightCorner(9, 3).transpose();
    full_covariance.bottomRightCorner(3, 3) = var_b.asDiagonal();
  }
  // Bias from the initial static period; 1 sigma = sample std / sqrt(samples) (white noise).
  const char* axes = "xyz";
  for (int i = 0; i < 3; ++i) {
    out.fit.parameters.push_back({fmt::format("gyro.bias.{}", axes[i]), out.b_g[i], "rad/s",
                                  init.std_omega_ib_s[i] / std::sqrt(double(init.count()))});
  }
  out.fit.SetCorrelation(full_covariance);
  out.fit.messages.push_back(fmt::format(
      "gyro bias from the initial static period ({:.1f} s, {} samples); Earth rate is not "
      "modelled (error up to 7.3e-5 rad/s x rotation time)",
      init.t_end_s - init.t_begin_s, init.count()));
  return out;
}

void CalibrationFit::SetCorrelation(const Eigen::MatrixXd& covariance) {
  const size_t n = parameters.size();
  const auto m = static_cast<size_t>(covariance.rows());
  correlation.assign(n * n, 0.0);
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = 0; j < n; ++j) {
      if (i == j) {
        correlation[i * n + j] = 1.0;
      } else if (i < m && j < m) {
        const double d = std::sqrt(covariance(i, i) * covariance(j, j));
        correlation[i * n + j] = d > 0 ? covariance(i, j) / d : 0.0;
      }
    }
  }
}

void TruthInCalibrationFrame(const Eigen::Matrix3d& T_a_full, const Eigen::Matrix3d& T_g_full,
                             Eigen::Matrix3d* T_a, Eigen::Matrix3d* T_g) {
  Eigen::HouseholderQR<Eigen::Matrix3d> qr(T_a_full.transpose());
  Eigen::Matrix3d Q = qr.householderQ();
  Eigen::Matrix3d R = qr.matrixQR().triangularView<Eigen::Upper>();
  for (int i = 0; i < 3; ++i) {
    if (R(i, i) < 0.0) {
      R.row(i) *= -1.0;
      Q.col(i) *= -1.0;
    }
  }
  *T_a = R.transpose();
  *T_g = T_g_full * Q;
}

}  // namespace driftlab::calib
