#include "driftlab/gnss.h"

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>

#include "driftlab/aiding.h"
#include "driftlab/attitude.h"
#include "driftlab/elementary.h"
#include "driftlab/spec_error.h"

namespace driftlab {
namespace {

void CheckSigmas(const Vector3d& s, const std::string& field) {
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(s[i]) || s[i] < 0.0) {
      throw SpecError(field + "[" + std::to_string(i) + "]", ValueText(s[i]), ">= 0 and finite");
    }
  }
}

bool InOutage(const GnssConfig& config, double t_s) {
  for (const GnssOutage& o : config.outages) {
    if (t_s >= o.start_s && t_s < o.start_s + o.duration_s) return true;
  }
  return false;
}

// The GNSS receiver as the EKF's aid: epochs at its rate outside the outages, its position
// Gauss-Markov error as 3 states (when configured), GnssUpdate as its model.
class GnssSensor : public AidingSensor {
 public:
  GnssSensor(const GnssConfig& config, double imu_rate_hz, std::string path)
      : config_(config), imu_rate_hz_(imu_rate_hz), path_(std::move(path)) {
    ValidateGnssConfig(config, imu_rate_hz, path_);
    decimation_ = static_cast<int64_t>(std::llround(imu_rate_hz / config.rate_hz));
  }
  const std::string& path() const override { return path_; }
  int64_t decimation() const override { return decimation_; }
  bool Available(double t_s) const override { return !InOutage(config_, t_s); }
  std::vector<AidingErrorStates> ErrorStates() const override {
    const Vector3d& s = config_.position_gauss_markov_sigma_ned_m;
    if (s.isZero(0.0)) return {};
    return {AidingErrorStates{path_,
                              {s.x(), s.y(), s.z()},
                              config_.position_gauss_markov_tau_s,
                              "position_gauss_markov"}};
  }
  std::string NoiseTerm(int row) const override {
    return row < 3 ? "position_white" : "velocity_white";
  }
  void Model(const AidingEstimate& e, AidingUpdate* u) const override {
    GnssUpdate(config_, e, nullptr, u);
  }
  std::unique_ptr<AidingRun> Start(const NavEnvironment& env, uint64_t seed,
                                   uint32_t run) const override;
  const GnssConfig& config() const { return config_; }
  double imu_rate_hz() const { return imu_rate_hz_; }

 private:
  GnssConfig config_;
  double imu_rate_hz_;
  std::string path_;
  int64_t decimation_ = 1;
};

class GnssRun : public AidingRun {
 public:
  GnssRun(const GnssSensor& sensor, const NavEnvironment& env, uint64_t seed, uint32_t run)
      : config_(sensor.config()),
        simulator_(sensor.config(), env, sensor.imu_rate_hz(), seed, run, sensor.path()) {}
  bool Measure(int64_t k, const AidingTruth& truth) override {
    return simulator_.Measure(k, truth.truth, truth.omega_ib_b, &fix_);
  }
  void Innovation(const AidingEstimate& e, AidingUpdate* u) const override {
    GnssUpdate(config_, e, &fix_, u);
  }

 private:
  GnssConfig config_;
  GnssSimulator simulator_;
  GnssMeasurement fix_;
};

std::unique_ptr<AidingRun> GnssSensor::Start(const NavEnvironment& env, uint64_t seed,
                                             uint32_t run) const {
  return std::make_unique<GnssRun>(*this, env, seed, run);
}

}  // namespace

std::shared_ptr<const AidingSensor> MakeGnssSensor(const GnssConfig& config, double imu_rate_hz,
                                                   const std::string& path) {
  return std::make_shared<GnssSensor>(config, imu_rate_hz, path);
}

void GnssUpdate(const GnssConfig& g, const AidingEstimate& e, const GnssMeasurement* fix,
                AidingUpdate* u) {
  const NavState& s = *e.state;
  const ErrorStateLayout& layout = *e.layout;
  u->H = Eigen::Matrix<double, AidingUpdate::kMaxDim, Eigen::Dynamic>::Zero(6, layout.size);
  const Matrix3d C = s.C_b_n();
  const Vector3d& l = g.lever_arm_b_m;
  const Vector3d lever_n = C * l;
  u->dim = g.use_velocity ? 6 : 3;
  // Position rows: H_r = [I, 0, -[(C_b_n l_b) x], 0, 0] (Groves section 14.3.1, x = est - truth).
  u->H.block<3, 3>(0, kErrPosition) = Matrix3d::Identity();
  u->H.block<3, 3>(0, kErrAttitude) = -Skew(lever_n);
  const bool gm_state = e.first_state >= 0;
  // The Gauss-Markov error state x_e = e - e^: z = est - (fix - e^) = dr - x_e - noise.
  if (gm_state) u->H.block<3, 3>(0, e.first_state) = -Matrix3d::Identity();
  for (int i = 0; i < 3; ++i) {
    const double gm = gm_state ? 0.0 : g.position_gauss_markov_sigma_ned_m[i];
    u->R(i, i) = g.position_sigma_ned_m[i] * g.position_sigma_ned_m[i] + gm * gm;
  }
  Vector3d lever_velocity_n = Vector3d::Zero();
  if (u->dim == 6) {
    // The lever arm's velocity also depends on the gyro scale factor / misalignment (|l| sigma_s
    // omega, second order for lever arms of a metre): not modelled.
    const Vector3d w_x_l = C * e.omega_ib_b.cross(l);
    lever_velocity_n = w_x_l - e.env->EarthRate(s.llh.lat_rad).cross(lever_n);
    u->H.block<3, 3>(3, kErrVelocity) = Matrix3d::Identity();
    u->H.block<3, 3>(3, kErrAttitude) = -Skew(w_x_l);
    u->H.block<3, 3>(3, kErrGyroBias) = -C * Skew(l);
    for (int first : layout.gyro_bias_extra) u->H.block<3, 3>(3, first) = -C * Skew(l);
    for (int i = 0; i < 3; ++i) {
      u->R(3 + i, 3 + i) = g.velocity_sigma_ned_m_per_s[i] * g.velocity_sigma_ned_m_per_s[i];
    }
  }
  if (fix == nullptr) return;
  // Innovation: estimated antenna minus fix (position in metres NED at the fix), the fix
  // corrected by the estimated Gauss-Markov error.
  u->z.head<3>() = e.env->PositionErrorNed(s.llh, fix->llh) + lever_n;
  if (gm_state) u->z.head<3>() += Eigen::Map<const Vector3d>(e.own_states);
  if (u->dim == 6) u->z.tail<3>() = s.v_eb_n + lever_velocity_n - fix->v_eb_n;
}

void ValidateGnssConfig(const GnssConfig& c, double imu_rate_hz, const std::string& path) {
  if (!std::isfinite(c.rate_hz) || c.rate_hz <= 0.0 || c.rate_hz > imu_rate_hz) {
    throw SpecError(path + ".rate_hz", ValueText(c.rate_hz),
                    "(0, " + ValueText(imu_rate_hz) + "] Hz (not above the IMU rate)");
  }
  const double ratio = imu_rate_hz / c.rate_hz;
  if (std::abs(ratio - std::round(ratio)) > 1e-9 * ratio) {
    throw SpecError(path + ".rate_hz", ValueText(c.rate_hz),
                    "IMU rate " + ValueText(imu_rate_hz) + " Hz divided by an integer");
  }
  CheckSigmas(c.position_sigma_ned_m, path + ".position_sigma_ned_m");
  CheckSigmas(c.velocity_sigma_ned_m_per_s, path + ".velocity_sigma_ned_m_per_s");
  CheckSigmas(c.position_gauss_markov_sigma_ned_m, path + ".position_gauss_markov_sigma_ned_m");
  if (!c.position_gauss_markov_sigma_ned_m.isZero(0.0) &&
      (!std::isfinite(c.position_gauss_markov_tau_s) || c.position_gauss_markov_tau_s <= 0.0)) {
    throw SpecError(path + ".position_gauss_markov_tau_s", ValueText(c.position_gauss_markov_tau_s),
                    "> 0 s");
  }
  // The filter divides by these: a zero white sigma on a used measurement is singular.
  for (int i = 0; i < 3; ++i) {
    if (c.position_sigma_ned_m[i] + c.position_gauss_markov_sigma_ned_m[i] <= 0.0) {
      throw SpecError(path + ".position_sigma_ned_m[" + std::to_string(i) + "]",
                      ValueText(c.position_sigma_ned_m[i]), "> 0 (with no correlated part)");
    }
    if (c.use_velocity && c.velocity_sigma_ned_m_per_s[i] <= 0.0) {
      throw SpecError(path + ".velocity_sigma_ned_m_per_s[" + std::to_string(i) + "]",
                      ValueText(c.velocity_sigma_ned_m_per_s[i]), "> 0 when use_velocity");
    }
  }
  if (!c.lever_arm_b_m.allFinite() || c.lever_arm_b_m.norm() > 100.0) {
    throw SpecError(path + ".lever_arm_b_m", ValueText(c.lever_arm_b_m.norm()) + " m", "<= 100 m");
  }
  for (size_t i = 0; i < c.outages.size(); ++i) {
    const std::string f = path + ".outages[" + std::to_string(i) + "]";
    const GnssOutage& o = c.outages[i];
    if (!std::isfinite(o.start_s) || o.start_s < 0.0) {
      throw SpecError(f + ".start_s", ValueText(o.start_s), ">= 0 s");
    }
    if (!std::isfinite(o.duration_s) || o.duration_s <= 0.0) {
      throw SpecError(f + ".duration_s", ValueText(o.duration_s), "> 0 s");
    }
    if (i > 0) {
      const GnssOutage& p = c.outages[i - 1];
      if (o.start_s < p.start_s + p.duration_s) {
        throw SpecError(f + ".start_s", ValueText(o.start_s),
                        ">= " + ValueText(p.start_s + p.duration_s) +
                            " s (after the end of outages[" + std::to_string(i - 1) +
                            "]; outages ascending and not overlapping)");
      }
    }
  }
}

void AntennaState(const NavEnvironment& env, const NavState& body, const Vector3d& omega_ib_b,
                  const Vector3d& lever_arm_b_m, Llh* llh, Vector3d* v_eb_n) {
  const Matrix3d C = body.C_b_n();
  const Vector3d l_n = C * lever_arm_b_m;
  const double L = body.llh.lat_rad, h = body.llh.h_m;
  llh->lat_rad = L + l_n.x() / (env.MeridianRadiusAt(L) + h);
  llh->lon_rad = body.llh.lon_rad + l_n.y() / ((env.TransverseRadiusAt(L) + h) * math::Cos(L));
  llh->h_m = h - l_n.z();
  *v_eb_n = body.v_eb_n + C * omega_ib_b.cross(lever_arm_b_m) - env.EarthRate(L).cross(l_n);
}

GnssSimulator::GnssSimulator(const GnssConfig& config, const NavEnvironment& env,
                             double imu_rate_hz, uint64_t seed, uint32_t run_index,
                             const std::string& path)
    : config_(config), env_(env) {
  ValidateGnssConfig(config, imu_rate_hz, path);
  decimation_ = static_cast<int64_t>(std::llround(imu_rate_hz / config.rate_hz));
  const double T = 1.0 / config.rate_hz;
  const bool gm = !config.position_gauss_markov_sigma_ned_m.isZero(0.0);
  gm_a_ = gm ? math::Exp(-T / config.position_gauss_markov_tau_s) : 0.0;
  for (uint8_t axis = 0; axis < 3; ++axis) {
    white_position_[axis] =
        RandomStream(seed, run_index, {SensorId::kGnss, axis, ErrorTerm::kWhiteNoise, 0});
    white_velocity_[axis] =
        RandomStream(seed, run_index, {SensorId::kGnss, axis, ErrorTerm::kWhiteNoise, 1});
    gm_drive_[axis] =
        RandomStream(seed, run_index, {SensorId::kGnss, axis, ErrorTerm::kGaussMarkov, 0});
    if (gm) {
      const RandomStream start(seed, run_index,
                               {SensorId::kGnss, axis, ErrorTerm::kInitialState, 0});
      gm_state_[axis] = config.position_gauss_markov_sigma_ned_m[axis] * start.Gaussian(0);
    }
  }
}

bool GnssSimulator::InOutage(double t_s) const { return driftlab::InOutage(config_, t_s); }

bool GnssSimulator::Measure(int64_t k, const NavState& truth, const Vector3d& omega_ib_b,
                            GnssMeasurement* out) {
  if (k % decimation_ != 0) return false;
  const int64_t j = k / decimation_;
  // Advance the correlated error to epoch j (epoch 0 is the stationary start).
  for (int64_t e = last_epoch_ + 1; e <= j; ++e) {
    if (e == 0) continue;
    for (int axis = 0; axis < 3; ++axis) {
      const double s = config_.position_gauss_markov_sigma_ned_m[axis];
      if (s > 0.0) {
        gm_state_[axis] =
            gm_a_ * gm_state_[axis] +
            s * std::sqrt(1.0 - gm_a_ * gm_a_) * gm_drive_[axis].Gaussian(static_cast<uint64_t>(e));
      }
    }
  }
  last_epoch_ = std::max(last_epoch_, j);
  if (InOutage(truth.t_s)) return false;
  Llh llh;
  Vector3d v;
  AntennaState(env_, truth, omega_ib_b, config_.lever_arm_b_m, &llh, &v);
  Vector3d dr, dv;
  for (int axis = 0; axis < 3; ++axis) {
    dr[axis] = gm_state_[axis] + config_.position_sigma_ned_m[axis] *
                                     white_position_[axis].Gaussian(static_cast<uint64_t>(j));
    dv[axis] = config_.velocity_sigma_ned_m_per_s[axis] *
               white_velocity_[axis].Gaussian(static_cast<uint64_t>(j));
  }
  const double L = llh.lat_rad, h = llh.h_m;
  out->t_s = truth.t_s;
  out->llh.lat_rad = L + dr.x() / (env_.MeridianRadiusAt(L) + h);
  out->llh.lon_rad = llh.lon_rad + dr.y() / ((env_.TransverseRadiusAt(L) + h) * math::Cos(L));
  out->llh.h_m = h - dr.z();
  out->v_eb_n = v + dv;
  return true;
}

}  // namespace driftlab
