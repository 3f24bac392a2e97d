#include "driftlab/aiding.h"

#include <cmath>

#include "driftlab/elementary.h"
#include "driftlab/spec_error.h"

namespace driftlab {
namespace {

void CheckSigma(double value, const std::string& field, double max, const std::string& unit,
                bool positive) {
  const bool ok = std::isfinite(value) && (positive ? value > 0.0 : value >= 0.0) && value <= max;
  if (!ok) {
    throw SpecError(
        field, ValueText(value),
        std::string(positive ? "0 < " : "0 <= ") + "sigma <= " + ValueText(max) + " " + unit);
  }
}

}  // namespace

int64_t AidingDecimation(double rate_hz, double imu_rate_hz, const std::string& field) {
  if (!std::isfinite(rate_hz) || rate_hz <= 0.0 || rate_hz > imu_rate_hz) {
    throw SpecError(field, ValueText(rate_hz),
                    "0 < rate_hz <= " + ValueText(imu_rate_hz) + " Hz (not above the IMU rate)");
  }
  const double ratio = imu_rate_hz / rate_hz;
  if (std::abs(ratio - std::round(ratio)) > 1e-9 * ratio) {
    throw SpecError(field, ValueText(rate_hz),
                    "the IMU rate " + ValueText(imu_rate_hz) + " Hz divided by an integer");
  }
  return static_cast<int64_t>(std::llround(ratio));
}

void ValidateBarometerConfig(const BarometerConfig& c, double imu_rate_hz,
                             const std::string& path) {
  AidingDecimation(c.rate_hz, imu_rate_hz, path + ".rate_hz");
  CheckSigma(c.noise_sigma_m, path + ".noise_sigma_m", 1000.0, "m", true);
  CheckSigma(c.bias.sigma, path + ".bias_gauss_markov_sigma_m", 1000.0, "m", false);
  if (c.bias.sigma > 0.0 && (!std::isfinite(c.bias.tau_s) || c.bias.tau_s <= 0.0)) {
    throw SpecError(path + ".bias_gauss_markov_tau_s", ValueText(c.bias.tau_s),
                    "> 0 s when bias_gauss_markov_sigma_m > 0");
  }
}

void ValidateMagnetometerConfig(const MagnetometerConfig& c, double imu_rate_hz,
                                const std::string& path) {
  AidingDecimation(c.rate_hz, imu_rate_hz, path + ".rate_hz");
  if (!c.earth_field_n.allFinite() || c.earth_field_n.head<2>().norm() <= 0.0) {
    throw SpecError(path + ".earth_field_ned_ut",
                    ValueText(c.earth_field_n.x()) + ", " + ValueText(c.earth_field_n.y()) + ", " +
                        ValueText(c.earth_field_n.z()),
                    "finite, with a non-zero horizontal part (north, east) to give a heading");
  }
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(c.hard_iron_b[i])) {
      throw SpecError(path + ".hard_iron_ut[" + std::to_string(i) + "]",
                      ValueText(c.hard_iron_b[i]), "finite");
    }
  }
  for (int i = 0; i < 9; ++i) {
    const double v = c.soft_iron(i / 3, i % 3);
    if (!std::isfinite(v) || std::abs(v) > 10.0) {
      throw SpecError(path + ".soft_iron[" + std::to_string(i) + "]", ValueText(v),
                      "-10 <= value <= 10");
    }
  }
  if (!(std::abs(c.soft_iron.determinant()) > 1e-6)) {
    throw SpecError(path + ".soft_iron", "determinant " + ValueText(c.soft_iron.determinant()),
                    "an invertible matrix (|det| > 1e-6)");
  }
  CheckSigma(c.noise_sigma, path + ".noise_sigma_ut", 1.0e4, "uT", false);
}

void ValidateZuptConfig(const ZuptConfig& c, double imu_rate_hz, const std::string& path) {
  AidingDecimation(c.rate_hz, imu_rate_hz, path + ".rate_hz");
  CheckSigma(c.velocity_sigma_m_per_s, path + ".velocity_sigma_m_per_s", 10.0, "m/s", true);
}

void ValidateAidingSpec(const AidingSpec& a, double imu_rate_hz, double duration_s) {
  if (a.gnss) {
    ValidateGnssConfig(*a.gnss, imu_rate_hz, "aiding.gnss");
    for (size_t i = 0; duration_s >= 0.0 && i < a.gnss->outages.size(); ++i) {
      const GnssOutage& o = a.gnss->outages[i];
      const double end_s = o.start_s + o.duration_s;
      if (end_s > duration_s * (1.0 + 1e-12)) {
        throw SpecError("aiding.gnss.outages[" + std::to_string(i) + "].end_s", ValueText(end_s),
                        "<= " + ValueText(duration_s) + " s (the trajectory's duration)");
      }
    }
  }
  if (a.barometer) ValidateBarometerConfig(*a.barometer, imu_rate_hz);
  if (a.magnetometer) ValidateMagnetometerConfig(*a.magnetometer, imu_rate_hz);
  if (a.zupt) ValidateZuptConfig(*a.zupt, imu_rate_hz);
}

double MagneticDeclination(const Vector3d& earth_field_n) {
  return math::Atan2(earth_field_n.y(), earth_field_n.x());
}

BarometerSimulator::BarometerSimulator(const BarometerConfig& config, double imu_rate_hz,
                                       uint64_t seed, uint32_t run_index, const std::string& path)
    : config_(config) {
  ValidateBarometerConfig(config, imu_rate_hz, path);
  decimation_ = AidingDecimation(config.rate_hz, imu_rate_hz, path + ".rate_hz");
  white_ = RandomStream(seed, run_index, {SensorId::kBarometer, 0, ErrorTerm::kWhiteNoise, 0});
  drive_ = RandomStream(seed, run_index, {SensorId::kBarometer, 0, ErrorTerm::kGaussMarkov, 0});
  if (config.bias.sigma > 0.0) {
    // b_{j+1} = a b_j + sigma sqrt(1 - a^2) w_j, a = exp(-T / tau): exact for the continuous
    // first-order Gauss-Markov process sampled at T (Maybeck vol. 1, section 4.9).
    gm_a_ = math::Exp(-1.0 / (config.rate_hz * config.bias.tau_s));
    gm_drive_ = config.bias.sigma * std::sqrt(1.0 - gm_a_ * gm_a_);
    const RandomStream start(seed, run_index,
                             {SensorId::kBarometer, 0, ErrorTerm::kInitialState, 0});
    bias_m_ = config.bias.sigma * start.Gaussian(0);
  }
}

bool BarometerSimulator::Measure(int64_t k, double h_true_m, double* h_m) {
  if (k % decimation_ != 0) return false;
  const int64_t j = k / decimation_;
  if (config_.bias.sigma > 0.0) {
    for (int64_t e = last_epoch_ + 1; e <= j; ++e) {
      bias_m_ = gm_a_ * bias_m_ + gm_drive_ * drive_.Gaussian(static_cast<uint64_t>(e));
    }
  }
  last_epoch_ = std::max(last_epoch_, j);
  *h_m = h_true_m + bias_m_ + config_.noise_sigma_m * white_.Gaussian(static_cast<uint64_t>(j));
  return true;
}

MagnetometerSimulator::MagnetometerSimulator(const MagnetometerConfig& config, double imu_rate_hz,
                                             uint64_t seed, uint32_t run_index,
                                             const std::string& path)
    : config_(config) {
  ValidateMagnetometerConfig(config, imu_rate_hz, path);
  decimation_ = AidingDecimation(config.rate_hz, imu_rate_hz, path + ".rate_hz");
  for (uint8_t axis = 0; axis < 3; ++axis) {
    white_[axis] =
        RandomStream(seed, run_index, {SensorId::kMagnetometer, axis, ErrorTerm::kWhiteNoise, 0});
  }
}

bool MagnetometerSimulator::Measure(int64_t k, const Matrix3d& C_b_n, Vector3d* m_b) const {
  if (k % decimation_ != 0) return false;
  const uint64_t j = static_cast<uint64_t>(k / decimation_);
  // m_b = S C_n_b m_n + h + n   (Groves (6.4) with the calibration left uncompensated)
  *m_b = config_.soft_iron * (C_b_n.transpose() * config_.earth_field_n) + config_.hard_iron_b;
  if (config_.noise_sigma > 0.0) {
    for (int axis = 0; axis < 3; ++axis)
      (*m_b)[axis] += config_.noise_sigma * white_[axis].Gaussian(j);
  }
  return true;
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
