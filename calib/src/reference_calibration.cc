#include "driftlab/calib/reference_calibration.h"

#include <ceres/ceres.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "driftlab/spec_error.h"

namespace driftlab::calib {
namespace {

struct LineResidual {
  double x, y;
  template <typename T>
  bool operator()(const T* p, T* r) const {
    r[0] = p[0] * T(x) + p[1] - T(y);
    return true;
  }
};

// p = [K row-major (9), y_0 (3)].
struct MatrixResidual {
  Eigen::Vector3d x, y;
  template <typename T>
  bool operator()(const T* p, T* r) const {
    for (int i = 0; i < 3; ++i) {
      r[i] =
          p[3 * i] * T(x[0]) + p[3 * i + 1] * T(x[1]) + p[3 * i + 2] * T(x[2]) + p[9 + i] - T(y[i]);
    }
    return true;
  }
};

}  // namespace

AxisReferenceFit FitReferenceAxis(const std::vector<double>& input,
                                  const std::vector<double>& output, const std::string& axis,
                                  const std::string& input_unit, const std::string& output_unit) {
  if (input.size() != output.size()) {
    throw SpecError("data", fmt::format("{} inputs but {} outputs", input.size(), output.size()),
                    0);
  }
  for (size_t i = 0; i < input.size(); ++i) {
    if (!std::isfinite(input[i]) || !std::isfinite(output[i])) {
      throw SpecError("data", fmt::format("row {} of axis {} is not finite", i + 1, axis), 0);
    }
  }
  const auto [lo, hi] = std::minmax_element(input.begin(), input.end());
  if (input.empty() || *hi - *lo <= 1e-12 * std::max(1.0, std::abs(*hi))) {
    throw SpecError("data",
                    fmt::format("the data cannot determine {}.sensitivity: one input level ({} "
                                "{}); a line needs at least 2 different inputs",
                                axis, input.empty() ? 0.0 : *lo, input_unit),
                    0);
  }
  if (input.size() < 3) {
    throw SpecError("data",
                    fmt::format("too few points for axis {}: {}; a line with an uncertainty needs "
                                "at least 3",
                                axis, input.size()),
                    0);
  }
  AxisReferenceFit out;
  out.fit.kind = "reference";
  out.fit.residual_unit = output_unit;
  out.fit.poses_used = static_cast<int>(input.size());
  double p[2] = {0.0, 0.0};
  ceres::Problem problem;
  for (size_t i = 0; i < input.size(); ++i) {
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<LineResidual, 1, 2>(new LineResidual{input[i], output[i]}),
        nullptr, p);
  }
  const std::string ratio = output_unit + "/(" + input_unit + ")";
  detail::SolveAndReport(&problem, p, 2, {axis + ".sensitivity", axis + ".null"},
                         {ratio, output_unit}, &out.fit);
  out.sensitivity = p[0];
  out.null = p[1];
  double worst = 0.0;
  for (double r : out.fit.residuals) worst = std::max(worst, std::abs(r));
  out.linearity_error_percent = 100.0 * worst / (std::abs(p[0]) * (*hi - *lo));
  out.fit.messages.push_back(
      fmt::format("{}: linearity error {:.3g} % of the full-scale output span {:.4g} {}", axis,
                  out.linearity_error_percent, std::abs(p[0]) * (*hi - *lo), output_unit));
  return out;
}

MatrixReferenceFit FitReferenceMatrix(const std::vector<Eigen::Vector3d>& input,
                                      const std::vector<Eigen::Vector3d>& output,
                                      const std::string& input_unit,
                                      const std::string& output_unit) {
  if (input.size() != output.size()) {
    throw SpecError("data", fmt::format("{} inputs but {} outputs", input.size(), output.size()),
                    0);
  }
  if (input.size() < 5) {
    throw SpecError("data",
                    fmt::format("too few rows: {}; the 12-parameter matrix fit needs at least 5 "
                                "(4 input vectors spanning 3 axes plus one for the uncertainty)",
                                input.size()),
                    0);
  }
  for (size_t i = 0; i < input.size(); ++i) {
    if (!input[i].allFinite() || !output[i].allFinite()) {
      throw SpecError("data", fmt::format("row {} is not finite", i + 1), 0);
    }
  }
  MatrixReferenceFit out;
  out.fit.kind = "reference";
  out.fit.residual_unit = output_unit;
  out.fit.poses_used = static_cast<int>(input.size());
  double p[12] = {0};
  ceres::Problem problem;
  for (size_t i = 0; i < input.size(); ++i) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<MatrixResidual, 3, 12>(
                                 new MatrixResidual{input[i], output[i]}),
                             nullptr, p);
  }
  std::vector<std::string> names, units;
  const char* axes = "xyz";
  const std::string ratio = output_unit + "/(" + input_unit + ")";
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      names.push_back(fmt::format("K.{}{}", axes[r], axes[c]));
      units.push_back(ratio);
    }
  }
  for (int r = 0; r < 3; ++r) {
    names.push_back(fmt::format("null.{}", axes[r]));
    units.push_back(output_unit);
  }
  detail::SolveAndReport(&problem, p, 12, names, units, &out.fit);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out.K(r, c) = p[3 * r + c];
    out.null[r] = p[9 + r];
  }
  for (int a = 0; a < 3; ++a) {
    double lo = input[0][a], hi = input[0][a], worst = 0.0;
    for (size_t i = 0; i < input.size(); ++i) {
      lo = std::min(lo, input[i][a]);
      hi = std::max(hi, input[i][a]);
      worst = std::max(worst, std::abs(out.fit.residuals[3 * i + a]));
    }
    out.linearity_error_percent[a] = 100.0 * worst / (std::abs(out.K(a, a)) * (hi - lo));
  }
  return out;
}

}  // namespace driftlab::calib
