// Initial errors as stated (monte_carlo.h InitialErrorSigmas): fixed errors are the start of every
// run exactly, the attitude error is a rotation about the navigation axes (not a perturbation of
// the Euler angles), and a fixed tilt reproduces the textbook free-inertial error growth without
// a random draw.
#include <gtest/gtest.h>

#include <cmath>

#include "driftlab/earth.h"
#include "driftlab/monte_carlo.h"
#include "driftlab/nav_state.h"
#include "driftlab/special_functions.h"

namespace driftlab {
namespace {

constexpr double kDeg = M_PI / 180.0;

// 60 s at rest at 45 N heading east (yaw 90 deg), 20 Hz, error-free IMU.
MonteCarloSpec RestingEastJob(uint32_t runs) {
  MonteCarloSpec spec;
  spec.simulation.motion.initial.llh = {45.0 * kDeg, 7.0 * kDeg, 300.0};
  spec.simulation.motion.initial.attitude.yaw_rad = 90.0 * kDeg;
  spec.simulation.motion.segments.push_back(StaticSegment{60.0});
  spec.simulation.rate_hz = 20.0;
  spec.runs = runs;
  spec.seed = 5;
  spec.epoch_every_samples = 20;
  return spec;
}

// The navigation state of `run` at sample 0 and the truth there, from the replay of the run.
std::pair<NavState, NavState> StartOf(const MonteCarloSpec& spec, uint32_t run) {
  std::pair<NavState, NavState> out;
  bool seen = false;
  ReplayMonteCarloRun(
      spec, run, /*navigate=*/true, [](const MonteCarloRunLayout&) {},
      [&](const MonteCarloRunStep& step) {
        if (step.k == 0 && step.nav != nullptr) {
          out = {*step.nav, *step.truth};
          seen = true;
        }
      });
  EXPECT_TRUE(seen);
  return out;
}

TEST(InitialErrorsTest, FixedErrorsAreTheStartOfEveryRunExactly) {
  MonteCarloSpec spec = RestingEastJob(3);
  spec.initial_errors.fixed_position_ned_m = Vector3d(1.0, -2.0, 3.0);
  spec.initial_errors.fixed_velocity_ned_m_per_s = Vector3d(0.1, 0.0, -0.2);
  spec.initial_errors.fixed_attitude_ned_rad = Vector3d(1e-3, -2e-3, 3e-3);
  ValidateMonteCarloSpec(spec);
  for (uint32_t run : {0u, 2u}) {
    SCOPED_TRACE(run);
    const auto [nav, truth] = StartOf(spec, run);
    // Position: the offset goes in as curvilinear coordinates with the environment's radii and is
    // measured back with the same radii: equal to rounding of ~1e-16 x the 6.4e6 m radius.
    const Vector3d dr = NavEnvironment::Wgs84().PositionErrorNed(nav.llh, truth.llh);
    EXPECT_NEAR(dr.x(), 1.0, 1e-8);
    EXPECT_NEAR(dr.y(), -2.0, 1e-8);
    EXPECT_NEAR(dr.z(), 3.0, 1e-8);
    // Velocity: one addition per axis.
    EXPECT_NEAR((nav.v_eb_n - truth.v_eb_n - Vector3d(0.1, 0.0, -0.2)).norm(), 0.0, 1e-15);
    // Attitude: exp([psi x]) C_b_n with psi the stated rotation; recovered by the rotation vector
    // of C_est C_true^T, exact to the rounding of a few 3 x 3 products and the quaternion (1e-15).
    const Vector3d psi = AttitudeErrorNed(nav.C_b_n(), truth.C_b_n());
    EXPECT_NEAR((psi - Vector3d(1e-3, -2e-3, 3e-3)).norm(), 0.0, 1e-14);
  }
  // No random part: every run starts alike, the spread at t = 0 is exactly zero.
  const MonteCarloStatistics stats = RunMonteCarlo(spec);
  const EpochSummary e0 = stats.SummarizeEpoch(0);
  for (int c = 0; c < kNumErrorComponents; ++c) EXPECT_EQ(e0.components[c].std, 0.0) << c;
}

TEST(InitialErrorsTest, AttitudeSigmaIsARotationAboutTheNavigationAxes) {
  // Heading east, a rotation about north tilts the nose (pitch), one about east rolls the body:
  // for small angles d(roll, pitch, yaw) = (psi_E, -psi_N, psi_D) at yaw 90 deg
  // (EulerErrorFromAttitudeError, error_state.h).
  MonteCarloSpec spec = RestingEastJob(400);
  spec.epoch_every_samples = 1200;
  spec.initial_errors.attitude_ned_rad = Vector3d(1e-3, 2e-3, 3e-3);
  const MonteCarloStatistics stats = RunMonteCarlo(spec);
  const EpochSummary e0 = stats.SummarizeEpoch(0);
  // 400 runs: sample sigma / true sigma in [sqrt(chi2_{a/2}(399)/399), sqrt(chi2_{1-a/2}/399)],
  // three comparisons at Bonferroni a = 0.05 / 3; the small-angle mapping is exact to O(psi^2)
  // = 1e-5 relative, far inside the interval.
  const double a = 0.05 / 3.0;
  const double lo = std::sqrt(ChiSquareQuantile(a / 2, 399.0) / 399.0);
  const double hi = std::sqrt(ChiSquareQuantile(1 - a / 2, 399.0) / 399.0);
  const double expected[3] = {2e-3, 1e-3, 3e-3};  // roll <- psi_E, pitch <- psi_N, yaw <- psi_D
  for (int i = 0; i < 3; ++i) {
    const double s = e0.components[static_cast<int>(ErrorComponent::kRoll) + i].std;
    EXPECT_GT(s, lo * expected[i]) << i;
    EXPECT_LT(s, hi * expected[i]) << i;
  }
}

// A fixed 1 mrad tilt about east at the equator, heading north, error-free IMU: the textbook
// Schuler-and-Earth-rate solution dr_N = R_N th0 w^2 / (w^2 - Omega^2) (cos(Omega t) - cos(w t))
// with th0 = 1e-3 exactly, where a random draw could only reproduce it up to the draw.
TEST(InitialErrorsTest, FixedTiltAtTheEquatorFollowsTheSchulerSolutionExactly) {
  MonteCarloSpec spec;
  spec.simulation.motion.initial.llh = {0.0, 0.0, 0.0};
  spec.simulation.motion.segments.push_back(StaticSegment{10200.0});
  spec.simulation.rate_hz = 1.0;
  spec.simulation.ned.vertical = VerticalChannel::kTruthHeight;
  spec.runs = 1;
  spec.initial_errors.fixed_attitude_ned_rad = Vector3d(0.0, 1e-3, 0.0);
  spec.epoch_every_samples = 300;
  const MonteCarloStatistics stats = RunMonteCarlo(spec);
  auto value = [&](size_t e, ErrorComponent c) {
    return static_cast<double>(stats.data().epochs[e].sum[static_cast<int>(c)].Value());
  };
  // At yaw 0 a rotation about east is a pitch error of the same size (to O(th0^2)).
  EXPECT_NEAR(value(0, ErrorComponent::kPitch), 1e-3, 1e-9);
  const double th0 = 1e-3;
  const double R_N = MeridianRadius(0.0);
  const double w2 = GravityNed(0.0, 0.0).z() / R_N;
  const double Omega = kWgs84EarthRate_rad_per_s;
  for (size_t e = 0; e < stats.num_epochs(); ++e) {
    const double t = stats.data().epoch_times_s[e];
    const double theory =
        R_N * th0 * w2 / (w2 - Omega * Omega) * (std::cos(Omega * t) - std::cos(std::sqrt(w2) * t));
    // Linear theory: the neglected terms are of relative order th0 (1e-3) of the peak error
    // 2 R_N th0 (as PitchErrorAtEquatorFollowsSchulerAndEarthRateSolution, monte_carlo_test.cc).
    EXPECT_NEAR(value(e, ErrorComponent::kPositionNorth), -theory, 2e-3 * 2.0 * R_N * th0)
        << "t = " << t;
  }
}

TEST(InitialErrorsTest, CovarianceAnalysisStartsFromTheRandomPartOnly) {
  // The free INS's analysis predicts the spread about the mean; the fixed part moves the mean.
  MonteCarloSpec spec = RestingEastJob(2);
  spec.initial_errors.position_ned_m = Vector3d(1.0, 2.0, 3.0);
  spec.initial_errors.fixed_position_ned_m = Vector3d(10.0, 10.0, 10.0);
  spec.initial_errors.attitude_ned_rad = Vector3d(1e-3, 1e-3, 2e-3);
  spec.initial_errors.fixed_attitude_ned_rad = Vector3d(5e-3, 0.0, 0.0);
  spec.simulation.ned.vertical = VerticalChannel::kFree;
  spec.covariance = true;
  const MonteCarloOutput output = RunMonteCarloWithAnalysis(spec);
  ASSERT_TRUE(output.covariance.has_value());
  const CovarianceEpoch& start = output.covariance->epochs.front();
  // P0 = diag(sigma^2) exactly for position; the attitude block is diag(psi sigma^2), whose roll,
  // pitch, yaw sigmas at yaw 90 deg are (psi_E, psi_N, psi_D) to rounding.
  EXPECT_NEAR(start.sigma[0], 1.0, 1e-12);
  EXPECT_NEAR(start.sigma[1], 2.0, 1e-12);
  EXPECT_NEAR(start.sigma[2], 3.0, 1e-12);
  EXPECT_NEAR(start.euler_sigma_rad[0], 1e-3, 1e-12);
  EXPECT_NEAR(start.euler_sigma_rad[1], 1e-3, 1e-12);
  EXPECT_NEAR(start.euler_sigma_rad[2], 2e-3, 1e-12);
}

}  // namespace
}  // namespace driftlab
