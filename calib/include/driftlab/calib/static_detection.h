// Raw IMU recordings and detection of the static intervals (poses) of a multi-position tumble.
//
// Method: Tedaldi, Pretto, Menegatti, "A robust and easy to implement method for IMU calibration
// without external equipments", ICRA 2014, section IV-A (the method of imu_tk). The recording
// starts with an initial static period of init_static_s; the static detector is the norm of the
// vector of per-axis accelerometer variances over a centred moving window of window_s,
//   varsigma(t) = |[var(f_x), var(f_y), var(f_z)]|,
// and a sample is static when varsigma(t) < max(threshold_factor * varsigma_init, 1e-12 (m/s^2)^2),
// varsigma_init being the same norm over the initial static period (the floor serves noise-free
// simulated data). Runs of static samples shorter than min_pose_s are
// dropped. Each remaining interval is one pose; its mean specific force and mean rate are the
// inputs of the accelerometer and gyro calibrations (multi_position.h).
//
// Frames and units: the sensor triad axes (not yet calibrated), SI units (s, rad/s, m/s^2).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace driftlab::calib {

// A raw recording: samples at times t_s of the gyro triad (omega, rad/s) and the accelerometer
// triad (f, m/s^2), in the sensor's own (uncalibrated) axes.
struct RawImuRecording {
  std::vector<double> t_s;
  std::vector<Eigen::Vector3d> omega_ib_s;  // [rad/s]
  std::vector<Eigen::Vector3d> f_ib_s;      // [m/s^2]
  size_t size() const { return t_s.size(); }
};

// Reads a CSV recording. With rate_hz == 0 each row is `t_s, gx, gy, gz, ax, ay, az` (7 columns,
// strictly increasing time); with rate_hz > 0 each row is `gx, gy, gz, ax, ay, az` (6 columns) and
// t = k / rate_hz. Gyro in rad/s, accel in m/s^2. A first line that is not numeric is a header.
// Lines starting with '#' are skipped. Throws SpecError naming the file, line and column for a
// wrong column count, a value that is not a finite number, or non-increasing time.
RawImuRecording ReadRawImuCsv(const std::string& path, double rate_hz = 0.0);

// Checks a recording in memory (same errors as ReadRawImuCsv; field = `what`).
void ValidateRecording(const RawImuRecording& recording, const std::string& what);

struct StaticDetectionOptions {
  double init_static_s = 20.0;    // length of the initial static period [s]
  double window_s = 1.0;          // moving-variance window [s] (Tedaldi: t_w)
  double threshold_factor = 6.0;  // static when varsigma < factor * varsigma_init (Tedaldi: k)
  double min_pose_s = 2.0;        // shortest accepted pose [s]
};

// One static interval: samples [begin, end) of the recording.
struct StaticInterval {
  int64_t begin = 0;
  int64_t end = 0;
  double t_begin_s = 0.0;
  double t_end_s = 0.0;
  Eigen::Vector3d mean_f_ib_s = Eigen::Vector3d::Zero();      // [m/s^2]
  Eigen::Vector3d mean_omega_ib_s = Eigen::Vector3d::Zero();  // [rad/s]
  Eigen::Vector3d std_f_ib_s = Eigen::Vector3d::Zero();       // sample std per axis [m/s^2]
  Eigen::Vector3d std_omega_ib_s = Eigen::Vector3d::Zero();   // [rad/s]
  int64_t count() const { return end - begin; }
};

struct StaticDetection {
  std::vector<StaticInterval> intervals;  // in time order; intervals[0] holds the initial period
  double init_variance_norm = 0.0;        // varsigma_init [(m/s^2)^2]
  double threshold = 0.0;                 // [(m/s^2)^2]
  double rate_hz = 0.0;                   // mean sample rate of the recording
};

// Throws SpecError ("options.<field>") for invalid options, and ("data", message) when the
// recording is shorter than init_static_s + window_s or its initial period is not static (the
// moving variance of its windows varies by more than threshold_factor between the quietest and
// the noisiest window).
StaticDetection DetectStaticIntervals(const RawImuRecording& recording,
                                      const StaticDetectionOptions& options);

}  // namespace driftlab::calib
