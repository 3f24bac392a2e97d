// Dataset rows and the scoring of an external solution (see dataset_rows.h).
#include "driftlab/app/dataset_rows.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include "driftlab/spec_error.h"
#include "driftlab/units.h"

namespace driftlab::app {
namespace {

// Degrees at the API edge (as translate.cc converts job angles).

enum NavigationColumn { kT = 0, kLat, kLon, kHeight, kVn, kVe, kVd, kRoll, kPitch, kYaw };

}  // namespace

const std::vector<std::string>& ImuColumns() {
  static const std::vector<std::string> columns = {
      "t_s",          "dtheta_x_rad", "dtheta_y_rad",      "dtheta_z_rad",      "dv_x_m_per_s",
      "dv_y_m_per_s", "dv_z_m_per_s", "omega_x_rad_per_s", "omega_y_rad_per_s", "omega_z_rad_per_s",
      "f_x_m_per_s2", "f_y_m_per_s2", "f_z_m_per_s2"};
  return columns;
}

const std::vector<std::string>& TruthColumns() {
  static const std::vector<std::string> columns = {
      "t_s",         "lat_rad",     "lon_rad",  "h_m",       "v_n_m_per_s",
      "v_e_m_per_s", "v_d_m_per_s", "roll_rad", "pitch_rad", "yaw_rad"};
  return columns;
}

const std::vector<std::string>& NavigationColumns() {
  static const std::vector<std::string> columns = {"t_s",
                                                   "lat_deg",
                                                   "lon_deg",
                                                   "height_m",
                                                   "v_north_m_per_s",
                                                   "v_east_m_per_s",
                                                   "v_down_m_per_s",
                                                   "roll_deg",
                                                   "pitch_deg",
                                                   "yaw_deg"};
  return columns;
}

void AppendImuRow(double t_s, const ImuIncrement& increment, const ImuSample& sample,
                  std::vector<double>* out) {
  const double v[kImuRowSize] = {t_s,
                                 increment.delta_theta_ib_b.x(),
                                 increment.delta_theta_ib_b.y(),
                                 increment.delta_theta_ib_b.z(),
                                 increment.delta_v_ib_b.x(),
                                 increment.delta_v_ib_b.y(),
                                 increment.delta_v_ib_b.z(),
                                 sample.omega_ib_b.x(),
                                 sample.omega_ib_b.y(),
                                 sample.omega_ib_b.z(),
                                 sample.f_ib_b.x(),
                                 sample.f_ib_b.y(),
                                 sample.f_ib_b.z()};
  out->insert(out->end(), v, v + kImuRowSize);
}

void AppendTruthRow(const NavState& s, std::vector<double>* out) {
  const EulerAngles e = s.euler();
  const double v[kTruthRowSize] = {s.t_s,        s.llh.lat_rad, s.llh.lon_rad, s.llh.h_m,
                                   s.v_eb_n.x(), s.v_eb_n.y(),  s.v_eb_n.z(),  e.roll_rad,
                                   e.pitch_rad,  e.yaw_rad};
  out->insert(out->end(), v, v + kTruthRowSize);
}

void AppendNavigationRow(double t_s, const NavState& s, std::vector<double>* out) {
  const EulerAngles e = s.euler();
  const double v[kNavigationRowSize] = {t_s,
                                        kRadToDeg * s.llh.lat_rad,
                                        kRadToDeg * s.llh.lon_rad,
                                        s.llh.h_m,
                                        s.v_eb_n.x(),
                                        s.v_eb_n.y(),
                                        s.v_eb_n.z(),
                                        kRadToDeg * e.roll_rad,
                                        kRadToDeg * e.pitch_rad,
                                        kRadToDeg * e.yaw_rad};
  out->insert(out->end(), v, v + kNavigationRowSize);
}

SolutionColumns::SolutionColumns(const std::vector<std::string>& names, const std::string& field) {
  const std::vector<std::string>& known = NavigationColumns();
  std::fill(std::begin(index_), std::end(index_), -1);
  for (size_t i = 0; i < names.size(); ++i) {
    const auto it = std::find(known.begin(), known.end(), names[i]);
    const std::string path = fmt::format("{}[{}]", field, i);
    if (it == known.end()) {
      throw SpecError(path, "\"" + names[i] + "\"",
                      fmt::format("one of {} (any order)", fmt::join(known, ", ")));
    }
    int& slot = index_[it - known.begin()];
    if (slot >= 0) {
      throw SpecError(path, "\"" + names[i] + "\"",
                      fmt::format("each column once (also at {}[{}])", field, slot));
    }
    slot = static_cast<int>(i);
  }
  for (int c = 0; c < kNavigationRowSize; ++c) {
    if (index_[c] < 0) {
      throw SpecError(field, "no column " + known[static_cast<size_t>(c)],
                      fmt::format("the columns {} (any order)", fmt::join(known, ", ")));
    }
  }
  size_ = names.size();
}

SolutionState SolutionColumns::Parse(const double* row, uint64_t row_index,
                                     const std::string& field) const {
  const std::vector<std::string>& known = NavigationColumns();
  double v[kNavigationRowSize];
  for (int c = 0; c < kNavigationRowSize; ++c) {
    v[c] = row[index_[c]];
    if (!std::isfinite(v[c])) {
      throw SpecError(fmt::format("{}[{}].{}", field, row_index, known[static_cast<size_t>(c)]),
                      ValueText(v[c]), "a finite number");
    }
  }
  if (std::abs(v[kLat]) > 90.0) {
    throw SpecError(fmt::format("{}[{}].lat_deg", field, row_index), ValueText(v[kLat]),
                    "[-90, 90] deg");
  }
  SolutionState s;
  s.t_s = v[kT];
  s.llh.lat_rad = kDegToRad * v[kLat];
  s.llh.lon_rad = kDegToRad * v[kLon];
  s.llh.h_m = v[kHeight];
  s.v_eb_n = Eigen::Vector3d(v[kVn], v[kVe], v[kVd]);
  s.euler.roll_rad = kDegToRad * v[kRoll];
  s.euler.pitch_rad = kDegToRad * v[kPitch];
  s.euler.yaw_rad = kDegToRad * v[kYaw];
  return s;
}

NavError SolutionError(const NavEnvironment& env, const SolutionState& solution,
                       const NavState& truth) {
  NavError e;
  e.r_ned_m = env.PositionErrorNed(solution.llh, truth.llh);
  e.v_ned_m_per_s = solution.v_eb_n - truth.v_eb_n;
  e.euler_rad = EulerDifference(solution.euler, truth.euler());
  e.psi_nb_n_rad = AttitudeErrorNed(EulerToDcm(solution.euler), truth.C_b_n());
  return e;
}

RunScorer::RunScorer(const MonteCarloSpec& spec, uint32_t run, const std::atomic<bool>* cancel)
    : spec_(spec), run_(run) {
  const bool done = ReplayMonteCarloRun(
      spec, run, /*navigate=*/false,
      [&](const MonteCarloRunLayout& layout) {
        env_ = *layout.env;
        dt_s_ = layout.dt_s;
        reports_.reserve(layout.num_epochs + layout.num_checkpoints);
      },
      [&](const MonteCarloRunStep& step) {
        if (step.epoch < 0 && step.checkpoint < 0) return;
        Report r;
        r.t_s = step.report_t_s;
        r.epoch = step.epoch;
        r.checkpoint = step.checkpoint;
        r.truth = *step.truth;
        reports_.push_back(std::move(r));
      },
      cancel);
  cancelled_ = !done;
}

void RunScorer::Add(const SolutionState& state, uint64_t row_index, const std::string& field) {
  const double tolerance = kTimeMatchFraction * dt_s_;
  auto it = std::lower_bound(reports_.begin(), reports_.end(), state.t_s - tolerance,
                             [](const Report& r, double t) { return r.t_s < t; });
  if (it == reports_.end() || it->t_s > state.t_s + tolerance) return;
  if (it->error) {
    throw SpecError(
        fmt::format("{}[{}].t_s", field, row_index), ValueText(state.t_s),
        fmt::format("one row per epoch (a row at t_s = {} s came before)", ValueText(it->t_s)));
  }
  it->error = SolutionError(env_, state, it->truth);
}

MonteCarloStatistics RunScorer::Statistics(const std::string& field) const {
  const auto start = std::chrono::steady_clock::now();
  MonteCarloStatisticsData data;
  data.seed = spec_.seed;
  data.job_runs = spec_.runs;
  data.runs.push_back(RunRange{run_, run_ + 1});
  for (const Report& r : reports_) {
    if (!r.error) {
      throw SpecError(field, fmt::format("no row at t_s = {} s", ValueText(r.t_s)),
                      fmt::format("a row at every output epoch of the job ({} epochs and "
                                  "checkpoints, matched within {} s)",
                                  reports_.size(), ValueText(kTimeMatchFraction * dt_s_)));
    }
    const ErrorComponentValues v = ErrorComponentsOf(*r.error);
    if (r.epoch >= 0) {
      // As RunMonteCarlo's RunSink::Record: exact sums of x and x^2 of the one run.
      data.epoch_times_s.push_back(r.t_s);
      EpochSums& sums = data.epochs.emplace_back();
      for (int c = 0; c < kNumErrorComponents; ++c) {
        sums.sum[c].Add(v[static_cast<size_t>(c)]);
        sums.sum_squares[c].AddSquare(v[static_cast<size_t>(c)]);
      }
    }
    if (r.checkpoint >= 0) {
      CheckpointValues cp;
      cp.t_s = r.t_s;
      cp.run_index = {run_};
      cp.values = {v};
      data.checkpoints.push_back(std::move(cp));
    }
  }
  data.timings.threads = 1;
  data.timings.wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return MonteCarloStatistics(std::move(data));
}

}  // namespace driftlab::app
