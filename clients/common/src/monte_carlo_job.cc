#include "driftlab/jobspec/monte_carlo_job.h"

#include <fmt/format.h>
#include <google/protobuf/util/message_differencer.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <string>
#include <vector>

#include "driftlab/jobspec/sensor_model.h"
#include "driftlab/jobspec/translate.h"
#include "driftlab/spec_error.h"
#include "field_checks.h"

namespace driftlab::jobspec {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
constexpr double kRadToDeg = 180.0 / M_PI;
// Limits of the initial errors: beyond them the linear error models (and a real INS's
// initialisation) make no sense.
constexpr double kMaxInitialPosition_m = 1.0e5;
constexpr double kMaxInitialVelocity_m_per_s = 100.0;
constexpr double kMaxInitialAttitude_deg = 30.0;
constexpr char kMergeEncoding[] = "driftlab.exact_sum.v1";

// The engine's component index (mc_statistics.h) <-> the result's enum (result.proto): the same
// order, the proto's values starting at 1.
v1::ErrorComponent ProtoComponent(int c) { return static_cast<v1::ErrorComponent>(c + 1); }
bool IsAngle(int c) {
  return c == static_cast<int>(ErrorComponent::kRoll) ||
         c == static_cast<int>(ErrorComponent::kPitch) ||
         c == static_cast<int>(ErrorComponent::kYaw);
}
// Engine unit -> result unit (radians -> degrees for the angles). Adding +0.0 turns -0 into +0:
// protobuf's JSON parser reads "-0" as 0, so without it a shard written to a file and read back
// would not reproduce the single-process bits.
double ToResultUnit(int c, double value) {
  return (IsAngle(c) ? value * kRadToDeg : value) + 0.0;
}

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

void SetStatistics(const ComponentEpochSummary& in, int c, v1::ComponentStatistics* out) {
  out->set_component(ProtoComponent(c));
  out->set_mean(ToResultUnit(c, in.mean));
  out->set_std(ToResultUnit(c, in.std));
  out->set_rms(ToResultUnit(c, in.rms));
  out->set_std_ci95_low(ToResultUnit(c, in.std_ci95_low));
  out->set_std_ci95_high(ToResultUnit(c, in.std_ci95_high));
  out->set_rms_ci95_low(ToResultUnit(c, in.rms_ci95_low));
  out->set_rms_ci95_high(ToResultUnit(c, in.rms_ci95_high));
}

void SetExactSum(const ExactSum& sum, v1::ExactSum* out) {
  for (int64_t limb : sum.Serialize()) out->add_limbs(limb);
}

ExactSum GetExactSum(const v1::ExactSum& in, const std::string& field) {
  const std::vector<int64_t> limbs(in.limbs().begin(), in.limbs().end());
  return ExactSum::Deserialize(limbs, field);
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

MonteCarloSpec ToMonteCarloSpec(const JobFile& file, const MonteCarloOverrides& overrides) {
  MonteCarloSpec spec;
  spec.simulation = ValidateJob(file);
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
  spec.initial_errors.position_ned_m =
      Sigmas(initial.position_ned_m(), "monte_carlo.initial_errors.position_ned_m",
             kMaxInitialPosition_m, "m", 1.0);
  spec.initial_errors.velocity_ned_m_per_s =
      Sigmas(initial.velocity_ned_m_per_s(), "monte_carlo.initial_errors.velocity_ned_m_per_s",
             kMaxInitialVelocity_m_per_s, "m/s", 1.0);
  spec.initial_errors.attitude_rad =
      Sigmas(initial.attitude_deg(), "monte_carlo.initial_errors.attitude_deg",
             kMaxInitialAttitude_deg, "deg", kDegToRad);

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
    if (!spec.initial_errors.attitude_rad.isZero()) {
      throw SpecError("monte_carlo.initial_errors.attitude_deg", "non-zero",
                      "empty or zeros with STATIC_ALIGNMENT (the attitude comes from the "
                      "alignment)");
    }
  } else {
    spec.initialization = InitializationKind::kTruthPlusErrors;
    if (init.has_alignment_duration_s() || init.has_heading_sigma_deg()) {
      throw SpecError("monte_carlo.initialization.alignment_duration_s", "set",
                      "only with kind STATIC_ALIGNMENT");
    }
    if (seed000 && !(spec.initial_errors.position_ned_m.isZero() &&
                     spec.initial_errors.velocity_ned_m_per_s.isZero() &&
                     spec.initial_errors.attitude_rad.isZero())) {
      throw SpecError("monte_carlo.initial_errors", "non-zero",
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
  return spec;
}

v1::Job JobAsRun(const v1::Job& job, const MonteCarloSpec& spec) {
  v1::Job out = job;
  out.mutable_monte_carlo()->set_runs(spec.runs);
  out.mutable_monte_carlo()->set_seed(spec.seed);
  return out;
}

void FillCheckpointSummaries(v1::JobResult* result) {
  for (v1::Checkpoint& checkpoint : *result->mutable_checkpoints()) {
    checkpoint.clear_components();
    const int n = checkpoint.runs_size();
    std::vector<double> values(n);
    for (int c = 0; c < kNumErrorComponents; ++c) {
      for (int r = 0; r < n; ++r) values[r] = std::abs(checkpoint.runs(r).values(c));
      std::sort(values.begin(), values.end());
      v1::ComponentPercentiles* out = checkpoint.add_components();
      out->set_component(ProtoComponent(c));
      if (n == 0) continue;
      out->set_p50(SortedPercentile(values, 0.50));
      out->set_p68(SortedPercentile(values, 0.68));
      out->set_p95(SortedPercentile(values, 0.95));
      out->set_p99(SortedPercentile(values, 0.99));
      out->set_max_abs(values.back());
    }
    if (n == 0) continue;
    const int h = static_cast<int>(ErrorComponent::kHorizontalPosition);
    checkpoint.set_cep50_m(checkpoint.components(h).p50());
    checkpoint.set_cep95_m(checkpoint.components(h).p95());
    // 2DRMS = 2 sqrt(mean(dN^2 + dE^2)), summed in run order.
    double sum = 0.0;
    for (const v1::RunValues& run : checkpoint.runs()) {
      sum += run.values(0) * run.values(0) + run.values(1) * run.values(1);
    }
    checkpoint.set_drms2_m(2.0 * std::sqrt(sum / n));
  }
}

v1::JobResult ToJobResult(const v1::Job& job_as_run, const MonteCarloStatistics& statistics,
                          const std::string& engine_version, double cpu_s) {
  const MonteCarloStatisticsData& data = statistics.data();
  if (data.cancelled) throw SpecError("result", "cancelled", "a job that ran to its end");
  if (data.runs.size() != 1) {
    throw SpecError("result.runs", fmt::format("{} separate run ranges", data.runs.size()),
                    "one contiguous range of runs");
  }
  v1::JobResult result;
  *result.mutable_job() = job_as_run;
  result.set_engine_version(engine_version);
  result.set_seed(data.seed);
  result.set_runs(data.job_runs);
  result.set_first_run(data.runs[0].first);
  result.set_run_count(data.runs[0].end - data.runs[0].first);

  const std::vector<EpochSummary> epochs = statistics.SummarizeEpochs();
  v1::MergeState* merge = result.mutable_merge_state();
  merge->set_encoding(kMergeEncoding);
  for (size_t e = 0; e < epochs.size(); ++e) {
    v1::EpochStatistics* out = result.add_epochs();
    out->set_t_s(epochs[e].t_s);
    v1::EpochSums* sums = merge->add_epochs();
    sums->set_t_s(epochs[e].t_s);
    for (int c = 0; c < kNumErrorComponents; ++c) {
      SetStatistics(epochs[e].components[c], c, out->add_components());
      v1::ComponentSums* component = sums->add_components();
      component->set_component(ProtoComponent(c));
      SetExactSum(data.epochs[e].sum[c], component->mutable_sum());
      SetExactSum(data.epochs[e].sum_squares[c], component->mutable_sum_of_squares());
    }
  }
  for (const CheckpointValues& in : data.checkpoints) {
    v1::Checkpoint* out = result.add_checkpoints();
    out->set_t_s(in.t_s);
    for (size_t r = 0; r < in.run_index.size(); ++r) {
      v1::RunValues* run = out->add_runs();
      run->set_run_index(in.run_index[r]);
      for (int c = 0; c < kNumErrorComponents; ++c) {
        run->add_values(ToResultUnit(c, in.values[r][c]));
      }
    }
  }
  FillCheckpointSummaries(&result);

  v1::Timings* timings = result.mutable_timings();
  timings->set_wall_s(data.timings.wall_s);
  if (cpu_s >= 0.0) timings->set_cpu_s(cpu_s);
  timings->set_samples(static_cast<uint64_t>(data.timings.samples_processed));
  timings->set_samples_per_s(data.timings.wall_s > 0.0
                                 ? static_cast<double>(data.timings.samples_processed) /
                                       data.timings.wall_s
                                 : 0.0);
  timings->set_threads(static_cast<uint32_t>(data.timings.threads));
  return result;
}

MonteCarloStatistics StatisticsFromJobResult(const v1::JobResult& result,
                                             const std::string& source) {
  const v1::MergeState& merge = result.merge_state();
  if (merge.encoding() != kMergeEncoding) {
    throw SpecError(
        source + ": merge_state.encoding", fmt::format("\"{}\"", merge.encoding()),
        fmt::format("\"{}\" (a result written by this driftlab's `run`)", kMergeEncoding));
  }
  if (merge.epochs_size() != result.epochs_size()) {
    throw SpecError(source + ": merge_state.epochs", fmt::format("{} entries", merge.epochs_size()),
                    fmt::format("one per epoch ({})", result.epochs_size()));
  }
  MonteCarloStatisticsData data;
  data.seed = result.seed();
  data.job_runs = result.runs();
  data.runs = {RunRange{result.first_run(), result.first_run() + result.run_count()}};
  for (int e = 0; e < merge.epochs_size(); ++e) {
    const v1::EpochSums& in = merge.epochs(e);
    const std::string field = fmt::format("{}: merge_state.epochs[{}]", source, e);
    if (in.t_s() != result.epochs(e).t_s() || in.components_size() != kNumErrorComponents) {
      throw SpecError(
          field, fmt::format("t_s {} with {} components", in.t_s(), in.components_size()),
          fmt::format("t_s {} with {} components", result.epochs(e).t_s(), kNumErrorComponents));
    }
    data.epoch_times_s.push_back(in.t_s());
    EpochSums sums;
    for (int c = 0; c < kNumErrorComponents; ++c) {
      sums.sum[c] = GetExactSum(in.components(c).sum(), field);
      sums.sum_squares[c] = GetExactSum(in.components(c).sum_of_squares(), field);
    }
    data.epochs.push_back(std::move(sums));
  }
  for (const v1::Checkpoint& in : result.checkpoints()) {
    CheckpointValues out;
    out.t_s = in.t_s();
    for (const v1::RunValues& run : in.runs()) {
      out.run_index.push_back(run.run_index());
      ErrorComponentValues values{};
      for (int c = 0; c < kNumErrorComponents && c < run.values_size(); ++c) {
        values[c] = IsAngle(c) ? run.values(c) * kDegToRad : run.values(c);
      }
      out.values.push_back(values);
    }
    data.checkpoints.push_back(std::move(out));
  }
  data.timings.wall_s = result.timings().wall_s();
  data.timings.samples_processed = static_cast<int64_t>(result.timings().samples());
  data.timings.threads = static_cast<int>(result.timings().threads());
  return MonteCarloStatistics(std::move(data), source);
}

v1::JobResult MergeJobResults(const std::vector<v1::JobResult>& shards,
                              const std::vector<std::string>& sources,
                              const std::string& engine_version) {
  if (shards.empty()) throw SpecError("SHARD", "none", "at least one result file");
  for (size_t i = 1; i < shards.size(); ++i) {
    if (!google::protobuf::util::MessageDifferencer::Equals(shards[i].job(), shards[0].job())) {
      throw SpecError(sources[i], "a result of a different job (its job echo differs)",
                      fmt::format("shards of the job in {}", sources[0]));
    }
  }
  MonteCarloStatistics merged = StatisticsFromJobResult(shards[0], sources[0]);
  for (size_t i = 1; i < shards.size(); ++i) {
    merged.Merge(StatisticsFromJobResult(shards[i], sources[i]));
  }
  v1::JobResult result = ToJobResult(shards[0].job(), merged, engine_version);
  // The per-run checkpoint values exactly as the shards hold them (the conversion to the engine
  // and back need not reproduce the bits of the angles), in run order.
  for (int k = 0; k < result.checkpoints_size(); ++k) {
    std::vector<const v1::RunValues*> runs;
    for (const v1::JobResult& shard : shards) {
      for (const v1::RunValues& run : shard.checkpoints(k).runs()) runs.push_back(&run);
    }
    std::sort(runs.begin(), runs.end(),
              [](const auto* a, const auto* b) { return a->run_index() < b->run_index(); });
    v1::Checkpoint* checkpoint = result.mutable_checkpoints(k);
    checkpoint->clear_runs();
    for (const v1::RunValues* run : runs) *checkpoint->add_runs() = *run;
  }
  FillCheckpointSummaries(&result);
  bool all_cpu = true;
  double cpu_s = 0.0;
  for (const v1::JobResult& shard : shards) {
    all_cpu = all_cpu && shard.timings().has_cpu_s();
    cpu_s += shard.timings().cpu_s();
  }
  if (all_cpu) result.mutable_timings()->set_cpu_s(cpu_s);
  return result;
}

}  // namespace driftlab::jobspec
