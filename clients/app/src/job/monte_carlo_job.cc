#include "driftlab/app/monte_carlo_job.h"

#include <fmt/format.h>
#include <google/protobuf/util/message_differencer.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "driftlab/aiding.h"
#include "driftlab/app/result_file.h"
#include "driftlab/app/sensor_model.h"
#include "driftlab/app/translate.h"
#include "driftlab/ins_gnss_filter.h"
#include "driftlab/sensors.h"
#include "driftlab/spec_error.h"
#include "driftlab/trajectory.h"
#include "driftlab/units.h"
#include "job/field_checks.h"
#include "job/job_translation.h"

namespace driftlab::app {
namespace {

// Limits of the initial errors: beyond them the linear error models (and a real INS's
// initialisation) make no sense.
constexpr double kMaxInitialPosition_m = 1.0e5;
constexpr double kMaxInitialVelocity_m_per_s = 100.0;
constexpr double kMaxInitialAttitude_deg = 30.0;

Eigen::Vector3d Sigmas(const google::protobuf::RepeatedField<double>& values,
                       const std::string& path, double max, std::string_view unit, double scale) {
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  if (values.empty()) return out;
  if (values.size() != 3) {
    throw SpecError(path, fmt::format("{} values", values.size()), "exactly 3 values");
  }
  for (int i = 0; i < 3; ++i) {
    out[i] = Check(fmt::format("{}[{}]", path, i), values[i], Closed(0.0, max, unit)) * scale;
  }
  return out;
}

// A 3-vector field: empty = the default, else exactly 3 values each in `range`.
Eigen::Vector3d Vector3Or(const google::protobuf::RepeatedField<double>& values,
                          const std::string& path, const Range& range,
                          const Eigen::Vector3d& default_value) {
  if (values.empty()) return default_value;
  if (values.size() != 3) {
    throw SpecError(path, fmt::format("{} values", values.size()), "exactly 3 values");
  }
  Eigen::Vector3d out;
  for (int i = 0; i < 3; ++i) out[i] = Check(fmt::format("{}[{}]", path, i), values[i], range);
  return out;
}

// An aiding rate: absent = the IMU rate divided by the smallest integer that brings it to
// default_hz or below; else 0 < rate <= rate_hz with rate_hz / rate an integer.
double AidingRate(const std::string& path, bool has, double value, double default_hz,
                  double rate_hz) {
  if (!has) return rate_hz / std::ceil(rate_hz / default_hz - 1e-9);
  Range range = Positive(rate_hz, "Hz");
  range.note = "(at most the IMU rate rate_hz, which it must divide by an integer)";
  Check(path, value, range);
  AidingDecimation(value, rate_hz, path);
  return value;
}

constexpr double kMaxAidingSigma_m = 1000.0;
constexpr double kMaxAidingSigma_m_per_s = 100.0;
constexpr double kMaxCorrelationTime_s = 1.0e6;

GnssConfig ToGnssConfig(const v1::GnssAiding& in, double rate_hz, double duration_s) {
  const std::string p = "aiding.gnss";
  GnssConfig g;
  g.rate_hz = AidingRate(p + ".rate_hz", in.has_rate_hz(), in.rate_hz(), 1.0, rate_hz);
  g.position_sigma_ned_m = Vector3Or(in.position_sigma_ned_m(), p + ".position_sigma_ned_m",
                                     Closed(0.0, kMaxAidingSigma_m, "m"), g.position_sigma_ned_m);
  g.velocity_sigma_ned_m_per_s =
      Vector3Or(in.velocity_sigma_ned_m_per_s(), p + ".velocity_sigma_ned_m_per_s",
                Closed(0.0, kMaxAidingSigma_m_per_s, "m/s"), g.velocity_sigma_ned_m_per_s);
  g.position_gauss_markov_sigma_ned_m =
      Vector3Or(in.position_gauss_markov_sigma_ned_m(), p + ".position_gauss_markov_sigma_ned_m",
                Closed(0.0, kMaxAidingSigma_m, "m"), g.position_gauss_markov_sigma_ned_m);
  g.position_gauss_markov_tau_s =
      OptionalOr(p + ".position_gauss_markov_tau_s", in.has_position_gauss_markov_tau_s(),
                 in.position_gauss_markov_tau_s(), g.position_gauss_markov_tau_s,
                 Positive(kMaxCorrelationTime_s, "s"));
  g.lever_arm_b_m = Vector3Or(in.lever_arm_b_m(), p + ".lever_arm_b_m", Closed(-100.0, 100.0, "m"),
                              Eigen::Vector3d::Zero());
  g.use_velocity = in.has_use_velocity() ? in.use_velocity() : true;
  double previous_end_s = 0.0;
  for (int i = 0; i < in.outages_size(); ++i) {
    const v1::GnssOutage& o = in.outages(i);
    const std::string f = fmt::format("{}.outages[{}]", p, i);
    Range start_range = Closed(0.0, duration_s, "s");
    start_range.hi_open = true;
    start_range.note = "(inside the trajectory)";
    const double start_s = Required(f + ".start_s", o.has_start_s(), o.start_s(), start_range);
    if (i > 0 && start_s < previous_end_s) {
      throw SpecError(f + ".start_s", fmt::format("{}", start_s),
                      fmt::format(">= {} s, the end of outages[{}] (outages ascending and not "
                                  "overlapping)",
                                  previous_end_s, i - 1));
    }
    Range end_range = Closed(start_s, duration_s, "s");
    end_range.lo_open = true;
    end_range.note = "(after start_s, inside the trajectory)";
    const double end_s = Required(f + ".end_s", o.has_end_s(), o.end_s(), end_range);
    g.outages.push_back(GnssOutage{start_s, end_s - start_s});
    previous_end_s = end_s;
  }
  // Zero sigmas, lever arm length and the rest, with the engine's own messages.
  ValidateGnssConfig(g, rate_hz, p);
  return g;
}

BarometerConfig ToBarometerConfig(const v1::BarometerAiding& in, double rate_hz) {
  const std::string p = "aiding.barometer";
  BarometerConfig b;
  b.rate_hz = AidingRate(p + ".rate_hz", in.has_rate_hz(), in.rate_hz(), 10.0, rate_hz);
  b.noise_sigma_m = OptionalOr(p + ".noise_sigma_m", in.has_noise_sigma_m(), in.noise_sigma_m(),
                               b.noise_sigma_m, Positive(kMaxAidingSigma_m, "m"));
  b.bias.sigma =
      OptionalOr(p + ".bias_gauss_markov_sigma_m", in.has_bias_gauss_markov_sigma_m(),
                 in.bias_gauss_markov_sigma_m(), 0.0, Closed(0.0, kMaxAidingSigma_m, "m"));
  if (b.bias.sigma > 0.0) {
    b.bias.tau_s = Required(p + ".bias_gauss_markov_tau_s", in.has_bias_gauss_markov_tau_s(),
                            in.bias_gauss_markov_tau_s(), Positive(kMaxCorrelationTime_s, "s"));
  } else if (in.has_bias_gauss_markov_tau_s()) {
    b.bias.tau_s = Check(p + ".bias_gauss_markov_tau_s", in.bias_gauss_markov_tau_s(),
                         Positive(kMaxCorrelationTime_s, "s"));
  }
  ValidateBarometerConfig(b, rate_hz, p);
  return b;
}

MagnetometerConfig ToMagnetometerConfig(const v1::MagnetometerAiding& in, double rate_hz) {
  const std::string p = "aiding.magnetometer";
  MagnetometerConfig m;
  m.rate_hz = AidingRate(p + ".rate_hz", in.has_rate_hz(), in.rate_hz(), rate_hz, rate_hz);
  m.earth_field_n = Vector3Or(in.earth_field_ned_ut(), p + ".earth_field_ned_ut",
                              Closed(-1000.0, 1000.0, "uT"), m.earth_field_n);
  m.hard_iron_b = Vector3Or(in.hard_iron_ut(), p + ".hard_iron_ut", Closed(-1000.0, 1000.0, "uT"),
                            Eigen::Vector3d::Zero());
  const auto& soft = in.soft_iron();
  if (!soft.empty() && soft.size() != 3 && soft.size() != 9) {
    throw SpecError(p + ".soft_iron", fmt::format("{} values", soft.size()),
                    "3 values (diagonal) or 9 (row order)");
  }
  for (int i = 0; i < soft.size(); ++i) {
    Check(fmt::format("{}.soft_iron[{}]", p, i), soft[i], Closed(-10.0, 10.0, ""));
  }
  if (soft.size() == 3) {
    m.soft_iron = Eigen::Vector3d(soft[0], soft[1], soft[2]).asDiagonal();
  } else if (soft.size() == 9) {
    for (int i = 0; i < 9; ++i) m.soft_iron(i / 3, i % 3) = soft[i];
  }
  m.noise_sigma = OptionalOr(p + ".noise_sigma_ut", in.has_noise_sigma_ut(), in.noise_sigma_ut(),
                             m.noise_sigma, Closed(0.0, 1000.0, "uT"));
  ValidateMagnetometerConfig(m, rate_hz, p);
  return m;
}

ZuptConfig ToZuptConfig(const v1::ZuptAiding& in, double rate_hz) {
  const std::string p = "aiding.zupt";
  ZuptConfig z;
  z.rate_hz = AidingRate(p + ".rate_hz", in.has_rate_hz(), in.rate_hz(), 1.0, rate_hz);
  z.velocity_sigma_m_per_s =
      OptionalOr(p + ".velocity_sigma_m_per_s", in.has_velocity_sigma_m_per_s(),
                 in.velocity_sigma_m_per_s(), z.velocity_sigma_m_per_s, Positive(10.0, "m/s"));
  return z;
}

OdometerConfig ToOdometerConfig(const v1::OdometerAiding& in, double rate_hz) {
  const std::string p = "aiding.odometer";
  OdometerConfig o;
  o.rate_hz = AidingRate(p + ".rate_hz", in.has_rate_hz(), in.rate_hz(), 10.0, rate_hz);
  o.speed_sigma_m_per_s =
      OptionalOr(p + ".speed_sigma_m_per_s", in.has_speed_sigma_m_per_s(), in.speed_sigma_m_per_s(),
                 o.speed_sigma_m_per_s, Positive(10.0, "m/s"));
  o.scale_factor_sigma =
      1e-6 * OptionalOr(p + ".scale_factor_sigma_ppm", in.has_scale_factor_sigma_ppm(),
                        in.scale_factor_sigma_ppm(), 0.0, Closed(0.0, 100000.0, "ppm"));
  o.lever_arm_b_m = Vector3Or(in.lever_arm_b_m(), p + ".lever_arm_b_m", Closed(-100.0, 100.0, "m"),
                              Eigen::Vector3d::Zero());
  o.non_holonomic = !in.has_non_holonomic() || in.non_holonomic();
  o.non_holonomic_sigma_m_per_s = OptionalOr(
      p + ".non_holonomic_sigma_m_per_s", in.has_non_holonomic_sigma_m_per_s(),
      in.non_holonomic_sigma_m_per_s(), o.non_holonomic_sigma_m_per_s, Positive(10.0, "m/s"));
  ValidateOdometerConfig(o, rate_hz, p);
  return o;
}

// navigation.filter / ekf / complementary, aiding and the covariance switch.
void TranslateFilterAndAiding(const v1::Job& job, const MonteCarloOverrides& overrides,
                              MonteCarloSpec* spec) {
  const v1::Navigation& nav = job.navigation();
  const double rate_hz = spec->simulation.rate_hz;
  switch (nav.filter()) {
    case v1::Navigation::FILTER_UNSPECIFIED:
    case v1::Navigation::NONE:
      spec->filter = NavigationFilterKind::kNone;
      break;
    case v1::Navigation::INS_GNSS_EKF:
      spec->filter = NavigationFilterKind::kInsGnssEkf;
      break;
    case v1::Navigation::COMPLEMENTARY:
      spec->filter = NavigationFilterKind::kComplementary;
      break;
    default:
      throw SpecError("navigation.filter", fmt::format("{}", static_cast<int>(nav.filter())),
                      "one of NONE, INS_GNSS_EKF, COMPLEMENTARY");
  }
  if (nav.has_ekf() && spec->filter != NavigationFilterKind::kInsGnssEkf) {
    throw SpecError("navigation.ekf", "set", "only with navigation.filter INS_GNSS_EKF");
  }
  if (nav.has_complementary() && spec->filter != NavigationFilterKind::kComplementary) {
    throw SpecError("navigation.complementary", "set", "only with navigation.filter COMPLEMENTARY");
  }
  spec->ekf_propagation_step_samples = static_cast<int64_t>(OptionalOr(
      "navigation.ekf.propagation_step_samples", nav.ekf().has_propagation_step_samples(),
      nav.ekf().propagation_step_samples(), 10.0, Closed(1.0, 10000.0, "samples")));
  if (nav.ekf().has_sensor() && nav.ekf().sensor().ByteSizeLong() > 0) {
    spec->filter_sensor = ToImuErrorModel(nav.ekf().sensor(), "navigation.ekf.sensor");
  }
  spec->filter_augment_scale_misalignment =
      !nav.ekf().has_augment_scale_misalignment() || nav.ekf().augment_scale_misalignment();
  spec->filter_flicker_states_per_axis = static_cast<int>(
      OptionalOr("navigation.ekf.flicker_states_per_axis", nav.ekf().has_flicker_states_per_axis(),
                 nav.ekf().flicker_states_per_axis(), static_cast<double>(kMaxFlickerComponents),
                 Closed(1.0, static_cast<double>(kMaxFlickerComponents), "states")));
  const v1::ComplementaryOptions& c = nav.complementary();
  switch (c.pair()) {
    case v1::ComplementaryOptions::PAIR_UNSPECIFIED:
    case v1::ComplementaryOptions::FIRST_ORDER:
      spec->complementary.kind = ComplementaryPairKind::kFirstOrder;
      break;
    case v1::ComplementaryOptions::BUTTERWORTH4:
      spec->complementary.kind = ComplementaryPairKind::kButterworth4;
      break;
    case v1::ComplementaryOptions::BUTTERWORTH4_SEED:
      spec->complementary.kind = ComplementaryPairKind::kButterworth4Seed;
      break;
    default:
      throw SpecError("navigation.complementary.pair",
                      fmt::format("{}", static_cast<int>(c.pair())),
                      "one of FIRST_ORDER, BUTTERWORTH4, BUTTERWORTH4_SEED");
  }
  Range crossover = Positive(rate_hz / 2.0, "Hz");
  crossover.hi_open = true;
  crossover.note = "(below half the IMU rate)";
  spec->complementary.crossover_hz =
      OptionalOr("navigation.complementary.crossover_hz", c.has_crossover_hz(), c.crossover_hz(),
                 0.1, crossover);
  spec->complementary.heading_crossover_hz =
      OptionalOr("navigation.complementary.heading_crossover_hz", c.has_heading_crossover_hz(),
                 c.heading_crossover_hz(), 0.01, crossover);

  const v1::Aiding& aiding = job.aiding();
  if (aiding.has_gnss()) {
    double duration_s = 0.0;
    std::vector<std::pair<double, double>> invisible_s;
    const bool gps_column =
        std::any_of(spec->simulation.motion.segments.begin(),
                    spec->simulation.motion.segments.end(), [](const Segment& s) {
                      const auto* c = std::get_if<GnssInsSimCommand>(&s);
                      return c != nullptr && !c->gps_visible;
                    });
    if (aiding.gnss().outages_size() > 0 || gps_column) {
      // Outages must lie inside the trajectory: its duration from the motion plan.
      const TrajectoryGenerator planned(spec->simulation.motion, rate_hz);
      duration_s = planned.duration_s();
      invisible_s = planned.gps_invisible_s();
    }
    spec->aiding.gnss = ToGnssConfig(aiding.gnss(), rate_hz, duration_s);
    // gnss-ins-sim's GPS-visibility column: no fix during the commands marked 0, in addition to
    // the job's outages (union of both, ascending and non-overlapping as GnssConfig requires).
    if (!invisible_s.empty()) {
      std::vector<std::pair<double, double>> windows = invisible_s;
      for (const GnssOutage& o : spec->aiding.gnss->outages) {
        windows.emplace_back(o.start_s, o.start_s + o.duration_s);
      }
      std::sort(windows.begin(), windows.end());
      std::vector<GnssOutage> merged;
      double end_s = 0.0;
      for (const auto& [start, end] : windows) {
        if (!merged.empty() && start <= end_s) {
          end_s = std::max(end_s, end);
          merged.back().duration_s = end_s - merged.back().start_s;
        } else {
          merged.push_back(GnssOutage{start, end - start});
          end_s = end;
        }
      }
      spec->aiding.gnss->outages = merged;
    }
  }
  if (aiding.has_barometer()) {
    spec->aiding.barometer = ToBarometerConfig(aiding.barometer(), rate_hz);
  }
  if (aiding.has_magnetometer()) {
    spec->aiding.magnetometer = ToMagnetometerConfig(aiding.magnetometer(), rate_hz);
  }
  if (aiding.has_zupt() && aiding.zupt().enabled()) {
    spec->aiding.zupt = ToZuptConfig(aiding.zupt(), rate_hz);
  }
  if (aiding.has_odometer()) spec->aiding.odometer = ToOdometerConfig(aiding.odometer(), rate_hz);

  const v1::MonteCarlo& mc = job.monte_carlo();
  spec->covariance = overrides.covariance || (mc.has_covariance() && mc.covariance());
  spec->covariance_step_samples = static_cast<int64_t>(
      OptionalOr("monte_carlo.covariance_step_samples", mc.has_covariance_step_samples(),
                 mc.covariance_step_samples(), 10.0, Closed(1.0, 10000.0, "samples")));
  if (overrides.covariance && !mc.has_covariance()) {
    // Name the flag, not the field, when the combination does not fit.
    try {
      ValidateFilterAndAiding(*spec);
    } catch (const SpecError& e) {
      if (e.field() != "monte_carlo.covariance") throw;
      throw SpecError("--covariance", "given",
                      "only with mechanization NED, vertical channel FREE, initialization "
                      "TRUTH_PLUS_ERRORS and navigation.filter NONE or INS_GNSS_EKF");
    }
  }
  ValidateFilterAndAiding(*spec);
}

}  // namespace

void ParseShard(const std::string& text, MonteCarloOverrides* overrides) {
  const std::string allowed = "i/K with integers 0 <= i < K, K >= 1 (e.g. 0/4)";
  const size_t slash = text.find('/');
  uint32_t i = 0;
  uint32_t k = 0;
  auto parse = [](std::string_view s, uint32_t* value) {
    const auto [end, error] = std::from_chars(s.data(), s.data() + s.size(), *value);
    return error == std::errc() && end == s.data() + s.size() && !s.empty();
  };
  if (slash == std::string::npos || !parse(std::string_view(text).substr(0, slash), &i) ||
      !parse(std::string_view(text).substr(slash + 1), &k) || k == 0 || i >= k) {
    throw SpecError("--shard", text, allowed);
  }
  overrides->shard_index = i;
  overrides->shard_count = k;
}

MonteCarloSpec TranslateMonteCarloJob(const JobFile& file, const MonteCarloOverrides& overrides) {
  MonteCarloSpec spec;
  spec.simulation = PlanSimulationSpec(file);
  spec.sensor = ToImuErrorModel(file.job);
  const v1::MonteCarlo& mc = file.job.monte_carlo();
  const double rate_hz = spec.simulation.rate_hz;

  const Range runs_range = Closed(1, kMaxMonteCarloRuns, "");
  if (overrides.runs) {
    spec.runs = static_cast<uint32_t>(Check("--runs", *overrides.runs, runs_range));
  } else {
    spec.runs = static_cast<uint32_t>(
        OptionalOr("monte_carlo.runs", mc.has_runs(), mc.runs(), kDefaultRuns, runs_range));
  }
  spec.seed = overrides.seed.value_or(JobSeed(file.job));
  if (overrides.threads) {
    spec.threads =
        static_cast<int>(Check("--threads", *overrides.threads,
                               Closed(0, kMaxMonteCarloThreads, "(0 = all hardware threads)")));
  }
  if (overrides.shard_count) {
    const uint32_t k = *overrides.shard_count;
    const uint32_t i = overrides.shard_index.value_or(0);
    if (k > spec.runs) {
      throw SpecError("--shard", fmt::format("{}/{}", i, k),
                      fmt::format("i/K with K <= runs = {} (every shard needs a run)", spec.runs));
    }
    const uint64_t n = spec.runs;
    spec.first_run = static_cast<uint32_t>(i * n / k);
    spec.run_count = static_cast<uint32_t>((i + 1) * n / k - spec.first_run);
  } else {
    spec.first_run = 0;
    spec.run_count = spec.runs;
  }

  const v1::InitialErrors& initial = mc.initial_errors();
  const std::string ie = "monte_carlo.initial_errors";
  InitialErrorSigmas& errors = spec.initial_errors;
  errors.position_ned_m =
      Sigmas(initial.position_ned_m(), ie + ".position_ned_m", kMaxInitialPosition_m, "m", 1.0);
  errors.velocity_ned_m_per_s = Sigmas(initial.velocity_ned_m_per_s(), ie + ".velocity_ned_m_per_s",
                                       kMaxInitialVelocity_m_per_s, "m/s", 1.0);
  errors.attitude_rad = Sigmas(initial.attitude_deg(), ie + ".attitude_deg",
                               kMaxInitialAttitude_deg, "deg", kDegToRad);
  if (!initial.attitude_deg().empty() && !initial.attitude_ned_deg().empty()) {
    throw SpecError(ie + ".attitude_ned_deg", "given with attitude_deg",
                    "one of attitude_ned_deg (a rotation about north, east, down) or attitude_deg "
                    "(added to the Euler angles)");
  }
  errors.attitude_ned_rad = Sigmas(initial.attitude_ned_deg(), ie + ".attitude_ned_deg",
                                   kMaxInitialAttitude_deg, "deg", kDegToRad);
  errors.fixed_position_ned_m = Vector3Or(
      initial.fixed_position_ned_m(), ie + ".fixed_position_ned_m",
      Closed(-kMaxInitialPosition_m, kMaxInitialPosition_m, "m"), Eigen::Vector3d::Zero());
  errors.fixed_velocity_ned_m_per_s =
      Vector3Or(initial.fixed_velocity_ned_m_per_s(), ie + ".fixed_velocity_ned_m_per_s",
                Closed(-kMaxInitialVelocity_m_per_s, kMaxInitialVelocity_m_per_s, "m/s"),
                Eigen::Vector3d::Zero());
  errors.fixed_attitude_ned_rad =
      Vector3Or(initial.fixed_attitude_ned_deg(), ie + ".fixed_attitude_ned_deg",
                Closed(-kMaxInitialAttitude_deg, kMaxInitialAttitude_deg, "deg"),
                Eigen::Vector3d::Zero()) *
      kDegToRad;
  if (errors.fixed_attitude_ned_rad.norm() > kMaxInitialAttitude_deg * kDegToRad) {
    throw SpecError(
        ie + ".fixed_attitude_ned_deg",
        fmt::format("a rotation of {} deg", errors.fixed_attitude_ned_rad.norm() * kRadToDeg),
        fmt::format("a rotation of at most {} deg", kMaxInitialAttitude_deg));
  }
  // The first attitude field with a non-zero value, for the messages below.
  const char* attitude_field = !errors.attitude_rad.isZero(0.0)       ? "attitude_deg"
                               : !errors.attitude_ned_rad.isZero(0.0) ? "attitude_ned_deg"
                                                                      : "fixed_attitude_ned_deg";

  const v1::Initialization& init = mc.initialization();
  const bool seed000 = spec.simulation.mechanization == MechanizationKind::kSeed000;
  if (init.kind() == v1::Initialization::STATIC_ALIGNMENT) {
    if (seed000) {
      throw SpecError("monte_carlo.initialization.kind", "STATIC_ALIGNMENT",
                      "TRUTH_PLUS_ERRORS with navigation.mechanization SEED000 (it aligns itself "
                      "over navigation.seed000.static_period_s)");
    }
    spec.initialization = InitializationKind::kStaticAlignment;
    spec.alignment.duration_s =
        Required("monte_carlo.initialization.alignment_duration_s", init.has_alignment_duration_s(),
                 init.alignment_duration_s(), Positive(100000.0, "s"));
    if (init.has_heading_sigma_deg()) {
      spec.alignment.heading_sigma_rad = Check("monte_carlo.initialization.heading_sigma_deg",
                                               init.heading_sigma_deg(), Positive(180.0, "deg")) *
                                         kDegToRad;
    }
    if (!errors.attitude_is_zero()) {
      throw SpecError(ie + "." + attitude_field, "non-zero",
                      "empty or zeros with STATIC_ALIGNMENT (the attitude comes from the "
                      "alignment)");
    }
  } else {
    spec.initialization = InitializationKind::kTruthPlusErrors;
    if (init.has_alignment_duration_s() || init.has_heading_sigma_deg()) {
      throw SpecError("monte_carlo.initialization.alignment_duration_s", "set",
                      "only with kind STATIC_ALIGNMENT");
    }
    if (seed000 && !errors.is_zero()) {
      throw SpecError(ie, "non-zero",
                      "no initial errors with navigation.mechanization SEED000 (it initialises "
                      "itself from its static period)");
    }
  }

  // Epochs.
  if (mc.has_epoch_interval_s() && !mc.epoch_times_s().empty()) {
    throw SpecError("monte_carlo", "both epoch_interval_s and epoch_times_s are set",
                    "exactly one of them, or neither (an epoch every second)");
  }
  if (!mc.epoch_times_s().empty()) {
    spec.epoch_times_s.assign(mc.epoch_times_s().begin(), mc.epoch_times_s().end());
    for (size_t i = 0; i < spec.epoch_times_s.size(); ++i) {
      Check(fmt::format("monte_carlo.epoch_times_s[{}]", i), spec.epoch_times_s[i],
            Closed(0.0, 1.0e7, "s"));
    }
  } else {
    const double interval_s =
        OptionalOr("monte_carlo.epoch_interval_s", mc.has_epoch_interval_s(), mc.epoch_interval_s(),
                   kDefaultEpochInterval_s, Positive(1.0e7, "s"));
    const double samples = interval_s * rate_hz;
    const double k = std::max(1.0, std::round(samples));
    if (mc.has_epoch_interval_s() && std::abs(samples - k) > 1e-6 * k) {
      throw SpecError(
          "monte_carlo.epoch_interval_s", fmt::format("{}", interval_s),
          fmt::format("a multiple of the IMU interval 1 / rate_hz = {} s", 1.0 / rate_hz));
    }
    spec.epoch_every_samples = static_cast<int64_t>(k);
  }
  spec.checkpoint_times_s.assign(mc.checkpoint_times_s().begin(), mc.checkpoint_times_s().end());
  for (size_t i = 0; i < spec.checkpoint_times_s.size(); ++i) {
    Check(fmt::format("monte_carlo.checkpoint_times_s[{}]", i), spec.checkpoint_times_s[i],
          Closed(0.0, 1.0e7, "s"));
  }
  TranslateFilterAndAiding(file.job, overrides, &spec);
  if (overrides.max_memory_bytes) spec.max_memory_bytes = *overrides.max_memory_bytes;
  ValidateMonteCarloSpec(spec);
  return spec;
}

v1::Job JobAsRun(const v1::Job& job, const MonteCarloSpec& spec) {
  v1::Job out = job;
  out.mutable_monte_carlo()->set_runs(spec.runs);
  out.mutable_monte_carlo()->set_seed(spec.seed);
  if (spec.covariance) out.mutable_monte_carlo()->set_covariance(true);  // `run --covariance`
  return out;
}

}  // namespace driftlab::app
