// The truth of a Monte-Carlo job, generated once and shared read-only by its runs, and the error
// model the filter and the covariance analysis derive from it.
#include <algorithm>
#include <atomic>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "driftlab/aiding.h"
#include "montecarlo/internal.h"

namespace driftlab::mc_detail {

SharedTruth BuildSharedTruth(const MonteCarloSpec& spec, bool keep_imu,
                             const std::atomic<bool>* cancel, bool* cancelled) {
  SharedTruth s;
  const std::unique_ptr<TrajectoryGenerator> generator = PrepareSharedTruth(spec, keep_imu, &s);
  StreamSharedTruth(spec, keep_imu, generator.get(), &s, cancel, cancelled, nullptr);
  return s;
}

std::unique_ptr<TrajectoryGenerator> PrepareSharedTruth(const MonteCarloSpec& spec, bool keep_imu,
                                                        SharedTruth* out) {
  auto owned_generator =
      std::make_unique<TrajectoryGenerator>(spec.simulation.motion, spec.simulation.rate_hz);
  const TrajectoryGenerator& generator = *owned_generator;
  SharedTruth& s = *out;
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
  if (keep_imu && spec.filter == NavigationFilterKind::kInsGnssEkf) {
    s.schedule = std::make_shared<const AidingSchedule>(
        MakeAidingSensors(aiding, s.rate_hz), s.rate_hz, s.start_step + 1, s.n,
        [&](double t) { return generator.IsStaticAt(t); });
  }
  if (keep_imu && aiding.magnetometer) {
    s.mag_decimation =
        AidingDecimation(aiding.magnetometer->rate_hz, s.rate_hz, "aiding.magnetometer.rate_hz");
    s.mag_q_b_n.resize(static_cast<size_t>(s.n / s.mag_decimation) + 1);
    s.mag_q_b_n[0] = s.truth0.q_b_n;
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
  return owned_generator;
}

void StreamSharedTruth(const MonteCarloSpec& spec, bool keep_imu, TrajectoryGenerator* generator_in,
                       SharedTruth* out, const std::atomic<bool>* cancel, bool* cancelled,
                       TruthStream* stream) {
  TrajectoryGenerator& generator = *generator_in;
  SharedTruth& s = *out;
  const bool seed000 = spec.simulation.mechanization == MechanizationKind::kSeed000;
  const bool point_samples = seed000 || spec.filter == NavigationFilterKind::kComplementary;
  const bool truth_height =
      keep_imu && !seed000 && spec.simulation.ned.vertical == VerticalChannel::kTruthHeight;
  size_t next_report = 0;
  auto keep_truth = [&](int64_t k, const NavState& truth) {
    if (k == s.start_step) s.truth_start = truth;
    while (next_report < s.reports.size() && s.reports[next_report].k == k) {
      s.reports[next_report++].truth = truth;
    }
  };
  keep_truth(0, s.truth0);
  if (stream != nullptr) stream->Publish(0);
  // The point samples only for mechanization B and the complementary filter (generator work
  // otherwise spent on values nobody reads).
  generator.set_point_samples(keep_imu && point_samples);
  TrajectorySample sample;
  while (generator.Next(&sample)) {
    const int64_t k = generator.step();
    if (cancel != nullptr && (k & 4095) == 0 && cancel->load(std::memory_order_relaxed)) {
      if (cancelled != nullptr) *cancelled = true;
      return;
    }
    const size_t uk = static_cast<size_t>(k);
    if (keep_imu && point_samples) {
      s.samples[uk] = sample.sample;
    } else if (keep_imu) {
      s.increments[uk] = sample.increment;
    }
    if (s.schedule) {
      const uint32_t due = s.schedule->Due(k, sample.truth.t_s);
      if (due != 0) {
        s.aiding_epochs.push_back(SharedTruth::AidingEpoch{
            k, due, AidingTruth{sample.truth, sample.increment.delta_theta_ib_b / s.dt_s}});
      }
    }
    if (s.mag_decimation > 0 && k % s.mag_decimation == 0) {
      s.mag_q_b_n[static_cast<size_t>(k / s.mag_decimation)] = sample.truth.q_b_n;
    }
    if (truth_height) {
      s.h_m[uk] = sample.truth.llh.h_m;
      s.v_D_m_per_s[uk] = sample.truth.v_eb_n.z();
    }
    keep_truth(k, sample.truth);
    if (stream != nullptr && (k & (kTruthPublishSamples - 1)) == 0) stream->Publish(k);
  }
  if (stream != nullptr) stream->Publish(s.n);
}

ErrorStateNoiseFromImu PrepareFilterModel(const MonteCarloSpec& spec, SharedTruth* s) {
  ErrorStateNoiseFromImu noise = FilterErrorModel(spec, *s);
  if (spec.filter == NavigationFilterKind::kInsGnssEkf || spec.covariance) {
    s->ekf_noise = noise.noise;
    s->ekf_P0 = StartErrorCovariance(spec, s->truth_start.euler(), noise.noise);
  }
  return noise;
}

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
  // The aids' own error states (GNSS Gauss-Markov error, barometer bias, ...), in their order.
  if (ekf) {
    for (const auto& sensor : MakeAidingSensors(spec.aiding, s.rate_hz)) {
      for (AidingErrorStates& states : sensor->ErrorStates()) {
        out.noise.aiding_states.push_back(std::move(states));
      }
    }
  }
  return out;
}

}  // namespace driftlab::mc_detail
