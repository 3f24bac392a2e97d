// Checks of a motion specification's fields (motion_checks.h).
#include "trajectory/motion_checks.h"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <string>

#include "driftlab/spec_error.h"
#include "driftlab/units.h"

namespace driftlab::trajectory_detail {

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

}  // namespace driftlab::trajectory_detail
