// Checks of a motion specification's fields: each rejects with a SpecError naming the field path,
// the value and the allowed range (spec_error.h). Private to the trajectory generator.
#pragma once

#include <string>

#include "driftlab/trajectory.h"

namespace driftlab::trajectory_detail {

// WGS-84 navigation is limited to |L| < 89.9 deg: tan L and 1 / cos L in the transport rate and the
// longitude rate grow without bound at the pole.
constexpr double kMaxWgs84Latitude_deg = 89.9;
// Height range of the normal-gravity model's free-air expansion (earth.h) with margin.
constexpr double kMinHeight_m = -1.0e4;
constexpr double kMaxHeight_m = 1.0e5;
constexpr double kMaxSpeed_m_per_s = 1.0e4;

// Shortest text that parses back to the same double ("nan", "inf" for the non-finite).
std::string CompactText(double x);
[[noreturn]] void Reject(const std::string& field, double value, const std::string& allowed);
[[noreturn]] void RejectText(const std::string& field, const std::string& message);
void CheckFinite(const std::string& field, double value);
// 0 < value <= hi.
void CheckPositive(const std::string& field, double value, double hi, const std::string& unit);
// 0 < value <= kMaxDuration_s.
void CheckDuration(const std::string& field, double value);
// 0 <= value <= hi.
void CheckNonNegative(const std::string& field, double value, double hi, const std::string& unit);

// Latitude (within the Earth model's navigable range), longitude and height of `path`.
void ValidateLlh(const std::string& path, const Llh& llh, EarthModel model);
// The motion's rate, Earth model, initial state, and gnss-ins-sim limits (not its segments,
// which the planner checks as it plans them).
void ValidateMotionHeader(const MotionSpec& motion, double rate_hz);

}  // namespace driftlab::trajectory_detail
