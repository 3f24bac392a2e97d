// One validation path: app::ToMonteCarloSpec — what `driftlab validate`, `driftlab run` and the
// server's Submit call — makes every check RunMonteCarlo makes against the trajectory, refuses a
// job whose memory exceeds its limit before anything is allocated, and bounds the sizes of a job's
// fields.
#include <gtest/gtest.h>

#include <string>

#include "driftlab/app/job_file.h"
#include "driftlab/app/monte_carlo_job.h"
#include "driftlab/app/schema_check.h"
#include "driftlab/monte_carlo.h"
#include "driftlab/nav_state.h"
#include "driftlab/spec_error.h"
#include "support/job_json.h"

namespace driftlab::app {
namespace {

// 120 s at rest, 100 Hz; `monte_carlo` and `extra` fields spliced in.
std::string JobWithMonteCarloAt(const std::string& monte_carlo, double rate_hz = 100.0,
                                double duration_s = 120.0, const std::string& name = "short") {
  return R"({"name": ")" + name + R"(", "rate_hz": )" + std::to_string(rate_hz) +
         R"(, "motion": {"initial": {"lat_deg": 45, "lon_deg": 7},
               "segments": [{"static": {"duration_s": )" +
         std::to_string(duration_s) + R"(}}]},
    "navigation": {"ned": {"vertical_channel": "TRUTH_HEIGHT"}},
    "sensor": {"preset": "tactical"},
    "monte_carlo": )" +
         monte_carlo + "}";
}

using testing::File;

// The field a SpecError names, "" when the job is accepted.
std::string RefusedField(const std::string& json, const MonteCarloOverrides& overrides = {}) {
  try {
    ToMonteCarloSpec(File(json), overrides);
  } catch (const SpecError& e) {
    return e.field();
  }
  return "";
}

TEST(ValidationPath, CheckpointsAgainstTheTrajectoryAreCheckedWithoutRunning) {
  EXPECT_EQ(RefusedField(JobWithMonteCarloAt(R"({"runs": 2, "checkpoint_times_s": [10, 60]})")),
            "");
  // Past the trajectory's end (120 s): validate refuses it as RunMonteCarlo does.
  EXPECT_EQ(RefusedField(JobWithMonteCarloAt(R"({"runs": 2, "checkpoint_times_s": [10, 500]})")),
            "monte_carlo.checkpoint_times_s[1]");
  // Not ascending.
  EXPECT_EQ(RefusedField(JobWithMonteCarloAt(R"({"runs": 2, "checkpoint_times_s": [60, 10]})")),
            "monte_carlo.checkpoint_times_s[1]");
  // Two times on one sample of the 100 Hz grid (dt = 10 ms).
  EXPECT_EQ(RefusedField(JobWithMonteCarloAt(R"({"runs": 2, "checkpoint_times_s": [10, 10.001]})")),
            "monte_carlo.checkpoint_times_s[1]");
}

TEST(ValidationPath, EpochLimitIsCheckedWithoutRunning) {
  // One epoch per sample of 10 000 s at 100 Hz: 1 000 001 epochs, over the engine's limit.
  ASSERT_LT(kMaxMonteCarloEpochs, size_t{1'000'001});
  EXPECT_EQ(
      RefusedField(JobWithMonteCarloAt(R"({"runs": 1, "epoch_interval_s": 0.01})", 100.0, 10000.0)),
      "monte_carlo.epoch_interval_s");
  EXPECT_EQ(
      RefusedField(JobWithMonteCarloAt(R"({"runs": 1, "epoch_interval_s": 1})", 100.0, 10000.0)),
      "");
}

// The refusal names the shortest interval as a user writes it: 10 000 s at 100 Hz in at most
// 20 000 epochs needs 1 000 000 / 19 999 + 1 = 51 samples between epochs, 0.51 s (51 x 0.01 s,
// which 17 significant digits print as 0.51000000000000001).
TEST(ValidationPath, EpochLimitMessageSaysTheShortestIntervalAsWritten) {
  ASSERT_EQ(kMaxMonteCarloEpochs, size_t{20000});
  std::string message;
  try {
    ToMonteCarloSpec(
        File(JobWithMonteCarloAt(R"({"runs": 1, "epoch_interval_s": 0.01})", 100.0, 10000.0)), {});
  } catch (const SpecError& e) {
    message = e.what();
  }
  EXPECT_NE(message.find("monte_carlo.epoch_interval_s: 0.01 s is not allowed; allowed: at least "
                         "0.51 s, a multiple of 1 / rate_hz"),
            std::string::npos)
      << message;
}

TEST(ValidationPath, JobOverItsMemoryLimitIsRefusedBeforeAnyAllocation) {
  // 1 run x 100 000 s at 2000 Hz = 2e8 IMU increments of shared truth, each two
  // 3-vectors of doubles (48 bytes): at least 9.6 GB, over the 8 GB default.
  const std::string job =
      JobWithMonteCarloAt(R"({"runs": 1, "epoch_interval_s": 10})", 2000.0, 100000.0);
  const uint64_t lower_bound = uint64_t{200'000'000} * sizeof(ImuIncrement);
  MonteCarloOverrides unlimited;
  unlimited.max_memory_bytes = 0;
  const MonteCarloSpec spec = ToMonteCarloSpec(File(job), unlimited);
  EXPECT_GE(EstimateMonteCarloMemoryBytes(spec), lower_bound);
  // The estimate is from above but not absurdly so: the truth dominates, the rest of this job
  // (one run, 10 001 epochs of statistics) is under 2x the truth.
  EXPECT_LT(EstimateMonteCarloMemoryBytes(spec), 2 * lower_bound);

  try {
    ToMonteCarloSpec(File(job), {});
    FAIL() << "a 9.6 GB job was accepted under the 8 GB default";
  } catch (const LimitError& e) {
    EXPECT_EQ(e.field(), "monte_carlo");
    const std::string message = e.what();
    EXPECT_NE(message.find("--max-memory-gb"), std::string::npos) << message;
    EXPECT_NE(message.find("8 GB"), std::string::npos) << message;
  }
  // The limit is the caller's: 20 GB admits it.
  MonteCarloOverrides raised;
  raised.max_memory_bytes = 20'000'000'000ull;
  EXPECT_EQ(RefusedField(job, raised), "");
}

TEST(ValidationPath, FieldSizesAreBounded) {
  EXPECT_EQ(RefusedField(JobWithMonteCarloAt(R"({"runs": 2})", 100.0, 120.0,
                                             std::string(kMaxJobNameBytes, 'n'))),
            "");
  EXPECT_EQ(RefusedField(JobWithMonteCarloAt(R"({"runs": 2})", 100.0, 120.0,
                                             std::string(kMaxJobNameBytes + 1, 'n'))),
            "name");
  // A repeated field over its entry limit is refused by its size, before its values are checked.
  std::string times = "[";
  for (int i = 0; i <= kMaxJobRepeatedFieldSize; ++i) times += (i ? ",1" : "1");
  times += "]";
  EXPECT_EQ(
      RefusedField(JobWithMonteCarloAt(R"({"runs": 2, "checkpoint_times_s": )" + times + "}")),
      "monte_carlo.checkpoint_times_s");
}

}  // namespace
}  // namespace driftlab::app
