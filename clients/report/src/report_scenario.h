// What a result's job simulated, regenerated from its echo for the report (html_report.h): the
// true trajectory north/east of the start with its length and top speed, the time windows to
// shade (GNSS outages, ZUPT periods), the "What was simulated" table (motion, IMU model in
// datasheet units, mechanization, aiding, filter, runs) and the trajectory plot.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "driftlab/v1/result.pb.h"
#include "interactive_plot.h"

namespace driftlab::app {

struct Scenario {
  bool regenerated = false;
  std::string note;  // why the truth was not regenerated
  std::vector<double> north_m, east_m;
  double distance_m = 0, max_speed_m_per_s = 0, duration_s = 0;
  std::vector<std::pair<double, double>> outages_s, zupts_s;
};

// Regenerates the truth of `result`'s job (at most kMaxTrajectorySteps (report_style.h) steps;
// otherwise, or when the motion cannot be regenerated here, `note` says why).
Scenario RegenerateScenario(const v1::JobResult& result);

// The "What was simulated" table.
std::string SetupTable(const v1::JobResult& result, const Scenario& scenario);

// Shaded time windows (GNSS outages, ZUPT periods) for the plots against time, and their key.
std::vector<plot::Shade> Shades(const Scenario& scenario);
std::string ShadeKey(const Scenario& scenario);

// The true trajectory, north against east of the start, or a sentence saying why there is none.
std::string TrajectoryPlot(const Scenario& scenario);

}  // namespace driftlab::app
