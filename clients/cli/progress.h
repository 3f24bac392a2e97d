// Progress of a Monte-Carlo job on stderr, shared by the in-process `driftlab run` and the remote
// commands (`run --server`, `watch`), which feed it from the engine's progress callback and from
// the server's Watch stream respectively: a bar redrawn in place when stderr is a terminal,
// otherwise a plain line at every 10 % of the runs.
#pragma once

#include <fmt/format.h>
#include <unistd.h>

#include <cstdio>
#include <string>

#include "driftlab/monte_carlo.h"

namespace driftlab::cli {

class ProgressPrinter {
 public:
  ProgressPrinter() : terminal_(isatty(STDERR_FILENO) == 1) {}

  void Update(const MonteCarloProgress& p) {
    if (p.runs_total == 0) return;
    const double fraction = static_cast<double>(p.runs_done) / p.runs_total;
    const double rate = p.elapsed_s > 0 ? p.samples_done / p.elapsed_s : 0.0;
    if (terminal_) {
      constexpr int kWidth = 30;
      const int filled = static_cast<int>(fraction * kWidth);
      const double eta_s =
          rate > 0 ? static_cast<double>(p.samples_total - p.samples_done) / rate : 0.0;
      fmt::print(stderr, "\r[{:<{}}] {:3.0f}% {}/{} runs  {:.2f} M samples/s  ETA {:.0f} s ",
                 std::string(filled, '#'), kWidth, 100 * fraction, p.runs_done, p.runs_total,
                 rate / 1e6, eta_s);
      drawn_ = true;
    } else {
      const int decile = static_cast<int>(fraction * 10);
      if (decile > last_decile_) {
        last_decile_ = decile;
        fmt::print(stderr, "progress: {:3d}% ({}/{} runs, {:.1f} s, {:.2f} M samples/s)\n",
                   decile * 10, p.runs_done, p.runs_total, p.elapsed_s, rate / 1e6);
      }
    }
  }
  void Finish() {
    if (drawn_) fmt::print(stderr, "\n");
    drawn_ = false;
  }

 private:
  bool terminal_;
  bool drawn_ = false;
  int last_decile_ = 0;
};

}  // namespace driftlab::cli
