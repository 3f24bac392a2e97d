// One seeded run's data as numeric rows, and the scoring of an external navigation solution
// against that run's truth: what the gRPC Datasets service streams (ExportRun) and reads
// (ScoreSolution), reusable by the CLI's `export --server` / `score`.
//
// Row layouts (each value a double, row-major):
//  * IMU rows: the columns of imu.csv that `driftlab export` writes (io.h ImuCsvWriter): t_s, the
//    measured increment over (t_{k-1}, t_k] in body axes (dtheta_{x,y,z}_rad, dv_{x,y,z}_m_per_s)
//    and the measured point sample at t_k (omega_{x,y,z}_rad_per_s, f_{x,y,z}_m_per_s2).
//  * Truth rows: the columns of truth.csv (io.h NavStateCsvWriter): t_s, lat_rad, lon_rad, h_m,
//    v_{n,e,d}_m_per_s, roll_rad, pitch_rad, yaw_rad (Euler angles of C_b_n, attitude.h).
//  * Navigation rows (a solution; the API's edge unit for angles is the degree): t_s, lat_deg,
//    lon_deg, height_m, v_north_m_per_s, v_east_m_per_s, v_down_m_per_s, roll_deg, pitch_deg,
//    yaw_deg. The values are the same doubles the CSV writers print, so a row equals the CSV line
//    read back (the CSV prints shortest round-trip text).
//
// Scoring (RunScorer): the solution's errors against the truth at the job's output epochs, as
// ComputeNavError (nav_state.h) defines them, reduced to the one-run MonteCarloStatistics that
// RunMonteCarlo gives for a shard of that run alone. Position and velocity errors are computed
// as ComputeNavError does; the Euler-angle differences come from the solution's roll/pitch/yaw
// directly (EulerDifference), which is what ComputeNavError computes from a DCM with those angles,
// without the round trip through a rotation matrix.
#pragma once

#include <atomic>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "driftlab/attitude.h"
#include "driftlab/earth.h"
#include "driftlab/mc_statistics.h"
#include "driftlab/monte_carlo.h"
#include "driftlab/nav_state.h"

namespace driftlab::app {

inline constexpr int kImuRowSize = 13;
inline constexpr int kTruthRowSize = 10;
inline constexpr int kNavigationRowSize = 10;

// Column names (with units) of the three layouts above.
const std::vector<std::string>& ImuColumns();
const std::vector<std::string>& TruthColumns();
const std::vector<std::string>& NavigationColumns();

// Appends one row to `out`.
void AppendImuRow(double t_s, const ImuIncrement& increment, const ImuSample& sample,
                  std::vector<double>* out);
void AppendTruthRow(const NavState& state, std::vector<double>* out);
// The navigation row of `state` at time t_s (the solution's own t_s is not used: mechanizations
// keep their own clock).
void AppendNavigationRow(double t_s, const NavState& state, std::vector<double>* out);

// One row of an external solution in SI (angles in radians).
struct SolutionState {
  double t_s = 0.0;
  Llh llh;
  Eigen::Vector3d v_eb_n = Eigen::Vector3d::Zero();  // N, E, D [m/s]
  EulerAngles euler;                                 // of C_b_n [rad]
};

// The column layout of an external solution: the names of NavigationColumns() in any order, each
// exactly once (t_s required; all ten are needed for the ten error components).
class SolutionColumns {
 public:
  // Throws SpecError naming `field` (e.g. "header.columns[3]") for an unknown or repeated name,
  // or `field` itself for a missing one.
  SolutionColumns(const std::vector<std::string>& names, const std::string& field);
  size_t size() const { return size_; }
  // The state of one row (size() values). Throws SpecError naming "<field>[<row>].<column>" for a
  // non-finite value or a latitude outside [-90, 90] deg.
  SolutionState Parse(const double* row, uint64_t row_index, const std::string& field) const;

 private:
  size_t size_ = 0;
  int index_[kNavigationRowSize] = {};  // position of each NavigationColumns() name in a row
};

// The errors ComputeNavError gives for an estimate with this position, velocity and attitude.
NavError SolutionError(const NavEnvironment& env, const SolutionState& solution,
                       const NavState& truth);

// Scores one run of a Monte-Carlo job: the constructor replays the run's truth
// (ReplayMonteCarloRun without navigation) to learn its output epochs and the truth there; Add
// takes the solution's rows in any order (rows at other times are ignored), Statistics reduces
// the errors at the epochs. A row belongs to an epoch when |t_s - t_epoch| <= kTimeMatchFraction
// dt: the epochs are IMU samples dt apart, so a time that differs from k dt only by rounding
// (k / rate_hz, a printed decimal) matches sample k and no other.
class RunScorer {
 public:
  static constexpr double kTimeMatchFraction = 1e-3;

  // Throws SpecError (the job's validation, as RunMonteCarlo). `cancel` as ReplayMonteCarloRun;
  // cancelled() tells whether it stopped the replay.
  RunScorer(const MonteCarloSpec& spec, uint32_t run, const std::atomic<bool>* cancel = nullptr);

  bool cancelled() const { return cancelled_; }
  double dt_s() const { return dt_s_; }
  size_t num_epochs() const { return reports_.size(); }

  // Adds one solution row (its index names it in errors). Throws SpecError
  // "<field>[<row>].t_s" for a second row at the same epoch.
  void Add(const SolutionState& state, uint64_t row_index, const std::string& field);

  // The one-run statistics (seed, job runs and the run as RunMonteCarlo's shard [run, run + 1)).
  // Throws SpecError naming the first epoch time without a solution row.
  MonteCarloStatistics Statistics(const std::string& field) const;

 private:
  struct Report {
    double t_s = 0.0;  // k dt as the statistics report it
    int epoch = -1;
    int checkpoint = -1;
    NavState truth;
    std::optional<NavError> error;
  };
  MonteCarloSpec spec_;
  uint32_t run_ = 0;
  NavEnvironment env_ = NavEnvironment::Wgs84();
  double dt_s_ = 0.0;
  std::vector<Report> reports_;  // ascending t_s
  bool cancelled_ = false;
};

}  // namespace driftlab::app
