// Unit tests of the job-schema layer: loading (JSON, YAML), the descriptor-driven schema check and
// the translation to engine types with validation.
#include "driftlab/app/job_file.h"

#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>
#include <google/protobuf/util/message_differencer.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <variant>

#include "driftlab/app/job_validator.h"
#include "driftlab/app/translate.h"
#include "driftlab/spec_error.h"
#include "driftlab/trajectory.h"

namespace driftlab::app {
namespace {

const std::filesystem::path kExamples = std::filesystem::path(DRIFTLAB_SOURCE_DIR) / "examples";

// A valid job moving north at 10 m/s with the given segments and extra top-level fields.
std::string JobWithSegments(const std::string& segments, const std::string& extra = "") {
  return R"({"motion": {"initial": {"lat_deg": 45, "lon_deg": 7,
                                     "velocity_ned_m_per_s": [10, 0, 0]},
                        "segments": [)" +
         segments + R"(]}, "rate_hz": 100)" + extra + "}";
}

// The SpecError message of parsing and translating `json`, or "" if it is valid.
std::string JsonError(const std::string& json) {
  try {
    ToSimulationSpec(ParseJobJson(json), kTestData);
  } catch (const SpecError& e) {
    return e.what();
  }
  return "";
}

std::string YamlError(const std::string& yaml) {
  try {
    ToSimulationSpec(ParseJobYaml(yaml), kTestData);
  } catch (const SpecError& e) {
    return e.what();
  }
  return "";
}

TEST(JobSpec, YamlJobEqualsItsJsonTwin) {
  const JobFile yaml = LoadJobFile(kExamples / "aircraft_climb_turns.yaml");
  const JobFile json = LoadJobFile(kCliData / "aircraft_climb_turns_twin.json");
  EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(yaml.job, json.job))
      << yaml.job.DebugString() << "\nvs\n"
      << json.job.DebugString();

  // Same translated spec: the generated trajectories agree to the bit (tolerance 0: identical
  // numbers through a deterministic generator).
  const SimulationSpec a = ToSimulationSpec(yaml.job, yaml.base_dir);
  const SimulationSpec b = ToSimulationSpec(json.job, json.base_dir);
  ASSERT_EQ(a.motion.segments.size(), 8u);
  ASSERT_EQ(a.motion.segments.size(), b.motion.segments.size());
  EXPECT_EQ(a.rate_hz, b.rate_hz);
  EXPECT_EQ(a.mechanization, b.mechanization);
  EXPECT_EQ(a.ned.vertical, b.ned.vertical);
  EXPECT_EQ(a.ned.coning_sculling, b.ned.coning_sculling);
  TrajectoryGenerator ga(a.motion, a.rate_hz), gb(b.motion, b.rate_hz);
  ASSERT_EQ(ga.num_steps(), gb.num_steps());
  TrajectorySample sa, sb;
  while (ga.Next(&sa)) {
    ASSERT_TRUE(gb.Next(&sb));
    ASSERT_EQ(sa.truth.llh.lat_rad, sb.truth.llh.lat_rad);
    ASSERT_EQ(sa.truth.llh.lon_rad, sb.truth.llh.lon_rad);
    ASSERT_EQ(sa.truth.llh.h_m, sb.truth.llh.h_m);
    ASSERT_EQ(sa.truth.v_eb_n, sb.truth.v_eb_n);
    ASSERT_EQ(sa.truth.q_b_n.coeffs(), sb.truth.q_b_n.coeffs());
    ASSERT_EQ(sa.increment.delta_theta_ib_b, sb.increment.delta_theta_ib_b);
    ASSERT_EQ(sa.increment.delta_v_ib_b, sb.increment.delta_v_ib_b);
  }
}

TEST(JobSpec, AnglesAreConvertedFromDegreesToRadians) {
  const SimulationSpec spec = ToSimulationSpec(
      ParseJobJson(R"({"motion": {"initial": {"lat_deg": 45, "lon_deg": -3.7722, "roll_deg": 10,
                                              "pitch_deg": -5, "yaw_deg": 90,
                                              "velocity_ned_m_per_s": [0, 8, 0]},
                                  "segments": [{"turn": {"rate_deg_per_s": 36,
                                                         "angle_deg": 720}}]},
                      "rate_hz": 100})"),
      kTestData);
  // One multiplication by pi/180: within 4 ulp (EXPECT_DOUBLE_EQ) of the exact radian value.
  EXPECT_DOUBLE_EQ(spec.motion.initial.llh.lat_rad, M_PI / 4);
  EXPECT_DOUBLE_EQ(spec.motion.initial.llh.lon_rad, -3.7722 * kDeg);
  EXPECT_DOUBLE_EQ(spec.motion.initial.attitude.roll_rad, M_PI / 18);
  EXPECT_DOUBLE_EQ(spec.motion.initial.attitude.pitch_rad, -M_PI / 36);
  EXPECT_DOUBLE_EQ(spec.motion.initial.attitude.yaw_rad, M_PI / 2);
  EXPECT_EQ(spec.motion.initial.v_eb_n, Eigen::Vector3d(0, 8, 0));
  const auto& turn = std::get<TurnSegment>(spec.motion.segments.at(0));
  EXPECT_DOUBLE_EQ(*turn.rate_rad_per_s, M_PI / 5);
  EXPECT_DOUBLE_EQ(*turn.angle_rad, 4 * M_PI);
  EXPECT_FALSE(turn.duration_s.has_value());
  EXPECT_FALSE(turn.radius_m.has_value());
}

TEST(JobSpec, AbsentOptionalFieldsTakeTheDocumentedDefaults) {
  const SimulationSpec spec = ToSimulationSpec(
      ParseJobJson(JobWithSegments(R"({"climb": {"climb_rate_m_per_s": 2, "duration_s": 30}},
                                      {"turn": {"radius_m": 100, "duration_s": 10}},
                                      {"figure_eight": {"radius_m": 50}})")),
      kTestData);
  EXPECT_EQ(spec.motion.earth_model, EarthModel::kWgs84);
  EXPECT_FALSE(spec.motion.flat_gravity_m_per_s2.has_value());
  EXPECT_EQ(spec.mechanization, MechanizationKind::kNed);
  EXPECT_EQ(spec.ned.vertical, VerticalChannel::kFree);
  EXPECT_TRUE(spec.ned.coning_sculling);
  EXPECT_EQ(spec.seed000.static_period_s, 90.0);
  EXPECT_EQ(spec.seed000.lowpass_cutoff_hz, 0.0);
  EXPECT_EQ(spec.motion.initial.llh.h_m, 0.0);
  EXPECT_EQ(std::get<ClimbSegment>(spec.motion.segments[0]).vertical_acceleration_m_per_s2, 0.5);
  EXPECT_TRUE(std::get<TurnSegment>(spec.motion.segments[1]).right);
  EXPECT_EQ(std::get<FigureEightSegment>(spec.motion.segments[2]).loops, 1);
  EXPECT_EQ(spec.motion.field_path, "motion");
}

TEST(JobSpec, EnumsAndOptionsReachTheEngineSpec) {
  const SimulationSpec spec = ToSimulationSpec(
      ParseJobJson(R"({"motion": {"earth_model": "FLAT", "flat_gravity_m_per_s2": 9.8,
                                  "initial": {"lat_deg": 40, "lon_deg": -3},
                                  "vehicle": {"coordinated_turns": true},
                                  "segments": [{"static": {"duration_s": 100}}]},
                      "rate_hz": 200,
                      "navigation": {"mechanization": "SEED000",
                                     "ned": {"vertical_channel": "TRUTH_HEIGHT",
                                             "coning_sculling": false},
                                     "seed000": {"static_period_s": 60,
                                                 "lowpass_cutoff_hz": 5}}})"),
      kTestData);
  EXPECT_EQ(spec.motion.earth_model, EarthModel::kFlat);
  EXPECT_EQ(spec.motion.flat_gravity_m_per_s2, 9.8);
  EXPECT_TRUE(spec.motion.vehicle.coordinated_turns);
  EXPECT_FALSE(spec.motion.vehicle.pitch_follows_flight_path);
  EXPECT_EQ(spec.rate_hz, 200.0);
  EXPECT_EQ(spec.mechanization, MechanizationKind::kSeed000);
  EXPECT_EQ(spec.ned.vertical, VerticalChannel::kTruthHeight);
  EXPECT_FALSE(spec.ned.coning_sculling);
  EXPECT_EQ(spec.seed000.static_period_s, 60.0);
  EXPECT_EQ(spec.seed000.lowpass_cutoff_hz, 5.0);
}

TEST(JobSpec, JsonNamesInLowerCamelCaseAreAcceptedLikeProtoNames) {
  EXPECT_EQ(JsonError(R"({"motion": {"initial": {"latDeg": 45, "lonDeg": 7},
                                     "segments": [{"static": {"durationS": 10}}]},
                          "rateHz": 100})"),
            "");
}

TEST(JobSpec, UnknownFieldNamesItsPathAndTheAllowedFields) {
  EXPECT_EQ(JsonError(JobWithSegments(R"({"constant_velocity": {"duration_s": 1}},
                                         {"spin": {"duration_s": 5}})")),
            "motion.segments[1].spin: unknown field; allowed: static, accelerate, "
            "constant_velocity, turn, climb, zigzag, ship_motion, figure_eight");
  EXPECT_EQ(JsonError(JobWithSegments(R"({"turn": {"rate_deg_per_s": 3, "angle_deg": 90,
                                                   "bank_deg": 20}})")),
            "motion.segments[0].turn.bank_deg: unknown field; allowed: rate_deg_per_s, radius_m, "
            "direction, angle_deg, duration_s, transition_s");
}

TEST(JobSpec, WrongTypeNamesItsPathTheValueAndTheExpectedType) {
  EXPECT_EQ(JsonError(R"({"name": 7})"), "name: 7 is not allowed; allowed: a string");
  EXPECT_EQ(JsonError(JobWithSegments(R"({"constant_velocity": {"duration_s": [1]}})")),
            "motion.segments[0].constant_velocity.duration_s: a list is not allowed; allowed: a "
            "number");
  EXPECT_EQ(JsonError(JobWithSegments(R"({"figure_eight": {"radius_m": 10, "loops": 1.5}})")),
            "motion.segments[0].figure_eight.loops: 1.5 is not allowed; allowed: an integer from "
            "-2147483648 to 2147483647");
  EXPECT_EQ(JsonError(R"({"motion": {"segments": {"static": {}}}})"),
            "motion.segments: an object is not allowed; allowed: a list");
  EXPECT_EQ(JsonError(R"({"motion": {"vehicle": {"coordinated_turns": "yes"}}})"),
            "motion.vehicle.coordinated_turns: \"yes\" is not allowed; allowed: true or false");
}

TEST(JobSpec, BadEnumNameListsTheAllowedNames) {
  EXPECT_EQ(JsonError(JobWithSegments(R"({"constant_velocity": {"duration_s": 1}})",
                                      R"(, "navigation": {"mechanization": "INS"})")),
            "navigation.mechanization: \"INS\" is not allowed; allowed: NED, SEED000");
  EXPECT_EQ(YamlError("motion:\n  earth_model: ROUND\n"),
            "motion.earth_model: \"ROUND\" is not allowed; allowed: WGS84, FLAT");
}

TEST(JobSpec, TwoKindsInOneSegmentAreRejected) {
  EXPECT_EQ(JsonError(JobWithSegments(R"({"static": {"duration_s": 1},
                                          "turn": {"rate_deg_per_s": 1, "angle_deg": 9}})")),
            "motion.segments[0]: static and turn are both set; allowed: exactly one of static, "
            "accelerate, constant_velocity, turn, climb, zigzag, ship_motion, figure_eight");
  EXPECT_EQ(JsonError(JobWithSegments("{}")),
            "motion.segments[0]: empty segment is not allowed; allowed: exactly one of static, "
            "accelerate, constant_velocity, turn, climb, zigzag, ship_motion, figure_eight");
}

TEST(JobSpec, NanAndInfinityAreRejectedWithTheirPath) {
  // JSON has no NaN literal: the protobuf JSON mapping reads the strings "NaN" and "Infinity".
  EXPECT_EQ(JsonError(JobWithSegments(R"({"constant_velocity": {"duration_s": "NaN"}})")),
            "motion.segments[0].constant_velocity.duration_s: nan is not allowed; allowed: 0 < "
            "duration_s <= 100000 s");
  EXPECT_EQ(JsonError(JobWithSegments(R"({"constant_velocity": {"duration_s": 1}})",
                                      R"(, "navigation": {"seed000": {"lowpass_cutoff_hz":
                                                                      "-Infinity"}})")),
            "navigation.seed000.lowpass_cutoff_hz: -inf is not allowed; allowed: 0 <= "
            "lowpass_cutoff_hz < 50 Hz (rate_hz / 2; 0 = no filter)");
  EXPECT_EQ(YamlError("motion:\n  initial: {lat_deg: .nan, lon_deg: 7}\n"
                      "  segments: [static: {duration_s: 1}]\nrate_hz: 100\n"),
            "motion.initial.lat_deg: nan is not allowed; allowed: -89 <= lat_deg <= 89 deg");
  EXPECT_EQ(YamlError("motion:\n  initial: {lat_deg: 1, lon_deg: 7}\n"
                      "  segments: [static: {duration_s: .inf}]\nrate_hz: 100\n"),
            "motion.segments[0].static.duration_s: inf is not allowed; allowed: 0 < duration_s "
            "<= 100000 s");
}

TEST(JobSpec, MissingRequiredFieldIsReportedAsMissing) {
  EXPECT_EQ(JsonError(R"({"motion": {"initial": {"lon_deg": 7},
                                     "segments": [{"static": {"duration_s": 10}}]},
                          "rate_hz": 100})"),
            "motion.initial.lat_deg: missing is not allowed; allowed: -89 <= lat_deg <= 89 deg");
  EXPECT_EQ(JsonError(R"({"motion": {"initial": {"lat_deg": 1, "lon_deg": 7},
                                     "segments": [{"static": {"duration_s": 10}}]}})"),
            "rate_hz: missing is not allowed; allowed: 1 <= rate_hz <= 2000 Hz");
  EXPECT_EQ(JsonError(JobWithSegments(R"({"zigzag": {"amplitude_m": 5, "duration_s": 60}})")),
            "motion.segments[0].zigzag.period_s: missing is not allowed; allowed: 0 < period_s "
            "<= 100000 s");
  EXPECT_EQ(JsonError(R"({"rate_hz": 100})"),
            "motion: missing is not allowed; allowed: a motion {initial, segments, ...}");
  EXPECT_EQ(JsonError(R"({"rate_hz": 100, "motion": {"initial": {"lat_deg": 1, "lon_deg": 2}}})"),
            "motion.segments: missing is not allowed; allowed: a list of segments, or "
            "motion.gnss_ins_sim_file, or motion.truth_profile_file");
  EXPECT_EQ(JsonError(JobWithSegments(R"({"ship_motion": {"duration_s": 60,
                                                          "roll_amplitude_deg": 3}})")),
            "motion.segments[0].ship_motion.roll_period_s: missing is not allowed; allowed: 0 < "
            "roll_period_s <= 1000 s");
}

TEST(JobSpec, ExactlyOneOfTwoAlternativesIsEnforced) {
  EXPECT_EQ(JsonError(JobWithSegments(R"({"turn": {"rate_deg_per_s": 3, "radius_m": 100,
                                                   "angle_deg": 90}})")),
            "motion.segments[0].turn: both rate_deg_per_s and radius_m are set; allowed: exactly "
            "one of them");
  EXPECT_EQ(JsonError(JobWithSegments(R"({"turn": {"rate_deg_per_s": 3}})")),
            "motion.segments[0].turn.angle_deg: missing is not allowed; allowed: exactly one of "
            "motion.segments[0].turn.angle_deg or motion.segments[0].turn.duration_s");
  EXPECT_EQ(JsonError(JobWithSegments(R"({"turn": {"rate_deg_per_s": 3, "direction": "LEFT",
                                                   "angle_deg": 90}})")),
            "motion.segments[0].turn.direction: LEFT is not allowed; allowed: absent with "
            "rate_deg_per_s (its sign gives the direction: + = right)");
}

struct RangeCase {
  std::string job;
  std::string message;
};

class OutOfRange : public ::testing::TestWithParam<RangeCase> {};

TEST_P(OutOfRange, MessageNamesThePathTheValueAndTheAllowedRange) {
  EXPECT_EQ(JsonError(GetParam().job), GetParam().message);
}

INSTANTIATE_TEST_SUITE_P(
    JobSpec, OutOfRange,
    ::testing::Values(
        RangeCase{JobWithSegments(R"({"static": {"duration_s": -5}})"),
                  "motion.segments[0].static.duration_s: -5 is not allowed; allowed: 0 < "
                  "duration_s <= 100000 s"},
        RangeCase{R"({"rate_hz": 0.5})",
                  "rate_hz: 0.5 is not allowed; allowed: 1 <= rate_hz <= 2000 Hz"},
        RangeCase{R"({"rate_hz": 5000})",
                  "rate_hz: 5000 is not allowed; allowed: 1 <= rate_hz <= 2000 Hz"},
        RangeCase{R"({"rate_hz": 10, "motion": {"initial": {"lat_deg": 95, "lon_deg": 0},
                                                "segments": [{"static": {"duration_s": 1}}]}})",
                  "motion.initial.lat_deg: 95 is not allowed; allowed: -89 <= lat_deg <= 89 deg"},
        RangeCase{R"({"rate_hz": 10, "motion": {"initial": {"lat_deg": 5, "lon_deg": 0,
                                                            "velocity_ned_m_per_s": [1, 2]},
                                                "segments": [{"static": {"duration_s": 1}}]}})",
                  "motion.initial.velocity_ned_m_per_s: 2 values is not allowed; allowed: "
                  "exactly 3 values [north, east, down] m/s, or absent for rest"},
        RangeCase{JobWithSegments(R"({"turn": {"rate_deg_per_s": 0, "angle_deg": 90}})"),
                  "motion.segments[0].turn.rate_deg_per_s: 0 is not allowed; allowed: -180 <= "
                  "rate_deg_per_s <= 180 deg/s, not 0"},
        RangeCase{JobWithSegments(R"({"accelerate": {"acceleration_m_per_s2": -1,
                                                    "duration_s": 3}})"),
                  "motion.segments[0].accelerate.acceleration_m_per_s2: -1 is not allowed; "
                  "allowed: 0 < acceleration_m_per_s2 <= 100 m/s^2"},
        RangeCase{JobWithSegments(R"({"climb": {"climb_rate_m_per_s": 5,
                                               "height_change_m": -100}})"),
                  "motion.segments[0].climb.height_change_m: -100 is not allowed; allowed: "
                  "-31000 <= height_change_m <= 31000 m, not 0 (same sign as climb_rate_m_per_s)"},
        RangeCase{JobWithSegments(R"({"ship_motion": {"duration_s": 20, "ramp_s": 15}})"),
                  "motion.segments[0].ship_motion.ramp_s: 15 is not allowed; allowed: 0 <= "
                  "ramp_s <= 10 s (duration_s / 2)"},
        RangeCase{JobWithSegments(R"({"figure_eight": {"radius_m": 30, "loops": 0}})"),
                  "motion.segments[0].figure_eight.loops: 0 is not allowed; allowed: 1 <= loops "
                  "<= 1000"},
        RangeCase{JobWithSegments(R"({"constant_velocity": {"duration_s": 1}})",
                                  R"(, "navigation": {"seed000": {"lowpass_cutoff_hz": 50}})"),
                  "navigation.seed000.lowpass_cutoff_hz: 50 is not allowed; allowed: 0 <= "
                  "lowpass_cutoff_hz < 50 Hz (rate_hz / 2; 0 = no filter)"},
        RangeCase{R"({"rate_hz": 10, "motion": {"flat_gravity_m_per_s2": 9.8,
                      "initial": {"lat_deg": 5, "lon_deg": 0},
                      "segments": [{"static": {"duration_s": 1}}]}})",
                  "motion.flat_gravity_m_per_s2: 9.8 with earth_model WGS84 is not allowed; "
                  "allowed: absent unless earth_model is FLAT"}));

TEST(JobSpec, YamlScalarsResolveByTheCoreSchema) {
  google::protobuf::Value value;
  ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(
                  YamlToJson("n: 12\nf: -1.5e3\nq: '12'\nb: true\nz: ~\nnan: .nan\ninf: -.inf\n"
                             "s: hello\nl: [1, two]\nh: .5\ne: +2E-3\nv: 1.2.3\ni: 12e\n"),
                  &value)
                  .ok());
  const auto& fields = value.struct_value().fields();
  EXPECT_EQ(fields.at("n").number_value(), 12.0);
  EXPECT_EQ(fields.at("f").number_value(), -1500.0);
  EXPECT_EQ(fields.at("q").string_value(), "12");
  EXPECT_TRUE(fields.at("b").bool_value());
  EXPECT_EQ(fields.at("z").kind_case(), google::protobuf::Value::kNullValue);
  EXPECT_EQ(fields.at("nan").string_value(), "NaN");
  EXPECT_EQ(fields.at("inf").string_value(), "-Infinity");
  EXPECT_EQ(fields.at("s").string_value(), "hello");
  EXPECT_EQ(fields.at("l").list_value().values(1).string_value(), "two");
  EXPECT_EQ(fields.at("h").number_value(), 0.5);
  EXPECT_EQ(fields.at("e").number_value(), 2e-3);
  EXPECT_EQ(fields.at("v").string_value(), "1.2.3");
  EXPECT_EQ(fields.at("i").string_value(), "12e");
}

TEST(JobSpec, SyntaxErrorsAreOneLineWithTheSource) {
  const std::string json_error = JsonError("{\"rate_hz\": 100,\n \"motion\" {}}");
  EXPECT_EQ(json_error.find('\n'), std::string::npos) << json_error;
  // The missing ':' is on line 2 of the text, column 11 (CheckJsonSyntax).
  EXPECT_TRUE(json_error.starts_with(
      "job: invalid JSON at line 2, column 11: expected ':' after a member name, found '{'"))
      << json_error;
  const std::string yaml_error = YamlError("motion:\n  initial: [1, 2\n");
  EXPECT_EQ(yaml_error.find('\n'), std::string::npos) << yaml_error;
  EXPECT_TRUE(yaml_error.starts_with("job: invalid YAML at line ")) << yaml_error;
  EXPECT_EQ(YamlError("rate_hz: 1\nrate_hz: 2\n"), "rate_hz: line 2: given twice; allowed: once");
}

// yaml-cpp's LoadAll never returns on a ',' at a document's top level (calib/yaml_document.h):
// refused like a second document, in bounded time.
TEST(JobSpec, StrayTopLevelCommaInYamlIsRefusedInsteadOfLoopingForever) {
  for (const std::string yaml : {",", "rate_hz: 100\n---\n,", "# job\n,\n"}) {
    EXPECT_EQ(YamlError(yaml),
              "job: more than one YAML document (a --- separator, or a ',' outside [ ] and { }); "
              "allowed: one document")
        << yaml;
  }
  EXPECT_NE(YamlError("rate_hz: 100\n---\nrate_hz: 50\n").find("more than one YAML document"),
            std::string::npos);
}

TEST(JobSpec, ImportedMotionFileResolvesAgainstTheJobFileDirectory) {
  const JobFile file = LoadJobFile(kExamples / "gnss_ins_sim_import.json");
  EXPECT_EQ(file.base_dir, std::filesystem::absolute(kExamples));
  const SimulationSpec spec = ToSimulationSpec(file.job, file.base_dir);
  // motions/car_loop.csv has 10 command lines; its initial line is at 31.2304 N, 121.4737 E.
  EXPECT_EQ(spec.motion.segments.size(), 10u);
  EXPECT_DOUBLE_EQ(spec.motion.initial.llh.lat_rad, 31.2304 * kDeg);
  EXPECT_DOUBLE_EQ(spec.motion.gnss_ins_sim_limits.max_acceleration_m_per_s2, 2.0);
  EXPECT_DOUBLE_EQ(spec.motion.gnss_ins_sim_limits.max_angular_rate_rad_per_s, 2.0 * kDeg);

  v1::Job missing = file.job;
  missing.mutable_motion()->mutable_gnss_ins_sim_file()->set_path("motions/no_such_file.csv");
  EXPECT_THROW(ToSimulationSpec(missing, file.base_dir), SpecError);
}

TEST(JobSpec, TruthProfileFileIsTheWholeMotion) {
  const JobFile file = LoadJobFile(kExamples / "truth_profile_import.json");
  const SimulationSpec spec = ValidateJob(file).spec.simulation;
  // motions/north_drive_profile.csv: 31 samples from t = 0, at rest at 45 N, 7 E, 200 m.
  EXPECT_TRUE(spec.motion.segments.empty());
  ASSERT_EQ(spec.motion.truth_profile.size(), 31u);
  EXPECT_DOUBLE_EQ(spec.motion.initial.llh.lat_rad, 45.0 * kDeg);
  EXPECT_DOUBLE_EQ(spec.motion.initial.llh.lon_rad, 7.0 * kDeg);
  EXPECT_EQ(spec.motion.initial.llh.h_m, 200.0);
  EXPECT_EQ(spec.motion.truth_profile.back().v_eb_n, Eigen::Vector3d(10, 0, 0));

  EXPECT_EQ(JsonError(R"({"rate_hz": 10, "motion": {"initial": {"lat_deg": 1, "lon_deg": 2},
                          "truth_profile_file": {"path": "x.csv"}}})"),
            "motion.initial: given with motion.truth_profile_file is not allowed; allowed: absent "
            "(the profile's first sample is the initial state)");
  EXPECT_EQ(JsonError(R"({"rate_hz": 10, "motion": {"truth_profile_file": {}}})"),
            "motion.truth_profile_file.path: missing is not allowed; allowed: the path of a "
            "readable file");
  EXPECT_EQ(JsonError(R"({"rate_hz": 10, "motion": {"segments": [{"static": {"duration_s": 1}}],
                          "truth_profile_file": {"path": "x.csv"}}})"),
            "motion: more than one of segments, gnss_ins_sim_file, truth_profile_file is set; "
            "allowed: exactly one of them");
}

TEST(JobSpec, EngineChecksThatNeedThePlannedMotionRunInValidateJob) {
  // A static segment entered at 10 m/s passes the field checks; the generator rejects it.
  JobFile file{ParseJobJson(JobWithSegments(R"({"static": {"duration_s": 10}})")), kTestData};
  EXPECT_NO_THROW(ToSimulationSpec(file.job, file.base_dir));
  try {
    ValidateJob(file);
    ADD_FAILURE() << "static segment at speed accepted";
  } catch (const SpecError& e) {
    EXPECT_TRUE(e.field().starts_with("motion.segments[0]")) << e.what();
  }
}

TEST(JobSpec, Seed000StaticPeriodMustFitInTheInitialRest) {
  const JobFile file = LoadJobFile(kExamples / "ship_seaway.json");
  EXPECT_NO_THROW(ValidateJob(file));
  JobFile longer = file;
  longer.job.mutable_navigation()->mutable_seed000()->set_static_period_s(100);
  try {
    ValidateJob(longer);
    ADD_FAILURE() << "static period longer than the rest accepted";
  } catch (const SpecError& e) {
    EXPECT_EQ(e.field(), "navigation.seed000.static_period_s");
    EXPECT_TRUE(
        std::string(e.what()).starts_with("navigation.seed000.static_period_s: 100 is "
                                          "not allowed; allowed: 0 < static_period_s <= "))
        << e.what();
  }
}

TEST(JobSpec, EveryExampleTranslatesAndValidates) {
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(kExamples)) {
    const std::string extension = entry.path().extension().string();
    if (extension != ".json" && extension != ".yaml") continue;
    SCOPED_TRACE(entry.path().string());
    EXPECT_NO_THROW(ValidateJob(LoadJobFile(entry.path())));
    ++count;
  }
  EXPECT_GE(count, 9);
}

}  // namespace
}  // namespace driftlab::app
