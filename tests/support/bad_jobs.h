// Jobs that an earlier driftlab validated and then failed on, ran wrongly or named a field the
// schema does not have: each with the field the one validator (app::ValidateJob) must name now.
// Shared by tests/app/job (ValidateJob), tests/cli (`validate`, `run`, `simulate`, `export` as a
// child process) and tests/server (Jobs.Submit, Datasets), which compare their messages.
// Header-only; the jobs are inline JSON, small (seconds of motion at 20 Hz).
#pragma once

#include <string>
#include <vector>

namespace driftlab::testing {

// A 30 s drive at 20 Hz (10 s at rest, 10 s accelerating north, 10 s at 10 m/s), tactical IMU,
// 4 runs; `navigation`, `aiding`, `sensor` and `monte_carlo` JSON objects spliced in.
inline std::string SmallDriveJob(const std::string& navigation, const std::string& aiding = "{}",
                                 const std::string& sensor = R"({"preset": "tactical"})",
                                 const std::string& monte_carlo = R"({"runs": 4})") {
  return R"({"name": "small_drive", "rate_hz": 20,
    "motion": {"initial": {"lat_deg": 45, "lon_deg": 7, "height_m": 300},
      "segments": [{"static": {"duration_s": 10}},
                   {"accelerate": {"acceleration_m_per_s2": 1, "duration_s": 10}},
                   {"constant_velocity": {"duration_s": 10}}]},
    "navigation": )" +
         navigation + R"(, "aiding": )" + aiding + R"(, "sensor": )" + sensor +
         R"(, "monte_carlo": )" + monte_carlo + "}";
}

inline const char* kEkf = R"({"filter": "INS_GNSS_EKF"})";
// The EKF propagating every 5 samples (0.25 s at 20 Hz): the tactical preset's flicker design has
// its shortest Gauss-Markov state at bias_instability_tau_min_s / 4 = 0.25 s, which the validator
// requires to be at least the propagation interval (the default 10 samples, 0.5 s, is refused).
inline const char* kEkfTactical = R"({"filter": "INS_GNSS_EKF",
                                      "ekf": {"propagation_step_samples": 5}})";
inline const char* kGnss = R"({"gnss": {"rate_hz": 1}})";

struct BadJob {
  std::string name;   // test-name suffix
  std::string json;   // the job file
  std::string field;  // the field the error must name
  std::string value;  // a fragment of the message that must be there too (the value or cause)
};

// Jobs that validated and then failed or ran wrongly (non-finite or meaningless statistics, an
// option silently ignored, a value the CLI accepted and the server refused), as driftlab at
// e9ec37c did with each. The server accepts the same input (no file references), so each is also
// submitted there.
inline std::vector<BadJob> ValidatedThenFailedJobs() {
  return {
      // A gyro Gauss-Markov bias correlated for 1e-12 s: the EKF's covariance went to NaN, `run`
      // failed after all the work and the server stored NaN statistics as SUCCEEDED.
      {"GyroGaussMarkovTauFarBelowTheFilterStep",
       SmallDriveJob(kEkf, kGnss,
                     R"({"preset": "tactical", "gyro": {"gauss_markov_sigma_deg_per_h": 10,
                         "gauss_markov_tau_s": 1e-12}})"),
       "sensor.gyro.gauss_markov_tau_s", "1e-12 s"},
      // The covariance analysis with an accelerometer Gauss-Markov tau of 1 ms at 20 Hz: predicted
      // sigma 1e99 times too large (or NaN) with exit status 0.
      {"AccelGaussMarkovTauBelowTheCovarianceStep",
       SmallDriveJob(R"({"filter": "NONE"})", "{}",
                     R"({"accel": {"gauss_markov_sigma_ug": 100, "gauss_markov_tau_s": 0.001}})",
                     R"({"runs": 4, "covariance": true})"),
       "sensor.accel.gauss_markov_tau_s", "0.001 s"},
      // The GNSS position Gauss-Markov error at tau = 1e-6 s: the filter's GNSS error states blew
      // up.
      {"GnssGaussMarkovTauFarBelowTheFilterStep",
       SmallDriveJob(kEkfTactical,
                     R"({"gnss": {"rate_hz": 1, "position_gauss_markov_sigma_ned_m": [1, 1, 2],
                                         "position_gauss_markov_tau_s": 1e-6}})"),
       "aiding.gnss.position_gauss_markov_tau_s", "1e-06 s"},
      // The barometer's bias state with tau = 1e-6 s: its covariance grew 1e10-fold per filter
      // step and the filter discarded the barometer (final down sigma 0.43 m, as without it; the
      // white noise it is gives 0.11 m), with exit status 0.
      {"BarometerBiasTauFarBelowTheFilterStep",
       SmallDriveJob(kEkfTactical,
                     R"({"gnss": {"rate_hz": 1}, "barometer": {"bias_gauss_markov_sigma_m": 1,
                                         "bias_gauss_markov_tau_s": 1e-6}})"),
       "aiding.barometer.bias_gauss_markov_tau_s", "1e-06 s"},
      // The model the filter assumes (a mistuned filter) with a tau far below its step.
      {"FilterSensorGaussMarkovTauFarBelowTheFilterStep",
       SmallDriveJob(R"({"filter": "INS_GNSS_EKF", "ekf": {"sensor": {"preset": "tactical",
                         "gyro": {"gauss_markov_sigma_deg_per_h": 10, "gauss_markov_tau_s": 1e-9}}}})",
                     kGnss),
       "navigation.ekf.sensor.gyro.gauss_markov_tau_s", "1e-09 s"},
      // Flicker down to 1 us as filter states: their 0.25 us Gauss-Markov components.
      {"FlickerTauMinFarBelowTheFilterStep",
       SmallDriveJob(
           kEkf, kGnss,
           R"({"gyro": {"bias_instability_deg_per_h": 1, "bias_instability_tau_min_s": 1e-6,
                         "bias_instability_tau_max_s": 100}})"),
       "sensor.gyro.bias_instability_tau_min_s", "1e-06 s"},
      // A Gauss-Markov bias correlated for less than one IMU sample (20 Hz) is white noise at this
      // rate: the job states a model that does not exist at its rate (it ran, as white noise).
      {"GaussMarkovTauBelowTheImuInterval",
       SmallDriveJob(
           R"({})", "{}",
           R"({"gyro": {"gauss_markov_sigma_deg_per_h": 10, "gauss_markov_tau_s": 0.01}})"),
       "sensor.gyro.gauss_markov_tau_s", "0.05 s"},
      // ZUPT options while the ZUPT is off: ignored by the CLI (even NaN), refused by the server.
      {"ZuptOptionWhileDisabled",
       SmallDriveJob(kEkf,
                     R"({"gnss": {"rate_hz": 1}, "zupt": {"enabled": false, "rate_hz": "NaN"}})"),
       "aiding.zupt.rate_hz", "enabled false"},
      // SEED000 options with the NED mechanization: silently ignored.
      {"Seed000OptionsWithTheNedMechanization",
       SmallDriveJob(R"({"mechanization": "NED", "seed000": {"static_period_s": 5}})"),
       "navigation.seed000", "NED"},
  };
}

// Jobs whose error named a field the job schema does not have (the engine's own names).
inline std::vector<BadJob> WrongFieldNameJobs() {
  return {
      {"FlickerRangeOverTheLimit",
       SmallDriveJob(
           R"({})", "{}",
           R"({"gyro": {"bias_instability_deg_per_h": 1, "bias_instability_tau_min_s": 1e-3,
                         "bias_instability_tau_max_s": 1e7}})"),
       "sensor.gyro.bias_instability_tau_max_s", "<= 1e9 bias_instability_tau_min_s"},
      {"TooManyEpochs",
       R"({"name": "long", "rate_hz": 100, "motion": {"initial": {"lat_deg": 45, "lon_deg": 7},
           "segments": [{"static": {"duration_s": 10000}}]},
           "monte_carlo": {"runs": 1, "epoch_interval_s": 0.01}})",
       "monte_carlo.epoch_interval_s", "0.01 s"},
      {"ComplementaryFilterWithARollError",
       SmallDriveJob(R"({"filter": "COMPLEMENTARY"})", "{}", R"({"preset": "tactical"})",
                     R"({"runs": 4, "initial_errors": {"attitude_deg": [0.1, 0, 0.5]}})"),
       "monte_carlo.initial_errors.attitude_deg", "roll"},
      {"AlignmentOverAMovingSegment",
       SmallDriveJob(R"({})", "{}", R"({"preset": "tactical"})",
                     R"({"runs": 4, "initialization": {"kind": "STATIC_ALIGNMENT",
                         "alignment_duration_s": 15}})"),
       "monte_carlo.initialization.alignment_duration_s", "15"},
      {"FlatEarthAlignmentWithoutHeadingSigma",
       R"({"name": "flat", "rate_hz": 20, "motion": {"earth_model": "FLAT",
           "initial": {"lat_deg": 45, "lon_deg": 7}, "segments": [{"static": {"duration_s": 30}}]},
           "sensor": {"preset": "tactical"},
           "monte_carlo": {"runs": 2, "initialization": {"kind": "STATIC_ALIGNMENT",
             "alignment_duration_s": 10}}})",
       "monte_carlo.initialization.heading_sigma_deg", "flat Earth"},
  };
}

}  // namespace driftlab::testing
