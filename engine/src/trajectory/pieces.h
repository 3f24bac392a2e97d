// The kinematic pieces a motion is planned into: each evaluates, at local time s, the Euler
// angles, their rates, v_eb_n and dv_eb_n/dt in closed form (trajectory.cc integrates them).
// Private to the trajectory generator.
#pragma once

#include <array>
#include <bit>
#include <cstdint>
#include <variant>

#include "driftlab/attitude.h"
#include "driftlab/elementary.h"
#include "driftlab/trajectory.h"

namespace driftlab::trajectory_detail {

constexpr double kDynamicSubstep_s = 0.01;
constexpr double kUniformSubstep_s = 1.0;

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
inline void SinCosVia(TrigMemo* memo, TrigMemo::Slot slot, double x, double* s, double* c) {
  if (memo != nullptr) {
    memo->SinCos(slot, x, s, c);
  } else {
    math::SinCos(x, s, c);
  }
}

inline EulerTrig EulerTrigVia(TrigMemo* memo, const EulerAngles& e) {
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

}  // namespace driftlab::trajectory_detail
