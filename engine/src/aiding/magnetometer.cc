// Three-axis magnetometer (aiding.h MagnetometerConfig) for the complementary attitude filter:
// validation and the per-run simulator.
#include <cmath>

#include "aiding/checks.h"
#include "driftlab/aiding.h"
#include "driftlab/elementary.h"

namespace driftlab {

using aiding_checks::CheckSigma;

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

double MagneticDeclination(const Vector3d& earth_field_n) {
  return math::Atan2(earth_field_n.y(), earth_field_n.x());
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

}  // namespace driftlab
