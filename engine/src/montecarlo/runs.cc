// The scalar Monte-Carlo runs, one run at a time through the engine's run loop (run_loop.h): free
// NED (mechanization A), seed 000 (mechanization B), the INS/GNSS EKF and the complementary
// attitude filter. The navigators of the two filters are here; the free-inertial ones in
// run_loop.h.
#include <cmath>
#include <optional>
#include <utility>

#include "driftlab/aiding.h"
#include "driftlab/complementary_filter.h"
#include "driftlab/elementary.h"
#include "driftlab/ins_gnss_filter.h"
#include "driftlab/sensors.h"
#include "montecarlo/internal.h"
#include "montecarlo/progress.h"
#include "montecarlo/run_loop.h"

namespace driftlab::mc_detail {

namespace {

const ImuErrorModel* SensorOf(const MonteCarloSpec& spec) {
  return spec.sensor ? &*spec.sensor : nullptr;
}

// One run of `navigator` over the shared truth's samples k = 0..n through the run's sensor errors,
// `record(report, navigator)` at each report sample, progress and cancellation through `monitor`.
// Returns false if stopped early; else the run's samples are counted as done.
// `observer` (if not null) sees every sample after its report.
template <class Navigator, class Record>
bool RunOne(const SharedTruth& s, const MonteCarloSpec& spec, uint32_t run, Navigator& navigator,
            Record&& record, Monitor* monitor, RunObserver* observer) {
  using Input = typename Navigator::Input;
  constexpr bool kPointSamples = std::is_same_v<Input, ImuSample>;
  const std::vector<Input>* ideal = nullptr;
  if constexpr (kPointSamples) {
    ideal = &s.samples;
  } else {
    ideal = &s.increments;
  }
  run_loop::StoredImu<Input> measure(*ideal, SensorOf(spec), spec.seed, run, s.rate_hz);
  size_t next = 0;
  const size_t n_reports = s.reports.size();
  const InsGnssFilter* filter = nullptr;
  if constexpr (requires { navigator.filter(); }) filter = &navigator.filter();
  const std::function<NavState(const NavState&)> solution = [&navigator](const NavState& truth) {
    return NavState(navigator.Solution(truth));
  };
  auto report = [&](int64_t k, const Navigator& nav) {
    if (next < n_reports && s.reports[next].k == k) record(s.reports[next++], nav);
    if (observer != nullptr) observer->At(k, solution, filter);
  };
  int64_t polled = 0;
  auto poll = [&](int64_t k) {
    const int64_t d = k - polled;
    polled = k;
    return monitor->Poll(d);
  };
  if (!run_loop::RunLoop(s.n, measure, navigator, report, poll)) return false;
  // Samples of a run (Monitor's total): n + 1 point samples, n increments.
  monitor->RunDone((kPointSamples ? s.n + 1 : s.n) - polled);
  return true;
}

// The INS/GNSS EKF (ins_gnss_filter.h) with the run's aiding measurements. At a sample: predict
// (Step), report, then the updates of the aids the job's schedule (SharedTruth::schedule) has due
// at that sample (Correct), in the schedule's order (as FilterCovarianceAnalysis). Navigation
// starts at s0 = 0 (initialization TRUTH_PLUS_ERRORS, ValidateFilter).
class EkfNavigator {
 public:
  using Input = ImuIncrement;
  EkfNavigator(const SharedTruth& s, const MonteCarloSpec& spec, uint32_t run) : s_(s) {
    InsGnssFilterOptions options;
    options.imu_noise = s.ekf_noise;
    if (spec.aiding.gnss) {
      options.gnss = *spec.aiding.gnss;
    } else {
      options.gnss.rate_hz = s.rate_hz;  // unused; valid for any IMU rate
    }
    options.propagation_step_samples = spec.ekf_propagation_step_samples;
    options.mechanization = spec.simulation.ned;
    const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
    filter_.emplace(s.env, NedStartState(s, spec, run, true, zero, zero), s.ekf_P0, s.rate_hz,
                    options);
    aids_ = StartAidingRuns(s.schedule->sensors(), s.env, spec.seed, run, filter_->layout(),
                            s.ekf_noise);
  }

  void Step(int64_t k, const ImuIncrement& measured) {
    if (k > s_.start_step) filter_->Predict(measured);
  }
  void Correct(int64_t k, const ImuIncrement& measured) {
    if (next_ >= s_.aiding_epochs.size() || s_.aiding_epochs[next_].k != k) return;
    const SharedTruth::AidingEpoch& epoch = s_.aiding_epochs[next_++];
    for (size_t i = 0; i < aids_.runs.size(); ++i) {
      if ((epoch.due >> i & 1u) == 0) continue;
      AidingRun& aid = *aids_.runs[i];
      if (aid.Measure(k, epoch.truth)) {
        filter_->Update(aid, measured.delta_theta_ib_b / s_.dt_s, aids_.first_state[i]);
      }
    }
  }
  const NavState& Solution(const NavState&) const { return filter_->state(); }
  InsGnssFilter& filter() { return *filter_; }
  const InsGnssFilter& filter() const { return *filter_; }

 private:
  const SharedTruth& s_;
  std::optional<InsGnssFilter> filter_;
  AidingRuns aids_;
  size_t next_ = 0;  // the next of s_.aiding_epochs
};

// The complementary attitude filter (complementary_filter.h) on the measured point samples
// k = 0..n, with the run's magnetometer. Attitude only: position and velocity are the truth's
// (errors reported as 0).
class ComplementaryNavigator {
 public:
  using Input = ImuSample;
  ComplementaryNavigator(const SharedTruth& s, const MonteCarloSpec& spec, uint32_t run) : s_(s) {
    ComplementaryFilterOptions options = spec.complementary;
    if (spec.aiding.magnetometer) {
      mag_.emplace(*spec.aiding.magnetometer, s.rate_hz, spec.seed, run);
      options.magnetic_declination_rad =
          MagneticDeclination(spec.aiding.magnetometer->earth_field_n);
    }
    options.initial_yaw_rad =
        WrapPi(s.truth0.euler().yaw_rad +
               InitialErrorDraw(spec.seed, run, 2, spec.initial_errors.attitude_rad).z());
    filter_.emplace(options, s.rate_hz);
  }
  void Step(int64_t k, const ImuSample& measured) {
    Eigen::Vector3d m_b;
    const bool has_mag =
        mag_ && k % s_.mag_decimation == 0 &&
        mag_->Measure(
            k, s_.mag_q_b_n[static_cast<size_t>(k / s_.mag_decimation)].toRotationMatrix(), &m_b);
    filter_->Update(measured, has_mag ? &m_b : nullptr);
  }
  void Correct(int64_t, const ImuSample&) {}
  NavState Solution(const NavState& truth) const {
    NavState nav = truth;
    nav.q_b_n = Quaterniond(EulerToDcm(filter_->attitude()));
    return nav;
  }

 private:
  const SharedTruth& s_;
  std::optional<MagnetometerSimulator> mag_;
  std::optional<ComplementaryAttitudeFilter> filter_;
};

}  // namespace

bool RunNed(const SharedTruth& s, const MonteCarloSpec& spec, uint32_t run, bool gyrocompass,
            const RunSink& sink, Monitor* monitor, RunObserver* observer) {
  run_loop::NedNavigator navigator(
      s.env, s.dt_s, spec.simulation.ned, s.start_step,
      [&](const Eigen::Vector3d& sum_dtheta, const Eigen::Vector3d& sum_dv) {
        return NedStartState(s, spec, run, gyrocompass, sum_dtheta, sum_dv);
      },
      [&](int64_t k) {
        const size_t uk = static_cast<size_t>(k);
        return std::pair<double, double>(s.h_m[uk], s.v_D_m_per_s[uk]);
      });
  return RunOne(
      s, spec, run, navigator,
      [&](const Report& r, const auto& nav) {
        sink.Record(r, ComputeNavError(s.env, nav.Solution(r.truth), r.truth));
      },
      monitor, observer);
}

bool RunSeed000(const SharedTruth& s, const MonteCarloSpec& spec, uint32_t run, const RunSink& sink,
                Monitor* monitor, RunObserver* observer) {
  run_loop::Seed000Navigator navigator(s.env, s.truth0, s.dt_s, spec.simulation.seed000);
  return RunOne(
      s, spec, run, navigator,
      [&](const Report& r, const run_loop::Seed000Navigator& nav) {
        sink.Record(r, ComputeNavError(s.env, nav.Solution(r.truth), r.truth));
      },
      monitor, observer);
}

bool RunEkf(const SharedTruth& s, const MonteCarloSpec& spec, uint32_t run, const RunSink& sink,
            NeesAccumulator* nees, Monitor* monitor, RunObserver* observer) {
  EkfNavigator navigator(s, spec, run);
  InsGnssFilter& filter = navigator.filter();
  auto record = [&](const Report& r, const EkfNavigator&) {
    if (r.epoch >= 0) filter.SyncCovariance();
    const NavError error = ComputeNavError(s.env, filter.state(), r.truth);
    sink.Record(r, error);
    if (r.epoch < 0) return;
    // NEES of the 9 navigation states against the filter's P (chi2(9) for a consistent filter).
    Eigen::Matrix<double, 9, 1> e;
    e << error.r_ned_m, error.v_ned_m_per_s, error.psi_nb_n_rad;
    const Eigen::LLT<Eigen::Matrix<double, 9, 9>> llt(filter.P().topLeftCorner<9, 9>());
    if (llt.info() != Eigen::Success) return;
    const double value = e.dot(llt.solve(e));
    if (!std::isfinite(value)) return;
    nees->sum[static_cast<size_t>(r.epoch)].Add(value);
    ++nees->count[static_cast<size_t>(r.epoch)];
  };
  return RunOne(s, spec, run, navigator, record, monitor, observer);
}

bool RunComplementary(const SharedTruth& s, const MonteCarloSpec& spec, uint32_t run,
                      const RunSink& sink, Monitor* monitor, RunObserver* observer) {
  ComplementaryNavigator navigator(s, spec, run);
  return RunOne(
      s, spec, run, navigator,
      [&](const Report& r, const ComplementaryNavigator& nav) {
        sink.Record(r, ComputeNavError(s.env, nav.Solution(r.truth), r.truth));
      },
      monitor, observer);
}

}  // namespace driftlab::mc_detail
