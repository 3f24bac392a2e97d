// Reference (rate-table / tilt-table) calibration: a linear fit of a sensor's raw output (volts,
// counts) against known inputs (rates, accelerations), with Ceres.
//
// Model, per axis:      y = k x + y_0
//        full matrix:   y = K x + y_0   (K 3x3: diagonal = sensitivities, off-diagonal =
//                                        cross-axis sensitivities; y_0 = null / offset)
// x in the input unit the caller states (e.g. "deg/s", "g", "rad/s"), y in the output unit
// ("V", "counts"). Sensitivity k [output/input], null y_0 [output] (seed 003: "a straight-line fit
// gives each sensor's scale and offset"). Uncertainties are from ceres::Covariance scaled by the
// residual variance RSS / (m - n); with m = n + 1 (three levels for a line) that estimate has
// one degree of freedom and is correspondingly rough.
// Linearity error (IEEE Std 528-2001 "linearity error"): the largest |residual| of the straight
// line over the full-scale output span |k| (x_max - x_min) of the data, in percent.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "driftlab/calib/multi_position.h"

namespace driftlab::calib {

struct AxisReferenceFit {
  double sensitivity = 0.0;  // [output unit / input unit]
  double null = 0.0;         // [output unit]
  double linearity_error_percent = 0.0;
  CalibrationFit fit;  // parameters "<axis>.sensitivity", "<axis>.null"
};

// Per-axis straight-line fit of `output` against `input` (same length). Throws SpecError("data",
// ...) for fewer than 3 points, non-finite values, or fewer than 2 distinct input levels ("the
// data cannot determine <axis>.sensitivity: one input level").
AxisReferenceFit FitReferenceAxis(const std::vector<double>& input,
                                  const std::vector<double>& output, const std::string& axis,
                                  const std::string& input_unit, const std::string& output_unit);

struct MatrixReferenceFit {
  Eigen::Matrix3d K = Eigen::Matrix3d::Zero();  // [output / input]
  Eigen::Vector3d null = Eigen::Vector3d::Zero();
  Eigen::Vector3d linearity_error_percent = Eigen::Vector3d::Zero();
  CalibrationFit fit;  // parameters "K.xx" .. "K.zz", "null.x" .. "null.z"
};

// Full-matrix fit y_i = K x_i + y_0 over rows i (12 parameters). Throws SpecError when the inputs
// do not span three axes (names the undetermined parameter) or there are too few rows.
MatrixReferenceFit FitReferenceMatrix(const std::vector<Eigen::Vector3d>& input,
                                      const std::vector<Eigen::Vector3d>& output,
                                      const std::string& input_unit,
                                      const std::string& output_unit);

}  // namespace driftlab::calib
