// The Earth model's constants as plain data, with no library types: the WGS-84 defining and derived
// constants (the one set: the scalar Earth model, earth.h, and the Earth functions written over the
// lane width, engine/src/earth/earth_lanes.h, both read them) and a navigation environment's
// parameters (NavEnvironment, earth.h). Included by the lockstep kernel files, which must not share
// inline code with the rest of the engine (engine/src/lanes/lane.h).
//
// References: NIMA TR8350.2 (WGS-84, 3rd ed., 2000), tables 3.1 and 3.3.
#pragma once

namespace driftlab {

// WGS-84 defining and derived constants (NIMA TR8350.2 tables 3.1 and 3.3).
inline constexpr double kWgs84SemiMajorAxis_m = 6378137.0;       // a, R_0
inline constexpr double kWgs84Flattening = 1.0 / 298.257223563;  // f
inline constexpr double kWgs84Eccentricity2 =                    // e^2 = f (2 - f)
    kWgs84Flattening * (2.0 - kWgs84Flattening);
inline constexpr double kWgs84SemiMinorAxis_m =  // b = a (1 - f)
    kWgs84SemiMajorAxis_m * (1.0 - kWgs84Flattening);
inline constexpr double kWgs84EarthRate_rad_per_s = 7.292115e-5;     // omega_ie
inline constexpr double kWgs84GM_m3_per_s2 = 3.986004418e14;         // mu
inline constexpr double kWgs84GammaEquator_m_per_s2 = 9.7803253359;  // normal gravity, L = 0
inline constexpr double kWgs84GammaPole_m_per_s2 = 9.8321849378;     // normal gravity, L = 90 deg

// Standard gravity (CGPM 1901), used only for converting g-based datasheet units.
inline constexpr double kStandardGravity_m_per_s2 = 9.80665;

// The navigation environment (NavEnvironment) as the lane code reads it: WGS-84 (flat = 0), or the
// flat local frame (flat = 1) with its constant radii, which scale metres to latitude and
// longitude, and its constant gravity.
struct EarthParams {
  int flat = 0;
  double flat_R_N_m = 0.0, flat_R_E_m = 0.0, flat_gravity_m_per_s2 = 0.0;
};

}  // namespace driftlab
