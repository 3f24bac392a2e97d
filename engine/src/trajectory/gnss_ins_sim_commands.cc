// The planner's gnss-ins-sim motion-command executor (the model is described at the executor's
// members in planner.h).
#include <cmath>
#include <string>

#include "driftlab/elementary.h"
#include "driftlab/units.h"
#include "trajectory/motion_checks.h"
#include "trajectory/planner.h"

namespace driftlab::trajectory_detail {

Vector3d Planner::Clip(const Vector3d& x, double limit) {
  Vector3d y = x;
  for (int i = 0; i < 3; ++i) {
    if (y(i) > limit) y(i) = limit;
    if (y(i) < -limit) y(i) = -limit;
  }
  return y;
}

void Planner::CloseRun() {
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
      Vector3d(att_end(2) - x.run_att(2), att_end(1) - x.run_att(1), att_end(0) - x.run_att(0)) / T;
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

void Planner::ExecutorStep() {
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

void Planner::PlanSegment(const GnssInsSimCommand& cmd, const std::string& path) {
  // Field of one column: "<segments path>.gnss_ins_sim.<column>" or "<file>:<line> (<column>)".
  auto field = [&](const char* column) {
    return cmd.source.empty() ? path + ".gnss_ins_sim." + column : cmd.source + " (" + column + ")";
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

void Planner::FinishExecutor(bool drop_last_step) {
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

}  // namespace driftlab::trajectory_detail
