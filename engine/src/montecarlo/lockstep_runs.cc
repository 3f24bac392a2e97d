// The free-NED runs of a Monte-Carlo job in lockstep groups (lockstep_ned.h): the same samples,
// polls and reports as RunNed (montecarlo/runs.cc) for each run, and the same bits.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <memory>

#include "lockstep/lockstep_ned.h"
#include "montecarlo/internal.h"
#include "montecarlo/progress.h"

namespace driftlab::mc_detail {

namespace {

// Runs the runs of slots [slot_begin, slot_end) (at most kernel.width) with mechanization A in
// lockstep (lockstep_ned.h): the same samples, polls and reports as RunNed for each run, and the
// same bits. Returns false if stopped early.
bool RunNedGroup(const SharedTruth& s, const MonteCarloSpec& spec, const lockstep::LockstepJob& job,
                 const lockstep::Kernel& kernel, uint32_t slot_begin, uint32_t slot_end,
                 bool gyrocompass, RunSink sink, Monitor* monitor, lockstep::LockstepGroup* group,
                 lockstep::GroupStreams* streams, const TruthStream* truth) {
  using lockstep::kBlock;
  const int lanes = static_cast<int>(slot_end - slot_begin);
  group->lanes = lanes;
  for (int lane = 0; lane < lanes; ++lane) {
    lockstep::StartSensorLane(job, spec.first_run + slot_begin + static_cast<uint32_t>(lane), lane,
                              group, streams);
    for (int i = 0; i < 3; ++i) {
      group->nav.sum_dtheta[i][lane] = 0.0;
      group->nav.sum_dv[i][lane] = 0.0;
    }
  }
  lockstep::KernelInputs in;
  in.increments = s.increments.empty() ? nullptr : &s.increments[0].delta_theta_ib_b[0];
  if (job.kernel.truth_height) {
    in.h_m = s.h_m.data();
    in.v_D_m_per_s = s.v_D_m_per_s.data();
  }
  size_t next = 0;
  const size_t n_reports = s.reports.size();
  // The errors of all lanes at once (the kernel's nav_error_lanes::ErrorComponents: the
  // operations of ErrorComponentsOf(ComputeNavError(...)) in RunNed), then each run's sums.
  auto record = [&](const Report& r) {
    // The truth's share once for the group's lanes.
    const nav_error_lanes::TruthTerms terms = lockstep::ErrorTruthTerms(s.env, r.truth);
    double errors[kNumErrorComponents][lockstep::kMaxLanes];
    kernel.errors(terms, group->nav, errors);
    for (int lane = 0; lane < lanes; ++lane) {
      RunSink lane_sink = sink;
      lane_sink.slot = slot_begin + static_cast<uint32_t>(lane);
      ErrorComponentValues v;
      for (int c = 0; c < kNumErrorComponents; ++c) v[c] = errors[c][lane];
      lane_sink.Record(r, v);
    }
  };
  // Navigation starts at s0 from the alignment sums of k = 1..s0 (RunNed).
  auto start_navigation = [&] {
    const bool use_gyrocompass = truth != nullptr ? UseGyrocompass(spec, s) : gyrocompass;
    for (int lane = 0; lane < lanes; ++lane) {
      const uint32_t run = spec.first_run + slot_begin + static_cast<uint32_t>(lane);
      const lockstep::NavLanes& n = group->nav;
      const Eigen::Vector3d sum_dtheta(n.sum_dtheta[0][lane], n.sum_dtheta[1][lane],
                                       n.sum_dtheta[2][lane]);
      const Eigen::Vector3d sum_dv(n.sum_dv[0][lane], n.sum_dv[1][lane], n.sum_dv[2][lane]);
      lockstep::SetNavLane(NedStartState(s, spec, run, use_gyrocompass, sum_dtheta, sum_dv), lane,
                           group);
    }
    if (s.reports[0].k == s.start_step) {
      record(s.reports[0]);
      next = 1;
    }
  };
  if (truth != nullptr && !truth->WaitFor(0)) return false;
  if (s.start_step == 0) start_navigation();
  // Polls every poll_every samples, so that a poll covers about kPollSamples run-samples as in
  // RunNed (a power of two, a multiple of the deviate block).
  int64_t poll_every = kPollSamples;
  while (poll_every > kBlock && poll_every * lanes > kPollSamples) poll_every /= 2;
  int64_t polled = 0;
  int64_t k = 1;
  while (k <= s.n) {
    if ((k - 1) % kBlock == 0) lockstep::LoadBlock(job, kernel, k - 1, streams, group);
    // The segment [k, end): inside one deviate block, up to the next report, poll or s0.
    int64_t end = std::min<int64_t>((k - 1) / kBlock * kBlock + kBlock + 1, s.n + 1);
    end = std::min<int64_t>(end, (k + poll_every - 1) / poll_every * poll_every + 1);
    const bool navigate = k > s.start_step;
    if (!navigate) end = std::min<int64_t>(end, s.start_step + 1);
    if (navigate && next < n_reports) end = std::min<int64_t>(end, s.reports[next].k + 1);
    if (truth != nullptr && !truth->WaitFor(end - 1)) return false;
    kernel.advance(job.kernel, in, k, end, navigate, group);
    const int64_t last = end - 1;
    if (!navigate && last == s.start_step) start_navigation();
    if (navigate && next < n_reports && s.reports[next].k == last) record(s.reports[next++]);
    if ((last & (poll_every - 1)) == 0) {
      const int64_t d = last - polled;
      polled = last;
      if (monitor->Poll(d * lanes)) return false;
    }
    k = end;
  }
  for (int lane = 0; lane < lanes; ++lane) monitor->RunDone(s.n - polled);
  return true;
}

}  // namespace

void RunNedLockstep(const SharedTruth& s, const MonteCarloSpec& spec,
                    const lockstep::Kernel& kernel, bool gyrocompass, uint32_t run_count,
                    tbb::task_arena& arena,
                    tbb::enumerable_thread_specific<EpochAccumulator>& accumulators,
                    std::vector<std::vector<ErrorComponentValues>>& checkpoint_values,
                    Monitor* monitor, const TruthStream* truth) {
  const lockstep::LockstepJob job = lockstep::ComposeJob(
      spec.sensor ? &*spec.sensor : nullptr, spec.seed, s.env, s.rate_hz, spec.simulation.ned);
  const uint32_t width = static_cast<uint32_t>(kernel.width);
  const uint32_t groups = (run_count + width - 1) / width;
  struct Workspace {
    std::unique_ptr<lockstep::LockstepGroup> group = std::make_unique<lockstep::LockstepGroup>();
    lockstep::GroupStreams streams;
  };
  tbb::enumerable_thread_specific<Workspace> workspaces;
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, groups, 1),
                      [&](const tbb::blocked_range<uint32_t>& range) {
                        Workspace& w = workspaces.local();
                        RunSink sink;
                        sink.epochs = &accumulators.local();
                        sink.checkpoint_values = &checkpoint_values;
                        for (uint32_t g = range.begin(); g != range.end(); ++g) {
                          if (monitor->Stopped()) return;
                          const uint32_t begin = g * width;
                          const uint32_t end = std::min(run_count, begin + width);
                          if (!RunNedGroup(s, spec, job, kernel, begin, end, gyrocompass, sink,
                                           monitor, w.group.get(), &w.streams, truth)) {
                            return;
                          }
                        }
                      });
  });
}

}  // namespace driftlab::mc_detail
