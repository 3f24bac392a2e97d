// Error budget of the linear error model: how much of each navigation error component's variance
// comes from each independent error source (a sensor term, an initial error, an aid's noise).
//
// Method (Gelb, "Applied Optimal Estimation", 1974, section 7.3 "error budgets"; Maybeck,
// "Stochastic Models, Estimation and Control" vol. 1, 1979, section 6.8): with the linear model
// x(k+1) = Phi x(k) + w(k) and, at an aiding update, x+ = (I - K H) x - K v, where the gains K are
// the ones the filter computes from its full covariance P, and with sources s independent (the
// initial error, the process noise w and the measurement noise v split into mutually uncorrelated
// parts), the error covariance is P = sum_s P_s with each P_s propagated alone:
//   P_s(0) = the part of P(0) due to s (initial errors, bias and scale-factor sigmas),
//   P_s(k+1) = Phi P_s Phi^T + Q_d,s,   P_s+ = (I - K H) P_s (I - K H)^T + K R_s K^T,
// Q_d,s and R_s the parts of Q_d and R due to s. The sum is exact for the linear model; only
// rounding separates sum_s P_s from P.
//
// Sources are named as the job names them: "<triad>.<datasheet key>" from the one table of sensor
// terms (sensor_terms.h: gyro.arw, gyro.bias_instability, accel.turn_on_bias, ...),
// "initial.position" / ".velocity" / ".attitude", and "<aid>.<term>" for an aid's own error states
// and measurement noise (gnss.position_gauss_markov, gnss.position_white, barometer.noise, ...).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "driftlab/aiding.h"
#include "driftlab/covariance.h"
#include "driftlab/error_state.h"
#include "driftlab/mc_statistics.h"
#include "driftlab/sensor_params.h"

namespace driftlab {

// One independent error source of the error-state model.
struct ErrorSource {
  std::string name;      // "gyro.arw"
  std::string group;     // "gyro", "accel", "initial", "gnss", "barometer", "zupt"
  ErrorStateMatrix P0;   // its part of the initial covariance (layout size)
  Eigen::VectorXd q_c;   // its part of the diagonal of Q_c (layout size)
  std::string aid;       // its measurement noise: the rows of this aid's R ("aiding.gnss") ...
  std::string aid_term;  // ... whose AidingSensor::NoiseTerm is this ("position_white"); or ""
};

// The sources of the error-state model `noise` (MakeErrorStateNoise of `model`) with initial
// covariance P0 and the aids of `aids` (may be empty): every nonzero entry of P0 and of diag(Q_c)
// belongs to exactly one source, so sum_s P0_s = P0 and sum_s q_c,s = diag(Q_c) exactly; sources
// whose P0 and Q_c parts are both zero and that own no measurement rows are left out. Throws
// SpecError("budget", ...) when P0 couples two sources (it cannot be split into independent
// parts).
std::vector<ErrorSource> SplitErrorSources(const ImuErrorModel& model, const ErrorStateNoise& noise,
                                           const ErrorStateMatrix& P0, const AidingSensors& aids);

// The measurement update of a source's covariance with the gain K the filter computed from its
// full covariance (Joseph form, Maybeck vol. 1, (6-65)):
//   P_s <- (I - K H) P_s (I - K H)^T + K R_s K^T,
// R_s the elements of R whose row and column are both set in `rows` (bit r: row r), else 0.
void SourceJosephUpdate(const Eigen::MatrixXd& H, const Eigen::MatrixXd& R,
                        const Eigen::MatrixXd& K, uint32_t rows, ErrorStateMatrix* P_s);

// Variances of the 11 error components (mc_statistics.h ErrorComponent order) of a covariance P at
// the truth attitude: position and velocity diagonals [m^2, m^2/s^2], roll / pitch / yaw
// diag(T P_psi T^T) [rad^2] (EulerErrorFromAttitudeError), horizontal P_NN + P_EE and 3-D
// P_NN + P_EE + P_DD [m^2] (the mean square of the magnitude). Linear in P, so additive over
// sources.
using ComponentVariances = std::array<double, kNumErrorComponents>;
ComponentVariances ComponentVariancesOf(const ErrorStateMatrix& P, const EulerAngles& attitude);

// The budget a covariance analysis fills in (FilterCovarianceAnalysis): sources in, per epoch and
// source the component variances out.
struct ErrorBudgetRecord {
  std::vector<ErrorSource> sources;
  std::vector<std::vector<ComponentVariances>> variances;  // [epoch][source]
};

}  // namespace driftlab
