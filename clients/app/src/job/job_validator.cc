#include "driftlab/app/job_validator.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "driftlab/app/schema_check.h"
#include "driftlab/sensors.h"
#include "driftlab/spec_error.h"
#include "driftlab/trajectory.h"
#include "job/job_translation.h"

namespace driftlab::app {
namespace {

// Step 2: the server reads no file a client names.
void CheckNoFileReferences(const v1::Job& job) {
  const v1::Motion& motion = job.motion();
  if (motion.has_gnss_ins_sim_file()) {
    throw SpecError("motion.gnss_ins_sim_file.path",
                    "\"" + motion.gnss_ins_sim_file().path() + "\"",
                    "no file reference: the server does not read files; inline the motion as "
                    "motion.segments");
  }
  if (motion.has_truth_profile_file()) {
    throw SpecError("motion.truth_profile_file.path",
                    "\"" + motion.truth_profile_file().path() + "\"",
                    "no file reference: the server does not read files; inline the motion as "
                    "motion.segments");
  }
}

// Step 3: options that nothing would read. What the job states is what runs.
void CheckNothingIgnored(const v1::Job& job) {
  const v1::Navigation& nav = job.navigation();
  const bool seed000 = nav.mechanization() == v1::Navigation::SEED000;
  if (!seed000 && nav.has_seed000() && nav.seed000().ByteSizeLong() > 0) {
    throw SpecError("navigation.seed000", "set with navigation.mechanization NED",
                    "only with navigation.mechanization SEED000");
  }
  if (seed000 && nav.has_ned() && nav.ned().ByteSizeLong() > 0) {
    throw SpecError("navigation.ned", "set with navigation.mechanization SEED000",
                    "only with navigation.mechanization NED");
  }
  const v1::ZuptAiding& zupt = job.aiding().zupt();
  if (job.aiding().has_zupt() && !zupt.enabled() &&
      (zupt.has_rate_hz() || zupt.has_velocity_sigma_m_per_s())) {
    throw SpecError(
        zupt.has_rate_hz() ? "aiding.zupt.rate_hz" : "aiding.zupt.velocity_sigma_m_per_s",
        "set with aiding.zupt.enabled false", "only with aiding.zupt.enabled true");
  }
  const v1::Motion& motion = job.motion();
  if ((motion.has_gnss_ins_sim_file() || motion.has_truth_profile_file()) && motion.has_vehicle() &&
      motion.vehicle().ByteSizeLong() > 0) {
    throw SpecError("motion.vehicle", "set with an imported motion file",
                    "only with motion.segments (the file gives the attitude)");
  }
}

// Step 5: an error the engine reports about an imported motion names the job's file field; the
// engine's own location (a file line, a sample or command index) stays in the message.
[[noreturn]] void RethrowForMotionFile(const v1::Job& job, const SpecError& e) {
  const v1::Motion& motion = job.motion();
  const bool gnss_ins_sim = motion.has_gnss_ins_sim_file();
  const std::string field =
      gnss_ins_sim ? "motion.gnss_ins_sim_file.path" : "motion.truth_profile_file.path";
  const std::string& file =
      gnss_ins_sim ? motion.gnss_ins_sim_file().path() : motion.truth_profile_file().path();
  std::string detail = e.what();
  // "motion.truth_profile[12].t_s: ..." -> "sample [12].t_s: ..."; "motion.segments: ..." ->
  // "the motion: ..."
  const std::pair<std::string_view, std::string_view> renames[] = {
      {"motion.truth_profile", "sample "}, {"motion.segments", "the motion"}};
  for (const auto& [engine, user] : renames) {
    if (detail.starts_with(engine)) detail = std::string(user) + detail.substr(engine.size());
  }
  throw SpecError(field, fmt::format("'{}': {}", file, detail), 0);
}

bool FromMotionFile(const v1::Job& job) {
  return job.motion().has_gnss_ins_sim_file() || job.motion().has_truth_profile_file();
}

// Step 6. The interval [s] over which the EKF or the covariance analysis propagate a state the
// job's model gives them, or 0 when neither runs.
struct ModelIntervals {
  double sample_s = 0.0;    // the interval between the process's samples
  std::string sample_text;  // how sample_s follows from the job
  double model_s = 0.0;     // longest of the EKF's and the analysis' propagation intervals (or 0)
  std::string model_text;   // how model_s follows from the job
};

ModelIntervals IntervalsOf(const MonteCarloSpec& spec) {
  ModelIntervals out;
  const double rate_hz = spec.simulation.rate_hz;
  out.sample_s = 1.0 / rate_hz;
  out.sample_text = "the IMU interval 1 / rate_hz";
  if (spec.filter == NavigationFilterKind::kInsGnssEkf) {
    out.model_s = static_cast<double>(spec.ekf_propagation_step_samples) / rate_hz;
    out.model_text = fmt::format(
        "the EKF's propagation interval navigation.ekf.propagation_step_samples / rate_hz = {} / "
        "{} Hz",
        spec.ekf_propagation_step_samples, rate_hz);
  }
  if (spec.covariance) {
    const double t = static_cast<double>(spec.covariance_step_samples) / rate_hz;
    if (t > out.model_s) {
      out.model_s = t;
      out.model_text = fmt::format(
          "the covariance analysis' propagation interval monte_carlo.covariance_step_samples / "
          "rate_hz = {} / {} Hz",
          spec.covariance_step_samples, rate_hz);
    }
  }
  return out;
}

// A first-order Gauss-Markov correlation time `tau_s` at `path` (value in seconds in the job).
// Below one IMU interval the process is white noise at the IMU rate; below the propagation
// interval T of the model that carries it as a state, the EKF's second-order step decays the state
// by 1 - T/tau + (T/tau)^2/2 per step, which exceeds 1 (a growing covariance) for T/tau > 2 and
// overstates the stationary variance by (T/tau) (1 + d^2) / (1 - d^2) (67 % at T/tau = 1, 0.5 % at
// 0.1); the analysis' dense Van Loan exponential overflows. At tau >= T both stay finite and
// conservative.
void CheckCorrelationTime(const std::string& path, double tau_s, bool modelled,
                          const ModelIntervals& intervals, std::string_view white_noise_field) {
  const bool by_model = modelled && intervals.model_s > intervals.sample_s;
  const double min_s = by_model ? intervals.model_s : intervals.sample_s;
  if (tau_s >= min_s * (1.0 - 1e-12)) return;
  const std::string reason = fmt::format(
      "at least {} = {} s", by_model ? intervals.model_text : intervals.sample_text, min_s);
  throw SpecError(
      path, fmt::format("{} s", tau_s),
      fmt::format("{} <= {} (a shorter correlation time is white noise at this rate: give it as "
                  "{} instead, density sigma sqrt(2 tau) in SI units{})",
                  reason, path.substr(path.rfind('.') + 1), white_noise_field,
                  by_model ? ", or propagate more often" : ""));
}

// The gyro and accelerometer Gauss-Markov biases and the flicker design of one sensor model.
// `modelled`: the EKF or the covariance analysis carries this model's states.
void CheckSensorTimeConstants(const ImuErrorModel& model, const std::string& prefix, bool modelled,
                              const ModelIntervals& intervals) {
  for (const bool gyro : {true, false}) {
    const TriadErrorParams& p = gyro ? model.gyro : model.accel;
    const std::string triad = prefix + (gyro ? ".gyro" : ".accel");
    const std::string white = gyro ? "arw_deg_per_sqrt_h" : "vrw_m_per_s_per_sqrt_h";
    if (p.bias_gauss_markov.sigma > 0.0) {
      CheckCorrelationTime(triad + ".gauss_markov_tau_s", p.bias_gauss_markov.tau_s, modelled,
                           intervals, white);
    }
    // The flicker approximation's shortest Gauss-Markov component (sensors.h
    // DesignFlickerApproximation: tau_min_s / 4) becomes a filter state: the same bound on it.
    if (modelled && intervals.model_s > 0.0 && p.bias_flicker.bias_instability > 0.0) {
      const std::vector<GaussMarkovComponent> design = DesignFlickerApproximation(p.bias_flicker);
      const double shortest_s = design.front().tau_s;
      const double ratio = p.bias_flicker.tau_min_s / shortest_s;
      if (shortest_s < intervals.model_s * (1.0 - 1e-12)) {
        const std::string path = triad + ".bias_instability_tau_min_s";
        throw SpecError(
            path, fmt::format("{} s", p.bias_flicker.tau_min_s),
            fmt::format("at least {:.6g} s = {:.6g} x {} = {} s (the flicker design's shortest "
                        "Gauss-Markov state, bias_instability_tau_min_s / {:.6g}, must be at least "
                        "that interval; or propagate more often)",
                        intervals.model_s * ratio, ratio, intervals.model_text, intervals.model_s,
                        ratio));
      }
    }
  }
}

void CheckTimeConstants(const MonteCarloSpec& spec) {
  const ModelIntervals intervals = IntervalsOf(spec);
  const bool separate_filter_model = spec.filter_sensor.has_value();
  if (spec.sensor) {
    CheckSensorTimeConstants(*spec.sensor, "sensor", !separate_filter_model, intervals);
  }
  if (spec.filter_sensor) {
    CheckSensorTimeConstants(*spec.filter_sensor, "navigation.ekf.sensor", true, intervals);
  }
  const bool ekf = spec.filter == NavigationFilterKind::kInsGnssEkf;
  if (spec.aiding.gnss && !spec.aiding.gnss->position_gauss_markov_sigma_ned_m.isZero(0.0)) {
    ModelIntervals gnss = intervals;
    gnss.sample_s = 1.0 / spec.aiding.gnss->rate_hz;
    gnss.sample_text = "the fix interval 1 / aiding.gnss.rate_hz";
    CheckCorrelationTime("aiding.gnss.position_gauss_markov_tau_s",
                         spec.aiding.gnss->position_gauss_markov_tau_s, ekf || spec.covariance,
                         gnss, "aiding.gnss.position_sigma_ned_m");
  }
  if (spec.aiding.barometer && spec.aiding.barometer->bias.sigma > 0.0) {
    ModelIntervals baro = intervals;
    baro.sample_s = 1.0 / spec.aiding.barometer->rate_hz;
    baro.sample_text = "the sample interval 1 / aiding.barometer.rate_hz";
    CheckCorrelationTime("aiding.barometer.bias_gauss_markov_tau_s",
                         spec.aiding.barometer->bias.tau_s, ekf || spec.covariance, baro,
                         "aiding.barometer.noise_sigma_m");
  }
}

}  // namespace

ValidatedJob ValidateJob(const v1::Job& job, const std::filesystem::path& base_dir,
                         const JobValidationOptions& options) {
  CheckFieldSizes(job);
  if (!options.allow_file_references) CheckNoFileReferences(job);
  CheckNothingIgnored(job);
  ValidatedJob out;
  try {
    out.spec = TranslateMonteCarloJob(JobFile{job, base_dir}, options.overrides);
  } catch (const SpecError& e) {
    const bool engine_motion_path = std::string_view(e.field()).starts_with("motion.segments") ||
                                    std::string_view(e.field()).starts_with("motion.truth_profile");
    if (FromMotionFile(job) &&
        (engine_motion_path || !IsSchemaFieldPath(*v1::Job::descriptor(), e.field()))) {
      RethrowForMotionFile(job, e);
    }
    throw;
  }
  CheckTimeConstants(out.spec);
  CheckMessageValues(job);

  const MonteCarloSpec& spec = out.spec;
  out.runs = spec.run_count == 0 ? spec.runs - spec.first_run : spec.run_count;
  // Samples per run as the engine counts them: the generator's output steps, plus the initial
  // sample for mechanization SEED000, which consumes point samples from t = 0. Planning only.
  const TrajectoryGenerator planned(spec.simulation.motion, spec.simulation.rate_hz);
  out.samples_per_run = static_cast<uint64_t>(planned.num_steps()) +
                        (spec.simulation.mechanization == MechanizationKind::kSeed000 ? 1 : 0);
  out.samples_total = out.samples_per_run * out.runs;
  out.memory_bytes = EstimateMonteCarloMemoryBytes(spec);
  return out;
}

MonteCarloSpec ToMonteCarloSpec(const JobFile& file, const MonteCarloOverrides& overrides) {
  JobValidationOptions options;
  options.overrides = overrides;
  return ValidateJob(file, options).spec;
}

}  // namespace driftlab::app
