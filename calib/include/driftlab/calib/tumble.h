// Simulated multi-position tumble for calibration tests and examples: an IMU at rest on the
// Earth (latitude, height), turned between static poses by rotations at constant rate about axes
// fixed in the body (and, being fixed in the body and at rest otherwise, fixed in the local NED
// frame), recorded as point samples (ImuSample) and passed through the engine's ImuErrorSimulator.
//
// Ideal samples are exact at each instant: with C_b_n(t) = C_b_n(t_0) Exp(u theta(t)) during a
// rotation (u the unit axis in b, theta' = constant rate),
//   omega_ib_b = C_n_b omega_ie_n + u theta'      (Groves (5.37), omega_en = 0 at rest)
//   f_ib_b    = -C_n_b g_n                        (at rest; g_n from earth.h GravityNed)
// The sensor sits at the centre of rotation (no lever arm). Rotations start and end half a
// sample period between samples, so each sample is either static or rotating and the rectangle
// rule sum omega_k dt integrates a rotation exactly. Rotation axes are taken from a fixed list
// and made perpendicular to the current down direction, so every rotation moves gravity in the
// body frame by its full angle.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "driftlab/calib/static_detection.h"
#include "driftlab/sensor_params.h"

namespace driftlab::calib {

struct TumbleSpec {
  double rate_hz = 100.0;
  double initial_static_s = 30.0;  // first pose (initial static period)
  double pose_s = 5.0;             // every later pose
  double rotation_s = 1.0;         // duration of each rotation (angles 80..150 deg)
  int pose_count = 19;             // >= 12 recommended; includes the initial pose
  double lat_rad = 0.7853981633974483;
  double h_m = 0.0;
  double initial_yaw_rad = 0.3;
  bool earth_rate = true;  // include omega_ie in the ideal gyro samples
};

struct Tumble {
  RawImuRecording recording;           // measured samples (through ImuErrorSimulator)
  std::vector<Eigen::Matrix3d> C_b_n;  // true attitude of each pose
  Eigen::Matrix3d T_a = Eigen::Matrix3d::Identity();  // injected accel I + S + M of this run
  Eigen::Vector3d b_a = Eigen::Vector3d::Zero();      // injected constant accel bias
  Eigen::Matrix3d T_g = Eigen::Matrix3d::Identity();
  Eigen::Vector3d b_g = Eigen::Vector3d::Zero();
};

// Throws SpecError("tumble.<field>") for invalid spec values and the engine's errors for an
// invalid model.
Tumble SimulateTumble(const TumbleSpec& spec, const ImuErrorModel& model, uint64_t seed,
                      uint32_t run_index);

}  // namespace driftlab::calib
