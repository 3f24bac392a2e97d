#include "driftlab/attitude.h"

#include <cmath>

#include "driftlab/elementary.h"
#include "math/elementary_functions.h"
#include "math/vector_lanes.h"
#include "stats/nav_error_lanes.h"

namespace driftlab {

Matrix3d Skew(const Vector3d& a) {
  Matrix3d S;
  S << 0.0, -a.z(), a.y(),  //
      a.z(), 0.0, -a.x(),   //
      -a.y(), a.x(), 0.0;
  return S;
}

EulerTrig::EulerTrig(const EulerAngles& e) {
  math::SinCos(e.roll_rad, &sp, &cp);
  math::SinCos(e.pitch_rad, &st, &ct);
  math::SinCos(e.yaw_rad, &ss, &cs);
}

Matrix3d EulerToDcm(const EulerAngles& e) { return EulerToDcm(EulerTrig(e)); }

Matrix3d EulerToDcm(const EulerTrig& t) {
  const double sp = t.sp, cp = t.cp, st = t.st, ct = t.ct, ss = t.ss, cs = t.cs;
  // Transpose of Groves (2.22) (which gives C_n_b).
  Matrix3d C_b_n;
  C_b_n << ct * cs, -cp * ss + sp * st * cs, sp * ss + cp * st * cs,  //
      ct * ss, cp * cs + sp * st * ss, -sp * cs + cp * st * ss,       //
      -st, sp * ct, cp * ct;
  return C_b_n;
}

EulerAngles DcmToEuler(const Matrix3d& C_b_n) {
  double e[3];  // the lockstep kernels' code at one lane (nav_error_lanes.h)
  nav_error_lanes::EulerOfDcm<1>(C_b_n(0, 0), C_b_n(1, 0), C_b_n(2, 0), C_b_n(2, 1), C_b_n(2, 2),
                                 e);
  EulerAngles out;
  out.roll_rad = e[0];
  out.pitch_rad = e[1];
  out.yaw_rad = e[2];
  return out;
}

Matrix3d RotationVectorToDcm(const Vector3d& rho) {
  const double a2 = rho.squaredNorm();
  const double a = std::sqrt(a2);
  double s, c;  // sin(a)/a and (1 - cos a)/a^2
  if (a < 1e-4) {
    // Taylor series; truncation below 1e-20 for a < 1e-4.
    s = 1.0 - a2 / 6.0 + a2 * a2 / 120.0;
    c = 0.5 - a2 / 24.0 + a2 * a2 / 720.0;
  } else {
    double sin_a, cos_a;
    elementary::SinCos<1>(a, sin_a, cos_a);
    s = sin_a / a;
    c = (1.0 - cos_a) / a2;
  }
  const Matrix3d K = Skew(rho);
  return Matrix3d::Identity() + s * K + c * K * K;
}

Quaterniond RotationVectorToQuaternion(const Vector3d& rho) {
  // The mechanization's code at one lane (math/vector_lanes.h).
  const vector_lanes::Q4<1> q =
      vector_lanes::RotationVectorToQuaternion<1>({rho.x(), rho.y(), rho.z()});
  return Quaterniond(q.w, q.x, q.y, q.z);
}

Vector3d QuaternionToRotationVector(const Quaterniond& q_in) {
  Quaterniond q = q_in.w() < 0.0 ? Quaterniond(-q_in.w(), -q_in.x(), -q_in.y(), -q_in.z()) : q_in;
  const Vector3d v = q.vec();
  const double s = v.norm();
  if (s < 1e-8) return 2.0 * v / q.w();  // 2 atan(s/w) / s -> 2/w, error O(s^2)
  const double angle = 2.0 * math::Atan2(s, q.w());
  return v * (angle / s);
}

Vector3d EulerRatesToBodyRate(const EulerAngles& e, const Vector3d& euler_rates) {
  return EulerRatesToBodyRate(EulerTrig(e), euler_rates);
}

Vector3d EulerRatesToBodyRate(const EulerTrig& t, const Vector3d& euler_rates) {
  const double sp = t.sp, cp = t.cp, st = t.st, ct = t.ct;
  const double droll = euler_rates.x(), dpitch = euler_rates.y(), dyaw = euler_rates.z();
  return Vector3d(droll - dyaw * st, dpitch * cp + dyaw * ct * sp, -dpitch * sp + dyaw * ct * cp);
}

double WrapPi(double angle_rad) { return nav_error_lanes::WrapPiOf(angle_rad); }

Vector3d EulerDifference(const EulerAngles& estimate, const EulerAngles& truth) {
  return Vector3d(WrapPi(estimate.roll_rad - truth.roll_rad),
                  WrapPi(estimate.pitch_rad - truth.pitch_rad),
                  WrapPi(estimate.yaw_rad - truth.yaw_rad));
}

Vector3d AttitudeErrorNed(const Matrix3d& C_b_n_estimate, const Matrix3d& C_b_n_truth) {
  const Matrix3d dC = C_b_n_estimate * C_b_n_truth.transpose();
  return QuaternionToRotationVector(Quaterniond(dC).normalized());
}

}  // namespace driftlab
