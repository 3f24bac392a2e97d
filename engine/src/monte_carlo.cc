// Monte-Carlo runner: validation, the shared truth, the per-run loop and the parallel reduction
// (see monte_carlo.h).
#include "driftlab/monte_carlo.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "driftlab/ins_gnss_filter.h"
#include "driftlab/random.h"
#include "driftlab/sensors.h"
#include "driftlab/spec_error.h"
#include "lockstep_ned.h"

namespace driftlab {

namespace {

using Clock = std::chrono::steady_clock;

// Cancellation and progress are polled every kPollSamples samples of a run.
constexpr int64_t kPollSamples = 1024;
constexpr int64_t kProgressInterval_ns = 100'000'000;  // at most 10 progress calls per second

std::string Num(double v) {
  std::ostringstream os;
  os.precision(17);
  os << v;
  return os.str();
}

std::string Indexed(const std::string& field, size_t i) {
  return field + "[" + std::to_string(i) + "]";
}

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

void ValidateSigmas(const Eigen::Vector3d& v, const std::string& field, const std::string& unit) {
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(v[i]) || v[i] < 0.0) {
      throw SpecError(Indexed(field, static_cast<size_t>(i)), Num(v[i]),
                      "a finite 1-sigma >= 0 [" + unit + "]");
    }
  }
}

// A sample at which errors are reported: an epoch (per-epoch sums), a checkpoint (per-run values)
// or both. `truth` is the truth state at sample k.
struct Report {
  int64_t k = 0;
  int epoch = -1;
  int checkpoint = -1;
  NavState truth;
};

// What the runs share, read-only.
struct SharedTruth {
  NavEnvironment env;
  double dt_s = 0.0;
  double rate_hz = 0.0;
  int64_t n = 0;           // output intervals; samples k = 0..n
  int64_t start_step = 0;  // s0: sample at which navigation starts
  NavState truth0;         // truth at t = 0
  NavState truth_start;    // truth at s0
  // Mechanization A: increments[k] covers (t_{k-1}, t_k], k = 1..n (index 0 unused).
  std::vector<ImuIncrement> increments;
  // Mechanization B: point samples k = 0..n.
  std::vector<ImuSample> samples;
  // Truth-height aiding: h and v_D at every sample.
  std::vector<double> h_m, v_D_m_per_s;
  std::vector<Report> reports;  // ascending k, all >= start_step
  // Aiding: truth at the GNSS epochs j (sample j * gnss_decimation) and the ideal body rate there;
  // truth height at the barometer epochs; truth attitude at the magnetometer epochs; ZUPT samples.
  int64_t gnss_decimation = 0, baro_decimation = 0, mag_decimation = 0;
  std::vector<NavState> gnss_truth;
  std::vector<Vector3d> gnss_omega_ib_b;
  std::vector<double> baro_h_m;
  std::vector<Quaterniond> mag_q_b_n;
  std::vector<int64_t> zupt_epochs;
  // kInsGnssEkf: the filter's noise model and initial covariance.
  ErrorStateNoise ekf_noise;
  ErrorStateMatrix ekf_P0;
};

// Converts requested times into ascending sample indices in [first_k, n].
std::vector<int64_t> SnapTimes(const std::vector<double>& times_s, const std::string& field,
                               int64_t first_k, int64_t n, double dt_s) {
  std::vector<int64_t> out;
  const double t_min = static_cast<double>(first_k) * dt_s;
  const double t_max = static_cast<double>(n) * dt_s;
  const double slack = 0.5 * dt_s;
  const std::string allowed = "[" + Num(t_min) + ", " + Num(t_max) +
                              "] s (navigation start to trajectory end), strictly ascending";
  for (size_t i = 0; i < times_s.size(); ++i) {
    const double t = times_s[i];
    if (!std::isfinite(t) || t < t_min - slack || t > t_max + slack) {
      throw SpecError(Indexed(field, i), Num(t), allowed);
    }
    const int64_t k = std::clamp<int64_t>(std::llround(t / dt_s), first_k, n);
    if (!out.empty() && k <= out.back()) {
      throw SpecError(
          Indexed(field, i), Num(t),
          allowed + " after snapping to the IMU sample grid (dt = " + Num(dt_s) + " s)");
    }
    out.push_back(k);
  }
  return out;
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

// The filter, the aiding and the covariance analysis fit together and with the navigation.
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
  only_with(a.gnss.has_value(), "aiding.gnss", "INS_GNSS_EKF");
  only_with(a.barometer.has_value(), "aiding.barometer", "INS_GNSS_EKF");
  only_with(a.zupt.has_value(), "aiding.zupt", "INS_GNSS_EKF");
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
    if (!a.gnss && !a.barometer && !a.zupt) {
      throw SpecError("navigation.filter", name,
                      "INS_GNSS_EKF with at least one of aiding.gnss, aiding.barometer, "
                      "aiding.zupt (an EKF without measurements is the free INS: use NONE)");
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
    if (!e.position_ned_m.isZero(0.0) || !e.velocity_ned_m_per_s.isZero(0.0)) {
      throw SpecError("monte_carlo.initial_errors", "non-zero position or velocity sigma",
                      "zero with navigation.filter COMPLEMENTARY (it estimates attitude only)");
    }
    if (e.attitude_rad.x() != 0.0 || e.attitude_rad.y() != 0.0) {
      throw SpecError("monte_carlo.initial_errors.attitude_rad", "non-zero roll or pitch sigma",
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

// Validates the Monte-Carlo fields that do not need the trajectory.
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
  ValidateSigmas(spec.initial_errors.attitude_rad, "monte_carlo.initial_errors.attitude_rad",
                 "rad");
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
      throw SpecError("monte_carlo.initialization", "static_alignment",
                      "truth_plus_errors with mechanization seed000 (it initialises itself from "
                      "its static period)");
    }
    const InitialErrorSigmas& e = spec.initial_errors;
    if (!e.position_ned_m.isZero(0.0) || !e.velocity_ned_m_per_s.isZero(0.0) ||
        !e.attitude_rad.isZero(0.0)) {
      throw SpecError("monte_carlo.initial_errors", "non-zero",
                      "zero with mechanization seed000 (it initialises itself from its static "
                      "period)");
    }
  }
  if (!seed000 && spec.initialization == InitializationKind::kStaticAlignment) {
    const AlignmentOptions& a = spec.alignment;
    if (!std::isfinite(a.duration_s) || a.duration_s <= 0.0) {
      throw SpecError("monte_carlo.alignment.duration_s", Num(a.duration_s),
                      "a finite duration > 0 [s]");
    }
    if (a.heading_sigma_rad &&
        (!std::isfinite(*a.heading_sigma_rad) || *a.heading_sigma_rad <= 0.0)) {
      throw SpecError("monte_carlo.alignment.heading_sigma_rad", Num(*a.heading_sigma_rad),
                      "a finite 1-sigma > 0 [rad], or absent (always gyrocompass)");
    }
    if (!spec.initial_errors.attitude_rad.isZero(0.0)) {
      throw SpecError("monte_carlo.initial_errors.attitude_rad", "non-zero",
                      "zero with initialization static_alignment (the attitude comes from the "
                      "alignment)");
    }
  }
  ValidateFilter(spec);
}

// The layout of a job, from the motion's plan alone (no trajectory streamed): navigation start,
// the report samples (epochs and checkpoints), with every check that needs the trajectory.
struct JobPlan {
  int64_t n = 0;                // output intervals; samples k = 0..n
  int64_t start_step = 0;       // s0
  std::vector<Report> reports;  // truth states not filled in
};

JobPlan PlanJob(const MonteCarloSpec& spec, const TrajectoryGenerator& generator) {
  JobPlan plan;
  plan.n = generator.num_steps();
  const double dt_s = generator.dt_s();
  const bool seed000 = spec.simulation.mechanization == MechanizationKind::kSeed000;

  // Navigation start.
  if (seed000) {
    const double T = spec.simulation.seed000.static_period_s;
    if (T > generator.duration_s()) {
      throw SpecError("navigation.seed000.static_period_s", Num(T),
                      "at most the motion's duration (" + Num(generator.duration_s()) + " s)");
    }
    plan.start_step = std::llround(T / dt_s);  // Seed000Options: N = round(T / dt)
  } else if (spec.initialization == InitializationKind::kStaticAlignment) {
    const double T = spec.alignment.duration_s;
    plan.start_step = std::llround(T / dt_s);
    if (plan.start_step < 1 || plan.start_step > plan.n) {
      throw SpecError("monte_carlo.alignment.duration_s", Num(T),
                      "[" + Num(dt_s) + ", " + Num(generator.duration_s()) +
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
      throw SpecError("monte_carlo.alignment.duration_s", Num(T),
                      "a window over which the trajectory is static (the vehicle moves before " +
                          Num(static_cast<double>(plan.start_step) * dt_s) + " s)");
    }
    if (!spec.alignment.heading_sigma_rad && generator.environment().model() == EarthModel::kFlat) {
      throw SpecError("monte_carlo.alignment.heading_sigma_rad", "",
                      "a 1-sigma > 0 [rad] with the flat Earth model (no Earth rotation to "
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
      throw SpecError(
          "monte_carlo.epoch_every_samples", std::to_string(spec.epoch_every_samples),
          "at least " +
              std::to_string((plan.n - plan.start_step) / (kMaxMonteCarloEpochs - 1) + 1) +
              " (at most " + std::to_string(kMaxMonteCarloEpochs) + " epochs)");
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

// Memory of a job [bytes] from its plan (EstimateMonteCarloMemoryBytes, monte_carlo.h).
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
  if (spec.aiding.gnss) bytes += per_rate(spec.aiding.gnss->rate_hz, sizeof(NavState) + 24);
  if (spec.aiding.barometer) bytes += per_rate(spec.aiding.barometer->rate_hz, sizeof(double));
  if (spec.aiding.magnetometer) bytes += per_rate(spec.aiding.magnetometer->rate_hz, 32);
  if (spec.aiding.zupt) bytes += samples * sizeof(int64_t);
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

std::string Gigabytes(uint64_t bytes) {
  std::ostringstream out;
  out.precision(3);
  out << static_cast<double>(bytes) / 1e9 << " GB";
  return out.str();
}

}  // namespace

uint64_t EstimateMonteCarloMemoryBytes(const MonteCarloSpec& spec) {
  const TrajectoryGenerator generator(spec.simulation.motion, spec.simulation.rate_hz);
  return MemoryOfPlan(spec, PlanJob(spec, generator), generator.rate_hz());
}

void ValidateMonteCarloSpec(const MonteCarloSpec& spec) {
  ValidateSpec(spec);
  if (spec.sensor) ValidateImuErrorModel(*spec.sensor, "sensor");
  const TrajectoryGenerator generator(spec.simulation.motion, spec.simulation.rate_hz);
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

namespace {

// Generates the truth once and keeps what the runs need (without keep_imu: only the layout, the
// reports and the start state, for ReplayMonteCarloRun). `cancel` is polled while the trajectory
// streams (every 4096 samples); when it is set the function returns early with `cancelled`.
SharedTruth BuildSharedTruth(const MonteCarloSpec& spec, bool keep_imu = true,
                             const std::atomic<bool>* cancel = nullptr, bool* cancelled = nullptr) {
  TrajectoryGenerator generator(spec.simulation.motion, spec.simulation.rate_hz);
  SharedTruth s;
  s.env = generator.environment();
  s.dt_s = generator.dt_s();
  s.rate_hz = generator.rate_hz();
  s.truth0 = generator.initial_state();
  const bool seed000 = spec.simulation.mechanization == MechanizationKind::kSeed000;
  JobPlan plan = PlanJob(spec, generator);
  s.n = plan.n;
  s.start_step = plan.start_step;
  s.reports = std::move(plan.reports);

  const AidingSpec& aiding = spec.aiding;
  if (keep_imu && aiding.gnss) {
    s.gnss_decimation = AidingDecimation(aiding.gnss->rate_hz, s.rate_hz, "aiding.gnss.rate_hz");
    s.gnss_truth.resize(static_cast<size_t>(s.n / s.gnss_decimation) + 1);
    s.gnss_omega_ib_b.resize(s.gnss_truth.size(), Vector3d::Zero());
    s.gnss_truth[0] = s.truth0;
  }
  if (keep_imu && aiding.barometer) {
    s.baro_decimation =
        AidingDecimation(aiding.barometer->rate_hz, s.rate_hz, "aiding.barometer.rate_hz");
    s.baro_h_m.resize(static_cast<size_t>(s.n / s.baro_decimation) + 1);
    s.baro_h_m[0] = s.truth0.llh.h_m;
  }
  if (keep_imu && aiding.magnetometer) {
    s.mag_decimation =
        AidingDecimation(aiding.magnetometer->rate_hz, s.rate_hz, "aiding.magnetometer.rate_hz");
    s.mag_q_b_n.resize(static_cast<size_t>(s.n / s.mag_decimation) + 1);
    s.mag_q_b_n[0] = s.truth0.q_b_n;
  }
  if (keep_imu && aiding.zupt) {
    s.zupt_epochs = ZuptEpochs(*aiding.zupt, s.rate_hz, s.start_step + 1, s.n,
                               [&](double t) { return generator.IsStaticAt(t); });
  }
  // Point samples for mechanization B and the complementary filter, increments otherwise.
  const bool point_samples = seed000 || spec.filter == NavigationFilterKind::kComplementary;

  // Stream the trajectory once.
  const bool truth_height =
      keep_imu && !seed000 && spec.simulation.ned.vertical == VerticalChannel::kTruthHeight;
  if (keep_imu && point_samples) {
    s.samples.resize(static_cast<size_t>(s.n) + 1);
    s.samples[0] = generator.initial_sample();
  } else if (keep_imu) {
    s.increments.resize(static_cast<size_t>(s.n) + 1);
  }
  if (truth_height) {
    s.h_m.resize(static_cast<size_t>(s.n) + 1);
    s.v_D_m_per_s.resize(static_cast<size_t>(s.n) + 1);
    s.h_m[0] = s.truth0.llh.h_m;
    s.v_D_m_per_s[0] = s.truth0.v_eb_n.z();
  }
  size_t next_report = 0;
  auto keep_truth = [&](int64_t k, const NavState& truth) {
    if (k == s.start_step) s.truth_start = truth;
    while (next_report < s.reports.size() && s.reports[next_report].k == k) {
      s.reports[next_report++].truth = truth;
    }
  };
  keep_truth(0, s.truth0);
  TrajectorySample sample;
  while (generator.Next(&sample)) {
    const int64_t k = generator.step();
    if (cancel != nullptr && (k & 4095) == 0 && cancel->load(std::memory_order_relaxed)) {
      if (cancelled != nullptr) *cancelled = true;
      return s;
    }
    const size_t uk = static_cast<size_t>(k);
    if (keep_imu && point_samples) {
      s.samples[uk] = sample.sample;
    } else if (keep_imu) {
      s.increments[uk] = sample.increment;
    }
    if (s.gnss_decimation > 0 && k % s.gnss_decimation == 0) {
      const size_t j = static_cast<size_t>(k / s.gnss_decimation);
      s.gnss_truth[j] = sample.truth;
      s.gnss_omega_ib_b[j] = sample.increment.delta_theta_ib_b / s.dt_s;
    }
    if (s.baro_decimation > 0 && k % s.baro_decimation == 0) {
      s.baro_h_m[static_cast<size_t>(k / s.baro_decimation)] = sample.truth.llh.h_m;
    }
    if (s.mag_decimation > 0 && k % s.mag_decimation == 0) {
      s.mag_q_b_n[static_cast<size_t>(k / s.mag_decimation)] = sample.truth.q_b_n;
    }
    if (truth_height) {
      s.h_m[uk] = sample.truth.llh.h_m;
      s.v_D_m_per_s[uk] = sample.truth.v_eb_n.z();
    }
    keep_truth(k, sample.truth);
  }
  return s;
}

// Shared state of the workers: progress counters, cancellation, progress-callback throttling.
class Monitor {
 public:
  Monitor(const std::function<void(const MonteCarloProgress&)>& progress,
          const std::atomic<bool>* cancel, uint32_t runs_total, int64_t samples_total,
          Clock::time_point start)
      : progress_(progress),
        cancel_(cancel),
        runs_total_(runs_total),
        samples_total_(samples_total),
        start_(start) {}

  // Called by a run every kPollSamples samples; true = stop.
  bool Poll(int64_t samples) {
    samples_done_.fetch_add(samples, std::memory_order_relaxed);
    MaybeReport();
    return Stopped();
  }
  bool Stopped() {
    if (cancel_ != nullptr && cancel_->load(std::memory_order_relaxed)) {
      stopped_.store(true, std::memory_order_relaxed);
    }
    return stopped_.load(std::memory_order_relaxed);
  }
  void RunDone(int64_t samples) {
    samples_done_.fetch_add(samples, std::memory_order_relaxed);
    runs_done_.fetch_add(1, std::memory_order_relaxed);
  }
  int64_t samples_done() const { return samples_done_.load(); }
  void ReportFinal() {
    if (!progress_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    progress_(Snapshot());
  }

 private:
  MonteCarloProgress Snapshot() const {
    MonteCarloProgress p;
    p.runs_done = runs_done_.load(std::memory_order_relaxed);
    p.runs_total = runs_total_;
    p.samples_done = samples_done_.load(std::memory_order_relaxed);
    p.samples_total = samples_total_;
    p.elapsed_s = Seconds(start_);
    return p;
  }
  void MaybeReport() {
    if (!progress_) return;
    const int64_t now_ns =
        std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - start_).count();
    if (now_ns < next_report_ns_.load(std::memory_order_relaxed)) return;
    std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock() || now_ns < next_report_ns_.load(std::memory_order_relaxed)) return;
    next_report_ns_.store(now_ns + kProgressInterval_ns, std::memory_order_relaxed);
    progress_(Snapshot());
  }

  const std::function<void(const MonteCarloProgress&)>& progress_;
  const std::atomic<bool>* cancel_;
  const uint32_t runs_total_;
  const int64_t samples_total_;
  const Clock::time_point start_;
  std::atomic<int64_t> samples_done_{0};
  std::atomic<uint32_t> runs_done_{0};
  std::atomic<bool> stopped_{false};
  std::atomic<int64_t> next_report_ns_{0};
  std::mutex mutex_;
};

// Per-thread accumulator of the epoch sums.
using EpochAccumulator = std::vector<EpochSums>;

// Where one run's reported errors go.
struct RunSink {
  EpochAccumulator* epochs = nullptr;
  // checkpoint_values[c][run - first_run]
  std::vector<std::vector<ErrorComponentValues>>* checkpoint_values = nullptr;
  uint32_t slot = 0;

  void Record(const Report& r, const NavError& error) const {
    const ErrorComponentValues v = ErrorComponentsOf(error);
    if (r.epoch >= 0) {
      EpochSums& sums = (*epochs)[static_cast<size_t>(r.epoch)];
      for (int c = 0; c < kNumErrorComponents; ++c) {
        sums.sum[c].Add(v[c]);
        sums.sum_squares[c].AddSquare(v[c]);
      }
    }
    if (r.checkpoint >= 0) (*checkpoint_values)[static_cast<size_t>(r.checkpoint)][slot] = v;
  }
};

Eigen::Vector3d InitialErrorDraw(uint64_t seed, uint32_t run, uint8_t component,
                                 const Eigen::Vector3d& sigma) {
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  for (int axis = 0; axis < 3; ++axis) {
    if (sigma[axis] == 0.0) continue;
    const RandomStream stream(seed, run,
                              StreamKey{SensorId::kInitialConditions, static_cast<uint8_t>(axis),
                                        ErrorTerm::kInitialError, component});
    out[axis] = sigma[axis] * stream.Gaussian(0);
  }
  return out;
}

// Truth position and velocity at navigation start plus the run's initial errors; attitude set by
// the caller.
NavState PerturbedStart(const SharedTruth& s, const MonteCarloSpec& spec, uint32_t run) {
  NavState init = s.truth_start;
  const Eigen::Vector3d dr =
      InitialErrorDraw(spec.seed, run, 0, spec.initial_errors.position_ned_m);
  const Eigen::Vector3d dv =
      InitialErrorDraw(spec.seed, run, 1, spec.initial_errors.velocity_ned_m_per_s);
  // Curvilinear position offset with the environment's radii (as PositionErrorNed measures it).
  const double L = init.llh.lat_rad;
  const double h = init.llh.h_m;
  init.llh.lat_rad += dr.x() / (s.env.MeridianRadiusAt(L) + h);
  init.llh.lon_rad += dr.y() / ((s.env.TransverseRadiusAt(L) + h) * std::cos(L));
  init.llh.h_m -= dr.z();
  init.v_eb_n += dv;
  return init;
}

// Mechanization A's state at navigation start s0 for `run`: the truth at s0 plus the run's
// position and velocity errors, with the attitude from the static alignment (sum_dtheta, sum_dv:
// the measured increments summed over the window, k = 1..s0) or the truth's plus the attitude
// errors.
NavState NedStartState(const SharedTruth& s, const MonteCarloSpec& spec, uint32_t run,
                       bool gyrocompass, const Eigen::Vector3d& sum_dtheta,
                       const Eigen::Vector3d& sum_dv) {
  NavState init = PerturbedStart(s, spec, run);
  if (spec.initialization == InitializationKind::kStaticAlignment) {
    const double T = static_cast<double>(s.start_step) * s.dt_s;
    const Eigen::Vector3d f = sum_dv / T;
    const Eigen::Vector3d w = sum_dtheta / T;
    EulerAngles e;
    e.roll_rad = std::atan2(-f.y(), -f.z());
    e.pitch_rad = std::atan(f.x() / std::hypot(f.y(), f.z()));
    if (gyrocompass) {
      const double sr = std::sin(e.roll_rad), cr = std::cos(e.roll_rad);
      const double sp = std::sin(e.pitch_rad), cp = std::cos(e.pitch_rad);
      e.yaw_rad = std::atan2(-w.y() * cr + w.z() * sr, w.x() * cp + (w.y() * sr + w.z() * cr) * sp);
    } else {
      const Eigen::Vector3d heading_sigma(0.0, 0.0, *spec.alignment.heading_sigma_rad);
      e.yaw_rad = WrapPi(s.truth_start.euler().yaw_rad +
                         InitialErrorDraw(spec.seed, run, 3, heading_sigma).z());
    }
    init.q_b_n = Quaterniond(EulerToDcm(e));
  } else {
    EulerAngles e = s.truth_start.euler();
    const Eigen::Vector3d da =
        InitialErrorDraw(spec.seed, run, 2, spec.initial_errors.attitude_rad);
    e.roll_rad += da.x();
    e.pitch_rad += da.y();
    e.yaw_rad += da.z();
    init.q_b_n = Quaterniond(EulerToDcm(e));
  }
  return init;
}

// Runs one run with mechanization A. Returns false if stopped early.
bool RunNed(const SharedTruth& s, const MonteCarloSpec& spec, uint32_t run, bool gyrocompass,
            const RunSink& sink, Monitor* monitor, int64_t* samples) {
  std::optional<ImuErrorSimulator> sim;
  if (spec.sensor) sim.emplace(*spec.sensor, spec.seed, run, s.rate_hz);
  const bool truth_height = spec.simulation.ned.vertical == VerticalChannel::kTruthHeight;
  ImuIncrement measured;
  auto measure = [&](int64_t k) {
    const ImuIncrement& ideal = s.increments[static_cast<size_t>(k)];
    if (sim) {
      sim->Apply(ideal, &measured);
    } else {
      measured = ideal;
    }
  };
  int64_t polled = 0;
  auto poll = [&](int64_t k) {
    if ((k & (kPollSamples - 1)) != 0) return false;
    const int64_t d = k - polled;
    polled = k;
    return monitor->Poll(d);
  };

  // Alignment window: accumulate the measured increments.
  Eigen::Vector3d sum_dtheta = Eigen::Vector3d::Zero(), sum_dv = Eigen::Vector3d::Zero();
  for (int64_t k = 1; k <= s.start_step; ++k) {
    measure(k);
    sum_dtheta += measured.delta_theta_ib_b;
    sum_dv += measured.delta_v_ib_b;
    if (poll(k)) {
      *samples = k;
      return false;
    }
  }

  NedMechanization ned(s.env, NedStartState(s, spec, run, gyrocompass, sum_dtheta, sum_dv), s.dt_s,
                       spec.simulation.ned);
  size_t next = 0;
  const size_t n_reports = s.reports.size();
  if (s.reports[0].k == s.start_step) {
    sink.Record(s.reports[0], ComputeNavError(s.env, ned.state(), s.reports[0].truth));
    next = 1;
  }
  for (int64_t k = s.start_step + 1; k <= s.n; ++k) {
    measure(k);
    ned.Update(measured);
    if (truth_height) {
      ned.SetVertical(s.h_m[static_cast<size_t>(k)], s.v_D_m_per_s[static_cast<size_t>(k)]);
    }
    if (next < n_reports && s.reports[next].k == k) {
      sink.Record(s.reports[next], ComputeNavError(s.env, ned.state(), s.reports[next].truth));
      ++next;
    }
    if (poll(k)) {
      *samples = k;
      return false;
    }
  }
  *samples = s.n - polled;
  return true;
}

// Runs the runs of slots [slot_begin, slot_end) (at most kernel.width) with mechanization A in
// lockstep (lockstep_ned.h): the same samples, polls and reports as RunNed for each run, and the
// same bits. Returns false if stopped early.
bool RunNedGroup(const SharedTruth& s, const MonteCarloSpec& spec, const lockstep::LockstepJob& job,
                 const lockstep::Kernel& kernel, uint32_t slot_begin, uint32_t slot_end,
                 bool gyrocompass, RunSink sink, Monitor* monitor, lockstep::LockstepGroup* group,
                 lockstep::GroupStreams* streams) {
  using lockstep::kBlock;
  const int lanes = static_cast<int>(slot_end - slot_begin);
  group->lanes = lanes;
  for (int lane = 0; lane < lanes; ++lane) {
    lockstep::StartSensorLane(job, spec.first_run + slot_begin + static_cast<uint32_t>(lane), lane,
                              group, streams);
    for (int i = 0; i < 3; ++i) {
      group->nav.sum_dtheta[i][lane] = 0.0;
      group->nav.sum_dv[i][lane] = 0.0;
    }
  }
  lockstep::KernelInputs in;
  in.increments = s.increments.empty() ? nullptr : &s.increments[0].delta_theta_ib_b[0];
  if (job.kernel.truth_height) {
    in.h_m = s.h_m.data();
    in.v_D_m_per_s = s.v_D_m_per_s.data();
  }
  size_t next = 0;
  const size_t n_reports = s.reports.size();
  auto record = [&](const Report& r) {
    for (int lane = 0; lane < lanes; ++lane) {
      RunSink lane_sink = sink;
      lane_sink.slot = slot_begin + static_cast<uint32_t>(lane);
      lane_sink.Record(
          r, ComputeNavError(s.env, lockstep::NavStateOfLane(*group, s.dt_s, lane), r.truth));
    }
  };
  // Navigation starts at s0 from the alignment sums of k = 1..s0 (RunNed).
  auto start_navigation = [&] {
    for (int lane = 0; lane < lanes; ++lane) {
      const uint32_t run = spec.first_run + slot_begin + static_cast<uint32_t>(lane);
      const lockstep::NavLanes& n = group->nav;
      const Eigen::Vector3d sum_dtheta(n.sum_dtheta[0][lane], n.sum_dtheta[1][lane],
                                       n.sum_dtheta[2][lane]);
      const Eigen::Vector3d sum_dv(n.sum_dv[0][lane], n.sum_dv[1][lane], n.sum_dv[2][lane]);
      lockstep::SetNavLane(NedStartState(s, spec, run, gyrocompass, sum_dtheta, sum_dv), lane,
                           group);
    }
    if (s.reports[0].k == s.start_step) {
      record(s.reports[0]);
      next = 1;
    }
  };
  if (s.start_step == 0) start_navigation();
  // Polls every poll_every samples, so that a poll covers about kPollSamples run-samples as in
  // RunNed (a power of two, a multiple of the deviate block).
  int64_t poll_every = kPollSamples;
  while (poll_every > kBlock && poll_every * lanes > kPollSamples) poll_every /= 2;
  int64_t polled = 0;
  int64_t k = 1;
  while (k <= s.n) {
    if ((k - 1) % kBlock == 0) lockstep::LoadBlock(job, kernel, k - 1, streams, group);
    // The segment [k, end): inside one deviate block, up to the next report, poll or s0.
    int64_t end = std::min<int64_t>((k - 1) / kBlock * kBlock + kBlock + 1, s.n + 1);
    end = std::min<int64_t>(end, (k + poll_every - 1) / poll_every * poll_every + 1);
    const bool navigate = k > s.start_step;
    if (!navigate) end = std::min<int64_t>(end, s.start_step + 1);
    if (navigate && next < n_reports) end = std::min<int64_t>(end, s.reports[next].k + 1);
    kernel.advance(job.kernel, in, k, end, navigate, group);
    const int64_t last = end - 1;
    if (!navigate && last == s.start_step) start_navigation();
    if (navigate && next < n_reports && s.reports[next].k == last) record(s.reports[next++]);
    if ((last & (poll_every - 1)) == 0) {
      const int64_t d = last - polled;
      polled = last;
      if (monitor->Poll(d * lanes)) return false;
    }
    k = end;
  }
  for (int lane = 0; lane < lanes; ++lane) monitor->RunDone(s.n - polled);
  return true;
}

// All runs of a kNed job in lockstep groups of kernel.width runs, in parallel over groups.
void RunNedLockstep(const SharedTruth& s, const MonteCarloSpec& spec,
                    const lockstep::Kernel& kernel, bool gyrocompass, uint32_t run_count,
                    tbb::task_arena& arena,
                    tbb::enumerable_thread_specific<EpochAccumulator>& accumulators,
                    std::vector<std::vector<ErrorComponentValues>>& checkpoint_values,
                    Monitor* monitor) {
  const lockstep::LockstepJob job = lockstep::ComposeJob(
      spec.sensor ? &*spec.sensor : nullptr, spec.seed, s.env, s.rate_hz, spec.simulation.ned);
  const uint32_t width = static_cast<uint32_t>(kernel.width);
  const uint32_t groups = (run_count + width - 1) / width;
  struct Workspace {
    std::unique_ptr<lockstep::LockstepGroup> group = std::make_unique<lockstep::LockstepGroup>();
    lockstep::GroupStreams streams;
  };
  tbb::enumerable_thread_specific<Workspace> workspaces;
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, groups, 1),
                      [&](const tbb::blocked_range<uint32_t>& range) {
                        Workspace& w = workspaces.local();
                        RunSink sink;
                        sink.epochs = &accumulators.local();
                        sink.checkpoint_values = &checkpoint_values;
                        for (uint32_t g = range.begin(); g != range.end(); ++g) {
                          if (monitor->Stopped()) return;
                          const uint32_t begin = g * width;
                          const uint32_t end = std::min(run_count, begin + width);
                          if (!RunNedGroup(s, spec, job, kernel, begin, end, gyrocompass, sink,
                                           monitor, w.group.get(), &w.streams)) {
                            return;
                          }
                        }
                      });
  });
}

// Runs one run with mechanization B. Returns false if stopped early.
bool RunSeed000(const SharedTruth& s, const MonteCarloSpec& spec, uint32_t run, const RunSink& sink,
                Monitor* monitor, int64_t* samples) {
  std::optional<ImuErrorSimulator> sim;
  if (spec.sensor) sim.emplace(*spec.sensor, spec.seed, run, s.rate_hz);
  ImuSample measured;
  Seed000Mechanization mech(s.dt_s, spec.simulation.seed000);
  size_t next = 0;
  const size_t n_reports = s.reports.size();
  int64_t polled = 0;
  for (int64_t k = 0; k <= s.n; ++k) {
    const ImuSample& ideal = s.samples[static_cast<size_t>(k)];
    if (sim) {
      sim->Apply(ideal, &measured);
    } else {
      measured = ideal;
    }
    mech.Update(measured);
    if (next < n_reports && s.reports[next].k == k) {
      const NavState nav = mech.ToNed(s.env, s.truth0);
      sink.Record(s.reports[next], ComputeNavError(s.env, nav, s.reports[next].truth));
      ++next;
    }
    if (k > 0 && (k & (kPollSamples - 1)) == 0) {
      const int64_t d = k - polled;
      polled = k;
      if (monitor->Poll(d)) {
        *samples = 0;
        return false;
      }
    }
  }
  *samples = s.n + 1 - polled;
  return true;
}

// The error-state model the EKF and the covariance analysis use (MakeErrorStateNoise of the
// filter's IMU model, spec.filter_sensor or else the truth's), with the GNSS and barometer
// Gauss-Markov errors as states for the EKF, and the run's time scales and motion bounds.
ErrorStateNoiseFromImu FilterErrorModel(const MonteCarloSpec& spec, const SharedTruth& s) {
  const bool ekf = spec.filter == NavigationFilterKind::kInsGnssEkf;
  const double duration_s = static_cast<double>(s.n - s.start_step) * s.dt_s;
  ErrorModelOptions options;
  options.augment_scale_misalignment = spec.filter_augment_scale_misalignment;
  options.flicker_states_per_axis = spec.filter_flicker_states_per_axis;
  // The run's time scales: from the shortest aiding interval (or the IMU interval) to its length.
  double aid_interval_s = 0.0;
  double unaided_s = duration_s;
  if (ekf && spec.aiding.gnss) {
    aid_interval_s = 1.0 / spec.aiding.gnss->rate_hz;
    unaided_s = aid_interval_s;
    for (const GnssOutage& o : spec.aiding.gnss->outages)
      unaided_s = std::max(unaided_s, o.duration_s);
  }
  options.time_scale_min_s = std::max(aid_interval_s, s.dt_s);
  options.time_scale_max_s = std::max(duration_s, options.time_scale_min_s);
  options.unaided_interval_s = unaided_s;
  for (size_t k = 1; k < s.increments.size(); ++k) {
    options.max_abs_omega_ib_b =
        options.max_abs_omega_ib_b.cwiseMax(s.increments[k].delta_theta_ib_b.cwiseAbs() / s.dt_s);
    options.max_abs_f_ib_b =
        options.max_abs_f_ib_b.cwiseMax(s.increments[k].delta_v_ib_b.cwiseAbs() / s.dt_s);
  }
  ErrorStateNoiseFromImu out;
  const std::optional<ImuErrorModel>& model = spec.filter_sensor ? spec.filter_sensor : spec.sensor;
  if (model) {
    out = MakeErrorStateNoise(*model, spec.filter_sensor ? "navigation.ekf.sensor" : "sensor",
                              options);
  }
  if (spec.filter_sensor) {
    static const std::string kMistuned =
        "navigation.ekf.sensor (the filter assumes this model, not the truth's sensor: the "
        "predicted sigma "
        "is the filter's belief, a mistuning shows as NEES outside its band)";
    out.unrepresented.push_back(kMistuned);
  }
  if (ekf && spec.aiding.gnss && !spec.aiding.gnss->position_gauss_markov_sigma_ned_m.isZero(0.0)) {
    out.noise.gnss_position_gm_sigma_ned_m = spec.aiding.gnss->position_gauss_markov_sigma_ned_m;
    out.noise.gnss_position_gm_tau_s = spec.aiding.gnss->position_gauss_markov_tau_s;
  }
  if (ekf && spec.aiding.barometer && spec.aiding.barometer->bias.sigma > 0.0) {
    out.noise.barometer_bias_sigma_m = spec.aiding.barometer->bias.sigma;
    out.noise.barometer_bias_tau_s = spec.aiding.barometer->bias.tau_s;
  }
  return out;
}

// Per-thread NEES sums of a kInsGnssEkf job (FilterConsistencyData), indexed by epoch.
struct NeesAccumulator {
  std::vector<ExactSum> sum;
  std::vector<uint64_t> count;
};

// Runs one run with the INS/GNSS EKF (mechanization A, kTruthPlusErrors). Returns false if
// stopped early. At a sample: predict, report (after propagating P to the sample at an epoch),
// then the GNSS, barometer and ZUPT updates due at that sample, in this order (as
// FilterCovarianceAnalysis).
bool RunEkf(const SharedTruth& s, const MonteCarloSpec& spec, uint32_t run, const RunSink& sink,
            NeesAccumulator* nees, Monitor* monitor, int64_t* samples) {
  std::optional<ImuErrorSimulator> sim;
  if (spec.sensor) sim.emplace(*spec.sensor, spec.seed, run, s.rate_hz);
  const AidingSpec& aiding = spec.aiding;
  InsGnssFilterOptions options;
  options.imu_noise = s.ekf_noise;
  if (aiding.gnss) {
    options.gnss = *aiding.gnss;
  } else {
    options.gnss.rate_hz = s.rate_hz;  // unused; valid for any IMU rate
  }
  options.propagation_step_samples = spec.ekf_propagation_step_samples;
  options.mechanization = spec.simulation.ned;
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  InsGnssFilter filter(s.env, NedStartState(s, spec, run, true, zero, zero), s.ekf_P0, s.rate_hz,
                       options);
  std::optional<GnssSimulator> gnss;
  if (aiding.gnss) gnss.emplace(*aiding.gnss, s.env, s.rate_hz, spec.seed, run);
  std::optional<BarometerSimulator> baro;
  double baro_sigma_m = 0.0;
  if (aiding.barometer) {
    baro.emplace(*aiding.barometer, s.rate_hz, spec.seed, run);
    // The bias is a filter state when the filter's model has it; otherwise it widens R.
    baro_sigma_m = s.ekf_noise.barometer_bias_sigma_m > 0.0
                       ? aiding.barometer->noise_sigma_m
                       : std::hypot(aiding.barometer->noise_sigma_m, aiding.barometer->bias.sigma);
  }
  std::optional<ZuptSimulator> zupt;
  if (aiding.zupt) zupt.emplace(*aiding.zupt, s.rate_hz, spec.seed, run);
  size_t next_zupt = 0;

  auto record = [&](const Report& r) {
    if (r.epoch >= 0) filter.SyncCovariance();
    const NavError error = ComputeNavError(s.env, filter.state(), r.truth);
    sink.Record(r, error);
    if (r.epoch < 0) return;
    // NEES of the 9 navigation states against the filter's P (chi2(9) for a consistent filter).
    Eigen::Matrix<double, 9, 1> e;
    e << error.r_ned_m, error.v_ned_m_per_s, error.psi_nb_n_rad;
    const Eigen::LLT<Eigen::Matrix<double, 9, 9>> llt(filter.P().topLeftCorner<9, 9>());
    if (llt.info() != Eigen::Success) return;
    const double value = e.dot(llt.solve(e));
    if (!std::isfinite(value)) return;
    nees->sum[static_cast<size_t>(r.epoch)].Add(value);
    ++nees->count[static_cast<size_t>(r.epoch)];
  };

  size_t next = 0;
  const size_t n_reports = s.reports.size();
  if (s.reports[0].k == s.start_step) {
    record(s.reports[0]);
    next = 1;
  }
  ImuIncrement measured;
  int64_t polled = 0;
  for (int64_t k = s.start_step + 1; k <= s.n; ++k) {
    const ImuIncrement& ideal = s.increments[static_cast<size_t>(k)];
    if (sim) {
      sim->Apply(ideal, &measured);
    } else {
      measured = ideal;
    }
    filter.Predict(measured);
    if (next < n_reports && s.reports[next].k == k) record(s.reports[next++]);
    if (gnss && k % s.gnss_decimation == 0) {
      const size_t j = static_cast<size_t>(k / s.gnss_decimation);
      GnssMeasurement fix;
      if (gnss->Measure(k, s.gnss_truth[j], s.gnss_omega_ib_b[j], &fix)) {
        filter.Update(fix, measured.delta_theta_ib_b / s.dt_s);
      }
    }
    if (baro && k % s.baro_decimation == 0) {
      double h_m = 0.0;
      baro->Measure(k, s.baro_h_m[static_cast<size_t>(k / s.baro_decimation)], &h_m);
      filter.UpdateHeight(h_m, baro_sigma_m);
    }
    if (next_zupt < s.zupt_epochs.size() && s.zupt_epochs[next_zupt] == k) {
      filter.UpdateZeroVelocity(aiding.zupt->velocity_sigma_m_per_s, zupt->Measure(k));
      ++next_zupt;
    }
    if ((k & (kPollSamples - 1)) == 0) {
      const int64_t d = k - polled;
      polled = k;
      if (monitor->Poll(d)) {
        *samples = 0;
        return false;
      }
    }
  }
  *samples = s.n - polled;
  return true;
}

// Runs one run with the complementary attitude filter on the measured point samples k = 0..n.
// Returns false if stopped early.
bool RunComplementary(const SharedTruth& s, const MonteCarloSpec& spec, uint32_t run,
                      const RunSink& sink, Monitor* monitor, int64_t* samples) {
  std::optional<ImuErrorSimulator> sim;
  if (spec.sensor) sim.emplace(*spec.sensor, spec.seed, run, s.rate_hz);
  ComplementaryFilterOptions options = spec.complementary;
  std::optional<MagnetometerSimulator> mag;
  if (spec.aiding.magnetometer) {
    mag.emplace(*spec.aiding.magnetometer, s.rate_hz, spec.seed, run);
    options.magnetic_declination_rad = MagneticDeclination(spec.aiding.magnetometer->earth_field_n);
  }
  options.initial_yaw_rad =
      WrapPi(s.truth0.euler().yaw_rad +
             InitialErrorDraw(spec.seed, run, 2, spec.initial_errors.attitude_rad).z());
  ComplementaryAttitudeFilter filter(options, s.rate_hz);
  ImuSample measured;
  size_t next = 0;
  const size_t n_reports = s.reports.size();
  int64_t polled = 0;
  for (int64_t k = 0; k <= s.n; ++k) {
    const ImuSample& ideal = s.samples[static_cast<size_t>(k)];
    if (sim) {
      sim->Apply(ideal, &measured);
    } else {
      measured = ideal;
    }
    Eigen::Vector3d m_b;
    const bool has_mag =
        mag && k % s.mag_decimation == 0 &&
        mag->Measure(k, s.mag_q_b_n[static_cast<size_t>(k / s.mag_decimation)].toRotationMatrix(),
                     &m_b);
    filter.Update(measured, has_mag ? &m_b : nullptr);
    if (next < n_reports && s.reports[next].k == k) {
      // Attitude only: position and velocity are the truth's (errors reported as 0).
      NavState nav = s.reports[next].truth;
      nav.q_b_n = Quaterniond(EulerToDcm(filter.attitude()));
      sink.Record(s.reports[next], ComputeNavError(s.env, nav, s.reports[next].truth));
      ++next;
    }
    if (k > 0 && (k & (kPollSamples - 1)) == 0) {
      const int64_t d = k - polled;
      polled = k;
      if (monitor->Poll(d)) {
        *samples = 0;
        return false;
      }
    }
  }
  *samples = s.n + 1 - polled;
  return true;
}

// Gyrocompass or external heading: one decision per job (it depends on the model only).
bool UseGyrocompass(const MonteCarloSpec& spec, const SharedTruth& truth) {
  const bool seed000 = spec.simulation.mechanization == MechanizationKind::kSeed000;
  if (seed000 || spec.initialization != InitializationKind::kStaticAlignment ||
      !spec.alignment.heading_sigma_rad) {
    return true;
  }
  const double omega_ie = truth.env.model() == EarthModel::kFlat ? 0.0 : kWgs84EarthRate_rad_per_s;
  const double predicted =
      spec.sensor
          ? PredictedGyrocompassHeadingSigma(spec.sensor->gyro, truth.truth_start.llh.lat_rad,
                                             spec.alignment.duration_s, omega_ie)
          : (omega_ie > 0.0 ? 0.0 : std::numeric_limits<double>::infinity());
  return predicted < *spec.alignment.heading_sigma_rad;
}

}  // namespace

double PredictedGyrocompassHeadingSigma(const TriadErrorParams& gyro, double L_b, double duration_s,
                                        double omega_ie_rad_per_s) {
  const double horizontal_rate = omega_ie_rad_per_s * std::cos(L_b);
  if (!(std::abs(horizontal_rate) > 0.0)) return std::numeric_limits<double>::infinity();
  // 0.664 = sqrt(2 ln 2 / pi), the flicker floor of the Allan deviation (sensor_params.h).
  const double flicker = std::sqrt(2.0 * std::log(2.0) / M_PI) * gyro.bias_flicker.bias_instability;
  const double fixed = gyro.fixed_bias.cwiseAbs().maxCoeff();
  const double T = duration_s;
  const double bias2 = fixed * fixed + gyro.turn_on_bias_sigma * gyro.turn_on_bias_sigma +
                       gyro.bias_gauss_markov.sigma * gyro.bias_gauss_markov.sigma +
                       flicker * flicker + gyro.random_walk * gyro.random_walk * T / 3.0;
  const double white2 = gyro.white_noise_density * gyro.white_noise_density / T;
  return std::sqrt(bias2 + white2) / std::abs(horizontal_rate);
}

void ValidateFilterAndAiding(const MonteCarloSpec& spec) {
  ValidateFilter(spec);
  ValidateAidingSpec(spec.aiding, spec.simulation.rate_hz, -1.0);
}

void FilterConsistencyData::Merge(const FilterConsistencyData& other) {
  if (other.nees_sum.size() != nees_sum.size() || other.nees_count.size() != nees_count.size()) {
    throw SpecError("statistics.nees", std::to_string(other.nees_sum.size()) + " epochs",
                    std::to_string(nees_sum.size()) + " epochs (the same job)");
  }
  for (size_t e = 0; e < nees_sum.size(); ++e) {
    nees_sum[e].Merge(other.nees_sum[e]);
    if (__builtin_add_overflow(nees_count[e], other.nees_count[e], &nees_count[e])) {
      throw SpecError("statistics.nees_counts[" + std::to_string(e) + "]", "a sum beyond 2^64",
                      "counts of at most one per run");
    }
  }
}

MonteCarloStatistics RunMonteCarlo(const MonteCarloSpec& spec,
                                   const std::function<void(const MonteCarloProgress&)>& progress,
                                   const std::atomic<bool>* cancel) {
  MonteCarloSpec without_analysis = spec;
  without_analysis.covariance = false;
  return std::move(RunMonteCarloWithAnalysis(without_analysis, progress, cancel).statistics);
}

MonteCarloOutput RunMonteCarloWithAnalysis(
    const MonteCarloSpec& spec, const std::function<void(const MonteCarloProgress&)>& progress,
    const std::atomic<bool>* cancel) {
  const Clock::time_point start = Clock::now();
  ValidateMonteCarloSpec(spec);
  const uint32_t run_count = spec.run_count == 0 ? spec.runs - spec.first_run : spec.run_count;

  bool cancelled_early = false;
  SharedTruth shared = BuildSharedTruth(spec, true, cancel, &cancelled_early);
  if (cancelled_early) {
    MonteCarloOutput output;
    MonteCarloStatisticsData data;
    data.seed = spec.seed;
    data.job_runs = spec.runs;
    data.cancelled = true;
    data.timings.truth_s = Seconds(start);
    data.timings.wall_s = data.timings.truth_s;
    output.statistics = MonteCarloStatistics(std::move(data));
    return output;
  }
  const bool ekf = spec.filter == NavigationFilterKind::kInsGnssEkf;
  const bool complementary = spec.filter == NavigationFilterKind::kComplementary;
  // The error-state model the filter and the analysis assume (no sensor: no process noise, no
  // bias uncertainty).
  const ErrorStateNoiseFromImu noise = FilterErrorModel(spec, shared);
  if (ekf || spec.covariance) {
    shared.ekf_noise = noise.noise;
    shared.ekf_P0 = InitialErrorCovariance(
        spec.initial_errors.position_ned_m, spec.initial_errors.velocity_ned_m_per_s,
        spec.initial_errors.attitude_rad, shared.truth_start.euler(), noise.noise);
  }
  const SharedTruth& truth = shared;
  const double truth_s = Seconds(start);
  const bool seed000 = spec.simulation.mechanization == MechanizationKind::kSeed000;

  const bool gyrocompass = UseGyrocompass(spec, truth);

  // Output buffers: per-run checkpoint values (each run writes its own slot), per-thread sums.
  size_t n_epochs = 0, n_checkpoints = 0;
  for (const Report& r : truth.reports) {
    if (r.epoch >= 0) ++n_epochs;
    if (r.checkpoint >= 0) ++n_checkpoints;
  }
  if (uint64_t{run_count} * n_checkpoints > uint64_t{kMaxMonteCarloRuns} * 10) {
    throw SpecError("monte_carlo.checkpoint_times_s",
                    std::to_string(n_checkpoints) + " checkpoints",
                    "runs x checkpoints <= " + std::to_string(uint64_t{kMaxMonteCarloRuns} * 10));
  }
  std::vector<std::vector<ErrorComponentValues>> checkpoint_values(
      n_checkpoints, std::vector<ErrorComponentValues>(run_count));
  const EpochAccumulator exemplar(n_epochs);
  tbb::enumerable_thread_specific<EpochAccumulator> accumulators(exemplar);
  NeesAccumulator nees_exemplar;
  if (ekf) {
    nees_exemplar.sum.resize(n_epochs);
    nees_exemplar.count.assign(n_epochs, 0);
  }
  tbb::enumerable_thread_specific<NeesAccumulator> nees_accumulators(nees_exemplar);

  const int64_t samples_per_run = seed000 || complementary ? truth.n + 1 : truth.n;
  Monitor monitor(progress, cancel, run_count, samples_per_run * int64_t{run_count}, start);
  const int threads = spec.threads > 0 ? spec.threads : tbb::info::default_concurrency();
  tbb::task_arena arena(threads);
  // Mechanization A without a filter runs in lockstep groups (DRIFTLAB_ISA=scalar: one run at a
  // time, RunNed, kept as the reference the lockstep path must match bit for bit).
  const bool run_lockstep = !seed000 && !ekf && !complementary && !lockstep::ScalarForced();
  if (run_lockstep) {
    RunNedLockstep(truth, spec, lockstep::SelectKernel(), gyrocompass, run_count, arena,
                   accumulators, checkpoint_values, &monitor);
  }
  // The other navigators, one run at a time (none left when the runs went in lockstep above).
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, run_lockstep ? 0 : run_count, 1),
                      [&](const tbb::blocked_range<uint32_t>& range) {
                        RunSink sink;
                        sink.epochs = &accumulators.local();
                        sink.checkpoint_values = &checkpoint_values;
                        for (uint32_t slot = range.begin(); slot != range.end(); ++slot) {
                          if (monitor.Stopped()) return;
                          sink.slot = slot;
                          const uint32_t run = spec.first_run + slot;
                          int64_t samples = 0;
                          bool done = false;
                          if (seed000) {
                            done = RunSeed000(truth, spec, run, sink, &monitor, &samples);
                          } else if (ekf) {
                            done = RunEkf(truth, spec, run, sink, &nees_accumulators.local(),
                                          &monitor, &samples);
                          } else if (complementary) {
                            done = RunComplementary(truth, spec, run, sink, &monitor, &samples);
                          } else {
                            done = RunNed(truth, spec, run, gyrocompass, sink, &monitor, &samples);
                          }
                          if (!done) return;
                          monitor.RunDone(samples);
                        }
                      });
  });

  MonteCarloStatisticsData data;
  data.seed = spec.seed;
  data.job_runs = spec.runs;
  data.timings.truth_s = truth_s;
  data.timings.threads = threads;
  MonteCarloOutput output;
  if (monitor.Stopped()) {
    data.cancelled = true;
    data.timings.samples_processed = monitor.samples_done();
    data.timings.wall_s = Seconds(start);
    output.statistics = MonteCarloStatistics(std::move(data));
    return output;
  }
  monitor.ReportFinal();

  data.runs.push_back(RunRange{spec.first_run, spec.first_run + run_count});
  data.epochs.resize(n_epochs);
  for (const EpochAccumulator& local : accumulators) {
    for (size_t e = 0; e < n_epochs; ++e) {
      for (int c = 0; c < kNumErrorComponents; ++c) {
        data.epochs[e].sum[c].Merge(local[e].sum[c]);
        data.epochs[e].sum_squares[c].Merge(local[e].sum_squares[c]);
      }
    }
  }
  size_t c = 0;
  for (const Report& r : truth.reports) {
    if (r.epoch >= 0) data.epoch_times_s.push_back(static_cast<double>(r.k) * truth.dt_s);
    if (r.checkpoint >= 0) {
      CheckpointValues cp;
      cp.t_s = static_cast<double>(r.k) * truth.dt_s;
      cp.run_index.resize(run_count);
      for (uint32_t i = 0; i < run_count; ++i) cp.run_index[i] = spec.first_run + i;
      cp.values = std::move(checkpoint_values[c++]);
      data.checkpoints.push_back(std::move(cp));
    }
  }
  if (ekf) {
    FilterConsistencyData consistency;
    consistency.nees_sum.resize(n_epochs);
    consistency.nees_count.assign(n_epochs, 0);
    for (const NeesAccumulator& local : nees_accumulators) {
      for (size_t e = 0; e < n_epochs; ++e) {
        consistency.nees_sum[e].Merge(local.sum[e]);
        consistency.nees_count[e] += local.count[e];
      }
    }
    output.consistency = std::move(consistency);
  }
  if (spec.covariance) {
    // The analysis at the epochs' samples, the ZUPT epochs as the runs use them.
    std::vector<int64_t> epoch_samples;
    for (const Report& r : truth.reports) {
      if (r.epoch >= 0) epoch_samples.push_back(r.k);
    }
    CovarianceAnalysisResult analysis;
    analysis.filter = spec.filter;
    analysis.step_samples = ekf ? spec.ekf_propagation_step_samples : spec.covariance_step_samples;
    analysis.unrepresented = noise.unrepresented;
    // The EKF's analysis uses its propagation interval and discretisation, so that it predicts
    // that filter; the free INS's uses covariance_step_samples with Van Loan's exact transition.
    analysis.epochs = FilterCovarianceAnalysis(
        spec.simulation.motion, spec.simulation.rate_hz, truth.ekf_noise, truth.ekf_P0,
        ekf ? &spec.aiding : nullptr, truth.zupt_epochs, epoch_samples, analysis.step_samples,
        ekf ? InsGnssFilterOptions().discretization : Discretization::kVanLoan);
    output.covariance = std::move(analysis);
  }
  data.timings.samples_processed = monitor.samples_done();
  data.timings.wall_s = Seconds(start);
  output.statistics = MonteCarloStatistics(std::move(data));
  return output;
}

bool ReplayMonteCarloRun(const MonteCarloSpec& spec_in, uint32_t run, bool navigate,
                         const std::function<void(const MonteCarloRunLayout&)>& on_start,
                         const std::function<void(const MonteCarloRunStep&)>& on_step,
                         const std::atomic<bool>* cancel) {
  MonteCarloSpec spec = spec_in;
  spec.first_run = run;
  spec.run_count = 1;
  ValidateSpec(spec);
  if (spec.sensor) ValidateImuErrorModel(*spec.sensor, "sensor");
  if (navigate && spec.filter != NavigationFilterKind::kNone) {
    throw SpecError("navigation.filter", FilterName(spec.filter),
                    "NONE to replay the run's navigation (the replay reproduces the free-inertial "
                    "mechanization; the IMU data and truth are available with any filter)");
  }
  const SharedTruth s = BuildSharedTruth(spec, /*keep_imu=*/false);
  const bool seed000 = spec.simulation.mechanization == MechanizationKind::kSeed000;
  const bool gyrocompass = UseGyrocompass(spec, s);
  const bool truth_height =
      !seed000 && spec.simulation.ned.vertical == VerticalChannel::kTruthHeight;

  MonteCarloRunLayout layout;
  layout.env = &s.env;
  layout.rate_hz = s.rate_hz;
  layout.dt_s = s.dt_s;
  layout.num_steps = s.n;
  layout.navigation_start_step = s.start_step;
  for (const Report& r : s.reports) {
    if (r.epoch >= 0) ++layout.num_epochs;
    if (r.checkpoint >= 0) ++layout.num_checkpoints;
  }
  if (on_start) on_start(layout);

  // Two simulators of the run, as RunSimulation: increments (what mechanization A and
  // RunMonteCarlo's kNed runs use) and point samples (mechanization B).
  std::optional<ImuErrorSimulator> increment_errors, sample_errors;
  if (spec.sensor) {
    increment_errors.emplace(*spec.sensor, spec.seed, run, s.rate_hz);
    sample_errors.emplace(*spec.sensor, spec.seed, run, s.rate_hz);
  }
  TrajectoryGenerator generator(spec.simulation.motion, spec.simulation.rate_hz);
  const NavState truth0 = generator.initial_state();
  ImuIncrement measured_increment;  // zero at k = 0
  ImuSample measured_sample = generator.initial_sample();
  if (sample_errors) sample_errors->Apply(generator.initial_sample(), &measured_sample);

  std::optional<NedMechanization> ned;
  std::optional<Seed000Mechanization> mech;
  Eigen::Vector3d sum_dtheta = Eigen::Vector3d::Zero(), sum_dv = Eigen::Vector3d::Zero();
  NavState nav;
  size_t next_report = 0;
  auto emit = [&](int64_t k, const NavState& truth) {
    MonteCarloRunStep step;
    step.k = k;
    step.truth = &truth;
    step.measured_increment = &measured_increment;
    step.measured_sample = &measured_sample;
    if (navigate && k >= s.start_step) step.nav = &nav;
    if (next_report < s.reports.size() && s.reports[next_report].k == k) {
      step.epoch = s.reports[next_report].epoch;
      step.checkpoint = s.reports[next_report].checkpoint;
      step.report_t_s = static_cast<double>(k) * s.dt_s;
      ++next_report;
    }
    on_step(step);
  };

  // k = 0: mechanization B takes its first sample; mechanization A starts here unless aligning.
  if (navigate && seed000) {
    mech.emplace(s.dt_s, spec.simulation.seed000);
    mech->Update(measured_sample);
    if (s.start_step == 0) nav = mech->ToNed(s.env, truth0);
  } else if (navigate && s.start_step == 0) {
    ned.emplace(s.env, NedStartState(s, spec, run, gyrocompass, sum_dtheta, sum_dv), s.dt_s,
                spec.simulation.ned);
    nav = ned->state();
  }
  emit(0, truth0);

  TrajectorySample sample;
  while (generator.Next(&sample)) {
    const int64_t k = generator.step();
    if (increment_errors) {
      increment_errors->Apply(sample.increment, &measured_increment);
      sample_errors->Apply(sample.sample, &measured_sample);
    } else {
      measured_increment = sample.increment;
      measured_sample = sample.sample;
    }
    if (navigate && seed000) {
      mech->Update(measured_sample);
      if (k >= s.start_step) nav = mech->ToNed(s.env, truth0);
    } else if (navigate && k <= s.start_step) {
      // Alignment window (k = 1..s0), then the start state at s0 (RunNed).
      sum_dtheta += measured_increment.delta_theta_ib_b;
      sum_dv += measured_increment.delta_v_ib_b;
      if (k == s.start_step) {
        ned.emplace(s.env, NedStartState(s, spec, run, gyrocompass, sum_dtheta, sum_dv), s.dt_s,
                    spec.simulation.ned);
        nav = ned->state();
      }
    } else if (navigate) {
      ned->Update(measured_increment);
      if (truth_height) ned->SetVertical(sample.truth.llh.h_m, sample.truth.v_eb_n.z());
      nav = ned->state();
    }
    emit(k, sample.truth);
    if ((k & (kPollSamples - 1)) == 0 && cancel != nullptr &&
        cancel->load(std::memory_order_relaxed)) {
      return false;
    }
  }
  return true;
}

}  // namespace driftlab
