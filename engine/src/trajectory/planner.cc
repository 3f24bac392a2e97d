// The planner's native segments (static, constant velocity, accelerate, turn, climb, zigzag,
// ship motion, figure eight) as TrackPieces; see trajectory.h for each segment's model.
#include "trajectory/planner.h"

#include <cmath>
#include <string>
#include <variant>

#include "driftlab/elementary.h"
#include "driftlab/units.h"
#include "trajectory/motion_checks.h"

namespace driftlab::trajectory_detail {

void Planner::Plan() {
  for (size_t i = 0; i < motion_.segments.size(); ++i) {
    const std::string path = motion_.field_path + ".segments[" + std::to_string(i) + "]";
    if (!std::holds_alternative<GnssInsSimCommand>(motion_.segments[i])) FinishExecutor(false);
    const auto* command = std::get_if<GnssInsSimCommand>(&motion_.segments[i]);
    origins_.push_back(SegmentOrigin{
        exec_.active ? exec_.t_start + static_cast<double>(exec_.steps) * dt_s_ : state_.t,
        command != nullptr && !command->source.empty() ? command->source : path});
    std::visit([&](const auto& segment) { PlanSegment(segment, path); }, motion_.segments[i]);
  }
  FinishExecutor(true);
}

void Planner::TrackStart(double* V, double* chi, double* v_down) const {
  if (state_.has_track) {
    *V = state_.V;
    *chi = state_.chi;
    *v_down = state_.v_down;
    return;
  }
  *V = math::Hypot(state_.v_eb_n.x(), state_.v_eb_n.y());
  *chi = *V > 0.0 ? math::Atan2(state_.v_eb_n.y(), state_.v_eb_n.x()) : state_.euler.yaw_rad;
  *v_down = state_.v_eb_n.z();
}

TrackPiece Planner::TrackTemplate(double V, double chi, double v_down, double dchi0) const {
  TrackPiece p;
  p.speed = Ramp::Constant(V);
  p.chi0 = chi;
  p.v_down = Ramp::Constant(v_down);
  p.pitch_follows = motion_.vehicle.pitch_follows_flight_path;
  p.coordinated = motion_.vehicle.coordinated_turns;
  p.g_m_per_s2 = g_m_per_s2_;
  p.yaw_offset = state_.euler.yaw_rad - chi;
  p.pitch_offset = state_.euler.pitch_rad - (p.pitch_follows ? math::Atan2(-v_down, V) : 0.0);
  p.roll_offset =
      state_.euler.roll_rad - (p.coordinated ? math::Atan(V * dchi0 / g_m_per_s2_) : 0.0);
  return p;
}

void Planner::Add(double duration, const TrackPiece& p) {
  if (!(duration > 0.0)) return;
  Piece piece;
  piece.t0 = state_.t;
  piece.t1 = state_.t + duration;
  piece.max_substep_s = p.Uniform() ? kUniformSubstep_s : kDynamicSubstep_s;
  piece.kin = p;
  pieces_->push_back(piece);
  state_.t = piece.t1;
  const Kinematics end = p.Evaluate(duration, nullptr);
  state_.euler = end.euler;
  state_.v_eb_n = end.v_eb_n;
  state_.has_track = true;
  state_.has_body = false;
  state_.V = p.speed.Value(duration);
  state_.chi = p.chi0 + (p.chi1 + p.chi2 * duration) * duration;
  if (p.zigzag.amplitude != 0.0) {
    state_.chi += p.zigzag.amplitude * math::Sin(p.zigzag.omega * duration + p.zigzag.phase);
  }
  state_.v_down = p.v_down.Value(duration);
}

void Planner::CheckFlightPath(const std::string& path, double V_min, double v_down) const {
  if (motion_.vehicle.pitch_follows_flight_path && V_min == 0.0 && v_down != 0.0) {
    RejectText(path, "vertical speed " + CompactText(-v_down) +
                         " m/s at zero ground speed; allowed: ground speed > 0 whenever the "
                         "vertical speed is non-zero (vehicle.pitch_follows_flight_path: the "
                         "flight-path angle would jump to +-90 deg)");
  }
}

void Planner::PlanSegment(const StaticSegment& s, const std::string& path) {
  CheckDuration(path + ".static.duration_s", s.duration_s);
  const double speed = state_.v_eb_n.norm();
  if (speed != 0.0) {
    RejectText(path + ".static",
               "speed " + CompactText(speed) +
                   " m/s at the segment's start is not allowed; allowed: 0 (a static segment "
                   "must start at rest)");
  }
  double V, chi, vD;
  TrackStart(&V, &chi, &vD);
  Add(s.duration_s, TrackTemplate(0.0, chi, 0.0, 0.0));
}

void Planner::PlanSegment(const ConstantVelocitySegment& s, const std::string& path) {
  CheckDuration(path + ".constant_velocity.duration_s", s.duration_s);
  double V, chi, vD;
  TrackStart(&V, &chi, &vD);
  CheckFlightPath(path + ".constant_velocity", V, vD);
  Add(s.duration_s, TrackTemplate(V, chi, vD, 0.0));
}

void Planner::PlanSegment(const AccelerateSegment& s, const std::string& path) {
  const std::string base = path + ".accelerate";
  CheckPositive(base + ".acceleration_m_per_s2", s.acceleration_m_per_s2, 1000.0, " m/s^2");
  if (s.target_speed_m_per_s.has_value() == s.duration_s.has_value()) {
    RejectText(base, std::string(s.duration_s ? "both" : "neither") +
                         " of target_speed_m_per_s and duration_s given; allowed: exactly one");
  }
  double V, chi, vD;
  TrackStart(&V, &chi, &vD);
  double V_end, T;
  if (s.target_speed_m_per_s) {
    const double target = *s.target_speed_m_per_s;
    CheckNonNegative(base + ".target_speed_m_per_s", target, kMaxSpeed_m_per_s, " m/s");
    if (s.decelerate) {
      RejectText(base + ".decelerate",
                 "true with target_speed_m_per_s; allowed: only with duration_s (the target "
                 "gives the sign)");
    }
    if (target == V) {
      Reject(base + ".target_speed_m_per_s", target,
             "a speed different from the current ground speed " + CompactText(V) + " m/s");
    }
    V_end = target;
    T = std::abs(target - V) / s.acceleration_m_per_s2;
    if (!(T <= kMaxDuration_s)) {
      Reject(base + ".target_speed_m_per_s", target,
             "reachable within " + CompactText(kMaxDuration_s) + " s at the given acceleration");
    }
  } else {
    T = *s.duration_s;
    CheckDuration(base + ".duration_s", T);
    const double sign = s.decelerate ? -1.0 : 1.0;
    V_end = V + sign * s.acceleration_m_per_s2 * T;
    if (V_end < 0.0) {
      Reject(base + ".duration_s", T,
             "0 < duration_s <= " + CompactText(V / s.acceleration_m_per_s2) +
                 " s (decelerating from " + CompactText(V) + " m/s must not reverse)");
    }
    if (V_end > kMaxSpeed_m_per_s) {
      Reject(base + ".duration_s", T,
             "a duration that keeps the speed <= " + CompactText(kMaxSpeed_m_per_s) + " m/s");
    }
  }
  CheckFlightPath(base, std::min(V, V_end), vD);
  TrackPiece p = TrackTemplate(V, chi, vD, 0.0);
  p.speed = Ramp::Between(V, V_end, T);
  Add(T, p);
}

void Planner::AddTurn(double omega, double transition_s, double hold_s) {
  double V, chi, vD;
  TrackStart(&V, &chi, &vD);
  const TrackPiece shape = TrackTemplate(V, chi, vD, 0.0);
  const double Tr = transition_s;
  auto piece = [&](double chi0, double chi1, double chi2) {
    TrackPiece p = shape;
    p.chi0 = chi0;
    p.chi1 = chi1;
    p.chi2 = chi2;
    return p;
  };
  if (Tr > 0.0) Add(Tr, piece(chi, 0.0, omega / (2.0 * Tr)));
  if (hold_s > 0.0) Add(hold_s, piece(state_.chi, omega, 0.0));
  if (Tr > 0.0) Add(Tr, piece(state_.chi, omega, -omega / (2.0 * Tr)));
}

double Planner::TurnRate(const std::string& base, const TurnRateSpec& turn, double V) const {
  double omega;
  if (turn.rate_rad_per_s) {
    omega = *turn.rate_rad_per_s;
    if (turn.either_sign) {
      if (!(std::isfinite(omega) && omega != 0.0 && std::abs(omega) <= kMaxTurnRate_rad_per_s)) {
        Reject(base + ".rate_deg_per_s", omega * kRadToDeg,
               "-720 <= rate_deg_per_s <= 720 deg/s, not 0");
      }
    } else if (!(omega > 0.0 && omega <= kMaxTurnRate_rad_per_s)) {
      Reject(base + ".rate_deg_per_s", omega * kRadToDeg, "0 < rate_deg_per_s <= 720 deg/s");
    }
  } else {
    const double radius_m = *turn.radius_m;
    CheckPositive(base + ".radius_m", radius_m, 1.0e7, " m");
    if (!(V > 0.0)) {
      RejectText(base + ".radius_m",
                 std::string("given at ground speed 0; allowed: ") + turn.radius_at_rest_allowed);
    }
    omega = (turn.right ? 1.0 : -1.0) * V / radius_m;
    if (!(V / radius_m <= kMaxTurnRate_rad_per_s)) {
      Reject(base + ".radius_m", radius_m,
             "radius_m >= " + CompactText(V / kMaxTurnRate_rad_per_s) + " m at the ground speed " +
                 CompactText(V) + " m/s (a turn rate of at most " +
                 CompactText(kMaxTurnRate_rad_per_s * kRadToDeg) +
                 " deg/s, as for rate_deg_per_s)");
    }
  }
  const double Tr = turn.transition_s;
  CheckNonNegative(base + ".transition_s", Tr, kMaxDuration_s / 2.0, " s");
  if (motion_.vehicle.coordinated_turns && Tr == 0.0) {
    Reject(base + ".transition_s", Tr,
           "transition_s > 0 with vehicle.coordinated_turns (the bank angle must be continuous)");
  }
  return omega;
}

void Planner::PlanSegment(const TurnSegment& s, const std::string& path) {
  const std::string base = path + ".turn";
  if (s.rate_rad_per_s.has_value() == s.radius_m.has_value()) {
    RejectText(base, std::string(s.rate_rad_per_s ? "both" : "neither") +
                         " of rate_deg_per_s and radius_m given; allowed: exactly one");
  }
  if (s.angle_rad.has_value() == s.duration_s.has_value()) {
    RejectText(base, std::string(s.angle_rad ? "both" : "neither") +
                         " of angle_deg and duration_s given; allowed: exactly one");
  }
  double V, chi, vD;
  TrackStart(&V, &chi, &vD);
  const double omega =
      TurnRate(base,
               {s.rate_rad_per_s, s.radius_m, s.right, /*either_sign=*/true, s.transition_s,
                "a turn by radius needs speed > 0 (give rate_deg_per_s to turn on the spot)"},
               V);
  const double Tr = s.transition_s;
  double hold;
  if (s.angle_rad) {
    const double angle = *s.angle_rad;
    if (!(angle > 0.0 && angle <= 200.0 * M_PI)) {
      Reject(base + ".angle_deg", angle * kRadToDeg, "0 < angle_deg <= 36000 deg");
    }
    hold = angle / std::abs(omega) - Tr;
    if (hold < 0.0) {
      Reject(
          base + ".angle_deg", angle * kRadToDeg,
          "angle_deg >= |rate| x transition_s = " + CompactText(std::abs(omega) * Tr * kRadToDeg) +
              " deg (the ramps alone turn that much)");
    }
  } else {
    CheckDuration(base + ".duration_s", *s.duration_s);
    hold = *s.duration_s - 2.0 * Tr;
    if (hold < 0.0) {
      Reject(base + ".duration_s", *s.duration_s,
             "duration_s >= 2 x transition_s = " + CompactText(2.0 * Tr) + " s");
    }
  }
  CheckFlightPath(base, V, vD);
  AddTurn(omega, Tr, hold);
}

void Planner::PlanSegment(const ClimbSegment& s, const std::string& path) {
  const std::string base = path + ".climb";
  const double c = s.climb_rate_m_per_s;
  if (!(std::isfinite(c) && c != 0.0 && std::abs(c) <= kMaxSpeed_m_per_s)) {
    Reject(base + ".climb_rate_m_per_s", c,
           "-" + CompactText(kMaxSpeed_m_per_s) +
               " <= climb_rate_m_per_s <= " + CompactText(kMaxSpeed_m_per_s) + " m/s, not 0");
  }
  const double a = s.vertical_acceleration_m_per_s2;
  CheckPositive(base + ".vertical_acceleration_m_per_s2", a, 1000.0, " m/s^2");
  if (s.height_change_m.has_value() == s.duration_s.has_value()) {
    RejectText(base, std::string(s.duration_s ? "both" : "neither") +
                         " of height_change_m and duration_s given; allowed: exactly one");
  }
  double V, chi, vD;
  TrackStart(&V, &chi, &vD);
  if (motion_.vehicle.pitch_follows_flight_path && V == 0.0) {
    RejectText(base,
               "climb at ground speed 0 with vehicle.pitch_follows_flight_path; allowed: "
               "ground speed > 0 (the flight-path angle would jump to +-90 deg)");
  }
  const double v0 = -vD;  // vertical speed up at the start
  const double Tr = std::abs(c - v0) / a;
  double hold;
  if (s.height_change_m) {
    const double dh = *s.height_change_m;
    if (!(std::isfinite(dh) && dh != 0.0 && (dh > 0.0) == (c > 0.0))) {
      Reject(base + ".height_change_m", dh,
             "a finite non-zero height change with the sign of climb_rate_m_per_s (" +
                 CompactText(c) + " m/s)");
    }
    // Height change = (v0 + c) Tr  (two ramps) + c hold.
    hold = (dh - (v0 + c) * Tr) / c;
    if (hold < 0.0) {
      Reject(base + ".height_change_m", dh,
             "|height_change_m| >= " + CompactText(std::abs((v0 + c) * Tr)) +
                 " m (the height changed during the two vertical-speed ramps)");
    }
  } else {
    CheckDuration(base + ".duration_s", *s.duration_s);
    hold = *s.duration_s - 2.0 * Tr;
    if (hold < 0.0) {
      Reject(base + ".duration_s", *s.duration_s,
             "duration_s >= 2 |climb_rate - vertical speed| / vertical_acceleration = " +
                 CompactText(2.0 * Tr) + " s");
    }
  }
  const TrackPiece shape = TrackTemplate(V, chi, vD, 0.0);
  auto piece = [&](double v_down_start, double v_down_end, double duration) {
    TrackPiece p = shape;
    p.v_down = duration > 0.0 && v_down_start != v_down_end
                   ? Ramp::Between(v_down_start, v_down_end, duration)
                   : Ramp::Constant(v_down_start);
    return p;
  };
  if (Tr > 0.0) Add(Tr, piece(-v0, -c, Tr));
  if (hold > 0.0) Add(hold, piece(-c, -c, hold));
  if (Tr > 0.0) Add(Tr, piece(-c, -v0, Tr));
}

void Planner::PlanSegment(const ZigzagSegment& s, const std::string& path) {
  const std::string base = path + ".zigzag";
  CheckPositive(base + ".amplitude_m", s.amplitude_m, 1.0e6, " m");
  CheckPositive(base + ".period_s", s.period_s, kMaxDuration_s, " s");
  CheckSampledPeriod(base + ".period_s", s.period_s);
  CheckDuration(base + ".duration_s", s.duration_s);
  if (motion_.vehicle.coordinated_turns) {
    RejectText(base,
               "zigzag with vehicle.coordinated_turns is not allowed: its turn rate starts "
               "at 2 pi A / period, so the bank angle would jump; allowed: "
               "coordinated_turns false, or turn segments with transition_s > 0");
  }
  double V, chi, vD;
  TrackStart(&V, &chi, &vD);
  if (!(V > 0.0)) {
    RejectText(base,
               "at ground speed 0; allowed: ground speed > 0 (the heading amplitude is "
               "2 pi amplitude_m / (speed x period_s))");
  }
  // Lateral half-excursion = V A period / (2 pi)  =>  A = 2 pi amplitude / (V period).
  const double A = 2.0 * M_PI * s.amplitude_m / (V * s.period_s);
  if (A > 0.5 * M_PI) {
    Reject(base + ".amplitude_m", s.amplitude_m,
           "0 < amplitude_m <= speed x period_s / 4 = " + CompactText(V * s.period_s / 4.0) +
               " m (heading amplitude at most 90 deg)");
  }
  CheckFlightPath(base, V, vD);
  TrackPiece p = TrackTemplate(V, chi, vD, 0.0);
  p.zigzag = Wave{A, 2.0 * M_PI / s.period_s, 0.0};
  Add(s.duration_s, p);
}

void Planner::CheckSampledPeriod(const std::string& field, double period_s) const {
  const double min_period_s = kMinSamplesPerPeriod * dt_s_;
  if (period_s < min_period_s) {
    Reject(field, period_s,
           field.substr(field.rfind('.') + 1) + " >= " + CompactText(min_period_s) + " s (" +
               CompactText(kMinSamplesPerPeriod) + " output intervals at rate_hz " +
               CompactText(rate_hz_) + " Hz; the Nyquist limit is 2)");
  }
}

void Planner::PlanSegment(const ShipMotionSegment& s, const std::string& path) {
  const std::string base = path + ".ship_motion";
  CheckDuration(base + ".duration_s", s.duration_s);
  struct Component {
    const char* name;
    double amplitude, period, phase, max_amplitude;
    const char* unit;
    double scale;
  };
  const Component components[4] = {
      {"roll", s.roll_amplitude_rad, s.roll_period_s, s.roll_phase_rad, M_PI / 2, " deg",
       kRadToDeg},
      {"pitch", s.pitch_amplitude_rad, s.pitch_period_s, s.pitch_phase_rad, M_PI / 2, " deg",
       kRadToDeg},
      {"yaw", s.yaw_amplitude_rad, s.yaw_period_s, s.yaw_phase_rad, M_PI, " deg", kRadToDeg},
      {"heave", s.heave_amplitude_m, s.heave_period_s, s.heave_phase_rad, 1000.0, " m", 1.0}};
  double longest = 0.0, longest_any = 0.0;
  for (const Component& c : components) {
    const std::string name = base + "." + c.name;
    const std::string amplitude_field = name + (c.scale == 1.0 ? "_amplitude_m" : "_amplitude_deg");
    if (!(c.amplitude >= 0.0 && c.amplitude <= c.max_amplitude)) {
      Reject(amplitude_field, c.amplitude * c.scale,
             "0 <= " + amplitude_field.substr(amplitude_field.rfind('.') + 1) +
                 " <= " + CompactText(c.max_amplitude * c.scale) + c.unit);
    }
    CheckPositive(name + "_period_s", c.period, kMaxDuration_s, " s");
    if (c.amplitude > 0.0) CheckSampledPeriod(name + "_period_s", c.period);
    if (!std::isfinite(c.phase)) Reject(name + "_phase_deg", c.phase * kRadToDeg, "finite");
    longest_any = std::max(longest_any, c.period);
    if (c.amplitude > 0.0) longest = std::max(longest, c.period);
  }
  if (longest == 0.0) longest = longest_any;
  CheckNonNegative(base + ".ramp_s", s.ramp_s, kMaxDuration_s, " s");
  const double R = s.ramp_s > 0.0 ? s.ramp_s : longest;
  if (R > 0.5 * s.duration_s) {
    Reject(
        base + ".ramp_s", s.ramp_s,
        "ramp_s <= duration_s / 2 = " + CompactText(0.5 * s.duration_s) + " s" +
            (s.ramp_s > 0.0 ? std::string()
                            : " (ramp_s = 0 means the longest period, " + CompactText(R) + " s)"));
  }
  double V, chi, vD;
  TrackStart(&V, &chi, &vD);
  CheckFlightPath(base, V, vD);
  const TrackPiece base_piece = TrackTemplate(V, chi, vD, 0.0);
  const PlanState start = state_;
  auto wave = [](double amplitude, double period, double phase, double s0) {
    const double omega = 2.0 * M_PI / period;
    return Wave{amplitude, omega, phase + omega * s0};
  };
  // Pieces: raised-cosine fade-in [0, R], full amplitude, fade-out [T - R, T].
  const double T = s.duration_s;
  const double starts[3] = {0.0, R, T - R};
  const double lengths[3] = {R, T - 2.0 * R, R};
  for (int i = 0; i < 3; ++i) {
    if (!(lengths[i] > 0.0)) continue;
    TrackPiece p = base_piece;
    p.ship = true;
    const double s0 = starts[i];
    p.roll_wave = wave(s.roll_amplitude_rad, s.roll_period_s, s.roll_phase_rad, s0);
    p.pitch_wave = wave(s.pitch_amplitude_rad, s.pitch_period_s, s.pitch_phase_rad, s0);
    p.yaw_wave = wave(s.yaw_amplitude_rad, s.yaw_period_s, s.yaw_phase_rad, s0);
    p.heave_wave = wave(s.heave_amplitude_m, s.heave_period_s, s.heave_phase_rad, s0);
    if (i == 0) {  // e = (1 - cos(pi s / R)) / 2
      p.envelope_mean = 0.5;
      p.envelope_amplitude = -0.5;
      p.envelope_omega = M_PI / R;
    } else if (i == 1) {
      p.envelope_mean = 1.0;
      p.envelope_amplitude = 0.0;
    } else {  // e = (1 + cos(pi s / R)) / 2
      p.envelope_mean = 0.5;
      p.envelope_amplitude = 0.5;
      p.envelope_omega = M_PI / R;
    }
    Add(lengths[i], p);
  }
  // The segment ends with the envelope at zero: back on the base motion exactly.
  state_.euler = start.euler;
  state_.v_eb_n = Vector3d(V * math::Cos(chi), V * math::Sin(chi), vD);
  state_.has_track = true;
  state_.V = V;
  state_.chi = chi;
  state_.v_down = vD;
}

void Planner::PlanSegment(const FigureEightSegment& s, const std::string& path) {
  const std::string base = path + ".figure_eight";
  if (s.radius_m.has_value() == s.rate_rad_per_s.has_value()) {
    RejectText(base, std::string(s.radius_m ? "both" : "neither") +
                         " of radius_m and rate_deg_per_s given; allowed: exactly one");
  }
  if (!(s.loops >= 1 && s.loops <= 100000)) {
    Reject(base + ".loops", s.loops, "1 <= loops <= 100000");
  }
  double V, chi, vD;
  TrackStart(&V, &chi, &vD);
  const double omega = TurnRate(base,
                                {s.rate_rad_per_s, s.radius_m, /*right=*/true,
                                 /*either_sign=*/false, s.transition_s, "speed > 0"},
                                V);
  const double Tr = s.transition_s;
  const double hold = 2.0 * M_PI / omega - Tr;
  if (hold < 0.0) {
    Reject(base + ".transition_s", Tr,
           "transition_s <= 2 pi / rate = " + CompactText(2.0 * M_PI / omega) + " s");
  }
  CheckFlightPath(base, V, vD);
  for (int loop = 0; loop < s.loops; ++loop) {
    AddTurn(omega, Tr, hold);
    AddTurn(-omega, Tr, hold);
  }
}

}  // namespace driftlab::trajectory_detail
