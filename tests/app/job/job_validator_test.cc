// app::ValidateJob, the one validator of every entry: each class of job that validated and then
// failed (or ran wrongly) is refused with the field named; every field path it reports exists in
// the job schema (checked by descriptors over a corpus of bad jobs made by mutating every field of
// valid jobs); the final check refuses a result with a non-finite statistic.
#include "driftlab/app/job_validator.h"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/message.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "driftlab/app/job_file.h"
#include "driftlab/app/monte_carlo_job.h"
#include "driftlab/app/schema_check.h"
#include "driftlab/spec_error.h"
#include "support/bad_jobs.h"

namespace driftlab::app {
namespace {

namespace fs = std::filesystem;
using google::protobuf::FieldDescriptor;
using google::protobuf::Message;
using google::protobuf::Reflection;

// The SpecError ValidateJob throws for `json` ("" field when it accepts the job).
struct Refusal {
  std::string field;
  std::string message;
};
Refusal RefusalOf(const v1::Job& job, const fs::path& base_dir = ".",
                  const JobValidationOptions& options = {}) {
  try {
    ValidateJob(job, base_dir, options);
  } catch (const SpecError& e) {
    return {e.field(), e.what()};
  }
  return {};
}

TEST(JobValidator, EveryClassThatValidatedThenFailedIsRefusedWithItsField) {
  for (const testing::BadJob& bad : testing::ValidatedThenFailedJobs()) {
    SCOPED_TRACE(bad.name);
    const Refusal r = RefusalOf(ParseJobJson(bad.json));
    EXPECT_EQ(r.field, bad.field) << r.message;
    EXPECT_NE(r.message.find(bad.value), std::string::npos) << r.message;
    // The server's options (no file references) give the same refusal.
    JobValidationOptions server;
    server.allow_file_references = false;
    EXPECT_EQ(RefusalOf(ParseJobJson(bad.json), "", server).message, r.message);
  }
}

TEST(JobValidator, ErrorsNameTheJobsFieldsNotTheEnginesOwnNames) {
  for (const testing::BadJob& bad : testing::WrongFieldNameJobs()) {
    SCOPED_TRACE(bad.name);
    const Refusal r = RefusalOf(ParseJobJson(bad.json));
    EXPECT_EQ(r.field, bad.field) << r.message;
    EXPECT_NE(r.message.find(bad.value), std::string::npos) << r.message;
  }
}

TEST(JobValidator, TimeConstantsAtTheirLimitsAreAccepted) {
  // 20 Hz, the EKF propagating every 10 samples: tau >= 0.5 s; without a filter tau >= 0.05 s.
  const auto job = [](const std::string& navigation, double tau_s) {
    return ParseJobJson(testing::SmallDriveJob(
        navigation, navigation == "{}" ? "{}" : testing::kGnss,
        R"({"gyro": {"gauss_markov_sigma_deg_per_h": 10, "gauss_markov_tau_s": )" +
            std::to_string(tau_s) + "}}"));
  };
  EXPECT_EQ(RefusalOf(job(testing::kEkf, 0.5)).message, "");
  EXPECT_EQ(RefusalOf(job(testing::kEkf, 0.49)).field, "sensor.gyro.gauss_markov_tau_s");
  EXPECT_EQ(RefusalOf(job("{}", 0.05)).message, "");
  EXPECT_EQ(RefusalOf(job("{}", 0.049)).field, "sensor.gyro.gauss_markov_tau_s");
  // Propagating every sample lowers the EKF's bound to the IMU interval.
  EXPECT_EQ(
      RefusalOf(job(R"({"filter": "INS_GNSS_EKF", "ekf": {"propagation_step_samples": 1}})", 0.05))
          .message,
      "");
}

TEST(JobValidator, LargestDocumentedSigmasAreAccepted) {
  // 1e5 ppm and 100 mrad are the documented maxima: once refused by the engine under its own
  // names (scale_factor_sigma, misalignment_sigma_rad).
  EXPECT_EQ(
      RefusalOf(ParseJobJson(testing::SmallDriveJob("{}", "{}",
                                                    R"({"gyro": {"scale_factor_sigma_ppm": 1e5,
                              "misalignment_sigma_mrad": 100}})")))
          .message,
      "");
}

TEST(JobValidator, ImportedMotionErrorsNameTheFileField) {
  const fs::path dir =
      fs::temp_directory_path() / ("job_validator_test_" + std::to_string(getpid()));
  fs::create_directories(dir);
  // Two samples: the profile lasts 0.01 s, below one output interval at 20 Hz.
  std::ofstream(dir / "short.csv") << "0,45,7,200,0,0,0,0,0,0\n0.01,45,7,200,0,0,0,0,0,0\n";
  const Refusal r = RefusalOf(
      ParseJobJson(R"({"rate_hz": 20, "motion": {"truth_profile_file": {"path": "short.csv"}}})"),
      dir);
  EXPECT_EQ(r.field, "motion.truth_profile_file.path") << r.message;
  EXPECT_NE(r.message.find("short.csv"), std::string::npos) << r.message;
  // The server reads no files: refused before anything is read.
  JobValidationOptions server;
  server.allow_file_references = false;
  EXPECT_EQ(RefusalOf(ParseJobJson(R"({"rate_hz": 20, "motion": {"truth_profile_file":
                                        {"path": "short.csv"}}})"),
                      dir, server)
                .field,
            "motion.truth_profile_file.path");
  fs::remove_all(dir);
}

// ---- Every field path the validator reports is one of the schema -------------------------------

// Bad values for a double field: outside every range, at the boundaries, not finite.
const double kBadDoubles[] = {
    -1e300, -1.0, 0.0, 1e-12, 0.5, 1e300, std::numeric_limits<double>::quiet_NaN()};

// Calls `visit` after changing one field of `message` (or of a message reached through its set
// fields) at a time, restoring it after: every double to each bad value (also fields not set),
// every repeated double field to 2 and 4 elements and each element to each bad value, every enum
// to each of its values, every integer to 0 and 10^9, the preset to an unknown name.
void Mutations(Message* message, const std::function<void()>& visit) {
  const Reflection& r = *message->GetReflection();
  const google::protobuf::Descriptor& d = *message->GetDescriptor();
  for (int i = 0; i < d.field_count(); ++i) {
    const FieldDescriptor* f = d.field(i);
    const std::unique_ptr<Message> saved(message->New());
    saved->CopyFrom(*message);
    const auto restore = [&] { message->CopyFrom(*saved); };
    if (f->is_repeated()) {
      if (f->cpp_type() == FieldDescriptor::CPPTYPE_DOUBLE) {
        for (int n : {2, 4}) {
          r.ClearField(message, f);
          for (int k = 0; k < n; ++k) r.AddDouble(message, f, 1.0);
          visit();
          restore();
        }
        for (int k = 0; k < r.FieldSize(*message, f); ++k) {
          for (double v : kBadDoubles) {
            r.SetRepeatedDouble(message, f, k, v);
            visit();
            restore();
          }
        }
      } else if (f->cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE) {
        for (int k = 0; k < r.FieldSize(*message, f); ++k) {
          Mutations(r.MutableRepeatedMessage(message, f, k), visit);
          restore();
        }
      }
      continue;
    }
    switch (f->cpp_type()) {
      case FieldDescriptor::CPPTYPE_DOUBLE:
        for (double v : kBadDoubles) {
          r.SetDouble(message, f, v);
          visit();
          restore();
        }
        break;
      case FieldDescriptor::CPPTYPE_ENUM:
        for (int v = 0; v < f->enum_type()->value_count(); ++v) {
          r.SetEnumValue(message, f, f->enum_type()->value(v)->number());
          visit();
          restore();
        }
        break;
      case FieldDescriptor::CPPTYPE_UINT32:
        for (uint32_t v : {0u, 1000000000u}) {
          r.SetUInt32(message, f, v);
          visit();
          restore();
        }
        break;
      case FieldDescriptor::CPPTYPE_INT32:
        for (int32_t v : {0, -1, 1000000000}) {
          r.SetInt32(message, f, v);
          visit();
          restore();
        }
        break;
      case FieldDescriptor::CPPTYPE_BOOL:
        r.SetBool(message, f, !r.GetBool(*message, f));
        visit();
        restore();
        break;
      case FieldDescriptor::CPPTYPE_STRING:
        if (f->name() == "preset") {
          r.SetString(message, f, "no_such_preset");
          visit();
          restore();
        }
        break;
      case FieldDescriptor::CPPTYPE_MESSAGE:
        if (r.HasField(*message, f)) {
          Mutations(r.MutableMessage(message, f), visit);
          restore();
        }
        break;
      default:
        break;
    }
  }
}

TEST(JobValidator, EveryFieldPathItReportsExistsInTheSchema) {
  // Valid jobs covering every part of the schema: segments of every kind (the zigzag in
  // seed002_zigzag.json: it is refused with coordinated turns, which inline job 9 has), each filter
  // and aid, the alignment, mechanization SEED000, a filter model, the covariance analysis, initial
  // errors of every kind, imported motions.
  std::vector<std::pair<std::string, fs::path>> bases;
  for (const char* name :
       {"car_drive_gnss.json", "aircraft_climb_turns.yaml", "seed002_zigzag.json",
        "ship_seaway.json", "static_alignment_navigation.yaml", "gnss_ins_sim_import.json",
        "truth_profile_import.json"}) {
    bases.emplace_back(name, kExamples / name);
  }
  std::vector<v1::Job> jobs;
  for (const auto& [name, path] : bases) jobs.push_back(LoadJobFile(path).job);
  jobs.push_back(ParseJobJson(testing::SmallDriveJob(
      R"({"filter": "INS_GNSS_EKF", "ekf": {"propagation_step_samples": 5,
          "flicker_states_per_axis": 2, "sensor": {"preset": "tactical"}}})",
      R"({"gnss": {"rate_hz": 1, "position_gauss_markov_sigma_ned_m": [1, 1, 2],
                   "position_gauss_markov_tau_s": 50, "outages": [{"start_s": 12, "end_s": 15}]},
          "barometer": {"bias_gauss_markov_sigma_m": 1, "bias_gauss_markov_tau_s": 100},
          "zupt": {"enabled": true}})",
      R"({"gyro": {"fixed_bias_deg_per_h": [1, 2, 3], "turn_on_bias_deg_per_h": 1,
                   "bias_instability_deg_per_h": 0.5, "bias_instability_tau_min_s": 1,
                   "bias_instability_tau_max_s": 100, "gauss_markov_sigma_deg_per_h": 1,
                   "gauss_markov_tau_s": 10, "arw_deg_per_sqrt_h": 0.1,
                   "scale_factor_fixed_ppm": [1, 2, 3], "misalignment_fixed_mrad": [1, 0, 0, 0, 0, 1],
                   "g_sensitivity_deg_per_h_per_g": [1, 1, 1], "quantization_urad": 1,
                   "range_deg_per_s": 500},
          "accel": {"fixed_bias_mg": [1, 0, 0], "vrw_m_per_s_per_sqrt_h": 0.01,
                    "gauss_markov_sigma_ug": 10, "gauss_markov_tau_s": 10, "range_g": 16}})",
      R"({"runs": 4, "covariance": true, "covariance_step_samples": 5,
          "initial_errors": {"position_ned_m": [1, 1, 1], "velocity_ned_m_per_s": [0.1, 0.1, 0.1],
            "attitude_ned_deg": [0.1, 0.1, 0.1], "fixed_position_ned_m": [1, 0, 0],
            "fixed_velocity_ned_m_per_s": [0, 0.1, 0], "fixed_attitude_ned_deg": [0, 0, 0.2]},
          "epoch_times_s": [0, 10, 20, 30], "checkpoint_times_s": [15]})")));
  jobs.push_back(ParseJobJson(testing::SmallDriveJob(
      R"({"filter": "COMPLEMENTARY", "complementary": {"pair": "BUTTERWORTH4",
          "crossover_hz": 0.2, "heading_crossover_hz": 0.02}})",
      R"({"magnetometer": {"rate_hz": 10, "earth_field_ned_ut": [20, 1, 45],
          "hard_iron_ut": [1, 2, 3], "soft_iron": [1, 1, 1], "noise_sigma_ut": 0.1}})",
      R"({"preset": "tactical"})",
      R"({"runs": 4, "initial_errors": {"attitude_deg": [0, 0, 1]}})")));
  jobs.push_back(ParseJobJson(R"({"rate_hz": 20, "motion": {"earth_model": "FLAT",
      "flat_gravity_m_per_s2": 9.8, "initial": {"lat_deg": 10, "lon_deg": 20, "height_m": 5,
        "velocity_ned_m_per_s": [0, 5, 0], "roll_deg": 1, "pitch_deg": 2, "yaw_deg": 90},
      "vehicle": {"coordinated_turns": true, "pitch_follows_flight_path": true},
      "segments": [{"turn": {"rate_deg_per_s": 10, "duration_s": 3, "transition_s": 1}},
        {"turn": {"radius_m": 50, "direction": "LEFT", "angle_deg": 30, "transition_s": 1}},
        {"climb": {"climb_rate_m_per_s": 2, "height_change_m": 10}},
        {"ship_motion": {"duration_s": 10, "roll_amplitude_deg": 5, "roll_period_s": 8,
          "heave_amplitude_m": 1, "heave_period_s": 6, "ramp_s": 1}},
        {"figure_eight": {"radius_m": 20, "loops": 1, "transition_s": 1}},
        {"accelerate": {"acceleration_m_per_s2": 1, "target_speed_m_per_s": 0}},
        {"static": {"duration_s": 5}}]},
      "navigation": {"ned": {"vertical_channel": "TRUTH_HEIGHT", "coning_sculling": false}},
      "sensor": {"preset": "tactical"},
      "monte_carlo": {"runs": 2, "epoch_interval_s": 1,
        "initialization": {"kind": "TRUTH_PLUS_ERRORS"}}})"));
  jobs.push_back(ParseJobJson(R"({"rate_hz": 20, "motion": {"initial": {"lat_deg": 10,
        "lon_deg": 20}, "segments": [{"static": {"duration_s": 6}},
        {"accelerate": {"acceleration_m_per_s2": 1, "duration_s": 3, "decelerate": false}}]},
      "navigation": {"mechanization": "SEED000", "seed000": {"static_period_s": 5,
        "lowpass_cutoff_hz": 1}},
      "sensor": {"preset": "tactical"}, "monte_carlo": {"runs": 2, "seed": 3}})"));

  const std::vector<fs::path> base_dirs = [&] {
    std::vector<fs::path> dirs(jobs.size(), kExamples);
    return dirs;
  }();
  size_t refusals = 0;
  std::set<std::string> fields;
  for (size_t b = 0; b < jobs.size(); ++b) {
    SCOPED_TRACE(b < bases.size() ? bases[b].first : "inline job " + std::to_string(b));
    ASSERT_EQ(RefusalOf(jobs[b], base_dirs[b]).message, "") << "the base job must be valid";
    const bool from_file =
        jobs[b].motion().has_gnss_ins_sim_file() || jobs[b].motion().has_truth_profile_file();
    v1::Job job = jobs[b];
    // Mutating the monte_carlo and the rest; the motion files' paths stay.
    Mutations(&job, [&] {
      try {
        ValidateJob(job, base_dirs[b]);
      } catch (const SpecError& e) {
        ++refusals;
        fields.insert(e.field());
        EXPECT_TRUE(IsSchemaFieldPath(*v1::Job::descriptor(), e.field()))
            << "not a field of the job schema: " << e.what();
        if (from_file) {
          EXPECT_FALSE(e.field().starts_with("motion.segments"))
              << "a job with an imported motion has no segments: " << e.what();
        }
      }
    });
  }
  // The corpus exercises the validator widely: hundreds of refusals naming well over a hundred
  // different fields (a regression in the mutation walk would show as a collapse of these).
  EXPECT_GT(refusals, 500u);
  EXPECT_GT(fields.size(), 100u);
}

TEST(JobValidator, SchemaFieldPathsAreRecognised) {
  const auto& d = *v1::Job::descriptor();
  EXPECT_TRUE(IsSchemaFieldPath(d, "rate_hz"));
  EXPECT_TRUE(IsSchemaFieldPath(d, "motion.segments[2].turn.radius_m"));
  EXPECT_TRUE(IsSchemaFieldPath(d, "sensor.gyro.fixed_bias_deg_per_h[1]"));
  EXPECT_TRUE(IsSchemaFieldPath(d, "monte_carlo"));
  EXPECT_FALSE(IsSchemaFieldPath(d, "sensor.gyro.bias_flicker.tau_max_s"));
  EXPECT_FALSE(IsSchemaFieldPath(d, "monte_carlo.epoch_every_samples"));
  EXPECT_FALSE(IsSchemaFieldPath(d, "rate_hz[0]"));          // not repeated
  EXPECT_FALSE(IsSchemaFieldPath(d, "rate_hz.x"));           // a scalar has no fields
  EXPECT_FALSE(IsSchemaFieldPath(d, "motion.segments[x]"));  // not an index
  EXPECT_FALSE(IsSchemaFieldPath(d, "motion."));
}

// ---- The final check: no non-finite statistic written or stored --------------------------------

// The covariance analysis propagates every 5 samples (0.25 s at 20 Hz): the tactical preset's
// shortest flicker state is 0.25 s, and the validator refuses a longer propagation interval.
v1::JobResult SmallResult(bool covariance) {
  JobValidationOptions options;
  options.overrides.covariance = covariance;
  const ValidatedJob job =
      ValidateJob(ParseJobJson(testing::SmallDriveJob(
                      R"({})", "{}", R"({"preset": "tactical"})",
                      R"({"runs": 3, "epoch_interval_s": 10, "covariance_step_samples": 5})")),
                  ".", options);
  return ToJobResult(JobAsRun(ParseJobJson(testing::SmallDriveJob("{}")), job.spec),
                     RunMonteCarloWithAnalysis(job.spec), "test");
}

TEST(JobValidator, ResultsWithANonFiniteStatisticAreRefused) {
  v1::JobResult result = SmallResult(/*covariance=*/true);
  EXPECT_NO_THROW(CheckResultStatistics(result));
  v1::JobResult bad = result;
  bad.mutable_covariance()->mutable_epochs(1)->set_sigma(0,
                                                         std::numeric_limits<double>::quiet_NaN());
  try {
    CheckResultStatistics(bad);
    ADD_FAILURE() << "a NaN predicted sigma passed";
  } catch (const SpecError& e) {
    EXPECT_EQ(e.field(), "result");
    EXPECT_NE(std::string(e.what()).find("covariance.epochs[1].sigma[0]"), std::string::npos)
        << e.what();
  }
  bad = result;
  bad.mutable_epochs(2)->mutable_components(3)->set_rms(std::numeric_limits<double>::infinity());
  EXPECT_THROW(CheckResultStatistics(bad), SpecError);
}

}  // namespace
}  // namespace driftlab::app
