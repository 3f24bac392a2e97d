// Monte-Carlo error statistics: mergeable per-epoch moments and per-run values at checkpoints
// (DESIGN.md "Statistics", invariant 5).
//
// The navigation errors of one run at one epoch (nav_state.h, ComputeNavError: estimate minus
// truth, position in metres along N, E, D at the truth point, velocity in NED, roll/pitch/yaw
// differences wrapped to (-pi, pi]) are reduced to the 11 components of ErrorComponent.
//
// Per epoch, every component's sum of x and of x^2 over the runs is kept in an ExactSum
// (exact_sum.h), so statistics are bit-identical for any thread count and any grouping of shard
// merges (the sums are exact; the merge order is irrelevant). At checkpoints (the final epoch
// always, plus listed times) the per-run values are kept, sorted by run index, for percentiles,
// CEP and maxima.
//
// Summaries (N = number of runs):
//   mean  = S1 / N;   std = sqrt((S2 - S1^2 / N) / (N - 1));   rms = sqrt(S2 / N)
//   95 % CI of std: [std sqrt((N-1) / chi2_{0.975}(N-1)), std sqrt((N-1) / chi2_{0.025}(N-1))]
//   95 % CI of rms: [rms sqrt(N / chi2_{0.975}(N)),       rms sqrt(N / chi2_{0.025}(N))]
//   (for Gaussian errors: (N-1) s^2 / sigma^2 ~ chi2(N-1); for zero-mean Gaussian errors
//   N rms^2 / sigma^2 ~ chi2(N); e.g. Papoulis & Pillai, "Probability, Random Variables and
//   Stochastic Processes", 4th ed., section 8.3). With N = 1 std and the CIs are NaN.
//   Percentiles of |x| at checkpoints: the linear interpolation of the sorted sample
//   x_(0) <= ... <= x_(N-1) at h = (N - 1) p, i.e. x_(floor h) + (h - floor h)(x_(floor h + 1) -
//   x_(floor h)) (definition 7 of R. J. Hyndman, Y. Fan, Am. Stat. 50 (1996) 361; numpy's default).
//   CEP50, CEP95 = the 50th and 95th percentiles of the horizontal position error (empirical
//   circular error probable); 2DRMS = 2 sqrt(mean(dN^2 + dE^2)); max = largest |x|.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "driftlab/exact_sum.h"
#include "driftlab/nav_state.h"

namespace driftlab {

// Error components reported per epoch. Units: [m], [m/s], [rad].
enum class ErrorComponent : int {
  kPositionNorth = 0,       // [m]
  kPositionEast = 1,        // [m]
  kPositionDown = 2,        // [m]
  kVelocityNorth = 3,       // [m/s]
  kVelocityEast = 4,        // [m/s]
  kVelocityDown = 5,        // [m/s]
  kRoll = 6,                // [rad] roll difference
  kPitch = 7,               // [rad]
  kYaw = 8,                 // [rad]
  kHorizontalPosition = 9,  // [m] sqrt(dN^2 + dE^2)
  kPosition3d = 10,         // [m] |dr|
};
inline constexpr int kNumErrorComponents = 11;

// Snake-case name with unit, e.g. "position_north_m", "yaw_rad", "horizontal_position_m".
std::string_view ErrorComponentName(ErrorComponent component);

// One run's 11 error components at one epoch, indexed by ErrorComponent.
using ErrorComponentValues = std::array<double, kNumErrorComponents>;

// The 11 components of a navigation error.
ErrorComponentValues ErrorComponentsOf(const NavError& error);

// Per-epoch exact sums over runs, indexed by ErrorComponent.
struct EpochSums {
  std::array<ExactSum, kNumErrorComponents> sum;          // sum of x [unit]
  std::array<ExactSum, kNumErrorComponents> sum_squares;  // sum of x^2 [unit^2], exact squares
};

// Per-run values at one checkpoint, ascending by run index.
struct CheckpointValues {
  double t_s = 0.0;                          // time since the start of the trajectory [s]
  std::vector<uint32_t> run_index;           // strictly ascending
  std::vector<ErrorComponentValues> values;  // values[i] belongs to run run_index[i]
};

// Half-open range of run indices [first, end).
struct RunRange {
  uint32_t first = 0;
  uint32_t end = 0;
  bool operator==(const RunRange&) const = default;
};

// Cost of the computation that produced the statistics (summed over merged parts).
struct MonteCarloTimings {
  double wall_s = 0.0;            // wall-clock time of RunMonteCarlo (sum over merged parts)
  double truth_s = 0.0;           // of which: generating the shared truth
  int64_t samples_processed = 0;  // IMU samples through sensor model + mechanization, all runs
  int threads = 0;                // worker threads used (max over merged parts)
};

// Everything a MonteCarloStatistics holds, as plain data (the CLI converts it to and from the
// result proto).
struct MonteCarloStatisticsData {
  uint64_t seed = 0;      // the job's seed
  uint32_t job_runs = 0;  // runs of the whole job (all shards)
  // Runs included, ascending, disjoint, adjacent ranges joined.
  std::vector<RunRange> runs;
  std::vector<double> epoch_times_s;          // strictly ascending [s]
  std::vector<EpochSums> epochs;              // parallel to epoch_times_s
  std::vector<CheckpointValues> checkpoints;  // ascending t_s; the last is the final epoch
  MonteCarloTimings timings;
  // True if the job was cancelled: then runs, epochs and checkpoint values are empty.
  bool cancelled = false;
};

// Summary of one component at one epoch (units of the component).
struct ComponentEpochSummary {
  double mean = 0.0;
  double std = 0.0;  // sample standard deviation, N - 1 in the denominator
  double rms = 0.0;
  double std_ci95_low = 0.0, std_ci95_high = 0.0;
  double rms_ci95_low = 0.0, rms_ci95_high = 0.0;
};

struct EpochSummary {
  double t_s = 0.0;
  uint64_t runs = 0;
  std::array<ComponentEpochSummary, kNumErrorComponents> components;
};

// Distribution of |x| of one component at a checkpoint.
struct ComponentDistribution {
  double p50 = 0.0, p68 = 0.0, p95 = 0.0, p99 = 0.0;
  double max = 0.0;
};

struct CheckpointSummary {
  double t_s = 0.0;
  uint64_t runs = 0;
  std::array<ComponentDistribution, kNumErrorComponents> abs;
  double cep50_m = 0.0;  // = abs[kHorizontalPosition].p50
  double cep95_m = 0.0;  // = abs[kHorizontalPosition].p95
  double drms2_m = 0.0;  // 2DRMS
};

// Percentile (p in [0, 1]) of an ascending sample by Hyndman & Fan definition 7 (see above).
double SortedPercentile(const std::vector<double>& ascending, double p);

class MonteCarloStatistics {
 public:
  MonteCarloStatistics() = default;
  // Takes the data after checking its consistency (sizes, ascending times, disjoint run ranges
  // inside [0, job_runs), checkpoint runs equal to the runs); throws SpecError naming `field`.
  explicit MonteCarloStatistics(MonteCarloStatisticsData data,
                                const std::string& field = "statistics");

  const MonteCarloStatisticsData& data() const { return data_; }
  bool cancelled() const { return data_.cancelled; }
  uint64_t run_count() const;
  size_t num_epochs() const { return data_.epoch_times_s.size(); }
  size_t num_checkpoints() const { return data_.checkpoints.size(); }

  // Adds the runs of `other` (a shard of the same job). Requires the same seed, job_runs, epoch
  // times and checkpoint times, disjoint runs, and neither part cancelled; throws SpecError
  // (field "statistics.runs", "statistics.epoch_times_s", ...) otherwise. The result does not
  // depend on the order or grouping of merges.
  void Merge(const MonteCarloStatistics& other);

  EpochSummary SummarizeEpoch(size_t epoch) const;
  std::vector<EpochSummary> SummarizeEpochs() const;
  CheckpointSummary SummarizeCheckpoint(size_t checkpoint) const;

 private:
  MonteCarloStatisticsData data_;
};

}  // namespace driftlab
