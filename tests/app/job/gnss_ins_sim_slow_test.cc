// gnss-ins-sim's Monte-Carlo statistics reproduced: its static demo file with its
// mid-accuracy IMU, Gauss-Markov bias started at zero, free integration, through driftlab's job
// path (motion.gnss_ins_sim_file, preset gnss-ins-sim-mid, FLAT earth as gnss-ins-sim's virtual
// inertial frame). The reference sigmas were computed by gnss-ins-sim itself
// (github.com/Aceinna/gnss-ins-sim commit 966ff271bf21d08fbd0e31d1eb47fa5f3acef8d3, Debian
// python3-numpy 1.24.2 / python3-scipy 1.10.1): Sim([100, 0, 0], motion_def-static.csv,
// ref_frame=1, imu=IMU('mid-accuracy', axis=6)), algorithm demo_algorithms/free_integration.py,
// sim.run(200), sample standard deviation (ddof 1) of the 200 runs' errors at the last sample
// (bench/gnss_ins_sim_compare.py computes the same).
#include <gtest/gtest.h>

#include <array>
#include <string>

#include "driftlab/app/job_file.h"
#include "driftlab/app/monte_carlo_job.h"
#include "driftlab/monte_carlo.h"

namespace driftlab::app {
namespace {

TEST(GnssInsSimStatistics, StaticMidAccuracyFinalSigmasInsideTheFTestIntervalOfItsOwnRuns) {
  const std::string file =
      std::string(DRIFTLAB_SOURCE_DIR) + "/tests/data/gnss_ins_sim/motion_def-static.csv";
  const std::string json = R"({"name": "gnss_ins_sim_static_mid", "rate_hz": 100,
    "motion": {"earth_model": "FLAT", "gnss_ins_sim_file": {"path": ")" +
                           file + R"("}},
    "navigation": {"mechanization": "NED"},
    "sensor": {"preset": "gnss-ins-sim-mid"},
    "monte_carlo": {"runs": 200, "seed": 19}})";
  const JobFile job{ParseJobJson(json), "."};
  const MonteCarloSpec spec = ToMonteCarloSpec(job, {});
  const v1::JobResult result = ToJobResult(JobAsRun(job.job, spec), RunMonteCarlo(spec), "test");
  const v1::EpochStatistics& final_epoch = result.epochs(result.epochs_size() - 1);
  // gnss-ins-sim's last sample is at 499.99 s (50000 samples at 100 Hz).
  EXPECT_NEAR(final_epoch.t_s(), 499.99, 1e-9);
  // N, E, D [m]; v_N, v_E, v_D [m/s]; roll, pitch, yaw [deg] (gnss-ins-sim, 200 runs).
  constexpr std::array<double, 9> kGnssInsSimSigma = {
      2.041013568e+03, 2.187302025e+03, 7.071179799e+00, 1.200666678e+01, 1.268745534e+01,
      4.573077719e-02, 3.354270551e-01, 2.791548993e-01, 3.395820476e-01};
  // Equal variances: (s_driftlab / s_gnss-ins-sim)^2 ~ F(199, 199). Two-sided 95 % family-wise
  // over the 9 components (Bonferroni, 0.05 / 9 each): F quantiles 0.00278 and 0.99722 of
  // F(199, 199) = 0.67375 and 1.48423 (scipy.stats.f.ppf).
  constexpr double kLow = 0.67374823, kHigh = 1.48423396;
  for (int i = 0; i < 9; ++i) {
    const double s = final_epoch.components(i).std();
    const double ratio = (s / kGnssInsSimSigma[i]) * (s / kGnssInsSimSigma[i]);
    std::printf("component %d: driftlab sigma %.6g, gnss-ins-sim %.6g, variance ratio %.3f\n",
                i + 1, s, kGnssInsSimSigma[i], ratio);
    EXPECT_GT(ratio, kLow) << "component " << i + 1;
    EXPECT_LT(ratio, kHigh) << "component " << i + 1;
  }
}

}  // namespace
}  // namespace driftlab::app
