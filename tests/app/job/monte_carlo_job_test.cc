// The job's monte_carlo section, its translation to the engine, and the result file: shards merged
// give the single-process result bit for bit, through the JSON files.
#include "driftlab/app/monte_carlo_job.h"

#include <google/protobuf/util/message_differencer.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "driftlab/app/job_file.h"
#include "driftlab/app/result_file.h"
#include "driftlab/monte_carlo.h"
#include "driftlab/spec_error.h"
#include "support/job_json.h"

namespace driftlab::app {
namespace {

// A short job: 60 s at rest then 60 s driving, 50 Hz, tactical IMU, small initial errors.
std::string JobWithMonteCarlo(const std::string& monte_carlo, const std::string& extra = "") {
  return R"({"name": "short", "rate_hz": 50,
    "motion": {"initial": {"lat_deg": 30, "lon_deg": 10, "yaw_deg": 20},
               "segments": [{"static": {"duration_s": 60}},
                            {"accelerate": {"acceleration_m_per_s2": 1, "target_speed_m_per_s": 10}},
                            {"turn": {"rate_deg_per_s": 10, "angle_deg": 90, "transition_s": 1}},
                            {"constant_velocity": {"duration_s": 30}}]},
    "navigation": {"ned": {"vertical_channel": "TRUTH_HEIGHT"}},
    "sensor": {"preset": "tactical"},
    "monte_carlo": )" +
         monte_carlo + extra + "}";
}

using testing::File;

std::string SpecErrorOf(const std::string& json, const MonteCarloOverrides& overrides = {}) {
  try {
    ToMonteCarloSpec(File(json), overrides);
  } catch (const SpecError& e) {
    return e.what();
  }
  return "";
}

TEST(MonteCarloJob, DefaultsAndOverrides) {
  const MonteCarloSpec spec = ToMonteCarloSpec(File(JobWithMonteCarlo("{}")), {});
  EXPECT_EQ(spec.runs, kDefaultRuns);
  EXPECT_EQ(spec.seed, 1u);
  EXPECT_EQ(spec.first_run, 0u);
  EXPECT_EQ(spec.run_count, kDefaultRuns);
  EXPECT_EQ(spec.epoch_every_samples, 50);  // 1 s at 50 Hz
  ASSERT_TRUE(spec.sensor.has_value());
  EXPECT_EQ(spec.sensor->name, "tactical");

  MonteCarloOverrides overrides;
  overrides.runs = 10;
  overrides.seed = 99;
  ParseShard("2/3", &overrides);
  const MonteCarloSpec shard =
      ToMonteCarloSpec(File(JobWithMonteCarlo(R"({"runs": 500})")), overrides);
  EXPECT_EQ(shard.runs, 10u);
  EXPECT_EQ(shard.seed, 99u);
  // Shard i of K holds runs [floor(i N / K), floor((i + 1) N / K)): 2/3 of 10 = [6, 10).
  EXPECT_EQ(shard.first_run, 6u);
  EXPECT_EQ(shard.run_count, 4u);
}

TEST(MonteCarloJob, BadSettingsNameTheField) {
  EXPECT_NE(
      SpecErrorOf(JobWithMonteCarlo(R"({"runs": 0})")).find("monte_carlo.runs: 0 is not allowed"),
      std::string::npos);
  MonteCarloOverrides runs;
  runs.runs = 0;
  EXPECT_NE(SpecErrorOf(JobWithMonteCarlo("{}"), runs).find("--runs: 0 is not allowed"),
            std::string::npos);
  for (const char* bad : {"4/4", "1/0", "a/b", "1", "-1/3", "1/3/4"}) {
    MonteCarloOverrides overrides;
    try {
      ParseShard(bad, &overrides);
      ADD_FAILURE() << "accepted --shard " << bad;
    } catch (const SpecError& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("--shard: ") + bad + " is not allowed"),
                std::string::npos)
          << e.what();
    }
  }
  MonteCarloOverrides many;
  many.runs = 3;
  ParseShard("0/4", &many);
  EXPECT_NE(SpecErrorOf(JobWithMonteCarlo("{}"), many)
                .find("--shard: 0/4 is not allowed; allowed: i/K with K "
                      "<= runs = 3"),
            std::string::npos);
  EXPECT_NE(SpecErrorOf(JobWithMonteCarlo(R"({"epoch_interval_s": 0.03})"))
                .find("monte_carlo.epoch_interval_s: 0.03 is not allowed; allowed: a multiple of "
                      "the IMU interval"),
            std::string::npos);
  EXPECT_NE(SpecErrorOf(JobWithMonteCarlo(R"({"epoch_interval_s": 1, "epoch_times_s": [5]})"))
                .find("monte_carlo: both epoch_interval_s and epoch_times_s"),
            std::string::npos);
  EXPECT_NE(SpecErrorOf(JobWithMonteCarlo(R"({"initial_errors": {"attitude_deg": [1, -1, 0]}})"))
                .find("monte_carlo.initial_errors.attitude_deg[1]: -1 is not allowed"),
            std::string::npos);
  EXPECT_NE(SpecErrorOf(JobWithMonteCarlo(R"({"initialization": {"kind": "STATIC_ALIGNMENT"}})"))
                .find("monte_carlo.initialization.alignment_duration_s: missing"),
            std::string::npos);
  EXPECT_NE(SpecErrorOf(JobWithMonteCarlo(R"({"initialization": {"kind": "STATIC_ALIGNMENT",
                                  "alignment_duration_s": 30},
                                "initial_errors": {"attitude_deg": [1, 1, 1]}})"))
                .find("monte_carlo.initial_errors.attitude_deg: non-zero is not allowed"),
            std::string::npos);
}

// Runs the job (or one shard of it) and converts the statistics to a result.
v1::JobResult RunToResult(const std::string& json, const MonteCarloOverrides& overrides) {
  const JobFile file = File(json);
  const MonteCarloSpec spec = ToMonteCarloSpec(file, overrides);
  return ToJobResult(JobAsRun(file.job, spec), RunMonteCarlo(spec), "test");
}

// Everything but the timings (which measure the machine, not the job).
void ExpectSameStatistics(v1::JobResult a, v1::JobResult b) {
  a.clear_timings();
  b.clear_timings();
  std::string difference;
  google::protobuf::util::MessageDifferencer differencer;
  differencer.ReportDifferencesToString(&difference);
  EXPECT_TRUE(differencer.Compare(a, b)) << difference;
}

TEST(MonteCarloJob, FourShardsMergedThroughFilesEqualOneProcessBitForBit) {
  const std::string json = JobWithMonteCarlo(R"({"runs": 22, "seed": 5, "epoch_interval_s": 2,
                                   "checkpoint_times_s": [30],
                                   "initial_errors": {"attitude_deg": [0.01, 0.01, 0.1]}})");
  MonteCarloOverrides whole;
  whole.threads = 2;
  const v1::JobResult single = RunToResult(json, whole);
  EXPECT_EQ(single.run_count(), 22u);
  ASSERT_EQ(single.checkpoints_size(), 2);
  EXPECT_EQ(single.checkpoints(1).runs_size(), 22);

  // Shards in a scrambled order, each written to and read back from its JSON file.
  std::vector<v1::JobResult> shards;
  std::vector<std::string> names;
  for (const char* shard : {"2/4", "0/4", "3/4", "1/4"}) {
    MonteCarloOverrides overrides;
    overrides.threads = 1;
    ParseShard(shard, &overrides);
    shards.push_back(ParseJobResultJson(JobResultToJson(RunToResult(json, overrides))));
    names.push_back(shard);
  }
  ExpectSameStatistics(MergeJobResults(shards, names, "test"), single);

  // Threads 1 vs 2: bit-identical too.
  MonteCarloOverrides one_thread;
  one_thread.threads = 1;
  ExpectSameStatistics(RunToResult(json, one_thread), single);

  // A shard missing, or given twice, is refused.
  EXPECT_THROW(MergeJobResults({shards[0], shards[0]}, {"a", "b"}, "test"), SpecError);
  // A shard of another job (different seed) is refused.
  const v1::JobResult other = RunToResult(
      JobWithMonteCarlo(
          R"({"runs": 22, "seed": 6, "epoch_interval_s": 2, "checkpoint_times_s": [30]})"),
      [] {
        MonteCarloOverrides o;
        ParseShard("0/4", &o);
        return o;
      }());
  EXPECT_THROW(MergeJobResults({shards[1], other}, {"a", "b"}, "test"), SpecError);
}

TEST(MonteCarloJob, ResultAnglesAreInDegreesAndSummariesAreConsistent) {
  const v1::JobResult result = RunToResult(
      JobWithMonteCarlo(R"({"runs": 12, "initial_errors": {"attitude_deg": [0.5, 0.5, 2]}})"), {});
  // At t = 0 the attitude errors are the initial errors: the sample std of 12 draws of N(0, s^2)
  // lies within [0.45 s, 1.55 s] with probability > 0.99 (chi-square, 11 dof: 0.2 % and 99.8 %
  // quantiles 2.6 and 30 -> sqrt(2.6/11) = 0.49, sqrt(30/11) = 1.65; the tolerance is looser).
  const v1::EpochStatistics& first = result.epochs(0);
  EXPECT_EQ(first.t_s(), 0.0);
  const double yaw_std = first.components(v1::YAW_DEG - 1).std();
  EXPECT_GT(yaw_std, 0.45 * 2.0);
  EXPECT_LT(yaw_std, 1.65 * 2.0);
  // The final checkpoint's p50 <= p68 <= p95 <= p99 <= max for every component, CEP50 is the
  // horizontal p50, and the per-run values are the file's runs in order.
  const v1::Checkpoint& last = result.checkpoints(result.checkpoints_size() - 1);
  ASSERT_EQ(last.runs_size(), 12);
  for (int r = 0; r < 12; ++r) EXPECT_EQ(last.runs(r).run_index(), static_cast<uint32_t>(r));
  for (const v1::ComponentPercentiles& c : last.components()) {
    EXPECT_LE(c.p50(), c.p68());
    EXPECT_LE(c.p68(), c.p95());
    EXPECT_LE(c.p95(), c.p99());
    EXPECT_LE(c.p99(), c.max_abs());
  }
  EXPECT_EQ(last.cep50_m(), last.components(v1::HORIZONTAL_POSITION_M - 1).p50());
  EXPECT_EQ(last.t_s(), result.epochs(result.epochs_size() - 1).t_s());
}

}  // namespace
}  // namespace driftlab::app
