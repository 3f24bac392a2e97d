#include "driftlab/units.h"

#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <string>

#include "driftlab/earth.h"
#include "driftlab/spec_error.h"

namespace driftlab {
namespace {

constexpr double kDegree_rad = M_PI / 180.0;

// A unit term: SI factor and dimension exponents in halves.
struct Term {
  double factor = 1.0;
  Dimension dim;
};

Term Multiply(const Term& a, const Term& b) {
  return {a.factor * b.factor,
          {a.dim.angle2 + b.dim.angle2, a.dim.length2 + b.dim.length2, a.dim.time2 + b.dim.time2}};
}

Term Inverse(const Term& a) {
  return {1.0 / a.factor, {-a.dim.angle2, -a.dim.length2, -a.dim.time2}};
}

// Symbol table: SI factor per symbol (BIPM SI Brochure, 9th ed., tables 4 and 8; 1 ft = 0.3048 m
// and 1 nmi = 1852 m exactly by international agreement; g = 9.80665 m/s^2, CGPM 1901).
struct Symbol {
  std::string_view name;
  double factor;
  Dimension dim;
};

constexpr Dimension kA = dims::kAngle;
constexpr Dimension kT = dims::kTime;
constexpr Dimension kL = dims::kLength;
constexpr Dimension kF = dims::kFrequency;
constexpr Dimension kG = dims::kAcceleration;
constexpr Dimension kW = dims::kAngularRate;
constexpr Dimension kOne = dims::kDimensionless;
constexpr double kG0 = kStandardGravity_m_per_s2;

const std::array kSymbols = {
    Symbol{"rad", 1.0, kA},
    Symbol{"mrad", 1e-3, kA},
    Symbol{"urad", 1e-6, kA},
    Symbol{"\u00B5rad", 1e-6, kA},  // micro sign
    Symbol{"\u03BCrad", 1e-6, kA},  // Greek mu
    Symbol{"deg", kDegree_rad, kA},
    Symbol{"degree", kDegree_rad, kA},
    Symbol{"degrees", kDegree_rad, kA},
    Symbol{"\u00B0", kDegree_rad, kA},  // degree sign
    Symbol{"\u00BA", kDegree_rad, kA},  // masculine ordinal, used for degrees in Spanish texts
    Symbol{"mdeg", kDegree_rad * 1e-3, kA},
    Symbol{"arcmin", kDegree_rad / 60.0, kA},
    Symbol{"arcsec", kDegree_rad / 3600.0, kA},
    Symbol{"s", 1.0, kT},
    Symbol{"sec", 1.0, kT},
    Symbol{"ms", 1e-3, kT},
    Symbol{"us", 1e-6, kT},
    Symbol{"\u00B5s", 1e-6, kT},
    Symbol{"\u03BCs", 1e-6, kT},
    Symbol{"min", 60.0, kT},
    Symbol{"h", 3600.0, kT},
    Symbol{"hr", 3600.0, kT},
    Symbol{"hour", 3600.0, kT},
    Symbol{"hours", 3600.0, kT},
    Symbol{"Hz", 1.0, kF},
    Symbol{"kHz", 1e3, kF},
    Symbol{"m", 1.0, kL},
    Symbol{"mm", 1e-3, kL},
    Symbol{"km", 1e3, kL},
    Symbol{"ft", 0.3048, kL},
    Symbol{"nmi", 1852.0, kL},
    Symbol{"g", kG0, kG},
    Symbol{"mg", kG0 * 1e-3, kG},
    Symbol{"ug", kG0 * 1e-6, kG},
    Symbol{"\u00B5g", kG0 * 1e-6, kG},
    Symbol{"\u03BCg", kG0 * 1e-6, kG},
    Symbol{"ng", kG0 * 1e-9, kG},
    Symbol{"gal", 1e-2, kG},  // cm/s^2
    Symbol{"Gal", 1e-2, kG},
    Symbol{"mgal", 1e-5, kG},
    Symbol{"mGal", 1e-5, kG},
    Symbol{"ppm", 1e-6, kOne},
    Symbol{"ppb", 1e-9, kOne},
    Symbol{"%", 1e-2, kOne},
    Symbol{"dph", kDegree_rad / 3600.0, kW},
    Symbol{"dps", kDegree_rad, kW},
    Symbol{"rpm", 2.0 * M_PI / 60.0, kW},
};

// Upper-case spellings that are unambiguous for the units above.
struct Alias {
  std::string_view alias;
  std::string_view name;
};
const std::array kAliases = {
    Alias{"hz", "Hz"},   Alias{"HZ", "Hz"},   Alias{"khz", "kHz"}, Alias{"Hr", "hr"},
    Alias{"HR", "hr"},   Alias{"Deg", "deg"}, Alias{"DEG", "deg"}, Alias{"Rad", "rad"},
    Alias{"RAD", "rad"}, Alias{"PPM", "ppm"},
};

const Symbol* FindSymbol(std::string_view name) {
  for (const Symbol& s : kSymbols) {
    if (s.name == name) return &s;
  }
  for (const Alias& a : kAliases) {
    if (a.alias == name) return FindSymbol(a.name);
  }
  return nullptr;
}

std::string DimensionText(Dimension d) {
  std::string out;
  auto add = [&out](const char* base, int twice) {
    if (twice == 0) return;
    if (!out.empty()) out += " ";
    out += base;
    if (twice == 2) return;
    out += "^";
    out += twice % 2 == 0 ? std::to_string(twice / 2) : std::to_string(twice) + "/2";
  };
  add("rad", d.angle2);
  add("m", d.length2);
  add("s", d.time2);
  return out.empty() ? "1" : out;
}

// Why a unit text did not parse; turned into a SpecError with the allowed units by the caller.
struct UnitSyntaxError {
  std::string reason;
};

// Recursive-descent parser of the grammar in units.h over UTF-8 text.
class UnitParser {
 public:
  explicit UnitParser(std::string_view text) : text_(text) {}

  Term Parse() {
    if (text_.size() > kMaxUnitTextBytes) {
      Fail("longer than " + std::to_string(kMaxUnitTextBytes) + " bytes");
    }
    SkipSpace();
    if (pos_ == text_.size()) return Term{};  // no unit: dimensionless
    Term t = Product();
    SkipSpace();
    if (pos_ != text_.size()) Fail("unexpected '" + std::string(text_.substr(pos_, 20)) + "'");
    return t;
  }

 private:
  [[noreturn]] void Fail(const std::string& why) const { throw UnitSyntaxError{why}; }

  void SkipSpace() {
    while (pos_ < text_.size() && (text_[pos_] == ' ' || text_[pos_] == '\t')) ++pos_;
  }
  bool Consume(std::string_view token) {
    if (text_.substr(pos_, token.size()) == token) {
      pos_ += token.size();
      return true;
    }
    return false;
  }
  bool AtIdentifierChar() const {
    if (pos_ >= text_.size()) return false;
    const auto c = static_cast<unsigned char>(text_[pos_]);
    if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '%') return true;
    // UTF-8 lead bytes of µ (C2 B5), ° (C2 B0), º (C2 BA) and μ (CE BC).
    const std::string_view rest = text_.substr(pos_);
    return rest.starts_with("\u00B5") || rest.starts_with("\u00B0") || rest.starts_with("\u00BA") ||
           rest.starts_with("\u03BC");
  }
  bool AtFactorStart() const {
    if (pos_ >= text_.size()) return false;
    return AtIdentifierChar() || text_[pos_] == '(' || text_.substr(pos_).starts_with("\u221A") ||
           text_[pos_] == '1';
  }

  Term Product() {
    Term t = Power();
    for (;;) {
      SkipSpace();
      if (Consume("/")) {
        SkipSpace();
        t = Multiply(t, Inverse(Power()));
      } else if (Consume("*") || Consume("\u00B7") || Consume("\u22C5")) {
        SkipSpace();
        t = Multiply(t, Power());
      } else if (AtFactorStart()) {
        t = Multiply(t, Power());
      } else {
        return t;
      }
    }
  }

  Term Power() {
    Term t = Factor();
    // Exponent p / q with q in {1, 2}.
    int p = 1, q = 1;
    bool has_exponent = true;
    if (Consume("\u00B2")) {
      p = 2;
    } else if (Consume("\u00B3")) {
      p = 3;
    } else if (pos_ < text_.size() && std::isdigit(static_cast<unsigned char>(text_[pos_]))) {
      p = Integer();  // "s2"
    } else if (Consume("^")) {
      const bool paren = Consume("(");
      int sign = 1;
      if (Consume("-") || Consume("\u2212")) {
        sign = -1;
      } else {
        Consume("+");
      }
      p = sign * Integer();
      if (Consume(".5")) {
        p = 2 * p + sign;
        q = 2;
      } else if (pos_ + 1 < text_.size() && text_[pos_] == '/' &&
                 std::isdigit(static_cast<unsigned char>(text_[pos_ + 1]))) {
        ++pos_;  // "^-1/2"; a '/' followed by a unit is a division
        q = Integer();
      }
      if (paren && !Consume(")")) Fail("missing ')' in exponent");
    } else {
      has_exponent = false;
    }
    return has_exponent ? Raise(t, p, q) : t;
  }

  int Integer() {
    const size_t start = pos_;
    int value = 0;
    while (pos_ < text_.size() && std::isdigit(static_cast<unsigned char>(text_[pos_])) &&
           pos_ - start < 3) {
      value = 10 * value + (text_[pos_] - '0');
      ++pos_;
    }
    if (pos_ == start) Fail("expected an integer exponent");
    return value;
  }

  // t^(p/q) for q in {1, 2}; factors by repeated multiplication (exact for integer powers up to
  // rounding) and sqrt (correctly rounded).
  Term Raise(const Term& t, int p, int q) {
    if (q != 1 && q != 2) Fail("exponent denominator must be 1 or 2");
    const Dimension& d = t.dim;
    if (q == 2 && (d.angle2 % 2 != 0 || d.length2 % 2 != 0 || d.time2 % 2 != 0))
      Fail("square root of a unit that already has a half power");
    const double base = q == 2 ? std::sqrt(t.factor) : t.factor;
    double factor = 1.0;
    for (int i = 0; i < std::abs(p); ++i) factor *= base;
    if (p < 0) factor = 1.0 / factor;
    return {factor, {d.angle2 * p / q, d.length2 * p / q, d.time2 * p / q}};
  }

  // Factor nests (parentheses, square roots): bounded so that no input exhausts the stack.
  Term Factor() {
    if (++depth_ > kMaxUnitNesting) {
      Fail("nested deeper than " + std::to_string(kMaxUnitNesting) + " levels");
    }
    Term t = FactorBody();
    --depth_;
    return t;
  }

  Term FactorBody() {
    SkipSpace();
    if (Consume("(")) {
      Term t = Product();
      SkipSpace();
      if (!Consume(")")) Fail("missing ')'");
      return t;
    }
    if (Consume("\u221A")) return Raise(Factor(), 1, 2);  // √
    if (Consume("1")) return Term{};                      // as in "1/s"
    if (!AtIdentifierChar()) {
      Fail(pos_ < text_.size() ? "unexpected '" + std::string(text_.substr(pos_, 1)) + "'"
                               : "unit ends early");
    }
    const size_t start = pos_;
    while (AtIdentifierChar()) {
      pos_ += static_cast<unsigned char>(text_[pos_]) >= 0x80 ? 2 : 1;
    }
    const std::string_view name = text_.substr(start, pos_ - start);
    // sqrt(...), sqrtHz, rt-hr, rtHz, rt(Hz): square-root prefixes.
    for (std::string_view prefix : {std::string_view("sqrt"), std::string_view("rt")}) {
      if (!name.starts_with(prefix) || FindSymbol(name) != nullptr) continue;
      if (name.size() > prefix.size()) {
        pos_ = start + prefix.size();
        return Raise(Factor(), 1, 2);
      }
      Consume("-");
      return Raise(Factor(), 1, 2);
    }
    const Symbol* symbol = FindSymbol(name);
    if (symbol == nullptr) Fail("unknown unit symbol '" + std::string(name) + "'");
    return {symbol->factor, symbol->dim};
  }

  std::string_view text_;
  size_t pos_ = 0;
  int depth_ = 0;
};

std::string_view TrimBlanks(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

void CheckDimension(const Unit& unit, Dimension expected, std::string_view text,
                    std::string_view field_path) {
  if (unit.dimension == expected) return;
  throw SpecError(std::string(field_path),
                  "'" + std::string(text) + "' (a unit of " + DimensionName(unit.dimension) + ")",
                  "units of " + DimensionName(expected) + ": " + AllowedUnits(expected));
}

}  // namespace

std::string DimensionName(Dimension d) {
  if (d == dims::kDimensionless) return "ratio (dimensionless)";
  if (d == dims::kAngle) return "angle";
  if (d == dims::kAngularRate) return "angular rate";
  if (d == dims::kAngularAcceleration) return "angular acceleration (rate ramp)";
  if (d == dims::kAngleRandomWalk) return "angle random walk (rate noise density)";
  if (d == dims::kRateRandomWalk) return "rate random walk";
  if (d == dims::kLength) return "length";
  if (d == dims::kVelocity) return "velocity";
  if (d == dims::kAcceleration) return "acceleration (specific force)";
  if (d == dims::kJerk) return "acceleration ramp";
  if (d == dims::kVelocityRandomWalk) return "velocity random walk (acceleration noise density)";
  if (d == dims::kAccelRandomWalk) return "acceleration random walk";
  if (d == dims::kTime) return "time";
  if (d == dims::kFrequency) return "frequency";
  return DimensionText(d);
}

std::string AllowedUnits(Dimension d) {
  if (d == dims::kDimensionless) return "ppm, ppb, %, or no unit";
  if (d == dims::kAngle) return "rad, mrad, urad, deg (°), mdeg, arcmin, arcsec";
  if (d == dims::kAngularRate) return "rad/s, deg/s, deg/h, dps, dph, rpm";
  if (d == dims::kAngularAcceleration) return "rad/s^2, deg/s^2, deg/h^2, deg/h/s";
  if (d == dims::kAngleRandomWalk)
    return "deg/sqrt(h), deg/√h, deg/rt-hr, (deg/s)/sqrt(Hz), (deg/h)/sqrt(Hz), deg/sqrt(s), "
           "rad/sqrt(s)";
  if (d == dims::kRateRandomWalk)
    return "deg/h/sqrt(h), deg/h^1.5, (deg/s)/sqrt(s), (deg/s^2)/sqrt(Hz), rad/s/sqrt(s)";
  if (d == dims::kLength) return "m, mm, km, ft, nmi";
  if (d == dims::kVelocity) return "m/s, km/h, ft/s, nmi/h";
  if (d == dims::kAcceleration) return "m/s^2, g, mg, ug (µg), gal, mgal";
  if (d == dims::kJerk) return "m/s^3, g/s, mg/s, ug/s";
  if (d == dims::kVelocityRandomWalk)
    return "(m/s)/sqrt(h), m/s/sqrt(s), m/s^2/sqrt(Hz), g/sqrt(Hz), mg/sqrt(Hz), ug/sqrt(Hz) "
           "(µg/√Hz)";
  if (d == dims::kAccelRandomWalk)
    return "m/s^2/sqrt(h), m/s^2/sqrt(s), mg/sqrt(h), ug/sqrt(h), (ug/s)/sqrt(Hz)";
  if (d == dims::kTime) return "s, ms, min, h";
  if (d == dims::kFrequency) return "Hz, kHz, 1/s";
  return "any unit of dimension " + DimensionText(d);
}

namespace {

constexpr std::string_view kAllSymbols =
    "products and quotients of rad, mrad, urad, deg (°), arcmin, arcsec, s, ms, min, h, hr, Hz, "
    "m, mm, km, ft, nmi, g, mg, ug (µg), gal, ppm, ppb, %, dph, dps, rpm with sqrt(), √, rt-, "
    "^n, ^-1/2, ², ³";

// Parses `unit`; on failure throws SpecError naming the field, the whole text as written and the
// allowed units.
Unit ParseUnitOrThrow(std::string_view unit, std::string_view text, std::string_view field_path,
                      std::string_view allowed) {
  // A text too long to be a unit: say so first (an echo of it would be cut before the reason).
  if (TrimBlanks(unit).size() > kMaxUnitTextBytes) {
    throw SpecError(std::string(field_path),
                    "a unit text of " + std::to_string(TrimBlanks(unit).size()) + " bytes",
                    "a unit text of at most " + std::to_string(kMaxUnitTextBytes) + " bytes");
  }
  try {
    const Term t = UnitParser(TrimBlanks(unit)).Parse();
    return Unit{t.factor, t.dim};
  } catch (const UnitSyntaxError& e) {
    throw SpecError(std::string(field_path), "'" + std::string(text) + "' (" + e.reason + ")",
                    std::string(allowed));
  }
}

}  // namespace

Unit ParseUnit(std::string_view unit, std::string_view field_path) {
  return ParseUnitOrThrow(unit, unit, field_path, kAllSymbols);
}

Quantity ParseQuantity(std::string_view text, Dimension expected, std::string_view field_path) {
  const std::string_view trimmed = TrimBlanks(text);
  const std::string allowed =
      "a number followed by a unit of " + DimensionName(expected) + ": " + AllowedUnits(expected);
  std::string_view rest = trimmed;
  bool negative = false;
  if (rest.starts_with("+")) {
    rest.remove_prefix(1);
  } else if (rest.starts_with("\u2212")) {  // Unicode minus sign
    rest.remove_prefix(3);
    negative = true;
  }
  double value = 0.0;
  const auto [end, ec] = std::from_chars(rest.data(), rest.data() + rest.size(), value);
  if (ec != std::errc() || !std::isfinite(value)) {
    throw SpecError(std::string(field_path), "'" + std::string(text) + "' (no valid number)",
                    allowed);
  }
  if (negative) value = -value;
  Quantity q;
  q.value = value;
  q.unit = std::string(TrimBlanks(rest.substr(static_cast<size_t>(end - rest.data()))));
  if (q.unit.empty() && expected != dims::kDimensionless) {
    throw SpecError(std::string(field_path), "'" + std::string(text) + "' (missing unit)", allowed);
  }
  const Unit unit = ParseUnitOrThrow(q.unit, text, field_path, allowed);
  CheckDimension(unit, expected, text, field_path);
  q.value_si = value * unit.si_factor;
  q.dimension = unit.dimension;
  return q;
}

double ToSi(double value, std::string_view unit, Dimension expected, std::string_view field_path) {
  const Unit u =
      ParseUnitOrThrow(unit, unit, field_path,
                       "units of " + DimensionName(expected) + ": " + AllowedUnits(expected));
  CheckDimension(u, expected, unit, field_path);
  return value * u.si_factor;
}

double FromSi(double value_si, std::string_view unit) {
  return value_si / ParseUnit(unit).si_factor;
}

std::string FormatQuantity(double value_si, std::string_view unit, int precision) {
  const double value = FromSi(value_si, unit);
  std::array<char, 64> buf{};
  const auto result = precision > 0 ? std::to_chars(buf.data(), buf.data() + buf.size(), value,
                                                    std::chars_format::general, precision)
                                    : std::to_chars(buf.data(), buf.data() + buf.size(), value);
  std::string out(buf.data(), result.ptr);
  const std::string_view u = TrimBlanks(unit);
  if (!u.empty()) {
    out += " ";
    out += u;
  }
  return out;
}

}  // namespace driftlab
