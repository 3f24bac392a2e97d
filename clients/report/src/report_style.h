// Drawing limits and colours shared by the report's parts (html_report.cc, report_scenario.cc).
#pragma once

#include <cstdint>

namespace driftlab::app {

// At most this many epochs are drawn per envelope (every k-th and the last; the statistics
// tables use all), and this many runs in the scatter (the first by run index; the histograms use
// all): keeps a 1000000-run or 100000-epoch report to a few MB.
inline constexpr int kMaxDrawnEpochs = 2000;
inline constexpr int kMaxScatterPoints = 5000;
// The trajectory plot regenerates the truth from the job when it has at most this many steps
// (a 2-hour job at 100 Hz: 720000 steps) and draws at most kMaxDrawnEpochs points.
inline constexpr int64_t kMaxTrajectorySteps = 2000000;

inline constexpr const char* kBandColor = "#6baed6";
inline constexpr const char* kMeanColor = "#08519c";
inline constexpr const char* kRmsColor = "#cb181d";
inline constexpr const char* kCep50Color = "#238b45";
inline constexpr const char* kCep95Color = "#d94801";
inline constexpr const char* kBarColor = "#6baed6";
inline constexpr const char* kPredictedColor = "#252525";
inline constexpr const char* kOutageShade = "rgba(217,72,1,0.13)";
inline constexpr const char* kZuptShade = "rgba(35,139,69,0.13)";

}  // namespace driftlab::app
