#include "driftlab/app/result_check.h"

#include <fmt/format.h>

#include <cmath>
#include <vector>

#include "driftlab/app/job_result.h"
#include "driftlab/app/result_file.h"
#include "driftlab/spec_error.h"

namespace driftlab::app {
namespace {

// a and b agree: both NaN, equal (infinities too), or within kResultCheckRelTol of the larger, or
// within kResultCheckRelTol of `scale` (a mean near 0 against the spread of the values).
bool Agree(double a, double b, double scale = 0.0) {
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b);
  if (a == b) return true;
  const double tol = kResultCheckRelTol * std::max({std::abs(a), std::abs(b), std::abs(scale)});
  return std::isfinite(tol) && std::abs(a - b) <= tol;
}

void Expect(double value, double expected, const std::string& source, const std::string& field,
            const std::string& data, double scale = 0.0) {
  if (Agree(value, expected, scale)) return;
  throw SpecError(source + ": " + field, fmt::format("{}", value),
                  fmt::format("{} (what its {} give: a result's statistics must agree with the "
                              "data they summarise)",
                              expected, data));
}

void CheckEpochsAgainstSums(const v1::JobResult& result, const std::string& source) {
  // The engine's summary of the sums, written as `run` and `merge` write it.
  v1::JobResult epochs_only = result;
  epochs_only.clear_checkpoints();
  const MonteCarloStatistics statistics = StatisticsFromJobResult(epochs_only, source);
  const v1::JobResult expected = ToJobResult(result.job(), statistics, "");
  for (int e = 0; e < result.epochs_size(); ++e) {
    const std::string data = fmt::format("exact sums merge_state.epochs[{}]", e);
    for (int c = 0; c < result.epochs(e).components_size(); ++c) {
      const v1::ComponentStatistics& in = result.epochs(e).components(c);
      const v1::ComponentStatistics& want = expected.epochs(e).components(c);
      const std::string p = fmt::format("epochs[{}].components[{}].", e, c);
      Expect(in.mean(), want.mean(), source, p + "mean", data, want.rms());
      Expect(in.std(), want.std(), source, p + "std", data);
      Expect(in.rms(), want.rms(), source, p + "rms", data);
      Expect(in.std_ci95_low(), want.std_ci95_low(), source, p + "std_ci95_low", data);
      Expect(in.std_ci95_high(), want.std_ci95_high(), source, p + "std_ci95_high", data);
      Expect(in.rms_ci95_low(), want.rms_ci95_low(), source, p + "rms_ci95_low", data);
      Expect(in.rms_ci95_high(), want.rms_ci95_high(), source, p + "rms_ci95_high", data);
    }
  }
}

void CheckCheckpointsAgainstRuns(const v1::JobResult& result, const std::string& source) {
  v1::JobResult expected = result;
  FillCheckpointSummaries(&expected);
  for (int k = 0; k < result.checkpoints_size(); ++k) {
    const v1::Checkpoint& in = result.checkpoints(k);
    const int n = in.runs_size();
    if (n == 0) continue;
    const v1::Checkpoint& want = expected.checkpoints(k);
    const std::string data = fmt::format("per-run values checkpoints[{}].runs", k);
    const std::string p = fmt::format("checkpoints[{}].", k);
    for (int c = 0; c < in.components_size(); ++c) {
      const v1::ComponentPercentiles& a = in.components(c);
      const v1::ComponentPercentiles& b = want.components(c);
      const std::string q = fmt::format("{}components[{}].", p, c);
      Expect(a.p50(), b.p50(), source, q + "p50", data);
      Expect(a.p68(), b.p68(), source, q + "p68", data);
      Expect(a.p95(), b.p95(), source, q + "p95", data);
      Expect(a.p99(), b.p99(), source, q + "p99", data);
      Expect(a.max_abs(), b.max_abs(), source, q + "max_abs", data);
    }
    Expect(in.cep50_m(), want.cep50_m(), source, p + "cep50_m", data);
    Expect(in.cep95_m(), want.cep95_m(), source, p + "cep95_m", data);
    Expect(in.drms2_m(), want.drms2_m(), source, p + "drms2_m", data);

    // The epoch at the same time: its moments are those of these values.
    for (int e = 0; e < result.epochs_size(); ++e) {
      if (result.epochs(e).t_s() != in.t_s()) continue;
      for (int c = 0; c < result.epochs(e).components_size(); ++c) {
        double sum = 0, sum_squares = 0;
        for (const v1::RunValues& run : in.runs()) {
          sum += run.values(c);
          sum_squares += run.values(c) * run.values(c);
        }
        const double mean = sum / n;
        double ss = 0;  // two-pass variance
        for (const v1::RunValues& run : in.runs()) {
          ss += (run.values(c) - mean) * (run.values(c) - mean);
        }
        const double rms = std::sqrt(sum_squares / n);
        const double std = n > 1 ? std::sqrt(ss / (n - 1)) : std::nan("");
        const v1::ComponentStatistics& s = result.epochs(e).components(c);
        const std::string f = fmt::format("epochs[{}].components[{}].", e, c);
        Expect(s.mean(), mean, source, f + "mean", data, rms);
        Expect(s.std(), std, source, f + "std", data, rms);
        Expect(s.rms(), rms, source, f + "rms", data);
      }
    }
  }
}

void CheckNees(const v1::JobResult& result, const std::string& source) {
  const v1::FilterConsistency& consistency = result.filter_consistency();
  const v1::MergeState& merge = result.merge_state();
  if (consistency.epochs().empty() || merge.nees_sums().empty()) return;
  if (merge.nees_sums_size() != consistency.epochs_size() ||
      merge.nees_counts_size() != consistency.epochs_size()) {
    throw SpecError(
        source + ": merge_state.nees_sums",
        fmt::format("{} sums, {} counts", merge.nees_sums_size(), merge.nees_counts_size()),
        fmt::format("one of each per filter_consistency epoch ({})", consistency.epochs_size()));
  }
  v1::JobResult expected;
  SetFilterConsistencyFromSums(result, source, &expected);
  for (int e = 0; e < consistency.epochs_size(); ++e) {
    const v1::NeesEpoch& in = consistency.epochs(e);
    const v1::NeesEpoch& want = expected.filter_consistency().epochs(e);
    const std::string p = fmt::format("filter_consistency.epochs[{}].", e);
    const std::string data = fmt::format("NEES sums merge_state.nees_sums[{}]", e);
    if (in.runs() != want.runs()) {
      throw SpecError(source + ": " + p + "runs", std::to_string(in.runs()),
                      fmt::format("{} (merge_state.nees_counts[{}])", want.runs(), e));
    }
    if (want.runs() == 0) continue;
    Expect(in.average_nees(), want.average_nees(), source, p + "average_nees", data);
  }
}

}  // namespace

void VerifyResultStatistics(const v1::JobResult& result, const std::string& source) {
  if (!result.merge_state().epochs().empty()) CheckEpochsAgainstSums(result, source);
  CheckCheckpointsAgainstRuns(result, source);
  CheckNees(result, source);
}

}  // namespace driftlab::app
