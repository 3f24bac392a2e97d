// The odometer and non-holonomic constraints (aiding.h OdometerConfig, engine/src/aiding/
// odometer.cc): the measurement model's H is the derivative of its innovation, the simulated
// errors have their sigmas, and the car drive's truth keeps the constraints at the reference point.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <vector>

#include "driftlab/aiding.h"
#include "driftlab/attitude.h"
#include "driftlab/error_state.h"
#include "driftlab/presets.h"
#include "driftlab/trajectory.h"

namespace driftlab {
namespace {

constexpr double kDeg = M_PI / 180.0;

OdometerConfig Config() {
  OdometerConfig c;
  c.rate_hz = 10.0;
  c.speed_sigma_m_per_s = 0.05;
  c.scale_factor_sigma = 0.002;
  c.lever_arm_b_m = Vector3d(-1.2, 0.3, 0.4);
  c.non_holonomic_sigma_m_per_s = 0.1;
  return c;
}

// A moving, turning, tilted state and its error-state layout with the odometer's scale-factor
// state (the tactical preset's bias states; gyro bias at kErrGyroBias).
struct Case {
  NavEnvironment env = NavEnvironment::Wgs84();
  NavState state;
  Vector3d omega_ib_b = Vector3d(0.02, -0.03, 0.25);
  ErrorStateNoise noise;
  Case() {
    state.llh = {48.0 * kDeg, 11.0 * kDeg, 500.0};
    state.v_eb_n = Vector3d(8.0, -5.0, 0.3);
    state.q_b_n = Quaterniond(EulerToDcm(EulerAngles{3.0 * kDeg, -2.0 * kDeg, 150.0 * kDeg}));
    noise = MakeErrorStateNoise(FindImuPreset("tactical")).noise;
    noise.aiding_states.push_back(
        AidingErrorStates{"aiding.odometer", {0.002}, 0.0, "scale_factor"});
  }
};

// H = dz/dx at x = 0: central differences of the innovation in each navigation and sensor error
// of the estimate (x = estimate - truth; x_k = k - k^ moves k^ by -x_k; x_bg = b_g - b^_g moves the
// corrected rate by +x_bg). The innovation is linear in v and in k^ and smooth in psi and omega:
// with steps h = 1e-4 (m/s, rad, rad/s) the central difference's error is O(h^2 |v|) ~ 1e-7, and
// rounding ~ 1e-16 |v| / h ~ 1e-11: tolerance 1e-6.
TEST(Odometer, MeasurementMatrixIsTheDerivativeOfTheInnovation) {
  const Case c;
  const ErrorStateLayout layout(c.noise);
  const int first = layout.AidingFirst(c.noise, "aiding.odometer");
  ASSERT_GE(first, kNumErrorStates);
  const std::shared_ptr<const AidingSensor> sensor = MakeOdometerSensor(Config(), 100.0);
  std::unique_ptr<AidingRun> run = sensor->Start(c.env, 1, 0);
  AidingTruth truth{c.state, c.omega_ib_b};
  ASSERT_TRUE(run->Measure(0, truth));
  const double k_hat0 = 0.001;
  auto innovation = [&](const NavState& s, const Vector3d& omega, double k_hat) {
    AidingEstimate e;
    e.env = &c.env;
    e.state = &s;
    e.omega_ib_b = omega;
    e.layout = &layout;
    e.first_state = first;
    e.own_states = &k_hat;
    AidingUpdate u;
    run->Innovation(e, &u);
    return u;
  };
  const AidingUpdate u0 = innovation(c.state, c.omega_ib_b, k_hat0);
  ASSERT_EQ(u0.dim, 3);
  constexpr double h = 1e-4;
  auto check = [&](int column, const std::function<AidingUpdate(double)>& perturbed) {
    const AidingUpdate plus = perturbed(h), minus = perturbed(-h);
    for (int row = 0; row < 3; ++row) {
      const double derivative = (plus.z(row) - minus.z(row)) / (2.0 * h);
      EXPECT_NEAR(u0.H(row, column), derivative, 1e-6) << "row " << row << " column " << column;
    }
  };
  for (int i = 0; i < 3; ++i) {
    check(kErrVelocity + i, [&](double d) {
      NavState s = c.state;
      s.v_eb_n[i] += d;
      return innovation(s, c.omega_ib_b, k_hat0);
    });
    check(kErrAttitude + i, [&](double d) {
      // Estimated attitude exp([psi x]) C_b_n (the filter's correction undoes it).
      NavState s = c.state;
      Vector3d psi = Vector3d::Zero();
      psi[i] = d;
      s.q_b_n = Quaterniond(RotationVectorToDcm(psi) * c.state.C_b_n());
      return innovation(s, c.omega_ib_b, k_hat0);
    });
    check(kErrGyroBias + i, [&](double d) {
      Vector3d omega = c.omega_ib_b;
      omega[i] += d;
      return innovation(c.state, omega, k_hat0);
    });
    // Position enters only through the Earth rate's latitude: no H (and a derivative below the
    // tolerance: |d omega_ie / dL| |l| / R ~ 1e-11).
    check(kErrPosition + i, [&](double) { return u0; });
  }
  check(first, [&](double d) { return innovation(c.state, c.omega_ib_b, k_hat0 - d); });
  // R: speed noise, constraint noise (the scale factor is a state).
  EXPECT_DOUBLE_EQ(u0.R(0, 0), 0.05 * 0.05);
  EXPECT_DOUBLE_EQ(u0.R(1, 1), 0.1 * 0.1);
  EXPECT_DOUBLE_EQ(u0.R(2, 2), 0.1 * 0.1);
  EXPECT_EQ(u0.R(0, 1), 0.0);
}

// Over N runs at one epoch the speed error s - v_P,x = k v_P,x + n_s has variance
// (sigma_k v_P,x)^2 + sigma_s^2, and the constraint pseudo-measurements (0 + n) variance
// sigma_nhc^2, with the 95 % interval of a variance from N = 4000 deviates +-1.96 sqrt(2 / N)
// (4.4 %); widened to 4 sqrt(2 / N) (8.9 %) for three tests.
TEST(Odometer, SimulatedErrorsHaveTheirSigmas) {
  const Case c;
  OdometerConfig config = Config();
  config.lever_arm_b_m = Vector3d::Zero();
  config.scale_factor_sigma = 0.01;  // 1 %: at 9.4 m/s as large as the 0.05 m/s noise x 1.9
  const std::shared_ptr<const AidingSensor> sensor = MakeOdometerSensor(config, 100.0);
  const Vector3d v_b = c.state.C_b_n().transpose() * c.state.v_eb_n;
  const double v_x =
      v_b.x() + (c.omega_ib_b - c.state.C_b_n().transpose() * c.env.EarthRate(c.state.llh.lat_rad))
                    .cross(config.lever_arm_b_m)
                    .x();
  constexpr int kRuns = 4000;
  Vector3d sum_squares = Vector3d::Zero();
  const AidingTruth truth{c.state, c.omega_ib_b};
  // The measured values through the innovation at the truth with k^ = 0: z = v_P - measured.
  const ErrorStateLayout layout(c.noise);
  for (uint32_t r = 0; r < kRuns; ++r) {
    std::unique_ptr<AidingRun> run = sensor->Start(c.env, 11, r);
    ASSERT_TRUE(run->Measure(50, truth));
    AidingEstimate e;
    e.env = &c.env;
    e.state = &c.state;
    e.omega_ib_b = c.omega_ib_b;
    e.layout = &layout;
    AidingUpdate u;
    run->Innovation(e, &u);
    // z_y,z = v_P,y,z (the estimate, here the truth) - (0 + n): this state has lateral and
    // vertical velocity, so the simulated error is z - v_P.
    const Vector3d error(u.z(0), u.z(1) - v_b.y(), u.z(2) - v_b.z());
    sum_squares += error.cwiseAbs2() / kRuns;
  }
  const double tolerance = 4.0 * std::sqrt(2.0 / kRuns);
  const double speed_var = 0.01 * 0.01 * v_x * v_x + 0.05 * 0.05;
  EXPECT_NEAR(sum_squares[0] / speed_var, 1.0, tolerance);
  EXPECT_NEAR(sum_squares[1] / (0.1 * 0.1), 1.0, tolerance);
  EXPECT_NEAR(sum_squares[2] / (0.1 * 0.1), 1.0, tolerance);
}

// The car drive of examples/car_drive_gnss_odometer.json (its turns and stops) keeps the
// constraints at its reference point 0.3 m below the IMU: the truth's lateral and vertical body
// velocity there stays below 1 % of the constraints' noise (0.1 m/s), so the pseudo-measurements'
// only error is the simulated residual motion (the filter's R).
TEST(Odometer, CarDriveTruthKeepsTheConstraintsAtTheReferencePoint) {
  MotionSpec m;
  m.initial.llh = {48.1374 * kDeg, 11.5755 * kDeg, 520.0};
  m.initial.attitude.yaw_rad = 90.0 * kDeg;
  m.segments.push_back(StaticSegment{5.0});
  AccelerateSegment a;
  a.acceleration_m_per_s2 = 2.0;
  a.target_speed_m_per_s = 6.0;
  m.segments.push_back(a);
  TurnSegment radius;
  radius.radius_m = 15.0;
  radius.right = true;
  radius.angle_rad = 90.0 * kDeg;
  radius.transition_s = 2.0;
  m.segments.push_back(radius);
  TurnSegment rate;
  rate.rate_rad_per_s = -15.0 * kDeg;
  rate.angle_rad = 90.0 * kDeg;
  rate.transition_s = 2.0;
  m.segments.push_back(rate);
  m.segments.push_back(ConstantVelocitySegment{5.0});
  const Trajectory t = GenerateTrajectory(m, 100.0);
  const Vector3d l(0.0, 0.0, 0.3);
  double max_lateral = 0.0, max_vertical = 0.0;
  for (size_t k = 1; k < t.truth.size(); ++k) {
    const NavState& s = t.truth[k];
    const Matrix3d C_n_b = s.C_b_n().transpose();
    const Vector3d omega_ib_b = t.increments[k - 1].delta_theta_ib_b / t.dt_s;
    const Vector3d v_P_b =
        C_n_b * s.v_eb_n + (omega_ib_b - C_n_b * t.environment.EarthRate(s.llh.lat_rad)).cross(l);
    max_lateral = std::max(max_lateral, std::abs(v_P_b.y()));
    max_vertical = std::max(max_vertical, std::abs(v_P_b.z()));
  }
  EXPECT_LT(max_lateral, 1e-3);
  EXPECT_LT(max_vertical, 1e-3);
}

}  // namespace
}  // namespace driftlab
