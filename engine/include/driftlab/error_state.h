// 15-state error model of the NED strapdown INS (mechanization A), linearised along a reference
// (truth or estimated) trajectory: the basis of the linear covariance analysis (covariance.h)
// and of the INS/GNSS error-state Kalman filter (ins_gnss_filter.h).
//
// State x (estimate minus truth), in this order:
//   x[0:3]   delta_r_n   position error N, E, D [m] at the true point, as NavEnvironment::
//                        PositionErrorNed measures it: (R_N + h) dL, (R_E + h) cos L dlambda, -dh
//   x[3:6]   delta_v_n   velocity error v_eb_n N, E, D [m/s]
//   x[6:9]   psi_nb_n    attitude error, the small rotation vector in n with
//                        C_b_n(estimate) = exp([psi x]) C_b_n(truth) (attitude.h AttitudeErrorNed)
//   x[9:12]  b_a         accelerometer bias, body frame [m/s^2]; measured f = f + b_a + w_a
//   x[12:15] b_g         gyro bias, body frame [rad/s]; measured omega = omega + b_g + w_g
//
// Continuous-time model  x' = F x + G w  (Groves, "Principles of GNSS, Inertial, and Multisensor
// Integrated Navigation Systems", 2nd ed., section 14.2.4, the local-navigation-frame error
// equations; here with the position error in metres instead of curvilinear, and the signs of the
// estimate-minus-truth convention):
//   psi'  = -omega_in_n x psi + C_b_n b_g - d(omega_in_n)
//   dv'   = -(C_b_n f_ib_b) x psi + C_b_n b_a - (2 omega_ie_n + omega_en_n) x dv
//           + v_eb_n x (2 d(omega_ie_n) + d(omega_en_n)) + dg_n
//   dr_N' = dv_N + (v_N dr_D - v_D dr_N) / (R_N + h)
//   dr_E' = dv_E + v_E tan L dr_N / (R_N + h) + (v_E dr_D - v_D dr_E) / (R_E + h)
//           - v_N tan L dr_E / (R_N + h)
//   dr_D' = dv_D
//   b'    = -b / tau (first-order Gauss-Markov) or 0 (random walk / constant)
// The position rows are Groves (2.111) differentiated and scaled by the radii. d(omega_ie_n) =
// omega_ie [-sin L, 0, -cos L] dL; d(omega_en_n) from differentiating Groves (5.44) in v_N, v_E,
// L and h; dL = dr_N / (R_N + h), dh = -dr_D; the vertical gravity gradient
// dg_D = (d g_D / d h) dh (~ 2 g / R dr_D, the vertical channel's instability). The derivative
// of the radii with latitude (O(e^2)) is neglected. For the flat environment (EarthModel::kFlat)
// the Earth and transport rates and the gravity gradient are zero and so are their error terms.
//
// Process noise: spectral densities of the white terms of the sensor model: gyro ARW N_g^2
// [rad^2/s] on psi, accelerometer VRW N_a^2 [m^2/s^3] on dv (both isotropic, so C_b_n drops out),
// and the bias driving noise (2 sigma^2 / tau for a Gauss-Markov bias; K^2 for a random walk).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "driftlab/earth.h"
#include "driftlab/nav_state.h"
#include "driftlab/sensor_params.h"

namespace driftlab {

inline constexpr int kNumErrorStates = 15;
inline constexpr int kErrPosition = 0;
inline constexpr int kErrVelocity = 3;
inline constexpr int kErrAttitude = 6;
inline constexpr int kErrAccelBias = 9;
inline constexpr int kErrGyroBias = 12;

using ErrorStateVector = Eigen::Matrix<double, kNumErrorStates, 1>;
using ErrorStateMatrix = Eigen::Matrix<double, kNumErrorStates, kNumErrorStates>;

// Stochastic model of one triad's bias as the error state represents it (per axis, identical
// axes): b' = -b / tau_s + w, PSD of w = driving_psd; tau_s = 0 means b' = w (random walk, or a
// random constant when driving_psd = 0). initial_sigma is the 1-sigma at t = 0.
struct BiasStateModel {
  double initial_sigma = 0.0;  // [u]
  double tau_s = 0.0;          // [s], 0 = no decay
  double driving_psd = 0.0;    // [u^2 / s]
};

// Noise model of the 15-state error model. Units: gyro u = rad/s, accelerometer u = m/s^2.
struct ErrorStateNoise {
  double gyro_white_psd = 0.0;   // N_g^2 [rad^2/s] (angle random walk squared)
  double accel_white_psd = 0.0;  // N_a^2 [m^2/s^3] (velocity random walk squared)
  BiasStateModel gyro_bias;
  BiasStateModel accel_bias;
};

// The error-state noise model of an IMU error model, and the terms of the IMU model that the
// 15-state model cannot represent (listed by field path, e.g. "sensor.gyro.bias_flicker"):
// deterministic terms (fixed bias, fixed scale factor or misalignment: they shift the mean, which
// a covariance does not describe), scale factor and misalignment errors, g-sensitivity, flicker,
// quantization, saturation, and a turn-on bias together with a Gauss-Markov or random-walk bias
// (one state per axis holds one process). Per triad:
//   white noise density N -> white PSD N^2;
//   turn-on bias sigma s0 alone -> random constant (initial_sigma s0);
//   Gauss-Markov (sigma, tau) -> initial_sigma sigma, tau, driving PSD 2 sigma^2 / tau;
//   random walk K -> driving PSD K^2, initial sigma 0 (the simulator starts the walk at 0).
struct ErrorStateNoiseFromImu {
  ErrorStateNoise noise;
  std::vector<std::string> unrepresented;
};
ErrorStateNoiseFromImu MakeErrorStateNoise(const ImuErrorModel& model,
                                           const std::string& path = "sensor");

// Continuous-time system matrix F at the reference state (position, velocity, attitude) with
// the specific force f_ib_b [m/s^2] (Groves section 14.2.4, see above).
ErrorStateMatrix ErrorStateSystemMatrix(const NavEnvironment& env, const NavState& reference,
                                        const Vector3d& f_ib_b, const ErrorStateNoise& noise);

// Continuous process-noise spectral density Q_c = G Q G^T (diagonal).
ErrorStateMatrix ErrorStateProcessNoise(const ErrorStateNoise& noise);

enum class Discretization {
  // Van Loan (1978), "Computing integrals involving the matrix exponential", IEEE TAC 23(3):
  // exp([[-F, Q_c], [0, F^T]] dt) = [[., Phi^-1 Q_d], [0, Phi^T]]; exact for constant F over dt.
  kVanLoan,
  // Phi = I + F dt + (F dt)^2 / 2, Q_d = (Phi Q_c Phi^T + Q_c) dt / 2 (trapezoidal; Groves
  // section 3.2.3); local error O(dt^3).
  kSecondOrder,
};

// Discrete transition matrix Phi and process noise Q_d over dt for constant F and Q_c.
void DiscretizeErrorModel(const ErrorStateMatrix& F, const ErrorStateMatrix& Q_c, double dt_s,
                          Discretization method, ErrorStateMatrix* Phi, ErrorStateMatrix* Q_d);

// Matrix T with [d roll, d pitch, d yaw] = T psi_nb_n for small errors at the Euler angles
// `attitude`: T = E^-1, E = [Rz(yaw) Ry(pitch) x, Rz(yaw) y, z] (the n-frame axes of the three
// elementary rotations of C_b_n = Rz Ry Rx). Singular at pitch = +-90 deg.
Matrix3d EulerErrorFromAttitudeError(const EulerAngles& attitude);

// Initial covariance for independent Gaussian position N/E/D [m], velocity N/E/D [m/s] and
// roll/pitch/yaw [rad] errors (as monte_carlo.h InitialErrorSigmas applies them: Euler angles
// perturbed, so P_psi = E diag(sigma^2) E^T) and the bias initial sigmas of `noise`.
ErrorStateMatrix InitialErrorCovariance(const Vector3d& position_sigma_ned_m,
                                        const Vector3d& velocity_sigma_ned_m_per_s,
                                        const Vector3d& euler_sigma_rad,
                                        const EulerAngles& attitude, const ErrorStateNoise& noise);

}  // namespace driftlab
