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
#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "driftlab/elementary.h"
#include "driftlab/units.h"
#include "trajectory/motion_checks.h"
#include "trajectory/pieces.h"
#include "trajectory/planner.h"

namespace driftlab {

using namespace trajectory_detail;

namespace {

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
  std::optional<EulerSingularity> euler_singularity;
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
  std::vector<SegmentOrigin> origins;
  if (motion.truth_profile.empty()) {
    Planner planner(motion, m.env, rate_hz, &m.pieces, &m.gps_invisible_s);
    planner.Plan();
    m.duration_s = planner.duration();
    origins = planner.origins();
  } else {
    PlanTruthProfile(motion, &m.pieces);
    m.duration_s = m.pieces.back().t1;
    for (size_t i = 0; i < m.pieces.size(); ++i) {
      origins.push_back(SegmentOrigin{
          m.pieces[i].t0, motion.field_path + ".truth_profile[" + std::to_string(i) + "]"});
    }
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
  // After the duration checks: the limits are checked at every sub-step of the motion.
  CheckPlannedKinematics(m.pieces, origins, &m.euler_singularity);
  if (!motion.truth_profile.empty()) CheckTruthProfilePositions(motion, m.env, m.pieces);
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
const std::optional<TrajectoryGenerator::EulerSingularity>& TrajectoryGenerator::euler_singularity()
    const {
  return impl_->euler_singularity;
}

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
