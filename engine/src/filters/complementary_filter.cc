#include "driftlab/complementary_filter.h"

#include <cmath>
#include <string>

#include "driftlab/elementary.h"
#include "driftlab/spec_error.h"

namespace driftlab {
namespace {

// Bilinear transform of the normalised analog section 1 / (p^2 + b p + 1) (low-pass) or
// p^2 / (p^2 + b p + 1) (high-pass) with p = c (1 - z^-1) / (1 + z^-1), c = 1 / tan(w_c dt / 2)
// (prewarped): multiplying through by (1 + z^-1)^2,
//   den = (c^2 + b c + 1) + 2 (1 - c^2) z^-1 + (c^2 - b c + 1) z^-2
//   num = (1 + z^-1)^2 (low-pass)  or  c^2 (1 - z^-1)^2 (high-pass).
Biquad SecondOrderSection(double b, double c, bool high_pass) {
  const double a0 = c * c + b * c + 1.0;
  Biquad q;
  q.a1 = 2.0 * (1.0 - c * c) / a0;
  q.a2 = (c * c - b * c + 1.0) / a0;
  if (high_pass) {
    q.b0 = c * c / a0;
    q.b1 = -2.0 * c * c / a0;
    q.b2 = c * c / a0;
  } else {
    q.b0 = 1.0 / a0;
    q.b1 = 2.0 / a0;
    q.b2 = 1.0 / a0;
  }
  return q;
}

// First order: 1 / (p + 1) -> (1 + z^-1) / ((c + 1) + (1 - c) z^-1).
Biquad FirstOrderLowPass(double c) {
  Biquad q;
  q.b0 = 1.0 / (c + 1.0);
  q.b1 = 1.0 / (c + 1.0);
  q.a1 = (1.0 - c) / (c + 1.0);
  return q;
}

// Euler-angle rates from the body rate (Groves (2.58)).
Vector3d EulerRates(double roll, double pitch, const Vector3d& w) {
  const double s = math::Sin(roll), c = math::Cos(roll);
  const double yz = w.y() * s + w.z() * c;
  return Vector3d(w.x() + yz * math::Tan(pitch), w.y() * c - w.z() * s, yz / math::Cos(pitch));
}

}  // namespace

std::complex<double> Biquad::Response(double omega_dt_rad) const {
  const std::complex<double> z1 = std::polar(1.0, -omega_dt_rad);  // z^-1
  return (b0 + z1 * (b1 + z1 * b2)) / (1.0 + z1 * (a1 + z1 * a2));
}

IirCascade::IirCascade(const std::array<Biquad, 2>& sections, int count)
    : sections_(sections), count_(count) {}

std::complex<double> IirCascade::Response(double omega_dt_rad) const {
  std::complex<double> h = 1.0;
  for (int i = 0; i < count_; ++i) h *= sections_[i].Response(omega_dt_rad);
  return h;
}

// Transposed direct form II: y = b0 x + s1; s1' = b1 x - a1 y + s2; s2' = b2 x - a2 y.
// Steady state for constant x (y = G x): s2 = b2 x - a2 y, s1 = y - b0 x.
void IirCascade::Reset(double x) {
  for (int i = 0; i < count_; ++i) {
    const Biquad& q = sections_[i];
    const double y = q.DcGain() * x;
    state_[i][1] = q.b2 * x - q.a2 * y;
    state_[i][0] = y - q.b0 * x;
    x = y;
  }
}

double IirCascade::Step(double x) {
  for (int i = 0; i < count_; ++i) {
    const Biquad& q = sections_[i];
    std::array<double, 2>& s = state_[i];
    const double y = q.b0 * x + s[0];
    s[0] = q.b1 * x - q.a1 * y + s[1];
    s[1] = q.b2 * x - q.a2 * y;
    x = y;
  }
  return x;
}

std::complex<double> ComplementaryPairDesign::LowPassResponse(double f_hz) const {
  return low_pass.Response(2.0 * M_PI * f_hz / rate_hz);
}

std::complex<double> ComplementaryPairDesign::HighPassResponse(double f_hz) const {
  if (kind == ComplementaryPairKind::kButterworth4Seed) {
    return high_pass.Response(2.0 * M_PI * f_hz / rate_hz);
  }
  return 1.0 - LowPassResponse(f_hz);
}

ComplementaryPairDesign DesignComplementaryPair(ComplementaryPairKind kind, double crossover_hz,
                                                double rate_hz, const std::string& crossover_field,
                                                const std::string& rate_field) {
  if (!std::isfinite(rate_hz) || rate_hz <= 0.0) {
    throw SpecError(rate_field, ValueText(rate_hz), "> 0 Hz");
  }
  if (!std::isfinite(crossover_hz) || crossover_hz <= 0.0 || crossover_hz >= 0.5 * rate_hz) {
    throw SpecError(crossover_field, ValueText(crossover_hz),
                    "(0, " + ValueText(0.5 * rate_hz) + ") Hz (below the Nyquist frequency)");
  }
  ComplementaryPairDesign d;
  d.kind = kind;
  d.crossover_hz = crossover_hz;
  d.rate_hz = rate_hz;
  const double c = 1.0 / math::Tan(M_PI * crossover_hz / rate_hz);  // 1 / tan(w_c dt / 2)
  if (kind == ComplementaryPairKind::kFirstOrder) {
    d.low_pass = IirCascade({FirstOrderLowPass(c), Biquad{}}, 1);
    return d;
  }
  // Butterworth n = 4: B(p) = (p^2 + 2 sin(pi/8) p + 1)(p^2 + 2 sin(3 pi/8) p + 1)
  // = p^4 + 2.6131 p^3 + 3.4142 p^2 + 2.6131 p + 1 (poles exp(j pi (2k + 3) / 8), k = 0..3).
  const double b1 = 2.0 * math::Sin(M_PI / 8.0), b2 = 2.0 * math::Sin(3.0 * M_PI / 8.0);
  d.low_pass = IirCascade({SecondOrderSection(b1, c, false), SecondOrderSection(b2, c, false)}, 2);
  if (kind == ComplementaryPairKind::kButterworth4Seed) {
    d.high_pass = IirCascade({SecondOrderSection(b1, c, true), SecondOrderSection(b2, c, true)}, 2);
  }
  return d;
}

EulerAngles AccelerometerTilt(const Vector3d& f_ib_b) {
  EulerAngles e;
  e.roll_rad = math::Atan2(-f_ib_b.y(), -f_ib_b.z());
  e.pitch_rad = math::Atan(f_ib_b.x() / math::Hypot(f_ib_b.y(), f_ib_b.z()));
  return e;
}

double MagneticHeading(const Vector3d& m_b, double roll_rad, double pitch_rad,
                       double declination_rad) {
  const double sr = math::Sin(roll_rad), cr = math::Cos(roll_rad);
  const double sp = math::Sin(pitch_rad), cp = math::Cos(pitch_rad);
  const double mx = m_b.x() * cp + (m_b.y() * sr + m_b.z() * cr) * sp;
  const double my = m_b.y() * cr - m_b.z() * sr;
  return WrapPi(math::Atan2(-my, mx) + declination_rad);
}

ComplementaryAttitudeFilter::ComplementaryAttitudeFilter(const ComplementaryFilterOptions& options,
                                                         double rate_hz)
    : options_(options),
      dt_s_(1.0 / rate_hz),
      tilt_(DesignComplementaryPair(options.kind, options.crossover_hz, rate_hz)),
      heading_(DesignComplementaryPair(options.kind, options.heading_crossover_hz, rate_hz,
                                       "complementary_filter.heading_crossover_hz")) {
  if (!options.omega_correction_b.allFinite()) {
    throw SpecError("complementary_filter.omega_correction_b", "non-finite", "finite [rad/s]");
  }
  if (!std::isfinite(options.magnetic_declination_rad) ||
      std::abs(options.magnetic_declination_rad) > M_PI) {
    throw SpecError("complementary_filter.magnetic_declination_rad",
                    ValueText(options.magnetic_declination_rad), "[-pi, pi] rad");
  }
  for (int axis = 0; axis < 3; ++axis) {
    const ComplementaryPairDesign& d = axis < 2 ? tilt_ : heading_;
    low_[axis] = d.low_pass;
    high_[axis] = d.high_pass;
  }
}

double ComplementaryAttitudeFilter::Blend(int axis, double measured) {
  double& theta_g = gyro_angle_[axis];
  if (options_.kind == ComplementaryPairKind::kButterworth4Seed) {
    return low_[axis].Step(measured) + high_[axis].Step(theta_g);
  }
  return theta_g + low_[axis].Step(WrapPi(measured - theta_g));
}

void ComplementaryAttitudeFilter::Update(const ImuSample& sample, const Vector3d* m_b) {
  measured_ = AccelerometerTilt(sample.f_ib_b);
  if (!started_) {
    started_ = true;
    heading_aided_ = m_b != nullptr;
    measured_.yaw_rad = heading_aided_
                            ? MagneticHeading(*m_b, measured_.roll_rad, measured_.pitch_rad,
                                              options_.magnetic_declination_rad)
                            : options_.initial_yaw_rad;
    gyro_angle_ = {measured_.roll_rad, measured_.pitch_rad, measured_.yaw_rad};
    const bool seed = options_.kind == ComplementaryPairKind::kButterworth4Seed;
    for (int axis = 0; axis < 3; ++axis) {
      // Complementary kinds filter the difference (0 at the start); the seed kind the angles.
      low_[axis].Reset(seed ? gyro_angle_[axis] : 0.0);
      if (seed) high_[axis].Reset(gyro_angle_[axis]);
    }
    estimate_ = measured_;
  } else {
    // theta_g(k) = theta_g(k-1) + Euler rates(estimate(k-1), (omega(k-1) + omega(k)) / 2) dt:
    // trapezoidal rule, the Euler-rate matrix taken at the previous estimate.
    const Vector3d rates =
        EulerRates(estimate_.roll_rad, estimate_.pitch_rad,
                   0.5 * (previous_omega_b_ + sample.omega_ib_b) - options_.omega_correction_b);
    for (int axis = 0; axis < 3; ++axis) gyro_angle_[axis] += rates[axis] * dt_s_;
    estimate_.roll_rad = Blend(0, measured_.roll_rad);
    estimate_.pitch_rad = Blend(1, measured_.pitch_rad);
    if (heading_aided_ && m_b != nullptr) {
      measured_.yaw_rad = MagneticHeading(*m_b, estimate_.roll_rad, estimate_.pitch_rad,
                                          options_.magnetic_declination_rad);
      yaw_offset_ = Blend(2, measured_.yaw_rad) - gyro_angle_[2];
    }
    measured_.yaw_rad = heading_aided_ ? measured_.yaw_rad : gyro_angle_[2];
    estimate_.yaw_rad = WrapPi(gyro_angle_[2] + yaw_offset_);
  }
  previous_omega_b_ = sample.omega_ib_b;
}

}  // namespace driftlab
