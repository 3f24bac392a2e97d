// Aided navigation through the job schema: job.proto `aiding` and `navigation.filter` ->
// ToMonteCarloSpec -> RunMonteCarloWithAnalysis -> ToJobResult, the validation of every aiding
// field, the result's predicted sigma and filter consistency, and
// shards merged through result files. Short scenarios; the statistical checks of the predicted
// sigma against 500 runs are in aided_job_slow_test.cc.
#include <google/protobuf/util/message_differencer.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "driftlab/app/job_file.h"
#include "driftlab/app/monte_carlo_job.h"
#include "driftlab/app/result_file.h"
#include "driftlab/monte_carlo.h"
#include "driftlab/spec_error.h"
#include "driftlab/trajectory.h"
#include "support/job_json.h"

namespace driftlab::app {
namespace {

// A short drive: 20 s at rest, accelerate to 10 m/s, a 90 deg turn, 40 s straight, stop, 10 s at
// rest (about 92 s), 50 Hz, tactical IMU without the terms the 15-state model cannot represent.
std::string AidedJob(const std::string& navigation, const std::string& aiding,
                     const std::string& monte_carlo = R"({"runs": 12, "seed": 3,
      "initial_errors": {"position_ned_m": [1, 1, 2], "velocity_ned_m_per_s": [0.05, 0.05, 0.05],
                         "attitude_deg": [0.05, 0.05, 0.2]}})") {
  return R"({"name": "aided", "rate_hz": 50,
    "motion": {"initial": {"lat_deg": 45, "lon_deg": 7, "height_m": 300, "yaw_deg": 30},
               "segments": [{"static": {"duration_s": 20}},
                            {"accelerate": {"acceleration_m_per_s2": 2, "target_speed_m_per_s": 10}},
                            {"turn": {"rate_deg_per_s": 10, "angle_deg": 90, "transition_s": 1}},
                            {"constant_velocity": {"duration_s": 40}},
                            {"accelerate": {"acceleration_m_per_s2": 2, "target_speed_m_per_s": 0}},
                            {"static": {"duration_s": 10}}]},
    "navigation": )" +
         navigation + R"(,
    "aiding": )" +
         aiding +
         R"(,
    "sensor": {"preset": "tactical",
               "gyro": {"bias_instability_deg_per_h": 0, "scale_factor_sigma_ppm": 0,
                        "misalignment_sigma_mrad": 0, "range_deg_per_s": 0},
               "accel": {"bias_instability_ug": 0, "scale_factor_sigma_ppm": 0,
                         "misalignment_sigma_mrad": 0, "range_g": 0}},
    "monte_carlo": )" +
         monte_carlo + "}";
}

const char kEkf[] = R"({"filter": "INS_GNSS_EKF"})";
const char kGnss[] =
    R"({"gnss": {"lever_arm_b_m": [0.5, 0, -1], "outages": [{"start_s": 40, "end_s": 60}]},
        "zupt": {"enabled": true}})";

using testing::File;

// The SpecError message of translating (and, if that passes, running) the job; "" if none.
std::string ErrorOf(const std::string& json, const MonteCarloOverrides& overrides = {}) {
  try {
    MonteCarloSpec spec = ToMonteCarloSpec(File(json), overrides);
    spec.runs = 1;
    spec.run_count = 1;
    RunMonteCarloWithAnalysis(spec);
  } catch (const SpecError& e) {
    return e.what();
  }
  return "";
}

TEST(AidedJob, ExampleTranslatesToTheEkfWithGnssOutageAndZupt) {
  const JobFile file =
      LoadJobFile(std::string(DRIFTLAB_SOURCE_DIR) + "/examples/car_drive_gnss.json");
  const MonteCarloSpec spec = ToMonteCarloSpec(file, {});
  EXPECT_EQ(spec.filter, NavigationFilterKind::kInsGnssEkf);
  ASSERT_TRUE(spec.aiding.gnss.has_value());
  const GnssConfig& g = *spec.aiding.gnss;
  EXPECT_EQ(g.rate_hz, 1.0);
  EXPECT_EQ(g.position_sigma_ned_m, Eigen::Vector3d(1.5, 1.5, 3.0));
  EXPECT_EQ(g.velocity_sigma_ned_m_per_s, Eigen::Vector3d(0.05, 0.05, 0.1));
  EXPECT_EQ(g.lever_arm_b_m, Eigen::Vector3d(0.5, 0.0, -1.2));
  ASSERT_EQ(g.outages.size(), 1u);
  EXPECT_EQ(g.outages[0].start_s, 200.0);
  EXPECT_EQ(g.outages[0].duration_s, 60.0);  // [200, 260)
  ASSERT_TRUE(spec.aiding.zupt.has_value());
  EXPECT_EQ(spec.aiding.zupt->velocity_sigma_m_per_s, 0.01);
  EXPECT_FALSE(spec.aiding.barometer.has_value());
  EXPECT_FALSE(spec.covariance);
  MonteCarloOverrides overrides;
  overrides.covariance = true;
  EXPECT_TRUE(ToMonteCarloSpec(file, overrides).covariance);
}

TEST(AidedJob, DefaultsOfEachAid) {
  const MonteCarloSpec spec = ToMonteCarloSpec(
      File(AidedJob(kEkf, R"({"gnss": {}, "barometer": {}, "zupt": {"enabled": true}})")), {});
  EXPECT_EQ(spec.aiding.gnss->rate_hz, 1.0);
  EXPECT_EQ(spec.aiding.gnss->position_sigma_ned_m, Eigen::Vector3d(1.5, 1.5, 3.0));
  EXPECT_TRUE(spec.aiding.gnss->use_velocity);
  EXPECT_EQ(spec.aiding.barometer->rate_hz, 10.0);
  EXPECT_EQ(spec.aiding.barometer->noise_sigma_m, 0.5);
  EXPECT_EQ(spec.aiding.barometer->bias.sigma, 0.0);
  EXPECT_EQ(spec.aiding.zupt->rate_hz, 1.0);
  EXPECT_EQ(spec.ekf_propagation_step_samples, 10);
  // An aid whose message is absent, or ZUPT not enabled, is not used (ZUPT settings with
  // enabled false are refused: JobValidator's ZuptOptionWhileDisabled).
  const MonteCarloSpec off =
      ToMonteCarloSpec(File(AidedJob(kEkf, R"({"gnss": {}, "zupt": {"enabled": false}})")), {});
  EXPECT_FALSE(off.aiding.zupt.has_value());
  EXPECT_FALSE(off.aiding.barometer.has_value());

  const MonteCarloSpec comp = ToMonteCarloSpec(
      File(
          AidedJob(R"({"filter": "COMPLEMENTARY", "complementary": {"pair": "BUTTERWORTH4",
                   "crossover_hz": 0.05}})",
                   R"({"magnetometer": {"hard_iron_ut": [1, 2, 3], "soft_iron": [1.01, 0.99, 1]}})",
                   R"({"runs": 2})")),
      {});
  EXPECT_EQ(comp.filter, NavigationFilterKind::kComplementary);
  EXPECT_EQ(comp.complementary.kind, ComplementaryPairKind::kButterworth4);
  EXPECT_EQ(comp.complementary.crossover_hz, 0.05);
  EXPECT_EQ(comp.complementary.heading_crossover_hz, 0.01);
  EXPECT_EQ(comp.aiding.magnetometer->rate_hz, 50.0);  // default: the IMU rate
  EXPECT_EQ(comp.aiding.magnetometer->hard_iron_b, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(comp.aiding.magnetometer->soft_iron(0, 0), 1.01);
  EXPECT_EQ(comp.aiding.magnetometer->soft_iron(1, 1), 0.99);
  EXPECT_EQ(comp.aiding.magnetometer->soft_iron(0, 1), 0.0);
}

struct BadCase {
  std::string navigation, aiding, monte_carlo;
  bool covariance_flag = false;
  std::string field;     // the message starts with "<field>: "
  std::string contains;  // and contains this (value or allowed range)
};

TEST(AidedJob, BadAidingConfigurationNamesTheField) {
  const std::string mc = R"({"runs": 2})";
  const std::vector<BadCase> cases = {
      // Negative sigma.
      {kEkf, R"({"gnss": {"position_sigma_ned_m": [1.5, -1, 3]}})", mc, false,
       "aiding.gnss.position_sigma_ned_m[1]", "-1"},
      {kEkf, R"({"gnss": {"velocity_sigma_ned_m_per_s": [0.1, 0.1, -0.2]}})", mc, false,
       "aiding.gnss.velocity_sigma_ned_m_per_s[2]", "-0.2"},
      {kEkf, R"({"barometer": {"noise_sigma_m": -0.5}})", mc, false,
       "aiding.barometer.noise_sigma_m", "-0.5"},
      {kEkf, R"({"zupt": {"enabled": true, "velocity_sigma_m_per_s": 0}})", mc, false,
       "aiding.zupt.velocity_sigma_m_per_s", "0"},
      {R"({"filter": "COMPLEMENTARY"})", R"({"magnetometer": {"noise_sigma_ut": -1}})", mc, false,
       "aiding.magnetometer.noise_sigma_ut", "-1"},
      // Overlapping and unordered outages.
      {kEkf,
       R"({"gnss": {"outages": [{"start_s": 30, "end_s": 50}, {"start_s": 45, "end_s": 60}]}})", mc,
       false, "aiding.gnss.outages[1].start_s", ">= 50 s"},
      {kEkf, R"({"gnss": {"outages": [{"start_s": 30, "end_s": 30}]}})", mc, false,
       "aiding.gnss.outages[0].end_s", "30"},
      // Outage outside the trajectory (about 92 s long).
      {kEkf, R"({"gnss": {"outages": [{"start_s": 80, "end_s": 500}]}})", mc, false,
       "aiding.gnss.outages[0].end_s", "500"},
      {kEkf, R"({"gnss": {"outages": [{"start_s": 400, "end_s": 500}]}})", mc, false,
       "aiding.gnss.outages[0].start_s", "400"},
      {kEkf, R"({"gnss": {"outages": [{"end_s": 50}]}})", mc, false,
       "aiding.gnss.outages[0].start_s", "missing"},
      // Aiding rate above the IMU rate (50 Hz), or not dividing it.
      {kEkf, R"({"gnss": {"rate_hz": 100}})", mc, false, "aiding.gnss.rate_hz", "100"},
      {kEkf, R"({"gnss": {"rate_hz": 3}})", mc, false, "aiding.gnss.rate_hz", "divide"},
      {kEkf, R"({"barometer": {"rate_hz": 60}})", mc, false, "aiding.barometer.rate_hz", "60"},
      {R"({"filter": "COMPLEMENTARY"})", R"({"magnetometer": {"rate_hz": 51}})", mc, false,
       "aiding.magnetometer.rate_hz", "51"},
      // Other fields.
      {kEkf, R"({"barometer": {"bias_gauss_markov_sigma_m": 2}})", mc, false,
       "aiding.barometer.bias_gauss_markov_tau_s", "missing"},
      {kEkf, R"({"gnss": {"lever_arm_b_m": [0, 1]}})", mc, false, "aiding.gnss.lever_arm_b_m",
       "2 values"},
      {R"({"filter": "COMPLEMENTARY"})", R"({"magnetometer": {"soft_iron": [1, 0, 0, 1]}})", mc,
       false, "aiding.magnetometer.soft_iron", "4 values"},
      {R"({"filter": "COMPLEMENTARY"})", R"({"magnetometer": {"soft_iron": [1, 0, 0]}})", mc, false,
       "aiding.magnetometer.soft_iron", "invertible"},
      {R"({"filter": "COMPLEMENTARY", "complementary": {"crossover_hz": 30}})", "{}", mc, false,
       "navigation.complementary.crossover_hz", "30"},
      {R"({"filter": "INS_GNSS_EKF", "ekf": {"propagation_step_samples": 0}})", R"({"gnss": {}})",
       mc, false, "navigation.ekf.propagation_step_samples", "0"},
      // Filter and aids that do not fit together.
      {kEkf, "{}", mc, false, "navigation.filter", "at least one of aiding.gnss"},
      {R"({"filter": "NONE"})", R"({"gnss": {}})", mc, false, "aiding.gnss", "INS_GNSS_EKF"},
      {kEkf, R"({"magnetometer": {}, "gnss": {}})", mc, false, "aiding.magnetometer",
       "COMPLEMENTARY"},
      {R"({"filter": "COMPLEMENTARY"})", R"({"barometer": {}})", mc, false, "aiding.barometer",
       "INS_GNSS_EKF"},
      {R"({"filter": "INS_GNSS_EKF", "ned": {"vertical_channel": "TRUTH_HEIGHT"}})",
       R"({"gnss": {}})", mc, false, "navigation.ned.vertical_channel", "FREE"},
      {kEkf, R"({"gnss": {}})",
       R"({"runs": 2, "initialization": {"kind": "STATIC_ALIGNMENT", "alignment_duration_s": 10}})",
       false, "monte_carlo.initialization.kind", "TRUTH_PLUS_ERRORS"},
      {R"({"filter": "COMPLEMENTARY"})", "{}",
       R"({"runs": 2, "initial_errors": {"position_ned_m": [1, 1, 1]}})", false,
       "monte_carlo.initial_errors", "COMPLEMENTARY"},
      // Covariance analysis of a filter it does not describe.
      {R"({"filter": "COMPLEMENTARY"})", "{}", mc, true, "--covariance", "NONE or INS_GNSS_EKF"},
      {R"({"ned": {"vertical_channel": "TRUTH_HEIGHT"}})", "{}",
       R"({"runs": 2, "covariance": true})", false, "monte_carlo.covariance", "FREE"},
      {"{}", "{}", R"({"runs": 2, "covariance": true, "covariance_step_samples": 0})", false,
       "monte_carlo.covariance_step_samples", "0"},
  };
  for (const BadCase& c : cases) {
    MonteCarloOverrides overrides;
    overrides.covariance = c.covariance_flag;
    const std::string message = ErrorOf(AidedJob(c.navigation, c.aiding, c.monte_carlo), overrides);
    EXPECT_EQ(message.rfind(c.field + ": ", 0), 0u) << c.aiding << " -> " << message;
    EXPECT_NE(message.find(c.contains), std::string::npos) << c.aiding << " -> " << message;
  }
  // An unknown filter is rejected by the schema check, naming the field and the allowed names.
  try {
    ParseJobJson(AidedJob(R"({"filter": "KALMAN"})", "{}"));
    ADD_FAILURE() << "unknown filter accepted";
  } catch (const SpecError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind("navigation.filter: \"KALMAN\"", 0), 0u) << message;
    EXPECT_NE(message.find("INS_GNSS_EKF"), std::string::npos) << message;
  }
}

// The result holds one predicted-sigma record and one NEES record per epoch, in the statistics'
// component order and units; a job split into shards and merged through result files equals the
// single-process result bit for bit, NEES sums included.
TEST(AidedJob, ResultCarriesPredictedSigmaAndNeesAndShardsMergeBitForBit) {
  const std::string json = AidedJob(kEkf, kGnss,
                                    R"({"runs": 12, "seed": 3, "covariance": true,
      "initial_errors": {"position_ned_m": [1, 1, 2], "velocity_ned_m_per_s": [0.05, 0.05, 0.05],
                         "attitude_deg": [0.05, 0.05, 0.2]}})");
  const JobFile file = File(json);
  MonteCarloOverrides overrides;
  overrides.threads = 2;
  const MonteCarloSpec spec = ToMonteCarloSpec(file, overrides);
  const MonteCarloOutput output = RunMonteCarloWithAnalysis(spec);
  const v1::JobResult single = ToJobResult(JobAsRun(file.job, spec), output, "test");

  ASSERT_TRUE(single.has_covariance());
  EXPECT_EQ(single.covariance().filter(), "INS_GNSS_EKF");
  EXPECT_EQ(single.covariance().step_samples(), 10u);
  EXPECT_TRUE(single.covariance().unrepresented().empty());
  ASSERT_EQ(single.covariance().epochs_size(), single.epochs_size());
  ASSERT_TRUE(single.has_filter_consistency());
  ASSERT_EQ(single.filter_consistency().epochs_size(), single.epochs_size());
  EXPECT_EQ(single.filter_consistency().state_dimension(), 9u);
  for (int e = 0; e < single.epochs_size(); ++e) {
    const v1::PredictedEpoch& p = single.covariance().epochs(e);
    EXPECT_EQ(p.t_s(), single.epochs(e).t_s());
    ASSERT_EQ(p.sigma_size(), 11);
    // Horizontal RMS = sqrt(sigma_N^2 + sigma_E^2) by definition (rounding only).
    EXPECT_NEAR(p.sigma(9), std::hypot(p.sigma(0), p.sigma(1)), 1e-12 * p.sigma(9));
    const v1::NeesEpoch& n = single.filter_consistency().epochs(e);
    EXPECT_EQ(n.t_s(), single.epochs(e).t_s());
    if (e == 0) continue;  // the start: P0 has no process noise yet, every run counts anyway
    EXPECT_EQ(n.runs(), 12u);
    EXPECT_LT(n.chi2_95_low(), 9.0);
    EXPECT_GT(n.chi2_95_high(), 9.0);
  }
  // Degrees at the edge: the predicted initial roll sigma is the job's 0.05 deg (first epoch, t =
  // 0: P0 itself; the Euler-angle sigma equals the input sigma up to the psi <-> Euler round trip).
  EXPECT_NEAR(single.covariance().epochs(0).sigma(6), 0.05, 1e-9);
  EXPECT_NEAR(single.covariance().epochs(0).sigma(0), 1.0, 1e-12);

  // Bit-identical for another thread count.
  MonteCarloOverrides one_thread;
  one_thread.threads = 1;
  const v1::JobResult threads1 =
      ToJobResult(JobAsRun(file.job, spec),
                  RunMonteCarloWithAnalysis(ToMonteCarloSpec(file, one_thread)), "test");
  EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(threads1.filter_consistency(),
                                                                 single.filter_consistency()));
  EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(threads1.merge_state(),
                                                                 single.merge_state()));

  // Three shards through JSON files, merged in another order.
  std::vector<v1::JobResult> shards;
  std::vector<std::string> names;
  for (uint32_t i : {2u, 0u, 1u}) {
    MonteCarloOverrides shard;
    ParseShard(std::to_string(i) + "/3", &shard);
    const MonteCarloSpec shard_spec = ToMonteCarloSpec(file, shard);
    const v1::JobResult part =
        ToJobResult(JobAsRun(file.job, shard_spec), RunMonteCarloWithAnalysis(shard_spec), "test");
    shards.push_back(ParseJobResultJson(JobResultToJson(part)));
    names.push_back("shard" + std::to_string(i));
  }
  const v1::JobResult merged = MergeJobResults(shards, names, "test");
  EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(merged.filter_consistency(),
                                                                 single.filter_consistency()));
  EXPECT_TRUE(
      google::protobuf::util::MessageDifferencer::Equals(merged.covariance(), single.covariance()));
  EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(merged.merge_state(),
                                                                 single.merge_state()));
}

// The complementary filter through the job path: attitude errors only (position and velocity are
// not estimated and reported as 0), no covariance, no NEES.
TEST(AidedJob, ComplementaryFilterReportsAttitudeErrorsOnly) {
  const JobFile file = File(AidedJob(R"({"filter": "COMPLEMENTARY"})", R"({"magnetometer": {}})",
                                     R"({"runs": 4, "seed": 5})"));
  const MonteCarloSpec spec = ToMonteCarloSpec(file, {});
  const v1::JobResult result =
      ToJobResult(JobAsRun(file.job, spec), RunMonteCarloWithAnalysis(spec), "test");
  EXPECT_FALSE(result.has_covariance());
  EXPECT_FALSE(result.has_filter_consistency());
  const v1::EpochStatistics& last = result.epochs(result.epochs_size() - 1);
  for (int c = 0; c < 6; ++c) EXPECT_EQ(last.components(c).rms(), 0.0) << c;
  // Roll at the end, after 10 s at rest: the 0.5 mg accelerometer turn-on bias gives 0.03 deg,
  // the turn's 1.75 m/s^2 centripetal leak (10 deg) decays as exp(-t / 1.6 s) through the 0.1 Hz
  // low-pass over the ~60 s since: below 0.2 deg; non-zero as the sensors have errors. (Heading
  // settles over 1 / (2 pi 0.01 Hz) = 16 s and still carries the pitch leak of the final braking
  // through the levelling of the magnetometer: not checked here; see aiding_test.cc.)
  EXPECT_GT(last.components(6).rms(), 0.0);
  EXPECT_LT(last.components(6).rms(), 0.2);
}

// gnss-ins-sim's GPS-visibility column: the 3d demo file alternates visible (1) and
// invisible (0) commands; with GNSS aiding the invisible commands' times become outages, merged
// with the job's own (here one overlapping the first invisible window).
TEST(AidedJob, GnssInsSimGpsVisibilityZeroBecomesOutages) {
  const std::string file =
      std::string(DRIFTLAB_SOURCE_DIR) + "/tests/data/gnss_ins_sim/motion_def-3d.csv";
  const std::string job = R"({"name": "gis", "rate_hz": 100,
    "motion": {"earth_model": "FLAT", "gnss_ins_sim_file": {"path": ")" +
                          file + R"("}},
    "navigation": {"filter": "INS_GNSS_EKF"},
    "aiding": {"gnss": {"outages": [{"start_s": 5, "end_s": 12}]}},
    "sensor": {"preset": "tactical"},
    "monte_carlo": {"runs": 2}})";
  const MonteCarloSpec spec = ToMonteCarloSpec(JobFile{ParseJobJson(job), "."}, {});
  const TrajectoryGenerator planned(spec.simulation.motion, 100.0);
  const auto& invisible = planned.gps_invisible_s();
  // Commands 1 (10 s, type 1) and 3, 5, 7 (types 2, converging early) have GPS 0.
  ASSERT_EQ(invisible.size(), 4u);
  EXPECT_EQ(invisible[0].first, 0.0);
  EXPECT_NEAR(invisible[0].second, 10.0, 1e-12);  // k dt rounding
  const std::vector<GnssOutage>& outages = spec.aiding.gnss->outages;
  ASSERT_EQ(outages.size(), 4u);
  EXPECT_EQ(outages[0].start_s, 0.0);  // [0, 10) and the job's [5, 12) merged
  EXPECT_NEAR(outages[0].start_s + outages[0].duration_s, 12.0, 1e-12);
  for (size_t i = 1; i < 4; ++i) {
    EXPECT_EQ(outages[i].start_s, invisible[i].first);
    EXPECT_EQ(outages[i].start_s + outages[i].duration_s, invisible[i].second);
  }
}

}  // namespace
}  // namespace driftlab::app
