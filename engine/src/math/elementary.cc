#include "driftlab/elementary.h"

#include "math/lane_math.h"

namespace driftlab::math {

double Exp(double x) { return lane_math::Exp(x); }
double Expm1(double x) { return lane_math::Expm1(x); }
double Log(double x) { return lane_math::Ln(x); }
double Log1p(double x) { return lane_math::Log1p(x); }
double Sin(double x) {
  double s, c;
  lane_math::SinCosScalar(x, &s, &c);
  return s;
}
double Cos(double x) {
  double s, c;
  lane_math::SinCosScalar(x, &s, &c);
  return c;
}
void SinCos(double x, double* sin_x, double* cos_x) { lane_math::SinCosScalar(x, sin_x, cos_x); }
double Tan(double x) {
  double s, c;
  lane_math::SinCosScalar(x, &s, &c);
  return s / c;
}
double Atan(double x) { return lane_math::Atan(x); }
double Atan2(double y, double x) { return lane_math::Atan2(y, x); }
double Asin(double x) { return lane_math::Asin(x); }
double Acos(double x) { return lane_math::Acos(x); }
double Hypot(double x, double y) { return lane_math::Hypot(x, y); }
double LgammaPositive(double a) { return lane_math::LgammaPositive(a); }

}  // namespace driftlab::math
