// Monte-Carlo spec validation and the job plan: the fields' ranges, the filter/aiding/analysis
// combinations, the navigation start and report samples, and the memory a job needs.
#include <tbb/info.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "driftlab/ins_gnss_filter.h"
#include "driftlab/monte_carlo.h"
#include "driftlab/sensors.h"
#include "driftlab/spec_error.h"
#include "montecarlo/internal.h"

namespace driftlab {
namespace mc_detail {

namespace {

// Converts requested times into ascending sample indices in [first_k, n].
std::vector<int64_t> SnapTimes(const std::vector<double>& times_s, const std::string& field,
                               int64_t first_k, int64_t n, double dt_s) {
  std::vector<int64_t> out;
  const double t_min = static_cast<double>(first_k) * dt_s;
  const double t_max = static_cast<double>(n) * dt_s;
  const double slack = 0.5 * dt_s;
  const std::string allowed = "[" + ValueText(t_min) + ", " + ValueText(t_max) +
                              "] s (navigation start to trajectory end), strictly ascending";
  for (size_t i = 0; i < times_s.size(); ++i) {
    const double t = times_s[i];
    if (!std::isfinite(t) || t < t_min - slack || t > t_max + slack) {
      throw SpecError(IndexedField(field, i), ValueText(t), allowed);
    }
    const int64_t k = std::clamp<int64_t>(std::llround(t / dt_s), first_k, n);
    if (!out.empty() && k <= out.back()) {
      throw SpecError(
          IndexedField(field, i), ValueText(t),
          allowed + " after snapping to the IMU sample grid (dt = " + ValueText(dt_s) + " s)");
    }
    out.push_back(k);
  }
  return out;
}

std::string Gigabytes(uint64_t bytes) {
  std::ostringstream out;
  out.precision(3);
  out << static_cast<double>(bytes) / 1e9 << " GB";
  return out.str();
}

}  // namespace

void ValidateSigmas(const Eigen::Vector3d& v, const std::string& field, const std::string& unit) {
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(v[i]) || v[i] < 0.0) {
      throw SpecError(IndexedField(field, static_cast<size_t>(i)), ValueText(v[i]),
                      "a finite 1-sigma >= 0 [" + unit + "]");
    }
  }
}

const char* FilterName(NavigationFilterKind f) {
  switch (f) {
    case NavigationFilterKind::kNone:
      return "NONE";
    case NavigationFilterKind::kInsGnssEkf:
      return "INS_GNSS_EKF";
    case NavigationFilterKind::kComplementary:
      return "COMPLEMENTARY";
  }
  return "?";
}

void ValidateFilter(const MonteCarloSpec& spec) {
  const NavigationFilterKind f = spec.filter;
  const std::string name = FilterName(f);
  const bool seed000 = spec.simulation.mechanization == MechanizationKind::kSeed000;
  const bool truth_plus = spec.initialization == InitializationKind::kTruthPlusErrors;
  const bool free_vertical = spec.simulation.ned.vertical == VerticalChannel::kFree;
  const AidingSpec& a = spec.aiding;
  if (f != NavigationFilterKind::kNone) {
    if (seed000) {
      throw SpecError("navigation.filter", name,
                      "NONE with mechanization SEED000 (filters run on mechanization NED)");
    }
    if (!truth_plus) {
      throw SpecError("monte_carlo.initialization.kind", "STATIC_ALIGNMENT",
                      "TRUTH_PLUS_ERRORS with navigation.filter " + name);
    }
  }
  const auto only_with = [&](bool present, const std::string& field, const std::string& filter) {
    if (present && name != filter) {
      throw SpecError(field, "set",
                      "only with navigation.filter " + filter + " (the filter is " + name + ")");
    }
  };
  const std::vector<std::string> ekf_aids = AidingSensorPaths(a);
  for (const std::string& path : ekf_aids) only_with(true, path, "INS_GNSS_EKF");
  only_with(a.magnetometer.has_value(), "aiding.magnetometer", "COMPLEMENTARY");
  if (spec.filter_flicker_states_per_axis < 1 ||
      spec.filter_flicker_states_per_axis > kMaxFlickerComponents) {
    throw SpecError("navigation.ekf.flicker_states_per_axis",
                    std::to_string(spec.filter_flicker_states_per_axis),
                    "[1, " + std::to_string(kMaxFlickerComponents) + "]");
  }
  if (spec.filter_sensor) {
    if (f != NavigationFilterKind::kInsGnssEkf && !spec.covariance) {
      throw SpecError("navigation.ekf.sensor", "set",
                      "only with navigation.filter INS_GNSS_EKF or the covariance analysis (the "
                      "filter is " +
                          name + ")");
    }
    ValidateImuErrorModel(*spec.filter_sensor, "navigation.ekf.sensor");
  }
  if (f == NavigationFilterKind::kInsGnssEkf) {
    if (ekf_aids.empty()) {
      throw SpecError("navigation.filter", name,
                      "INS_GNSS_EKF with at least one of aiding.gnss, aiding.barometer, "
                      "aiding.zupt or another aiding sensor of the EKF (docs/aiding.md; an EKF "
                      "without measurements is the free INS: use NONE)");
    }
    if (!free_vertical) {
      throw SpecError("navigation.ned.vertical_channel", "TRUTH_HEIGHT",
                      "FREE with navigation.filter INS_GNSS_EKF (aid the height with "
                      "aiding.barometer instead)");
    }
    if (spec.ekf_propagation_step_samples < 1 || spec.ekf_propagation_step_samples > 10000) {
      throw SpecError("navigation.ekf.propagation_step_samples",
                      std::to_string(spec.ekf_propagation_step_samples), "[1, 10000]");
    }
  }
  if (f == NavigationFilterKind::kComplementary) {
    const InitialErrorSigmas& e = spec.initial_errors;
    if (!e.position_ned_m.isZero(0.0) || !e.velocity_ned_m_per_s.isZero(0.0) ||
        !e.fixed_position_ned_m.isZero(0.0) || !e.fixed_velocity_ned_m_per_s.isZero(0.0)) {
      throw SpecError("monte_carlo.initial_errors", "non-zero position or velocity errors",
                      "zero with navigation.filter COMPLEMENTARY (it estimates attitude only)");
    }
    if (!e.attitude_ned_rad.isZero(0.0) || !e.fixed_attitude_ned_rad.isZero(0.0)) {
      throw SpecError("monte_carlo.initial_errors.attitude_ned_deg", "non-zero",
                      "absent with navigation.filter COMPLEMENTARY (its initial yaw error is "
                      "monte_carlo.initial_errors.attitude_deg[2])");
    }
    if (e.attitude_rad.x() != 0.0 || e.attitude_rad.y() != 0.0) {
      throw SpecError("monte_carlo.initial_errors.attitude_deg", "non-zero roll or pitch sigma",
                      "zero roll and pitch with navigation.filter COMPLEMENTARY (it levels from "
                      "the accelerometer; only the initial yaw error is used)");
    }
    const double rate = spec.simulation.rate_hz;
    DesignComplementaryPair(spec.complementary.kind, spec.complementary.crossover_hz, rate,
                            "navigation.complementary.crossover_hz", "rate_hz");
    DesignComplementaryPair(spec.complementary.kind, spec.complementary.heading_crossover_hz, rate,
                            "navigation.complementary.heading_crossover_hz", "rate_hz");
  }
  if (spec.covariance) {
    if (seed000 || !truth_plus || !free_vertical || f == NavigationFilterKind::kComplementary) {
      throw SpecError("monte_carlo.covariance", "true",
                      "false unless mechanization NED, vertical channel FREE, initialization "
                      "TRUTH_PLUS_ERRORS and filter NONE or INS_GNSS_EKF (the 15-state error "
                      "model describes those)");
    }
    if (spec.covariance_step_samples < 1 || spec.covariance_step_samples > 10000) {
      throw SpecError("monte_carlo.covariance_step_samples",
                      std::to_string(spec.covariance_step_samples), "[1, 10000]");
    }
  }
}

void ValidateSpec(const MonteCarloSpec& spec) {
  if (spec.runs < 1 || spec.runs > kMaxMonteCarloRuns) {
    throw SpecError("monte_carlo.runs", std::to_string(spec.runs),
                    "[1, " + std::to_string(kMaxMonteCarloRuns) + "]");
  }
  if (spec.first_run >= spec.runs) {
    throw SpecError("monte_carlo.first_run", std::to_string(spec.first_run),
                    "[0, runs - 1] = [0, " + std::to_string(spec.runs - 1) + "]");
  }
  if (uint64_t{spec.first_run} + spec.run_count > spec.runs) {
    throw SpecError("monte_carlo.run_count", std::to_string(spec.run_count),
                    "first_run + run_count <= runs, i.e. <= " +
                        std::to_string(spec.runs - spec.first_run) + " (0 = all from first_run)");
  }
  if (spec.threads < 0 || spec.threads > kMaxMonteCarloThreads) {
    throw SpecError("monte_carlo.threads", std::to_string(spec.threads),
                    "[0, " + std::to_string(kMaxMonteCarloThreads) + "] (0 = all cores)");
  }
  ValidateSigmas(spec.initial_errors.position_ned_m, "monte_carlo.initial_errors.position_ned_m",
                 "m");
  ValidateSigmas(spec.initial_errors.velocity_ned_m_per_s,
                 "monte_carlo.initial_errors.velocity_ned_m_per_s", "m/s");
  ValidateSigmas(spec.initial_errors.attitude_rad, "monte_carlo.initial_errors.attitude_deg",
                 "rad");
  ValidateSigmas(spec.initial_errors.attitude_ned_rad,
                 "monte_carlo.initial_errors.attitude_ned_deg", "rad");
  const auto require_finite = [](const Eigen::Vector3d& v, const std::string& field) {
    for (int i = 0; i < 3; ++i) {
      if (!std::isfinite(v[i])) {
        throw SpecError(IndexedField(field, static_cast<size_t>(i)), ValueText(v[i]),
                        "a finite number");
      }
    }
  };
  require_finite(spec.initial_errors.fixed_position_ned_m,
                 "monte_carlo.initial_errors.fixed_position_ned_m");
  require_finite(spec.initial_errors.fixed_velocity_ned_m_per_s,
                 "monte_carlo.initial_errors.fixed_velocity_ned_m_per_s");
  require_finite(spec.initial_errors.fixed_attitude_ned_rad,
                 "monte_carlo.initial_errors.fixed_attitude_ned_deg");
  if (spec.epoch_times_s.empty()) {
    if (spec.epoch_every_samples < 1) {
      throw SpecError("monte_carlo.epoch_every_samples", std::to_string(spec.epoch_every_samples),
                      ">= 1 samples (or give epoch_times_s)");
    }
  } else if (spec.epoch_every_samples != 0) {
    throw SpecError("monte_carlo.epoch_every_samples", std::to_string(spec.epoch_every_samples),
                    "0 when epoch_times_s is given (one of the two)");
  }
  if (spec.checkpoint_times_s.size() + 1 > kMaxMonteCarloCheckpoints) {
    throw SpecError("monte_carlo.checkpoint_times_s",
                    std::to_string(spec.checkpoint_times_s.size()) + " times",
                    "at most " + std::to_string(kMaxMonteCarloCheckpoints - 1));
  }
  const bool seed000 = spec.simulation.mechanization == MechanizationKind::kSeed000;
  if (seed000) {
    if (spec.initialization != InitializationKind::kTruthPlusErrors) {
      throw SpecError("monte_carlo.initialization.kind", "STATIC_ALIGNMENT",
                      "TRUTH_PLUS_ERRORS with navigation.mechanization SEED000 (it initialises "
                      "itself from its static period)");
    }
    if (!spec.initial_errors.is_zero()) {
      throw SpecError("monte_carlo.initial_errors", "non-zero",
                      "zero with navigation.mechanization SEED000 (it initialises itself from its "
                      "static period)");
    }
  }
  if (!seed000 && spec.initialization == InitializationKind::kStaticAlignment) {
    const AlignmentOptions& a = spec.alignment;
    if (!std::isfinite(a.duration_s) || a.duration_s <= 0.0) {
      throw SpecError("monte_carlo.initialization.alignment_duration_s", ValueText(a.duration_s),
                      "a finite duration > 0 [s]");
    }
    if (a.heading_sigma_rad &&
        (!std::isfinite(*a.heading_sigma_rad) || *a.heading_sigma_rad <= 0.0)) {
      throw SpecError("monte_carlo.initialization.heading_sigma_deg",
                      ValueText(*a.heading_sigma_rad * 180.0 / M_PI),
                      "a finite 1-sigma > 0 [deg], or absent (always gyrocompass)");
    }
    if (!spec.initial_errors.attitude_is_zero()) {
      throw SpecError("monte_carlo.initial_errors", "non-zero attitude errors",
                      "no attitude errors with initialization STATIC_ALIGNMENT (the attitude "
                      "comes from the alignment)");
    }
  }
  ValidateFilter(spec);
}

JobPlan PlanJob(const MonteCarloSpec& spec, const TrajectoryGenerator& generator) {
  JobPlan plan;
  plan.n = generator.num_steps();
  const double dt_s = generator.dt_s();
  const bool seed000 = spec.simulation.mechanization == MechanizationKind::kSeed000;

  // Navigation start.
  if (seed000) {
    const double T = spec.simulation.seed000.static_period_s;
    if (T > generator.duration_s()) {
      throw SpecError(
          "navigation.seed000.static_period_s", ValueText(T),
          "at most the motion's duration (" + ValueText(generator.duration_s()) + " s)");
    }
    plan.start_step = std::llround(T / dt_s);  // Seed000Options: N = round(T / dt)
  } else if (spec.initialization == InitializationKind::kStaticAlignment) {
    const double T = spec.alignment.duration_s;
    plan.start_step = std::llround(T / dt_s);
    if (plan.start_step < 1 || plan.start_step > plan.n) {
      throw SpecError("monte_carlo.initialization.alignment_duration_s", ValueText(T),
                      "[" + ValueText(dt_s) + ", " + ValueText(generator.duration_s()) +
                          "] s (at least one IMU sample, at most the trajectory)");
    }
    // Static at every sample of the window and at every kink inside it.
    bool is_static = true;
    for (int64_t k = 0; k <= plan.start_step && is_static; ++k) {
      is_static = generator.IsStaticAt(static_cast<double>(k) * dt_s);
    }
    for (double t : generator.breakpoints_s()) {
      if (t <= static_cast<double>(plan.start_step) * dt_s) is_static &= generator.IsStaticAt(t);
    }
    if (!is_static) {
      throw SpecError("monte_carlo.initialization.alignment_duration_s", ValueText(T),
                      "a window over which the trajectory is static (the vehicle moves before " +
                          ValueText(static_cast<double>(plan.start_step) * dt_s) + " s)");
    }
    if (!spec.alignment.heading_sigma_rad && generator.environment().model() == EarthModel::kFlat) {
      throw SpecError("monte_carlo.initialization.heading_sigma_deg", "",
                      "a 1-sigma > 0 [deg] with the flat Earth model (no Earth rotation to "
                      "gyrocompass on)");
    }
  }

  // Epochs and checkpoints as sample indices.
  std::vector<int64_t> epoch_k;
  if (spec.epoch_times_s.empty()) {
    for (int64_t k = plan.start_step; k <= plan.n; k += spec.epoch_every_samples) {
      epoch_k.push_back(k);
      if (epoch_k.size() > kMaxMonteCarloEpochs) break;
    }
    if (epoch_k.back() != plan.n) epoch_k.push_back(plan.n);
    if (epoch_k.size() > kMaxMonteCarloEpochs) {
      // The job states the interval in seconds (monte_carlo.epoch_interval_s).
      const int64_t min_samples = (plan.n - plan.start_step) / (kMaxMonteCarloEpochs - 1) + 1;
      throw SpecError("monte_carlo.epoch_interval_s",
                      ValueText(static_cast<double>(spec.epoch_every_samples) * dt_s) + " s",
                      "at least " + ValueText(static_cast<double>(min_samples) * dt_s) +
                          " s, a multiple of 1 / rate_hz (at most " +
                          std::to_string(kMaxMonteCarloEpochs) + " epochs)");
    }
  } else {
    if (spec.epoch_times_s.size() > kMaxMonteCarloEpochs) {
      throw SpecError("monte_carlo.epoch_times_s", std::to_string(spec.epoch_times_s.size()),
                      "at most " + std::to_string(kMaxMonteCarloEpochs) + " epochs");
    }
    epoch_k =
        SnapTimes(spec.epoch_times_s, "monte_carlo.epoch_times_s", plan.start_step, plan.n, dt_s);
  }
  std::vector<int64_t> checkpoint_k = SnapTimes(
      spec.checkpoint_times_s, "monte_carlo.checkpoint_times_s", plan.start_step, plan.n, dt_s);
  if (checkpoint_k.empty() || checkpoint_k.back() != plan.n) checkpoint_k.push_back(plan.n);

  // Merge both ascending lists into the report list.
  size_t i = 0, j = 0;
  while (i < epoch_k.size() || j < checkpoint_k.size()) {
    Report r;
    const int64_t ke = i < epoch_k.size() ? epoch_k[i] : std::numeric_limits<int64_t>::max();
    const int64_t kc =
        j < checkpoint_k.size() ? checkpoint_k[j] : std::numeric_limits<int64_t>::max();
    r.k = std::min(ke, kc);
    if (ke == r.k) r.epoch = static_cast<int>(i++);
    if (kc == r.k) r.checkpoint = static_cast<int>(j++);
    plan.reports.push_back(r);
  }
  ValidateAidingSpec(spec.aiding, generator.rate_hz(), generator.duration_s());
  return plan;
}

uint64_t MemoryOfPlan(const MonteCarloSpec& spec, const JobPlan& plan, double rate_hz) {
  const uint64_t samples = static_cast<uint64_t>(plan.n) + 1;
  const bool seed000 = spec.simulation.mechanization == MechanizationKind::kSeed000;
  const bool point_samples = seed000 || spec.filter == NavigationFilterKind::kComplementary;
  uint64_t bytes = samples * (point_samples ? sizeof(ImuSample) : sizeof(ImuIncrement));
  if (!seed000 && spec.simulation.ned.vertical == VerticalChannel::kTruthHeight) {
    bytes += samples * 2 * sizeof(double);
  }
  const auto per_rate = [&](double aiding_hz, uint64_t item_bytes) {
    return aiding_hz > 0.0
               ? static_cast<uint64_t>(static_cast<double>(samples) * aiding_hz / rate_hz + 1.0) *
                     item_bytes
               : uint64_t{0};
  };
  // The truth at the aiding epochs (SharedTruth::AidingEpoch, at most one per aid and epoch) and
  // the ZUPT windows' epochs.
  for (const auto& aid : MakeAidingSensors(spec.aiding, rate_hz)) {
    const uint64_t epochs = samples / static_cast<uint64_t>(aid->decimation()) + 1;
    bytes += epochs * (sizeof(NavState) + sizeof(Vector3d) + 16);
    if (aid->OnlyWhileStatic()) bytes += epochs * sizeof(int64_t);
  }
  if (spec.aiding.magnetometer) bytes += per_rate(spec.aiding.magnetometer->rate_hz, 32);
  size_t epochs = 0, checkpoints = 0;
  for (const Report& r : plan.reports) {
    epochs += r.epoch >= 0;
    checkpoints += r.checkpoint >= 0;
  }
  bytes += plan.reports.size() * sizeof(Report);
  const uint64_t runs = spec.run_count == 0 ? spec.runs - spec.first_run : spec.run_count;
  // Per-run values at the checkpoints: the engine's, then the result's copy (proto and JSON text,
  // ~48 bytes a value).
  bytes += runs * checkpoints * (sizeof(ErrorComponentValues) + kNumErrorComponents * 48);
  // Per-thread exact sums per epoch (and the NEES sums of a filter), and the result's epochs.
  const uint64_t threads = spec.threads > 0
                               ? static_cast<uint64_t>(spec.threads)
                               : static_cast<uint64_t>(tbb::info::default_concurrency());
  bytes += (threads + 1) * epochs * (sizeof(EpochSums) + 2 * sizeof(ExactSum));
  bytes += epochs * kNumErrorComponents * 400;
  return bytes;
}

}  // namespace mc_detail

using mc_detail::Gigabytes;
using mc_detail::JobPlan;
using mc_detail::MemoryOfPlan;
using mc_detail::PlanJob;
using mc_detail::Report;
using mc_detail::ValidateFilter;
using mc_detail::ValidateSpec;

uint64_t EstimateMonteCarloMemoryBytes(const MonteCarloSpec& spec) {
  const TrajectoryGenerator generator(spec.simulation.motion, spec.simulation.rate_hz);
  return MemoryOfPlan(spec, PlanJob(spec, generator), generator.rate_hz());
}

void ValidateMonteCarloSpec(const MonteCarloSpec& spec) {
  ValidateSpec(spec);
  if (spec.sensor) ValidateImuErrorModel(*spec.sensor, "sensor");
  const TrajectoryGenerator generator(spec.simulation.motion, spec.simulation.rate_hz);
  // The Monte Carlo's statistics of roll, pitch and yaw errors mean nothing where roll and yaw are
  // undefined.
  if (const auto& singular = generator.euler_singularity()) {
    throw SpecError(singular->field, singular->message, 0);
  }
  const JobPlan plan = PlanJob(spec, generator);
  const uint64_t runs = spec.run_count == 0 ? spec.runs - spec.first_run : spec.run_count;
  size_t checkpoints = 0;
  for (const Report& r : plan.reports) checkpoints += r.checkpoint >= 0;
  if (runs * checkpoints > uint64_t{kMaxMonteCarloRuns} * 10) {
    throw SpecError("monte_carlo.checkpoint_times_s", std::to_string(checkpoints) + " checkpoints",
                    "runs x checkpoints <= " + std::to_string(uint64_t{kMaxMonteCarloRuns} * 10));
  }
  const uint64_t bytes = MemoryOfPlan(spec, plan, generator.rate_hz());
  if (spec.max_memory_bytes > 0 && bytes > spec.max_memory_bytes) {
    throw LimitError("monte_carlo",
                     "the job needs about " + Gigabytes(bytes) + " of memory (" +
                         std::to_string(plan.n + 1) +
                         " IMU samples of shared truth, runs x checkpoints of kept values); "
                         "allowed: at most " +
                         Gigabytes(spec.max_memory_bytes) +
                         " (raise the limit with driftlab run --max-memory-gb or the server's "
                         "--max-job-memory-gb; or shorten the motion, lower rate_hz, split runs "
                         "into shards)",
                     0);
  }
}

void ValidateFilterAndAiding(const MonteCarloSpec& spec) {
  ValidateFilter(spec);
  ValidateAidingSpec(spec.aiding, spec.simulation.rate_hz, -1.0);
}

}  // namespace driftlab
