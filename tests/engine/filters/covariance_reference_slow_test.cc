// The structured covariance steps (covariance.cc: block products, the sensor channels of F_ns,
// power series of the exact step) against a dense reference written here: the same analysis loop
// with P <- Phi P Phi^T + Q_d from the dense Phi and Q_d of DiscretizeErrorModel (Van Loan's
// exponential of the 2N x 2N matrix), on the tactical preset's full model (87 states: flicker,
// scale factor, misalignment) and a consumer MEMS preset (icm-42688-p). Slow: ~1000 exponentials
// of 174 x 174 matrices.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "driftlab/covariance.h"
#include "driftlab/error_state.h"
#include "driftlab/presets.h"
#include "driftlab/trajectory.h"
#include "support/motion_builders.h"

namespace driftlab {
namespace {

// 24 s: static, accelerate to 12 m/s, a 90-degree turn, straight.
const Trajectory& ShortDrive() {
  static const Trajectory t = [] {
    MotionSpec m;
    m.initial.llh = {48.1 * kDeg, 11.6 * kDeg, 520.0};
    m.segments.push_back(StaticSegment{4.0});
    AccelerateSegment a;
    a.acceleration_m_per_s2 = 2.0;
    a.target_speed_m_per_s = 12.0;
    m.segments.push_back(a);
    m.segments.push_back(testing::TurnByRate(15.0, 90.0, 2.0));
    m.segments.push_back(ConstantVelocitySegment{4.0});
    return GenerateTrajectory(m, 100.0);
  }();
  return t;
}

// FreeInertialCovariance's loop (covariance.cc) with the dense step; P at the same epochs.
std::vector<ErrorStateMatrix> DenseFreeInertial(const Trajectory& t, const ErrorStateNoise& noise,
                                                const ErrorStateMatrix& P0,
                                                const CovarianceAnalysisOptions& o) {
  const ErrorStateMatrix Q_c = ErrorStateProcessNoise(noise);
  const int64_t n = static_cast<int64_t>(t.increments.size());
  std::vector<ErrorStateMatrix> out{P0};
  ErrorStateMatrix P = P0;
  for (int64_t k = 0; k < n;) {
    const int64_t s = std::min(o.step_samples, n - k);
    Vector3d f_n = Vector3d::Zero(), omega_b = Vector3d::Zero();
    for (int64_t i = 0; i < s; ++i) {
      f_n += 0.5 * (t.truth[k + i].C_b_n() + t.truth[k + i + 1].C_b_n()) *
             t.increments[k + i].delta_v_ib_b;
      omega_b += t.increments[k + i].delta_theta_ib_b;
    }
    const double T = s * t.dt_s;
    const NavState& mid = t.truth[k + s / 2];
    const ErrorStateMatrix F = ErrorStateSystemMatrix(
        t.environment, mid, mid.C_b_n().transpose() * (f_n / T), noise, omega_b / T);
    ErrorStateMatrix Phi, Q_d;
    DiscretizeErrorModel(F, Q_c, T, o.discretization, &Phi, &Q_d);
    P = (Phi * P * Phi.transpose()).eval() + Q_d;
    P = (0.5 * (P + P.transpose())).eval();
    k += s;
    if (k % o.epoch_every_samples == 0 || k == n) out.push_back(P);
  }
  return out;
}

struct Case {
  std::string preset;
  bool correlated_P0;  // P0 with every state correlated (the sensor block dense)
};

TEST(LinearCovarianceReference, StructuredAnalysisEqualsTheDenseAnalysis) {
  // Both loops compute the same Phi P Phi^T + Q_d, exp(F dt) and its noise integral exactly (the
  // structured series truncated below 1e-17 of its sum); what separates them is rounding, mostly
  // the dense exponential's (Pade with scaling and squaring: ~N u ||F dt|| ~ 1e-13 relative per
  // step, Higham 2005) accumulated over the 240 steps of 0.1 s: <= 3e-11, so sigma agrees to
  // 1e-9 relative with a factor 30 to spare. The second-order step (the filter's) against the
  // dense second-order formula to the same bound.
  const Trajectory& t = ShortDrive();
  for (const Case& c : {Case{"tactical", false}, Case{"tactical", true}, Case{"icm-42688-p", false},
                        Case{"icm-42688-p", true}}) {
    ErrorModelOptions options;
    options.time_scale_min_s = 0.25;  // the shortest flicker time constant: |D dt| = 0.4
    options.time_scale_max_s = 600.0;
    const ErrorStateNoise noise =
        MakeErrorStateNoise(FindImuPreset(c.preset), "sensor", options).noise;
    const int N = ErrorStateLayout(noise).size;
    ErrorStateMatrix P0 =
        InitialErrorCovariance(Vector3d(1, 1, 2), Vector3d(0.02, 0.02, 0.02),
                               Vector3d(3e-4, 3e-4, 2e-3), t.truth[0].euler(), noise);
    if (c.correlated_P0) {
      // A correlation coefficient of 0.3 between every pair of states.
      const Eigen::VectorXd s = P0.diagonal().cwiseSqrt();
      P0 = 0.7 * P0 + 0.3 * s * s.transpose();
    }
    for (const Discretization method : {Discretization::kVanLoan, Discretization::kSecondOrder}) {
      CovarianceAnalysisOptions o;
      o.step_samples = 10;
      o.epoch_every_samples = 200;
      o.discretization = method;
      const std::vector<CovarianceEpoch> epochs = FreeInertialCovariance(t, noise, P0, o);
      const std::vector<ErrorStateMatrix> dense = DenseFreeInertial(t, noise, P0, o);
      ASSERT_EQ(epochs.size(), dense.size());
      const std::string what = c.preset + (c.correlated_P0 ? ", correlated P0" : "") +
                               (method == Discretization::kVanLoan ? ", Van Loan" : ", 2nd order") +
                               ", " + std::to_string(N) + " states";
      double worst = 0.0;
      for (size_t e = 0; e < epochs.size(); ++e) {
        for (int i = 0; i < N; ++i) {
          const double ref = std::sqrt(dense[e](i, i));
          const double got = epochs[e].sigma[i];
          worst = std::max(worst, ref > 0.0 ? std::abs(got - ref) / ref : std::abs(got));
        }
      }
      std::printf("%s: largest relative sigma difference %.2e\n", what.c_str(), worst);
      EXPECT_LT(worst, 1e-9) << what;
      // The structured P is symmetric to rounding and positive semi-definite as the dense one.
      const ErrorStateMatrix& P = epochs.back().P;
      EXPECT_LT((P - P.transpose()).cwiseAbs().maxCoeff(), 1e-15 * P.cwiseAbs().maxCoeff()) << what;
      EXPECT_GE(Eigen::SelfAdjointEigenSolver<ErrorStateMatrix>(P).eigenvalues().minCoeff(),
                -1e-12 * P.diagonal().maxCoeff())
          << what;
    }
  }
}

}  // namespace
}  // namespace driftlab
