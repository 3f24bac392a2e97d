// Zero-velocity updates (aiding.h ZuptConfig): validation, the per-run simulator, and the
// measurement model the EKF and the covariance analysis share. The ZUPT epochs are the schedule's
// (aiding.h AidingSchedule: the ZUPT samples where the truth stands still).
#include <cmath>

#include "aiding/checks.h"
#include "driftlab/aiding.h"

namespace driftlab {
namespace {

using aiding_checks::CheckSigma;

// v_measured = 0 + n (Groves 2nd ed., section 15.3.1): z = v^_eb_n - v_measured,
// H = [0, I, 0, 0, 0], R = sigma^2 I.
class ZuptSensor : public AidingSensor {
 public:
  ZuptSensor(const ZuptConfig& config, double imu_rate_hz, std::string path)
      : config_(config), imu_rate_hz_(imu_rate_hz), path_(std::move(path)) {
    ValidateZuptConfig(config, imu_rate_hz, path_);
    decimation_ = AidingDecimation(config.rate_hz, imu_rate_hz, path_ + ".rate_hz");
  }
  const std::string& path() const override { return path_; }
  int64_t decimation() const override { return decimation_; }
  bool OnlyWhileStatic() const override { return true; }
  void Model(const AidingEstimate& e, AidingUpdate* u) const override {
    u->dim = 3;
    u->H = Eigen::Matrix<double, AidingUpdate::kMaxDim, Eigen::Dynamic>::Zero(AidingUpdate::kMaxDim,
                                                                              e.layout->size);
    u->H.block<3, 3>(0, kErrVelocity) = Matrix3d::Identity();
    const double var = config_.velocity_sigma_m_per_s * config_.velocity_sigma_m_per_s;
    u->R.topLeftCorner<3, 3>() = Matrix3d::Identity() * var;
  }
  std::unique_ptr<AidingRun> Start(const NavEnvironment& env, uint64_t seed,
                                   uint32_t run) const override;
  const ZuptConfig& config() const { return config_; }
  double imu_rate_hz() const { return imu_rate_hz_; }

 private:
  ZuptConfig config_;
  double imu_rate_hz_;
  std::string path_;
  int64_t decimation_ = 1;
};

class ZuptRun : public AidingRun {
 public:
  ZuptRun(const ZuptSensor& sensor, uint64_t seed, uint32_t run)
      : sensor_(sensor),
        simulator_(sensor.config(), sensor.imu_rate_hz(), seed, run, sensor.path()) {}
  bool Measure(int64_t k, const AidingTruth&) override {
    v_measured_n_ = simulator_.Measure(k);
    return true;
  }
  void Innovation(const AidingEstimate& e, AidingUpdate* u) const override {
    sensor_.Model(e, u);
    u->z.head<3>() = e.state->v_eb_n - v_measured_n_;
  }

 private:
  ZuptSensor sensor_;  // a copy: the run outlives no sensor
  ZuptSimulator simulator_;
  Vector3d v_measured_n_ = Vector3d::Zero();
};

std::unique_ptr<AidingRun> ZuptSensor::Start(const NavEnvironment&, uint64_t seed,
                                             uint32_t run) const {
  return std::make_unique<ZuptRun>(*this, seed, run);
}

}  // namespace

void ValidateZuptConfig(const ZuptConfig& c, double imu_rate_hz, const std::string& path) {
  AidingDecimation(c.rate_hz, imu_rate_hz, path + ".rate_hz");
  CheckSigma(c.velocity_sigma_m_per_s, path + ".velocity_sigma_m_per_s", 10.0, "m/s", true);
}

std::shared_ptr<const AidingSensor> MakeZuptSensor(const ZuptConfig& config, double imu_rate_hz,
                                                   const std::string& path) {
  return std::make_shared<ZuptSensor>(config, imu_rate_hz, path);
}

ZuptSimulator::ZuptSimulator(const ZuptConfig& config, double imu_rate_hz, uint64_t seed,
                             uint32_t run_index, const std::string& path)
    : config_(config) {
  ValidateZuptConfig(config, imu_rate_hz, path);
  decimation_ = AidingDecimation(config.rate_hz, imu_rate_hz, path + ".rate_hz");
  for (uint8_t axis = 0; axis < 3; ++axis) {
    white_[axis] =
        RandomStream(seed, run_index, {SensorId::kZeroVelocity, axis, ErrorTerm::kWhiteNoise, 0});
  }
}

Vector3d ZuptSimulator::Measure(int64_t k) const {
  const uint64_t j = static_cast<uint64_t>(k / decimation_);
  Vector3d v;
  for (int axis = 0; axis < 3; ++axis) {
    v[axis] = config_.velocity_sigma_m_per_s * white_[axis].Gaussian(j);
  }
  return v;
}

}  // namespace driftlab
