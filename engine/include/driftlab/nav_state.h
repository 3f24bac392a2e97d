// Navigation state of a body: time, geodetic position, Earth-referenced velocity in NED and
// attitude. Used for both the truth trajectory and INS solutions.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "driftlab/attitude.h"
#include "driftlab/earth.h"

namespace driftlab {

struct NavState {
  double t_s = 0.0;
  Llh llh;                                      // L_b, lambda_b [rad], h_b [m]
  Vector3d v_eb_n = Vector3d::Zero();           // [m/s] NED
  Quaterniond q_b_n = Quaterniond::Identity();  // body -> NED

  Matrix3d C_b_n() const { return q_b_n.toRotationMatrix(); }
  EulerAngles euler() const { return DcmToEuler(C_b_n()); }
};

// Ideal or measured IMU output integrated over one sample interval (t_{k-1}, t_k]:
// delta_theta_ib_b = integral of omega_ib_b dt, delta_v_ib_b = integral of f_ib_b dt, both in the
// body frame as a real integrating IMU reports them (so they contain coning and sculling).
struct ImuIncrement {
  Vector3d delta_theta_ib_b = Vector3d::Zero();  // [rad]
  Vector3d delta_v_ib_b = Vector3d::Zero();      // [m/s]
};

// Point samples of the IMU's kinematic inputs at one instant.
struct ImuSample {
  Vector3d omega_ib_b = Vector3d::Zero();  // [rad/s]
  Vector3d f_ib_b = Vector3d::Zero();      // [m/s^2]
};

// Navigation errors of an estimate against the truth at one epoch.
struct NavError {
  Vector3d r_ned_m = Vector3d::Zero();        // position error N, E, D [m]
  Vector3d v_ned_m_per_s = Vector3d::Zero();  // velocity error N, E, D [m/s]
  Vector3d euler_rad = Vector3d::Zero();      // roll, pitch, yaw differences, wrapped [rad]
  Vector3d psi_nb_n_rad = Vector3d::Zero();   // attitude error as rotation vector in n [rad]
};

NavError ComputeNavError(const NavEnvironment& env, const NavState& estimate,
                         const NavState& truth);

// The truth's share of ComputeNavError (its position scaling, Euler angles and C_b_n), computed
// once for many estimates against one truth (the runs of a lockstep group at a report):
// ComputeNavError(env, estimate, NavErrorTruth(env, truth)) performs the operations of
// ComputeNavError(env, estimate, truth), so it gives the same bits.
struct NavErrorTruth {
  NavErrorTruth(const NavEnvironment& env, const NavState& truth);
  Llh llh;
  Vector3d v_eb_n;
  NavEnvironment::PositionScale position_scale;
  EulerAngles euler;
  Matrix3d C_b_n;
};
NavError ComputeNavError(const NavEnvironment& env, const NavState& estimate,
                         const NavErrorTruth& truth);

}  // namespace driftlab
