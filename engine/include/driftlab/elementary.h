// The engine's own elementary functions (engine/src/math/elementary_functions.h), for every result
// the engine computes: the C library's exp, log, log1p, sin, cos, tan, atan, atan2, asin, acos,
// expm1, lgamma and hypot round differently on different machines (glibc's FMA and SSE2 variants on
// x86-64, arm64's), and DESIGN.md "Same bits everywhere" asks for one answer everywhere. IEEE basic
// operations only: the same bits on every machine; within a few ulp of the exact values
// (elementary_test.cc).
#pragma once

namespace driftlab::math {

double Exp(double x);
double Expm1(double x);  // e^x - 1, accurate near 0
double Log(double x);    // natural logarithm
double Log1p(double x);  // ln(1 + x), accurate near 0
double Sin(double x);    // |x| >= 1.5e6 rad: the C library's (no navigation angle gets there)
double Cos(double x);
void SinCos(double x, double* sin_x, double* cos_x);
double Tan(double x);
double Atan(double x);
double Atan2(double y, double x);
double Asin(double x);
double Acos(double x);
double Hypot(double x, double y);
double LgammaPositive(double a);  // ln Gamma(a) for a > 0 (NaN otherwise)

}  // namespace driftlab::math
