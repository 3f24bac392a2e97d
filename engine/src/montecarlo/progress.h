// Progress and cancellation of a Monte-Carlo job (Monitor), shared by its workers.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <mutex>

#include "driftlab/monte_carlo.h"
#include "montecarlo/internal.h"

namespace driftlab::mc_detail {

constexpr int64_t kProgressInterval_ns = 100'000'000;  // at most 10 progress calls per second

// Shared state of the workers: progress counters, cancellation, progress-callback throttling.
class Monitor {
 public:
  Monitor(const std::function<void(const MonteCarloProgress&)>& progress,
          const std::atomic<bool>* cancel, uint32_t runs_total, int64_t samples_total,
          Clock::time_point start)
      : progress_(progress),
        cancel_(cancel),
        runs_total_(runs_total),
        samples_total_(samples_total),
        start_(start) {}

  // Called by a run every kPollSamples samples; true = stop.
  bool Poll(int64_t samples) {
    samples_done_.fetch_add(samples, std::memory_order_relaxed);
    MaybeReport();
    return Stopped();
  }
  bool Stopped() {
    if (cancel_ != nullptr && cancel_->load(std::memory_order_relaxed)) {
      stopped_.store(true, std::memory_order_relaxed);
    }
    return stopped_.load(std::memory_order_relaxed);
  }
  void RunDone(int64_t samples) {
    samples_done_.fetch_add(samples, std::memory_order_relaxed);
    runs_done_.fetch_add(1, std::memory_order_relaxed);
  }
  int64_t samples_done() const { return samples_done_.load(); }
  void ReportFinal() {
    if (!progress_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    progress_(Snapshot());
  }

 private:
  MonteCarloProgress Snapshot() const {
    MonteCarloProgress p;
    p.runs_done = runs_done_.load(std::memory_order_relaxed);
    p.runs_total = runs_total_;
    p.samples_done = samples_done_.load(std::memory_order_relaxed);
    p.samples_total = samples_total_;
    p.elapsed_s = Seconds(start_);
    return p;
  }
  void MaybeReport() {
    if (!progress_) return;
    const int64_t now_ns =
        std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - start_).count();
    if (now_ns < next_report_ns_.load(std::memory_order_relaxed)) return;
    std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock() || now_ns < next_report_ns_.load(std::memory_order_relaxed)) return;
    next_report_ns_.store(now_ns + kProgressInterval_ns, std::memory_order_relaxed);
    progress_(Snapshot());
  }

  const std::function<void(const MonteCarloProgress&)>& progress_;
  const std::atomic<bool>* cancel_;
  const uint32_t runs_total_;
  const int64_t samples_total_;
  const Clock::time_point start_;
  std::atomic<int64_t> samples_done_{0};
  std::atomic<uint32_t> runs_done_{0};
  std::atomic<bool> stopped_{false};
  std::atomic<int64_t> next_report_ns_{0};
  std::mutex mutex_;
};

}  // namespace driftlab::mc_detail
