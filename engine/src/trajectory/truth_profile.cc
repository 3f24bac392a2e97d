// The truth profile as cubic splines (planner.h).
#include <algorithm>
#include <string>
#include <variant>
#include <vector>

#include "driftlab/attitude.h"
#include "trajectory/motion_checks.h"
#include "trajectory/planner.h"

namespace driftlab::trajectory_detail {

namespace {

// Not-a-knot cubic spline through (x_i, y_i), i = 0..n-1: returns the slopes y'(x_i).
// The interior conditions (continuity of y'') give, with h_i = x_{i+1} - x_i and
// d_i = (y_{i+1} - y_i) / h_i,
//   h_i s_{i-1} + 2 (h_{i-1} + h_i) s_i + h_{i-1} s_{i+1} = 3 (h_i d_{i-1} + h_{i-1} d_i);
// the not-a-knot end conditions (y''' continuous at x_1 and x_{n-2}) give
//   h_1 s_0 + (h_0 + h_1) s_1 = ((h_0 + 2 (h_0 + h_1)) h_1 d_0 + h_0^2 d_1) / (h_0 + h_1)
// and its mirror image (de Boor, A Practical Guide to Splines, rev. ed. 2001, ch. IV). Subtracting
// each end row from its neighbour leaves a diagonally dominant tridiagonal system in s_1..s_{n-2}.
std::vector<double> NotAKnotSlopes(const std::vector<double>& x, const std::vector<double>& y) {
  const size_t n = x.size();
  std::vector<double> s(n, 0.0);
  std::vector<double> h(n - 1), d(n - 1);
  for (size_t i = 0; i + 1 < n; ++i) {
    h[i] = x[i + 1] - x[i];
    d[i] = (y[i + 1] - y[i]) / h[i];
  }
  if (n == 2) {
    s[0] = s[1] = d[0];
    return s;
  }
  if (n == 3) {  // the parabola through the three points
    const double c2 = (d[1] - d[0]) / (h[0] + h[1]);
    s[0] = d[0] - c2 * h[0];
    s[1] = d[0] + c2 * h[0];
    s[2] = d[1] + c2 * h[1];
    return s;
  }
  const size_t m = n - 2;  // unknowns s_1..s_{n-2}
  std::vector<double> lower(m, 0.0), diag(m, 0.0), upper(m, 0.0), rhs(m, 0.0);
  for (size_t i = 1; i + 1 < n; ++i) {
    lower[i - 1] = h[i];
    diag[i - 1] = 2.0 * (h[i - 1] + h[i]);
    upper[i - 1] = h[i - 1];
    rhs[i - 1] = 3.0 * (h[i] * d[i - 1] + h[i - 1] * d[i]);
  }
  const double left_sum = h[0] + h[1];
  const double left_rhs = ((h[0] + 2.0 * left_sum) * h[1] * d[0] + h[0] * h[0] * d[1]) / left_sum;
  const double right_sum = h[n - 3] + h[n - 2];
  const double right_rhs =
      (h[n - 2] * h[n - 2] * d[n - 3] + (2.0 * right_sum + h[n - 2]) * h[n - 3] * d[n - 2]) /
      right_sum;
  // Row 1 minus the left end row: (h_0 + h_1) s_1 + h_0 s_2 = rhs_1 - left_rhs.
  diag[0] -= left_sum;
  rhs[0] -= left_rhs;
  lower[0] = 0.0;
  // Row n-2 minus the right end row: h_{n-2} s_{n-3} + (h_{n-3} + h_{n-2}) s_{n-2} = ...
  diag[m - 1] -= right_sum;
  rhs[m - 1] -= right_rhs;
  upper[m - 1] = 0.0;
  // Thomas algorithm.
  for (size_t i = 1; i < m; ++i) {
    const double w = lower[i] / diag[i - 1];
    diag[i] -= w * upper[i - 1];
    rhs[i] -= w * rhs[i - 1];
  }
  std::vector<double> sol(m);
  sol[m - 1] = rhs[m - 1] / diag[m - 1];
  for (size_t i = m - 1; i-- > 0;) sol[i] = (rhs[i] - upper[i] * sol[i + 1]) / diag[i];
  for (size_t i = 0; i < m; ++i) s[i + 1] = sol[i];
  s[0] = (left_rhs - left_sum * s[1]) / h[1];
  s[n - 1] = (right_rhs - right_sum * s[n - 2]) / h[n - 3];
  return s;
}

}  // namespace

void PlanTruthProfile(const MotionSpec& motion, std::vector<Piece>* pieces) {
  const std::vector<TruthProfileSample>& samples = motion.truth_profile;
  const std::string base = motion.field_path + ".truth_profile";
  const size_t n = samples.size();
  if (n < 2) RejectText(base, std::to_string(n) + " samples; allowed: at least 2");
  std::vector<double> t(n);
  std::vector<std::vector<double>> channels(6, std::vector<double>(n));
  for (size_t i = 0; i < n; ++i) {
    const TruthProfileSample& p = samples[i];
    const std::string at = base + "[" + std::to_string(i) + "]";
    const double values[] = {p.t_s,
                             p.llh.lat_rad,
                             p.llh.lon_rad,
                             p.llh.h_m,
                             p.v_eb_n.x(),
                             p.v_eb_n.y(),
                             p.v_eb_n.z(),
                             p.attitude.roll_rad,
                             p.attitude.pitch_rad,
                             p.attitude.yaw_rad};
    const char* names[] = {".t_s", ".lat", ".lon",  ".h_m",   ".v_n",
                           ".v_e", ".v_d", ".roll", ".pitch", ".yaw"};
    for (int j = 0; j < 10; ++j) CheckFinite(at + names[j], values[j]);
    if (i > 0 && !(p.t_s > samples[i - 1].t_s)) {
      Reject(at + ".t_s", p.t_s,
             "a time greater than the previous sample's " + CompactText(samples[i - 1].t_s) + " s");
    }
    t[i] = p.t_s - samples[0].t_s;
    channels[0][i] = p.v_eb_n.x();
    channels[1][i] = p.v_eb_n.y();
    channels[2][i] = p.v_eb_n.z();
    channels[3][i] = p.attitude.roll_rad;
    channels[4][i] = p.attitude.pitch_rad;
    channels[5][i] = p.attitude.yaw_rad;
    if (i > 0) {  // unwrap roll and yaw: the spline must not see a 2 pi jump
      channels[3][i] = channels[3][i - 1] + WrapPi(channels[3][i] - channels[3][i - 1]);
      channels[5][i] = channels[5][i - 1] + WrapPi(channels[5][i] - channels[5][i - 1]);
    }
  }
  if (t[n - 1] > kMaxDuration_s) {
    Reject(base + "[" + std::to_string(n - 1) + "].t_s", samples[n - 1].t_s,
           "a profile lasting at most " + CompactText(kMaxDuration_s) + " s");
  }
  std::vector<std::vector<double>> slopes;
  for (const auto& y : channels) slopes.push_back(NotAKnotSlopes(t, y));
  pieces->reserve(n - 1);
  for (size_t i = 0; i + 1 < n; ++i) {
    Piece piece;
    piece.t0 = t[i];
    piece.t1 = t[i + 1];
    SplinePiece sp;
    const double h = t[i + 1] - t[i];
    for (size_t c = 0; c < 6; ++c) {
      const double y0 = channels[c][i], y1 = channels[c][i + 1];
      const double s0 = slopes[c][i], s1 = slopes[c][i + 1];
      const double dd = (y1 - y0) / h;
      sp.c[c] = {y0, s0, (3.0 * dd - 2.0 * s0 - s1) / h, (s0 + s1 - 2.0 * dd) / (h * h)};
    }
    piece.kin = sp;
    pieces->push_back(piece);
  }
}

void CheckTruthProfilePositions(const MotionSpec& motion, const NavEnvironment& env,
                                const std::vector<Piece>& pieces) {
  const std::vector<TruthProfileSample>& samples = motion.truth_profile;
  for (size_t i = 0; i + 1 < samples.size() && i < pieces.size(); ++i) {
    const auto* spline = std::get_if<SplinePiece>(&pieces[i].kin);
    if (spline == nullptr) continue;
    const double h = pieces[i].t1 - pieces[i].t0;
    // Integral over [0, h] of c0 + c1 s + c2 s^2 + c3 s^3, per velocity channel.
    Vector3d integral;
    for (int c = 0; c < 3; ++c) {
      const auto& k = spline->c[static_cast<size_t>(c)];
      integral(c) = h * (k[0] + h * (k[1] / 2.0 + h * (k[2] / 3.0 + h * k[3] / 4.0)));
    }
    const Vector3d displacement = env.PositionErrorNed(samples[i + 1].llh, samples[i].llh);
    const double mismatch = (displacement - integral).norm();
    const double allowed = 10.0 + 0.1 * std::max(displacement.norm(), integral.norm());
    if (!(mismatch <= allowed)) {
      RejectText(motion.field_path + ".truth_profile[" + std::to_string(i + 1) + "]",
                 "its position is " + CompactText(displacement.norm()) +
                     " m from the previous sample's, the velocities integrate to " +
                     CompactText(integral.norm()) + " m (they disagree by " +
                     CompactText(mismatch) + " m); allowed: a disagreement of at most " +
                     CompactText(allowed) +
                     " m (10 m + 10 %): positions after the first sample are integrated from the "
                     "velocities");
    }
  }
}

}  // namespace driftlab::trajectory_detail
