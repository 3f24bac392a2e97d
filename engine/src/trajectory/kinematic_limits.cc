// Limits of the planned motion (planner.h, CheckPlannedKinematics).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "driftlab/attitude.h"
#include "driftlab/units.h"
#include "trajectory/motion_checks.h"
#include "trajectory/planner.h"

namespace driftlab::trajectory_detail {

namespace {

constexpr double kMaxPlannedPitch_deg = 89.9;
constexpr double kMaxPlannedBodyRate_rad_per_s = 100.0;
constexpr double kMaxPlannedAcceleration_m_per_s2 = 1000.0;

void CheckAt(const Piece& piece, double t, const std::string& field,
             std::optional<TrajectoryGenerator::EulerSingularity>* singularity) {
  const Kinematics k = piece.Evaluate(t);
  const double pitch_deg = k.euler.pitch_rad * kRadToDeg;
  if (!(std::abs(pitch_deg) < kMaxPlannedPitch_deg) && !singularity->has_value()) {
    *singularity = TrajectoryGenerator::EulerSingularity{
        field, "the motion reaches pitch " + CompactText(pitch_deg) +
                   " deg at t = " + CompactText(t) +
                   " s; allowed: |pitch| < 89.9 deg (at +-90 deg roll and yaw are undefined and "
                   "their error statistics meaningless)"};
  }
  const double rate = EulerRatesToBodyRate(k.euler, k.euler_rates).norm();
  if (!(rate <= kMaxPlannedBodyRate_rad_per_s)) {
    RejectText(field, "the motion turns at " + CompactText(rate * kRadToDeg) +
                          " deg/s at t = " + CompactText(t) + " s; allowed: at most " +
                          CompactText(kMaxPlannedBodyRate_rad_per_s * kRadToDeg) + " deg/s");
  }
  const double acceleration = k.a_eb_n.norm();
  if (!(acceleration <= kMaxPlannedAcceleration_m_per_s2)) {
    RejectText(field, "the motion accelerates at " + CompactText(acceleration) +
                          " m/s^2 at t = " + CompactText(t) + " s; allowed: at most " +
                          CompactText(kMaxPlannedAcceleration_m_per_s2) + " m/s^2");
  }
}

bool IsUniform(const Piece& piece) {
  if (const auto* p = std::get_if<TrackPiece>(&piece.kin)) return p->Uniform();
  if (const auto* p = std::get_if<BodyPiece>(&piece.kin)) return p->Uniform();
  return false;
}

}  // namespace

void CheckPlannedKinematics(const std::vector<Piece>& pieces,
                            const std::vector<SegmentOrigin>& origins,
                            std::optional<TrajectoryGenerator::EulerSingularity>* singularity) {
  size_t origin = 0;
  for (const Piece& piece : pieces) {
    while (origin + 1 < origins.size() && origins[origin + 1].t_s <= piece.t0) ++origin;
    const std::string& field = origins.empty() ? std::string() : origins[origin].field;
    const double span = piece.t1 - piece.t0;
    // Uniform pieces have constant rates and attitude: their ends suffice.
    const int64_t n =
        IsUniform(piece)
            ? 1
            : std::max<int64_t>(1, static_cast<int64_t>(std::ceil(span / piece.max_substep_s)));
    for (int64_t i = 0; i < n; ++i) {
      CheckAt(piece, piece.t0 + span * static_cast<double>(i) / static_cast<double>(n), field,
              singularity);
    }
    // The end as its left limit (the piece's own closed form at t1).
    CheckAt(piece, piece.t1, field, singularity);
  }
}

}  // namespace driftlab::trajectory_detail
