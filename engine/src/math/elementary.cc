#include "driftlab/elementary.h"

#include "math/elementary_functions.h"

namespace driftlab::math {

double Exp(double x) { return elementary::Exp(x); }
double Expm1(double x) { return elementary::Expm1(x); }
double Log(double x) { return elementary::Ln(x); }
double Log1p(double x) { return elementary::Log1p(x); }
double Sin(double x) {
  double s, c;
  elementary::SinCosScalar(x, &s, &c);
  return s;
}
double Cos(double x) {
  double s, c;
  elementary::SinCosScalar(x, &s, &c);
  return c;
}
void SinCos(double x, double* sin_x, double* cos_x) { elementary::SinCosScalar(x, sin_x, cos_x); }
double Tan(double x) {
  double s, c;
  elementary::SinCosScalar(x, &s, &c);
  return s / c;
}
double Atan(double x) { return elementary::Atan(x); }
double Atan2(double y, double x) { return elementary::Atan2(y, x); }
double Asin(double x) { return elementary::Asin(x); }
double Acos(double x) { return elementary::Acos(x); }
double Hypot(double x, double y) { return elementary::Hypot(x, y); }
double LgammaPositive(double a) { return elementary::LgammaPositive(a); }

}  // namespace driftlab::math
