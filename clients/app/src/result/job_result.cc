#include "driftlab/app/job_result.h"

#include <fmt/format.h>
#include <google/protobuf/util/message_differencer.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "driftlab/app/result_check.h"
#include "driftlab/ins_gnss_filter.h"
#include "driftlab/spec_error.h"
#include "driftlab/units.h"

namespace driftlab::app {
namespace {

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
double ToResultUnit(int c, double value) { return (IsAngle(c) ? value * kRadToDeg : value) + 0.0; }

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

const char* FilterName(NavigationFilterKind filter) {
  switch (filter) {
    case NavigationFilterKind::kInsGnssEkf:
      return "INS_GNSS_EKF";
    case NavigationFilterKind::kComplementary:
      return "COMPLEMENTARY";
    case NavigationFilterKind::kNone:
      break;
  }
  return "NONE";
}

// Predicted sigma of the 11 components (mc_statistics.h order) in the result's units: N, E, D
// position and velocity sigma, roll/pitch/yaw sigma, then the RMS horizontal and 3-D position
// errors sqrt(P_NN + P_EE) and sqrt(P_NN + P_EE + P_DD).
void SetCovariance(const CovarianceAnalysisResult& analysis,
                   const std::vector<double>& epoch_times_s, v1::JobResult* result) {
  if (analysis.epochs.size() != epoch_times_s.size()) {
    throw SpecError("result.covariance", fmt::format("{} epochs", analysis.epochs.size()),
                    fmt::format("one per statistics epoch ({})", epoch_times_s.size()));
  }
  v1::CovarianceAnalysis* out = result->mutable_covariance();
  out->set_filter(FilterName(analysis.filter));
  out->set_step_samples(static_cast<uint32_t>(analysis.step_samples));
  for (const std::string& term : analysis.unrepresented) out->add_unrepresented(term);
  for (size_t e = 0; e < analysis.epochs.size(); ++e) {
    const CovarianceEpoch& in = analysis.epochs[e];
    v1::PredictedEpoch* epoch = out->add_epochs();
    epoch->set_t_s(epoch_times_s[e]);
    std::array<double, kNumErrorComponents> sigma{};
    for (int c = 0; c < 6; ++c) sigma[c] = in.sigma[c];
    for (int c = 0; c < 3; ++c) sigma[6 + c] = in.euler_sigma_rad[c];
    sigma[static_cast<int>(ErrorComponent::kHorizontalPosition)] = in.horizontal_sigma_m;
    sigma[static_cast<int>(ErrorComponent::kPosition3d)] =
        std::sqrt(std::max(0.0, in.P(0, 0) + in.P(1, 1) + in.P(2, 2)));
    for (int c = 0; c < kNumErrorComponents; ++c) epoch->add_sigma(ToResultUnit(c, sigma[c]));
  }
}

// filter_consistency from the NEES sums, and the sums into the merge state.
void SetConsistency(const FilterConsistencyData& data, const std::vector<double>& epoch_times_s,
                    v1::JobResult* result) {
  if (data.nees_sum.size() != epoch_times_s.size() ||
      data.nees_count.size() != epoch_times_s.size()) {
    throw SpecError("result.filter_consistency", fmt::format("{} epochs", data.nees_sum.size()),
                    fmt::format("one per statistics epoch ({})", epoch_times_s.size()));
  }
  v1::FilterConsistency* out = result->mutable_filter_consistency();
  out->set_state_dimension(FilterConsistencyData::kStateDimension);
  v1::MergeState* merge = result->mutable_merge_state();
  merge->clear_nees_sums();
  merge->clear_nees_counts();
  double sum_of_averages = 0.0;
  int averaged_epochs = 0;
  for (size_t e = 0; e < epoch_times_s.size(); ++e) {
    SetExactSum(data.nees_sum[e], merge->add_nees_sums());
    merge->add_nees_counts(data.nees_count[e]);
    v1::NeesEpoch* epoch = out->add_epochs();
    epoch->set_t_s(epoch_times_s[e]);
    const uint64_t n = data.nees_count[e];
    epoch->set_runs(n);
    if (n == 0) continue;
    const double average =
        static_cast<double>(data.nees_sum[e].Value() / static_cast<long double>(n));
    epoch->set_average_nees(average);
    double low = 0.0, high = 0.0;
    Chi2MeanBounds95(FilterConsistencyData::kStateDimension, static_cast<int>(n), &low, &high);
    epoch->set_chi2_95_low(low);  // chi2_0.025(9 n) / n
    epoch->set_chi2_95_high(high);
    sum_of_averages += average;
    ++averaged_epochs;
  }
  if (averaged_epochs > 0) out->set_mean_average_nees(sum_of_averages / averaged_epochs);
}

FilterConsistencyData ConsistencyFromJobResult(const v1::JobResult& result,
                                               const std::string& source) {
  const v1::MergeState& merge = result.merge_state();
  if (merge.nees_sums_size() != result.epochs_size() ||
      merge.nees_counts_size() != result.epochs_size()) {
    throw SpecError(
        source + ": merge_state.nees_sums",
        fmt::format("{} sums, {} counts", merge.nees_sums_size(), merge.nees_counts_size()),
        fmt::format("one of each per epoch ({})", result.epochs_size()));
  }
  FilterConsistencyData data;
  for (int e = 0; e < merge.nees_sums_size(); ++e) {
    data.nees_sum.push_back(
        GetExactSum(merge.nees_sums(e), fmt::format("{}: merge_state.nees_sums[{}]", source, e)));
    data.nees_count.push_back(merge.nees_counts(e));
  }
  return data;
}

}  // namespace

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
  CheckResultStatistics(result);
  return result;
}

v1::JobResult ToJobResult(const v1::Job& job_as_run, const MonteCarloOutput& output,
                          const std::string& engine_version, double cpu_s) {
  v1::JobResult result = ToJobResult(job_as_run, output.statistics, engine_version, cpu_s);
  const std::vector<double>& times = output.statistics.data().epoch_times_s;
  if (output.covariance) SetCovariance(*output.covariance, times, &result);
  if (output.consistency) SetConsistency(*output.consistency, times, &result);
  CheckResultStatistics(result);
  return result;
}

void CheckResultStatistics(const v1::JobResult& result) {
  const auto refuse = [](const std::string& path, double value, const std::string& allowed) {
    throw SpecError("result",
                    fmt::format("{}: {} is not allowed; allowed: {} (a result with a non-finite "
                                "statistic is neither written nor stored)",
                                path, value, allowed),
                    0);
  };
  const auto finite = [&refuse](const std::string& path, double value) {
    if (!std::isfinite(value)) refuse(path, value, "a finite number");
  };
  // Whatever parts the result holds: a shard's runs, or the epochs alone (result_check.cc
  // re-summarises a file's exact sums without its checkpoints). The sample sigma and its interval
  // are NaN by definition for one run (result.proto); never infinite.
  const bool single_run = result.run_count() == 1;
  for (int e = 0; e < result.epochs_size(); ++e) {
    for (int c = 0; c < result.epochs(e).components_size(); ++c) {
      const v1::ComponentStatistics& s = result.epochs(e).components(c);
      const std::string p = fmt::format("epochs[{}].components[{}].", e, c);
      finite(p + "mean", s.mean());
      finite(p + "rms", s.rms());
      finite(p + "rms_ci95_low", s.rms_ci95_low());
      finite(p + "rms_ci95_high", s.rms_ci95_high());
      for (const auto& [name, value] : {std::pair<const char*, double>{"std", s.std()},
                                        {"std_ci95_low", s.std_ci95_low()},
                                        {"std_ci95_high", s.std_ci95_high()}}) {
        if (single_run && std::isnan(value)) continue;
        finite(p + name, value);
      }
    }
  }
  for (int k = 0; k < result.checkpoints_size(); ++k) {
    const v1::Checkpoint& checkpoint = result.checkpoints(k);
    const std::string p = fmt::format("checkpoints[{}].", k);
    for (int c = 0; c < checkpoint.components_size(); ++c) {
      const v1::ComponentPercentiles& q = checkpoint.components(c);
      const std::string pc = fmt::format("{}components[{}].", p, c);
      finite(pc + "p50", q.p50());
      finite(pc + "p68", q.p68());
      finite(pc + "p95", q.p95());
      finite(pc + "p99", q.p99());
      finite(pc + "max_abs", q.max_abs());
    }
    finite(p + "cep50_m", checkpoint.cep50_m());
    finite(p + "cep95_m", checkpoint.cep95_m());
    finite(p + "drms2_m", checkpoint.drms2_m());
    for (int r = 0; r < checkpoint.runs_size(); ++r) {
      for (int c = 0; c < checkpoint.runs(r).values_size(); ++c) {
        finite(fmt::format("{}runs[{}].values[{}]", p, r, c), checkpoint.runs(r).values(c));
      }
    }
  }
  for (int e = 0; e < result.covariance().epochs_size(); ++e) {
    const v1::PredictedEpoch& epoch = result.covariance().epochs(e);
    for (int c = 0; c < epoch.sigma_size(); ++c) {
      if (!(std::isfinite(epoch.sigma(c)) && epoch.sigma(c) >= 0.0)) {
        refuse(fmt::format("covariance.epochs[{}].sigma[{}]", e, c), epoch.sigma(c),
               "a finite sigma >= 0");
      }
    }
  }
  const v1::FilterConsistency& nees = result.filter_consistency();
  for (int e = 0; e < nees.epochs_size(); ++e) {
    const v1::NeesEpoch& epoch = nees.epochs(e);
    const std::string path = fmt::format("filter_consistency.epochs[{}]", e);
    if (epoch.has_average_nees() && !std::isfinite(epoch.average_nees())) {
      refuse(path + ".average_nees", epoch.average_nees(), "a finite number");
    }
    if (epoch.has_chi2_95_low() && !std::isfinite(epoch.chi2_95_low())) {
      refuse(path + ".chi2_95_low", epoch.chi2_95_low(), "a finite number");
    }
    if (epoch.has_chi2_95_high() && !std::isfinite(epoch.chi2_95_high())) {
      refuse(path + ".chi2_95_high", epoch.chi2_95_high(), "a finite number");
    }
  }
  if (nees.has_mean_average_nees() && !std::isfinite(nees.mean_average_nees())) {
    refuse("filter_consistency.mean_average_nees", nees.mean_average_nees(), "a finite number");
  }
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

void SetFilterConsistencyFromSums(const v1::JobResult& result, const std::string& source,
                                  v1::JobResult* out) {
  std::vector<double> times;
  for (const v1::EpochStatistics& epoch : result.epochs()) times.push_back(epoch.t_s());
  SetConsistency(ConsistencyFromJobResult(result, source), times, out);
}

v1::JobResult MergeJobResults(const std::vector<v1::JobResult>& shards,
                              const std::vector<std::string>& sources,
                              const std::string& engine_version) {
  if (shards.empty()) throw SpecError("SHARD", "none", "at least one result file");
  // The merge adds the shards' exact sums: each shard's statistics must be what its sums and
  // per-run values give, or the merged result would silently differ from every shard.
  for (size_t i = 0; i < shards.size(); ++i) VerifyResultStatistics(shards[i], sources[i]);
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
  // The covariance analysis depends on the job only: every shard holds the same.
  if (shards[0].has_covariance()) *result.mutable_covariance() = shards[0].covariance();
  if (shards[0].has_filter_consistency()) {
    FilterConsistencyData nees = ConsistencyFromJobResult(shards[0], sources[0]);
    for (size_t i = 1; i < shards.size(); ++i) {
      nees.Merge(ConsistencyFromJobResult(shards[i], sources[i]));
    }
    SetConsistency(nees, merged.data().epoch_times_s, &result);
  }
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
  CheckResultStatistics(result);
  return result;
}

}  // namespace driftlab::app
