// Navigation start states of the runs: the initial-error draws, the static alignment (levelling
// and gyrocompassing) and the per-job gyrocompass decision.
#include <cmath>
#include <limits>

#include "driftlab/attitude.h"
#include "driftlab/elementary.h"
#include "driftlab/random.h"
#include "montecarlo/internal.h"

namespace driftlab {
namespace mc_detail {

Eigen::Vector3d InitialErrorDraw(uint64_t seed, uint32_t run, uint8_t component,
                                 const Eigen::Vector3d& sigma) {
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  for (int axis = 0; axis < 3; ++axis) {
    if (sigma[axis] == 0.0) continue;
    const RandomStream stream(seed, run,
                              StreamKey{SensorId::kInitialConditions, static_cast<uint8_t>(axis),
                                        ErrorTerm::kInitialError, component});
    out[axis] = sigma[axis] * stream.Gaussian(0);
  }
  return out;
}

NavState PerturbedStart(const SharedTruth& s, const MonteCarloSpec& spec, uint32_t run) {
  const InitialErrorSigmas& errors = spec.initial_errors;
  NavState init = s.truth_start;
  Eigen::Vector3d dr = InitialErrorDraw(spec.seed, run, 0, errors.position_ned_m);
  Eigen::Vector3d dv = InitialErrorDraw(spec.seed, run, 1, errors.velocity_ned_m_per_s);
  // The fixed parts only where given, so that a job without them keeps its bits (-0 + 0 = +0).
  if (!errors.fixed_position_ned_m.isZero(0.0)) dr += errors.fixed_position_ned_m;
  if (!errors.fixed_velocity_ned_m_per_s.isZero(0.0)) dv += errors.fixed_velocity_ned_m_per_s;
  // Curvilinear position offset with the environment's radii (as PositionErrorNed measures it).
  const double L = init.llh.lat_rad;
  const double h = init.llh.h_m;
  init.llh.lat_rad += dr.x() / (s.env.MeridianRadiusAt(L) + h);
  init.llh.lon_rad += dr.y() / ((s.env.TransverseRadiusAt(L) + h) * math::Cos(L));
  init.llh.h_m -= dr.z();
  init.v_eb_n += dv;
  return init;
}

// Mechanization A's state at navigation start s0 for `run`: the truth at s0 plus the run's

NavState NedStartState(const SharedTruth& s, const MonteCarloSpec& spec, uint32_t run,
                       bool gyrocompass, const Eigen::Vector3d& sum_dtheta,
                       const Eigen::Vector3d& sum_dv) {
  NavState init = PerturbedStart(s, spec, run);
  if (spec.initialization == InitializationKind::kStaticAlignment) {
    const double T = static_cast<double>(s.start_step) * s.dt_s;
    const Eigen::Vector3d f = sum_dv / T;
    const Eigen::Vector3d w = sum_dtheta / T;
    EulerAngles e;
    e.roll_rad = math::Atan2(-f.y(), -f.z());
    e.pitch_rad = math::Atan(f.x() / math::Hypot(f.y(), f.z()));
    if (gyrocompass) {
      const double sr = math::Sin(e.roll_rad), cr = math::Cos(e.roll_rad);
      const double sp = math::Sin(e.pitch_rad), cp = math::Cos(e.pitch_rad);
      e.yaw_rad =
          math::Atan2(-w.y() * cr + w.z() * sr, w.x() * cp + (w.y() * sr + w.z() * cr) * sp);
    } else {
      const Eigen::Vector3d heading_sigma(0.0, 0.0, *spec.alignment.heading_sigma_rad);
      e.yaw_rad = WrapPi(s.truth_start.euler().yaw_rad +
                         InitialErrorDraw(spec.seed, run, 3, heading_sigma).z());
    }
    init.q_b_n = Quaterniond(EulerToDcm(e));
  } else {
    const InitialErrorSigmas& errors = spec.initial_errors;
    EulerAngles e = s.truth_start.euler();
    const Eigen::Vector3d da = InitialErrorDraw(spec.seed, run, 2, errors.attitude_rad);
    e.roll_rad += da.x();
    e.pitch_rad += da.y();
    e.yaw_rad += da.z();
    if (errors.attitude_ned_rad.isZero(0.0) && errors.fixed_attitude_ned_rad.isZero(0.0)) {
      init.q_b_n = Quaterniond(EulerToDcm(e));
    } else {
      // The attitude error as a rotation about the navigation axes:
      //   C_b_n(start) = exp([psi x]) C_b_n,  psi = fixed + N(0, sigma^2) per axis
      // (psi_nb_n of attitude.h AttitudeErrorNed; Groves 2nd ed. (5.73) for the exponential).
      const Eigen::Vector3d psi = errors.fixed_attitude_ned_rad +
                                  InitialErrorDraw(spec.seed, run, 4, errors.attitude_ned_rad);
      init.q_b_n = Quaterniond(RotationVectorToDcm(psi) * EulerToDcm(e)).normalized();
    }
  }
  return init;
}

ErrorStateMatrix StartErrorCovariance(const MonteCarloSpec& spec, const EulerAngles& attitude,
                                      const ErrorStateNoise& noise) {
  const InitialErrorSigmas& errors = spec.initial_errors;
  if (errors.attitude_ned_rad.isZero(0.0) && errors.fixed_position_ned_m.isZero(0.0) &&
      errors.fixed_velocity_ned_m_per_s.isZero(0.0) && errors.fixed_attitude_ned_rad.isZero(0.0)) {
    return InitialErrorCovariance(errors.position_ned_m, errors.velocity_ned_m_per_s,
                                  errors.attitude_rad, attitude, noise);
  }
  // The EKF cannot know the fixed part: it is told the mean-square error per axis,
  // sigma^2 + fixed^2. The covariance analysis of the free INS predicts the spread about the mean
  // (the fixed part moves the mean only, the error model being linear): sigma^2.
  const bool ekf = spec.filter == NavigationFilterKind::kInsGnssEkf;
  const auto mean_square = [ekf](const Eigen::Vector3d& sigma, const Eigen::Vector3d& fixed) {
    return Eigen::Vector3d(ekf ? (sigma.cwiseAbs2() + fixed.cwiseAbs2()).cwiseSqrt() : sigma);
  };
  ErrorStateMatrix P = InitialErrorCovariance(
      mean_square(errors.position_ned_m, errors.fixed_position_ned_m),
      mean_square(errors.velocity_ned_m_per_s, errors.fixed_velocity_ned_m_per_s),
      errors.attitude_rad, attitude, noise);
  // psi = exp-rotation about n applied after the Euler perturbation: independent, so the
  // covariances of psi_nb_n add (to first order).
  const Eigen::Vector3d psi_sigma =
      mean_square(errors.attitude_ned_rad, errors.fixed_attitude_ned_rad);
  P.block<3, 3>(kErrAttitude, kErrAttitude) += psi_sigma.cwiseAbs2().asDiagonal();
  return P;
}

bool UseGyrocompass(const MonteCarloSpec& spec, const SharedTruth& truth) {
  const bool seed000 = spec.simulation.mechanization == MechanizationKind::kSeed000;
  if (seed000 || spec.initialization != InitializationKind::kStaticAlignment ||
      !spec.alignment.heading_sigma_rad) {
    return true;
  }
  const double omega_ie = truth.env.model() == EarthModel::kFlat ? 0.0 : kWgs84EarthRate_rad_per_s;
  const double predicted =
      spec.sensor
          ? PredictedGyrocompassHeadingSigma(spec.sensor->gyro, truth.truth_start.llh.lat_rad,
                                             spec.alignment.duration_s, omega_ie)
          : (omega_ie > 0.0 ? 0.0 : std::numeric_limits<double>::infinity());
  return predicted < *spec.alignment.heading_sigma_rad;
}

}  // namespace mc_detail

double PredictedGyrocompassHeadingSigma(const TriadErrorParams& gyro, double L_b, double duration_s,
                                        double omega_ie_rad_per_s) {
  const double horizontal_rate = omega_ie_rad_per_s * math::Cos(L_b);
  if (!(std::abs(horizontal_rate) > 0.0)) return std::numeric_limits<double>::infinity();
  // 0.664 = sqrt(2 ln 2 / pi), the flicker floor of the Allan deviation (sensor_params.h).
  const double flicker =
      std::sqrt(2.0 * math::Log(2.0) / M_PI) * gyro.bias_flicker.bias_instability;
  const double fixed = gyro.fixed_bias.cwiseAbs().maxCoeff();
  const double T = duration_s;
  const double bias2 = fixed * fixed + gyro.turn_on_bias_sigma * gyro.turn_on_bias_sigma +
                       gyro.bias_gauss_markov.sigma * gyro.bias_gauss_markov.sigma +
                       flicker * flicker + gyro.random_walk * gyro.random_walk * T / 3.0;
  const double white2 = gyro.white_noise_density * gyro.white_noise_density / T;
  return std::sqrt(bias2 + white2) / std::abs(horizontal_rate);
}

}  // namespace driftlab
