// Attitude mathematics: skew-symmetric matrices, Euler angles <-> direction-cosine matrices,
// rotation vectors <-> DCMs and quaternions, and Euler-angle rates <-> body angular rate.
//
// Conventions (Groves 2nd ed., section 2.2): C_b_n is the coordinate-transformation matrix from
// body to navigation frame (x_n = C_b_n x_b). Euler angles are the zyx (yaw psi, pitch theta,
// roll phi) sequence from n to b, so C_b_n = Rz(psi) Ry(theta) Rx(phi) and
//   roll = atan2(C32, C33), pitch = -asin(C31), yaw = atan2(C21, C11)    (Groves (2.17); seed 000)
// Quaternions are Eigen's Hamilton quaternions; q_b_n.toRotationMatrix() == C_b_n.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace driftlab {

using Eigen::Matrix3d;
using Eigen::Quaterniond;
using Eigen::Vector3d;

// Roll, pitch, yaw in radians.
struct EulerAngles {
  double roll_rad = 0.0;
  double pitch_rad = 0.0;
  double yaw_rad = 0.0;
};

// [a x], the matrix with [a x] b = a x b.
Matrix3d Skew(const Vector3d& a);

Matrix3d EulerToDcm(const EulerAngles& e);  // C_b_n

// sin and cos of the three Euler angles, for code that needs both EulerToDcm and
// EulerRatesToBodyRate of the same angles (the trajectory generator: 3 sin/cos pairs instead of 5).
struct EulerTrig {
  explicit EulerTrig(const EulerAngles& e);
  // From the six values (remembered from the same angles: the trajectory generator's TrigMemo).
  EulerTrig(double sp_in, double cp_in, double st_in, double ct_in, double ss_in, double cs_in)
      : sp(sp_in), cp(cp_in), st(st_in), ct(ct_in), ss(ss_in), cs(cs_in) {}
  double sp, cp;  // roll
  double st, ct;  // pitch
  double ss, cs;  // yaw
};
Matrix3d EulerToDcm(const EulerTrig& t);
EulerAngles DcmToEuler(const Matrix3d& C_b_n);

// Exact rotation matrix of a rotation vector (Rodrigues), with Taylor series near zero so the
// result is accurate to rounding for any |rho|. Groves (5.73).
Matrix3d RotationVectorToDcm(const Vector3d& rho);
Quaterniond RotationVectorToQuaternion(const Vector3d& rho);
// Rotation vector of a quaternion (angle in [0, pi]).
Vector3d QuaternionToRotationVector(const Quaterniond& q);

// Body angular rate of b with respect to n, resolved in b, from Euler angles and their rates:
//   omega_nb_b = [phi' - psi' sin theta,
//                 theta' cos phi + psi' cos theta sin phi,
//                 -theta' sin phi + psi' cos theta cos phi]          Groves (2.58) inverse
Vector3d EulerRatesToBodyRate(const EulerAngles& e, const Vector3d& euler_rates);
Vector3d EulerRatesToBodyRate(const EulerTrig& t, const Vector3d& euler_rates);

// Small-angle attitude error of `estimate` relative to `truth` as roll/pitch/yaw differences
// wrapped to (-pi, pi].
Vector3d EulerDifference(const EulerAngles& estimate, const EulerAngles& truth);

// Attitude error as the rotation vector psi_nb_n with C_b_n(estimate) = (I - [psi x]) ... i.e.
// the small rotation taking truth to estimate, resolved in n: exp([psi x]) = C_est C_true^T.
Vector3d AttitudeErrorNed(const Matrix3d& C_b_n_estimate, const Matrix3d& C_b_n_truth);

// Wrap an angle to (-pi, pi].
double WrapPi(double angle_rad);

}  // namespace driftlab
