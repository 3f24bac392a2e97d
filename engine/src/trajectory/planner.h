// The planner: turns a motion's segments (or its truth profile) into kinematic pieces, checking
// each segment's fields as it plans it. Private to the trajectory generator.
#pragma once

#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "driftlab/earth.h"
#include "driftlab/trajectory.h"
#include "trajectory/pieces.h"

namespace driftlab::trajectory_detail {

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

// Where a part of the planned motion comes from: it starts at t_s [s]; `field` names it in
// messages.
struct SegmentOrigin {
  double t_s = 0.0;
  std::string field;
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

  void Plan();
  double duration() const { return state_.t; }
  // Each segment's start time [s] and the field a message about it names (its path, or for a
  // gnss-ins-sim command read from a file, the file and line), in the segments' order.
  const std::vector<SegmentOrigin>& origins() const { return origins_; }

 private:
  // Start values of the parametric model.
  void TrackStart(double* V, double* chi, double* v_down) const;
  TrackPiece TrackTemplate(double V, double chi, double v_down, double dchi0) const;
  void Add(double duration, const TrackPiece& p);
  void CheckFlightPath(const std::string& path, double V_min, double v_down) const;
  void PlanSegment(const StaticSegment& s, const std::string& path);
  void PlanSegment(const ConstantVelocitySegment& s, const std::string& path);
  void PlanSegment(const AccelerateSegment& s, const std::string& path);

  // Turn pieces: rate ramps 0 -> omega over transition_s, holds for hold_s, ramps back to 0. All
  // pieces share the attitude offsets fixed at the turn's start (chi' = 0 there).
  void AddTurn(double omega, double transition_s, double hold_s);
  // Turns and figure eights: at most 720 deg/s, given as a rate or implied by radius and speed.
  static constexpr double kMaxTurnRate_rad_per_s = 4.0 * M_PI;
  // A turn's rate as a turn or a figure-eight segment gives it: exactly one of rate_rad_per_s and
  // radius_m (the caller checks that), and the ramp time transition_s.
  struct TurnRateSpec {
    std::optional<double> rate_rad_per_s;
    std::optional<double> radius_m;
    bool right = true;        // a radius turns right (omega > 0) or left
    bool either_sign = true;  // a rate may be negative (a turn) or must be positive (figure eight)
    double transition_s = 0.0;
    const char* radius_at_rest_allowed = "";  // what a radius at ground speed 0 is told is allowed
  };
  // The turn rate omega [rad/s] of `turn` at ground speed V [m/s]: the rate, or +-V / radius_m. The
  // rate, given or implied, is at most kMaxTurnRate_rad_per_s; transition_s is checked too (>= 0,
  // and > 0 with vehicle.coordinated_turns). Messages name base + ".rate_deg_per_s", ".radius_m",
  // ".transition_s".
  double TurnRate(const std::string& base, const TurnRateSpec& turn, double V) const;
  void PlanSegment(const TurnSegment& s, const std::string& path);
  void PlanSegment(const ClimbSegment& s, const std::string& path);
  void PlanSegment(const ZigzagSegment& s, const std::string& path);

  // A periodic motion sampled at rate_hz: the Nyquist limit is 2 samples per period; a period of
  // fewer than kMinSamplesPerPeriod samples would alias in the output.
  static constexpr double kMinSamplesPerPeriod = 4.0;
  void CheckSampledPeriod(const std::string& field, double period_s) const;
  void PlanSegment(const ShipMotionSegment& s, const std::string& path);
  void PlanSegment(const FigureEightSegment& s, const std::string& path);

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

  static Vector3d Clip(const Vector3d& x, double limit);
  void CloseRun();
  void ExecutorStep();
  void PlanSegment(const GnssInsSimCommand& cmd, const std::string& path);

  // Ends a block of consecutive gnss-ins-sim commands; `drop_last_step` when the motion ends with
  // it (gnss-ins-sim's output stops at the state before the executor's last step).
  void FinishExecutor(bool drop_last_step);
  std::vector<SegmentOrigin> origins_;
  const MotionSpec& motion_;
  std::vector<Piece>* pieces_;
  std::vector<std::pair<double, double>>* gps_invisible_s_;
  PlanState state_;
  Executor exec_;
  double rate_hz_ = 1.0;
  double dt_s_ = 1.0;
  double g_m_per_s2_ = 9.8;
};

// The truth profile's samples as not-a-knot cubic splines of velocity and attitude (one piece
// per interval); checks the samples (finite, times increasing, duration within the limit).
void PlanTruthProfile(const MotionSpec& motion, std::vector<Piece>* pieces);

// A truth profile's positions against its velocities: between consecutive samples i, i+1 the
// displacement from their positions (NED metres at sample i, env.PositionErrorNed) must agree with
// the integral of the velocity splines (the motion the generator integrates: its positions after
// the first sample come from the velocities) within 10 m + 10 % of the displacement. A sampled
// smooth motion meets it by orders of magnitude (the spline's error is O(h^4) of the velocity's
// third derivative); a position jump (a wrong row, degrees read as radians) does not. Throws
// SpecError naming `truth_profile[i+1]`.
void CheckTruthProfilePositions(const MotionSpec& motion, const NavEnvironment& env,
                                const std::vector<Piece>& pieces);

// Limits of the planned motion, whatever its source (segments, a gnss-ins-sim file, a truth
// profile), checked on the pieces at every sub-step (the generator's integration grid) and at
// their ends:
//  - |pitch| < 89.9 deg: at +-90 deg roll and yaw are undefined (the Euler angles' gimbal lock) and
//    the roll, pitch and yaw errors of the results lose their meaning; not an error of the motion
//    (the truth is valid through it): the first place is returned in *singularity;
//  - body angular rate |omega_nb_b| <= 100 rad/s (the gnss-ins-sim commands' rate limit);
//  - acceleration |dv_eb_n/dt| <= 1000 m/s^2 (the segments' and commands' acceleration limit).
// Throws SpecError naming the origin in which the offending piece starts (`origins` ascending in
// time, the first at 0) and the time reached.
void CheckPlannedKinematics(const std::vector<Piece>& pieces,
                            const std::vector<SegmentOrigin>& origins,
                            std::optional<TrajectoryGenerator::EulerSingularity>* singularity);

}  // namespace driftlab::trajectory_detail
