// Loosely coupled INS/GNSS error-state Kalman filter on mechanization A (Groves 2nd ed., sections
// 14.1-14.2 and 14.3.1; closed-loop correction, section 14.1.1):
//   * the NED mechanization (ins.h) integrates the IMU increments corrected by the estimated
//     biases (the sum of the bias states' estimates) and, when augmented, the estimated scale
//     factor and misalignment: (I - S^ - M^) (delta_theta - b^_g dt), likewise delta_v (first
//     order inverse of m~ = (I + S + M) m + b);
//   * between fixes each Gauss-Markov state's estimate decays as its conditional mean,
//     b^ <- exp(-T / tau) b^ (Maybeck vol. 1, 4.11);
//   * the error covariance (error_state.h; 15 core states plus the augmented ones of the noise
//     model) is propagated along the estimated trajectory,
//     P <- Phi P Phi^T + Q_d, every propagation_step_samples samples (and before each update);
//   * each aiding sensor's measurement (aiding.h; the model in the sensor's own file, which the
//     covariance analysis uses too), for example at a GNSS fix the innovation z = (estimated
//     antenna position - fix) [m, NED] and (estimated antenna velocity - fix) [m/s], with
//       H_r = [I, 0, -[(C_b_n l_b) x], 0, 0],
//       H_v = [0, I, -[(C_b_n (omega_ib_b x l_b)) x], 0, -C_b_n [l_b x]]     (Groves
//       section 14.3.1)
//     (signs for x = estimate - truth), with the GNSS Gauss-Markov error a state when the noise
//     model has one (the fix corrected by its estimate e^; H = -I on x_e = e - e^; R = white^2),
//     K = P H^T (H P H^T + R)^-1,
//     P <- (I - K H) P (I - K H)^T + K R K^T (Joseph form);
//   * barometer (barometer.cc): z = (h_baro - b^) - h^ = dr_D + x_b + noise (x = estimate - truth,
//     dr_D = -dh; x_b = b - b^ the barometer bias state when the noise model has one),
//     H = [0 0 1 | 0 ... | 1], R = noise^2;
//   * zero velocity (zupt.cc, Groves section 15.3.1): z = v^_eb_n - v_measured (0 plus
//     the residual motion), H = [0, I, 0, 0, 0], R = sigma^2 I;
//   * closed loop: the estimated error x = K z is removed from the navigation state at once
//     (position and velocity subtracted, attitude C_b_n <- exp(-[psi x]) C_b_n) and added to the
//     sensor-error estimates (biases, scale factor, misalignment, aiding errors), then x = 0. The
//     mechanization restarts from the corrected state, so its first step after a fix uses
//     single-sample coning/sculling (O(dt^2) per fix).
// The bias states are the residual errors of the corrected measurements: x_ba = b_a - b^_a,
// x_bg = b_g - b^_g (the corrected specific force minus the true one).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "driftlab/aiding.h"
#include "driftlab/covariance.h"
#include "driftlab/error_state.h"
#include "driftlab/gnss.h"
#include "driftlab/ins.h"

namespace driftlab {

struct ErrorBudgetRecord;  // error_budget.h

struct InsGnssFilterOptions {
  ErrorStateNoise imu_noise;  // process noise and bias models (MakeErrorStateNoise)
  GnssConfig gnss;            // measurement noise, lever arm, use of velocity
  int64_t propagation_step_samples = 10;
  Discretization discretization = Discretization::kSecondOrder;
  NedMechanizationOptions mechanization;
};

class InsGnssFilter {
 public:
  // Throws SpecError for invalid options ("aiding.gnss...", "filter.propagation_step_samples").
  InsGnssFilter(const NavEnvironment& env, const NavState& initial, const ErrorStateMatrix& P0,
                double imu_rate_hz, const InsGnssFilterOptions& options);
  // One IMU interval with the measured increment. No allocation.
  void Predict(const ImuIncrement& measured);
  // The update of an aiding sensor (aiding.h) at the current time with its last measurement:
  // its innovation and model (AidingRun::Innovation) at the filter's estimate, omega_ib_b the
  // measured body rate (corrected here by the estimated gyro errors), first_state the index of the
  // aid's own error states (-1: none; AidingRuns::first_state).
  void Update(const AidingRun& aid, const Vector3d& omega_ib_b, int first_state);
  // GNSS update with a fix taken at the current time (the GNSS model of options().gnss, gnss.cc
  // GnssUpdate); omega_ib_b is the measured body rate (for the lever-arm velocity).
  void Update(const GnssMeasurement& fix, const Vector3d& omega_ib_b);
  // Propagates P over the samples since the last propagation (so that P is at state().t_s).
  void SyncCovariance();

  const NavState& state() const { return ins_.state(); }
  const ErrorStateMatrix& P() const { return propagator_.P(); }
  const Vector3d& accel_bias() const { return accel_bias_; }  // b^_a [m/s^2], all components
  const Vector3d& gyro_bias() const { return gyro_bias_; }    // b^_g [rad/s], all components
  const ErrorStateLayout& layout() const { return propagator_.layout(); }
  const InsGnssFilterOptions& options() const { return options_; }
  // Normalised innovation squared z^T S^-1 z of the last update and its dimension (1 to 6).
  double last_nis() const { return last_nis_; }
  int last_measurement_dim() const { return last_dim_; }

 private:
  // Kalman update with innovation z (estimate minus measurement), then the closed-loop correction.
  void Correct(const AidingUpdate& update);
  template <int M>
  void Correct(const Eigen::Matrix<double, M, Eigen::Dynamic>& H,
               const Eigen::Matrix<double, M, M>& R, const Eigen::Matrix<double, M, 1>& z);
  // The estimate an aid's model sees (omega_ib_b measured).
  AidingEstimate Estimate(const Vector3d& omega_ib_b, int first_state) const;
  // Sums the bias estimates and builds I - S^ - M^ from sensor_estimate_.
  void RefreshCorrections();

  NavEnvironment env_;
  double dt_s_;
  InsGnssFilterOptions options_;
  NedMechanization ins_;
  ErrorCovariancePropagator propagator_;
  Vector3d accel_bias_ = Vector3d::Zero();
  Vector3d gyro_bias_ = Vector3d::Zero();
  Matrix3d gyro_correction_ = Matrix3d::Identity();   // I - S^_g - M^_g
  Matrix3d accel_correction_ = Matrix3d::Identity();  // I - S^_a - M^_a
  // Estimates of the sensor and aiding error states (indices 9.. of the error state, minus 9),
  // and 1 / tau of each (0 for constants and random walks).
  Eigen::VectorXd sensor_estimate_;
  Eigen::VectorXd inverse_tau_;
  Vector3d f_n_sum_ = Vector3d::Zero();    // sum of C_b_n delta_v since the last propagation
  Vector3d theta_sum_ = Vector3d::Zero();  // sum of corrected delta_theta since then
  int64_t pending_ = 0;                    // samples since the last propagation
  double last_nis_ = 0.0;
  int last_dim_ = 0;
};

// Linear covariance analysis of the filter (or of the free INS) along the truth trajectory of
// `motion` at rate_hz, streamed (memory O(step_samples)): P0 at t = 0, propagated as the filter
// does (every step_samples samples, and at every epoch and update sample; F at the truth state at
// the end of the interval with its mean specific force), and at each sample after recording an
// epoch, updated in Joseph form by the aids the schedule has due there, in its order (each aid's
// AidingSensor::Model at the truth state with the ideal body rate: the filter's H and R).
// schedule = nullptr: free inertial. epoch_samples ascending in [0, n]; `noise` holds the aids'
// own error states (AidingSensor::ErrorStates) as the filter's does.
// The gain is the one a filter running on the truth would use; for a consistent filter the
// predicted sigma is the Monte-Carlo spread (Maybeck vol. 1, section 6.8; Gelb, "Applied Optimal
// Estimation", section 7.1, covariance analysis).
//
// With `budget` (error_budget.h), the same pass also propagates each of budget->sources alone
// with the same transitions and, at each update, the gain K of the full P (Gelb 1974, section
// 7.3), and records every source's component variances at the epochs in budget->variances.
std::vector<CovarianceEpoch> FilterCovarianceAnalysis(const MotionSpec& motion, double rate_hz,
                                                      const ErrorStateNoise& noise,
                                                      const ErrorStateMatrix& P0,
                                                      const AidingSchedule* schedule,
                                                      const std::vector<int64_t>& epoch_samples,
                                                      int64_t step_samples, Discretization method,
                                                      ErrorBudgetRecord* budget = nullptr);

// The normalised estimation error squared e^T P^-1 e (NEES) of an error state.
double Nees(const ErrorStateVector& error, const ErrorStateMatrix& P);

// Two-sided 95 % bounds [chi2_0.025(n dof), chi2_0.975(n dof)] / n of the mean of n independent
// chi-square(dof) variables (e.g. the NEES averaged over n runs), by the Wilson-Hilferty
// approximation
//   chi2_p(k) = k (1 - 2 / (9k) + z_p sqrt(2 / (9k)))^3   (relative error < 1e-3 for k >= 30;
// Johnson, Kotz & Balakrishnan, "Continuous Univariate Distributions" vol. 1, 18.5).
void Chi2MeanBounds95(int dof, int n, double* low, double* high);

}  // namespace driftlab
