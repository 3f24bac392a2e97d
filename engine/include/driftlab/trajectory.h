// Trajectory generator: a motion (initial state + segments, or an imported motion file) turned
// into a truth trajectory and ideal IMU data at a fixed output rate.
//
// Physics. Every segment defines the vehicle's Euler angles and NED velocity as smooth functions
// of time with analytic first derivatives (continuous across segment boundaries). From them:
//   omega_ib_b = omega_nb_b + C_n_b (omega_ie_n + omega_en_n)                   Groves (5.40)
//   f_ib_b     = C_n_b (dv_eb_n/dt - g_b_n + (omega_en_n + 2 omega_ie_n) x v_eb_n)   Groves (5.54)
// with omega_nb_b from the Euler-angle rates. Position (L, lambda, h) is integrated from the
// velocity with Groves (2.111). Ideal IMU increments are the integrals of omega_ib_b and f_ib_b
// over each output interval, computed with Gauss-Legendre quadrature on internal sub-steps that are
// split at every breakpoint of the kinematics, so they are exact to rounding for the smooth pieces
// (and therefore contain the coning and sculling a real integrating IMU sees).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "driftlab/attitude.h"
#include "driftlab/earth.h"
#include "driftlab/nav_state.h"

namespace driftlab {

// ---- Motion definition -------------------------------------------------------------------------

struct InitialState {
  Llh llh;                             // [rad, rad, m]
  Vector3d v_eb_n = Vector3d::Zero();  // [m/s] NED
  EulerAngles attitude;                // [rad]
};

// How the vehicle's attitude follows its velocity in the parametric segments. The parametric model
// is v_eb_n = [V cos chi, V sin chi, v_D] with ground speed V, track angle chi (initially
// atan2(v_E, v_N), or the yaw when V = 0) and down velocity v_D; the yaw follows the track
// (yaw - chi constant), the pitch and roll are held unless the options below say otherwise. The
// offsets (yaw - chi, pitch - flight-path angle, roll - bank) are fixed at each segment's start, so
// the attitude is always continuous.
struct VehicleOptions {
  // Aircraft: bank angle phi = atan(V * turn_rate / g) in turns (coordinated turn).
  // Cars and ships: no bank in turns.
  bool coordinated_turns = false;
  // Aircraft: pitch follows the flight-path angle atan2(v_up, ground speed) in climbs.
  bool pitch_follows_flight_path = false;
};

// Hold still (speed must be zero when it starts).
struct StaticSegment {
  double duration_s = 0.0;
};

// Change along-track speed at a constant rate; heading, vertical speed and attitude held.
// Exactly one of duration_s or target_speed_m_per_s is set; acceleration_m_per_s2 > 0 is the
// magnitude, the sign follows from the target (or, with duration_s, is given by `decelerate`).
struct AccelerateSegment {
  double acceleration_m_per_s2 = 0.0;
  std::optional<double> target_speed_m_per_s;
  std::optional<double> duration_s;
  bool decelerate = false;  // only with duration_s
};

struct ConstantVelocitySegment {
  double duration_s = 0.0;
};

// Turn at a constant rate (positive = clockwise seen from above, i.e. yaw increasing) entered and
// left with a linear ramp of the turn rate over transition_s. Rate given directly or by radius and
// direction at the current ground speed. Length given by the heading change or by duration.
struct TurnSegment {
  std::optional<double> rate_rad_per_s;
  std::optional<double> radius_m;  // with `right`
  bool right = true;
  std::optional<double> angle_rad;  // total heading change magnitude, > 0
  std::optional<double> duration_s;
  double transition_s = 0.0;
};

// Climb (climb_rate_m_per_s > 0) or descend (< 0): vertical speed ramps from its current value to
// the climb rate at vertical_acceleration_m_per_s2, holds, and ramps back, so that the height
// changes by height_change_m (or for duration_s in total).
struct ClimbSegment {
  double climb_rate_m_per_s = 0.0;
  double vertical_acceleration_m_per_s2 = 0.5;
  std::optional<double> height_change_m;
  std::optional<double> duration_s;
};

// S-shaped weave (seed 002's zigzag): track angle chi = chi_0 + A sin(2 pi t / period), with the
// heading amplitude A set from the lateral amplitude: lateral half-excursion = V A period / (2 pi).
struct ZigzagSegment {
  double amplitude_m = 0.0;
  double period_s = 0.0;
  double duration_s = 0.0;
};

// Ship in a seaway (seed 000's vessel): sinusoidal roll, pitch, yaw and heave superimposed on the
// current motion, faded in and out with a raised-cosine envelope over ramp_s so that attitude and
// velocity stay continuous. heave is displacement, positive up.
struct ShipMotionSegment {
  double duration_s = 0.0;
  double roll_amplitude_rad = 0.0, roll_period_s = 1.0, roll_phase_rad = 0.0;
  double pitch_amplitude_rad = 0.0, pitch_period_s = 1.0, pitch_phase_rad = 0.0;
  double yaw_amplitude_rad = 0.0, yaw_period_s = 1.0, yaw_phase_rad = 0.0;
  double heave_amplitude_m = 0.0, heave_period_s = 1.0, heave_phase_rad = 0.0;
  double ramp_s = 0.0;
};

// Figure-eight: a full circle one way, then a full circle the other, at the current speed.
struct FigureEightSegment {
  std::optional<double> radius_m;
  std::optional<double> rate_rad_per_s;  // magnitude
  double transition_s = 0.0;
  int loops = 1;  // number of figure-eights
};

// One command line of a gnss-ins-sim motion-definition file (after the initial-state line).
// Angles are converted to radians; the file's column order is (yaw, pitch, roll) and the velocity
// is in the body frame (forward-right-down).
//
// Meaning of the types (gnss-ins-sim README, "Motion definition", and the docstring of
// gnss_ins_sim/pathgen/pathgen.py, github.com/Aceinna/gnss-ins-sim):
//   1: Euler-angle rates [rad/s] and body-frame acceleration [m/s^2], held for duration_s.
//   2: absolute attitude and absolute body velocity to reach.
//   3: attitude change and body-velocity change.
//   4: absolute attitude and body-velocity change.
//   5: attitude change and absolute body velocity.
// For types 2-5 duration_s is the maximum time: the next command starts as soon as the target is
// reached, or after duration_s if it is not reached by then.
//
// Execution reproduces gnss-ins-sim's own executor (pathgen.py path_gen(), commit 966ff27; see
// trajectory.cc): a discrete loop at the simulation rate, which is the job's rate_hz as in
// gnss-ins-sim (its simulation rate is its IMU rate). Type-1 rates and accelerations pass a
// first-order low-pass filter (0.9 per step); types 2-5 track the target with a low-pass-filtered
// velocity command and a PD controller on the Euler angles (kp 5, kd 10) under the
// GnssInsSimLimits, and end early once both |att - target| < 1e-4 rad and |v_b - target| < 1e-4
// m/s. A command runs at most round(duration_s * rate_hz) steps, so the motion depends on the
// rate, exactly as gnss-ins-sim's does. Absolute targets are taken literally against the
// accumulated (unwrapped) Euler angles. The state is held constant-rate over each step and the
// truth and IMU increments are integrated exactly from those pieces; a motion made only of these
// commands ends at gnss-ins-sim's last output sample (one step before its executor's last step).
struct GnssInsSimCommand {
  int type = 1;                           // 1..5, gnss-ins-sim's documented meaning
  Vector3d euler_ypr = Vector3d::Zero();  // rad or rad/s depending on type (yaw, pitch, roll)
  Vector3d v_b = Vector3d::Zero();        // m/s or m/s^2 depending on type
  double duration_s = 0.0;  // duration (type 1) or maximum duration (types 2-5); 0: no step
  bool gps_visible = true;
  // Where the command came from, e.g. "motion_def.csv:5", used as the field path of errors; empty
  // for commands built in code (then the path is "<motion>.segments[i].gnss_ins_sim").
  std::string source;
};

// Limits that gnss-ins-sim applies to commands of types 2-5. Defaults are that tool's built-in
// 'high_mobility' mode, used when no mode is given: gnss_ins_sim/sim/ins_sim.py defines
// `high_mobility = np.array([1.0, 0.5, 2.0])   # m/s/s, rad/s/s, rad/s` and Sim.__parse_mode()
// returns it unconverted for mode=None, so the defaults are 1 m/s^2, 0.5 rad/s^2 (28.6 deg/s^2)
// and 2 rad/s (114.6 deg/s). (A user-given mode array is in [m/s^2, deg/s^2, deg/s] and is
// converted; the README's example passes mode=[1.0, 0.5, 2.0], i.e. 0.5 deg/s^2 and 2 deg/s.)
// Each limit applies per channel: per body axis for the acceleration, per Euler angle for the
// angular acceleration and rate (pathgen.py clips each component). Type-1 commands are not
// limited by them (as in gnss-ins-sim) but must stay below 100 rad/s and 1000 m/s^2.
struct GnssInsSimLimits {
  double max_acceleration_m_per_s2 = 1.0;
  double max_angular_acceleration_rad_per_s2 = 0.5;
  double max_angular_rate_rad_per_s = 2.0;
};

// A truth profile (Groves' motion-profile layout): samples of time, LLH, NED velocity, attitude.
// The kinematics between samples are the C^2 cubic-spline interpolants of velocity and Euler
// angles; position is integrated from the interpolated velocity (the file's positions are only
// checked).
struct TruthProfileSample {
  double t_s = 0.0;
  Llh llh;
  Vector3d v_eb_n = Vector3d::Zero();
  EulerAngles attitude;
};

using Segment = std::variant<StaticSegment, AccelerateSegment, ConstantVelocitySegment, TurnSegment,
                             ClimbSegment, ZigzagSegment, ShipMotionSegment, FigureEightSegment,
                             GnssInsSimCommand>;

struct MotionSpec {
  EarthModel earth_model = EarthModel::kWgs84;
  // Flat frame only: the constant gravity; if unset, normal gravity at the initial point.
  std::optional<double> flat_gravity_m_per_s2;
  InitialState initial;
  VehicleOptions vehicle;
  std::vector<Segment> segments;  // parametric / gnss-ins-sim commands, in order
  GnssInsSimLimits gnss_ins_sim_limits;
  std::vector<TruthProfileSample> truth_profile;  // if non-empty: the whole motion (no segments)
  // Field-path prefix used in SpecError messages, e.g. "motion".
  std::string field_path = "motion";
};

// Output-rate limits of the generator (1-2000 Hz, durations up to 100,000 s).
inline constexpr double kMinRate_hz = 1.0;
inline constexpr double kMaxRate_hz = 2000.0;
inline constexpr double kMaxDuration_s = 100000.0;

// ---- Generated data ----------------------------------------------------------------------------

// One output step k >= 1: the truth at t_k, the ideal increment over (t_{k-1}, t_k], and the point
// sample at t_k (at a kink of the kinematics: the left limit, i.e. the end of the piece that ends
// at t_k).
struct TrajectorySample {
  NavState truth;
  ImuIncrement increment;
  ImuSample sample;
};

// Streaming generator: memory O(1) in the trajectory length.
class TrajectoryGenerator {
 public:
  // Validates the motion (throws SpecError naming the field) and plans the segments.
  TrajectoryGenerator(const MotionSpec& motion, double rate_hz);
  ~TrajectoryGenerator();
  TrajectoryGenerator(TrajectoryGenerator&&) noexcept;
  TrajectoryGenerator& operator=(TrajectoryGenerator&&) noexcept;

  const NavEnvironment& environment() const;
  double rate_hz() const;
  double dt_s() const;
  double duration_s() const;
  // Number of output intervals: floor(duration * rate + 1e-9).
  int64_t num_steps() const;
  // Truth and point sample at t = 0.
  const NavState& initial_state() const;
  const ImuSample& initial_sample() const;
  // Times at which the kinematics have a kink (segment boundaries, ramp ends), sorted; interior
  // times only (0 and the end are not listed).
  const std::vector<double>& breakpoints_s() const;
  // Time windows [start_s, end_s) of the gnss-ins-sim commands whose GPS-visibility column is 0
  // (the times of their executor steps), ascending and merged, clipped to the duration; empty for
  // other motions. A job with GNSS aiding turns them into outages.
  const std::vector<std::pair<double, double>>& gps_invisible_s() const;
  // Where the planned motion first reaches |pitch| >= 89.9 deg, if it does: the field that
  // planned it (segment path, gnss-ins-sim file and line, truth-profile row) and the message. There
  // roll and yaw are undefined, so Euler-angle errors lose their meaning; the truth and the IMU
  // data are valid through it (ValidateMonteCarloSpec refuses such a motion).
  struct EulerSingularity {
    std::string field;
    std::string message;
  };
  const std::optional<EulerSingularity>& euler_singularity() const;
  // True while the vehicle is static (speed and angular rate w.r.t. the Earth both exactly zero) at
  // t, in [0, duration]; left-continuous like the point samples (true at the end time of a static
  // segment).
  bool IsStaticAt(double t_s) const;

  // Advances one output step; false when the trajectory has ended.
  bool Next(TrajectorySample* out);
  // Whether Next computes the point sample (TrajectorySample::sample; default true). A caller that
  // only uses the increments and the truth (the free-inertial NED runs) turns it off to save the
  // generator that work; Next then leaves out->sample as it is. Nothing else changes.
  void set_point_samples(bool on);
  // Steps produced so far.
  int64_t step() const;

 private:
  struct Impl;
  Impl* impl_;
};

// Whole trajectory in memory: truth[0..n], samples[0..n] at t_k = k dt, increments[0..n-1] where
// increments[k] covers (t_k, t_{k+1}].
struct Trajectory {
  NavEnvironment environment;
  double dt_s = 0.0;
  std::vector<NavState> truth;
  std::vector<ImuSample> samples;
  std::vector<ImuIncrement> increments;
};

Trajectory GenerateTrajectory(const MotionSpec& motion, double rate_hz);

}  // namespace driftlab
