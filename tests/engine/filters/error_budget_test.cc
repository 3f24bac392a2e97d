// The error budget's engine parts (error_budget.h): the split of the error-state model into
// independent sources, and the sources' measurement update with the full filter's gain.
#include "driftlab/error_budget.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "driftlab/aiding.h"
#include "driftlab/error_state.h"
#include "driftlab/presets.h"
#include "driftlab/spec_error.h"

namespace driftlab {
namespace {

// The tactical preset with every stochastic term the error-state model represents, a GNSS aid with
// its Gauss-Markov error state, and initial errors.
struct Model {
  ImuErrorModel imu;
  ErrorStateNoise noise;
  ErrorStateMatrix P0;
  AidingSensors aids;
};

Model TacticalWithGnss() {
  Model m;
  m.imu = FindImuPreset("tactical");
  m.imu.gyro.random_walk = 1e-7;
  m.imu.gyro.bias_gauss_markov.sigma = 1e-5;
  m.imu.gyro.bias_gauss_markov.tau_s = 100.0;
  m.imu.gyro.scale_factor_sigma = 1e-4;
  m.imu.gyro.misalignment_sigma_rad = 1e-4;
  m.noise = MakeErrorStateNoise(m.imu).noise;
  GnssConfig gnss;
  gnss.position_gauss_markov_sigma_ned_m = Vector3d(1.0, 1.0, 2.0);
  gnss.position_gauss_markov_tau_s = 300.0;
  m.aids.push_back(MakeGnssSensor(gnss, 100.0));
  for (const auto& aid : m.aids) {
    for (const AidingErrorStates& a : aid->ErrorStates()) m.noise.aiding_states.push_back(a);
  }
  EulerAngles attitude;
  attitude.roll_rad = 0.1;
  attitude.pitch_rad = -0.05;
  attitude.yaw_rad = 1.0;
  m.P0 = InitialErrorCovariance(Vector3d(1, 2, 3), Vector3d(0.1, 0.1, 0.2),
                                Vector3d(1e-3, 1e-3, 5e-3), attitude, m.noise);
  return m;
}

TEST(ErrorBudgetSplit, SharesOfP0AndQcAddUpExactly) {
  const Model m = TacticalWithGnss();
  const std::vector<ErrorSource> sources = SplitErrorSources(m.imu, m.noise, m.P0, m.aids);
  ErrorStateMatrix P0_sum = ErrorStateMatrix::Zero(m.P0.rows(), m.P0.cols());
  Eigen::VectorXd q_sum = Eigen::VectorXd::Zero(m.P0.rows());
  std::set<std::string> names;
  for (const ErrorSource& s : sources) {
    P0_sum += s.P0;
    q_sum += s.q_c;
    EXPECT_TRUE(names.insert(s.name).second) << "duplicate " << s.name;
  }
  // Each entry belongs to one source: the sums are copies, exact to the bit.
  EXPECT_EQ(P0_sum, m.P0);
  EXPECT_EQ(q_sum, ErrorStateProcessNoise(m.noise).diagonal());
  for (const char* expected :
       {"initial.position", "initial.velocity", "initial.attitude", "gyro.arw", "accel.vrw",
        "gyro.turn_on_bias", "gyro.rate_random_walk", "gyro.gauss_markov_sigma",
        "gyro.bias_instability", "gyro.scale_factor", "gyro.misalignment",
        "gnss.position_gauss_markov", "gnss.position_white"}) {
    EXPECT_EQ(names.count(expected), 1u) << expected;
  }
}

TEST(ErrorBudgetSplit, CorrelatedInitialErrorsAcrossSourcesAreRefused) {
  const Model m = TacticalWithGnss();
  ErrorStateMatrix P0 = m.P0;
  P0(0, 3) = P0(3, 0) = 0.01;  // position correlated with velocity
  EXPECT_THROW(SplitErrorSources(m.imu, m.noise, P0, m.aids), SpecError);
}

TEST(ErrorBudgetUpdate, SourceUpdatesWithTheFullGainAddUpToTheUpdate) {
  // P = P_1 + P_2 + P_3 (random positive semi-definite), R owned by source 3 (rows 0-2): the
  // sources updated with the gain of P sum to P's Joseph update (algebraically exact; rounding of
  // O(n) products of O(1) numbers: 1e-12 relative).
  const int n = 20;
  std::srand(7);
  std::vector<ErrorStateMatrix> parts;
  ErrorStateMatrix P = ErrorStateMatrix::Zero(n, n);
  for (int s = 0; s < 3; ++s) {
    const Eigen::MatrixXd A = Eigen::MatrixXd::Random(n, n);
    parts.push_back(A * A.transpose());
    P += parts.back();
  }
  Eigen::Matrix<double, 3, Eigen::Dynamic> H = Eigen::MatrixXd::Random(3, n);
  const Eigen::Matrix3d R = Eigen::Vector3d(0.5, 0.7, 2.0).asDiagonal();
  const Eigen::MatrixXd K = JosephUpdate<3>(H, R, &P);
  ErrorStateMatrix sum = ErrorStateMatrix::Zero(n, n);
  for (int s = 0; s < 3; ++s) {
    SourceJosephUpdate(H, R, K, s == 2 ? 0x7u : 0u, &parts[static_cast<size_t>(s)]);
    sum += parts[static_cast<size_t>(s)];
  }
  EXPECT_LE((sum - P).cwiseAbs().maxCoeff(), 1e-12 * P.cwiseAbs().maxCoeff());
}

}  // namespace
}  // namespace driftlab
