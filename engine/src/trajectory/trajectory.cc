// Trajectory generator: plans a motion into smooth kinematic pieces, then integrates the truth and
// the ideal IMU increments. See trajectory.h for the physics; the numerics are:
//  - every piece evaluates, at local time s, the Euler angles, their rates, v_eb_n and dv_eb_n/dt
//  in
//    closed form; pieces are C^infinity inside, so the only kinks are piece boundaries;
//  - position (L, lambda, h) is integrated from v_eb_n with the classical RK4 on sub-steps of at
//    most 0.01 s (1 s for pieces of uniform motion, where the integrands vary only through the
//    position, on time scales R / v >= 6000 s), split at every piece boundary; Groves (2.111);
//  - the increments are 4-point Gauss-Legendre quadratures of omega_ib_b and f_ib_b on the same
//    sub-steps (exact for polynomials of degree 7); the position at the quadrature nodes is the
//    cubic Hermite interpolant of the sub-step's end points and rates (error O(h^4) of metres).
#include "driftlab/trajectory.h"

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "driftlab/elementary.h"
#include "driftlab/spec_error.h"
#include "driftlab/units.h"

namespace driftlab {

namespace {

constexpr double kDynamicSubstep_s = 0.01;
constexpr double kUniformSubstep_s = 1.0;
// WGS-84 navigation is limited to |L| < 89.9 deg: tan L and 1 / cos L in the transport rate and the
// longitude rate grow without bound at the pole.
constexpr double kMaxWgs84Latitude_deg = 89.9;
// Height range of the normal-gravity model's free-air expansion (earth.h) with margin.
constexpr double kMinHeight_m = -1.0e4;
constexpr double kMaxHeight_m = 1.0e5;
constexpr double kMaxSpeed_m_per_s = 1.0e4;

// Shortest text that parses back to the same double ("nan", "inf" for the non-finite).
std::string CompactText(double x) {
  if (std::isnan(x)) return "nan";
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  if (x == std::trunc(x) && std::abs(x) < 1e15) return std::to_string(static_cast<int64_t>(x));
  char buffer[40];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), x);
  return std::string(buffer, result.ptr);
}

[[noreturn]] void Reject(const std::string& field, double value, const std::string& allowed) {
  throw SpecError(field, CompactText(value), allowed);
}
[[noreturn]] void RejectText(const std::string& field, const std::string& message) {
  throw SpecError(field, message, 0);
}

void CheckFinite(const std::string& field, double value) {
  if (!std::isfinite(value)) Reject(field, value, "a finite number");
}
// 0 < value <= hi.
void CheckPositive(const std::string& field, double value, double hi, const std::string& unit) {
  if (!(value > 0.0 && value <= hi)) {
    Reject(field, value,
           "0 < " + field.substr(field.rfind('.') + 1) + " <= " + CompactText(hi) + unit);
  }
}
void CheckDuration(const std::string& field, double value) {
  CheckPositive(field, value, kMaxDuration_s, " s");
}
// 0 <= value <= hi.
void CheckNonNegative(const std::string& field, double value, double hi, const std::string& unit) {
  if (!(value >= 0.0 && value <= hi)) {
    Reject(field, value,
           "0 <= " + field.substr(field.rfind('.') + 1) + " <= " + CompactText(hi) + unit);
  }
}

// ---- Kinematic pieces ---------------------------------------------------------------------------

// The vehicle's kinematics at one instant.
struct Kinematics {
  EulerAngles euler;                        // [rad]
  Vector3d euler_rates = Vector3d::Zero();  // d(roll, pitch, yaw)/dt [rad/s]
  Vector3d v_eb_n = Vector3d::Zero();       // [m/s]
  Vector3d a_eb_n = Vector3d::Zero();       // dv_eb_n/dt [m/s^2]
};

// Linear function from `start` to `end` over [0, duration], evaluated from the nearer end so that
// both end values are exact (a segment that stops leaves the speed exactly zero).
struct Ramp {
  double start = 0.0, end = 0.0, slope = 0.0, duration = 0.0;
  static Ramp Constant(double v) { return Ramp{v, v, 0.0, 0.0}; }
  static Ramp Between(double a, double b, double duration_s) {
    return Ramp{a, b, (b - a) / duration_s, duration_s};
  }
  double Value(double s) const {
    return s <= 0.5 * duration ? start + slope * s : end - slope * (duration - s);
  }
};

// sin and cos of the angles the generator evaluates at every quadrature point - the track angle
// and the three Euler angles - remembered per slot with the argument's bit pattern: along a
// straight or level segment they stay the same for thousands of points, and std::sin / std::cos
// of the same argument give the same values, so the truth is the same bits as without it. One
// per generator (TrajectoryGenerator::Next's path only; the const queries pass none).
class TrigMemo {
 public:
  enum Slot {
    kTrack = 0,
    kRoll = 1,
    kPitch = 2,
    kYaw = 3,
    kHalfRoll = 4,
    kHalfPitch = 5,
    kHalfYaw = 6
  };
  void SinCos(Slot slot, double x, double* s, double* c) {
    Entry& e = entries_[slot];
    const uint64_t bits = std::bit_cast<uint64_t>(x);
    if (!e.valid || e.bits != bits) {
      math::SinCos(x, &e.s, &e.c);
      e.bits = bits;
      e.valid = true;
    }
    *s = e.s;
    *c = e.c;
  }

 private:
  struct Entry {
    uint64_t bits = 0;
    double s = 0.0, c = 1.0;
    bool valid = false;
  };
  Entry entries_[7];
};

// sin and cos of x, through `memo`'s slot when there is one.
void SinCosVia(TrigMemo* memo, TrigMemo::Slot slot, double x, double* s, double* c) {
  if (memo != nullptr) {
    memo->SinCos(slot, x, s, c);
  } else {
    math::SinCos(x, s, c);
  }
}

EulerTrig EulerTrigVia(TrigMemo* memo, const EulerAngles& e) {
  if (memo == nullptr) return EulerTrig(e);
  double sp, cp, st, ct, ss, cs;
  memo->SinCos(TrigMemo::kRoll, e.roll_rad, &sp, &cp);
  memo->SinCos(TrigMemo::kPitch, e.pitch_rad, &st, &ct);
  memo->SinCos(TrigMemo::kYaw, e.yaw_rad, &ss, &cs);
  return EulerTrig(sp, cp, st, ct, ss, cs);
}

// A sin(omega s + phase) and its first two derivatives.
struct Wave {
  double amplitude = 0.0, omega = 0.0, phase = 0.0;
  void Eval(double s, double* x, double* dx, double* ddx) const {
    if (amplitude == 0.0) {
      *x = *dx = *ddx = 0.0;
      return;
    }
    const double sn = math::Sin(omega * s + phase), cs = math::Cos(omega * s + phase);
    *x = amplitude * sn;
    *dx = amplitude * omega * cs;
    *ddx = -amplitude * omega * omega * sn;
  }
};

// Parametric vehicle model (static, accelerate, constant velocity, turn, climb, zigzag, figure
// eight, ship motion): ground speed V, track angle chi, down velocity v_D;
//   v_eb_n = [V cos chi, V sin chi, v_D]
//   yaw   = yaw_offset + chi
//   pitch = pitch_offset + atan2(-v_D, V)          if the pitch follows the flight path
//   roll  = roll_offset + atan(V chi' / g)         in coordinated turns (zero lateral force)
// The offsets are fixed per segment so that the attitude is continuous at its start. Ship motion
// adds envelope-weighted sinusoids to roll, pitch, yaw and a heave displacement (positive up).
struct TrackPiece {
  Ramp speed;                                 // V [m/s]
  double chi0 = 0.0, chi1 = 0.0, chi2 = 0.0;  // chi = chi0 + chi1 s + chi2 s^2 [rad]
  Wave zigzag;                                // + A sin(omega s)
  Ramp v_down;                                // v_D [m/s]
  double yaw_offset = 0.0, pitch_offset = 0.0, roll_offset = 0.0;
  bool pitch_follows = false;
  bool coordinated = false;
  double g_m_per_s2 = 9.8;
  bool ship = false;
  double envelope_mean = 1.0, envelope_amplitude = 0.0, envelope_omega = 0.0;
  Wave roll_wave, pitch_wave, yaw_wave, heave_wave;

  bool Uniform() const {
    return speed.slope == 0.0 && v_down.slope == 0.0 && chi1 == 0.0 && chi2 == 0.0 &&
           zigzag.amplitude == 0.0 && !ship;
  }

  Kinematics Evaluate(double s, TrigMemo* memo) const {
    Kinematics k;
    const double V = speed.Value(s), dV = speed.slope;
    double zx, zdx, zddx;
    zigzag.Eval(s, &zx, &zdx, &zddx);
    const double chi = chi0 + (chi1 + chi2 * s) * s + zx;
    const double dchi = chi1 + 2.0 * chi2 * s + zdx;
    const double ddchi = 2.0 * chi2 + zddx;
    double vD = v_down.Value(s), dvD = v_down.slope;
    double sn, c;
    SinCosVia(memo, TrigMemo::kTrack, chi, &sn, &c);

    double pitch = pitch_offset, dpitch = 0.0;
    if (pitch_follows) {
      // gamma = atan2(u, V), u = -v_D:  d gamma/dt = (V u' - u V') / (V^2 + u^2).
      const double u = -vD, du = -dvD, r2 = V * V + u * u;
      pitch += math::Atan2(u, V);
      if (r2 > 0.0) dpitch = (V * du - u * dV) / r2;
    }
    double roll = roll_offset, droll = 0.0;
    if (coordinated) {
      // phi = atan(V chi' / g):  d phi/dt = (V' chi' + V chi'') / g / (1 + (V chi' / g)^2).
      const double x = V * dchi / g_m_per_s2;
      roll += math::Atan(x);
      droll = (dV * dchi + V * ddchi) / g_m_per_s2 / (1.0 + x * x);
    }
    double yaw = yaw_offset + chi, dyaw = dchi;

    double dv_up = 0.0;  // heave: vertical velocity and acceleration added (up positive)
    double ddv_up = 0.0;
    if (ship) {
      // Envelope e = mean + amplitude cos(omega s) (raised-cosine ramps, 1 in between).
      const double ec = math::Cos(envelope_omega * s), es = math::Sin(envelope_omega * s);
      const double e = envelope_mean + envelope_amplitude * ec;
      const double de = -envelope_amplitude * envelope_omega * es;
      const double dde = -envelope_amplitude * envelope_omega * envelope_omega * ec;
      double x, dx, ddx;
      roll_wave.Eval(s, &x, &dx, &ddx);
      roll += e * x;
      droll += de * x + e * dx;
      pitch_wave.Eval(s, &x, &dx, &ddx);
      pitch += e * x;
      dpitch += de * x + e * dx;
      yaw_wave.Eval(s, &x, &dx, &ddx);
      yaw += e * x;
      dyaw += de * x + e * dx;
      // Heave displacement z = e x: v_up = e' x + e x', a_up = e'' x + 2 e' x' + e x''.
      heave_wave.Eval(s, &x, &dx, &ddx);
      dv_up = de * x + e * dx;
      ddv_up = dde * x + 2.0 * de * dx + e * ddx;
    }
    k.euler = EulerAngles{roll, pitch, yaw};
    k.euler_rates = Vector3d(droll, dpitch, dyaw);
    k.v_eb_n = Vector3d(V * c, V * sn, vD - dv_up);
    k.a_eb_n = Vector3d(dV * c - V * dchi * sn, dV * sn + V * dchi * c, dvD - ddv_up);
    return k;
  }
};

// gnss-ins-sim model: Euler angles (roll, pitch, yaw) = e0 + e1 s + e2 s^2 and body velocity
// v_b = linear from b_start to b_end; v_eb_n = C_b_n v_b and, since dC_b_n/dt = C_b_n [omega_nb_b
// x],
//   dv_eb_n/dt = C_b_n (dv_b/dt + omega_nb_b x v_b).
struct BodyPiece {
  Vector3d e0 = Vector3d::Zero(), e1 = Vector3d::Zero(), e2 = Vector3d::Zero();
  Vector3d b_start = Vector3d::Zero(), b_end = Vector3d::Zero(), b_slope = Vector3d::Zero();
  double duration = 0.0;

  bool Uniform() const { return e1.isZero(0.0) && e2.isZero(0.0) && b_slope.isZero(0.0); }

  Kinematics Evaluate(double s, TrigMemo* memo) const {
    Kinematics k;
    const Vector3d e = e0 + (e1 + e2 * s) * s;
    k.euler = EulerAngles{e.x(), e.y(), e.z()};
    k.euler_rates = e1 + 2.0 * s * e2;
    const Vector3d v_b = s <= 0.5 * duration ? Vector3d(b_start + b_slope * s)
                                             : Vector3d(b_end - b_slope * (duration - s));
    const EulerTrig trig = EulerTrigVia(memo, k.euler);
    const Matrix3d C_b_n = EulerToDcm(trig);
    const Vector3d omega_nb_b = EulerRatesToBodyRate(trig, k.euler_rates);
    k.v_eb_n = C_b_n * v_b;
    k.a_eb_n = C_b_n * (b_slope + omega_nb_b.cross(v_b));
    return k;
  }
};

// Truth profile: cubic polynomials in local time of v_N, v_E, v_D, roll, pitch, yaw.
struct SplinePiece {
  std::array<std::array<double, 4>, 6> c{};

  Kinematics Evaluate(double s, TrigMemo*) const {
    double value[6], rate[6];
    for (int i = 0; i < 6; ++i) {
      const auto& p = c[static_cast<size_t>(i)];
      value[i] = p[0] + s * (p[1] + s * (p[2] + s * p[3]));
      rate[i] = p[1] + s * (2.0 * p[2] + s * 3.0 * p[3]);
    }
    Kinematics k;
    k.v_eb_n = Vector3d(value[0], value[1], value[2]);
    k.a_eb_n = Vector3d(rate[0], rate[1], rate[2]);
    k.euler = EulerAngles{value[3], value[4], value[5]};
    k.euler_rates = Vector3d(rate[3], rate[4], rate[5]);
    return k;
  }
};

struct Piece {
  double t0 = 0.0;  // global start time [s]
  double t1 = 0.0;  // global end time [s]
  double max_substep_s = kDynamicSubstep_s;
  std::variant<TrackPiece, BodyPiece, SplinePiece> kin;

  Kinematics Evaluate(double t, TrigMemo* memo = nullptr) const {
    const double s = t - t0;
    return std::visit([s, memo](const auto& p) { return p.Evaluate(s, memo); }, kin);
  }
};

// ---- Planner ------------------------------------------------------------------------------------

// State carried from one segment to the next.
struct PlanState {
  double t = 0.0;
  EulerAngles euler;  // unwrapped
  Vector3d v_eb_n = Vector3d::Zero();
  bool has_track = false;  // V, chi, v_D exact from a parametric segment
  double V = 0.0, chi = 0.0, v_down = 0.0;
  bool has_body = false;  // v_b exact from a gnss-ins-sim command
  Vector3d v_b = Vector3d::Zero();
};

class Planner {
 public:
  Planner(const MotionSpec& motion, const NavEnvironment& env, double rate_hz,
          std::vector<Piece>* pieces, std::vector<std::pair<double, double>>* gps_invisible_s)
      : motion_(motion),
        pieces_(pieces),
        gps_invisible_s_(gps_invisible_s),
        rate_hz_(rate_hz),
        dt_s_(1.0 / rate_hz) {
    g_m_per_s2_ = env.Gravity(motion.initial.llh.lat_rad, motion.initial.llh.h_m).norm();
    state_.euler = motion.initial.attitude;
    state_.v_eb_n = motion.initial.v_eb_n;
  }

  void Plan() {
    for (size_t i = 0; i < motion_.segments.size(); ++i) {
      const std::string path = motion_.field_path + ".segments[" + std::to_string(i) + "]";
      if (!std::holds_alternative<GnssInsSimCommand>(motion_.segments[i])) FinishExecutor(false);
      std::visit([&](const auto& segment) { PlanSegment(segment, path); }, motion_.segments[i]);
    }
    FinishExecutor(true);
  }

  double duration() const { return state_.t; }

 private:
  // Start values of the parametric model.
  void TrackStart(double* V, double* chi, double* v_down) const {
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

  TrackPiece TrackTemplate(double V, double chi, double v_down, double dchi0) const {
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

  void Add(double duration, const TrackPiece& p) {
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

  void CheckFlightPath(const std::string& path, double V_min, double v_down) const {
    if (motion_.vehicle.pitch_follows_flight_path && V_min == 0.0 && v_down != 0.0) {
      RejectText(path, "vertical speed " + CompactText(-v_down) +
                           " m/s at zero ground speed; allowed: ground speed > 0 whenever the "
                           "vertical speed is non-zero (vehicle.pitch_follows_flight_path: the "
                           "flight-path angle would jump to +-90 deg)");
    }
  }

  void PlanSegment(const StaticSegment& s, const std::string& path) {
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

  void PlanSegment(const ConstantVelocitySegment& s, const std::string& path) {
    CheckDuration(path + ".constant_velocity.duration_s", s.duration_s);
    double V, chi, vD;
    TrackStart(&V, &chi, &vD);
    CheckFlightPath(path + ".constant_velocity", V, vD);
    Add(s.duration_s, TrackTemplate(V, chi, vD, 0.0));
  }

  void PlanSegment(const AccelerateSegment& s, const std::string& path) {
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

  // Turn pieces: rate ramps 0 -> omega over transition_s, holds for hold_s, ramps back to 0. All
  // pieces share the attitude offsets fixed at the turn's start (chi' = 0 there).
  void AddTurn(double omega, double transition_s, double hold_s) {
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

  void PlanSegment(const TurnSegment& s, const std::string& path) {
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
    double omega;
    if (s.rate_rad_per_s) {
      omega = *s.rate_rad_per_s;
      if (!(std::isfinite(omega) && omega != 0.0 && std::abs(omega) <= 4.0 * M_PI)) {
        Reject(base + ".rate_deg_per_s", omega * kRadToDeg,
               "-720 <= rate_deg_per_s <= 720 deg/s, not 0");
      }
    } else {
      CheckPositive(base + ".radius_m", *s.radius_m, 1.0e7, " m");
      if (!(V > 0.0)) {
        RejectText(base + ".radius_m",
                   "given at ground speed 0; allowed: a turn by radius needs "
                   "speed > 0 (give rate_deg_per_s to turn on the spot)");
      }
      omega = (s.right ? 1.0 : -1.0) * V / *s.radius_m;
    }
    const double Tr = s.transition_s;
    CheckNonNegative(base + ".transition_s", Tr, kMaxDuration_s / 2.0, " s");
    if (motion_.vehicle.coordinated_turns && Tr == 0.0) {
      Reject(base + ".transition_s", Tr,
             "transition_s > 0 with vehicle.coordinated_turns (the bank angle must be continuous)");
    }
    double hold;
    if (s.angle_rad) {
      const double angle = *s.angle_rad;
      if (!(angle > 0.0 && angle <= 200.0 * M_PI)) {
        Reject(base + ".angle_deg", angle * kRadToDeg, "0 < angle_deg <= 36000 deg");
      }
      hold = angle / std::abs(omega) - Tr;
      if (hold < 0.0) {
        Reject(base + ".angle_deg", angle * kRadToDeg,
               "angle_deg >= |rate| x transition_s = " +
                   CompactText(std::abs(omega) * Tr * kRadToDeg) +
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

  void PlanSegment(const ClimbSegment& s, const std::string& path) {
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

  void PlanSegment(const ZigzagSegment& s, const std::string& path) {
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

  // A periodic motion sampled at rate_hz: the Nyquist limit is 2 samples per period; a period of
  // fewer than kMinSamplesPerPeriod samples would alias in the output.
  static constexpr double kMinSamplesPerPeriod = 4.0;
  void CheckSampledPeriod(const std::string& field, double period_s) const {
    const double min_period_s = kMinSamplesPerPeriod * dt_s_;
    if (period_s < min_period_s) {
      Reject(field, period_s,
             field.substr(field.rfind('.') + 1) + " >= " + CompactText(min_period_s) + " s (" +
                 CompactText(kMinSamplesPerPeriod) + " output intervals at rate_hz " +
                 CompactText(rate_hz_) + " Hz; the Nyquist limit is 2)");
    }
  }

  void PlanSegment(const ShipMotionSegment& s, const std::string& path) {
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
      const std::string amplitude_field =
          name + (c.scale == 1.0 ? "_amplitude_m" : "_amplitude_deg");
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
      Reject(base + ".ramp_s", s.ramp_s,
             "ramp_s <= duration_s / 2 = " + CompactText(0.5 * s.duration_s) + " s" +
                 (s.ramp_s > 0.0
                      ? std::string()
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

  void PlanSegment(const FigureEightSegment& s, const std::string& path) {
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
    double omega;
    if (s.rate_rad_per_s) {
      if (!(*s.rate_rad_per_s > 0.0 && *s.rate_rad_per_s <= 4.0 * M_PI)) {
        Reject(base + ".rate_deg_per_s", *s.rate_rad_per_s * kRadToDeg,
               "0 < rate_deg_per_s <= 720 deg/s");
      }
      omega = *s.rate_rad_per_s;
    } else {
      CheckPositive(base + ".radius_m", *s.radius_m, 1.0e7, " m");
      if (!(V > 0.0)) {
        RejectText(base + ".radius_m", "given at ground speed 0; allowed: speed > 0");
      }
      omega = V / *s.radius_m;
    }
    const double Tr = s.transition_s;
    CheckNonNegative(base + ".transition_s", Tr, kMaxDuration_s / 2.0, " s");
    if (motion_.vehicle.coordinated_turns && Tr == 0.0) {
      Reject(base + ".transition_s", Tr,
             "transition_s > 0 with vehicle.coordinated_turns (the bank angle must be continuous)");
    }
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

  // ---- gnss-ins-sim commands ----
  //
  // The motion-command executor of gnss-ins-sim (gnss_ins_sim/pathgen/pathgen.py, path_gen(),
  // github.com/Aceinna/gnss-ins-sim at 966ff27), re-implemented from its description. It is a
  // discrete-time loop at the simulation rate (gnss-ins-sim's IMU rate, here the job's rate_hz)
  // over the state att = (yaw, pitch, roll) [rad, unwrapped], v_b [m/s], att_dot, v_dot_b; both
  // rates carry over from one command to the next. Per step, with dt = 1 / rate_hz:
  //   type 1:   att_dot = a att_dot + (1 - a) command rates;  v_dot_b = a v_dot_b + (1 - a) command
  //             acceleration  (first-order low-pass, a = 0.9);
  //   types 2-5 (targets att_com, v_com_b fixed at the command's start, parse_motion_def()):
  //             v_filt  = a v_filt + (1 - a) v_com_b   (v_filt starts at v_b)
  //             v_dot_b = clip((v_filt - v_b) / dt, +-max_acc)
  //             att_dd  = clip(kp (att_com - att) - kd att_dot, +-max_dw)     (PD, kp 5, kd 10)
  //             att_dot = clip(att_dot + att_dd dt, +-max_w)
  //             converged if |att - att_com| < 1e-4 and |v_b - v_com_b| < 1e-4 (2-norms);
  //   then the step: att += att_dot dt, v_b += v_dot_b dt (the rates are constant over the step).
  // A command runs at most round(duration * rate_hz) steps (round half to even, as numpy's round);
  // the step in which it converges is still taken, after which both rates are set to zero and the
  // next command starts. gnss-ins-sim records the state before each step, so its output ends one
  // step before the executor's last step: the import drops that last step, and gives the same
  // number of samples.
  //
  // Each step is a BodyPiece (Euler angles linear, v_b linear in time). Consecutive steps whose
  // rates agree within kExecutorMergeTolerance are one piece between the executor's states at its
  // ends (so the ends are exact and the rates inside differ by at most the tolerance).
  static constexpr double kExecutorFilterAlpha = 0.9;
  static constexpr double kExecutorKp = 5.0;
  static constexpr double kExecutorKd = 10.0;
  static constexpr double kExecutorConvergence = 1e-4;      // rad and m/s
  static constexpr double kExecutorMergeTolerance = 1e-12;  // rad/s and m/s^2
  // Type-1 command limits: the Euler-angle rates as the mobility limit's upper bound (100 rad/s),
  // accelerations as max_acceleration's (1000 m/s^2); beyond them the angles and the Gauss-Legendre
  // sums lose all precision and, for huge values, overflow to inf and NaN.
  static constexpr double kMaxCommandRate_rad_per_s = 100.0;
  static constexpr double kMaxCommandAcceleration_m_per_s2 = 1000.0;

  struct Executor {
    bool active = false;  // the previous segment was a gnss-ins-sim command
    double t_start = 0.0;
    int64_t steps = 0;  // steps taken since t_start
    Vector3d att = Vector3d::Zero(), v_b = Vector3d::Zero();
    Vector3d att_dot = Vector3d::Zero(), v_dot_b = Vector3d::Zero();
    // Open run of merged steps.
    int64_t run_steps = 0;
    Vector3d run_att = Vector3d::Zero(), run_v_b = Vector3d::Zero();
    Vector3d run_att_dot = Vector3d::Zero(), run_v_dot_b = Vector3d::Zero();
    Vector3d att_before_last = Vector3d::Zero(), v_b_before_last = Vector3d::Zero();
  };

  static Vector3d Clip(const Vector3d& x, double limit) {
    Vector3d y = x;
    for (int i = 0; i < 3; ++i) {
      if (y(i) > limit) y(i) = limit;
      if (y(i) < -limit) y(i) = -limit;
    }
    return y;
  }

  void CloseRun() {
    Executor& x = exec_;
    if (x.run_steps == 0) return;
    const int64_t first = x.steps - x.run_steps;
    const double t0 = x.t_start + static_cast<double>(first) * dt_s_;
    const double t1 = x.t_start + static_cast<double>(x.steps) * dt_s_;
    const double T = t1 - t0;
    BodyPiece p;
    const Vector3d att_end = x.att;
    p.e0 = Vector3d(x.run_att(2), x.run_att(1), x.run_att(0));
    p.e1 =
        Vector3d(att_end(2) - x.run_att(2), att_end(1) - x.run_att(1), att_end(0) - x.run_att(0)) /
        T;
    p.b_start = x.run_v_b;
    p.b_end = x.v_b;
    p.b_slope = (x.v_b - x.run_v_b) / T;
    p.duration = T;
    Piece piece;
    piece.t0 = t0;
    piece.t1 = t1;
    piece.max_substep_s = p.Uniform() ? kUniformSubstep_s : kDynamicSubstep_s;
    piece.kin = p;
    pieces_->push_back(piece);
    x.run_steps = 0;
    state_.t = t1;
    state_.euler = EulerAngles{att_end(2), att_end(1), att_end(0)};
    state_.v_b = x.v_b;
    state_.has_body = true;
    state_.has_track = false;
    state_.v_eb_n = EulerToDcm(state_.euler) * x.v_b;
  }

  void ExecutorStep() {
    Executor& x = exec_;
    auto close = [](const Vector3d& a, const Vector3d& b) {
      return (a - b).cwiseAbs().maxCoeff() <= kExecutorMergeTolerance;
    };
    if (x.run_steps > 0 && !(close(x.att_dot, x.run_att_dot) && close(x.v_dot_b, x.run_v_dot_b))) {
      CloseRun();
    }
    if (x.run_steps == 0) {
      x.run_att = x.att;
      x.run_v_b = x.v_b;
      x.run_att_dot = x.att_dot;
      x.run_v_dot_b = x.v_dot_b;
    }
    x.att_before_last = x.att;
    x.v_b_before_last = x.v_b;
    x.v_b = x.v_b + x.v_dot_b * dt_s_;
    x.att = x.att + x.att_dot * dt_s_;
    ++x.steps;
    ++x.run_steps;
  }

  void PlanSegment(const GnssInsSimCommand& cmd, const std::string& path) {
    // Field of one column: "<segments path>.gnss_ins_sim.<column>" or "<file>:<line> (<column>)".
    auto field = [&](const char* column) {
      return cmd.source.empty() ? path + ".gnss_ins_sim." + column
                                : cmd.source + " (" + column + ")";
    };
    if (cmd.type < 1 || cmd.type > 5) {
      Reject(field("type"), cmd.type, "1, 2, 3, 4 or 5 (gnss-ins-sim command types)");
    }
    const char* angle_names[3] = {"yaw", "pitch", "roll"};
    const char* velocity_names[3] = {"vx_body", "vy_body", "vz_body"};
    for (int i = 0; i < 3; ++i) {
      CheckFinite(field(angle_names[i]), cmd.euler_ypr(i));
      CheckFinite(field(velocity_names[i]), cmd.v_b(i));
    }
    if (cmd.type == 1) {
      for (int i = 0; i < 3; ++i) {
        if (!(std::abs(cmd.euler_ypr(i)) <= kMaxCommandRate_rad_per_s)) {
          Reject(field(angle_names[i]), cmd.euler_ypr(i) * kRadToDeg,
                 std::string("|") + angle_names[i] +
                     " rate| <= " + CompactText(kMaxCommandRate_rad_per_s * kRadToDeg) +
                     " deg/s (100 rad/s) in a type-1 command");
        }
        if (!(std::abs(cmd.v_b(i)) <= kMaxCommandAcceleration_m_per_s2)) {
          Reject(field(velocity_names[i]), cmd.v_b(i),
                 std::string("|") + velocity_names[i] + " acceleration| <= " +
                     CompactText(kMaxCommandAcceleration_m_per_s2) + " m/s^2 in a type-1 command");
        }
      }
    }
    const std::string duration_field = field("duration_s");
    // 0 is allowed: gnss-ins-sim then takes no step (round(duration * rate) = 0).
    if (!(cmd.duration_s >= 0.0 && cmd.duration_s <= kMaxDuration_s)) {
      Reject(duration_field, cmd.duration_s,
             "0 <= duration_s <= " + CompactText(kMaxDuration_s) + " s");
    }

    Executor& x = exec_;
    if (!x.active) {  // start of a block of commands: from the planned state, at rest rates
      x = Executor{};
      x.active = true;
      x.t_start = state_.t;
      x.att = Vector3d(state_.euler.yaw_rad, state_.euler.pitch_rad, state_.euler.roll_rad);
      x.v_b = state_.has_body ? state_.v_b
                              : Vector3d(EulerToDcm(state_.euler).transpose() * state_.v_eb_n);
    }
    const GnssInsSimLimits& lim = motion_.gnss_ins_sim_limits;
    const double a = kExecutorFilterAlpha, b = 1.0 - kExecutorFilterAlpha;
    // round(duration * fs) with numpy's round half to even (the default rounding mode).
    const auto max_steps = static_cast<int64_t>(std::nearbyint(cmd.duration_s * rate_hz_));
    // Targets (parse_motion_def): 2 abs/abs, 3 rel/rel, 4 abs att/rel vel, 5 rel att/abs vel.
    const bool absolute_attitude = cmd.type == 2 || cmd.type == 4;
    const bool absolute_velocity = cmd.type == 2 || cmd.type == 5;
    const Vector3d att_com = absolute_attitude ? cmd.euler_ypr : Vector3d(x.att + cmd.euler_ypr);
    const Vector3d v_com_b = absolute_velocity ? cmd.v_b : Vector3d(x.v_b + cmd.v_b);
    Vector3d v_filt = x.v_b;
    bool complete = false;
    const int64_t first_step = x.steps;
    for (int64_t n = 0; n < max_steps && !complete; ++n) {
      if (cmd.type == 1) {
        x.att_dot = a * x.att_dot + b * cmd.euler_ypr;
        x.v_dot_b = a * x.v_dot_b + b * cmd.v_b;
      } else {
        v_filt = a * v_filt + b * v_com_b;
        x.v_dot_b = Clip((v_filt - x.v_b) / dt_s_, lim.max_acceleration_m_per_s2);
        const Vector3d att_dd = Clip(kExecutorKp * (att_com - x.att) + kExecutorKd * (-x.att_dot),
                                     lim.max_angular_acceleration_rad_per_s2);
        x.att_dot = Clip(x.att_dot + att_dd * dt_s_, lim.max_angular_rate_rad_per_s);
        complete = (x.att - att_com).norm() < kExecutorConvergence &&
                   (x.v_b - v_com_b).norm() < kExecutorConvergence;
      }
      ExecutorStep();
    }
    if (complete) {
      x.att_dot.setZero();
      x.v_dot_b.setZero();
    }
    if (!cmd.gps_visible && x.steps > first_step) {  // its GPS epochs are those of its steps
      const double start_s = x.t_start + static_cast<double>(first_step) * dt_s_;
      const double end_s = x.t_start + static_cast<double>(x.steps) * dt_s_;
      if (!gps_invisible_s_->empty() && gps_invisible_s_->back().second >= start_s) {
        gps_invisible_s_->back().second = end_s;
      } else {
        gps_invisible_s_->emplace_back(start_s, end_s);
      }
    }
    if (!(x.v_b.norm() <= kMaxSpeed_m_per_s)) {
      Reject(field(cmd.type == 1 ? "vx_body" : "duration_s"), x.v_b.norm(),
             "a command ending at a speed <= " + CompactText(kMaxSpeed_m_per_s) +
                 " m/s (the speed it reaches)");
    }
  }

  // Ends a block of consecutive gnss-ins-sim commands; `drop_last_step` when the motion ends with
  // it (gnss-ins-sim's output stops at the state before the executor's last step).
  void FinishExecutor(bool drop_last_step) {
    Executor& x = exec_;
    if (!x.active) return;
    x.active = false;
    if (drop_last_step && x.run_steps > 0) {
      --x.steps;
      if (--x.run_steps == 0) {
        x.att = x.run_att;
        x.v_b = x.run_v_b;
      } else {
        x.att = x.att_before_last;
        x.v_b = x.v_b_before_last;
      }
    }
    CloseRun();
  }

  const MotionSpec& motion_;
  std::vector<Piece>* pieces_;
  std::vector<std::pair<double, double>>* gps_invisible_s_;
  PlanState state_;
  Executor exec_;
  double rate_hz_ = 1.0;
  double dt_s_ = 1.0;
  double g_m_per_s2_ = 9.8;
};

// Not-a-knot cubic spline through (x_i, y_i), i = 0..n-1: returns the slopes y'(x_i).
// The interior conditions (continuity of y'') give, with h_i = x_{i+1} - x_i and
// d_i = (y_{i+1} - y_i) / h_i,
//   h_i s_{i-1} + 2 (h_{i-1} + h_i) s_i + h_{i-1} s_{i+1} = 3 (h_i d_{i-1} + h_{i-1} d_i);
// the not-a-knot end conditions (y''' continuous at x_1 and x_{n-2}) give
//   h_1 s_0 + (h_0 + h_1) s_1 = ((h_0 + 2 (h_0 + h_1)) h_1 d_0 + h_0^2 d_1) / (h_0 + h_1)
// and its mirror image (de Boor, A Practical Guide to Splines, rev. ed. 2001, ch. IV). Subtracting
// each end row from its neighbour leaves a diagonally dominant tridiagonal system in s_1..s_{n-2}.
std::vector<double> NotAKnotSlopes(const std::vector<double>& x, const std::vector<double>& y) {
  const size_t n = x.size();
  std::vector<double> s(n, 0.0);
  std::vector<double> h(n - 1), d(n - 1);
  for (size_t i = 0; i + 1 < n; ++i) {
    h[i] = x[i + 1] - x[i];
    d[i] = (y[i + 1] - y[i]) / h[i];
  }
  if (n == 2) {
    s[0] = s[1] = d[0];
    return s;
  }
  if (n == 3) {  // the parabola through the three points
    const double c2 = (d[1] - d[0]) / (h[0] + h[1]);
    s[0] = d[0] - c2 * h[0];
    s[1] = d[0] + c2 * h[0];
    s[2] = d[1] + c2 * h[1];
    return s;
  }
  const size_t m = n - 2;  // unknowns s_1..s_{n-2}
  std::vector<double> lower(m, 0.0), diag(m, 0.0), upper(m, 0.0), rhs(m, 0.0);
  for (size_t i = 1; i + 1 < n; ++i) {
    lower[i - 1] = h[i];
    diag[i - 1] = 2.0 * (h[i - 1] + h[i]);
    upper[i - 1] = h[i - 1];
    rhs[i - 1] = 3.0 * (h[i] * d[i - 1] + h[i - 1] * d[i]);
  }
  const double left_sum = h[0] + h[1];
  const double left_rhs = ((h[0] + 2.0 * left_sum) * h[1] * d[0] + h[0] * h[0] * d[1]) / left_sum;
  const double right_sum = h[n - 3] + h[n - 2];
  const double right_rhs =
      (h[n - 2] * h[n - 2] * d[n - 3] + (2.0 * right_sum + h[n - 2]) * h[n - 3] * d[n - 2]) /
      right_sum;
  // Row 1 minus the left end row: (h_0 + h_1) s_1 + h_0 s_2 = rhs_1 - left_rhs.
  diag[0] -= left_sum;
  rhs[0] -= left_rhs;
  lower[0] = 0.0;
  // Row n-2 minus the right end row: h_{n-2} s_{n-3} + (h_{n-3} + h_{n-2}) s_{n-2} = ...
  diag[m - 1] -= right_sum;
  rhs[m - 1] -= right_rhs;
  upper[m - 1] = 0.0;
  // Thomas algorithm.
  for (size_t i = 1; i < m; ++i) {
    const double w = lower[i] / diag[i - 1];
    diag[i] -= w * upper[i - 1];
    rhs[i] -= w * rhs[i - 1];
  }
  std::vector<double> sol(m);
  sol[m - 1] = rhs[m - 1] / diag[m - 1];
  for (size_t i = m - 1; i-- > 0;) sol[i] = (rhs[i] - upper[i] * sol[i + 1]) / diag[i];
  for (size_t i = 0; i < m; ++i) s[i + 1] = sol[i];
  s[0] = (left_rhs - left_sum * s[1]) / h[1];
  s[n - 1] = (right_rhs - right_sum * s[n - 2]) / h[n - 3];
  return s;
}

void PlanTruthProfile(const MotionSpec& motion, std::vector<Piece>* pieces) {
  const std::vector<TruthProfileSample>& samples = motion.truth_profile;
  const std::string base = motion.field_path + ".truth_profile";
  const size_t n = samples.size();
  if (n < 2) RejectText(base, std::to_string(n) + " samples; allowed: at least 2");
  std::vector<double> t(n);
  std::vector<std::vector<double>> channels(6, std::vector<double>(n));
  for (size_t i = 0; i < n; ++i) {
    const TruthProfileSample& p = samples[i];
    const std::string at = base + "[" + std::to_string(i) + "]";
    const double values[] = {p.t_s,
                             p.llh.lat_rad,
                             p.llh.lon_rad,
                             p.llh.h_m,
                             p.v_eb_n.x(),
                             p.v_eb_n.y(),
                             p.v_eb_n.z(),
                             p.attitude.roll_rad,
                             p.attitude.pitch_rad,
                             p.attitude.yaw_rad};
    const char* names[] = {".t_s", ".lat", ".lon",  ".h_m",   ".v_n",
                           ".v_e", ".v_d", ".roll", ".pitch", ".yaw"};
    for (int j = 0; j < 10; ++j) CheckFinite(at + names[j], values[j]);
    if (i > 0 && !(p.t_s > samples[i - 1].t_s)) {
      Reject(at + ".t_s", p.t_s,
             "a time greater than the previous sample's " + CompactText(samples[i - 1].t_s) + " s");
    }
    t[i] = p.t_s - samples[0].t_s;
    channels[0][i] = p.v_eb_n.x();
    channels[1][i] = p.v_eb_n.y();
    channels[2][i] = p.v_eb_n.z();
    channels[3][i] = p.attitude.roll_rad;
    channels[4][i] = p.attitude.pitch_rad;
    channels[5][i] = p.attitude.yaw_rad;
    if (i > 0) {  // unwrap roll and yaw: the spline must not see a 2 pi jump
      channels[3][i] = channels[3][i - 1] + WrapPi(channels[3][i] - channels[3][i - 1]);
      channels[5][i] = channels[5][i - 1] + WrapPi(channels[5][i] - channels[5][i - 1]);
    }
  }
  if (t[n - 1] > kMaxDuration_s) {
    Reject(base + "[" + std::to_string(n - 1) + "].t_s", samples[n - 1].t_s,
           "a profile lasting at most " + CompactText(kMaxDuration_s) + " s");
  }
  std::vector<std::vector<double>> slopes;
  for (const auto& y : channels) slopes.push_back(NotAKnotSlopes(t, y));
  pieces->reserve(n - 1);
  for (size_t i = 0; i + 1 < n; ++i) {
    Piece piece;
    piece.t0 = t[i];
    piece.t1 = t[i + 1];
    SplinePiece sp;
    const double h = t[i + 1] - t[i];
    for (size_t c = 0; c < 6; ++c) {
      const double y0 = channels[c][i], y1 = channels[c][i + 1];
      const double s0 = slopes[c][i], s1 = slopes[c][i + 1];
      const double dd = (y1 - y0) / h;
      sp.c[c] = {y0, s0, (3.0 * dd - 2.0 * s0 - s1) / h, (s0 + s1 - 2.0 * dd) / (h * h)};
    }
    piece.kin = sp;
    pieces->push_back(piece);
  }
}

void ValidateLlh(const std::string& path, const Llh& llh, EarthModel model) {
  CheckFinite(path + ".lat_deg", llh.lat_rad * kRadToDeg);
  CheckFinite(path + ".lon_deg", llh.lon_rad * kRadToDeg);
  CheckFinite(path + ".height_m", llh.h_m);
  const double lat_deg = llh.lat_rad * kRadToDeg;
  const double max_lat = model == EarthModel::kWgs84 ? kMaxWgs84Latitude_deg : 90.0;
  const bool ok =
      model == EarthModel::kWgs84 ? std::abs(lat_deg) < max_lat : std::abs(lat_deg) <= max_lat;
  if (!ok) {
    Reject(path + ".lat_deg", lat_deg,
           model == EarthModel::kWgs84
               ? "-89.9 < lat_deg < 89.9 deg (WGS-84 navigation is singular at the poles)"
               : "-90 <= lat_deg <= 90 deg");
  }
  if (!(std::abs(llh.lon_rad) <= 2.0 * M_PI)) {
    Reject(path + ".lon_deg", llh.lon_rad * kRadToDeg, "-360 <= lon_deg <= 360 deg");
  }
  if (!(llh.h_m >= kMinHeight_m && llh.h_m <= kMaxHeight_m)) {
    Reject(path + ".height_m", llh.h_m,
           CompactText(kMinHeight_m) + " <= height_m <= " + CompactText(kMaxHeight_m) + " m");
  }
}

void ValidateMotionHeader(const MotionSpec& motion, double rate_hz) {
  if (!(rate_hz >= kMinRate_hz && rate_hz <= kMaxRate_hz)) {
    Reject("rate_hz", rate_hz,
           CompactText(kMinRate_hz) + " <= rate_hz <= " + CompactText(kMaxRate_hz) + " Hz");
  }
  const std::string& m = motion.field_path;
  if (motion.flat_gravity_m_per_s2) {
    if (motion.earth_model != EarthModel::kFlat) {
      Reject(m + ".flat_gravity_m_per_s2", *motion.flat_gravity_m_per_s2,
             "absent unless earth_model is FLAT");
    }
    CheckPositive(m + ".flat_gravity_m_per_s2", *motion.flat_gravity_m_per_s2, 100.0, " m/s^2");
  }
  const bool has_profile = !motion.truth_profile.empty();
  if (has_profile == !motion.segments.empty()) {
    RejectText(m, std::string(has_profile ? "both" : "neither") +
                      " segments and a truth profile given; allowed: exactly one of them");
  }
  if (has_profile) {
    for (size_t i = 0; i < motion.truth_profile.size(); ++i) {
      ValidateLlh(m + ".truth_profile[" + std::to_string(i) + "]", motion.truth_profile[i].llh,
                  motion.earth_model);
    }
    return;
  }
  const std::string init = m + ".initial";
  ValidateLlh(init, motion.initial.llh, motion.earth_model);
  const char* v_names[3] = {".velocity_ned_m_per_s[0]", ".velocity_ned_m_per_s[1]",
                            ".velocity_ned_m_per_s[2]"};
  for (int i = 0; i < 3; ++i) CheckFinite(init + v_names[i], motion.initial.v_eb_n(i));
  if (!(motion.initial.v_eb_n.norm() <= kMaxSpeed_m_per_s)) {
    Reject(init + ".velocity_ned_m_per_s", motion.initial.v_eb_n.norm(),
           "speed <= " + CompactText(kMaxSpeed_m_per_s) + " m/s");
  }
  const EulerAngles& a = motion.initial.attitude;
  if (!(std::abs(a.roll_rad) <= 2.0 * M_PI)) {
    Reject(init + ".roll_deg", a.roll_rad * kRadToDeg, "-360 <= roll_deg <= 360 deg");
  }
  if (!(std::abs(a.pitch_rad) <= 0.5 * M_PI)) {
    Reject(init + ".pitch_deg", a.pitch_rad * kRadToDeg, "-90 <= pitch_deg <= 90 deg");
  }
  if (!(std::abs(a.yaw_rad) <= 2.0 * M_PI)) {
    Reject(init + ".yaw_deg", a.yaw_rad * kRadToDeg, "-360 <= yaw_deg <= 360 deg");
  }
  const GnssInsSimLimits& lim = motion.gnss_ins_sim_limits;
  const std::string g = m + ".gnss_ins_sim_file";
  CheckPositive(g + ".max_acceleration_m_per_s2", lim.max_acceleration_m_per_s2, 1000.0, " m/s^2");
  if (!(lim.max_angular_acceleration_rad_per_s2 > 0.0 &&
        lim.max_angular_acceleration_rad_per_s2 <= 1000.0)) {
    Reject(g + ".max_angular_acceleration_deg_per_s2",
           lim.max_angular_acceleration_rad_per_s2 * kRadToDeg,
           "0 < max_angular_acceleration_deg_per_s2 <= " + CompactText(1000.0 * kRadToDeg) +
               " deg/s^2");
  }
  if (!(lim.max_angular_rate_rad_per_s > 0.0 && lim.max_angular_rate_rad_per_s <= 100.0)) {
    Reject(g + ".max_angular_rate_deg_per_s", lim.max_angular_rate_rad_per_s * kRadToDeg,
           "0 < max_angular_rate_deg_per_s <= " + CompactText(100.0 * kRadToDeg) + " deg/s");
  }
}

Quaterniond EulerToQuaternion(const EulerAngles& e) {
  // C_b_n = Rz(yaw) Ry(pitch) Rx(roll)  (attitude.h).
  return Quaterniond(Eigen::AngleAxisd(e.yaw_rad, Vector3d::UnitZ()) *
                     Eigen::AngleAxisd(e.pitch_rad, Vector3d::UnitY()) *
                     Eigen::AngleAxisd(e.roll_rad, Vector3d::UnitX()));
}

// EulerToQuaternion with the half angles' sin and cos through `memo`: Eigen's own steps
// (Quaternion of an AngleAxis is (cos a/2, sin a/2 axis); the products in the same order), so the
// same bits.
Quaterniond EulerToQuaternion(const EulerAngles& e, TrigMemo* memo) {
  const auto of_axis = [memo](TrigMemo::Slot slot, double angle, const Vector3d& axis) {
    double s, c;
    memo->SinCos(slot, 0.5 * angle, &s, &c);
    Quaterniond q;
    q.w() = c;
    q.vec() = s * axis;
    return q;
  };
  return of_axis(TrigMemo::kHalfYaw, e.yaw_rad, Vector3d::UnitZ()) *
         of_axis(TrigMemo::kHalfPitch, e.pitch_rad, Vector3d::UnitY()) *
         of_axis(TrigMemo::kHalfRoll, e.roll_rad, Vector3d::UnitX());
}

// 4-point Gauss-Legendre nodes and weights on [-1, 1] (Abramowitz & Stegun, table 25.4).
constexpr double kGaussNode[4] = {-0.861136311594052575224, -0.339981043584856264803,
                                  0.339981043584856264803, 0.861136311594052575224};
constexpr double kGaussWeight[4] = {0.347854845137453857373, 0.652145154862546142627,
                                    0.652145154862546142627, 0.347854845137453857373};

}  // namespace

// ---- Generator ----------------------------------------------------------------------------------

struct TrajectoryGenerator::Impl {
  NavEnvironment env;
  std::string field_path;
  double rate_hz = 0.0;
  double dt_s = 0.0;
  double duration_s = 0.0;
  int64_t num_steps = 0;
  int64_t step = 0;
  std::vector<Piece> pieces;
  std::vector<double> breakpoints;
  std::vector<std::pair<double, double>> gps_invisible_s;
  TrigMemo trig_memo;         // Next's path only (IsStaticAt and the planner evaluate without it)
  bool point_samples = true;  // Next computes out->sample (set_point_samples)
  NavState initial;
  ImuSample initial_sample;
  // Integration state at t = step / rate_hz: (L, lambda, h) as an unevaluated sum llh + llh_lo.
  // Adding the small RK4 steps to L ~ 1 rad would otherwise round by up to half an ulp (3.5e-10 m)
  // per step, systematically when the step repeats (a straight line): 7 cm after 2e8 steps. The
  // low parts carry what each addition rounds off (Knuth's TwoSum), so the sum stays exact to
  // ~1e-16 relative whatever the number of steps.
  Vector3d llh = Vector3d::Zero();
  Vector3d llh_lo = Vector3d::Zero();
  size_t cursor = 0;

  const Piece& PieceLeftOf(double t) const {
    // The piece with t0 < t <= t1 (left-continuous), the first piece for t <= 0.
    auto it = std::lower_bound(pieces.begin(), pieces.end(), t,
                               [](const Piece& p, double value) { return p.t0 < value; });
    if (it == pieces.begin()) return pieces.front();
    return *(it - 1);
  }

  void PointSample(const Kinematics& k, const Vector3d& y, ImuSample* out) {
    PointSample(k, y, NavEnvironment::Latitude::Of(y.x()), out);
  }
  // `lat` is y's latitude with its sin and cos.
  void PointSample(const Kinematics& k, const Vector3d& y, const NavEnvironment::Latitude& lat,
                   ImuSample* out) {
    const EulerTrig trig = EulerTrigVia(&trig_memo, k.euler);  // once for both uses
    const Matrix3d C_n_b = EulerToDcm(trig).transpose();
    const NavEnvironment::PointRates earth = env.AtPoint(lat, y.z(), k.v_eb_n);
    const Vector3d& omega_ie_n = earth.omega_ie_n;
    const Vector3d& omega_en_n = earth.omega_en_n;
    // omega_ib_b = omega_nb_b + C_n_b (omega_ie_n + omega_en_n)             Groves (5.40)
    out->omega_ib_b = EulerRatesToBodyRate(trig, k.euler_rates) + C_n_b * (omega_ie_n + omega_en_n);
    // f_ib_b = C_n_b (dv_eb_n/dt - g_b_n + (omega_en_n + 2 omega_ie_n) x v_eb_n)   Groves (5.54)
    out->f_ib_b =
        C_n_b * (k.a_eb_n - earth.g_b_n + (omega_en_n + 2.0 * omega_ie_n).cross(k.v_eb_n));
  }

  // The rate at y, its latitude's sin and cos from those of a nearby known latitude.
  Vector3d Rate(const NavEnvironment::Latitude& known, const Vector3d& y,
                const Vector3d& v_eb_n) const {
    return env.LlhRate(NavEnvironment::Latitude::Near(known, y.x()), y.z(), v_eb_n);
  }

  // One RK4 sub-step of the position over [ta, tb] on piece p, with the Gauss-Legendre quadrature
  // of omega_ib_b and f_ib_b added to `inc`. k_a: kinematics at ta (in), at tb (out).
  void SubStep(const Piece& p, double ta, double tb, Kinematics* k_a, ImuIncrement* inc) {
    const double h = tb - ta;
    const Vector3d y0 = llh;
    const Kinematics k_m = p.Evaluate(ta + 0.5 * h, &trig_memo);
    const Kinematics k_b = p.Evaluate(tb, &trig_memo);
    // One full sin/cos of latitude a sub-step: every other point's from y0's
    // (NavEnvironment::Latitude::Near; the points are within one sub-step of y0).
    const NavEnvironment::Latitude lat0 = NavEnvironment::Latitude::Of(y0.x());
    const Vector3d f0 = env.LlhRate(lat0, y0.z(), k_a->v_eb_n);
    const Vector3d f1 = Rate(lat0, y0 + 0.5 * h * f0, k_m.v_eb_n);
    const Vector3d f2 = Rate(lat0, y0 + 0.5 * h * f1, k_m.v_eb_n);
    const Vector3d f3 = Rate(lat0, y0 + h * f2, k_b.v_eb_n);
    const Vector3d delta = (h / 6.0) * (f0 + 2.0 * f1 + 2.0 * f2 + f3);
    Vector3d y1;
    for (int i = 0; i < 3; ++i) {
      // TwoSum(a, b): s = fl(a + b), e = (a - (s - b')) + (b - b') with b' = s - a: a + b = s + e.
      const double a = y0(i), b = delta(i) + llh_lo(i);
      const double sum = a + b, b_virtual = sum - a;
      llh_lo(i) = (a - (sum - b_virtual)) + (b - b_virtual);
      y1(i) = sum;
    }
    const Vector3d fe = Rate(lat0, y1, k_b.v_eb_n);
    for (int j = 0; j < 4; ++j) {
      const double theta = 0.5 * (1.0 + kGaussNode[j]);
      const Kinematics k = p.Evaluate(ta + theta * h, &trig_memo);
      // Cubic Hermite position on the sub-step.
      const double t2 = theta * theta, t3 = t2 * theta;
      const Vector3d y = (2.0 * t3 - 3.0 * t2 + 1.0) * y0 + (t3 - 2.0 * t2 + theta) * h * f0 +
                         (-2.0 * t3 + 3.0 * t2) * y1 + (t3 - t2) * h * fe;
      ImuSample s;
      PointSample(k, y, NavEnvironment::Latitude::Near(lat0, y.x()), &s);
      const double w = 0.5 * h * kGaussWeight[j];
      inc->delta_theta_ib_b += w * s.omega_ib_b;
      inc->delta_v_ib_b += w * s.f_ib_b;
    }
    llh = y1;
    *k_a = k_b;
  }

  // Integrates from ta to tb; returns the kinematics at tb (left limit).
  Kinematics Integrate(double ta, double tb, ImuIncrement* inc) {
    double t = ta;
    Kinematics k;
    bool have_k = false;
    while (true) {
      while (cursor + 1 < pieces.size() && pieces[cursor].t1 <= t) {
        ++cursor;
        have_k = false;
      }
      const Piece& p = pieces[cursor];
      const double end = cursor + 1 < pieces.size() ? std::min(tb, p.t1) : tb;
      if (!have_k) {
        k = p.Evaluate(t, &trig_memo);
        have_k = true;
      }
      if (end > t) {
        const double span = end - t;
        const int64_t n = std::max<int64_t>(
            1, static_cast<int64_t>(std::ceil(span / p.max_substep_s * (1.0 - 1e-12))));
        double sa = t;
        for (int64_t i = 1; i <= n; ++i) {
          const double sb = i == n ? end : t + span * static_cast<double>(i) / n;
          SubStep(p, sa, sb, &k, inc);
          sa = sb;
        }
      }
      t = end;
      if (t >= tb) return k;
    }
  }

  void CheckPosition(double t) const {
    if (env.model() == EarthModel::kWgs84 &&
        std::abs(llh.x()) * kRadToDeg >= kMaxWgs84Latitude_deg) {
      RejectText(field_path, "the trajectory reaches latitude " + CompactText(llh.x() * kRadToDeg) +
                                 " deg at t = " + CompactText(t) +
                                 " s; allowed: |lat| < 89.9 deg on WGS-84");
    }
    if (!(llh.z() >= kMinHeight_m && llh.z() <= kMaxHeight_m)) {
      RejectText(field_path, "the trajectory reaches height " + CompactText(llh.z()) +
                                 " m at t = " + CompactText(t) +
                                 " s; allowed: " + CompactText(kMinHeight_m) +
                                 " <= h <= " + CompactText(kMaxHeight_m) + " m");
    }
  }
};

TrajectoryGenerator::TrajectoryGenerator(const MotionSpec& motion, double rate_hz)
    : impl_(new Impl) {
  std::unique_ptr<Impl> guard(impl_);
  ValidateMotionHeader(motion, rate_hz);
  Impl& m = *impl_;
  m.field_path = motion.field_path;
  m.rate_hz = rate_hz;
  m.dt_s = 1.0 / rate_hz;
  const Llh start_llh =
      motion.truth_profile.empty() ? motion.initial.llh : motion.truth_profile.front().llh;
  if (motion.earth_model == EarthModel::kFlat) {
    const double g = motion.flat_gravity_m_per_s2
                         ? *motion.flat_gravity_m_per_s2
                         : GravityNed(start_llh.lat_rad, start_llh.h_m).norm();
    m.env = NavEnvironment::Flat(start_llh, g);
  } else {
    m.env = NavEnvironment::Wgs84();
  }
  if (motion.truth_profile.empty()) {
    Planner planner(motion, m.env, rate_hz, &m.pieces, &m.gps_invisible_s);
    planner.Plan();
    m.duration_s = planner.duration();
  } else {
    PlanTruthProfile(motion, &m.pieces);
    m.duration_s = m.pieces.back().t1;
  }
  if (m.pieces.empty() || !(m.duration_s > 0.0)) {
    RejectText(motion.field_path + ".segments",
               "the motion lasts 0 s (every command already at its target); allowed: a total "
               "duration > 0");
  }
  if (m.duration_s > kMaxDuration_s * (1.0 + 1e-12)) {
    Reject(motion.field_path + ".segments", m.duration_s,
           "a total duration <= " + CompactText(kMaxDuration_s) + " s");
  }
  m.num_steps = static_cast<int64_t>(std::floor(m.duration_s * rate_hz + 1e-9));
  if (m.num_steps < 1) {
    Reject(motion.field_path + ".segments", m.duration_s,
           "a total duration of at least one output interval, 1 / rate_hz = " +
               CompactText(m.dt_s) + " s");
  }
  for (size_t i = 1; i < m.pieces.size(); ++i) m.breakpoints.push_back(m.pieces[i].t0);
  while (!m.gps_invisible_s.empty() && m.gps_invisible_s.back().first >= m.duration_s) {
    m.gps_invisible_s.pop_back();  // only the dropped last step
  }
  if (!m.gps_invisible_s.empty()) {
    m.gps_invisible_s.back().second = std::min(m.gps_invisible_s.back().second, m.duration_s);
  }

  m.llh = Vector3d(start_llh.lat_rad, start_llh.lon_rad, start_llh.h_m);
  const Kinematics k0 = m.pieces.front().Evaluate(0.0);
  m.initial.t_s = 0.0;
  m.initial.llh = start_llh;
  m.initial.v_eb_n = k0.v_eb_n;
  m.initial.q_b_n = EulerToQuaternion(k0.euler);
  m.PointSample(k0, m.llh, &m.initial_sample);
  guard.release();
}

TrajectoryGenerator::~TrajectoryGenerator() { delete impl_; }

TrajectoryGenerator::TrajectoryGenerator(TrajectoryGenerator&& other) noexcept
    : impl_(other.impl_) {
  other.impl_ = nullptr;
}

TrajectoryGenerator& TrajectoryGenerator::operator=(TrajectoryGenerator&& other) noexcept {
  if (this != &other) {
    delete impl_;
    impl_ = other.impl_;
    other.impl_ = nullptr;
  }
  return *this;
}

const NavEnvironment& TrajectoryGenerator::environment() const { return impl_->env; }
double TrajectoryGenerator::rate_hz() const { return impl_->rate_hz; }
double TrajectoryGenerator::dt_s() const { return impl_->dt_s; }
double TrajectoryGenerator::duration_s() const { return impl_->duration_s; }
int64_t TrajectoryGenerator::num_steps() const { return impl_->num_steps; }
const NavState& TrajectoryGenerator::initial_state() const { return impl_->initial; }
const ImuSample& TrajectoryGenerator::initial_sample() const { return impl_->initial_sample; }
const std::vector<double>& TrajectoryGenerator::breakpoints_s() const { return impl_->breakpoints; }
const std::vector<std::pair<double, double>>& TrajectoryGenerator::gps_invisible_s() const {
  return impl_->gps_invisible_s;
}
int64_t TrajectoryGenerator::step() const { return impl_->step; }

bool TrajectoryGenerator::IsStaticAt(double t_s) const {
  if (!(t_s >= 0.0 && t_s <= impl_->duration_s)) return false;
  const Kinematics k = impl_->PieceLeftOf(t_s).Evaluate(t_s);
  return k.v_eb_n.isZero(0.0) && k.euler_rates.isZero(0.0);
}

bool TrajectoryGenerator::Next(TrajectorySample* out) {
  Impl& m = *impl_;
  if (m.step >= m.num_steps) return false;
  const double ta = static_cast<double>(m.step) / m.rate_hz;
  const double tb = static_cast<double>(m.step + 1) / m.rate_hz;
  out->increment = ImuIncrement();
  const Kinematics k = m.Integrate(ta, tb, &out->increment);
  ++m.step;
  m.CheckPosition(tb);
  out->truth.t_s = tb;
  out->truth.llh = Llh{m.llh.x(), WrapPi(m.llh.y()), m.llh.z()};
  out->truth.v_eb_n = k.v_eb_n;
  out->truth.q_b_n = EulerToQuaternion(k.euler, &m.trig_memo);
  if (m.point_samples) m.PointSample(k, m.llh, &out->sample);
  return true;
}

void TrajectoryGenerator::set_point_samples(bool on) { impl_->point_samples = on; }

Trajectory GenerateTrajectory(const MotionSpec& motion, double rate_hz) {
  TrajectoryGenerator generator(motion, rate_hz);
  Trajectory trajectory;
  trajectory.environment = generator.environment();
  trajectory.dt_s = generator.dt_s();
  const size_t n = static_cast<size_t>(generator.num_steps());
  trajectory.truth.reserve(n + 1);
  trajectory.samples.reserve(n + 1);
  trajectory.increments.reserve(n);
  trajectory.truth.push_back(generator.initial_state());
  trajectory.samples.push_back(generator.initial_sample());
  TrajectorySample sample;
  while (generator.Next(&sample)) {
    trajectory.truth.push_back(sample.truth);
    trajectory.samples.push_back(sample.sample);
    trajectory.increments.push_back(sample.increment);
  }
  return trajectory;
}

}  // namespace driftlab
