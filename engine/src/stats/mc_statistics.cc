// Monte-Carlo error statistics (see mc_statistics.h for the definitions).
#include "driftlab/mc_statistics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "driftlab/allan.h"
#include "driftlab/spec_error.h"
#include "stats/nav_error_lanes.h"

namespace driftlab {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string RangesText(const std::vector<RunRange>& runs) {
  std::string s;
  for (const RunRange& r : runs) {
    if (!s.empty()) s += ", ";
    s += "[" + std::to_string(r.first) + ", " + std::to_string(r.end) + ")";
  }
  return s.empty() ? "none" : s;
}

// Joins adjacent ranges of an ascending, disjoint list.
std::vector<RunRange> Coalesce(const std::vector<RunRange>& sorted) {
  std::vector<RunRange> out;
  for (const RunRange& r : sorted) {
    if (!out.empty() && out.back().end == r.first) {
      out.back().end = r.end;
    } else {
      out.push_back(r);
    }
  }
  return out;
}

}  // namespace

std::string_view ErrorComponentName(ErrorComponent component) {
  switch (component) {
    case ErrorComponent::kPositionNorth:
      return "position_north_m";
    case ErrorComponent::kPositionEast:
      return "position_east_m";
    case ErrorComponent::kPositionDown:
      return "position_down_m";
    case ErrorComponent::kVelocityNorth:
      return "velocity_north_m_per_s";
    case ErrorComponent::kVelocityEast:
      return "velocity_east_m_per_s";
    case ErrorComponent::kVelocityDown:
      return "velocity_down_m_per_s";
    case ErrorComponent::kRoll:
      return "roll_rad";
    case ErrorComponent::kPitch:
      return "pitch_rad";
    case ErrorComponent::kYaw:
      return "yaw_rad";
    case ErrorComponent::kHorizontalPosition:
      return "horizontal_position_m";
    case ErrorComponent::kPosition3d:
      return "position_3d_m";
  }
  return "unknown";
}

static_assert(nav_error_lanes::kComponents == kNumErrorComponents);

ErrorComponentValues ErrorComponentsOf(const NavError& error) {
  ErrorComponentValues v;
  v[0] = error.r_ned_m.x();
  v[1] = error.r_ned_m.y();
  v[2] = error.r_ned_m.z();
  v[3] = error.v_ned_m_per_s.x();
  v[4] = error.v_ned_m_per_s.y();
  v[5] = error.v_ned_m_per_s.z();
  v[6] = error.euler_rad.x();
  v[7] = error.euler_rad.y();
  v[8] = error.euler_rad.z();
  // As the lockstep kernels at one lane (nav_error_lanes.h).
  v[9] = nav_error_lanes::Horizontal<1>(error.r_ned_m.x(), error.r_ned_m.y());
  v[10] = nav_error_lanes::Norm3<1>(error.r_ned_m.x(), error.r_ned_m.y(), error.r_ned_m.z());
  return v;
}

double SortedPercentile(const std::vector<double>& ascending, double p) {
  if (ascending.empty()) return kNaN;
  const double h = static_cast<double>(ascending.size() - 1) * p;
  const size_t lo = static_cast<size_t>(std::floor(h));
  if (lo + 1 >= ascending.size()) return ascending.back();
  const double frac = h - static_cast<double>(lo);
  return ascending[lo] + frac * (ascending[lo + 1] - ascending[lo]);
}

MonteCarloStatistics::MonteCarloStatistics(MonteCarloStatisticsData data, const std::string& field)
    : data_(std::move(data)) {
  const MonteCarloStatisticsData& d = data_;
  if (d.cancelled) return;
  uint64_t count = 0;
  for (size_t i = 0; i < d.runs.size(); ++i) {
    const RunRange& r = d.runs[i];
    const bool ordered =
        r.first < r.end && r.end <= d.job_runs && (i == 0 || d.runs[i - 1].end <= r.first);
    if (!ordered) {
      throw SpecError(IndexedField(field + ".runs", i),
                      "[" + std::to_string(r.first) + ", " + std::to_string(r.end) + ")",
                      "non-empty ranges, ascending and disjoint, within [0, " +
                          std::to_string(d.job_runs) + ")");
    }
    count += r.end - r.first;
  }
  data_.runs = Coalesce(d.runs);
  for (size_t i = 0; i < d.epoch_times_s.size(); ++i) {
    if (!std::isfinite(d.epoch_times_s[i]) ||
        (i > 0 && d.epoch_times_s[i] <= d.epoch_times_s[i - 1])) {
      throw SpecError(IndexedField(field + ".epoch_times_s", i), std::to_string(d.epoch_times_s[i]),
                      "finite and strictly ascending times [s]");
    }
  }
  if (d.epochs.size() != d.epoch_times_s.size()) {
    throw SpecError(field + ".epochs", std::to_string(d.epochs.size()) + " epochs",
                    "one per epoch time (" + std::to_string(d.epoch_times_s.size()) + ")");
  }
  for (size_t c = 0; c < d.checkpoints.size(); ++c) {
    const CheckpointValues& cp = d.checkpoints[c];
    const std::string path = IndexedField(field + ".checkpoints", c);
    if (!std::isfinite(cp.t_s) || (c > 0 && cp.t_s <= d.checkpoints[c - 1].t_s)) {
      throw SpecError(path + ".t_s", std::to_string(cp.t_s), "finite and strictly ascending [s]");
    }
    if (cp.run_index.size() != count || cp.values.size() != count) {
      throw SpecError(path + ".run_index", std::to_string(cp.run_index.size()) + " runs",
                      "one value per included run (" + std::to_string(count) + ")");
    }
    // The run indices must be exactly those of the ranges, ascending.
    size_t k = 0;
    for (const RunRange& r : data_.runs) {
      for (uint32_t run = r.first; run < r.end; ++run, ++k) {
        if (cp.run_index[k] != run) {
          throw SpecError(
              IndexedField(path + ".run_index", k), std::to_string(cp.run_index[k]),
              std::to_string(run) + " (the runs " + RangesText(data_.runs) + ", ascending)");
        }
      }
    }
  }
}

uint64_t MonteCarloStatistics::run_count() const {
  uint64_t n = 0;
  for (const RunRange& r : data_.runs) n += r.end - r.first;
  return n;
}

void MonteCarloStatistics::Merge(const MonteCarloStatistics& other) {
  const MonteCarloStatisticsData& o = other.data_;
  MonteCarloStatisticsData& d = data_;
  if (d.cancelled || o.cancelled) {
    throw SpecError("statistics.cancelled", "true", "false (a cancelled job has no statistics)");
  }
  if (o.seed != d.seed) {
    throw SpecError("statistics.seed", std::to_string(o.seed),
                    std::to_string(d.seed) + " (shards of one job share the seed)");
  }
  if (o.job_runs != d.job_runs) {
    throw SpecError("statistics.job_runs", std::to_string(o.job_runs),
                    std::to_string(d.job_runs) + " (shards of one job share the run count)");
  }
  if (o.epoch_times_s != d.epoch_times_s) {
    throw SpecError("statistics.epoch_times_s", std::to_string(o.epoch_times_s.size()) + " epochs",
                    "the same epoch times in every shard (" +
                        std::to_string(d.epoch_times_s.size()) + " epochs)");
  }
  if (o.checkpoints.size() != d.checkpoints.size()) {
    throw SpecError(
        "statistics.checkpoints", std::to_string(o.checkpoints.size()) + " checkpoints",
        "the same checkpoints in every shard (" + std::to_string(d.checkpoints.size()) + ")");
  }
  for (size_t c = 0; c < d.checkpoints.size(); ++c) {
    if (o.checkpoints[c].t_s != d.checkpoints[c].t_s) {
      throw SpecError(IndexedField("statistics.checkpoints", c) + ".t_s",
                      std::to_string(o.checkpoints[c].t_s),
                      std::to_string(d.checkpoints[c].t_s) + " (same checkpoints in every shard)");
    }
  }
  // Runs must be disjoint.
  std::vector<RunRange> all = d.runs;
  all.insert(all.end(), o.runs.begin(), o.runs.end());
  std::sort(all.begin(), all.end(),
            [](const RunRange& a, const RunRange& b) { return a.first < b.first; });
  for (size_t i = 1; i < all.size(); ++i) {
    if (all[i].first < all[i - 1].end) {
      throw SpecError("statistics.runs", RangesText(o.runs),
                      "runs disjoint from those already merged (" + RangesText(d.runs) + ")");
    }
  }
  d.runs = Coalesce(all);

  for (size_t e = 0; e < d.epochs.size(); ++e) {
    for (int c = 0; c < kNumErrorComponents; ++c) {
      d.epochs[e].sum[c].Merge(o.epochs[e].sum[c]);
      d.epochs[e].sum_squares[c].Merge(o.epochs[e].sum_squares[c]);
    }
  }
  for (size_t c = 0; c < d.checkpoints.size(); ++c) {
    CheckpointValues& mine = d.checkpoints[c];
    const CheckpointValues& theirs = o.checkpoints[c];
    CheckpointValues merged;
    merged.t_s = mine.t_s;
    merged.run_index.reserve(mine.run_index.size() + theirs.run_index.size());
    merged.values.reserve(merged.run_index.capacity());
    size_t i = 0, j = 0;
    while (i < mine.run_index.size() || j < theirs.run_index.size()) {
      const bool take_mine = j == theirs.run_index.size() ||
                             (i < mine.run_index.size() && mine.run_index[i] < theirs.run_index[j]);
      if (take_mine) {
        merged.run_index.push_back(mine.run_index[i]);
        merged.values.push_back(mine.values[i++]);
      } else {
        merged.run_index.push_back(theirs.run_index[j]);
        merged.values.push_back(theirs.values[j++]);
      }
    }
    mine = std::move(merged);
  }
  d.timings.wall_s += o.timings.wall_s;
  d.timings.truth_s += o.timings.truth_s;
  // Sample counts come from result files too (merge): a hand-edited count must not overflow the
  // signed sum (undefined behaviour).
  if (d.timings.samples_processed < 0 || o.timings.samples_processed < 0 ||
      __builtin_add_overflow(d.timings.samples_processed, o.timings.samples_processed,
                             &d.timings.samples_processed)) {
    throw SpecError(
        "timings.samples",
        std::to_string(d.timings.samples_processed) + " + " +
            std::to_string(o.timings.samples_processed),
        "counts whose sum is at most " + std::to_string(std::numeric_limits<int64_t>::max()));
  }
  d.timings.threads = std::max(d.timings.threads, o.timings.threads);
}

EpochSummary MonteCarloStatistics::SummarizeEpoch(size_t epoch) const {
  EpochSummary out;
  out.t_s = data_.epoch_times_s.at(epoch);
  const uint64_t n_runs = run_count();
  out.runs = n_runs;
  if (n_runs == 0) {
    for (auto& c : out.components) c = {kNaN, kNaN, kNaN, kNaN, kNaN, kNaN, kNaN};
    return out;
  }
  const long double n = static_cast<long double>(n_runs);
  const double nd = static_cast<double>(n_runs);
  // chi-square quantiles for the 95 % intervals (same for every component).
  const double rms_lo_q = ChiSquareQuantile(0.975, nd);
  const double rms_hi_q = ChiSquareQuantile(0.025, nd);
  const double std_lo_q = n_runs > 1 ? ChiSquareQuantile(0.975, nd - 1.0) : kNaN;
  const double std_hi_q = n_runs > 1 ? ChiSquareQuantile(0.025, nd - 1.0) : kNaN;
  const EpochSums& sums = data_.epochs.at(epoch);
  for (int c = 0; c < kNumErrorComponents; ++c) {
    const long double s1 = sums.sum[c].Value();
    const long double s2 = sums.sum_squares[c].Value();
    ComponentEpochSummary& r = out.components[c];
    r.mean = static_cast<double>(s1 / n);
    r.rms = static_cast<double>(std::sqrt(s2 / n));
    r.rms_ci95_low = r.rms * std::sqrt(nd / rms_lo_q);
    r.rms_ci95_high = r.rms * std::sqrt(nd / rms_hi_q);
    if (n_runs > 1) {
      // (S2 - S1^2 / N) / (N - 1); clamp the rounding residue of a zero variance at 0.
      const long double var = std::max((s2 - s1 * s1 / n) / (n - 1.0L), 0.0L);
      r.std = static_cast<double>(std::sqrt(var));
      r.std_ci95_low = r.std * std::sqrt((nd - 1.0) / std_lo_q);
      r.std_ci95_high = r.std * std::sqrt((nd - 1.0) / std_hi_q);
    } else {
      r.std = r.std_ci95_low = r.std_ci95_high = kNaN;
    }
  }
  return out;
}

std::vector<EpochSummary> MonteCarloStatistics::SummarizeEpochs() const {
  std::vector<EpochSummary> out;
  out.reserve(num_epochs());
  for (size_t e = 0; e < num_epochs(); ++e) out.push_back(SummarizeEpoch(e));
  return out;
}

CheckpointSummary MonteCarloStatistics::SummarizeCheckpoint(size_t checkpoint) const {
  const CheckpointValues& cp = data_.checkpoints.at(checkpoint);
  CheckpointSummary out;
  out.t_s = cp.t_s;
  out.runs = cp.values.size();
  std::vector<double> abs_values(cp.values.size());
  for (int c = 0; c < kNumErrorComponents; ++c) {
    for (size_t i = 0; i < cp.values.size(); ++i) abs_values[i] = std::abs(cp.values[i][c]);
    std::sort(abs_values.begin(), abs_values.end());
    ComponentDistribution& dist = out.abs[c];
    dist.p50 = SortedPercentile(abs_values, 0.50);
    dist.p68 = SortedPercentile(abs_values, 0.68);
    dist.p95 = SortedPercentile(abs_values, 0.95);
    dist.p99 = SortedPercentile(abs_values, 0.99);
    dist.max = abs_values.empty() ? kNaN : abs_values.back();
  }
  const int h = static_cast<int>(ErrorComponent::kHorizontalPosition);
  out.cep50_m = out.abs[h].p50;
  out.cep95_m = out.abs[h].p95;
  // Summed in run-index order (the stored order), so the result is the same for any split.
  long double sum_sq = 0.0L;
  for (const ErrorComponentValues& v : cp.values) {
    sum_sq += static_cast<long double>(v[0]) * v[0] + static_cast<long double>(v[1]) * v[1];
  }
  out.drms2_m =
      cp.values.empty() ? kNaN : static_cast<double>(2.0L * std::sqrt(sum_sq / cp.values.size()));
  return out;
}

}  // namespace driftlab
