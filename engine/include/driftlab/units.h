// Datasheet units at the edge of the engine (DESIGN.md invariant 1): parse quantities such as
// "0.15 deg/√h", "25 µg/√Hz", "10 deg/h", "300 ppm" into SI, and print SI values in a chosen unit.
//
// A unit is a product of base symbols with rational exponents, e.g. "(deg/h)/sqrt(Hz)" =
// deg^1 h^-1 Hz^-1/2. Each symbol carries an exact SI factor and a dimension over three base
// quantities: plane angle (rad, kept separate so that rad/s and Hz are not confused), length (m)
// and time (s). So "(deg/s)/sqrt(Hz)", "deg/sqrt(s)", "deg/√h" and "deg/rt-hr" all have the
// dimension angle * time^-1/2 (angle random walk) and convert by 1 (deg/s)/√Hz = 1 deg/√s
// = 60 deg/√h (seed 001). "g" is standard gravity, 9.80665 m/s^2 exactly (CGPM 1901,
// kStandardGravity_m_per_s2 in earth.h).
//
// Grammar (whitespace ignored except as a separator):
//   unit    := product
//   product := power (('/' | '*' | '·' | juxtaposition) power)*    left-associative: a/b/c = a b^-1
//   c^-1 power   := factor [exponent] factor  := symbol | '(' product ')' | ('sqrt' | '√' | 'rt'
//   ['-']) factor exponent:= '^' ['('] ['-'|'+'] int ['/' int | '.5'] [')'] | trailing digits
//   ("s2") | '²' | '³'
// Symbols (ASCII and Unicode):
//   angle  rad, mrad, urad/µrad, deg/degree(s)/°/º, mdeg, arcmin, arcsec
//   time   s/sec, ms, us/µs, min, h/hr/hour(s)            frequency  Hz, kHz
//   length m, mm, km, ft, nmi                             acceleration g, mg, ug/µg/μg, ng, gal,
//   mgal ratio  ppm, ppb, %, dimensionless "" or "1" shorthand dph = deg/h, dps = deg/s
// Reference for the definitions: BIPM SI Brochure (9th ed., 2019) tables 4 and 8; IEEE Std
// 952-1997 and 1293-1998 for the inertial-sensor units.
#pragma once

#include <cstddef>
#include <numbers>
#include <string>
#include <string_view>

namespace driftlab {

// Degrees and radians: pi / 180 and its inverse, each rounded once to double.
inline constexpr double kDegToRad = std::numbers::pi / 180.0;
inline constexpr double kRadToDeg = 180.0 / std::numbers::pi;

// Limits of a unit text (hostile input is bounded before the work; DESIGN.md invariant 10): its
// length and the nesting of parentheses and square roots. Real units ("((deg/h)/sqrt(Hz))") use 2
// or 3 levels.
inline constexpr size_t kMaxUnitTextBytes = 128;
inline constexpr int kMaxUnitNesting = 8;

// Dimension as exponents, in halves, of plane angle, length and time.
struct Dimension {
  int angle2 = 0;   // 2 x exponent of rad
  int length2 = 0;  // 2 x exponent of m
  int time2 = 0;    // 2 x exponent of s
  friend bool operator==(const Dimension&, const Dimension&) = default;
};

namespace dims {
inline constexpr Dimension kDimensionless{0, 0, 0};         // ppm, %
inline constexpr Dimension kAngle{2, 0, 0};                 // rad
inline constexpr Dimension kAngularRate{2, 0, -2};          // rad/s
inline constexpr Dimension kAngularAcceleration{2, 0, -4};  // rad/s^2 (rate ramp)
inline constexpr Dimension kAngleRandomWalk{2, 0, -1};      // rad/sqrt(s) = (rad/s)/sqrt(Hz)
inline constexpr Dimension kRateRandomWalk{2, 0, -3};       // rad/s/sqrt(s) = (rad/s^2)/sqrt(Hz)
inline constexpr Dimension kLength{0, 2, 0};                // m
inline constexpr Dimension kVelocity{0, 2, -2};             // m/s
inline constexpr Dimension kAcceleration{0, 2, -4};         // m/s^2 (specific force, g)
inline constexpr Dimension kJerk{0, 2, -6};                 // m/s^3 (acceleration ramp)
inline constexpr Dimension kVelocityRandomWalk{0, 2, -3};   // m/s/sqrt(s) = (m/s^2)/sqrt(Hz)
inline constexpr Dimension kAccelRandomWalk{0, 2, -5};      // m/s^2/sqrt(s)
inline constexpr Dimension kTime{0, 0, 2};                  // s
inline constexpr Dimension kFrequency{0, 0, -2};            // Hz
}  // namespace dims

// Human-readable name of a dimension ("angle random walk") and the unit spellings accepted for
// it, for error messages: "deg/sqrt(h), deg/√h, deg/rt-hr, (deg/s)/sqrt(Hz), rad/sqrt(s), ...".
std::string DimensionName(Dimension dimension);
std::string AllowedUnits(Dimension dimension);

// A parsed unit: value_si = value_in_unit * si_factor.
struct Unit {
  double si_factor = 1.0;
  Dimension dimension;
};

// A parsed quantity: the number as written, its unit, and the value in SI.
struct Quantity {
  double value = 0.0;     // as written, in `unit`
  std::string unit;       // unit text as written (trimmed)
  double value_si = 0.0;  // value * si_factor
  Dimension dimension;
};

// Parses a unit expression. Throws SpecError(field_path, ...) for an unknown symbol or bad syntax.
Unit ParseUnit(std::string_view unit, std::string_view field_path = "unit");

// Parses "<number> [unit]" (e.g. "0.15 deg/√h", "25µg/√Hz", "-3e-2 deg/h") and checks the unit's
// dimension against `expected`. Throws SpecError naming field_path, the text and the allowed units
// for a missing or malformed number, an unknown unit or a unit of the wrong dimension.
Quantity ParseQuantity(std::string_view text, Dimension expected,
                       std::string_view field_path = "value");

// Converts value in `unit` to SI, checking the dimension as ParseQuantity does.
double ToSi(double value, std::string_view unit, Dimension expected,
            std::string_view field_path = "value");
// Converts an SI value to `unit` (any dimension).
double FromSi(double value_si, std::string_view unit);

// Prints an SI value in `unit`, e.g. FormatQuantity(1e-3, "deg/s", 3) = "0.0573 deg/s".
// precision = significant digits; precision <= 0 prints the shortest text that parses back to
// exactly the same double in that unit.
std::string FormatQuantity(double value_si, std::string_view unit, int precision);

}  // namespace driftlab
