// Barometric altimeter (aiding.h BarometerConfig): validation, the per-run simulator, and the
// measurement model the EKF and the covariance analysis share.
#include <algorithm>
#include <cmath>

#include "aiding/checks.h"
#include "driftlab/aiding.h"
#include "driftlab/elementary.h"

namespace driftlab {
namespace {

using aiding_checks::CheckSigma;

// Height measurement h_baro = h + b + n (Groves 2nd ed., section 6.2.1). Innovation
//   z = (estimated down) - (measured down) = (h_baro - b^) - h^ = dr_D + x_b + n
// (x = estimate - truth, dr_D = -dh; x_b = b - b^ the bias state when the filter has one):
//   H = [0 0 1 | 0 ... | 1 (bias state)],  R = noise^2 (+ bias sigma^2 when the bias is no state).

class BarometerSensor : public AidingSensor {
 public:
  BarometerSensor(const BarometerConfig& config, double imu_rate_hz, std::string path)
      : config_(config), imu_rate_hz_(imu_rate_hz), path_(std::move(path)) {
    ValidateBarometerConfig(config, imu_rate_hz, path_);
    decimation_ = AidingDecimation(config.rate_hz, imu_rate_hz, path_ + ".rate_hz");
  }
  const std::string& path() const override { return path_; }
  int64_t decimation() const override { return decimation_; }
  std::vector<AidingErrorStates> ErrorStates() const override {
    if (!(config_.bias.sigma > 0.0)) return {};
    return {AidingErrorStates{path_, {config_.bias.sigma}, config_.bias.tau_s, "bias"}};
  }
  void Model(const AidingEstimate& e, AidingUpdate* u) const override {
    u->dim = 1;
    u->H = Eigen::Matrix<double, AidingUpdate::kMaxDim, Eigen::Dynamic>::Zero(AidingUpdate::kMaxDim,
                                                                              e.layout->size);
    u->H(0, kErrPosition + 2) = 1.0;
    if (e.first_state >= 0) u->H(0, e.first_state) = 1.0;
    // The bias in R only when it is not a state.
    const double bias_sigma = e.first_state >= 0 ? 0.0 : config_.bias.sigma;
    u->R(0, 0) = config_.noise_sigma_m * config_.noise_sigma_m + bias_sigma * bias_sigma;
  }
  std::unique_ptr<AidingRun> Start(const NavEnvironment& env, uint64_t seed,
                                   uint32_t run) const override;

 private:
  BarometerConfig config_;
  double imu_rate_hz_;
  std::string path_;
  int64_t decimation_ = 1;
};

class BarometerRun : public AidingRun {
 public:
  BarometerRun(const BarometerSensor& sensor, const BarometerConfig& config, double imu_rate_hz,
               uint64_t seed, uint32_t run, const std::string& path)
      : sensor_(sensor), simulator_(config, imu_rate_hz, seed, run, path) {}
  bool Measure(int64_t k, const AidingTruth& truth) override {
    return simulator_.Measure(k, truth.truth.llh.h_m, &h_m_);
  }
  void Innovation(const AidingEstimate& e, AidingUpdate* u) const override {
    sensor_.Model(e, u);
    const double bias_estimate_m = e.first_state >= 0 ? e.own_states[0] : 0.0;
    u->z(0) = h_m_ - bias_estimate_m - e.state->llh.h_m;
  }

 private:
  BarometerSensor sensor_;  // a copy: the run outlives no sensor
  BarometerSimulator simulator_;
  double h_m_ = 0.0;
};

std::unique_ptr<AidingRun> BarometerSensor::Start(const NavEnvironment&, uint64_t seed,
                                                  uint32_t run) const {
  return std::make_unique<BarometerRun>(*this, config_, imu_rate_hz_, seed, run, path_);
}

}  // namespace

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

std::shared_ptr<const AidingSensor> MakeBarometerSensor(const BarometerConfig& config,
                                                        double imu_rate_hz,
                                                        const std::string& path) {
  return std::make_shared<BarometerSensor>(config, imu_rate_hz, path);
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

}  // namespace driftlab
