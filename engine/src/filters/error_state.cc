#include "driftlab/error_state.h"

#include <algorithm>
#include <cmath>
#include <unsupported/Eigen/MatrixFunctions>
#include <utility>

#include "driftlab/attitude.h"
#include "driftlab/elementary.h"
#include "driftlab/sensors.h"

namespace driftlab {
namespace {

bool HasScaleMisalignment(const ScaleMisalignmentModel& m) {
  return m.scale_factor_sigma > 0.0 || m.misalignment_sigma_rad > 0.0;
}

// One triad's stochastic bias processes as states; appends the left-out terms.
void BiasModelOf(const TriadErrorParams& p, const std::string& path,
                 const ErrorModelOptions& options, BiasStateModel* primary,
                 std::vector<BiasStateModel>* extra, std::vector<std::string>* unrepresented) {
  *primary = BiasStateModel{};
  extra->clear();
  // Turn-on bias and random walk share one state: b(0) ~ N(0, s0^2), b' = w, PSD K^2.
  const bool turn_on = p.turn_on_bias_sigma > 0.0;
  const bool rw = p.random_walk > 0.0;
  const bool gm = p.bias_gauss_markov.sigma > 0.0;
  BiasStateModel gm_state;
  if (gm) {
    // First-order Gauss-Markov b' = -b / tau + w, PSD 2 sigma^2 / tau (Maybeck vol. 1, 4.11); a
    // bias started at 0 (gnss-ins-sim's convention) has no initial uncertainty.
    gm_state.initial_sigma = p.bias_gauss_markov.start_at_zero ? 0.0 : p.bias_gauss_markov.sigma;
    gm_state.tau_s = p.bias_gauss_markov.tau_s;
    gm_state.source = BiasStateSource::kGaussMarkov;
    gm_state.driving_psd =
        2.0 * p.bias_gauss_markov.sigma * p.bias_gauss_markov.sigma / p.bias_gauss_markov.tau_s;
  }
  BiasStateModel walk;
  walk.initial_sigma = p.turn_on_bias_sigma;
  walk.driving_psd = p.random_walk * p.random_walk;
  std::vector<BiasStateModel> states;
  if (turn_on || rw) states.push_back(walk);
  if (gm) states.push_back(gm_state);
  if (p.bias_flicker.bias_instability > 0.0) {
    for (const BiasStateModel& f :
         FitFlickerStates(p.bias_flicker, options.flicker_states_per_axis, options.time_scale_min_s,
                          options.time_scale_max_s)) {
      states.push_back(f);
    }
  }
  if (!states.empty()) {
    *primary = states[0];
    extra->assign(states.begin() + 1, states.end());
  }
  if (!p.fixed_bias.isZero(0.0)) {
    unrepresented->push_back(path +
                             ".fixed_bias (deterministic: the same error in every run, a mean "
                             "the filter does not estimate beyond its bias states)");
  }
  if (!p.scale_factor_fixed.isZero(0.0) || !p.scale_factor_asymmetry.isZero(0.0)) {
    unrepresented->push_back(path +
                             ".scale_factor_fixed/asymmetry (deterministic: error proportional "
                             "to the rate or specific force, the same in every run)");
  }
  if (!p.misalignment_fixed.isZero(0.0)) {
    unrepresented->push_back(path +
                             ".misalignment_fixed (deterministic: cross-axis error, the same in "
                             "every run)");
  }
  if (p.quantization > 0.0) {
    unrepresented->push_back(path +
                             ".quantization (white to first order, variance LSB^2 / 12 per "
                             "sample, carried remainder: bounded, negligible above 1 LSB)");
  }
  if (p.range > 0.0) {
    unrepresented->push_back(path + ".range (saturation: no effect unless the motion reaches it)");
  }
}

ScaleMisalignmentModel ScaleMisalignmentOf(const TriadErrorParams& p) {
  return ScaleMisalignmentModel{p.scale_factor_sigma, p.misalignment_sigma_rad};
}

// Conservative white-noise bound of a triad's random scale-factor and misalignment errors when
// they are not states. The error on axis i is e_i(t) = s_i m_i(t) + sum_{j != i} M_ij m_j(t) with
// random constants s_i ~ N(0, sigma_s^2), M_ij ~ N(0, sigma_m^2); over any window of length
// tau <= T its integral has variance <= (sigma_s^2 m_max,i^2 + sigma_m^2 sum_{j != i}
// m_max,j^2) tau^2 <= q_i tau with
//   q_i = (sigma_s^2 m_max,i^2 + sigma_m^2 sum_{j != i} m_max,j^2) T,
// the variance a white noise of PSD q_i adds over tau. So white noise of PSD max_i q_i (isotropic,
// as the error model's white terms) bounds the integrated error's variance over every unaided
// stretch up to T (the longest interval without aiding).
double ScaleMisalignmentWhiteBound(const ScaleMisalignmentModel& m, const Vector3d& max_abs_b,
                                   double T_s) {
  double q = 0.0;
  for (int i = 0; i < 3; ++i) {
    double cross = 0.0;
    for (int j = 0; j < 3; ++j) {
      if (j != i) cross += max_abs_b[j] * max_abs_b[j];
    }
    q = std::max(q, m.scale_factor_sigma * m.scale_factor_sigma * max_abs_b[i] * max_abs_b[i] +
                        m.misalignment_sigma_rad * m.misalignment_sigma_rad * cross);
  }
  return q * T_s;
}

}  // namespace

ErrorStateLayout::ErrorStateLayout(const ErrorStateNoise& noise) {
  int next = kNumErrorStates;
  auto take = [&next](int count) {
    const int first = next;
    next += count;
    return first;
  };
  for (size_t i = 0; i < noise.accel_bias_extra.size(); ++i) accel_bias_extra.push_back(take(3));
  for (size_t i = 0; i < noise.gyro_bias_extra.size(); ++i) gyro_bias_extra.push_back(take(3));
  if (HasScaleMisalignment(noise.gyro_scale_misalignment)) {
    gyro_scale = take(3);
    gyro_misalignment = take(6);
  }
  if (HasScaleMisalignment(noise.accel_scale_misalignment)) {
    accel_scale = take(3);
    accel_misalignment = take(6);
  }
  for (const AidingErrorStates& a : noise.aiding_states) {
    aiding.push_back(take(static_cast<int>(a.sigma.size())));
  }
  size = next;
}

int ErrorStateLayout::AidingFirst(const ErrorStateNoise& noise, const std::string& owner) const {
  for (size_t i = 0; i < noise.aiding_states.size() && i < aiding.size(); ++i) {
    if (noise.aiding_states[i].owner == owner) return aiding[i];
  }
  return -1;
}

std::vector<BiasStateModel> FitFlickerStates(const FlickerParams& flicker, int count,
                                             double t_min_s, double t_max_s) {
  const std::vector<GaussMarkovComponent> design = DesignFlickerApproximation(flicker);
  std::vector<BiasStateModel> out;
  auto gm = [](double variance, double tau_s) {
    BiasStateModel b;
    b.initial_sigma = std::sqrt(variance);  // the simulator starts flicker stationary
    b.tau_s = tau_s;
    b.driving_psd = 2.0 * variance / tau_s;
    b.source = BiasStateSource::kFlicker;
    return b;
  };
  if (design.empty()) return out;
  if (count >= static_cast<int>(design.size())) {
    for (const GaussMarkovComponent& c : design) out.push_back(gm(c.sigma * c.sigma, c.tau_s));
    return out;
  }
  count = std::max(count, 1);
  const double lo = math::Log(std::max(t_min_s, 1e-6));
  const double hi = math::Log(std::max(t_max_s, std::max(t_min_s, 1e-6) * 1.0001));
  std::vector<double> variance(static_cast<size_t>(count), 0.0);
  std::vector<double> log_tau_sum(static_cast<size_t>(count), 0.0);
  for (const GaussMarkovComponent& c : design) {
    const double x = (math::Log(c.tau_s) - lo) / (hi - lo) * count;
    const int g = std::clamp(static_cast<int>(std::floor(x)), 0, count - 1);
    variance[g] += c.sigma * c.sigma;
    log_tau_sum[g] += c.sigma * c.sigma * math::Log(c.tau_s);
  }
  for (int g = 0; g < count; ++g) {
    if (variance[g] > 0.0) out.push_back(gm(variance[g], math::Exp(log_tau_sum[g] / variance[g])));
  }
  return out;
}

ErrorStateNoiseFromImu MakeErrorStateNoise(const ImuErrorModel& model, const std::string& path,
                                           const ErrorModelOptions& options) {
  ErrorStateNoiseFromImu out;
  ErrorStateNoise& n = out.noise;
  n.gyro_white_psd = model.gyro.white_noise_density * model.gyro.white_noise_density;
  n.accel_white_psd = model.accel.white_noise_density * model.accel.white_noise_density;
  BiasModelOf(model.gyro, path + ".gyro", options, &n.gyro_bias, &n.gyro_bias_extra,
              &out.unrepresented);
  BiasModelOf(model.accel, path + ".accel", options, &n.accel_bias, &n.accel_bias_extra,
              &out.unrepresented);
  const ScaleMisalignmentModel gyro_sm = ScaleMisalignmentOf(model.gyro);
  const ScaleMisalignmentModel accel_sm = ScaleMisalignmentOf(model.accel);
  if (options.augment_scale_misalignment) {
    n.gyro_scale_misalignment = gyro_sm;
    n.accel_scale_misalignment = accel_sm;
  } else {
    const double T = options.unaided_interval_s;
    n.gyro_white_psd += ScaleMisalignmentWhiteBound(gyro_sm, options.max_abs_omega_ib_b, T);
    n.accel_white_psd += ScaleMisalignmentWhiteBound(accel_sm, options.max_abs_f_ib_b, T);
    for (const auto& [sm, name] : {std::pair{gyro_sm, ".gyro"}, std::pair{accel_sm, ".accel"}}) {
      if (HasScaleMisalignment(sm)) {
        out.unrepresented.push_back(
            path + name + ".scale_factor/misalignment (as a white-noise bound over " +
            std::to_string(T) +
            " s, filter.augment_scale_misalignment = false: conservative, NEES below its band)");
      }
    }
  }
  if (!model.gyro_g_sensitivity.isZero(0.0)) {
    out.unrepresented.push_back(path +
                                ".gyro_g_sensitivity (deterministic: rate error G f, the same in "
                                "every run; about G g while level, absorbed by the gyro bias "
                                "states while aided)");
  }
  return out;
}

ErrorStateMatrix ErrorStateSystemMatrix(const NavEnvironment& env, const NavState& reference,
                                        const Vector3d& f_ib_b, const ErrorStateNoise& noise,
                                        const Vector3d& omega_ib_b) {
  const ErrorStateLayout layout(noise);
  const double L = reference.llh.lat_rad;
  const double h = reference.llh.h_m;
  const Vector3d& v = reference.v_eb_n;
  const double RN = env.MeridianRadiusAt(L) + h;
  const double RE = env.TransverseRadiusAt(L) + h;
  const double tanL = math::Tan(L);
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
    const double cosL = math::Cos(L);
    Wen_r(2, 0) = -v.y() / (RE * cosL * cosL) / RN;  // dL = dr_N / RN
    // dh = -dr_D
    Wen_r(0, 2) = v.y() / (RE * RE);
    Wen_r(1, 2) = -v.x() / (RN * RN);
    Wen_r(2, 2) = -v.y() * tanL / (RE * RE);
  }

  ErrorStateMatrix F = ErrorStateMatrix::Zero(layout.size, layout.size);
  // Attitude: psi' = -omega_in x psi + C_b_n b_g - d(omega_in).
  F.block<3, 3>(kErrAttitude, kErrAttitude) = -Skew(omega_ie_n + omega_en_n);
  F.block<3, 3>(kErrAttitude, kErrVelocity) = -Wen_v;
  F.block<3, 3>(kErrAttitude, kErrPosition) = -(Wie_r + Wen_r);
  // Velocity.
  const Matrix3d V = Skew(v);
  F.block<3, 3>(kErrVelocity, kErrAttitude) = -Skew(C_b_n * f_ib_b);
  F.block<3, 3>(kErrVelocity, kErrVelocity) = -Skew(2.0 * omega_ie_n + omega_en_n) + V * Wen_v;
  F.block<3, 3>(kErrVelocity, kErrPosition) = V * (2.0 * Wie_r + Wen_r);
  // Vertical gravity gradient, central difference (g_D is quadratic in h: exact to rounding).
  const double dgD_dh = 0.5 * (env.Gravity(L, h + 1.0).z() - env.Gravity(L, h - 1.0).z());
  F(kErrVelocity + 2, kErrPosition + 2) += -dgD_dh;  // dh = -dr_D
  // Position (metres at the true point).
  F.block<3, 3>(kErrPosition, kErrVelocity) = Matrix3d::Identity();
  if (curved) {
    F(0, 0) += -v.z() / RN;
    F(0, 2) += v.x() / RN;
    F(1, 0) += v.y() * tanL / RN;
    F(1, 1) += -v.z() / RE - v.x() * tanL / RN;
    F(1, 2) += v.y() / RE;
  }
  // Sensor errors into the navigation rows (ErrorStateSensorCoupling); biases: b' = -b / tau
  // (Gauss-Markov) or 0.
  std::vector<SensorStateCoupling> coupling;
  ErrorStateSensorCoupling(layout, f_ib_b, omega_ib_b, &coupling);
  for (int j = kNumNavErrorStates; j < layout.size; ++j) {
    const SensorStateCoupling& c = coupling[static_cast<size_t>(j - kNumNavErrorStates)];
    if (c.coupled) F.block<3, 1>(c.nav_rows, j) = C_b_n.col(c.axis) * c.weight;
  }
  auto bias_decay = [&](int first, const BiasStateModel& b) {
    if (b.tau_s > 0.0) F.block<3, 3>(first, first) = -Matrix3d::Identity() / b.tau_s;
  };
  bias_decay(kErrAccelBias, noise.accel_bias);
  bias_decay(kErrGyroBias, noise.gyro_bias);
  for (size_t i = 0; i < layout.accel_bias_extra.size(); ++i) {
    bias_decay(layout.accel_bias_extra[i], noise.accel_bias_extra[i]);
  }
  for (size_t i = 0; i < layout.gyro_bias_extra.size(); ++i) {
    bias_decay(layout.gyro_bias_extra[i], noise.gyro_bias_extra[i]);
  }
  // Aiding errors: e' = -e / tau (Gauss-Markov) or 0 (random constants).
  for (size_t b = 0; b < noise.aiding_states.size(); ++b) {
    const AidingErrorStates& a = noise.aiding_states[b];
    if (!(a.tau_s > 0.0)) continue;
    for (size_t i = 0; i < a.sigma.size(); ++i) {
      const int j = layout.aiding[b] + static_cast<int>(i);
      F(j, j) = -1.0 / a.tau_s;
    }
  }
  return F;
}

void ErrorStateSensorCoupling(const ErrorStateLayout& layout, const Vector3d& f_ib_b,
                              const Vector3d& omega_ib_b, std::vector<SensorStateCoupling>* out) {
  out->assign(static_cast<size_t>(layout.size - kNumNavErrorStates), SensorStateCoupling{});
  auto set = [out](int state, int nav_rows, int axis, double weight) {
    (*out)[static_cast<size_t>(state - kNumNavErrorStates)] = {true, nav_rows, axis, weight};
  };
  // Biases: the bias of body axis i adds C_b_n.col(i) to the velocity (accelerometer) or attitude
  // (gyro) error rate.
  auto bias = [&](int first, int nav_rows) {
    for (int i = 0; i < 3; ++i) set(first + i, nav_rows, i, 1.0);
  };
  bias(kErrAccelBias, kErrVelocity);
  bias(kErrGyroBias, kErrAttitude);
  for (const int first : layout.accel_bias_extra) bias(first, kErrVelocity);
  for (const int first : layout.gyro_bias_extra) bias(first, kErrAttitude);
  // Scale factor / misalignment (random constants): d(error of m) / d s_i = m_i e_i,
  // d / d M_ij = m_j e_i, resolved in n by C_b_n (Groves 2nd ed. (4.17), (14.98)).
  auto scale_misalignment = [&](int scale, int mis, int nav_rows, const Vector3d& m_b) {
    if (scale < 0) return;
    for (int i = 0; i < 3; ++i) set(scale + i, nav_rows, i, m_b[i]);
    for (int k = 0; k < 6; ++k)
      set(mis + k, nav_rows, kMisalignmentRow[k], m_b[kMisalignmentCol[k]]);
  };
  scale_misalignment(layout.gyro_scale, layout.gyro_misalignment, kErrAttitude, omega_ib_b);
  scale_misalignment(layout.accel_scale, layout.accel_misalignment, kErrVelocity, f_ib_b);
}

ErrorStateMatrix ErrorStateProcessNoise(const ErrorStateNoise& noise) {
  const ErrorStateLayout layout(noise);
  ErrorStateMatrix Q = ErrorStateMatrix::Zero(layout.size, layout.size);
  auto diag3 = [&Q](int first, double q) {
    for (int i = 0; i < 3; ++i) Q(first + i, first + i) = q;
  };
  diag3(kErrVelocity, noise.accel_white_psd);
  diag3(kErrAttitude, noise.gyro_white_psd);
  diag3(kErrAccelBias, noise.accel_bias.driving_psd);
  diag3(kErrGyroBias, noise.gyro_bias.driving_psd);
  for (size_t i = 0; i < layout.accel_bias_extra.size(); ++i) {
    diag3(layout.accel_bias_extra[i], noise.accel_bias_extra[i].driving_psd);
  }
  for (size_t i = 0; i < layout.gyro_bias_extra.size(); ++i) {
    diag3(layout.gyro_bias_extra[i], noise.gyro_bias_extra[i].driving_psd);
  }
  // Gauss-Markov aiding errors: PSD 2 sigma^2 / tau (stationary variance sigma^2); random
  // constants none.
  for (size_t b = 0; b < noise.aiding_states.size(); ++b) {
    const AidingErrorStates& a = noise.aiding_states[b];
    if (!(a.tau_s > 0.0)) continue;
    for (size_t i = 0; i < a.sigma.size(); ++i) {
      const int j = layout.aiding[b] + static_cast<int>(i);
      const double s = a.sigma[i];
      Q(j, j) = 2.0 * s * s / a.tau_s;
    }
  }
  return Q;
}

void DiscretizeErrorModel(const ErrorStateMatrix& F, const ErrorStateMatrix& Q_c, double dt_s,
                          Discretization method, ErrorStateMatrix* Phi, ErrorStateMatrix* Q_d) {
  const Eigen::Index n = F.rows();
  if (method == Discretization::kVanLoan) {
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * n, 2 * n);
    A.topLeftCorner(n, n) = -F * dt_s;
    A.topRightCorner(n, n) = Q_c * dt_s;
    A.bottomRightCorner(n, n) = F.transpose() * dt_s;
    const Eigen::MatrixXd B = A.exp();
    *Phi = B.bottomRightCorner(n, n).transpose();
    *Q_d = *Phi * B.topRightCorner(n, n);
    *Q_d = 0.5 * (*Q_d + Q_d->transpose()).eval();
    return;
  }
  const ErrorStateMatrix Fdt = F * dt_s;
  *Phi = ErrorStateMatrix::Identity(n, n) + Fdt + 0.5 * Fdt * Fdt;
  *Q_d = 0.5 * dt_s * (*Phi * Q_c * Phi->transpose() + Q_c);
}

Matrix3d EulerErrorFromAttitudeError(const EulerAngles& e) {
  const double cy = math::Cos(e.yaw_rad), sy = math::Sin(e.yaw_rad);
  const double cp = math::Cos(e.pitch_rad), sp = math::Sin(e.pitch_rad);
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
  const ErrorStateLayout layout(noise);
  ErrorStateMatrix P = ErrorStateMatrix::Zero(layout.size, layout.size);
  P.block<3, 3>(kErrPosition, kErrPosition) = position_sigma_ned_m.cwiseAbs2().asDiagonal();
  P.block<3, 3>(kErrVelocity, kErrVelocity) = velocity_sigma_ned_m_per_s.cwiseAbs2().asDiagonal();
  const Matrix3d E = EulerErrorFromAttitudeError(attitude).inverse();
  P.block<3, 3>(kErrAttitude, kErrAttitude) =
      E * euler_sigma_rad.cwiseAbs2().asDiagonal() * E.transpose();
  auto diag = [&P](int first, int count, double sigma) {
    for (int i = 0; i < count; ++i) P(first + i, first + i) = sigma * sigma;
  };
  diag(kErrAccelBias, 3, noise.accel_bias.initial_sigma);
  diag(kErrGyroBias, 3, noise.gyro_bias.initial_sigma);
  for (size_t i = 0; i < layout.accel_bias_extra.size(); ++i) {
    diag(layout.accel_bias_extra[i], 3, noise.accel_bias_extra[i].initial_sigma);
  }
  for (size_t i = 0; i < layout.gyro_bias_extra.size(); ++i) {
    diag(layout.gyro_bias_extra[i], 3, noise.gyro_bias_extra[i].initial_sigma);
  }
  if (layout.gyro_scale >= 0) {
    diag(layout.gyro_scale, 3, noise.gyro_scale_misalignment.scale_factor_sigma);
    diag(layout.gyro_misalignment, 6, noise.gyro_scale_misalignment.misalignment_sigma_rad);
  }
  if (layout.accel_scale >= 0) {
    diag(layout.accel_scale, 3, noise.accel_scale_misalignment.scale_factor_sigma);
    diag(layout.accel_misalignment, 6, noise.accel_scale_misalignment.misalignment_sigma_rad);
  }
  for (size_t b = 0; b < noise.aiding_states.size(); ++b) {
    const AidingErrorStates& a = noise.aiding_states[b];
    for (size_t i = 0; i < a.sigma.size(); ++i) {
      diag(layout.aiding[b] + static_cast<int>(i), 1, a.sigma[i]);
    }
  }
  return P;
}

}  // namespace driftlab
