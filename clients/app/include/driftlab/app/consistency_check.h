// Is the filter (or the covariance analysis) honest about its uncertainty? A verdict from a result,
// so that a filter whose average NEES lies far outside its band does not pass unnoticed. Two
// checks, each a hypothesis test whose family-wise false-alarm rate is at most `alpha`
// (Bonferroni over the epochs or components tested, valid under any dependence between them):
//
// - NEES: at every epoch with runs, the N-run average NEES of a consistent d-state filter is
//   chi2(d N) / N (Bar-Shalom, Li & Kirubarajan, "Estimation with Applications to Tracking and
//   Navigation", 2001, section 5.4.2); an epoch is outside when its average leaves the two-sided
//   band at level alpha / K (K epochs tested).
// - Monte-Carlo / predicted sigma: at the final epoch, for each of the 9 position, velocity and
//   attitude components with a predicted sigma > 0, (N - 1) s^2 / sigma_p^2 is chi2(N - 1) when the
//   prediction is right (Gaussian errors); the ratio s / sigma_p gets its interval at confidence
//   1 - alpha / M (M components tested) and is flagged when the interval excludes 1.
//
// The verdict also lists the sensor and aiding terms that the prediction leaves out
// (covariance.unrepresented), the usual cause of an inconsistency.
#pragma once

#include <string>
#include <vector>

#include "driftlab/v1/result.pb.h"

namespace driftlab::app {

// Two-sided band [low, high] of the N-run average NEES of a consistent filter with
// `state_dimension` states, at false-alarm probability `alpha` (alpha / 2 on each side).
struct NeesBand {
  double low = 0;
  double high = 0;
};
NeesBand AverageNeesBand(int state_dimension, uint64_t runs, double alpha);

// Interval of sigma_true / sigma_predicted from a sample sigma `s` of `runs` runs, at confidence
// 1 - alpha (chi-square interval of a variance, e.g. NIST/SEMATECH e-Handbook 7.2.3.1).
struct RatioInterval {
  double ratio = 0;  // s / sigma_predicted
  double low = 0;
  double high = 0;
};
RatioInterval SigmaRatioInterval(double s, double sigma_predicted, uint64_t runs, double alpha);

struct ComponentConsistency {
  int component = 0;  // index in ErrorComponent order minus one (0 = north position)
  RatioInterval ratio;
  bool flagged = false;  // the interval excludes 1
};

struct ConsistencyVerdict {
  double alpha = 0.05;
  // NEES (a filter in the job).
  bool has_nees = false;
  int nees_epochs = 0;   // epochs tested
  int nees_above = 0;    // epochs above the Bonferroni band
  int nees_below = 0;    // epochs below it
  double worst_t_s = 0;  // the epoch farthest outside (or closest to an edge) in log ratio
  double worst_nees = 0;
  NeesBand worst_band;
  // Monte-Carlo / predicted sigma at the final epoch (a covariance analysis in the result).
  bool has_prediction = false;
  double final_t_s = 0;
  std::vector<ComponentConsistency> components;
  std::vector<std::string> unrepresented;

  bool tested() const { return has_nees || has_prediction; }
  bool consistent() const;
  // One line: "consistent (...)" or "INCONSISTENT: ..." naming the worst epoch and components.
  std::string Summary() const;
};

ConsistencyVerdict AssessConsistency(const v1::JobResult& result, double alpha = 0.05);

// Human name of error component index c (0 = "north position").
std::string ConsistencyComponentName(int c);

}  // namespace driftlab::app
