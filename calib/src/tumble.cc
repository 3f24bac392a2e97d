#include "driftlab/calib/tumble.h"

#include <fmt/format.h>

#include <array>
#include <cmath>

#include "driftlab/attitude.h"
#include "driftlab/earth.h"
#include "driftlab/nav_state.h"
#include "driftlab/sensors.h"
#include "driftlab/spec_error.h"

namespace driftlab::calib {
namespace {

struct Turn {
  std::array<double, 3> axis;
  double angle_deg;
};
// Axes and angles cycled through; their spread over the sphere is checked in
// multi_position_test.cc (pose-direction singular values > 0.4 for 9..24 poses).
constexpr std::array<Turn, 7> kTurns = {{{{1, 0, 0}, 90},
                                         {{0, 1, 0}, 120},
                                         {{0, 0, 1}, -90},
                                         {{1, 1, 0}, 135},
                                         {{0, 1, 1}, 100},
                                         {{1, 0, 1}, -150},
                                         {{1, -1, 1}, 80}}};

void Require(bool ok, const std::string& field, double value, const std::string& allowed) {
  if (!ok) throw SpecError("tumble." + field, fmt::format("{}", value), allowed);
}

}  // namespace

Tumble SimulateTumble(const TumbleSpec& spec, const ImuErrorModel& model, uint64_t seed,
                      uint32_t run_index) {
  Require(spec.rate_hz >= 1.0 && spec.rate_hz <= 1e5, "rate_hz", spec.rate_hz, "[1, 1e5] Hz");
  Require(spec.initial_static_s > 0.0 && spec.initial_static_s < 1e5, "initial_static_s",
          spec.initial_static_s, "(0, 1e5) s");
  Require(spec.pose_s > 0.0 && spec.pose_s < 1e5, "pose_s", spec.pose_s, "(0, 1e5) s");
  Require(spec.rotation_s * spec.rate_hz >= 2.0 && spec.rotation_s < 1e3, "rotation_s",
          spec.rotation_s, ">= 2 samples and < 1000 s");
  Require(spec.pose_count >= 1 && spec.pose_count <= 10000, "pose_count", spec.pose_count,
          "[1, 10000]");
  Require(std::abs(spec.lat_rad) <= 0.5 * M_PI, "lat_rad", spec.lat_rad, "[-pi/2, pi/2]");
  ImuErrorSimulator sim(model, seed, run_index, spec.rate_hz);
  Tumble out;
  out.T_a = sim.accel().scale_misalignment();
  out.b_a = sim.accel().constant_bias();
  out.T_g = sim.gyro().scale_misalignment();
  out.b_g = sim.gyro().constant_bias();
  const double dt = 1.0 / spec.rate_hz;
  const Eigen::Vector3d g_n = GravityNed(spec.lat_rad, spec.h_m);
  const Eigen::Vector3d omega_ie_n =
      spec.earth_rate ? EarthRateNed(spec.lat_rad) : Eigen::Vector3d::Zero();
  const int64_t n_init = std::llround(spec.initial_static_s * spec.rate_hz);
  const int64_t n_pose = std::llround(spec.pose_s * spec.rate_hz);
  const int64_t n_rot = std::llround(spec.rotation_s * spec.rate_hz);
  const int64_t total = n_init + (spec.pose_count - 1) * (n_rot + n_pose);
  auto& rec = out.recording;
  rec.t_s.reserve(total);
  rec.omega_ib_s.reserve(total);
  rec.f_ib_s.reserve(total);
  Eigen::Matrix3d C_b_n = EulerToDcm({0.0, 0.0, spec.initial_yaw_rad});
  ImuSample ideal, measured;
  int64_t k = 0;
  auto emit = [&](const Eigen::Matrix3d& C, const Eigen::Vector3d& omega_nb_b) {
    ideal.omega_ib_b = C.transpose() * omega_ie_n + omega_nb_b;
    ideal.f_ib_b = -C.transpose() * g_n;
    sim.Apply(ideal, &measured);
    rec.t_s.push_back(static_cast<double>(k) * dt);
    rec.omega_ib_s.push_back(measured.omega_ib_b);
    rec.f_ib_s.push_back(measured.f_ib_b);
    ++k;
  };
  out.C_b_n.push_back(C_b_n);
  for (int64_t i = 0; i < n_init; ++i) emit(C_b_n, Eigen::Vector3d::Zero());
  for (int p = 1; p < spec.pose_count; ++p) {
    const Turn& turn = kTurns[(p - 1) % kTurns.size()];
    const Eigen::Vector3d down_b = C_b_n.transpose() * Eigen::Vector3d::UnitZ();
    Eigen::Vector3d u(turn.axis[0], turn.axis[1], turn.axis[2]);
    u -= u.dot(down_b) * down_b;
    u.normalize();
    const double angle = turn.angle_deg * M_PI / 180.0;
    const double rate = angle / (static_cast<double>(n_rot) * dt);
    // Rotation over (t_s + dt/2, t_s + (n_rot + 1/2) dt): sample j (1..n_rot) at t_s + j dt sees
    // the attitude rotated by rate (j - 1/2) dt.
    for (int64_t j = 1; j <= n_rot; ++j) {
      const double theta = rate * (static_cast<double>(j) - 0.5) * dt;
      emit(C_b_n * RotationVectorToDcm(u * theta), u * rate);
    }
    C_b_n = C_b_n * RotationVectorToDcm(u * angle);
    out.C_b_n.push_back(C_b_n);
    for (int64_t i = 0; i < n_pose; ++i) emit(C_b_n, Eigen::Vector3d::Zero());
  }
  return out;
}

}  // namespace driftlab::calib
