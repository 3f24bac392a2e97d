#include "driftlab/covariance.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "driftlab/allan.h"
#include "driftlab/error_state.h"
#include "driftlab/ins.h"
#include "driftlab/mc_statistics.h"
#include "driftlab/monte_carlo.h"
#include "driftlab/presets.h"
#include "driftlab/sensors.h"
#include "driftlab/spec_error.h"
#include "driftlab/trajectory.h"
#include "support/bonferroni_checks.h"
#include "support/ins_gnss_scenarios.h"
#include "support/motion_builders.h"

namespace driftlab {
namespace {

// Car-like drive: 10 s static, accelerate to 20 m/s, straight, two turns, straight, slow down.
MotionSpec CarMotion() {
  MotionSpec m;
  m.initial.llh = {45.0 * kDeg, 7.0 * kDeg, 300.0};
  m.segments.push_back(StaticSegment{10.0});
  AccelerateSegment a;
  a.acceleration_m_per_s2 = 2.0;
  a.target_speed_m_per_s = 20.0;
  m.segments.push_back(a);
  m.segments.push_back(ConstantVelocitySegment{20.0});
  m.segments.push_back(testing::TurnByRate(10.0, 90.0, 2.0));
  m.segments.push_back(ConstantVelocitySegment{20.0});
  m.segments.push_back(testing::TurnByRate(-15.0, 180.0, 2.0));
  m.segments.push_back(ConstantVelocitySegment{15.0});
  AccelerateSegment d;
  d.acceleration_m_per_s2 = 1.0;
  d.target_speed_m_per_s = 5.0;
  m.segments.push_back(d);
  return m;
}

// Error of the mechanization started from `truth[0]` perturbed by e0 (position, velocity,
// attitude) with constant biases e0[9:15] added to the ideal increments, at every sample.
std::vector<ErrorStateVector> MechanizationErrors(const Trajectory& t, const ErrorStateVector& e0) {
  NavState init = t.truth[0];
  const double L = init.llh.lat_rad, h = init.llh.h_m;
  init.llh.lat_rad += e0[0] / (t.environment.MeridianRadiusAt(L) + h);
  init.llh.lon_rad += e0[1] / ((t.environment.TransverseRadiusAt(L) + h) * std::cos(L));
  init.llh.h_m -= e0[2];
  init.v_eb_n += e0.segment<3>(kErrVelocity);
  init.q_b_n = Quaterniond(RotationVectorToDcm(e0.segment<3>(kErrAttitude)) * init.C_b_n());
  NedMechanization ins(t.environment, init, t.dt_s, {});
  std::vector<ErrorStateVector> out;
  for (size_t k = 0; k < t.increments.size(); ++k) {
    ImuIncrement m = t.increments[k];
    m.delta_v_ib_b += e0.segment<3>(kErrAccelBias) * t.dt_s;
    m.delta_theta_ib_b += e0.segment<3>(kErrGyroBias) * t.dt_s;
    ins.Update(m);
    const NavError err = ComputeNavError(t.environment, ins.state(), t.truth[k + 1]);
    ErrorStateVector x = ErrorStateVector::Zero(kNumErrorStates);
    x.segment<3>(kErrPosition) = err.r_ned_m;
    x.segment<3>(kErrVelocity) = err.v_ned_m_per_s;
    x.segment<3>(kErrAttitude) = err.psi_nb_n_rad;
    out.push_back(x);
  }
  return out;
}

TEST(ErrorStateModel, LinearModelReproducesMechanizationErrorPropagation) {
  MotionSpec m = CarMotion();
  const Trajectory t = GenerateTrajectory(m, 50.0);
  const int64_t n = static_cast<int64_t>(t.increments.size());
  // One perturbation per block: 1 m, 0.05 m/s, 0.5 mrad, 1 mg, 5 deg/h on every axis.
  const double sizes[5] = {1.0, 0.05, 0.5e-3, 1e-3 * 9.80665, 5.0 * kDeg / 3600.0};
  ErrorStateNoise noise;  // no decay: constant biases
  for (int block = 0; block < 5; ++block) {
    ErrorStateVector e0 = ErrorStateVector::Zero(kNumErrorStates);
    e0.segment<3>(3 * block) = Vector3d(1.0, -0.7, 0.4) * sizes[block];
    const std::vector<ErrorStateVector> mech = MechanizationErrors(t, e0);
    // Linear prediction: x(k+1) = Phi(k) x(k) with F at the truth (Van Loan, 1 sample).
    ErrorStateVector x = e0;
    double worst = 0.0;
    for (int64_t k = 0; k < n; ++k) {
      const Vector3d f_b = t.increments[k].delta_v_ib_b / t.dt_s;
      const ErrorStateMatrix F = ErrorStateSystemMatrix(t.environment, t.truth[k], f_b, noise);
      ErrorStateMatrix Phi, Qd;
      DiscretizeErrorModel(F, ErrorStateMatrix::Zero(kNumErrorStates, kNumErrorStates), t.dt_s,
                           Discretization::kSecondOrder, &Phi, &Qd);
      x = Phi * x;
      for (int g = 0; g < 3; ++g) {
        const double scale = mech[k].segment<3>(3 * g).norm() + 1e-9;
        worst = std::max(worst, (x.segment<3>(3 * g) - mech[k].segment<3>(3 * g)).norm() / scale);
      }
    }
    const ErrorStateVector& last = mech.back();
    std::printf(
        "block %d: final mech r %.4g m v %.4g m/s psi %.4g rad; lin r %.4g v %.4g psi %.4g; "
        "worst rel %.3g\n",
        block, last.segment<3>(0).norm(), last.segment<3>(3).norm(), last.segment<3>(6).norm(),
        x.segment<3>(0).norm(), x.segment<3>(3).norm(), x.segment<3>(6).norm(), worst);
    for (int g = 0; g < 3; ++g) {
      // Second-order (nonlinear) terms: relative size ~ the largest attitude error, < 1e-3 here,
      // plus the F evaluated at the interval start (O(dt) in the turns' attitude change, 2e-3 rad
      // per sample at 15 deg/s, mostly averaging out): 1 % of the error's size.
      EXPECT_NEAR(
          (x.segment<3>(3 * g) - last.segment<3>(3 * g)).norm() / last.segment<3>(3 * g).norm(),
          0.0, 0.01)
          << "block " << block << " group " << g;
    }
  }
}

TEST(ErrorStateModel, VanLoanAndSecondOrderDiscretisationsAgreeToThirdOrder) {
  MotionSpec m = CarMotion();
  const Trajectory t = GenerateTrajectory(m, 10.0);
  ImuErrorModel model = FindImuPreset("tactical");
  ErrorStateNoise noise = MakeErrorStateNoise(model).noise;
  noise.gyro_bias.tau_s = 100.0;  // exercise the decay terms
  noise.accel_bias.tau_s = 100.0;
  const ErrorStateMatrix F =
      ErrorStateSystemMatrix(t.environment, t.truth[400], t.samples[400].f_ib_b, noise);
  const ErrorStateMatrix Qc = ErrorStateProcessNoise(noise);
  for (double dt : {0.1, 0.01}) {
    ErrorStateMatrix Phi1, Q1, Phi2, Q2;
    DiscretizeErrorModel(F, Qc, dt, Discretization::kVanLoan, &Phi1, &Q1);
    DiscretizeErrorModel(F, Qc, dt, Discretization::kSecondOrder, &Phi2, &Q2);
    // Phi: the first omitted Taylor term F^3 dt^3 / 6 bounds the difference (x 1.5 for the rest).
    const double phi_bound = 1.5 * (F * F * F).norm() * dt * dt * dt / 6.0;
    EXPECT_LE((Phi1 - Phi2).norm(), phi_bound + 1e-15) << dt;
    // Q_d: trapezoidal rule error O(dt^3) relative to Q_c dt: bound ||F||^2 dt^3 ||Q_c|| (x 1).
    const double q_bound = F.norm() * F.norm() * dt * dt * dt * Qc.norm();
    EXPECT_LE((Q1 - Q2).norm(), q_bound) << dt;
  }
}

using testing::TacticalRepresentable;

TEST(ErrorStateModel, NoiseFromImuRepresentsEveryStochasticTermAndNamesTheRest) {
  const ErrorStateNoiseFromImu full = MakeErrorStateNoise(FindImuPreset("tactical"));
  auto has = [&](const std::string& prefix) {
    return std::any_of(full.unrepresented.begin(), full.unrepresented.end(),
                       [&](const std::string& s) { return s.rfind(prefix, 0) == 0; });
  };
  EXPECT_FALSE(has("sensor.gyro.bias_flicker"));
  EXPECT_FALSE(has("sensor.accel.scale_factor"));
  EXPECT_FALSE(has("sensor.gyro.misalignment"));
  EXPECT_TRUE(has("sensor.gyro.range"));  // saturation: named with its effect
  // Turn-on bias in the core bias state, flicker as its design's d Gauss-Markov states per axis,
  // scale factor (3) and misalignment (6) per triad: 15 + 2 x 3 d + 2 x 9 states.
  const ErrorStateLayout layout(full.noise);
  const size_t d = DesignFlickerApproximation(FindImuPreset("tactical").gyro.bias_flicker).size();
  EXPECT_EQ(full.noise.gyro_bias.initial_sigma, FindImuPreset("tactical").gyro.turn_on_bias_sigma);
  EXPECT_EQ(layout.gyro_bias_extra.size(), d);
  EXPECT_EQ(layout.accel_bias_extra.size(), d);
  EXPECT_EQ(layout.size, static_cast<int>(15 + 6 * d + 18));
  const ErrorStateNoiseFromImu rep = MakeErrorStateNoise(TacticalRepresentable());
  EXPECT_TRUE(rep.unrepresented.empty());
  EXPECT_EQ(ErrorStateLayout(rep.noise).size, kNumErrorStates);
  // 0.15 deg/sqrt(h) = 4.363e-5 rad/sqrt(s): PSD its square (exact conversion).
  EXPECT_NEAR(rep.noise.gyro_white_psd, std::pow(0.15 * kDeg / 60.0, 2), 1e-20);
  // Without augmentation the scale factor and misalignment become a white-noise bound (named).
  ErrorModelOptions no_aug;
  no_aug.augment_scale_misalignment = false;
  no_aug.max_abs_omega_ib_b = Vector3d(0.1, 0.1, 1.0);
  no_aug.unaided_interval_s = 60.0;
  const ErrorStateNoiseFromImu bound =
      MakeErrorStateNoise(FindImuPreset("tactical"), "sensor", no_aug);
  EXPECT_EQ(ErrorStateLayout(bound.noise).size, layout.size - 18);
  // q = max_i (s^2 w_i^2 + m^2 sum_{j != i} w_j^2) T with 300 ppm, 0.5 mrad: the x (and y) axis,
  // whose misalignment picks up the 1 rad/s of z, beats z's own scale factor.
  const double q_x = std::pow(300e-6 * 0.1, 2) + std::pow(0.5e-3, 2) * (0.01 + 1.0);
  const double q_z = std::pow(300e-6 * 1.0, 2) + std::pow(0.5e-3, 2) * 0.02;
  const double q = std::max(q_x, q_z) * 60.0;
  EXPECT_NEAR(bound.noise.gyro_white_psd - full.noise.gyro_white_psd, q, 1e-15);
}

TEST(ErrorStateModel, FittedFlickerStatesReproduceTheFlickerFloorOverTheRunsTimeScales) {
  // Tactical gyro flicker B = 3 deg/h over 1..1000 s; fitted with 3 states over a run of 1..830 s.
  const FlickerParams f = FindImuPreset("tactical").gyro.bias_flicker;
  const std::vector<BiasStateModel> fit = FitFlickerStates(f, 3, 1.0, 830.0);
  ASSERT_EQ(fit.size(), 3u);
  std::vector<GaussMarkovComponent> components;
  double variance = 0.0, design_variance = 0.0;
  for (const BiasStateModel& b : fit) {
    components.push_back({b.initial_sigma, b.tau_s});
    variance += b.initial_sigma * b.initial_sigma;
  }
  for (const GaussMarkovComponent& c : DesignFlickerApproximation(f)) {
    design_variance += c.sigma * c.sigma;
  }
  // Lumping keeps the total variance exactly (rounding only).
  EXPECT_NEAR(variance / design_variance, 1.0, 1e-12);
  // Allan deviation of the fit against the floor 0.664 B at averaging times inside the run's
  // range: three states over three decades leave a ripple; a lumped group of components spanning
  // a decade has an Allan curve within a factor 1.5 of their sum's (the Gauss-Markov Allan curve's
  // peak is 0.617 sigma at 1.89 tau and falls as sqrt(t) and 1 / sqrt(t) on either side).
  const double floor = std::sqrt(2.0 * std::log(2.0) / M_PI) * f.bias_instability;
  for (double t : {2.0, 5.0, 10.0, 30.0, 100.0, 300.0}) {
    const double adev = SumOfGaussMarkovAllanDeviation(components, t);
    std::printf("t = %5.0f s: ADEV / flicker floor %.3f\n", t, adev / floor);
    EXPECT_GT(adev / floor, 1.0 / 1.5) << t;
    EXPECT_LT(adev / floor, 1.5) << t;
  }
  // count >= the design's size: the design itself.
  EXPECT_EQ(FitFlickerStates(f, kMaxFlickerComponents, 1.0, 830.0).size(),
            DesignFlickerApproximation(f).size());
}

// The 55-state model of the structured-step tests: the tactical preset with 3 flicker states per
// axis and the GNSS position and barometer Gauss-Markov states, along the car drive at 50 Hz; P0
// the initial errors plus random correlations.
struct StructuredCase {
  Trajectory t;
  ErrorStateNoise noise;
  ErrorStateMatrix P0;
};
StructuredCase MakeStructuredCase() {
  StructuredCase c;
  c.t = GenerateTrajectory(CarMotion(), 50.0);
  ErrorModelOptions three;
  three.flicker_states_per_axis = 3;
  c.noise = MakeErrorStateNoise(FindImuPreset("tactical"), "sensor", three).noise;
  c.noise.aiding_states.push_back(
      AidingErrorStates{"aiding.gnss", {0.5, 0.5, 1.0}, 100.0, "position_gauss_markov"});
  c.noise.aiding_states.push_back(AidingErrorStates{"aiding.barometer", {2.0}, 300.0, "bias"});
  const int n = ErrorStateLayout(c.noise).size;
  Eigen::MatrixXd A = Eigen::MatrixXd::Random(n, n) * 1e-3;
  c.P0 = A * A.transpose() + InitialErrorCovariance(Vector3d(1, 1, 2), Vector3d(0.1, 0.1, 0.1),
                                                    Vector3d(1e-3, 1e-3, 5e-3),
                                                    c.t.truth[0].euler(), c.noise);
  return c;
}

TEST(ErrorStateModel, StructuredPropagationEqualsTheDenseSecondOrderStep) {
  // The structured step (covariance.h) is the dense second-order Phi P Phi^T + Q_d rearranged:
  // equal to rounding (1e-12 relative, 51 states, sums of a few hundred products).
  const StructuredCase c = MakeStructuredCase();
  const Trajectory& t = c.t;
  const ErrorStateNoise& noise = c.noise;
  const ErrorStateMatrix& P0 = c.P0;
  const ErrorStateLayout layout(noise);
  ASSERT_EQ(layout.size, 55);
  ErrorCovariancePropagator prop(t.environment, noise, P0, Discretization::kSecondOrder);
  const size_t k = 400;
  const Vector3d f_b = t.increments[k].delta_v_ib_b / t.dt_s;
  const Vector3d w_b = t.increments[k].delta_theta_ib_b / t.dt_s;
  const double dt = 0.2;
  prop.Propagate(t.truth[k], f_b, dt, w_b);
  const ErrorStateMatrix F = ErrorStateSystemMatrix(t.environment, t.truth[k], f_b, noise, w_b);
  ErrorStateMatrix Phi, Qd;
  DiscretizeErrorModel(F, ErrorStateProcessNoise(noise), dt, Discretization::kSecondOrder, &Phi,
                       &Qd);
  const ErrorStateMatrix dense = Phi * P0 * Phi.transpose() + Qd;
  EXPECT_LT((prop.P() - dense).norm() / dense.norm(), 1e-12);
}

TEST(ErrorStateModel, StructuredExactStepEqualsVanLoansDenseExponential) {
  // The kVanLoan propagator sums the power series of the structured blocks (covariance.cc) where
  // the dense method exponentiates the 2N x 2N Van Loan matrix (N = 55): both are exp(F dt) and
  // its noise integral exactly, the series truncated below 1e-17 of its sum. What separates them
  // is the rounding of the dense exponential (Pade with scaling and squaring: relative error
  // ~ N u ||F dt|| ~ 1e-13 here, Higham 2005): 1e-11 relative leaves a factor 100. Steps of
  // 0.02 s (one sample), 0.2 s and 1 s, the last with the turn's largest rates.
  const StructuredCase c = MakeStructuredCase();
  const Trajectory& t = c.t;
  const ErrorStateNoise& noise = c.noise;
  const ErrorStateMatrix& P0 = c.P0;
  const ErrorStateLayout layout(noise);
  ASSERT_EQ(layout.size, 55);
  for (const auto& [k, dt] : {std::pair<size_t, double>{400, 0.02}, {400, 0.2}, {1500, 1.0}}) {
    ErrorCovariancePropagator prop(t.environment, noise, P0, Discretization::kVanLoan);
    const Vector3d f_b = t.increments[k].delta_v_ib_b / t.dt_s;
    const Vector3d w_b = t.increments[k].delta_theta_ib_b / t.dt_s;
    prop.Propagate(t.truth[k], f_b, dt, w_b);
    const ErrorStateMatrix F = ErrorStateSystemMatrix(t.environment, t.truth[k], f_b, noise, w_b);
    ErrorStateMatrix Phi, Qd;
    DiscretizeErrorModel(F, ErrorStateProcessNoise(noise), dt, Discretization::kVanLoan, &Phi, &Qd);
    const ErrorStateMatrix dense = Phi * P0 * Phi.transpose() + Qd;
    EXPECT_LT((prop.P() - dense).norm() / dense.norm(), 1e-11) << "dt = " << dt;
    // The noise integral alone (P0 = 0), where the series' Q_d is all there is.
    ErrorCovariancePropagator from_zero(t.environment, noise,
                                        ErrorStateMatrix::Zero(layout.size, layout.size),
                                        Discretization::kVanLoan);
    from_zero.Propagate(t.truth[k], f_b, dt, w_b);
    EXPECT_LT((from_zero.P() - Qd).norm() / Qd.norm(), 1e-11) << "dt = " << dt;
  }
}

// Acceptance criterion: support/bonferroni_checks.h (5 rule-picked epochs per component, every
// check at the Bonferroni-corrected level; family-wise false-alarm probability <= 5 %).
using testing::ExpectMonteCarloSigmaMatchesPrediction;

TEST(LinearCovariance, FreeInertialStaticSigmaMatchesMonteCarlo) {
  // 400 runs, seed 1, the first tried. Bonferroni criterion above: 5 epochs x 9 components = 45
  // checks at alpha = 0.05 / 45 = 1.1e-3 each; the variance ratio must lie in chi2(399) / 399
  // bounds [0.79, 1.25] (-11 % / +12 % in sigma); family-wise false alarm <= 5 %.
  MonteCarloSpec spec;
  spec.simulation.motion.initial.llh = {45.0 * kDeg, 7.0 * kDeg, 300.0};
  spec.simulation.motion.initial.attitude = {2.0 * kDeg, -1.0 * kDeg, 30.0 * kDeg};
  spec.simulation.motion.segments.push_back(StaticSegment{120.0});
  spec.simulation.rate_hz = 20.0;
  spec.sensor = TacticalRepresentable();
  spec.runs = 400;
  spec.seed = 1;
  spec.initial_errors.position_ned_m = Vector3d(1.0, 1.0, 2.0);
  spec.initial_errors.velocity_ned_m_per_s = Vector3d(0.02, 0.02, 0.05);
  spec.initial_errors.attitude_rad = Vector3d(0.5e-3, 0.5e-3, 2e-3);
  spec.epoch_every_samples = 40;  // 2 s
  spec.threads = 2;
  const MonteCarloStatistics stats = RunMonteCarlo(spec);

  const Trajectory t = GenerateTrajectory(spec.simulation.motion, spec.simulation.rate_hz);
  const ErrorStateNoise noise = MakeErrorStateNoise(*spec.sensor).noise;
  const ErrorStateMatrix P0 = InitialErrorCovariance(
      spec.initial_errors.position_ned_m, spec.initial_errors.velocity_ned_m_per_s,
      spec.initial_errors.attitude_rad, t.truth[0].euler(), noise);
  CovarianceAnalysisOptions o;
  o.step_samples = 2;
  o.epoch_every_samples = 40;
  const std::vector<CovarianceEpoch> predicted = FreeInertialCovariance(t, noise, P0, o);
  ExpectMonteCarloSigmaMatchesPrediction(stats, predicted);
}

TEST(LinearCovariance, BadOptionsNameTheField) {
  const Trajectory t = GenerateTrajectory(CarMotion(), 10.0);
  CovarianceAnalysisOptions o;
  o.step_samples = 0;
  try {
    FreeInertialCovariance(t, {}, ErrorStateMatrix::Zero(kNumErrorStates, kNumErrorStates), o);
    FAIL();
  } catch (const SpecError& e) {
    EXPECT_EQ(e.field(), "covariance.step_samples");
  }
  o.step_samples = 3;
  o.epoch_every_samples = 10;
  try {
    FreeInertialCovariance(t, {}, ErrorStateMatrix::Zero(kNumErrorStates, kNumErrorStates), o);
    FAIL();
  } catch (const SpecError& e) {
    EXPECT_EQ(e.field(), "covariance.epoch_every_samples");
  }
}

}  // namespace
}  // namespace driftlab
