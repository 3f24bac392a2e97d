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
//   x[15:]   augmented states (ErrorStateLayout), present only when the model has the term:
//            further bias components of each triad (a Gauss-Markov bias beside a turn-on bias,
//            the flicker components), scale-factor and misalignment errors of each triad, the
//            GNSS position Gauss-Markov error (NED) and the barometer Gauss-Markov bias.
// The bias, scale-factor and misalignment states are "truth minus estimate" (the residual error
// of the corrected measurement, as b_a, b_g); the GNSS and barometer error states likewise
// (x = e - e^, the residual error of the corrected fix).
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
//   psi' += C_b_n (dS_g + dM_g) omega_ib_b,  dv' += C_b_n (dS_a + dM_a) f_ib_b   (scale factor
//           S = diag, misalignment M = off-diagonal; sensor_params.h measurement model
//           m~ = (I + S + M) m + ...; Groves 2nd ed. (4.16)-(4.17), (14.98) augmented states)
//   s', m' = 0 (random constants per run);  e_gnss' = -e / tau;  b_baro' = -b / tau
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
#include "driftlab/sensors.h"

namespace driftlab {

// The core states; the error state has at least these.
inline constexpr int kNumErrorStates = 15;
inline constexpr int kNumNavErrorStates = 9;  // position, velocity, attitude
inline constexpr int kErrPosition = 0;
inline constexpr int kErrVelocity = 3;
inline constexpr int kErrAttitude = 6;
inline constexpr int kErrAccelBias = 9;
inline constexpr int kErrGyroBias = 12;

// Dynamic size: 15 core states plus the augmented ones of the model (ErrorStateLayout).
using ErrorStateVector = Eigen::VectorXd;
using ErrorStateMatrix = Eigen::MatrixXd;

// Stochastic model of one bias process as the error state represents it (per axis, identical
// axes, one state per axis): b' = -b / tau_s + w, PSD of w = driving_psd; tau_s = 0 means b' = w
// (random walk, or a random constant when driving_psd = 0). initial_sigma is the 1-sigma at t = 0.
// `source` says which terms of the IMU model (sensor_params.h) the state carries, for the error
// budget (error_budget.h): the turn-on bias (its initial sigma) with the random walk (its drive),
// a Gauss-Markov bias, or one state of the flicker bias instability.
enum class BiasStateSource { kTurnOnAndRandomWalk, kGaussMarkov, kFlicker };
struct BiasStateModel {
  double initial_sigma = 0.0;  // [u]
  double tau_s = 0.0;          // [s], 0 = no decay
  double driving_psd = 0.0;    // [u^2 / s]
  BiasStateSource source = BiasStateSource::kTurnOnAndRandomWalk;
};

// Scale-factor and misalignment errors of one triad as augmented random-constant states: 3 scale
// factors (diagonal of S) and 6 misalignments (off-diagonal of M, order (0,1) (0,2) (1,0) (1,2)
// (2,0) (2,1)), each N(0, sigma^2) per run as sensors.h draws them.
inline constexpr int kMisalignmentRow[6] = {0, 0, 1, 1, 2, 2};
inline constexpr int kMisalignmentCol[6] = {1, 2, 0, 2, 0, 1};
struct ScaleMisalignmentModel {
  double scale_factor_sigma = 0.0;      // [-]
  double misalignment_sigma_rad = 0.0;  // [rad]
};

// One aiding sensor's own error states (e.g. the GNSS position Gauss-Markov error, the barometer
// bias): sigma.size() scalar states, each a first-order Gauss-Markov process x' = -x / tau + w with
// PSD 2 sigma^2 / tau started in its stationary distribution N(0, sigma^2) (Maybeck vol. 1,
// 4.11), or with tau_s = 0 a random constant x ~ N(0, sigma^2). A sigma of 0 is a state that stays
// exactly known (0).
struct AidingErrorStates {
  std::string owner;          // the aid's field path ("aiding.gnss")
  std::vector<double> sigma;  // per state [the aid's unit]
  double tau_s = 0.0;         // correlation time [s]; 0 = random constant
  std::string term;           // the aid's term the states carry ("position_gauss_markov")
};

// Noise model of the error model. Units: gyro u = rad/s, accelerometer u = m/s^2.
struct ErrorStateNoise {
  double gyro_white_psd = 0.0;   // N_g^2 [rad^2/s] (angle random walk squared)
  double accel_white_psd = 0.0;  // N_a^2 [m^2/s^3] (velocity random walk squared)
  BiasStateModel gyro_bias;      // states 12-14
  BiasStateModel accel_bias;     // states 9-11
  // Further bias processes of each triad, 3 augmented states each (they add to the bias).
  std::vector<BiasStateModel> gyro_bias_extra;
  std::vector<BiasStateModel> accel_bias_extra;
  // Augmented scale factor / misalignment (a sigma of 0 adds no state).
  ScaleMisalignmentModel gyro_scale_misalignment;
  ScaleMisalignmentModel accel_scale_misalignment;
  // The aiding sensors' own error states (aiding.h AidingSensor::ErrorStates), in the order of
  // the job's aids: GNSS position Gauss-Markov error, barometer bias, odometer scale factor, ...
  std::vector<AidingErrorStates> aiding_states;
};

// Index of every augmented block in the error state of a noise model (-1 = absent).
struct ErrorStateLayout {
  explicit ErrorStateLayout(const ErrorStateNoise& noise);
  int size = kNumErrorStates;
  std::vector<int> accel_bias_extra;  // first index of each 3-state block
  std::vector<int> gyro_bias_extra;
  int gyro_scale = -1, gyro_misalignment = -1;    // 3 and 6 states
  int accel_scale = -1, accel_misalignment = -1;  // 3 and 6 states
  std::vector<int> aiding;  // first index of each ErrorStateNoise::aiding_states block
  // First index of the block of the aid at `owner` ("aiding.gnss"), -1 if it has none.
  int AidingFirst(const ErrorStateNoise& noise, const std::string& owner) const;
};

// Options of the conversion of an IMU error model into the error-state model.
struct ErrorModelOptions {
  // Scale factor and misalignment as augmented states; when false, their effect is bounded by an
  // added white noise derived from the motion (MakeErrorStateNoise).
  bool augment_scale_misalignment = true;
  // Flicker bias instability as this many Gauss-Markov states per axis (1..3 fitted; at least the
  // design's size, the default: every component of the simulator's design, two per decade, is a
  // state). Measured on examples/car_drive_gnss.json (tactical, 500 runs, seed 1): 3 fitted states
  // leave the average NEES above its band at 57 of 605 epochs during the outage (ADEV of the fit
  // 0.90 of the flicker floor at 30 s); every component: 0 of 605.
  int flicker_states_per_axis = kMaxFlickerComponents;
  // The run's time scales [s] over which the flicker states fit its Allan curve: the shortest
  // (the aiding interval, or the IMU interval) and the longest (the run's duration).
  double time_scale_min_s = 1.0;
  double time_scale_max_s = 1000.0;
  // For augment_scale_misalignment = false: the largest |omega_ib_b| and |f_ib_b| per body axis
  // over the run [rad/s], [m/s^2], and the longest interval without aiding T [s].
  Vector3d max_abs_omega_ib_b = Vector3d::Zero();
  Vector3d max_abs_f_ib_b = Vector3d::Zero();
  double unaided_interval_s = 0.0;
};

// The error-state noise model of an IMU error model, and the terms of the IMU model that the
// error-state model does not represent (listed by field path with the predicted effect, e.g.
// "sensor.gyro.fixed_bias (deterministic: shifts the mean error, ...)"). Per triad:
//   white noise density N -> white PSD N^2;
//   turn-on bias sigma s0 and random walk K -> one state per axis: b' = w, PSD K^2, initial
//     sigma s0 (a constant plus a walk started at 0 is a walk started at N(0, s0^2));
//   Gauss-Markov (sigma, tau) -> its own state: initial_sigma sigma (0 for start_at_zero), tau,
//     driving PSD 2 sigma^2 / tau (Maybeck vol. 1, 4.11; Groves 2nd ed. (14.74));
//   flicker (bias instability B) -> FitFlickerStates;
//   scale factor / misalignment sigma -> augmented states, or a motion bound (see
//     ErrorModelOptions::augment_scale_misalignment).
// Left out (named in `unrepresented`): deterministic terms (fixed bias, scale factor,
// misalignment, asymmetry, g-sensitivity: they shift every run's error the same way, which a
// covariance does not describe), quantization, saturation.
struct ErrorStateNoiseFromImu {
  ErrorStateNoise noise;
  std::vector<std::string> unrepresented;
};
ErrorStateNoiseFromImu MakeErrorStateNoise(const ImuErrorModel& model,
                                           const std::string& path = "sensor",
                                           const ErrorModelOptions& options = {});

// Flicker (1/f) bias instability as `count` first-order Gauss-Markov states. 1/f noise is well
// approximated by a sum of first-order Gauss-Markov (Lorentzian) processes with log-spaced time
// constants (Keshner, "1/f noise", Proc. IEEE 70(3), 1982; the simulator's design,
// sensors.h DesignFlickerApproximation). The simulator's components (two per decade) are lumped
// into `count` groups log-spaced over the run's time scales [t_min_s, t_max_s] (components
// outside go to the end groups): a group's variance is the sum of its members' variances and its
// time constant their variance-weighted geometric mean, so each group reproduces the Allan
// variance of its members at averaging times away from its edges (GaussMarkovAllanVariance is
// sigma^2 g(t / tau)). count >= the design's size returns the design itself.
std::vector<BiasStateModel> FitFlickerStates(const FlickerParams& flicker, int count,
                                             double t_min_s, double t_max_s);

// Continuous-time system matrix F at the reference state (position, velocity, attitude) with
// the specific force f_ib_b [m/s^2] and the body rate omega_ib_b [rad/s] (the latter only for the
// gyro scale-factor and misalignment columns) (Groves section 14.2.4, see above).
ErrorStateMatrix ErrorStateSystemMatrix(const NavEnvironment& env, const NavState& reference,
                                        const Vector3d& f_ib_b, const ErrorStateNoise& noise,
                                        const Vector3d& omega_ib_b = Vector3d::Zero());

// How one sensor error state (index j >= kNumNavErrorStates) enters the navigation error rates:
// column j of F is F(nav_rows + r, j) = C_b_n(r, axis) * weight, r = 0..2 (the bias, scale-factor
// and misalignment columns of ErrorStateSystemMatrix: an accelerometer error drives the velocity
// rows, a gyro error the attitude rows, through one column of C_b_n); `coupled` false: column j
// of F_ns is zero (the aiding sensors' states). Entry j - kNumNavErrorStates of the result.
struct SensorStateCoupling {
  bool coupled = false;
  int nav_rows = kErrVelocity;  // kErrVelocity or kErrAttitude
  int axis = 0;                 // body axis: the column of C_b_n
  double weight = 0.0;          // 1 for a bias; the measured rate / specific force component
};
// The couplings of every sensor error state of a layout with the specific force f_ib_b
// [m/s^2] and the body rate omega_ib_b [rad/s] (the scale-factor and misalignment weights).
void ErrorStateSensorCoupling(const ErrorStateLayout& layout, const Vector3d& f_ib_b,
                              const Vector3d& omega_ib_b, std::vector<SensorStateCoupling>* out);

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

// Discrete transition matrix Phi and process noise Q_d over dt for constant F and Q_c (any size).
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
