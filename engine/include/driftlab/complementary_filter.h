// Complementary attitude filter of seed 003 (pico-satellite IMU thesis): per axis, the tilt angles
// measured by the accelerometer (and optionally the heading measured by a magnetometer) are
// blended with the angles integrated from the gyros through a low-pass / high-pass pair that
// crosses over at crossover_hz. The accelerometer angle carries high-frequency errors (vehicle
// accelerations, noise), the gyro angle low-frequency errors (bias drift), so the low-pass goes
// on the first and the high-pass on the second (seed 003 section 2.7.5, after Brown & Hwang,
// "Introduction to Random Signals and Applied Kalman Filtering", complementary filter).
//
// Frames and units: body forward-right-down, NED reference; roll, pitch, yaw of C_b_n as in
// attitude.h (zyx), radians; omega_ib_b [rad/s], f_ib_b [m/s^2], magnetic field m_b in any unit.
//
// Per sample k (sample interval dt):
//   accelerometer tilt (Groves 2nd ed. section 5.6.2, levelling):
//     roll_a = atan2(-f_y, -f_z),  pitch_a = atan(f_x / sqrt(f_y^2 + f_z^2))
//   magnetometer heading (Groves section 6.1.1), with the field levelled by the current roll/pitch:
//     m_x' = m_x cos(pitch) + (m_y sin(roll) + m_z cos(roll)) sin(pitch)
//     m_y' = m_y cos(roll) - m_z sin(roll),     yaw_m = atan2(-m_y', m_x') + declination
//   gyro angles: Euler-angle rates from the body rate at the current estimate (Groves (2.58)),
//     roll'  = w_x + (w_y sin(roll) + w_z cos(roll)) tan(pitch)
//     pitch' = w_y cos(roll) - w_z sin(roll)
//     yaw'   = (w_y sin(roll) + w_z cos(roll)) / cos(pitch)
//   integrated by the trapezoidal rule over the sample interval, w = omega_ib_b -
//   omega_correction_b, with the Euler-rate matrix at the previous estimate.
//
// Pairs (digital, bilinear transform s = K (1 - z^-1) / (1 + z^-1) with prewarping
// K = w_c / tan(w_c dt / 2), so that the analog response at w_c = 2 pi crossover_hz is reproduced
// exactly at the same digital frequency; Oppenheim & Schafer, "Discrete-Time Signal Processing",
// 3rd ed., section 7.2.2):
//   kFirstOrder:    L(s) = 1 / (1 + s / w_c),  H = 1 - L = (s / w_c) / (1 + s / w_c).
//                   Sum exactly one; both -3 dB at w_c.
//   kButterworth4:  L(s) = 4th-order Butterworth low-pass at w_c,
//                     1 / ((p^2 + 2 sin(pi/8) p + 1)(p^2 + 2 sin(3 pi/8) p + 1)), p = s / w_c
//                   (poles on the unit circle at 5/8 pi .. 11/8 pi; seed 003 section 2.5.4),
//                   H = 1 - L (the true complementary high-pass). Sum exactly one, so the angle
//                   passes undistorted; L is -3 dB at w_c, but H = 1 - L = 1 + 1/sqrt(2) there
//                   (+4.65 dB, since L(j w_c) = -1/sqrt(2) for the 4th-order Butterworth).
//   kButterworth4Seed: seed 003's own pair: the Butterworth low-pass above on the accelerometer
//                   angle and the Butterworth high-pass (p -> 1/p, i.e. p^4 / B(p)) on the gyro
//                   angle. Both -3 dB at w_c and power complementary (|L|^2 + |H|^2 = 1), but
//                   L + H = (1 + p^4) / B(p) != 1: the true angle is distorted near w_c (gain
//                   sqrt(2) and a 180 degree phase shift at w_c).
//   A pair that sums to one and has |L| = |H| = 1/sqrt(2) at w_c needs L(j w_c) = (1 -+ j) / 2,
//   a 45 degree phase lag, while the 4th-order Butterworth lags 180 degrees there: the seed's
//   Butterworth pair cannot have both properties, which is why both 4th-order variants exist.
// Implementation of the complementary kinds: angle = theta_g + L(theta_a - theta_g) (the
// difference wrapped to (-pi, pi]), i.e. L theta_a + (1 - L) theta_g exactly; the seed kind:
// angle = L(theta_a) + H(theta_g). Filters are cascades of second-order sections (transposed
// direct form II), started in their steady state for the first sample. With the seed kind the
// heading's wrap at +-pi passes through the filters as a step; use a complementary kind with a
// magnetometer.
#pragma once

#include <array>
#include <complex>
#include <string>

#include "driftlab/attitude.h"
#include "driftlab/nav_state.h"

namespace driftlab {

enum class ComplementaryPairKind {
  kFirstOrder,
  kButterworth4,
  kButterworth4Seed,
};

// One second-order section H(z) = (b0 + b1 z^-1 + b2 z^-2) / (1 + a1 z^-1 + a2 z^-2)
// (first-order sections have b2 = a2 = 0).
struct Biquad {
  double b0 = 1.0, b1 = 0.0, b2 = 0.0;
  double a1 = 0.0, a2 = 0.0;
  std::complex<double> Response(double omega_dt_rad) const;  // at z = exp(j omega dt)
  double DcGain() const { return (b0 + b1 + b2) / (1.0 + a1 + a2); }
};

// A digital IIR filter as a cascade of up to two sections, with its state.
class IirCascade {
 public:
  IirCascade() = default;
  IirCascade(const std::array<Biquad, 2>& sections, int count);
  // Response at the digital frequency omega dt [rad] (product of the sections).
  std::complex<double> Response(double omega_dt_rad) const;
  // Sets the state to the steady state for the constant input x.
  void Reset(double x);
  double Step(double x);
  int count() const { return count_; }
  const Biquad& section(int i) const { return sections_[i]; }

 private:
  std::array<Biquad, 2> sections_{};
  std::array<std::array<double, 2>, 2> state_{};  // [section][s1, s2]
  int count_ = 0;
};

// The designed digital pair: low-pass L(z) on the accelerometer (magnetometer) angle and high-pass
// H(z) on the gyro angle.
struct ComplementaryPairDesign {
  ComplementaryPairKind kind = ComplementaryPairKind::kFirstOrder;
  double crossover_hz = 0.0;
  double rate_hz = 0.0;
  IirCascade low_pass;
  // Only for kButterworth4Seed; for the complementary kinds H = 1 - L.
  IirCascade high_pass;
  std::complex<double> LowPassResponse(double f_hz) const;
  std::complex<double> HighPassResponse(double f_hz) const;
};

// Designs the pair. Throws SpecError naming rate_field unless rate_hz > 0, and naming
// crossover_field unless 0 < crossover_hz < rate_hz / 2.
ComplementaryPairDesign DesignComplementaryPair(
    ComplementaryPairKind kind, double crossover_hz, double rate_hz,
    const std::string& crossover_field = "complementary_filter.crossover_hz",
    const std::string& rate_field = "rate_hz");

struct ComplementaryFilterOptions {
  ComplementaryPairKind kind = ComplementaryPairKind::kFirstOrder;
  double crossover_hz = 0.1;           // tilt pair
  double heading_crossover_hz = 0.01;  // heading pair (magnetometer), same kind
  double magnetic_declination_rad = 0.0;
  // Subtracted from omega_ib_b before integrating, e.g. C_n_b omega_ie_n for a known attitude; in
  // the body frame [rad/s].
  Vector3d omega_correction_b = Vector3d::Zero();
  double initial_yaw_rad = 0.0;  // used when no magnetometer sample comes with the first sample
};

// The filter. Update() per IMU sample: no allocation, no virtual call.
class ComplementaryAttitudeFilter {
 public:
  // Throws SpecError for invalid options (paths under "complementary_filter").
  ComplementaryAttitudeFilter(const ComplementaryFilterOptions& options, double rate_hz);
  // Feeds the point sample at t_k (k = 0, 1, ... at the rate); m_b optional magnetometer field.
  // The first sample initialises the angles from the accelerometer (and the magnetometer; without
  // one, yaw starts at options.initial_yaw_rad and is gyro-only). A sample without m_b after
  // magnetometer samples holds the heading low-pass (complementary kinds: yaw = theta_g + the last
  // low-pass output; seed kind: yaw = theta_g + the difference at the last magnetometer sample).
  void Update(const ImuSample& sample, const Vector3d* m_b = nullptr);
  const EulerAngles& attitude() const { return estimate_; }
  // The accelerometer-only tilt of the last sample (for diagnostics).
  const EulerAngles& accelerometer_attitude() const { return measured_; }
  const ComplementaryPairDesign& tilt_pair() const { return tilt_; }
  const ComplementaryPairDesign& heading_pair() const { return heading_; }

 private:
  double Blend(int axis, double measured);

  ComplementaryFilterOptions options_;
  double dt_s_;
  ComplementaryPairDesign tilt_;
  ComplementaryPairDesign heading_;
  std::array<IirCascade, 3> low_{};
  std::array<IirCascade, 3> high_{};
  std::array<double, 3> gyro_angle_{};  // theta_g per axis (roll, pitch, yaw), unwrapped
  bool started_ = false;
  bool heading_aided_ = false;
  Vector3d previous_omega_b_ = Vector3d::Zero();
  double yaw_offset_ = 0.0;  // yaw estimate minus theta_g at the last magnetometer sample
  EulerAngles estimate_;
  EulerAngles measured_;
};

// Tilt from a specific-force sample (levelling; Groves section 5.6.2): roll and pitch [rad].
EulerAngles AccelerometerTilt(const Vector3d& f_ib_b);
// Heading from a magnetometer sample levelled with roll and pitch (Groves section 6.1.1) [rad].
double MagneticHeading(const Vector3d& m_b, double roll_rad, double pitch_rad,
                       double declination_rad);

}  // namespace driftlab
