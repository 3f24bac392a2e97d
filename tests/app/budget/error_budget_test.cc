// The error budget (monte_carlo.h ComputeErrorBudget; app error_budget_job.h): a source's
// contribution is the Monte-Carlo variance of the job with that source alone; a mistuned filter is
// refused. The example jobs' additivity: error_budget_slow_test.cc.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "driftlab/app/consistency_check.h"
#include "driftlab/app/error_budget_job.h"
#include "driftlab/app/job_file.h"
#include "driftlab/app/job_result.h"
#include "driftlab/app/monte_carlo_job.h"
#include "driftlab/monte_carlo.h"
#include "driftlab/spec_error.h"
#include "support/job_json.h"

namespace driftlab::app {
namespace {

using testing::File;

MonteCarloSpec ExampleSpec(const std::string& name) {
  return ToMonteCarloSpec(LoadJobFile(std::string(DRIFTLAB_SOURCE_DIR) + "/examples/" + name), {});
}

// A free-inertial drive of 60 s at 100 Hz with gyro and accelerometer white noise only.
const char kWhiteNoiseJob[] = R"({"name": "white", "rate_hz": 100,
  "motion": {"initial": {"lat_deg": 45, "lon_deg": 7, "height_m": 300, "yaw_deg": 30},
             "segments": [{"static": {"duration_s": 5}},
                          {"accelerate": {"acceleration_m_per_s2": 2, "target_speed_m_per_s": 10}},
                          {"turn": {"rate_deg_per_s": 10, "angle_deg": 90, "transition_s": 1}},
                          {"constant_velocity": {"duration_s": 30}}]},
  "navigation": {"mechanization": "NED", "ned": {"vertical_channel": "FREE"}},
  "sensor": {"gyro": {"arw_deg_per_sqrt_h": 0.5}, "accel": {"vrw_m_per_s_per_sqrt_h": 0.2}},
  "monte_carlo": {"runs": 400, "seed": 11, "epoch_interval_s": 1.0}})";

TEST(ErrorBudget, WhiteNoiseOnlyGivesTwoSourcesEachMatchingItsMonteCarloAlone) {
  const MonteCarloSpec spec = ToMonteCarloSpec(File(kWhiteNoiseJob), {});
  const ErrorBudgetResult budget = ComputeErrorBudget(spec);
  const v1::ErrorBudget message = ToErrorBudget(v1::Job(), budget, "test");
  ASSERT_EQ(message.sources_size(), 2);
  std::set<std::string> names{message.sources(0).name(), message.sources(1).name()};
  EXPECT_EQ(names, (std::set<std::string>{"gyro.arw", "accel.vrw"}));
  const size_t last = budget.total.size() - 1;
  constexpr uint32_t kRuns = 400;
  // 2 sources x 9 components tested: Bonferroni, family-wise false-alarm rate 1 %.
  constexpr double kAlpha = 0.01 / 18.0;
  for (const std::string name : {"gyro.arw", "accel.vrw"}) {
    const size_t s =
        static_cast<size_t>(std::find_if(budget.sources.begin(), budget.sources.end(),
                                         [&](const ErrorSource& x) { return x.name == name; }) -
                            budget.sources.begin());
    ASSERT_LT(s, budget.sources.size());
    std::vector<std::string> on;
    const MonteCarloSpec alone = BudgetCheckSpec(spec, budget, name, kRuns, &on);
    EXPECT_EQ(on, std::vector<std::string>{name});
    const v1::JobResult result = ToJobResult(v1::Job(), RunMonteCarloWithAnalysis(alone), "");
    const v1::EpochStatistics& final_epoch = *result.epochs().rbegin();
    for (int c = 0; c < 9; ++c) {
      double variance = budget.contribution[last][s][static_cast<size_t>(c)];
      if (c >= 6) variance *= (180.0 / M_PI) * (180.0 / M_PI);  // the result's angles: degrees
      if (!(variance > 0.0)) continue;
      // (N - 1) s^2 / sigma^2 ~ chi2(N - 1) for Gaussian errors: the interval of s / sigma at
      // confidence 1 - kAlpha must contain 1.
      const RatioInterval r =
          SigmaRatioInterval(final_epoch.components(c).std(), std::sqrt(variance), kRuns, kAlpha);
      EXPECT_LE(r.low, 1.0) << name << " component " << c << " ratio " << r.ratio;
      EXPECT_GE(r.high, 1.0) << name << " component " << c << " ratio " << r.ratio;
    }
  }
}

TEST(ErrorBudget, MistunedFilterIsRefusedNamingTheField) {
  MonteCarloSpec spec = ExampleSpec("car_drive_gnss.json");
  spec.filter_sensor = spec.sensor;
  try {
    ComputeErrorBudget(spec);
    FAIL() << "no SpecError";
  } catch (const SpecError& e) {
    EXPECT_NE(std::string(e.what()).find("navigation.ekf.sensor"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace driftlab::app
