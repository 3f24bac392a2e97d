// Multi-position calibration of an accelerometer and a gyro triad without external equipment
// (Tedaldi, Pretto, Menegatti, ICRA 2014; the method of imu_tk), fitted with Ceres.
//
// Sensor model (the forward model of sensor_params.h, m~ = (I + S + M) m + b + n):
//   accelerometer  f~_s = T_a f_b + b_a,  T_a = I + S_a + M_a, M_a strictly LOWER triangular
//   gyro           w~_s = T_g w_b + b_g,  T_g = I + S_g + M_g, M_g any off-diagonal
// Frames: s = the sensor's own axes (raw data); b = the calibrated body frame defined by the
// accelerometer triad: x_b along the accelerometer's x axis and y_b in the plane of its x and y
// axes (that is what a lower-triangular T_a means). A magnitude-only fit cannot see a rotation of
// the whole triad, so 3 of the 9 accelerometer misalignments are fixed by this choice (Tedaldi
// eq. 5-6). The gyro's 9 parameters are then relative to b. Any full T = T_b R (R a rotation)
// maps to these parameters through a QR decomposition: see TruthInCalibrationFrame.
//
// Accelerometer fit: 9 parameters (3 scale-factor errors S_a, 3 misalignments M_a(1,0), M_a(2,0),
// M_a(2,1), 3 biases b_a) minimising sum over poses of (|T_a^-1 (f~_k - b_a)| - g)^2, g the normal
// gravity of earth.h GravityNed at (lat, h) (Tedaldi eq. 10).
// Gyro fit: bias b_g = mean rate over the initial static period; then 9 parameters (S_g, M_g)
// minimising, for each rotation between consecutive poses k -> k+1, the 2 components
// perpendicular to the measured down direction d_{k+1} of C(T_g)^T d_k - d_{k+1}, where C is the
// attitude change integrated from the calibrated rates T_g^-1 (w~ - b_g) one sample at a time
// (exact rotation-vector -> quaternion step, attitude.h) and d = -f/|f| from the calibrated
// accelerometer means (Tedaldi eq. 12-15). Earth rate is not modelled by this fit: it is an
// error of up to 7.3e-5 rad/s x rotation time (see multi_position_test.cc).
//
// Uncertainties: ceres::Covariance of the parameter block times the residual variance
// s^2 = RSS / (m - n) (m residuals, n parameters), i.e. the usual least-squares estimate
// assuming independent, equal-variance residuals. The gyro fit adds the effect of the error of
// its fixed bias (common to every rotation, so it does not average out):
//   Cov_x += A Cov_b A^T,  A = -(J_x^T J_x)^-1 J_x^T J_b,  Cov_b = diag(std^2 / samples) of the
// initial static period (first-order propagation of a fixed input through least squares); and
// likewise the error of the accelerometer calibration, which defines the frame b and the down
// directions: Cov_x += A_a Cov_a A_a^T with J_a by central differences.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "driftlab/calib/static_detection.h"

namespace ceres {
class Problem;
}

namespace driftlab::calib {

// One fitted parameter: value and 1-sigma uncertainty in `unit`.
struct FitParameter {
  std::string name;  // e.g. "accel.scale_factor.x", "accel.misalignment.zy", "gyro.bias.x"
  double value = 0.0;
  std::string unit;  // "1" (dimensionless), "rad", "m/s^2", "rad/s", "V/(rad/s)", ...
  double sigma = 0.0;
};

// What every fit reports (also the content of CalibrationResult in calibration.proto).
struct CalibrationFit {
  std::string kind;  // "accel", "gyro", "reference"
  std::vector<FitParameter> parameters;
  std::vector<double> residuals;  // per residual, in residual_unit
  std::string residual_unit;
  double residual_rms = 0.0;
  int iterations = 0;
  int poses_used = 0;
  double fit_time_s = 0.0;
  std::vector<std::string> messages;
  // Correlation matrix of `parameters`, row-major; empty when not computed.
  std::vector<double> correlation;
  // Sets `correlation` from a covariance of the first covariance.rows() parameters (the others,
  // if any, uncorrelated with them and with each other).
  void SetCorrelation(const Eigen::MatrixXd& covariance);

  const FitParameter& Find(const std::string& name) const;  // throws std::out_of_range
};

enum class RobustLoss { kNone, kHuber, kCauchy };

struct AccelCalibrationOptions {
  double lat_rad = 0.0;  // latitude of the recording, for local gravity
  double h_m = 0.0;      // height above the ellipsoid [m]
  RobustLoss loss = RobustLoss::kNone;
  double loss_scale_m_per_s2 = 0.01;  // Huber / Cauchy scale of the |f| residual
  // Smallest allowed singular value of the unit pose-direction matrix over sqrt(poses): 1/sqrt(3)
  // for directions spread evenly over the sphere, 0 when all poses lie in one plane.
  double min_direction_spread = 0.2;
};

struct AccelCalibration {
  Eigen::Matrix3d T_a = Eigen::Matrix3d::Identity();  // lower triangular, I + S + M
  Eigen::Vector3d b_a = Eigen::Vector3d::Zero();      // [m/s^2]
  double gravity_m_per_s2 = 0.0;
  CalibrationFit fit;
  Eigen::MatrixXd covariance;  // 9 x 9, order of AccelParameterNames()
  // Calibrated specific force in b from a raw sample.
  Eigen::Vector3d Apply(const Eigen::Vector3d& f_raw) const;
};

struct GyroCalibrationOptions {
  double min_rotation_rad = 0.0174533;  // a pose pair rotating less than this (1 deg) is skipped
};

struct GyroCalibration {
  Eigen::Matrix3d T_g = Eigen::Matrix3d::Identity();  // I + S + M, full
  Eigen::Vector3d b_g = Eigen::Vector3d::Zero();      // [rad/s]
  CalibrationFit fit;
  Eigen::Vector3d Apply(const Eigen::Vector3d& omega_raw) const;
};

// Throws SpecError("data", ...) for fewer than 9 poses ("too few poses: 7 static poses found; 9
// accelerometer parameters need at least 9"), for poses that do not span the sphere (smallest
// normalised singular value of the direction matrix below min_direction_spread), and when the
// fitted Jacobian is rank deficient (names the parameter the data cannot determine).
AccelCalibration CalibrateAccelerometers(const std::vector<StaticInterval>& poses,
                                         const AccelCalibrationOptions& options);

// Gyro calibration from the same recording (poses from DetectStaticIntervals; poses[0] is the
// initial static period). Throws SpecError("data", ...) when fewer than 5 consecutive pose pairs
// rotate by more than min_rotation_rad ("no motion between poses ...") or the fit is rank
// deficient.
GyroCalibration CalibrateGyros(const RawImuRecording& recording,
                               const std::vector<StaticInterval>& poses,
                               const AccelCalibration& accel,
                               const GyroCalibrationOptions& options);

// The parameters a perfect fit would return for sensors with full matrices T_a_full, T_g_full
// (sensor_params.h convention): T_a_full = L Q^T with L lower triangular (positive diagonal) and
// Q a rotation (the QR decomposition of T_a_full^T), so T_a = L and T_g = T_g_full Q.
void TruthInCalibrationFrame(const Eigen::Matrix3d& T_a_full, const Eigen::Matrix3d& T_g_full,
                             Eigen::Matrix3d* T_a, Eigen::Matrix3d* T_g);

namespace detail {
// Solves `problem` (a single parameter block `x` of n values, any number of residuals), then fills
// `fit` (parameters with names/units, 1-sigma from ceres::Covariance scaled by RSS / (m - n),
// residuals, RMS, iterations). Throws SpecError("data", ...) naming the parameter along the
// weakest direction when the Jacobian is rank deficient (reciprocal condition number of the
// column-scaled Jacobian below 1e-10) or m <= n.
void SolveAndReport(ceres::Problem* problem, double* x, int n,
                    const std::vector<std::string>& names, const std::vector<std::string>& units,
                    CalibrationFit* fit, Eigen::MatrixXd* covariance = nullptr);
}  // namespace detail

// Parameter names of the fits, in order (scale x,y,z; misalignments; biases).
const std::vector<std::string>& AccelParameterNames();
const std::vector<std::string>& GyroParameterNames();  // without the bias (not part of the fit)

}  // namespace driftlab::calib
