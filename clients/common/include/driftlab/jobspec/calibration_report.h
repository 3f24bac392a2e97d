// HTML reports of the calibration and noise-model fits (issue 5, item 7: `driftlab calibrate ...
// --report REPORT.html`, `driftlab allan DATA.csv --fit --report REPORT.html`): one
// self-contained file each (inline SVG and CSS, no script, no external resource), like the
// Monte-Carlo report (html_report.h). All text from the input is HTML-escaped.
//
// Calibration report (v1::CalibrationResult, calibration.proto): data file, latitude, height;
// the static-detection summary and the other messages; per fit a facts table (poses or rows used,
// Ceres iterations, residual RMS, fit time), the parameter table (value +- 1 sigma and unit; each
// number also in a data-value attribute at 17 significant digits) and a plot of the residuals
// against the pose (accel: |f| - g per static pose, m/s^2), the rotation (gyro: the two
// components of the down-direction error perpendicular to the measured down direction, rad) or
// the data row (reference: output residual per row, per axis or per output axis x, y, z for the
// full-matrix fit), one polyline per residual series with a marker per residual, the zero line
// and +-RMS. SI units except where a parameter says otherwise.
//
// Noise-fit report (v1::NoiseModelFit): per column a log-log plot of the overlapping Allan
// deviation with its 95 % confidence interval as error bars (allan.h; NIST SP 1065 chi-square
// intervals) and the fitted triad model's ADEV over the same taus (IEEE Std 952-1997 Annex C
// terms, calib/noise_fit.h), two polylines per plot; the fitted terms (value +- 1 sigma in SI and
// in datasheet units, the datasheet's figure beside when given); the fit tables; the job-schema
// sensor model as JSON.
#pragma once

#include <string>

#include "driftlab/jobspec/calibration_job.h"
#include "driftlab/v1/calibration.pb.h"

namespace driftlab::jobspec {

// `recording` (optional): the table the result was computed from, with `rate_hz` as in
// CalibrateSettings (0: the table's first column is t_s); adds the raw-recording plots.
std::string RenderCalibrationReport(const v1::CalibrationResult& result,
                                    const NumericTable* recording = nullptr, double rate_hz = 0.0);

// `data_name` titles the report (e.g. the CSV path).
std::string RenderNoiseFitReport(const v1::NoiseModelFit& fit, const std::string& data_name);

}  // namespace driftlab::jobspec
