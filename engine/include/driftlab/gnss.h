// GNSS position/velocity receiver model for loosely coupled aiding (Groves 2nd ed., section
// 9.4 and 14.3.1): at the GNSS rate, the antenna's position and velocity plus
//   white noise (per N, E, D axis, sigma per epoch) and
//   a first-order Gauss-Markov correlated position error (multipath, atmosphere residuals),
//     e_{j+1} = a e_j + sigma sqrt(1 - a^2) w_j,  a = exp(-T / tau)  (exact discretisation,
//     started in its stationary distribution),
// with no output inside outage windows. The antenna sits at lever_arm_b_m from the IMU:
//   r_a = r_b + C_b_n l_b,   v_a = v_eb_n + C_b_n (omega_ib_b x l_b) - omega_ie_n x (C_b_n l_b)
// (Groves section 14.3.1, lever arm, NED form).
// Randomness: RandomStream(seed, run, {SensorId::kGnss, axis 0..2 = N, E, D, term, component})
// at the GNSS epoch index j (epochs counted from t = 0, outages included): kWhiteNoise component
// 0 = position, 1 = velocity; kGaussMarkov the GM drive; kInitialState the GM stationary start.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "driftlab/earth.h"
#include "driftlab/nav_state.h"
#include "driftlab/random.h"

namespace driftlab {

// No GNSS output for t in [start_s, start_s + duration_s).
struct GnssOutage {
  double start_s = 0.0;
  double duration_s = 0.0;
};

struct GnssConfig {
  double rate_hz = 1.0;  // must divide the IMU rate (integer number of IMU samples per epoch)
  Vector3d position_sigma_ned_m = Vector3d(1.5, 1.5, 3.0);          // white, per epoch
  Vector3d velocity_sigma_ned_m_per_s = Vector3d(0.05, 0.05, 0.1);  // white, per epoch
  Vector3d position_gauss_markov_sigma_ned_m = Vector3d::Zero();    // correlated part
  double position_gauss_markov_tau_s = 100.0;                       // its correlation time
  Vector3d lever_arm_b_m = Vector3d::Zero();  // antenna relative to the IMU, body frame [m]
  std::vector<GnssOutage> outages;            // ascending, non-overlapping
  bool use_velocity = true;                   // the filter uses the velocity too
};

// Throws SpecError naming the field under `path` (e.g. "aiding.gnss.position_sigma_ned_m[2]",
// "aiding.gnss.outages[1].start_s" for an outage overlapping the previous one, "aiding.gnss.
// rate_hz" above the IMU rate or not dividing it) with the value and the allowed range.
void ValidateGnssConfig(const GnssConfig& config, double imu_rate_hz,
                        const std::string& path = "aiding.gnss");

// One GNSS fix of the antenna.
struct GnssMeasurement {
  double t_s = 0.0;
  Llh llh;                             // antenna position
  Vector3d v_eb_n = Vector3d::Zero();  // antenna velocity, NED [m/s]
};

// Per run: measurements from the truth. Not thread-safe (holds the GM state); one per run.
class GnssSimulator {
 public:
  GnssSimulator(const GnssConfig& config, const NavEnvironment& env, double imu_rate_hz,
                uint64_t seed, uint32_t run_index, const std::string& path = "aiding.gnss");
  // IMU samples per GNSS epoch.
  int64_t decimation() const { return decimation_; }
  // True if IMU sample k (time truth.t_s) is a GNSS epoch outside the outages; then *out holds the
  // fix. Call with k = 0, 1, 2, ... in order (the GM error advances at every epoch).
  bool Measure(int64_t k, const NavState& truth, const Vector3d& omega_ib_b, GnssMeasurement* out);
  bool InOutage(double t_s) const;
  const GnssConfig& config() const { return config_; }

 private:
  GnssConfig config_;
  NavEnvironment env_;
  int64_t decimation_ = 1;
  double gm_a_ = 0.0;
  std::array<RandomStream, 3> white_position_{}, white_velocity_{}, gm_drive_{};
  Vector3d gm_state_ = Vector3d::Zero();
  int64_t last_epoch_ = -1;
};

// Antenna position and velocity for the body state and the lever arm (see above).
void AntennaState(const NavEnvironment& env, const NavState& body, const Vector3d& omega_ib_b,
                  const Vector3d& lever_arm_b_m, Llh* llh, Vector3d* v_eb_n);

}  // namespace driftlab
