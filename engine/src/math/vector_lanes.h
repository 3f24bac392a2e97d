// 3-vectors and quaternions of W lanes (lanes/lane.h: W = 1 is the scalar code) with the operations
// the mechanization and the sensor-error step need, each in the operation order of Eigen 3.4's own
// fixed-size expressions in the default x86-64 / arm64 build, so that the lane code and the
// engine's Eigen code give the same bits: Matrix3d * Vector3d row by row as Dot3, the cross product
// as OrthoMethods.h, the quaternion product as its SSE2/NEON kernel (Geometry_SIMD.h), q * v as
// _transformVector, normalized() as division by sqrt of (x^2 + z^2) + (y^2 + w^2) (two-lane
// packets), squaredNorm of a 3-vector as x0 + (x1 + x2) (its unrolled reduction halves the range).
// A lane header (lanes/lane.h): internal linkage, no Eigen or standard-library templates.
#pragma once

#include "lanes/lane.h"
#include "math/elementary_functions.h"

namespace driftlab::vector_lanes {
namespace {

using lanes::D;
using lanes::U;

template <int W>
struct V3 {
  D<W> x, y, z;
};
// q = w + x i + y j + z k.
template <int W>
struct Q4 {
  D<W> w, x, y, z;
};

template <int W>
inline V3<W> Splat3(double x, double y, double z) {
  return {lanes::Splat<W>(x), lanes::Splat<W>(y), lanes::Splat<W>(z)};
}
// A 3-vector field of W lanes (lanes::Get: lane arrays, or plain doubles for W = 1).
template <int W, typename A>
inline V3<W> Get3(const A& a) {
  return {lanes::Get<W>(a[0]), lanes::Get<W>(a[1]), lanes::Get<W>(a[2])};
}
template <int W, typename A>
inline void Put3(A& a, const V3<W>& v) {
  lanes::Put<W>(a[0], v.x);
  lanes::Put<W>(a[1], v.y);
  lanes::Put<W>(a[2], v.z);
}

template <int W>
inline V3<W> Add(const V3<W>& a, const V3<W>& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <int W>
inline V3<W> Sub(const V3<W>& a, const V3<W>& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <int W>
inline V3<W> Scale(double s, const V3<W>& a) {
  return {s * a.x, s * a.y, s * a.z};
}
template <int W>
inline V3<W> Scale(const V3<W>& a, double s) {
  return {a.x * s, a.y * s, a.z * s};
}
template <int W>
inline V3<W> ScaleLanes(const D<W>& s, const V3<W>& a) {
  return {s * a.x, s * a.y, s * a.z};
}
// Eigen's cross product of 3-vectors (OrthoMethods.h).
template <int W>
inline V3<W> Cross(const V3<W>& a, const V3<W>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
// Row i of Eigen's Matrix3d * Vector3d from its three products: rows 0 and 1 are evaluated as one
// two-lane packet accumulated column by column, (a0 + a1) + a2; row 2 as a scalar unrolled
// reduction, a0 + (a1 + a2) (measured on Eigen 3.4 at -O2, SSE2).
template <typename T>
inline T Dot3(int row, T a0, T a1, T a2) {
  return row < 2 ? (a0 + a1) + a2 : a0 + (a1 + a2);
}
// Eigen's q * v (_transformVector): uv = 2 (q.vec x v); v + w uv + q.vec x uv.
template <int W>
inline V3<W> Rotate(const Q4<W>& q, const V3<W>& v) {
  const V3<W> qv{q.x, q.y, q.z};
  V3<W> uv = Cross(qv, v);
  uv = Add(uv, uv);
  return Add(Add(v, ScaleLanes<W>(q.w, uv)), Cross(qv, uv));
}
// Eigen's Quaternion<double> product, SSE2/NEON kernel (Geometry_SIMD.h), a * b.
template <int W>
inline Q4<W> Mul(const Q4<W>& a, const Q4<W>& b) {
  Q4<W> r;
  r.x = (a.w * b.x + a.y * b.z) - (a.z * b.y - a.x * b.w);
  r.y = (a.w * b.y + a.y * b.w) + (a.z * b.x - a.x * b.z);
  r.z = (a.w * b.z - a.y * b.x) + (a.z * b.w + a.x * b.y);
  r.w = (a.w * b.w - a.y * b.y) - (a.z * b.z + a.x * b.x);
  return r;
}
// Eigen's normalized() of a Quaternion<double> (coeffs x, y, z, w in two-lane packets); a zero
// quaternion is returned as it is.
template <int W>
inline Q4<W> Normalized(const Q4<W>& q) {
  using lanes::Select;
  const D<W> n2 = (q.x * q.x + q.z * q.z) + (q.y * q.y + q.w * q.w);
  const D<W> n = lanes::Sqrt<W>(n2);
  const U<W> positive = lanes::MaskOf<W>(n2 > 0.0);
  return {Select<W>(positive, q.w / n, q.w), Select<W>(positive, q.x / n, q.x),
          Select<W>(positive, q.y / n, q.y), Select<W>(positive, q.z / n, q.z)};
}
// The quaternion of the rotation vector rho (RotationVectorToQuaternion, attitude.h):
// (cos(a/2), sin(a/2)/a rho) with a = |rho|, and the Taylor series of cos(a/2) and sin(a/2)/a to
// a^4 for a < 1e-4 (omitted terms < 1e-20). Both branches for every lane, then the one each lane's
// angle takes; the series' constant fractions as products with their rounded reciprocals. Inlined:
// GCC otherwise calls it with its vector arguments through memory, which is slower.
template <int W>
__attribute__((always_inline)) inline Q4<W> RotationVectorToQuaternion(const V3<W>& rho) {
  using lanes::Select;
  const D<W> a2 = rho.x * rho.x + (rho.y * rho.y + rho.z * rho.z);
  const D<W> a = lanes::Sqrt<W>(a2);
  const U<W> small = lanes::MaskOf<W>(a < 1e-4);
  // The Earth-rate rotation (~1e-6 rad a step) and a slowly turning body take the series in
  // every lane: sin and cos are then skipped (their lanes would not be selected).
  bool any_large = false;
  for (int i = 0; i < W; ++i) any_large = any_large || lanes::GetLane<W>(small, i) == 0;
  D<W> sin_half = lanes::Splat<W>(0.0), cos_half = lanes::Splat<W>(1.0);
  if (any_large) elementary::SinCos<W>(0.5 * a, sin_half, cos_half);
  const D<W> w = Select<W>(small, 1.0 - a2 * (1.0 / 8.0) + a2 * a2 * (1.0 / 384.0), cos_half);
  const D<W> k = Select<W>(small, 0.5 - a2 * (1.0 / 48.0) + a2 * a2 * (1.0 / 3840.0), sin_half / a);
  return {w, k * rho.x, k * rho.y, k * rho.z};
}

}  // namespace
}  // namespace driftlab::vector_lanes
