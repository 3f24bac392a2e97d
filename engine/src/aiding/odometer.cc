// Odometer and non-holonomic constraints of a ground vehicle (aiding.h OdometerConfig):
// validation, the per-run simulator and the measurement model the EKF and the covariance analysis
// share (Groves, "Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems",
// 2nd ed., section 16.3 (odometers) and its non-holonomic motion constraints).
//
// The vehicle frame is the IMU body frame; the reference point P (the rear-axle centre, where the
// wheels neither slide sideways nor leave the road) sits at lever_arm_b_m = l_b from the IMU. Its
// velocity in the body frame (the lever-arm velocity as for a GNSS antenna, Groves section
// 14.3.1, resolved in b):
//   v_P_b = C_n_b v_eb_n + omega_eb_b x l_b,   omega_eb_b = omega_ib_b - C_n_b omega_ie_n.
// Measurements at each epoch (sample j of the odometer's rate):
//   odometer speed   s = (1 + k) v_P_b,x + n_s,        n_s ~ N(0, speed_sigma^2),
//     k the scale-factor error (tyre radius), a constant of the run, k ~ N(0, sigma_k^2);
//   constraints      0 = v_P_b,y + n_y,  0 = v_P_b,z + n_z,  n ~ N(0, non_holonomic_sigma^2):
//     the pseudo-measurements are zero, and n is the point's residual lateral and vertical motion
//     (side slip, suspension) that the rigid truth trajectory lacks (simulated as white noise, as
//     the ZUPT's residual motion). Where the truth itself moves P sideways (a lever arm with a yaw
//     or roll rate), that motion is an error the filter does not model, as on a real vehicle.
// Filter (x = estimate - truth for the navigation states, x_k = k - k^ for the scale-factor
// state, x_bg = b_g - b^_g): to first order, with C_n_b (I - [psi x]) the estimated attitude,
//   dv_P_b = C_n_b dv_eb_n + (C_n_b [v_eb_n x] + [l_b x] C_n_b [omega_ie_n x]) psi - [l_b x] x_bg
// (the second attitude term is the estimated attitude's error in the Earth rate resolved in b:
// d omega_eb_b = -C_n_b [omega_ie_n x] psi, d(omega x l) = -[l x] d omega; the latitude error in
// omega_ie_n, |d omega_ie / dL| |l| / R ~ 1e-11 per metre, and the gyro scale-factor and
// misalignment errors in omega x l, ~ sigma_sf |omega| |l| ~ 1e-5 m/s on a car, are not modelled),
// so with s^ = (1 + k^) v^_P_b,x:
//   z_s = s^ - s = (1 + k^) dv_P_b,x - v^_P_b,x x_k - n_s,   z_y,z = v^_P_b,y,z - 0 = dv_P_b,y,z -
//   n, H rows: (1 + k^) e_x^T J | -v^_P_b,x at x_k;  e_y^T J;  e_z^T J, with J the map above; R =
//   diag(speed_sigma^2, sigma_nhc^2, sigma_nhc^2).
// Randomness: RandomStream(seed, run, {SensorId::kOdometer, axis, term, 0}): kScaleFactor (axis 0,
// index 0) the scale factor; kWhiteNoise at the epoch index j, axis 0 the speed noise, 1 and 2 the
// lateral and vertical residual motion.
#include <array>
#include <cmath>

#include "aiding/checks.h"
#include "driftlab/aiding.h"
#include "driftlab/attitude.h"

namespace driftlab {
namespace {

using aiding_checks::CheckSigma;

// v_P_b of the state s with the body rate omega_ib_b (see above).
Vector3d PointVelocityBody(const NavEnvironment& env, const NavState& s, const Vector3d& omega_ib_b,
                           const Vector3d& l_b) {
  const Matrix3d C_n_b = s.C_b_n().transpose();
  const Vector3d omega_eb_b = omega_ib_b - C_n_b * env.EarthRate(s.llh.lat_rad);
  return C_n_b * s.v_eb_n + omega_eb_b.cross(l_b);
}

class OdometerSensor : public AidingSensor {
 public:
  OdometerSensor(const OdometerConfig& config, double imu_rate_hz, std::string path)
      : config_(config), path_(std::move(path)) {
    ValidateOdometerConfig(config, imu_rate_hz, path_);
    decimation_ = AidingDecimation(config.rate_hz, imu_rate_hz, path_ + ".rate_hz");
  }
  const std::string& path() const override { return path_; }
  int64_t decimation() const override { return decimation_; }
  std::vector<AidingErrorStates> ErrorStates() const override {
    if (!(config_.scale_factor_sigma > 0.0)) return {};
    return {AidingErrorStates{path_, {config_.scale_factor_sigma}, 0.0, "scale_factor"}};
  }
  std::string NoiseTerm(int row) const override {
    return row == 0 ? "speed_white" : "non_holonomic";
  }
  void Model(const AidingEstimate& e, AidingUpdate* u) const override {
    const NavState& s = *e.state;
    const Matrix3d C_n_b = s.C_b_n().transpose();
    const Vector3d& l = config_.lever_arm_b_m;
    const double k_hat = e.first_state >= 0 && e.own_states != nullptr ? e.own_states[0] : 0.0;
    const Vector3d v_P_b = PointVelocityBody(*e.env, s, e.omega_ib_b, l);
    // J = d v_P_b / d (dv_eb_n, psi, x_bg), one 3 x 3 block each.
    const Matrix3d J_v = C_n_b;
    const Matrix3d J_psi =
        C_n_b * Skew(s.v_eb_n) + Skew(l) * C_n_b * Skew(e.env->EarthRate(s.llh.lat_rad));
    const Matrix3d J_bg = -Skew(l);
    u->dim = config_.non_holonomic ? 3 : 1;
    u->H = Eigen::Matrix<double, AidingUpdate::kMaxDim, Eigen::Dynamic>::Zero(AidingUpdate::kMaxDim,
                                                                              e.layout->size);
    for (int row = 0; row < u->dim; ++row) {
      const double scale = row == 0 ? 1.0 + k_hat : 1.0;
      u->H.block<1, 3>(row, kErrVelocity) = scale * J_v.row(row);
      u->H.block<1, 3>(row, kErrAttitude) = scale * J_psi.row(row);
      u->H.block<1, 3>(row, kErrGyroBias) = scale * J_bg.row(row);
      for (int first : e.layout->gyro_bias_extra) {
        u->H.block<1, 3>(row, first) = scale * J_bg.row(row);
      }
    }
    // The scale factor is a state whenever its sigma is > 0 (ErrorStates).
    if (e.first_state >= 0) u->H(0, e.first_state) = -v_P_b.x();
    u->R(0, 0) = config_.speed_sigma_m_per_s * config_.speed_sigma_m_per_s;
    if (config_.non_holonomic) {
      const double var_n =
          config_.non_holonomic_sigma_m_per_s * config_.non_holonomic_sigma_m_per_s;
      u->R(1, 1) = var_n;
      u->R(2, 2) = var_n;
    }
  }
  std::unique_ptr<AidingRun> Start(const NavEnvironment& env, uint64_t seed,
                                   uint32_t run) const override;
  const OdometerConfig& config() const { return config_; }

 private:
  OdometerConfig config_;
  std::string path_;
  int64_t decimation_ = 1;
};

class OdometerRun : public AidingRun {
 public:
  OdometerRun(const OdometerSensor& sensor, const NavEnvironment& env, uint64_t seed, uint32_t run)
      : sensor_(sensor), env_(env) {
    const OdometerConfig& c = sensor.config();
    const RandomStream scale(seed, run, {SensorId::kOdometer, 0, ErrorTerm::kScaleFactor, 0});
    scale_factor_ = c.scale_factor_sigma > 0.0 ? c.scale_factor_sigma * scale.Gaussian(0) : 0.0;
    for (uint8_t axis = 0; axis < 3; ++axis) {
      white_[axis] =
          RandomStream(seed, run, {SensorId::kOdometer, axis, ErrorTerm::kWhiteNoise, 0});
    }
  }
  bool Measure(int64_t k, const AidingTruth& truth) override {
    const OdometerConfig& c = sensor_.config();
    const uint64_t j = static_cast<uint64_t>(k / sensor_.decimation());
    const Vector3d v_P_b = PointVelocityBody(env_, truth.truth, truth.omega_ib_b, c.lever_arm_b_m);
    measured_[0] =
        (1.0 + scale_factor_) * v_P_b.x() + c.speed_sigma_m_per_s * white_[0].Gaussian(j);
    measured_[1] = c.non_holonomic_sigma_m_per_s * white_[1].Gaussian(j);
    measured_[2] = c.non_holonomic_sigma_m_per_s * white_[2].Gaussian(j);
    return true;
  }
  void Innovation(const AidingEstimate& e, AidingUpdate* u) const override {
    sensor_.Model(e, u);
    const Vector3d v =
        PointVelocityBody(*e.env, *e.state, e.omega_ib_b, sensor_.config().lever_arm_b_m);
    const double k_hat = e.first_state >= 0 ? e.own_states[0] : 0.0;
    u->z(0) = (1.0 + k_hat) * v.x() - measured_[0];
    u->z(1) = v.y() - measured_[1];
    u->z(2) = v.z() - measured_[2];
  }
  double scale_factor() const { return scale_factor_; }

 private:
  OdometerSensor sensor_;  // a copy: the run outlives no sensor
  NavEnvironment env_;
  double scale_factor_ = 0.0;
  std::array<RandomStream, 3> white_{};
  Vector3d measured_ = Vector3d::Zero();  // speed, lateral, vertical
};

std::unique_ptr<AidingRun> OdometerSensor::Start(const NavEnvironment& env, uint64_t seed,
                                                 uint32_t run) const {
  return std::make_unique<OdometerRun>(*this, env, seed, run);
}

}  // namespace

void ValidateOdometerConfig(const OdometerConfig& c, double imu_rate_hz, const std::string& path) {
  AidingDecimation(c.rate_hz, imu_rate_hz, path + ".rate_hz");
  CheckSigma(c.speed_sigma_m_per_s, path + ".speed_sigma_m_per_s", 10.0, "m/s", true);
  if (!std::isfinite(c.scale_factor_sigma) || c.scale_factor_sigma < 0.0 ||
      c.scale_factor_sigma > 0.1) {
    throw SpecError(path + ".scale_factor_sigma_ppm", ValueText(c.scale_factor_sigma * 1e6),
                    "0 <= sigma <= 100000 ppm");
  }
  if (!c.lever_arm_b_m.allFinite() || c.lever_arm_b_m.norm() > 100.0) {
    throw SpecError(path + ".lever_arm_b_m", ValueText(c.lever_arm_b_m.norm()) + " m", "<= 100 m");
  }
  if (c.non_holonomic) {
    CheckSigma(c.non_holonomic_sigma_m_per_s, path + ".non_holonomic_sigma_m_per_s", 10.0, "m/s",
               true);
  }
}

std::shared_ptr<const AidingSensor> MakeOdometerSensor(const OdometerConfig& config,
                                                       double imu_rate_hz,
                                                       const std::string& path) {
  return std::make_shared<OdometerSensor>(config, imu_rate_hz, path);
}

}  // namespace driftlab
