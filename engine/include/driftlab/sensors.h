// Inertial sensor triad error simulation (DESIGN.md "Sensor models"; parameters in
// sensor_params.h, SI units). For one run, a simulator turns ideal IMU outputs into measured ones:
//
//   m~ = Q( Sat( (I + S + M) m + G f + b_fixed + b_turn_on + b_gm(t) + b_flicker(t) + b_rw(t)
//                + n(t) ) )
//
// either integrated over each output interval (ImuIncrement: delta_theta_ib_b, delta_v_ib_b) or as
// point samples at the output instants (ImuSample: omega_ib_b, f_ib_b). Terms, per axis of the
// body-frame triad (IEEE Std 952-1997 / IEEE Std 1293-1998 names):
//   S, M     scale factor (fixed + random per run, optional asymmetry) and misalignment (fixed +
//            random per run, off-diagonal), applied to the ideal value.
//   G f      gyro g-sensitivity; for increments G delta_v_ib_b (= integral of G f_ib_b dt).
//   b_fixed, b_turn_on   constant; turn-on bias drawn once per run.
//   b_gm     first-order Gauss-Markov, exact discretisation
//              b_{k+1} = a b_k + sigma sqrt(1 - a^2) w_k,  a = exp(-dt / tau)
//            and, for increments, the exact integral of b over the interval (jointly Gaussian with
//            b_{k+1} given b_k, two deviates per step; sensors.cc derives it).
//   b_flicker  sum of Gauss-Markov components (DesignFlickerApproximation); component j is
//            advanced exactly every h_j = 2^m_j dt <= tau_j / 32 and held between updates.
//   b_rw     rate / acceleration random walk, b_{k+1} = b_k + K sqrt(dt) w_k; the increment gets
//            the exact integral (Brownian bridge term, second deviate).
//   n        white noise: increments get N sqrt(dt) w (angle / velocity random walk); point
//            samples get N / sqrt(dt) w = N sqrt(rate_hz) w, i.e. white noise of two-sided PSD N^2
//            band-limited to the Nyquist frequency rate_hz / 2, which equals the average of the
//            continuous noise over the sample interval. Both give Allan deviation N / sqrt(tau).
//   Sat      saturation at +-range (point samples) or +-range * dt (increments).
//   Q        quantization to the LSB `quantization` (increments) or quantization * rate_hz (point
//            samples), the remainder carried to the next sample, so that the sum of outputs equals
//            the sum of inputs to within one LSB over any length.
// Gauss-Markov and flicker states start in their stationary distribution (the Gauss-Markov bias
// at 0 instead with GaussMarkovParams::start_at_zero); the random walk at 0.
//
// Randomness: every deviate comes from RandomStream(seed, run_index, {sensor, axis, term, ...}) at
// the index of the step (random.h), so a run's output is a pure function of (model, seed, run,
// rate) and of the sequence of ideal inputs. Deviates are drawn only for terms that are on, and in
// blocks of kDeviateBlock per stream; Apply does not allocate, lock, log or call virtually.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "driftlab/nav_state.h"
#include "driftlab/random.h"
#include "driftlab/sensor_params.h"
#include "driftlab/triad_step_params.h"

namespace driftlab {

// Throws SpecError naming the field (e.g. "sensor.gyro.bias_gauss_markov.tau_s"), its value and
// the allowed range for any NaN / infinite value, negative sigma, tau <= 0 of a term that is on,
// tau_min_s >= tau_max_s, |scale factor| >= 1, ...
void ValidateTriadErrorParams(const TriadErrorParams& params, const std::string& path);
void ValidateImuErrorModel(const ImuErrorModel& model, const std::string& path = "sensor");

// Allan variance [u^2] at averaging time tau_avg_s of a stationary first-order Gauss-Markov
// process with standard deviation sigma and correlation time tau_s:
//   AVAR(t) = (2 sigma^2 tau / t) [1 - tau / (2 t) (3 - 4 e^{-t/tau} + e^{-2 t/tau})]
// (the exponentially correlated noise of IEEE Std 952-1997 Annex C, written with
// q_c^2 = 2 sigma^2 / tau; El-Sheimy, Hou, Niu, IEEE Trans. Instrum. Meas. 57(1), 2008). Limits:
// (2/3) sigma^2 t / tau for t << tau (random walk), 2 sigma^2 tau / t for t >> tau (white); peak
// ADEV 0.6174 sigma at t = 1.8926 tau. A series is used for t < 0.01 tau (cancellation).
double GaussMarkovAllanVariance(double sigma, double tau_s, double tau_avg_s);

// One Gauss-Markov component of the flicker approximation.
struct GaussMarkovComponent {
  double sigma = 0.0;  // [u]
  double tau_s = 0.0;  // [s]
};

// At most this many components (tau_max_s / tau_min_s <= kMaxFlickerRangeRatio).
inline constexpr int kMaxFlickerComponents = 24;
inline constexpr double kMaxFlickerRangeRatio = 1e9;

// Sum-of-Gauss-Markov approximation of flicker bias noise with PSD B^2 / (2 pi f).
// Design (derived here; checked in sensors_test.cc and sensors_slow_test.cc):
//  * Time constants log-spaced with ratio r <= sqrt(10) (two per decade) from tau_min_s / 4 to
//    2 tau_max_s: the smallest integer count n with ln r = ln(8 tau_max / tau_min) / (n - 1)
//    <= ln sqrt(10).
//  * Equal variances sigma_j^2 = B^2 ln(r) / pi. Reason: a component's Allan variance is
//    sigma^2 g(t / tau) with integral over ln tau of g equal to 2 ln 2 (exact; sensors_test checks
//    it numerically), so a dense log-spaced sum gives AVAR = sigma_j^2 2 ln 2 / ln r, which equals
//    the flicker floor (2 ln 2 / pi) B^2 when sigma_j^2 = B^2 ln r / pi. Equivalently, in the
//    frequency domain the sum of the Lorentzian PSDs 2 sigma_j^2 tau_j / (1 + (2 pi f tau_j)^2)
//    integrates to sigma_j^2 / (2 f ln r) per unit ln tau, i.e. B^2 / (2 pi f).
//  * Tail lumping: the components missing below the first one add (sigma_j^2 / ln r) 2 tau_1 / t
//    at t >> tau_1, and the first one alone adds sigma_1^2 2 tau_1 / t there; likewise above the
//    last one ((2/3) t / tau behaviour). So the two end components get variance
//    sigma_j^2 (1 + 1 / ln r), which removes the edge roll-off to first order.
//  Result: Allan deviation within [+0.3 %, +3 %] of 0.664 B over [tau_min_s, tau_max_s] for the
//  default range 1..1000 s (ripple of the two-per-decade lattice); sensors_test asserts +-5 % over
//  several ranges, the brief's requirement being +-10 %.
std::vector<GaussMarkovComponent> DesignFlickerApproximation(const FlickerParams& params);

// Allan deviation [u] of a sum of independent Gauss-Markov components at averaging time t.
double SumOfGaussMarkovAllanDeviation(const std::vector<GaussMarkovComponent>& components,
                                      double tau_avg_s);

// The job constants of one triad at one output rate: every coefficient of the per-sample step
// that depends on the model and the rate only (sensors.cc derives each). Composed once per job
// (ComposeTriadJobConstants) and shared read-only by all runs, by TriadErrorSimulator and by the
// lockstep runner (lockstep_ned.h).
struct TriadJobConstants {
  double dt_s = 0.0;
  Eigen::Vector3d half_asymmetry = Eigen::Vector3d::Zero();
  bool has_asymmetry = false;
  // White noise: deviate scale for increments (N sqrt(dt)) and point samples (N / sqrt(dt)).
  bool white_noise = false;
  double white_increment = 0.0, white_sample = 0.0;
  // Gauss-Markov: b' = gm_decay b + gm_drive_sigma w1; increment integral =
  // gm_mean_gain b + gm_integral_w1_gain w1 + gm_integral_w2_gain w2 (sensors.cc).
  bool gauss_markov = false;
  double gm_decay = 0.0, gm_drive_sigma = 0.0, gm_mean_gain = 0.0;
  double gm_integral_w1_gain = 0.0, gm_integral_w2_gain = 0.0;
  // Random walk: b' = b + rw_step_sigma w1; increment integral = b dt + (dt/2) step +
  // rw_bridge_sigma w2.
  bool random_walk = false;
  double rw_step_sigma = 0.0, rw_bridge_sigma = 0.0;
  // The part of an increment's error that no state carries to the next step: the white noise,
  // the Gauss-Markov integral's w2 part and the random walk's Brownian-bridge w2 part. They are
  // independent zero-mean Gaussians, so their sum is one Gaussian of the summed variance and
  // the increment step draws ONE deviate for it (stream kWhiteNoise):
  //   independent_sigma = sqrt(white_increment^2 + gm_integral_w2_gain^2 + rw_bridge_sigma^2),
  // exactly white_increment when only white noise is on. Same distribution as three deviates,
  // 3 instead of 5 deviates per axis for white + GM + random walk.
  bool independent = false;
  double independent_sigma = 0.0;
  // Flicker: the design and, per component j, the decay and drive over its update period
  // 2^flicker_period_log2[j] samples.
  std::vector<GaussMarkovComponent> flicker;
  std::array<double, kMaxFlickerComponents> flicker_decay{};
  std::array<double, kMaxFlickerComponents> flicker_drive_sigma{};
  std::array<int, kMaxFlickerComponents> flicker_period_log2{};
  double range = 0.0;         // 0 = off
  double quantization = 0.0;  // increment LSB; 0 = off
};

// Validates `params` (field path `path`) and rate_hz, then composes the job constants.
TriadJobConstants ComposeTriadJobConstants(const TriadErrorParams& params, double rate_hz,
                                           const std::string& path = "sensor");
// The job constants flattened for the lane kernel's error step (terms that are off: flag 0).
TriadStepParams TriadStepParamsOf(const TriadJobConstants& job);
static_assert(kTriadStepMaxFlicker == kMaxFlickerComponents);

// The constants of one triad in one run, drawn from the run's streams: I + S + M (without
// asymmetry), b_fixed + b_turn_on, and the start states of the Gauss-Markov and flicker terms.
struct TriadRunConstants {
  Eigen::Matrix3d scale_misalignment = Eigen::Matrix3d::Identity();
  Eigen::Vector3d constant_bias = Eigen::Vector3d::Zero();
  std::array<double, 3> gm_state{};
  std::array<std::array<double, kMaxFlickerComponents>, 3> flicker_state{};
};
TriadRunConstants DrawTriadRunConstants(const TriadErrorParams& params,
                                        const TriadJobConstants& job, SensorId sensor,
                                        uint64_t seed, uint32_t run_index);

// Error simulator of one sensor triad for one run. Built once per run (allocates then); Apply*
// is the per-sample hot path. Not thread-safe (it holds the run's state); use one per run.
class TriadErrorSimulator {
 public:
  // Throws SpecError (field path `path`) for invalid params or rate_hz.
  TriadErrorSimulator(const TriadErrorParams& params, SensorId sensor, uint64_t seed,
                      uint32_t run_index, double rate_hz, const std::string& path = "sensor");

  // Measured increment [u s] over the next output interval from the ideal increment [u s].
  // `additive_increment` (e.g. G delta_v) is added after scale factor and misalignment.
  Eigen::Vector3d ApplyIncrement(const Eigen::Vector3d& ideal_increment,
                                 const Eigen::Vector3d& additive_increment);
  // Measured point sample [u] at the next output instant from the ideal value [u].
  Eigen::Vector3d ApplySample(const Eigen::Vector3d& ideal, const Eigen::Vector3d& additive);

  int64_t step() const { return step_; }
  double dt_s() const { return dt_s_; }
  // Per-run constants (fixed + random): I + S + M (without asymmetry) and b_fixed + b_turn_on.
  const Eigen::Matrix3d& scale_misalignment() const { return scale_misalignment_; }
  const Eigen::Vector3d& constant_bias() const { return constant_bias_; }
  const std::vector<GaussMarkovComponent>& flicker_components() const { return flicker_; }
  // The flicker update period of component j is 2^flicker_period_log2(j) samples.
  int flicker_period_log2(int j) const { return flicker_period_log2_[j]; }

  // Deviates drawn per stream refill.
  static constexpr int kDeviateBlock = 64;

 private:
  // A stream and a cache of kDeviateBlock of its deviates; At(i) returns deviate i.
  struct Channel {
    RandomStream stream;
    uint64_t base = ~uint64_t{0};
    std::array<double, kDeviateBlock> buffer{};
    double At(uint64_t index) {
      if (index < base || index - base >= static_cast<uint64_t>(kDeviateBlock)) Refill(index);
      return buffer[index - base];
    }
    void Refill(uint64_t index);
  };

  Channel& ChannelAt(int first, int axis) { return channels_[first + axis]; }

  double dt_s_ = 0.0;
  int64_t step_ = 0;

  Eigen::Matrix3d scale_misalignment_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d half_asymmetry_ = Eigen::Vector3d::Zero();
  bool has_asymmetry_ = false;
  Eigen::Vector3d constant_bias_ = Eigen::Vector3d::Zero();

  // White noise: deviate scale for point samples (N / sqrt(dt); the increment step's scale is
  // TriadJobConstants::independent_sigma).
  bool white_noise_ = false;
  double white_sample_ = 0.0;
  // Gauss-Markov: b' = a b + drive w1 (point samples; the increment step is the kernel's).
  double gm_a_ = 0.0, gm_drive_ = 0.0;
  // Random walk: b' = b + step w1.
  double rw_step_ = 0.0;
  // Flicker components.
  std::vector<GaussMarkovComponent> flicker_;
  std::array<double, kMaxFlickerComponents> flicker_a_{};
  std::array<double, kMaxFlickerComponents> flicker_drive_{};
  std::array<int, kMaxFlickerComponents> flicker_period_log2_{};
  int n_flicker_ = 0;

  double range_ = 0.0;         // 0 = off
  double quantization_ = 0.0;  // increment LSB; 0 = off

  // Channel index of the first axis of each stream; -1 = off. independent_ch_ is the kWhiteNoise
  // stream: the increments' state-independent deviate, and the white noise of point samples.
  int independent_ch_ = -1, gm_ch_ = -1, rw_ch_ = -1, flicker_ch_ = -1;
  std::vector<Channel> channels_;

  // The increment step is the triad error step at one lane (TriadStep<1>, engine/src/sensors/
  // triad_step.h, which the lockstep runs run at W lanes); these are its job constants (the
  // lockstep runs' struct) and run state, with the field names of lockstep::TriadLanes (one double
  // per lane).
  struct StepState {
    double scale_misalignment[3][3] = {};  // [row][column]
    double constant_bias[3] = {};
    // Per-axis state.
    double gm_state[3] = {};
    double rw_state[3] = {};
    double remainder[3] = {};
    double flicker_state[3][kMaxFlickerComponents] = {};
  };
  TriadStepParams step_params_;
  StepState state_;
};

// The error simulator of a full IMU (gyro and accelerometer triads) for one run at one output
// rate. Gyro measurements include G f (g-sensitivity) from the ideal specific force.
// Construction validates the model (paths "sensor.gyro...", "sensor.accel...") and draws the
// run's constants; each Apply advances both triads by one output sample.
class ImuErrorSimulator {
 public:
  ImuErrorSimulator(const ImuErrorModel& model, uint64_t seed, uint32_t run_index, double rate_hz);

  void Apply(const ImuIncrement& ideal, ImuIncrement* measured);
  void Apply(const ImuSample& ideal, ImuSample* measured);

  const TriadErrorSimulator& gyro() const { return gyro_; }
  const TriadErrorSimulator& accel() const { return accel_; }

 private:
  Eigen::Matrix3d gyro_g_sensitivity_;
  bool has_g_sensitivity_ = false;
  TriadErrorSimulator gyro_;
  TriadErrorSimulator accel_;
};

}  // namespace driftlab
