// Aiding sensors other than GNSS (gnss.h) for the navigation filters: a barometric altimeter, a
// three-axis magnetometer, and zero-velocity updates (ZUPT) at the trajectory's static periods.
// Each simulator is per run, seeded by the run's random streams (random.h), and produces its
// measurement at the IMU samples that are its epochs (sample k is an epoch when k is a multiple of
// the decimation imu_rate_hz / rate_hz).
//
// Barometric altimeter (Groves 2nd ed., section 6.2.1): h_baro = h_b + b + n, with n white
// (sigma noise_sigma_m per sample) and b a first-order Gauss-Markov bias (the slowly varying
// pressure error), exact discretisation b_{j+1} = a b_j + sigma sqrt(1 - a^2) w_j,
// a = exp(-T / tau), started in its stationary distribution. Streams: RandomStream(seed, run,
// {SensorId::kBarometer, axis 0, term, 0}) at the barometer epoch index j: kWhiteNoise the noise,
// kGaussMarkov the bias drive, kInitialState (index 0) the bias start.
//
// Magnetometer (Groves section 6.1.1, hard- and soft-iron model (6.4)):
//   m_b = S C_n_b m_n + h + n,
// m_n the Earth field in NED, S the uncompensated soft-iron matrix (identity = none), h the
// uncompensated hard-iron vector, n white noise per axis; any field unit (the job uses uT).
// Streams: RandomStream(seed, run, {SensorId::kMagnetometer, axis, kWhiteNoise, 0}) at the
// magnetometer epoch index.
//
// ZUPT: a zero-velocity measurement at the ZUPT epochs where the truth trajectory is static
// (TrajectoryGenerator::IsStaticAt: the simulation knows when the vehicle stands still, as a
// perfect stationarity detector would), v_measured = 0 + n (Groves section 15.3.1): n, white
// per axis with 1-sigma velocity_sigma_m_per_s, is the residual motion of a standing vehicle
// (engine vibration, rocking) that the exactly static truth trajectory lacks. The filter's R is
// the same sigma^2, so the measurement model is the filter's. Streams: RandomStream(seed, run,
// {SensorId::kZeroVelocity, axis, kWhiteNoise, 0}) at the ZUPT sample index k / decimation.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "driftlab/gnss.h"
#include "driftlab/nav_state.h"
#include "driftlab/random.h"
#include "driftlab/sensor_params.h"

namespace driftlab {

struct BarometerConfig {
  double rate_hz = 10.0;       // must divide the IMU rate
  double noise_sigma_m = 0.5;  // white, per sample [m]
  GaussMarkovParams bias;      // [m], [s]; sigma 0 = no bias
};

struct MagnetometerConfig {
  double rate_hz = 100.0;                              // must divide the IMU rate
  Vector3d earth_field_n = Vector3d(20.0, 0.0, 45.0);  // m_n, NED [field unit]
  Vector3d hard_iron_b = Vector3d::Zero();             // h [field unit]
  Matrix3d soft_iron = Matrix3d::Identity();           // S [-]
  double noise_sigma = 0.1;                            // per axis, per sample [field unit]
};

struct ZuptConfig {
  double rate_hz = 1.0;                  // must divide the IMU rate
  double velocity_sigma_m_per_s = 0.01;  // per axis
};

// The aiding a Monte-Carlo job configures (absent = not used).
struct AidingSpec {
  std::optional<GnssConfig> gnss;
  std::optional<BarometerConfig> barometer;
  std::optional<MagnetometerConfig> magnetometer;
  std::optional<ZuptConfig> zupt;
  bool empty() const { return !gnss && !barometer && !magnetometer && !zupt; }
};

// IMU samples per aiding epoch: imu_rate_hz / rate_hz, rounded. Throws SpecError naming `field`
// unless 0 < rate_hz <= imu_rate_hz and the ratio is an integer (to 1e-9 relative).
int64_t AidingDecimation(double rate_hz, double imu_rate_hz, const std::string& field);

// Validation: throws SpecError naming the field under `path` ("aiding.barometer.noise_sigma_m",
// ...) with the value and the allowed range.
void ValidateBarometerConfig(const BarometerConfig& config, double imu_rate_hz,
                             const std::string& path = "aiding.barometer");
void ValidateMagnetometerConfig(const MagnetometerConfig& config, double imu_rate_hz,
                                const std::string& path = "aiding.magnetometer");
void ValidateZuptConfig(const ZuptConfig& config, double imu_rate_hz,
                        const std::string& path = "aiding.zupt");
// All configured aids; the GNSS outages must also end by duration_s (the trajectory's end;
// negative = not checked): "aiding.gnss.outages[i].end_s".
void ValidateAidingSpec(const AidingSpec& aiding, double imu_rate_hz, double duration_s);

// Magnetic declination of the field: atan2(m_E, m_N) [rad].
double MagneticDeclination(const Vector3d& earth_field_n);

// Per run; not thread-safe (holds the bias state). Call Measure with k = 0, 1, 2, ... in order.
class BarometerSimulator {
 public:
  BarometerSimulator(const BarometerConfig& config, double imu_rate_hz, uint64_t seed,
                     uint32_t run_index, const std::string& path = "aiding.barometer");
  int64_t decimation() const { return decimation_; }
  // True if IMU sample k is a barometer epoch; then *h_m = truth height + bias + noise.
  bool Measure(int64_t k, double h_true_m, double* h_m);

 private:
  BarometerConfig config_;
  int64_t decimation_ = 1;
  double gm_a_ = 0.0, gm_drive_ = 0.0;
  RandomStream white_, drive_;
  double bias_m_ = 0.0;
  int64_t last_epoch_ = 0;
};

class MagnetometerSimulator {
 public:
  MagnetometerSimulator(const MagnetometerConfig& config, double imu_rate_hz, uint64_t seed,
                        uint32_t run_index, const std::string& path = "aiding.magnetometer");
  int64_t decimation() const { return decimation_; }
  // True if IMU sample k is a magnetometer epoch; then *m_b is the measured field with the true
  // attitude C_b_n.
  bool Measure(int64_t k, const Matrix3d& C_b_n, Vector3d* m_b) const;

 private:
  MagnetometerConfig config_;
  int64_t decimation_ = 1;
  std::array<RandomStream, 3> white_{};
};

class ZuptSimulator {
 public:
  ZuptSimulator(const ZuptConfig& config, double imu_rate_hz, uint64_t seed, uint32_t run_index,
                const std::string& path = "aiding.zupt");
  // The measured velocity [m/s, NED] at ZUPT sample k (a multiple of the decimation).
  Vector3d Measure(int64_t k) const;

 private:
  ZuptConfig config_;
  int64_t decimation_ = 1;
  std::array<RandomStream, 3> white_{};
};

// ZUPT epochs: the samples k in [first_k, n] with k a multiple of the decimation at which
// is_static(t_k) holds (t_k = k dt_s), ascending.
template <typename IsStatic>
std::vector<int64_t> ZuptEpochs(const ZuptConfig& config, double imu_rate_hz, int64_t first_k,
                                int64_t n, IsStatic&& is_static) {
  const int64_t d = AidingDecimation(config.rate_hz, imu_rate_hz, "aiding.zupt.rate_hz");
  std::vector<int64_t> out;
  for (int64_t k = (first_k + d - 1) / d * d; k <= n; k += d) {
    if (is_static(static_cast<double>(k) / imu_rate_hz)) out.push_back(k);
  }
  return out;
}

}  // namespace driftlab
