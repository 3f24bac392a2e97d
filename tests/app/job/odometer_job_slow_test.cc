// The odometer and non-holonomic constraints (docs/aiding.md) through the job path, by the
// filter-honesty checks of aided_job_slow_test.cc: examples/car_drive_gnss_odometer.json (the car
// drive with GNSS at 1 Hz, a 60 s outage from 200 s to 260 s, ZUPT, and the odometer with its
// scale factor as an EKF state), reduced to the IMU terms the error-state model represents, with
// 500 runs -> ToMonteCarloSpec -> RunMonteCarloWithAnalysis -> ToJobResult.
//
// The criteria (aided_job_slow_test.cc explains them): at 5 well-separated epochs (before the
// outage, its last fix, its middle and end, after it), for the 9 position, velocity and attitude
// components, (N - 1) s^2 / sigma_pred^2 inside [chi2_{a/2}(N - 1), chi2_{1-a/2}(N - 1)] with
// a = 0.05 / 45 (Bonferroni: family-wise false alarm <= 5 %; N = 500: about +-10 % on sigma);
// the N-run average NEES of the 9 navigation states at each epoch inside chi2(9 N) / N at
// a = 0.05 / 5. ONE seed, the example's seed 1: the first and only seed tried.
//
// The same checks on the example as it is (the tactical preset's full sensor model: flicker bias
// instability, scale factor, misalignment as the EKF's augmented states) with 200 runs (about
// +-17 % on sigma per comparison at the Bonferroni level).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "driftlab/app/job_file.h"
#include "driftlab/app/monte_carlo_job.h"
#include "driftlab/ins_gnss_filter.h"
#include "driftlab/monte_carlo.h"
#include "support/sample_statistics.h"

namespace driftlab::app {
namespace {

constexpr int kOdometerRuns = 500;

using testing::Chi2Quantile;
using testing::NormalQuantile;

// An example job reduced to the sensor terms the error-state model represents (flicker bias
// instability, scale factor, misalignment and range off), with the covariance analysis.
JobFile ReducedOdometerJob(const std::string& example, int runs) {
  JobFile file = LoadJobFile(std::string(DRIFTLAB_SOURCE_DIR) + "/examples/" + example);
  v1::Job& job = file.job;
  v1::GyroModel* gyro = job.mutable_sensor()->mutable_gyro();
  gyro->set_bias_instability_deg_per_h(0.0);
  gyro->set_scale_factor_sigma_ppm(0.0);
  gyro->set_misalignment_sigma_mrad(0.0);
  gyro->set_range_deg_per_s(0.0);
  v1::AccelModel* accel = job.mutable_sensor()->mutable_accel();
  accel->set_bias_instability_ug(0.0);
  accel->set_scale_factor_sigma_ppm(0.0);
  accel->set_misalignment_sigma_mrad(0.0);
  accel->set_range_g(0.0);
  job.mutable_monte_carlo()->set_runs(runs);
  job.mutable_monte_carlo()->set_covariance(true);
  return file;
}

// The example as it is (the full sensor model), with the covariance analysis.
JobFile FullOdometerJob(int runs) {
  JobFile file =
      LoadJobFile(std::string(DRIFTLAB_SOURCE_DIR) + "/examples/car_drive_gnss_odometer.json");
  file.job.mutable_monte_carlo()->set_runs(runs);
  file.job.mutable_monte_carlo()->set_covariance(true);
  return file;
}

v1::JobResult RunOdometerJob(const JobFile& file) {
  const MonteCarloSpec spec = ToMonteCarloSpec(file, {});
  const MonteCarloOutput output = RunMonteCarloWithAnalysis(spec);
  return ToJobResult(JobAsRun(file.job, spec), output, "test");
}

int OdometerEpochAt(const v1::JobResult& result, double t_s) {
  for (int e = 0; e < result.epochs_size(); ++e) {
    if (std::abs(result.epochs(e).t_s() - t_s) < 1e-6) return e;
  }
  ADD_FAILURE() << "no epoch at " << t_s;
  return 0;
}

const std::vector<double> kOdometerTimes = {100, 199, 230, 259, 400};

// MC sigma over predicted sigma at kOdometerTimes for the 9 navigation components: the
// chi-square test of the header, Bonferroni over the 45 comparisons.
void ExpectOdometerSigmaInBand(const v1::JobResult& result, int runs) {
  ASSERT_TRUE(result.has_covariance());
  EXPECT_EQ(result.covariance().filter(), "INS_GNSS_EKF");
  // Left out of the linear model at most the ranges (saturation), which the car drive's rates and
  // specific forces (below 1 rad/s and 2 g) stay far from.
  for (const std::string& term : result.covariance().unrepresented()) {
    EXPECT_NE(term.find("saturation"), std::string::npos) << term;
  }
  const int m = 9 * static_cast<int>(kOdometerTimes.size());
  const double a = 0.05 / m;
  const double lo = Chi2Quantile(runs - 1, a / 2), hi = Chi2Quantile(runs - 1, 1 - a / 2);
  std::printf("per-test interval of MC sigma / predicted: [%.3f, %.3f] (m = %d)\n",
              std::sqrt(lo / (runs - 1)), std::sqrt(hi / (runs - 1)), m);
  for (int c = 0; c < 9; ++c) {
    std::printf("  %-24s", v1::ErrorComponent_Name(static_cast<v1::ErrorComponent>(c + 1)).c_str());
    for (double t : kOdometerTimes) {
      const int e = OdometerEpochAt(result, t);
      const double s = result.epochs(e).components(c).std();
      const double p = result.covariance().epochs(e).sigma(c);
      const double statistic = (runs - 1) * s * s / (p * p);
      std::printf(" %4.0f s: %.3f", t, s / p);
      EXPECT_GE(statistic, lo) << "component " << c << " at " << t << " s: MC " << s
                               << " predicted " << p;
      EXPECT_LE(statistic, hi) << "component " << c << " at " << t << " s: MC " << s
                               << " predicted " << p;
    }
    std::printf("\n");
  }
}

// The N-run average NEES of the 9 navigation states at kOdometerTimes inside chi2(9 N) / N,
// Bonferroni over the 5 epochs.
void ExpectOdometerNeesInBand(const v1::JobResult& result, int runs) {
  ASSERT_TRUE(result.has_filter_consistency());
  const double k = 9.0 * runs;
  const double a = 0.05 / static_cast<double>(kOdometerTimes.size());
  const double lo = Chi2Quantile(k, a / 2) / runs, hi = Chi2Quantile(k, 1 - a / 2) / runs;
  for (double t : kOdometerTimes) {
    const v1::NeesEpoch& n = result.filter_consistency().epochs(OdometerEpochAt(result, t));
    ASSERT_EQ(n.runs(), static_cast<uint64_t>(runs));
    std::printf("average NEES at %.0f s: %.3f (Bonferroni 95 %% interval [%.3f, %.3f])\n", t,
                n.average_nees(), lo, hi);
    EXPECT_GE(n.average_nees(), lo) << t;
    EXPECT_LE(n.average_nees(), hi) << t;
  }
}

class OdometerJobSlow : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    result_ = new v1::JobResult(
        RunOdometerJob(ReducedOdometerJob("car_drive_gnss_odometer.json", kOdometerRuns)));
  }
  static void TearDownTestSuite() {
    delete result_;
    result_ = nullptr;
  }
  static v1::JobResult* result_;
};
v1::JobResult* OdometerJobSlow::result_ = nullptr;

TEST_F(OdometerJobSlow, MonteCarloSigmaMatchesCovarianceAnalysis) {
  ExpectOdometerSigmaInBand(*result_, kOdometerRuns);
}

TEST_F(OdometerJobSlow, AverageNeesWithinChiSquareBounds) {
  ExpectOdometerNeesInBand(*result_, kOdometerRuns);
}

// What the aid is for: through the outage the odometer and the constraints bound the velocity
// error, so the predicted horizontal error at its end (259 s) is a fraction of the GNSS-only
// filter's (car_drive_gnss.json, the same job without the odometer; its analysis alone, 1 run).
// Without the aid the error grows with the free-inertial velocity error over 60 s (metres); with
// it, with the speed's scale-factor residual and the heading error times the 60 s distance
// (0.2 % and ~0.01 rad of ~800 m: a few metres at most): at most half.
TEST_F(OdometerJobSlow, OdometerHoldsTheHorizontalErrorThroughTheOutage) {
  const v1::JobResult gnss_only = RunOdometerJob(ReducedOdometerJob("car_drive_gnss.json", 1));
  const int h = 9;  // HORIZONTAL_POSITION_M
  const double with = result_->covariance().epochs(OdometerEpochAt(*result_, 259.0)).sigma(h);
  const double without = gnss_only.covariance().epochs(OdometerEpochAt(gnss_only, 259.0)).sigma(h);
  std::printf("predicted horizontal RMS at 259 s: %.3f m with the odometer, %.3f m without\n", with,
              without);
  EXPECT_LT(with, 0.5 * without);
  // The MC agrees (ratio of squares, +-z sqrt(2 / N) with z at 1 - 0.05 / 2: +-12 %).
  const double rms = result_->epochs(OdometerEpochAt(*result_, 259.0)).components(h).rms();
  EXPECT_NEAR(rms * rms / (with * with), 1.0,
              NormalQuantile(1.0 - 0.025) * std::sqrt(2.0 / kOdometerRuns));
}

// The example's full sensor model (the tactical preset as the job names it), 200 runs.
TEST(OdometerJobSlowFullModel, MonteCarloSigmaAndNeesInTheirBands) {
  constexpr int kFullModelRuns = 200;
  const v1::JobResult result = RunOdometerJob(FullOdometerJob(kFullModelRuns));
  ExpectOdometerSigmaInBand(result, kFullModelRuns);
  ExpectOdometerNeesInBand(result, kFullModelRuns);
}

}  // namespace
}  // namespace driftlab::app
