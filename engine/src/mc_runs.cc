// The scalar Monte-Carlo runs, one run at a time: free NED (mechanization A), seed 000
// (mechanization B), the INS/GNSS EKF and the complementary attitude filter.
#include <cmath>
#include <optional>

#include "driftlab/aiding.h"
#include "driftlab/complementary_filter.h"
#include "driftlab/ins_gnss_filter.h"
#include "driftlab/sensors.h"
#include "mc_internal.h"
#include "mc_progress.h"

namespace driftlab::mc_detail {

// Runs one run with mechanization A. Returns false if stopped early.
bool RunNed(const SharedTruth& s, const MonteCarloSpec& spec, uint32_t run, bool gyrocompass,
            const RunSink& sink, Monitor* monitor, int64_t* samples) {
  std::optional<ImuErrorSimulator> sim;
  if (spec.sensor) sim.emplace(*spec.sensor, spec.seed, run, s.rate_hz);
  const bool truth_height = spec.simulation.ned.vertical == VerticalChannel::kTruthHeight;
  ImuIncrement measured;
  auto measure = [&](int64_t k) {
    const ImuIncrement& ideal = s.increments[static_cast<size_t>(k)];
    if (sim) {
      sim->Apply(ideal, &measured);
    } else {
      measured = ideal;
    }
  };
  int64_t polled = 0;
  auto poll = [&](int64_t k) {
    if ((k & (kPollSamples - 1)) != 0) return false;
    const int64_t d = k - polled;
    polled = k;
    return monitor->Poll(d);
  };

  // Alignment window: accumulate the measured increments.
  Eigen::Vector3d sum_dtheta = Eigen::Vector3d::Zero(), sum_dv = Eigen::Vector3d::Zero();
  for (int64_t k = 1; k <= s.start_step; ++k) {
    measure(k);
    sum_dtheta += measured.delta_theta_ib_b;
    sum_dv += measured.delta_v_ib_b;
    if (poll(k)) {
      *samples = k;
      return false;
    }
  }

  NedMechanization ned(s.env, NedStartState(s, spec, run, gyrocompass, sum_dtheta, sum_dv), s.dt_s,
                       spec.simulation.ned);
  size_t next = 0;
  const size_t n_reports = s.reports.size();
  if (s.reports[0].k == s.start_step) {
    sink.Record(s.reports[0], ComputeNavError(s.env, ned.state(), s.reports[0].truth));
    next = 1;
  }
  for (int64_t k = s.start_step + 1; k <= s.n; ++k) {
    measure(k);
    ned.Update(measured);
    if (truth_height) {
      ned.SetVertical(s.h_m[static_cast<size_t>(k)], s.v_D_m_per_s[static_cast<size_t>(k)]);
    }
    if (next < n_reports && s.reports[next].k == k) {
      sink.Record(s.reports[next], ComputeNavError(s.env, ned.state(), s.reports[next].truth));
      ++next;
    }
    if (poll(k)) {
      *samples = k;
      return false;
    }
  }
  *samples = s.n - polled;
  return true;
}

// Runs one run with mechanization B. Returns false if stopped early.
bool RunSeed000(const SharedTruth& s, const MonteCarloSpec& spec, uint32_t run, const RunSink& sink,
                Monitor* monitor, int64_t* samples) {
  std::optional<ImuErrorSimulator> sim;
  if (spec.sensor) sim.emplace(*spec.sensor, spec.seed, run, s.rate_hz);
  ImuSample measured;
  Seed000Mechanization mech(s.dt_s, spec.simulation.seed000);
  size_t next = 0;
  const size_t n_reports = s.reports.size();
  int64_t polled = 0;
  for (int64_t k = 0; k <= s.n; ++k) {
    const ImuSample& ideal = s.samples[static_cast<size_t>(k)];
    if (sim) {
      sim->Apply(ideal, &measured);
    } else {
      measured = ideal;
    }
    mech.Update(measured);
    if (next < n_reports && s.reports[next].k == k) {
      const NavState nav = mech.ToNed(s.env, s.truth0);
      sink.Record(s.reports[next], ComputeNavError(s.env, nav, s.reports[next].truth));
      ++next;
    }
    if (k > 0 && (k & (kPollSamples - 1)) == 0) {
      const int64_t d = k - polled;
      polled = k;
      if (monitor->Poll(d)) {
        *samples = 0;
        return false;
      }
    }
  }
  *samples = s.n + 1 - polled;
  return true;
}

// Runs one run with the INS/GNSS EKF (mechanization A, kTruthPlusErrors). Returns false if
// stopped early. At a sample: predict, report (after propagating P to the sample at an epoch),
// then the GNSS, barometer and ZUPT updates due at that sample, in this order (as
// FilterCovarianceAnalysis).
bool RunEkf(const SharedTruth& s, const MonteCarloSpec& spec, uint32_t run, const RunSink& sink,
            NeesAccumulator* nees, Monitor* monitor, int64_t* samples) {
  std::optional<ImuErrorSimulator> sim;
  if (spec.sensor) sim.emplace(*spec.sensor, spec.seed, run, s.rate_hz);
  const AidingSpec& aiding = spec.aiding;
  InsGnssFilterOptions options;
  options.imu_noise = s.ekf_noise;
  if (aiding.gnss) {
    options.gnss = *aiding.gnss;
  } else {
    options.gnss.rate_hz = s.rate_hz;  // unused; valid for any IMU rate
  }
  options.propagation_step_samples = spec.ekf_propagation_step_samples;
  options.mechanization = spec.simulation.ned;
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  InsGnssFilter filter(s.env, NedStartState(s, spec, run, true, zero, zero), s.ekf_P0, s.rate_hz,
                       options);
  std::optional<GnssSimulator> gnss;
  if (aiding.gnss) gnss.emplace(*aiding.gnss, s.env, s.rate_hz, spec.seed, run);
  std::optional<BarometerSimulator> baro;
  double baro_sigma_m = 0.0;
  if (aiding.barometer) {
    baro.emplace(*aiding.barometer, s.rate_hz, spec.seed, run);
    // The bias is a filter state when the filter's model has it; otherwise it widens R.
    baro_sigma_m = s.ekf_noise.barometer_bias_sigma_m > 0.0
                       ? aiding.barometer->noise_sigma_m
                       : std::hypot(aiding.barometer->noise_sigma_m, aiding.barometer->bias.sigma);
  }
  std::optional<ZuptSimulator> zupt;
  if (aiding.zupt) zupt.emplace(*aiding.zupt, s.rate_hz, spec.seed, run);
  size_t next_zupt = 0;

  auto record = [&](const Report& r) {
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

  size_t next = 0;
  const size_t n_reports = s.reports.size();
  if (s.reports[0].k == s.start_step) {
    record(s.reports[0]);
    next = 1;
  }
  ImuIncrement measured;
  int64_t polled = 0;
  for (int64_t k = s.start_step + 1; k <= s.n; ++k) {
    const ImuIncrement& ideal = s.increments[static_cast<size_t>(k)];
    if (sim) {
      sim->Apply(ideal, &measured);
    } else {
      measured = ideal;
    }
    filter.Predict(measured);
    if (next < n_reports && s.reports[next].k == k) record(s.reports[next++]);
    if (gnss && k % s.gnss_decimation == 0) {
      const size_t j = static_cast<size_t>(k / s.gnss_decimation);
      GnssMeasurement fix;
      if (gnss->Measure(k, s.gnss_truth[j], s.gnss_omega_ib_b[j], &fix)) {
        filter.Update(fix, measured.delta_theta_ib_b / s.dt_s);
      }
    }
    if (baro && k % s.baro_decimation == 0) {
      double h_m = 0.0;
      baro->Measure(k, s.baro_h_m[static_cast<size_t>(k / s.baro_decimation)], &h_m);
      filter.UpdateHeight(h_m, baro_sigma_m);
    }
    if (next_zupt < s.zupt_epochs.size() && s.zupt_epochs[next_zupt] == k) {
      filter.UpdateZeroVelocity(aiding.zupt->velocity_sigma_m_per_s, zupt->Measure(k));
      ++next_zupt;
    }
    if ((k & (kPollSamples - 1)) == 0) {
      const int64_t d = k - polled;
      polled = k;
      if (monitor->Poll(d)) {
        *samples = 0;
        return false;
      }
    }
  }
  *samples = s.n - polled;
  return true;
}

// Runs one run with the complementary attitude filter on the measured point samples k = 0..n.
// Returns false if stopped early.
bool RunComplementary(const SharedTruth& s, const MonteCarloSpec& spec, uint32_t run,
                      const RunSink& sink, Monitor* monitor, int64_t* samples) {
  std::optional<ImuErrorSimulator> sim;
  if (spec.sensor) sim.emplace(*spec.sensor, spec.seed, run, s.rate_hz);
  ComplementaryFilterOptions options = spec.complementary;
  std::optional<MagnetometerSimulator> mag;
  if (spec.aiding.magnetometer) {
    mag.emplace(*spec.aiding.magnetometer, s.rate_hz, spec.seed, run);
    options.magnetic_declination_rad = MagneticDeclination(spec.aiding.magnetometer->earth_field_n);
  }
  options.initial_yaw_rad =
      WrapPi(s.truth0.euler().yaw_rad +
             InitialErrorDraw(spec.seed, run, 2, spec.initial_errors.attitude_rad).z());
  ComplementaryAttitudeFilter filter(options, s.rate_hz);
  ImuSample measured;
  size_t next = 0;
  const size_t n_reports = s.reports.size();
  int64_t polled = 0;
  for (int64_t k = 0; k <= s.n; ++k) {
    const ImuSample& ideal = s.samples[static_cast<size_t>(k)];
    if (sim) {
      sim->Apply(ideal, &measured);
    } else {
      measured = ideal;
    }
    Eigen::Vector3d m_b;
    const bool has_mag =
        mag && k % s.mag_decimation == 0 &&
        mag->Measure(k, s.mag_q_b_n[static_cast<size_t>(k / s.mag_decimation)].toRotationMatrix(),
                     &m_b);
    filter.Update(measured, has_mag ? &m_b : nullptr);
    if (next < n_reports && s.reports[next].k == k) {
      // Attitude only: position and velocity are the truth's (errors reported as 0).
      NavState nav = s.reports[next].truth;
      nav.q_b_n = Quaterniond(EulerToDcm(filter.attitude()));
      sink.Record(s.reports[next], ComputeNavError(s.env, nav, s.reports[next].truth));
      ++next;
    }
    if (k > 0 && (k & (kPollSamples - 1)) == 0) {
      const int64_t d = k - polled;
      polled = k;
      if (monitor->Poll(d)) {
        *samples = 0;
        return false;
      }
    }
  }
  *samples = s.n + 1 - polled;
  return true;
}

}  // namespace driftlab::mc_detail
