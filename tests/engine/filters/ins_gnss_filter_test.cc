#include "driftlab/ins_gnss_filter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "driftlab/gnss.h"
#include "driftlab/presets.h"
#include "driftlab/random.h"
#include "driftlab/sensors.h"
#include "driftlab/spec_error.h"
#include "driftlab/trajectory.h"
#include "support/ins_gnss_scenarios.h"
#include "support/motion_builders.h"

namespace driftlab {
namespace {

using testing::DriveWithFinalStraight;

// Seed 1, the first tried. Acceptance: every check at its Bonferroni-corrected level, family-wise
// false alarm <= 5 % (ins_gnss_scenarios.h): NEES, 40 runs: average 15-state NEES at 5 epochs,
// alpha = 0.01 each, chi2(600) / 40 bounds [12.86, 17.32]; outage, 60 runs: MC / predicted
// variance at 5 outage epochs x north, east = 10 checks, alpha = 0.005 each, chi2(60) / 60 bounds
// [0.56, 1.59].
constexpr uint64_t kSeed = 1;

TEST(InsGnssFilter, NeesOfFortyRunsWithinChiSquareBounds) {
  // 40 runs, 50 Hz, an epoch every second.
  testing::ExpectNeesWithinChiSquareBounds(GenerateTrajectory(DriveWithFinalStraight(130.0), 50.0),
                                           40, 50, kSeed);
}

TEST(InsGnssFilter, HorizontalErrorDuringOutageFollowsPrediction) {
  // 60 runs, 50 Hz, outage from 80 s to 140 s.
  testing::ExpectOutageFollowsPrediction(GenerateTrajectory(DriveWithFinalStraight(130.0), 50.0),
                                         80.0, 60, 50, kSeed);
}

TEST(InsGnssFilter, BadAidingConfigurationNamesTheField) {
  auto field_of = [](const GnssConfig& c, double imu_rate) {
    try {
      ValidateGnssConfig(c, imu_rate);
    } catch (const SpecError& e) {
      return e.field();
    }
    return std::string("none");
  };
  GnssConfig c;
  c.position_sigma_ned_m.y() = -1.0;
  EXPECT_EQ(field_of(c, 100.0), "aiding.gnss.position_sigma_ned_m[1]");
  c = GnssConfig();
  c.outages = {{10.0, 30.0}, {35.0, 5.0}};
  EXPECT_EQ(field_of(c, 100.0), "aiding.gnss.outages[1].start_s");
  c = GnssConfig();
  c.rate_hz = 200.0;
  EXPECT_EQ(field_of(c, 100.0), "aiding.gnss.rate_hz");
  c.rate_hz = 3.0;  // 100 / 3 is not an integer number of IMU samples
  EXPECT_EQ(field_of(c, 100.0), "aiding.gnss.rate_hz");
  c = GnssConfig();
  c.velocity_sigma_ned_m_per_s.z() = std::nan("");
  EXPECT_EQ(field_of(c, 100.0), "aiding.gnss.velocity_sigma_ned_m_per_s[2]");
  c = GnssConfig();
  EXPECT_EQ(field_of(c, 100.0), "none");
  InsGnssFilterOptions o;
  o.propagation_step_samples = 0;
  try {
    InsGnssFilter f(NavEnvironment::Wgs84(), NavState(),
                    ErrorStateMatrix::Identity(kNumErrorStates, kNumErrorStates), 100.0, o);
    FAIL();
  } catch (const SpecError& e) {
    EXPECT_EQ(e.field(), "filter.propagation_step_samples");
  }
}

TEST(GnssModel, WhiteAndCorrelatedErrorsHaveTheirSigmas) {
  // Static truth; 4000 epochs: sample sigma within +-2.2 % (95 %, sqrt(2/4000) x 1.96)... the GM
  // part (tau = 20 epochs) has an effective sample of ~4000 / 40 = 100: +-14 % (95 %).
  GnssConfig c;
  c.rate_hz = 10.0;
  c.position_sigma_ned_m = Vector3d(1.0, 2.0, 3.0);
  c.velocity_sigma_ned_m_per_s = Vector3d(0.1, 0.1, 0.2);
  NavState truth;
  truth.llh = {0.5, 0.1, 100.0};
  const NavEnvironment env = NavEnvironment::Wgs84();
  GnssSimulator sim(c, env, 100.0, 5, 0);
  Vector3d s2 = Vector3d::Zero(), v2 = Vector3d::Zero();
  int n = 0;
  for (int64_t k = 0; k < 40000; ++k) {
    GnssMeasurement m;
    truth.t_s = k * 0.01;
    if (!sim.Measure(k, truth, Vector3d::Zero(), &m)) continue;
    const Vector3d dr = env.PositionErrorNed(m.llh, truth.llh);
    s2 += dr.cwiseAbs2();
    v2 += m.v_eb_n.cwiseAbs2();
    ++n;
  }
  EXPECT_EQ(n, 4000);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(std::sqrt(s2[i] / n) / c.position_sigma_ned_m[i], 1.0, 0.03);
    EXPECT_NEAR(std::sqrt(v2[i] / n) / c.velocity_sigma_ned_m_per_s[i], 1.0, 0.03);
  }
  // Correlated error: lag-one correlation of the position error = exp(-T / tau).
  c.position_sigma_ned_m = Vector3d::Constant(1e-6);
  c.position_gauss_markov_sigma_ned_m = Vector3d(2.0, 2.0, 2.0);
  c.position_gauss_markov_tau_s = 2.0;
  GnssSimulator gm(c, env, 100.0, 6, 0);
  double sxx = 0.0, sxy = 0.0, prev = 0.0;
  int m_count = 0;
  for (int64_t k = 0; k < 40000; k += 10) {
    GnssMeasurement m;
    truth.t_s = k * 0.01;
    ASSERT_TRUE(gm.Measure(k, truth, Vector3d::Zero(), &m));
    const double x = env.PositionErrorNed(m.llh, truth.llh).x();
    if (k > 0) sxy += x * prev;
    sxx += x * x;
    prev = x;
    ++m_count;
  }
  EXPECT_NEAR(std::sqrt(sxx / m_count), 2.0, 2.0 * 0.14);
  // Lag-one correlation estimate: standard error ~ sqrt((1 - rho^2) / N_eff) = 0.03 (N_eff 100).
  EXPECT_NEAR(sxy / sxx, std::exp(-0.1 / 2.0), 0.06);
}

}  // namespace
}  // namespace driftlab
