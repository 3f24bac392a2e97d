// Loosely coupled INS/GNSS error-state Kalman filter on mechanization A (Groves 2nd ed., sections
// 14.1-14.2 and 14.3.1; closed-loop correction, section 14.1.1):
//   * the NED mechanization (ins.h) integrates the IMU increments corrected by the estimated
//     biases: delta_theta - b_g dt, delta_v - b_a dt;
//   * the 15-state error covariance (error_state.h) is propagated along the estimated trajectory,
//     P <- Phi P Phi^T + Q_d, every propagation_step_samples samples (and before each update);
//   * at a GNSS fix the innovation z = (estimated antenna position - fix) [m, NED] and
//     (estimated antenna velocity - fix) [m/s], with
//       H_r = [I, 0, -[(C_b_n l_b) x], 0, 0],
//       H_v = [0, I, -[(C_b_n (omega_ib_b x l_b)) x], 0, -C_b_n [l_b x]]     (Groves
//       section 14.3.1)
//     (signs for x = estimate - truth), R = diag(white^2 + Gauss-Markov^2) (the correlated GNSS
//     error is treated as white: it is not a state), K = P H^T (H P H^T + R)^-1,
//     P <- (I - K H) P (I - K H)^T + K R K^T (Joseph form);
//   * closed loop: the estimated error x = K z is removed from the navigation state at once
//     (position and velocity subtracted, attitude C_b_n <- exp(-[psi x]) C_b_n) and added to the
//     bias estimates, then x = 0. The mechanization restarts from the corrected state, so its
//     first step after a fix uses single-sample coning/sculling (O(dt^2) per fix).
// The bias states are the residual errors of the corrected measurements: x_ba = b_a - b^_a,
// x_bg = b_g - b^_g (the corrected specific force minus the true one).
#pragma once

#include <cstdint>
#include <optional>

#include "driftlab/covariance.h"
#include "driftlab/error_state.h"
#include "driftlab/gnss.h"
#include "driftlab/ins.h"

namespace driftlab {

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
  // GNSS update with a fix taken at the current time; omega_ib_b is the measured body rate (for
  // the lever-arm velocity).
  void Update(const GnssMeasurement& fix, const Vector3d& omega_ib_b);
  // Propagates P over the samples since the last propagation (so that P is at state().t_s).
  void SyncCovariance();

  const NavState& state() const { return ins_.state(); }
  const ErrorStateMatrix& P() const { return propagator_.P(); }
  const Vector3d& accel_bias() const { return accel_bias_; }  // b^_a [m/s^2]
  const Vector3d& gyro_bias() const { return gyro_bias_; }    // b^_g [rad/s]
  // Normalised innovation squared z^T S^-1 z of the last update and its dimension (3 or 6).
  double last_nis() const { return last_nis_; }
  int last_measurement_dim() const { return last_dim_; }

 private:
  NavEnvironment env_;
  double dt_s_;
  InsGnssFilterOptions options_;
  NedMechanization ins_;
  ErrorCovariancePropagator propagator_;
  Vector3d accel_bias_ = Vector3d::Zero();
  Vector3d gyro_bias_ = Vector3d::Zero();
  Vector3d f_n_sum_ = Vector3d::Zero();  // sum of C_b_n delta_v since the last propagation
  int64_t pending_ = 0;                  // samples since the last propagation
  double last_nis_ = 0.0;
  int last_dim_ = 0;
};

// The normalised estimation error squared e^T P^-1 e (NEES) of a 15-state error.
double Nees(const ErrorStateVector& error, const ErrorStateMatrix& P);

// Two-sided 95 % bounds [chi2_0.025(n dof), chi2_0.975(n dof)] / n of the mean of n independent
// chi-square(dof) variables (e.g. the NEES averaged over n runs), by the Wilson-Hilferty
// approximation
//   chi2_p(k) = k (1 - 2 / (9k) + z_p sqrt(2 / (9k)))^3   (relative error < 1e-3 for k >= 30;
// Johnson, Kotz & Balakrishnan, "Continuous Univariate Distributions" vol. 1, 18.5).
void Chi2MeanBounds95(int dof, int n, double* low, double* high);

}  // namespace driftlab
