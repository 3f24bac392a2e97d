// Reduction of a Monte-Carlo job: the per-thread sums merged into the job's, and the merge of
// FilterConsistencyData across shards.
#include <string>

#include "driftlab/spec_error.h"
#include "montecarlo/internal.h"

namespace driftlab {
namespace mc_detail {

std::vector<EpochSums> MergeEpochSums(
    const tbb::enumerable_thread_specific<EpochAccumulator>& accumulators, size_t n_epochs) {
  std::vector<EpochSums> epochs(n_epochs);
  for (const EpochAccumulator& local : accumulators) {
    for (size_t e = 0; e < n_epochs; ++e) {
      for (int c = 0; c < kNumErrorComponents; ++c) {
        epochs[e].sum[c].Merge(local[e].sum[c]);
        epochs[e].sum_squares[c].Merge(local[e].sum_squares[c]);
      }
    }
  }
  return epochs;
}

FilterConsistencyData MergeNees(
    const tbb::enumerable_thread_specific<NeesAccumulator>& accumulators, size_t n_epochs) {
  FilterConsistencyData consistency;
  consistency.nees_sum.resize(n_epochs);
  consistency.nees_count.assign(n_epochs, 0);
  for (const NeesAccumulator& local : accumulators) {
    for (size_t e = 0; e < n_epochs; ++e) {
      consistency.nees_sum[e].Merge(local.sum[e]);
      consistency.nees_count[e] += local.count[e];
    }
  }
  return consistency;
}

}  // namespace mc_detail

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

}  // namespace driftlab
