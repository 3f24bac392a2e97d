// The error budget of the example jobs (monte_carlo.h ComputeErrorBudget): the sources add up to
// the job's covariance analysis at every epoch, and that analysis is the one `run --covariance`
// computes (5-10 s per job: the slow group).
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

MonteCarloSpec ExampleSpec(const std::string& name) {
  return ToMonteCarloSpec(LoadJobFile(std::string(DRIFTLAB_SOURCE_DIR) + "/examples/" + name), {});
}

// The relative difference |sum_s P_s - P| / P of every component at every epoch, the budget's total
// equal to `run --covariance`'s analysis (the same propagation: the same bits), and P unchanged by
// the sources propagated beside it.
void ExpectAddsUpToTheCovarianceAnalysis(const MonteCarloSpec& job) {
  const ErrorBudgetResult budget = ComputeErrorBudget(job);
  ASSERT_FALSE(budget.total.empty());
  ASSERT_EQ(budget.contribution.size(), budget.total.size());
  MonteCarloSpec with_analysis = job;
  with_analysis.covariance = true;
  with_analysis.runs = 1;
  with_analysis.run_count = 1;
  const MonteCarloOutput output = RunMonteCarloWithAnalysis(with_analysis);
  ASSERT_TRUE(output.covariance.has_value());
  ASSERT_EQ(output.covariance->epochs.size(), budget.total.size());
  double worst = 0.0;
  for (size_t e = 0; e < budget.total.size(); ++e) {
    const CovarianceEpoch& analysis = output.covariance->epochs[e];
    for (int i = 0; i < 6; ++i) {
      // The same analysis: bit-identical, not only close.
      EXPECT_EQ(budget.total[e][static_cast<size_t>(i)], analysis.P(i, i)) << "epoch " << e;
    }
    for (int c = 0; c < kNumErrorComponents; ++c) {
      double sum = 0.0;
      for (const ComponentVariances& v : budget.contribution[e]) sum += v[static_cast<size_t>(c)];
      const double total = budget.total[e][static_cast<size_t>(c)];
      if (total > 0.0) worst = std::max(worst, std::abs(sum - total) / total);
      if (total == 0.0) {
        EXPECT_EQ(sum, 0.0);
      }
    }
  }
  // The decomposition is exact for the linear model: only rounding of a few thousand steps of
  // sums of O(sources) terms (1e-16 each) separates the two; the bound is 1e-9.
  EXPECT_LE(worst, 1e-9);
  EXPECT_EQ(worst, budget.max_relative_sum_error);
}

TEST(ErrorBudgetSlow, FreeInertialCarDriveAddsUpToTheCovarianceAnalysis) {
  const MonteCarloSpec spec = ExampleSpec("car_drive.json");
  ExpectAddsUpToTheCovarianceAnalysis(spec);
}

TEST(ErrorBudgetSlow, FilterWithGnssOutageAddsUpToTheCovarianceAnalysis) {
  const MonteCarloSpec spec = ExampleSpec("car_drive_gnss.json");
  ASSERT_EQ(spec.filter, NavigationFilterKind::kInsGnssEkf);
  ExpectAddsUpToTheCovarianceAnalysis(spec);
}

TEST(ErrorBudgetSlow, SourcesAreNamedAsTheJobNamesThem) {
  const ErrorBudgetResult budget = ComputeErrorBudget(ExampleSpec("car_drive_gnss.json"));
  std::set<std::string> names;
  for (const ErrorSource& s : budget.sources) names.insert(s.name);
  for (const char* expected :
       {"gyro.arw", "gyro.bias_instability", "gyro.turn_on_bias", "gyro.scale_factor",
        "gyro.misalignment", "accel.vrw", "accel.bias_instability", "accel.turn_on_bias",
        "initial.position", "initial.velocity", "initial.attitude", "gnss.position_white"}) {
    EXPECT_EQ(names.count(expected), 1u) << expected;
  }
}

}  // namespace
}  // namespace driftlab::app
