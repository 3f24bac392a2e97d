#include "driftlab/error_state.h"

#include <cmath>
#include <unsupported/Eigen/MatrixFunctions>

#include "driftlab/attitude.h"

namespace driftlab {
namespace {

// One triad's bias as a single state per axis; appends the unrepresentable terms.
BiasStateModel BiasModelOf(const TriadErrorParams& p, const std::string& path,
                           std::vector<std::string>* unrepresented) {
  BiasStateModel b;
  const bool turn_on = p.turn_on_bias_sigma > 0.0;
  const bool gm = p.bias_gauss_markov.sigma > 0.0;
  const bool rw = p.random_walk > 0.0;
  if (gm) {
    // A bias started at 0 (gnss-ins-sim's convention) has no initial uncertainty.
    b.initial_sigma = p.bias_gauss_markov.start_at_zero ? 0.0 : p.bias_gauss_markov.sigma;
    b.tau_s = p.bias_gauss_markov.tau_s;
    b.driving_psd = 2.0 * p.bias_gauss_markov.sigma * p.bias_gauss_markov.sigma / b.tau_s;
    if (turn_on) unrepresented->push_back(path + ".turn_on_bias_sigma");
    if (rw) unrepresented->push_back(path + ".random_walk");
  } else if (rw) {
    b.driving_psd = p.random_walk * p.random_walk;
    if (turn_on) unrepresented->push_back(path + ".turn_on_bias_sigma");
  } else {
    b.initial_sigma = p.turn_on_bias_sigma;
  }
  if (!p.fixed_bias.isZero(0.0)) unrepresented->push_back(path + ".fixed_bias");
  if (p.bias_flicker.bias_instability > 0.0) unrepresented->push_back(path + ".bias_flicker");
  if (!p.scale_factor_fixed.isZero(0.0) || p.scale_factor_sigma > 0.0 ||
      !p.scale_factor_asymmetry.isZero(0.0)) {
    unrepresented->push_back(path + ".scale_factor");
  }
  if (!p.misalignment_fixed.isZero(0.0) || p.misalignment_sigma_rad > 0.0) {
    unrepresented->push_back(path + ".misalignment");
  }
  if (p.quantization > 0.0) unrepresented->push_back(path + ".quantization");
  if (p.range > 0.0) unrepresented->push_back(path + ".range (saturation, if reached)");
  return b;
}

}  // namespace

ErrorStateNoiseFromImu MakeErrorStateNoise(const ImuErrorModel& model, const std::string& path) {
  ErrorStateNoiseFromImu out;
  out.noise.gyro_white_psd = model.gyro.white_noise_density * model.gyro.white_noise_density;
  out.noise.accel_white_psd = model.accel.white_noise_density * model.accel.white_noise_density;
  out.noise.gyro_bias = BiasModelOf(model.gyro, path + ".gyro", &out.unrepresented);
  out.noise.accel_bias = BiasModelOf(model.accel, path + ".accel", &out.unrepresented);
  if (!model.gyro_g_sensitivity.isZero(0.0)) {
    out.unrepresented.push_back(path + ".gyro_g_sensitivity");
  }
  return out;
}

ErrorStateMatrix ErrorStateSystemMatrix(const NavEnvironment& env, const NavState& reference,
                                        const Vector3d& f_ib_b, const ErrorStateNoise& noise) {
  const double L = reference.llh.lat_rad;
  const double h = reference.llh.h_m;
  const Vector3d& v = reference.v_eb_n;
  const double RN = env.MeridianRadiusAt(L) + h;
  const double RE = env.TransverseRadiusAt(L) + h;
  const double tanL = std::tan(L);
  const Matrix3d C_b_n = reference.C_b_n();
  const Vector3d omega_ie_n = env.EarthRate(L);
  const Vector3d omega_en_n = env.TransportRate(L, h, v);
  const bool curved = env.model() == EarthModel::kWgs84;

  // d(omega_ie_n) / d(dr): only through dL = dr_N / RN: omega_ie [-sin L, 0, -cos L] / RN,
  // written from the vector itself so that the flat model (zero rate) gives zero.
  Matrix3d Wie_r = Matrix3d::Zero();
  Wie_r.col(0) = Vector3d(omega_ie_n.z(), 0.0, -omega_ie_n.x()) / RN;
  // d(omega_en_n) (Groves (5.44) differentiated; dR/dL neglected, O(e^2)):
  //   d/dv_N = [0, -1/RN, 0], d/dv_E = [1/RE, 0, -tan L/RE],
  //   d/dL = [0, 0, -v_E sec^2 L / RE], d/dh = [-v_E/RE^2, v_N/RN^2, v_E tan L/RE^2].
  Matrix3d Wen_v = Matrix3d::Zero(), Wen_r = Matrix3d::Zero();
  if (curved) {
    Wen_v(1, 0) = -1.0 / RN;
    Wen_v(0, 1) = 1.0 / RE;
    Wen_v(2, 1) = -tanL / RE;
    const double cosL = std::cos(L);
    Wen_r(2, 0) = -v.y() / (RE * cosL * cosL) / RN;  // dL = dr_N / RN
    // dh = -dr_D
    Wen_r(0, 2) = v.y() / (RE * RE);
    Wen_r(1, 2) = -v.x() / (RN * RN);
    Wen_r(2, 2) = -v.y() * tanL / (RE * RE);
  }

  ErrorStateMatrix F = ErrorStateMatrix::Zero();
  // Attitude: psi' = -omega_in x psi + C_b_n b_g - d(omega_in).
  F.block<3, 3>(kErrAttitude, kErrAttitude) = -Skew(omega_ie_n + omega_en_n);
  F.block<3, 3>(kErrAttitude, kErrVelocity) = -Wen_v;
  F.block<3, 3>(kErrAttitude, kErrPosition) = -(Wie_r + Wen_r);
  F.block<3, 3>(kErrAttitude, kErrGyroBias) = C_b_n;
  // Velocity.
  const Matrix3d V = Skew(v);
  F.block<3, 3>(kErrVelocity, kErrAttitude) = -Skew(C_b_n * f_ib_b);
  F.block<3, 3>(kErrVelocity, kErrVelocity) = -Skew(2.0 * omega_ie_n + omega_en_n) + V * Wen_v;
  F.block<3, 3>(kErrVelocity, kErrPosition) = V * (2.0 * Wie_r + Wen_r);
  // Vertical gravity gradient, central difference (g_D is quadratic in h: exact to rounding).
  const double dgD_dh = 0.5 * (env.Gravity(L, h + 1.0).z() - env.Gravity(L, h - 1.0).z());
  F(kErrVelocity + 2, kErrPosition + 2) += -dgD_dh;  // dh = -dr_D
  F.block<3, 3>(kErrVelocity, kErrAccelBias) = C_b_n;
  // Position (metres at the true point).
  F.block<3, 3>(kErrPosition, kErrVelocity) = Matrix3d::Identity();
  if (curved) {
    F(0, 0) += -v.z() / RN;
    F(0, 2) += v.x() / RN;
    F(1, 0) += v.y() * tanL / RN;
    F(1, 1) += -v.z() / RE - v.x() * tanL / RN;
    F(1, 2) += v.y() / RE;
  }
  // Biases.
  if (noise.accel_bias.tau_s > 0.0) {
    F.block<3, 3>(kErrAccelBias, kErrAccelBias) = -Matrix3d::Identity() / noise.accel_bias.tau_s;
  }
  if (noise.gyro_bias.tau_s > 0.0) {
    F.block<3, 3>(kErrGyroBias, kErrGyroBias) = -Matrix3d::Identity() / noise.gyro_bias.tau_s;
  }
  return F;
}

ErrorStateMatrix ErrorStateProcessNoise(const ErrorStateNoise& noise) {
  ErrorStateMatrix Q = ErrorStateMatrix::Zero();
  for (int i = 0; i < 3; ++i) {
    Q(kErrVelocity + i, kErrVelocity + i) = noise.accel_white_psd;
    Q(kErrAttitude + i, kErrAttitude + i) = noise.gyro_white_psd;
    Q(kErrAccelBias + i, kErrAccelBias + i) = noise.accel_bias.driving_psd;
    Q(kErrGyroBias + i, kErrGyroBias + i) = noise.gyro_bias.driving_psd;
  }
  return Q;
}

void DiscretizeErrorModel(const ErrorStateMatrix& F, const ErrorStateMatrix& Q_c, double dt_s,
                          Discretization method, ErrorStateMatrix* Phi, ErrorStateMatrix* Q_d) {
  constexpr int n = kNumErrorStates;
  if (method == Discretization::kVanLoan) {
    Eigen::Matrix<double, 2 * n, 2 * n> A = Eigen::Matrix<double, 2 * n, 2 * n>::Zero();
    A.topLeftCorner<n, n>() = -F * dt_s;
    A.topRightCorner<n, n>() = Q_c * dt_s;
    A.bottomRightCorner<n, n>() = F.transpose() * dt_s;
    const Eigen::Matrix<double, 2 * n, 2 * n> B = A.exp();
    *Phi = B.bottomRightCorner<n, n>().transpose();
    *Q_d = *Phi * B.topRightCorner<n, n>();
    *Q_d = 0.5 * (*Q_d + Q_d->transpose()).eval();
    return;
  }
  const ErrorStateMatrix Fdt = F * dt_s;
  *Phi = ErrorStateMatrix::Identity() + Fdt + 0.5 * Fdt * Fdt;
  *Q_d = 0.5 * dt_s * (*Phi * Q_c * Phi->transpose() + Q_c);
}

Matrix3d EulerErrorFromAttitudeError(const EulerAngles& e) {
  const double cy = std::cos(e.yaw_rad), sy = std::sin(e.yaw_rad);
  const double cp = std::cos(e.pitch_rad), sp = std::sin(e.pitch_rad);
  Matrix3d E;
  E.col(0) = Vector3d(cp * cy, cp * sy, -sp);  // roll axis: Rz Ry x
  E.col(1) = Vector3d(-sy, cy, 0.0);           // pitch axis: Rz y
  E.col(2) = Vector3d(0.0, 0.0, 1.0);          // yaw axis: z
  return E.inverse();
}

ErrorStateMatrix InitialErrorCovariance(const Vector3d& position_sigma_ned_m,
                                        const Vector3d& velocity_sigma_ned_m_per_s,
                                        const Vector3d& euler_sigma_rad,
                                        const EulerAngles& attitude, const ErrorStateNoise& noise) {
  ErrorStateMatrix P = ErrorStateMatrix::Zero();
  P.block<3, 3>(kErrPosition, kErrPosition) = position_sigma_ned_m.cwiseAbs2().asDiagonal();
  P.block<3, 3>(kErrVelocity, kErrVelocity) = velocity_sigma_ned_m_per_s.cwiseAbs2().asDiagonal();
  const Matrix3d E = EulerErrorFromAttitudeError(attitude).inverse();
  P.block<3, 3>(kErrAttitude, kErrAttitude) =
      E * euler_sigma_rad.cwiseAbs2().asDiagonal() * E.transpose();
  const double sa = noise.accel_bias.initial_sigma, sg = noise.gyro_bias.initial_sigma;
  P.block<3, 3>(kErrAccelBias, kErrAccelBias) = sa * sa * Matrix3d::Identity();
  P.block<3, 3>(kErrGyroBias, kErrGyroBias) = sg * sg * Matrix3d::Identity();
  return P;
}

}  // namespace driftlab
