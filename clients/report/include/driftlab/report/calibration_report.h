// HTML reports of the calibration and noise-model fits (`driftlab calibrate ... --report
// REPORT.html`, `driftlab allan DATA.csv --fit --report REPORT.html`): one self-contained file
// each with interactive plots (interactive_plot.h), like the Monte-Carlo report (html_report.h).
// All text from the input is HTML-escaped.
//
// Calibration report (v1::CalibrationResult, calibration.proto): data file, latitude, height;
// the static-detection summary (the pose list collapsed); with the recording: specific force and
// angular rate against time with the static poses shaded and numbered as in the pose list; the
// pose directions (azimuth and elevation of each pose's mean specific force, a map of the unit
// sphere); per fit a facts table (poses or rows used, Ceres iterations, residual RMS, fit time),
// the model equation and sign convention, the parameter table (value +- 1 sigma and unit, each
// number also in a data-value attribute at 17 significant digits; the same in ppm / mrad / mg /
// deg/h; a flag where |value| < 1 sigma), the correlation matrix (CalibrationFitResult.
// correlation) and a plot of the residuals against the pose (accel: |f| - g, m/s^2), the rotation
// from pose k (gyro: the two components of the down-direction error perpendicular to the measured
// down direction, rad) or the data row (reference), with +-RMS.
//
// Noise-fit report (v1::NoiseModelFit): per column a log-log plot of the overlapping Allan
// deviation in the terms table's units (deg/h, ug) with its 95 % confidence interval as a band
// (allan.h; NIST SP 1065 chi-square intervals), the fitted triad model's ADEV over the same taus
// (IEEE Std 952-1997 Annex C terms, calib/noise_fit.h), slope guides -1/2, 0, +1/2 and the
// read-off points of the kept terms; the fitted terms (value +- 1 sigma in SI and in datasheet
// units, the datasheet's figure beside when given); the fit tables; the job-schema sensor model as
// JSON.
#pragma once

#include <string>

#include "driftlab/app/calibration_job.h"
#include "driftlab/v1/calibration.pb.h"

namespace driftlab::app {

// `recording` (optional): the table the result was computed from, with `rate_hz` as in
// CalibrateSettings (0: the table's first column is t_s); adds the raw-recording plots.
std::string RenderCalibrationReport(const v1::CalibrationResult& result,
                                    const NumericTable* recording = nullptr, double rate_hz = 0.0);

// `data_name` titles the report (e.g. the CSV path).
std::string RenderNoiseFitReport(const v1::NoiseModelFit& fit, const std::string& data_name);

// The title of a noise-fit report rendered from the fit alone (`driftlab report FIT.json`, the
// server's web pages): the analysed columns, "gyro_x, gyro_y, ...".
std::string NoiseFitTitle(const v1::NoiseModelFit& fit);

}  // namespace driftlab::app
