// The aiding sensors of the navigation filters and the one schedule of their measurements.
//
// Each aiding sensor of the INS/GNSS EKF (GNSS gnss.h, barometer, ZUPT, odometer) is an
// AidingSensor: its validated configuration, its epochs (a decimation of the IMU rate, gated by
// GNSS outages or by the ZUPT static windows), its own error states (ErrorStates), and its
// measurement model (Model: H and R), in its own file under engine/src/aiding/. The EKF
// (ins_gnss_filter.h InsGnssFilter::Update) and the covariance analysis (FilterCovarianceAnalysis)
// both call Model, so that the analysis predicts the filter. Per run, AidingSensor::Start gives an
// AidingRun that simulates the sensor's measurement from the truth and forms the filter's
// innovation. AidingSchedule says which aid measures at which IMU sample; the Monte-Carlo runs,
// the covariance analysis and the shared truth (the truth kept at the aiding epochs) all use it.
// MakeAidingSensors is the one list of the aids, in the order the filter applies them at a sample.
//
// The magnetometer feeds the complementary attitude filter (complementary_filter.h) at its own
// decimation; it is not an EKF measurement.
//
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

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "driftlab/error_state.h"
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

// Odometer and non-holonomic constraints of a ground vehicle (odometer.cc: the model, Groves 2nd
// ed. section 16.3): the forward speed of the reference point at lever_arm_b_m with a per-run
// scale-factor error and white noise, and (non_holonomic) zero lateral and vertical velocity of
// that point with white residual motion.
struct OdometerConfig {
  double rate_hz = 10.0;                      // must divide the IMU rate
  double speed_sigma_m_per_s = 0.05;          // white, per epoch
  double scale_factor_sigma = 0.0;            // 1 sigma of the run's constant [-]; 0 = none
  Vector3d lever_arm_b_m = Vector3d::Zero();  // reference point relative to the IMU, body [m]
  bool non_holonomic = true;                  // the constraints as measurements
  double non_holonomic_sigma_m_per_s = 0.1;   // white, per epoch and axis
};

// The aiding a Monte-Carlo job configures (absent = not used).
struct AidingSpec {
  std::optional<GnssConfig> gnss;
  std::optional<BarometerConfig> barometer;
  std::optional<MagnetometerConfig> magnetometer;
  std::optional<ZuptConfig> zupt;
  std::optional<OdometerConfig> odometer;
  bool empty() const { return !gnss && !barometer && !magnetometer && !zupt && !odometer; }
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
void ValidateOdometerConfig(const OdometerConfig& config, double imu_rate_hz,
                            const std::string& path = "aiding.odometer");
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

// ---- The aiding sensors as the EKF and the covariance analysis see them.

// One aiding measurement for the filter: the first `dim` rows of H (dim x error-state size), R
// (dim x dim), and the innovation z = (the measurement predicted from the filter's estimate) -
// (the measurement) (x = estimate - truth, so that z = H x + noise).
struct AidingUpdate {
  static constexpr int kMaxDim = 6;
  int dim = 0;
  Eigen::Matrix<double, kMaxDim, Eigen::Dynamic> H;
  Eigen::Matrix<double, kMaxDim, kMaxDim> R = Eigen::Matrix<double, kMaxDim, kMaxDim>::Zero();
  Eigen::Matrix<double, kMaxDim, 1> z = Eigen::Matrix<double, kMaxDim, 1>::Zero();
};

// The truth an aid measures at one of its epochs: the state and the ideal body rate omega_ib_b
// (the sample's increment delta_theta_ib_b / dt) [rad/s].
struct AidingTruth {
  NavState truth;
  Vector3d omega_ib_b = Vector3d::Zero();
};

// Where the filter is at an update, as an aid's model and innovation need it.
struct AidingEstimate {
  const NavEnvironment* env = nullptr;
  const NavState* state = nullptr;         // the estimated navigation state (truth in the analysis)
  Vector3d omega_ib_b = Vector3d::Zero();  // the estimated body rate [rad/s]
  const ErrorStateLayout* layout = nullptr;
  int first_state = -1;                // index of the aid's first own state, -1 = none
  const double* own_states = nullptr;  // the estimates of the aid's own states (first_state >= 0)
};

// One aid in one run: its simulated measurement and the filter's innovation. Not thread-safe
// (holds the sensor's correlated errors); Measure is called at the aid's epochs in ascending k.
class AidingRun {
 public:
  virtual ~AidingRun() = default;
  // Simulates the measurement at IMU sample k (one of the aid's epochs) from the truth; false if
  // the sensor gives none there.
  virtual bool Measure(int64_t k, const AidingTruth& truth) = 0;
  // H, R (the sensor's Model at the estimate) and z for the last measurement.
  virtual void Innovation(const AidingEstimate& estimate, AidingUpdate* update) const = 0;
};

// One configured aiding sensor of a job (validated on construction).
class AidingSensor {
 public:
  virtual ~AidingSensor() = default;
  // The job field of the aid ("aiding.gnss"), also the owner of its error states.
  virtual const std::string& path() const = 0;
  // IMU samples per epoch (the sensor's rate divides the IMU rate).
  virtual int64_t decimation() const = 0;
  // Epochs only while the truth stands still (ZUPT); is_static decides (AidingSchedule).
  virtual bool OnlyWhileStatic() const { return false; }
  // Whether an epoch at truth time t_s gives a measurement (GNSS: outside the outages).
  virtual bool Available(double /*t_s*/) const { return true; }
  // The sensor's own error states in the EKF (empty: none); the model they are states of.
  virtual std::vector<AidingErrorStates> ErrorStates() const { return {}; }
  // H and R at estimate.state (the filter's estimate, or the truth in the covariance analysis);
  // with estimate.first_state < 0 the sensor's own errors are not states and R holds them.
  virtual void Model(const AidingEstimate& estimate, AidingUpdate* update) const = 0;
  // The term of the sensor's error model that makes row `row` of R (its white measurement noise,
  // named for the error budget: "position_white"); R holds nothing else when the sensor's own
  // errors are states.
  virtual std::string NoiseTerm(int /*row*/) const { return "noise"; }
  // The sensor in run `run` of the job (seed).
  virtual std::unique_ptr<AidingRun> Start(const NavEnvironment& env, uint64_t seed,
                                           uint32_t run) const = 0;
};

using AidingSensors = std::vector<std::shared_ptr<const AidingSensor>>;

// The EKF's aids of `aiding` (GNSS, barometer, ZUPT, odometer: those configured, in this order,
// the order of their updates at a sample), validated against the IMU rate (SpecError naming the
// field). The magnetometer is not among them (complementary filter).
AidingSensors MakeAidingSensors(const AidingSpec& aiding, double imu_rate_hz);
// The field paths of the EKF's aids configured in `aiding` (without validating them), in the same
// order.
std::vector<std::string> AidingSensorPaths(const AidingSpec& aiding);
// Each aid's sensor, from its own file (engine/src/aiding/<aid>.cc); `path` names its fields.
std::shared_ptr<const AidingSensor> MakeGnssSensor(const GnssConfig& config, double imu_rate_hz,
                                                   const std::string& path = "aiding.gnss");
std::shared_ptr<const AidingSensor> MakeBarometerSensor(
    const BarometerConfig& config, double imu_rate_hz,
    const std::string& path = "aiding.barometer");
std::shared_ptr<const AidingSensor> MakeZuptSensor(const ZuptConfig& config, double imu_rate_hz,
                                                   const std::string& path = "aiding.zupt");
std::shared_ptr<const AidingSensor> MakeOdometerSensor(const OdometerConfig& config,
                                                       double imu_rate_hz,
                                                       const std::string& path = "aiding.odometer");

// The one aiding schedule of a job: which aid measures at which IMU sample k in [first_k, n]:
// aid i at the multiples of its decimation, where it is Available (GNSS outages) and, for the
// ZUPT, where the truth stands still (is_static(k / imu_rate_hz), the ZUPT windows).
class AidingSchedule {
 public:
  AidingSchedule(AidingSensors sensors, double imu_rate_hz, int64_t first_k, int64_t n,
                 const std::function<bool(double)>& is_static);
  const AidingSensors& sensors() const { return sensors_; }
  // Bit i set: sensors()[i] measures at sample k (truth time t_s). At most 32 aids.
  uint32_t Due(int64_t k, double t_s) const;
  // Epochs of aid i per second of trajectory, at most (for memory estimates) [1/s].
  double MaxEpochRate(size_t i, double imu_rate_hz) const;

 private:
  AidingSensors sensors_;
  int64_t first_k_ = 0, n_ = 0;
  std::vector<std::vector<int64_t>> static_epochs_;  // per aid: its epochs while static (ZUPT)
};

// The per-run aids of a schedule and the filter's state index of each (-1: no own states).
struct AidingRuns {
  std::vector<std::unique_ptr<AidingRun>> runs;
  std::vector<int> first_state;
};
AidingRuns StartAidingRuns(const AidingSensors& sensors, const NavEnvironment& env, uint64_t seed,
                           uint32_t run, const ErrorStateLayout& layout,
                           const ErrorStateNoise& noise);

// The GNSS measurement model (gnss.cc; Groves 2nd ed., section 14.3.1) at estimate.state with the
// body rate estimate.omega_ib_b: H (rows 0-2 position, 3-5 velocity with use_velocity), R, and,
// with a fix, the innovation z = (estimated antenna position - fix) [m, NED] and (estimated antenna
// velocity - fix) [m/s], the fix corrected by the estimated Gauss-Markov error when it is a state.
void GnssUpdate(const GnssConfig& config, const AidingEstimate& estimate,
                const GnssMeasurement* fix, AidingUpdate* update);

// The multiples of `decimation` in [first_k, n] at which is_static(k / imu_rate_hz) holds,
// ascending (the ZUPT windows of AidingSchedule).
std::vector<int64_t> StaticEpochs(int64_t decimation, double imu_rate_hz, int64_t first_k,
                                  int64_t n, const std::function<bool(double)>& is_static);

// ZUPT epochs: the samples k in [first_k, n] with k a multiple of the decimation at which
// is_static(t_k) holds (t_k = k dt_s), ascending.
template <typename IsStatic>
std::vector<int64_t> ZuptEpochs(const ZuptConfig& config, double imu_rate_hz, int64_t first_k,
                                int64_t n, IsStatic&& is_static) {
  const int64_t d = AidingDecimation(config.rate_hz, imu_rate_hz, "aiding.zupt.rate_hz");
  return StaticEpochs(d, imu_rate_hz, first_k, n, std::forward<IsStatic>(is_static));
}

}  // namespace driftlab
