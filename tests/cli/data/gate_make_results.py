#!/usr/bin/python3
"""Writes the synthetic result files of the report and gate tests (run from this directory).

Not a simulation: a JobResult (proto/driftlab/v1/result.proto) whose statistics are computed
here, independently of driftlab's code, from 100 synthetic runs. Run r's error in component c at
time t is  scale * s_c * (0.1 + z_rc) * t / 600  with z_rc ~ N(0, 1) (numpy PCG64, seed 4), so
every statistic of the degraded copy (scale 1.5) is exactly 1.5 times the baseline's (to rounding).

  gate_baseline.json   scale 1
  gate_degraded.json   scale 1.5, same job: every error 50 % worse
  gate_other_job.json  scale 1, but the job echo has rate_hz 200 instead of 100

Statistics as result.proto defines them: std with divisor N - 1, chi-square 95 % intervals
(Papoulis & Pillai 4th ed. sec. 8.3), percentiles of |error| by linear interpolation (numpy's
default, Hyndman & Fan definition 7), CEP = percentiles of the horizontal error, 2DRMS =
2 sqrt(mean(dN^2 + dE^2)).
"""
import copy
import json

import numpy as np
from scipy.stats import chi2

RUNS = 100
T_FINAL_S = 600.0
EPOCHS_S = [60.0 * k for k in range(11)]
CHECKPOINTS_S = [300.0, 600.0]
# 1-sigma size at t = 600 s of north, east, down [m], velocity N/E/D [m/s], roll, pitch, yaw [deg].
SIGMA = [50.0, 40.0, 20.0, 0.3, 0.25, 0.1, 0.02, 0.02, 0.1]
COMPONENTS = ["POSITION_NORTH_M", "POSITION_EAST_M", "POSITION_DOWN_M",
              "VELOCITY_NORTH_M_PER_S", "VELOCITY_EAST_M_PER_S", "VELOCITY_DOWN_M_PER_S",
              "ROLL_DEG", "PITCH_DEG", "YAW_DEG", "HORIZONTAL_POSITION_M", "POSITION_3D_M"]

JOB = {
    "name": "gate_test_static_equator",
    "description": "Synthetic result for the report and gate tests (not a simulation).",
    "motion": {"initial": {"lat_deg": 0.0, "lon_deg": 10.0},
               "segments": [{"static": {"duration_s": 600.0}}]},
    "rate_hz": 100.0,
    "sensor": {"gyro": {"arw_deg_per_sqrt_h": 0.1}, "accel": {"vrw_m_per_s_per_sqrt_h": 0.05}},
    "monte_carlo": {"runs": RUNS, "seed": "7", "epoch_interval_s": 60.0,
                    "checkpoint_times_s": [300.0]},
}


def errors(scale, z, t_s):
    """Per-run values of the 11 components at t_s: array (RUNS, 11)."""
    signed = scale * np.array(SIGMA) * (0.1 + z) * (t_s / T_FINAL_S)
    horizontal = np.hypot(signed[:, 0], signed[:, 1])
    total = np.sqrt(signed[:, 0] ** 2 + signed[:, 1] ** 2 + signed[:, 2] ** 2)
    return np.column_stack([signed, horizontal, total])


def epoch_statistics(values, t_s):
    n = values.shape[0]
    components = []
    for c, name in enumerate(COMPONENTS):
        x = values[:, c]
        std = float(np.std(x, ddof=1))
        rms = float(np.sqrt(np.mean(x * x)))
        components.append({
            "component": name, "mean": float(np.mean(x)), "std": std, "rms": rms,
            "std_ci95_low": std * np.sqrt((n - 1) / chi2.ppf(0.975, n - 1)),
            "std_ci95_high": std * np.sqrt((n - 1) / chi2.ppf(0.025, n - 1)),
            "rms_ci95_low": rms * np.sqrt(n / chi2.ppf(0.975, n)),
            "rms_ci95_high": rms * np.sqrt(n / chi2.ppf(0.025, n)),
        })
    return {"t_s": t_s, "components": components}


def checkpoint(values, t_s):
    components = []
    for c, name in enumerate(COMPONENTS):
        a = np.abs(values[:, c])
        p = [float(v) for v in np.percentile(a, [50, 68, 95, 99])]
        components.append({"component": name, "p50": p[0], "p68": p[1], "p95": p[2],
                           "p99": p[3], "max_abs": float(a.max())})
    horizontal = values[:, 9]
    return {
        "t_s": t_s, "components": components,
        "cep50_m": float(np.percentile(horizontal, 50)),
        "cep95_m": float(np.percentile(horizontal, 95)),
        "drms2_m": float(2 * np.sqrt(np.mean(values[:, 0] ** 2 + values[:, 1] ** 2))),
        "runs": [{"run_index": r, "values": [float(v) for v in values[r]]} for r in range(RUNS)],
    }


def result(scale, job):
    z = np.random.default_rng(4).standard_normal((RUNS, len(SIGMA)))
    samples = RUNS * int(T_FINAL_S * job["rate_hz"] + 1)
    return {
        "job": job, "engine_version": "0.0.0-synthetic", "seed": "7", "runs": RUNS,
        "first_run": 0, "run_count": RUNS,
        "epochs": [epoch_statistics(errors(scale, z, t), t) for t in EPOCHS_S],
        "checkpoints": [checkpoint(errors(scale, z, t), t) for t in CHECKPOINTS_S],
        "timings": {"wall_s": 1.25, "cpu_s": 2.4, "samples": str(samples),
                    "samples_per_s": samples / 1.25, "threads": 2},
    }


def write(name, content):
    with open(name, "w") as f:
        json.dump(content, f, indent=1)
        f.write("\n")


other = copy.deepcopy(JOB)
other["rate_hz"] = 200.0
write("gate_baseline.json", result(1.0, JOB))
write("gate_degraded.json", result(1.5, JOB))
write("gate_other_job.json", result(1.0, other))
