#include "driftlab/app/translate.h"

#include <fmt/format.h>

#include <cmath>
#include <string>
#include <string_view>

#include "driftlab/app/schema_check.h"
#include "driftlab/io.h"
#include "driftlab/spec_error.h"
#include "driftlab/trajectory.h"
#include "driftlab/units.h"
#include "job/field_checks.h"
#include "job/job_translation.h"

namespace driftlab::app {
namespace {

// Allowed ranges of the job's numbers. The physical limits come from the engine (rate and
// duration, trajectory.h) or from the vehicles driftlab models; they are wide enough for any real
// car, ship or aircraft and exclude values where the models break down (NED singular at the poles,
// pitch of +-90 deg, the free-air gravity expansion far above 30 km).
constexpr double kMaxLatitude_deg = 89.0;
constexpr double kMinHeight_m = -1000.0;
constexpr double kMaxHeight_m = 30000.0;
constexpr double kMaxSpeed_m_per_s = 1000.0;
constexpr double kMaxAcceleration_m_per_s2 = 100.0;  // about 10 g
constexpr double kMaxTurnRate_deg_per_s = 180.0;
constexpr double kMaxRadius_m = 1.0e6;
constexpr double kMaxTurnAngle_deg = 36000.0;  // 100 full turns
constexpr double kMaxTransition_s = 1000.0;
constexpr double kMaxClimbRate_m_per_s = 500.0;
constexpr double kMaxHeightChange_m = kMaxHeight_m - kMinHeight_m;
constexpr double kMaxShipAngle_deg = 60.0;
constexpr double kMaxHeave_m = 50.0;
constexpr double kMaxPeriod_s = 1000.0;
constexpr double kMaxPhase_deg = 360.0;
constexpr double kMaxZigzagAmplitude_m = 1.0e5;
constexpr int kMaxLoops = 1000;
constexpr double kMaxAngularRate_deg_per_s = 3600.0;
constexpr double kMaxAngularAcceleration_deg_per_s2 = 3600.0;
constexpr double kMinFlatGravity_m_per_s2 = 0.1;
constexpr double kMaxFlatGravity_m_per_s2 = 30.0;

// "exactly one of a or b" for a pair of optional fields.
void ExactlyOne(const std::string& path, std::string_view a, bool has_a, std::string_view b,
                bool has_b) {
  if (has_a && has_b) {
    throw SpecError(path, fmt::format("both {} and {} are set; allowed: exactly one of them", a, b),
                    0);
  }
  if (!has_a && !has_b) {
    throw SpecError(fmt::format("{}.{}", path, a), "",
                    fmt::format("exactly one of {}.{} or {}.{}", path, a, path, b));
  }
}

std::filesystem::path Resolve(const std::string& file, const std::filesystem::path& base_dir) {
  std::filesystem::path path(file);
  return path.is_absolute() ? path : base_dir / path;
}

InitialState TranslateInitial(const v1::InitialState& in, const std::string& path) {
  InitialState out;
  out.llh.lat_rad = kDegToRad * Required(path + ".lat_deg", in.has_lat_deg(), in.lat_deg(),
                                         Closed(-kMaxLatitude_deg, kMaxLatitude_deg, "deg"));
  out.llh.lon_rad = kDegToRad * Required(path + ".lon_deg", in.has_lon_deg(), in.lon_deg(),
                                         Closed(-180, 360, "deg"));
  out.llh.h_m = Check(path + ".height_m", in.height_m(), Closed(kMinHeight_m, kMaxHeight_m, "m"));
  const std::string velocity_path = path + ".velocity_ned_m_per_s";
  if (in.velocity_ned_m_per_s_size() != 0) {
    if (in.velocity_ned_m_per_s_size() != 3) {
      throw SpecError(velocity_path, fmt::format("{} values", in.velocity_ned_m_per_s_size()),
                      "exactly 3 values [north, east, down] m/s, or absent for rest");
    }
    for (int i = 0; i < 3; ++i) {
      out.v_eb_n[i] = Check(fmt::format("{}[{}]", velocity_path, i), in.velocity_ned_m_per_s(i),
                            Closed(-kMaxSpeed_m_per_s, kMaxSpeed_m_per_s, "m/s"));
    }
  }
  out.attitude.roll_rad =
      kDegToRad * Check(path + ".roll_deg", in.roll_deg(), Closed(-180, 180, "deg"));
  out.attitude.pitch_rad =
      kDegToRad * Check(path + ".pitch_deg", in.pitch_deg(), Closed(-89.9, 89.9, "deg"));
  out.attitude.yaw_rad =
      kDegToRad * Check(path + ".yaw_deg", in.yaw_deg(), Closed(-360, 360, "deg"));
  return out;
}

double Duration(const std::string& path, bool has, double value) {
  return Required(path, has, value, Positive(kMaxDuration_s, "s"));
}

Segment TranslateAccelerate(const v1::AccelerateSegment& in, const std::string& path) {
  AccelerateSegment out;
  out.acceleration_m_per_s2 =
      Required(path + ".acceleration_m_per_s2", in.has_acceleration_m_per_s2(),
               in.acceleration_m_per_s2(), Positive(kMaxAcceleration_m_per_s2, "m/s^2"));
  ExactlyOne(path, "target_speed_m_per_s", in.has_target_speed_m_per_s(), "duration_s",
             in.has_duration_s());
  if (in.has_target_speed_m_per_s()) {
    out.target_speed_m_per_s = Check(path + ".target_speed_m_per_s", in.target_speed_m_per_s(),
                                     Closed(0, kMaxSpeed_m_per_s, "m/s"));
    if (in.decelerate()) {
      throw SpecError(path + ".decelerate", "true",
                      "false with target_speed_m_per_s (the target gives the sign)");
    }
  } else {
    out.duration_s = Duration(path + ".duration_s", true, in.duration_s());
  }
  out.decelerate = in.decelerate();
  return out;
}

Segment TranslateTurn(const v1::TurnSegment& in, const std::string& path) {
  TurnSegment out;
  ExactlyOne(path, "rate_deg_per_s", in.has_rate_deg_per_s(), "radius_m", in.has_radius_m());
  if (in.has_rate_deg_per_s()) {
    out.rate_rad_per_s = kDegToRad * Check(path + ".rate_deg_per_s", in.rate_deg_per_s(),
                                           NonZero(kMaxTurnRate_deg_per_s, "deg/s"));
    if (in.direction() != v1::TurnSegment::DIRECTION_UNSPECIFIED) {
      throw SpecError(path + ".direction", v1::TurnSegment::Direction_Name(in.direction()),
                      "absent with rate_deg_per_s (its sign gives the direction: + = right)");
    }
  } else {
    out.radius_m = Check(path + ".radius_m", in.radius_m(), Positive(kMaxRadius_m, "m"));
    out.right = in.direction() != v1::TurnSegment::LEFT;
  }
  ExactlyOne(path, "angle_deg", in.has_angle_deg(), "duration_s", in.has_duration_s());
  if (in.has_angle_deg()) {
    out.angle_rad =
        kDegToRad * Check(path + ".angle_deg", in.angle_deg(), Positive(kMaxTurnAngle_deg, "deg"));
  } else {
    out.duration_s = Duration(path + ".duration_s", true, in.duration_s());
  }
  out.transition_s =
      Check(path + ".transition_s", in.transition_s(), Closed(0, kMaxTransition_s, "s"));
  return out;
}

Segment TranslateClimb(const v1::ClimbSegment& in, const std::string& path) {
  ClimbSegment out;
  out.climb_rate_m_per_s = Required(path + ".climb_rate_m_per_s", in.has_climb_rate_m_per_s(),
                                    in.climb_rate_m_per_s(), NonZero(kMaxClimbRate_m_per_s, "m/s"));
  out.vertical_acceleration_m_per_s2 =
      OptionalOr(path + ".vertical_acceleration_m_per_s2", in.has_vertical_acceleration_m_per_s2(),
                 in.vertical_acceleration_m_per_s2(), out.vertical_acceleration_m_per_s2,
                 Positive(kMaxAcceleration_m_per_s2, "m/s^2"));
  ExactlyOne(path, "height_change_m", in.has_height_change_m(), "duration_s", in.has_duration_s());
  if (in.has_height_change_m()) {
    const std::string change_path = path + ".height_change_m";
    Range range = NonZero(kMaxHeightChange_m, "m");
    range.note = "(same sign as climb_rate_m_per_s)";
    const double change = Check(change_path, in.height_change_m(), range);
    if ((change > 0) != (out.climb_rate_m_per_s > 0)) {
      throw SpecError(change_path, fmt::format("{}", change), Allowed(change_path, range));
    }
    out.height_change_m = change;
  } else {
    out.duration_s = Duration(path + ".duration_s", true, in.duration_s());
  }
  return out;
}

Segment TranslateZigzag(const v1::ZigzagSegment& in, const std::string& path) {
  ZigzagSegment out;
  out.amplitude_m = Required(path + ".amplitude_m", in.has_amplitude_m(), in.amplitude_m(),
                             Positive(kMaxZigzagAmplitude_m, "m"));
  out.period_s =
      Required(path + ".period_s", in.has_period_s(), in.period_s(), Positive(kMaxDuration_s, "s"));
  out.duration_s = Duration(path + ".duration_s", in.has_duration_s(), in.duration_s());
  return out;
}

// One sinusoid of the ship motion: amplitude (converted by `scale`), its period (required when the
// amplitude is non-zero) and its phase in degrees.
void TranslateSinusoid(const std::string& path, std::string_view name, std::string_view unit,
                       double amplitude_limit, double scale, double amplitude, bool has_period,
                       double period, double phase_deg, double* amplitude_out, double* period_out,
                       double* phase_rad_out) {
  const std::string amplitude_path = fmt::format("{}.{}_amplitude_{}", path, name, unit);
  const std::string period_path = fmt::format("{}.{}_period_s", path, name);
  const std::string phase_path = fmt::format("{}.{}_phase_deg", path, name);
  *amplitude_out = scale * Check(amplitude_path, amplitude, Closed(0, amplitude_limit, unit));
  if (amplitude != 0.0 || has_period) {
    *period_out = Required(period_path, has_period, period, Positive(kMaxPeriod_s, "s"));
  }
  *phase_rad_out =
      kDegToRad * Check(phase_path, phase_deg, Closed(-kMaxPhase_deg, kMaxPhase_deg, "deg"));
}

Segment TranslateShipMotion(const v1::ShipMotionSegment& in, const std::string& path) {
  ShipMotionSegment out;
  out.duration_s = Duration(path + ".duration_s", in.has_duration_s(), in.duration_s());
  TranslateSinusoid(path, "roll", "deg", kMaxShipAngle_deg, kDegToRad, in.roll_amplitude_deg(),
                    in.has_roll_period_s(), in.roll_period_s(), in.roll_phase_deg(),
                    &out.roll_amplitude_rad, &out.roll_period_s, &out.roll_phase_rad);
  TranslateSinusoid(path, "pitch", "deg", kMaxShipAngle_deg, kDegToRad, in.pitch_amplitude_deg(),
                    in.has_pitch_period_s(), in.pitch_period_s(), in.pitch_phase_deg(),
                    &out.pitch_amplitude_rad, &out.pitch_period_s, &out.pitch_phase_rad);
  TranslateSinusoid(path, "yaw", "deg", kMaxShipAngle_deg, kDegToRad, in.yaw_amplitude_deg(),
                    in.has_yaw_period_s(), in.yaw_period_s(), in.yaw_phase_deg(),
                    &out.yaw_amplitude_rad, &out.yaw_period_s, &out.yaw_phase_rad);
  TranslateSinusoid(path, "heave", "m", kMaxHeave_m, 1.0, in.heave_amplitude_m(),
                    in.has_heave_period_s(), in.heave_period_s(), in.heave_phase_deg(),
                    &out.heave_amplitude_m, &out.heave_period_s, &out.heave_phase_rad);
  Range ramp = Closed(0, out.duration_s / 2, "s");
  ramp.note = "(duration_s / 2)";
  out.ramp_s = Check(path + ".ramp_s", in.ramp_s(), ramp);
  return out;
}

Segment TranslateFigureEight(const v1::FigureEightSegment& in, const std::string& path) {
  FigureEightSegment out;
  ExactlyOne(path, "radius_m", in.has_radius_m(), "rate_deg_per_s", in.has_rate_deg_per_s());
  if (in.has_radius_m()) {
    out.radius_m = Check(path + ".radius_m", in.radius_m(), Positive(kMaxRadius_m, "m"));
  } else {
    out.rate_rad_per_s = kDegToRad * Check(path + ".rate_deg_per_s", in.rate_deg_per_s(),
                                           Positive(kMaxTurnRate_deg_per_s, "deg/s"));
  }
  out.transition_s =
      Check(path + ".transition_s", in.transition_s(), Closed(0, kMaxTransition_s, "s"));
  out.loops = static_cast<int>(
      OptionalOr(path + ".loops", in.has_loops(), in.loops(), 1, Closed(1, kMaxLoops, "")));
  return out;
}

Segment TranslateSegment(const v1::Segment& in, const std::string& path) {
  switch (in.kind_case()) {
    case v1::Segment::kStatic:
      return StaticSegment{Duration(path + ".static.duration_s", in.static_().has_duration_s(),
                                    in.static_().duration_s())};
    case v1::Segment::kAccelerate:
      return TranslateAccelerate(in.accelerate(), path + ".accelerate");
    case v1::Segment::kConstantVelocity:
      return ConstantVelocitySegment{Duration(path + ".constant_velocity.duration_s",
                                              in.constant_velocity().has_duration_s(),
                                              in.constant_velocity().duration_s())};
    case v1::Segment::kTurn:
      return TranslateTurn(in.turn(), path + ".turn");
    case v1::Segment::kClimb:
      return TranslateClimb(in.climb(), path + ".climb");
    case v1::Segment::kZigzag:
      return TranslateZigzag(in.zigzag(), path + ".zigzag");
    case v1::Segment::kShipMotion:
      return TranslateShipMotion(in.ship_motion(), path + ".ship_motion");
    case v1::Segment::kFigureEight:
      return TranslateFigureEight(in.figure_eight(), path + ".figure_eight");
    case v1::Segment::KIND_NOT_SET:
      break;
  }
  std::string kinds;
  const auto* oneof = v1::Segment::descriptor()->oneof_decl(0);
  for (int i = 0; i < oneof->field_count(); ++i) {
    kinds += (i == 0 ? "" : ", ") + oneof->field(i)->name();
  }
  throw SpecError(path, "empty segment", "exactly one of " + kinds);
}

std::string RequiredPath(const std::string& path, const std::string& value) {
  if (value.empty()) throw SpecError(path, "", "the path of a readable file");
  return value;
}

MotionSpec TranslateMotion(const v1::Motion& in, const std::filesystem::path& base_dir) {
  const std::string path = "motion";
  const int sources = (in.segments_size() > 0 ? 1 : 0) + (in.has_gnss_ins_sim_file() ? 1 : 0) +
                      (in.has_truth_profile_file() ? 1 : 0);
  if (sources == 0) {
    throw SpecError(
        "motion.segments", "",
        "a list of segments, or motion.gnss_ins_sim_file, or motion.truth_profile_file");
  }
  if (sources > 1) {
    throw SpecError(path,
                    "more than one of segments, gnss_ins_sim_file, truth_profile_file is set; "
                    "allowed: exactly one of them",
                    0);
  }
  MotionSpec out;
  if (in.has_gnss_ins_sim_file()) {
    const v1::GnssInsSimFile& file = in.gnss_ins_sim_file();
    const std::string file_path = path + ".gnss_ins_sim_file";
    if (in.has_initial()) {
      throw SpecError(path + ".initial", "given with motion.gnss_ins_sim_file",
                      "absent (the file's first data line is the initial state)");
    }
    out = ReadGnssInsSimMotion(Resolve(RequiredPath(file_path + ".path", file.path()), base_dir));
    GnssInsSimLimits& limits = out.gnss_ins_sim_limits;
    limits.max_acceleration_m_per_s2 =
        OptionalOr(file_path + ".max_acceleration_m_per_s2", file.has_max_acceleration_m_per_s2(),
                   file.max_acceleration_m_per_s2(), limits.max_acceleration_m_per_s2,
                   Positive(kMaxAcceleration_m_per_s2, "m/s^2"));
    if (file.has_max_angular_acceleration_deg_per_s2()) {
      limits.max_angular_acceleration_rad_per_s2 =
          kDegToRad * Check(file_path + ".max_angular_acceleration_deg_per_s2",
                            file.max_angular_acceleration_deg_per_s2(),
                            Positive(kMaxAngularAcceleration_deg_per_s2, "deg/s^2"));
    }
    if (file.has_max_angular_rate_deg_per_s()) {
      limits.max_angular_rate_rad_per_s =
          kDegToRad * Check(file_path + ".max_angular_rate_deg_per_s",
                            file.max_angular_rate_deg_per_s(),
                            Positive(kMaxAngularRate_deg_per_s, "deg/s"));
    }
  } else if (in.has_truth_profile_file()) {
    if (in.has_initial()) {
      throw SpecError(path + ".initial", "given with motion.truth_profile_file",
                      "absent (the profile's first sample is the initial state)");
    }
    const std::string file =
        RequiredPath(path + ".truth_profile_file.path", in.truth_profile_file().path());
    out = TruthProfileMotion(ReadTruthProfile(Resolve(file, base_dir)));
  } else {
    if (!in.has_initial()) {
      throw SpecError(path + ".initial", "", "an initial state {lat_deg, lon_deg, ...}");
    }
    out.initial = TranslateInitial(in.initial(), path + ".initial");
    for (int i = 0; i < in.segments_size(); ++i) {
      out.segments.push_back(
          TranslateSegment(in.segments(i), fmt::format("{}.segments[{}]", path, i)));
    }
  }
  out.field_path = path;
  out.earth_model = in.earth_model() == v1::Motion::FLAT ? EarthModel::kFlat : EarthModel::kWgs84;
  if (in.has_flat_gravity_m_per_s2()) {
    if (out.earth_model != EarthModel::kFlat) {
      throw SpecError(path + ".flat_gravity_m_per_s2",
                      fmt::format("{} with earth_model WGS84", in.flat_gravity_m_per_s2()),
                      "absent unless earth_model is FLAT");
    }
    out.flat_gravity_m_per_s2 =
        Check(path + ".flat_gravity_m_per_s2", in.flat_gravity_m_per_s2(),
              Closed(kMinFlatGravity_m_per_s2, kMaxFlatGravity_m_per_s2, "m/s^2"));
  }
  out.vehicle.coordinated_turns = in.vehicle().coordinated_turns();
  out.vehicle.pitch_follows_flight_path = in.vehicle().pitch_follows_flight_path();
  return out;
}

}  // namespace

SimulationSpec ToSimulationSpec(const v1::Job& job, const std::filesystem::path& base_dir) {
  SimulationSpec spec;
  spec.rate_hz =
      Required("rate_hz", job.has_rate_hz(), job.rate_hz(), Closed(kMinRate_hz, kMaxRate_hz, "Hz"));
  if (!job.has_motion()) throw SpecError("motion", "", "a motion {initial, segments, ...}");
  spec.motion = TranslateMotion(job.motion(), base_dir);

  const v1::Navigation& navigation = job.navigation();
  spec.mechanization = navigation.mechanization() == v1::Navigation::SEED000
                           ? MechanizationKind::kSeed000
                           : MechanizationKind::kNed;
  spec.ned.vertical = navigation.ned().vertical_channel() == v1::NedOptions::TRUTH_HEIGHT
                          ? VerticalChannel::kTruthHeight
                          : VerticalChannel::kFree;
  spec.ned.coning_sculling =
      !navigation.ned().has_coning_sculling() || navigation.ned().coning_sculling();
  const v1::Seed000Options& seed000 = navigation.seed000();
  spec.seed000.static_period_s = OptionalOr(
      "navigation.seed000.static_period_s", seed000.has_static_period_s(),
      seed000.static_period_s(), spec.seed000.static_period_s, Positive(kMaxDuration_s, "s"));
  Range cutoff = Closed(0.0, spec.rate_hz / 2, "Hz");
  cutoff.hi_open = true;
  cutoff.note = "(rate_hz / 2; 0 = no filter)";
  spec.seed000.lowpass_cutoff_hz =
      Check("navigation.seed000.lowpass_cutoff_hz", seed000.lowpass_cutoff_hz(), cutoff);
  return spec;
}

std::vector<CommandPath> JobInputFiles(const v1::Job& job, const std::filesystem::path& base_dir) {
  std::vector<CommandPath> out;
  const v1::Motion& motion = job.motion();
  if (motion.has_gnss_ins_sim_file() && !motion.gnss_ins_sim_file().path().empty()) {
    out.push_back(
        {Resolve(motion.gnss_ins_sim_file().path(), base_dir), "motion.gnss_ins_sim_file.path"});
  }
  if (motion.has_truth_profile_file() && !motion.truth_profile_file().path().empty()) {
    out.push_back(
        {Resolve(motion.truth_profile_file().path(), base_dir), "motion.truth_profile_file.path"});
  }
  return out;
}

SimulationSpec PlanSimulationSpec(const JobFile& file) {
  SimulationSpec spec = ToSimulationSpec(file.job, file.base_dir);
  TrajectoryGenerator planned(spec.motion, spec.rate_hz);
  if (spec.mechanization == MechanizationKind::kSeed000) {
    // Seed 000's alignment averages the IMU over the static period: the vehicle must be at rest
    // at every sample of it, and the motion must last at least that long.
    const double period_s = spec.seed000.static_period_s;
    double at_rest_until_s = planned.duration_s();
    const int64_t samples = static_cast<int64_t>(std::floor(period_s * spec.rate_hz + 1e-9));
    for (int64_t k = 0; k <= samples; ++k) {
      const double t_s = static_cast<double>(k) / spec.rate_hz;
      if (!planned.IsStaticAt(t_s)) {
        at_rest_until_s = static_cast<double>(k - 1) / spec.rate_hz;
        break;
      }
    }
    const std::string path = "navigation.seed000.static_period_s";
    if (at_rest_until_s <= 0.0) {
      throw SpecError(path, fmt::format("{}", period_s),
                      "a motion that starts at rest (SEED000 aligns during its static period)");
    }
    if (period_s > at_rest_until_s) {
      Range range = Positive(at_rest_until_s, "s");
      range.note = "(the vehicle is at rest only until then)";
      throw SpecError(path, fmt::format("{}", period_s), Allowed(path, range));
    }
  }
  return spec;
}

}  // namespace driftlab::app
