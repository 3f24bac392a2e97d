#include "driftlab/app/consistency_check.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "driftlab/allan.h"  // ChiSquareQuantile
#include "driftlab/elementary.h"

namespace driftlab::app {
namespace {

constexpr int kSigmaComponents = 9;  // position, velocity, attitude (ErrorComponent 1-9)

}  // namespace

std::string ConsistencyComponentName(int c) {
  static const char* const kNames[kSigmaComponents] = {
      "north position", "east position", "down position",
      "north velocity", "east velocity", "down velocity",
      "roll",           "pitch",         "yaw"};
  return c >= 0 && c < kSigmaComponents ? kNames[c] : "component " + std::to_string(c + 1);
}

NeesBand AverageNeesBand(int state_dimension, uint64_t runs, double alpha) {
  const double nu = static_cast<double>(state_dimension) * static_cast<double>(runs);
  const double n = static_cast<double>(runs);
  return NeesBand{ChiSquareQuantile(0.5 * alpha, nu) / n,
                  ChiSquareQuantile(1.0 - 0.5 * alpha, nu) / n};
}

RatioInterval SigmaRatioInterval(double s, double sigma_predicted, uint64_t runs, double alpha) {
  // (N - 1) s^2 / sigma^2 ~ chi2(N - 1): sigma in [s sqrt((N-1)/chi2_{1-a/2}), s
  // sqrt((N-1)/chi2_{a/2})].
  const double dof = static_cast<double>(runs) - 1.0;
  RatioInterval r;
  r.ratio = s / sigma_predicted;
  r.low = r.ratio * std::sqrt(dof / ChiSquareQuantile(1.0 - 0.5 * alpha, dof));
  r.high = r.ratio * std::sqrt(dof / ChiSquareQuantile(0.5 * alpha, dof));
  return r;
}

bool ConsistencyVerdict::consistent() const {
  if (nees_above > 0 || nees_below > 0) return false;
  return std::none_of(components.begin(), components.end(),
                      [](const ComponentConsistency& c) { return c.flagged; });
}

std::string ConsistencyVerdict::Summary() const {
  if (!tested()) return "not tested (no filter and no covariance analysis in the result)";
  std::vector<std::string> parts;
  if (has_nees) {
    parts.push_back(fmt::format(
        "average NEES outside its band at {} of {} epochs ({} above, {} below; at t = {:g} s: "
        "{:.3g} against [{:.3g}, {:.3g}])",
        nees_above + nees_below, nees_epochs, nees_above, nees_below, worst_t_s, worst_nees,
        worst_band.low, worst_band.high));
  }
  if (has_prediction) {
    std::vector<std::string> flagged;
    for (const ComponentConsistency& c : components) {
      if (c.flagged) {
        flagged.push_back(fmt::format("{} {:.3g} [{:.3g}, {:.3g}]",
                                      ConsistencyComponentName(c.component), c.ratio.ratio,
                                      c.ratio.low, c.ratio.high));
      }
    }
    parts.push_back(
        flagged.empty()
            ? fmt::format("Monte-Carlo/predicted sigma consistent with 1 for all {} components at "
                          "t = {:g} s",
                          components.size(), final_t_s)
            : fmt::format("Monte-Carlo/predicted sigma at t = {:g} s: {}", final_t_s,
                          fmt::join(flagged, ", ")));
  }
  std::string text = consistent() ? "consistent" : "INCONSISTENT";
  text += fmt::format(" at family-wise level {:g}: {}", alpha, fmt::join(parts, "; "));
  if (!consistent() && !unrepresented.empty()) {
    text += fmt::format("; terms of the job's model the filter and prediction leave out: {}",
                        fmt::join(unrepresented, ", "));
  }
  return text;
}

ConsistencyVerdict AssessConsistency(const v1::JobResult& result, double alpha) {
  ConsistencyVerdict v;
  v.alpha = alpha;
  if (result.has_filter_consistency()) {
    const v1::FilterConsistency& fc = result.filter_consistency();
    int tested = 0;
    for (const v1::NeesEpoch& e : fc.epochs()) tested += e.runs() > 0 ? 1 : 0;
    if (tested > 0 && fc.state_dimension() > 0) {
      v.has_nees = true;
      v.nees_epochs = tested;
      double worst = -1.0;
      for (const v1::NeesEpoch& e : fc.epochs()) {
        if (e.runs() == 0) continue;
        const NeesBand band =
            AverageNeesBand(static_cast<int>(fc.state_dimension()), e.runs(), alpha / tested);
        const double nees = e.average_nees();
        if (nees > band.high) ++v.nees_above;
        if (nees < band.low) ++v.nees_below;
        // Distance from the band's geometric centre in log ratio: the epoch farthest from it.
        const double distance = std::abs(math::Log(nees / std::sqrt(band.low * band.high)));
        if (std::isfinite(distance) && distance > worst) {
          worst = distance;
          v.worst_t_s = e.t_s();
          v.worst_nees = nees;
          v.worst_band = band;
        }
      }
    }
  }
  if (result.has_covariance() && result.covariance().epochs_size() == result.epochs_size() &&
      result.epochs_size() > 0 && result.run_count() >= 2) {
    const v1::PredictedEpoch& predicted = *result.covariance().epochs().rbegin();
    const v1::EpochStatistics& final_epoch = *result.epochs().rbegin();
    std::vector<int> tested;
    for (int c = 0;
         c < kSigmaComponents && c < predicted.sigma_size() && c < final_epoch.components_size();
         ++c) {
      const double sigma_p = predicted.sigma(c);
      const double s = final_epoch.components(c).std();
      if (sigma_p > 0.0 && std::isfinite(sigma_p) && std::isfinite(s)) tested.push_back(c);
    }
    if (!tested.empty()) {
      v.has_prediction = true;
      v.final_t_s = final_epoch.t_s();
      const double per_component = alpha / static_cast<double>(tested.size());
      for (const int c : tested) {
        ComponentConsistency cc;
        cc.component = c;
        cc.ratio = SigmaRatioInterval(final_epoch.components(c).std(), predicted.sigma(c),
                                      result.run_count(), per_component);
        cc.flagged = cc.ratio.low > 1.0 || cc.ratio.high < 1.0;
        v.components.push_back(cc);
      }
    }
  }
  if (result.has_covariance()) {
    v.unrepresented.assign(result.covariance().unrepresented().begin(),
                           result.covariance().unrepresented().end());
  }
  return v;
}

}  // namespace driftlab::app
