#!/usr/bin/env python3
"""Runs gnss-ins-sim and driftlab on the same motion file and IMU error model; prints both
tools' error statistics at the final epoch and the speed ratio.

gnss-ins-sim (github.com/Aceinna/gnss-ins-sim; run from a checkout, on Debian's python3-numpy
and python3-scipy) generates the trajectory from the motion file, adds the errors of its built-in
IMU accuracy level and runs its free-integration demo algorithm
(demo_algorithms/free_integration.py) in its virtual inertial frame (ref_frame=1: flat,
constant gravity, no Earth rotation). driftlab runs the same motion file (motion.gnss_ins_sim_file,
earth_model FLAT) with the preset gnss-ins-sim-<level> (the same parameters, Gauss-Markov bias
started at zero as gnss-ins-sim does) through its NED mechanization, initialised at the truth.

Printed per error component at the final epoch: the standard deviation over the runs from each
tool, their ratio, and the 95 % F-test acceptance interval of that ratio for equal variances
(F distribution with (n1 - 1, n2 - 1) degrees of freedom, scipy.stats.f). Speed: IMU samples x
runs per second for each tool, by wall time (gnss-ins-sim: Sim.run() including its trajectory
generation; driftlab: the whole `driftlab run` process) and by CPU time (gnss-ins-sim: the Python
process during Sim.run(); driftlab: its result's timings.cpu_s, the Monte-Carlo loop), and their
ratios. On a shared machine the CPU-time ratio is the one to quote.

Usage:
  bench/gnss_ins_sim_compare.py --gnss-ins-sim /path/to/gnss-ins-sim \
      --driftlab build/clients/cli/driftlab \
      --motion /path/to/gnss-ins-sim/demo_motion_def_files/motion_def-static.csv \
      [--accuracy mid] [--runs 200] [--rate-hz 100] [--threads 1]
Writes only to a temporary directory.
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

COMPONENTS = ["north [m]", "east [m]", "down [m]", "v north [m/s]", "v east [m/s]",
              "v down [m/s]", "roll [deg]", "pitch [deg]", "yaw [deg]"]


def wrap_deg(x):
    return (np.asarray(x) + 180.0) % 360.0 - 180.0


def run_gnss_ins_sim(checkout, motion, accuracy, runs, rate_hz, numpy_seed):
    sys.path.insert(0, checkout)
    from gnss_ins_sim.sim import imu_model, ins_sim  # noqa: E402
    from demo_algorithms import free_integration  # noqa: E402
    d2r = math.pi / 180.0
    ini = np.genfromtxt(motion, delimiter=",", skip_header=1, max_rows=1)
    ini[0] *= d2r
    ini[1] *= d2r
    ini[6:9] *= d2r
    imu = imu_model.IMU(accuracy=accuracy + "-accuracy", axis=6, gps=False)
    algo = free_integration.FreeIntegration(ini)
    sim = ins_sim.Sim([rate_hz, 0.0, 0.0], motion, ref_frame=1, imu=imu, mode=None, env=None,
                      algorithm=[algo])
    # gnss-ins-sim draws its sensor errors from numpy's global generator without seeding it: seed
    # it here so that a call can be repeated (--numpy-seed).
    np.random.seed(numpy_seed)
    start, start_cpu = time.perf_counter(), time.process_time()
    sim.run(runs)
    wall_s, cpu_s = time.perf_counter() - start, time.process_time() - start_cpu
    pos, ref_pos, vel, ref_vel, att, ref_att = sim.get_data(
        ["pos", "ref_pos", "vel", "ref_vel", "att_euler", "ref_att_euler"])
    samples = ref_pos.shape[0]
    errors = np.zeros((runs, 9))
    for r in range(runs):
        key = "algo0_%d" % r  # algorithm 0, run r
        # ref_frame=1 positions are the initial ECEF point plus the motion along the virtual
        # inertial frame's north, east, down axes: their difference is the NED error.
        errors[r, 0:3] = pos[key][-1] - ref_pos[-1]
        errors[r, 3:6] = vel[key][-1] - ref_vel[-1]
        # Euler angles [yaw, pitch, roll] in rad -> roll, pitch, yaw errors in deg.
        d = wrap_deg(np.degrees(att[key][-1] - ref_att[-1]))
        errors[r, 6:9] = [d[2], d[1], d[0]]
    return errors, samples, wall_s, cpu_s


def run_driftlab(binary, motion, accuracy, runs, rate_hz, threads, workdir):
    job = {
        "name": "gnss_ins_sim_compare",
        "motion": {"earth_model": "FLAT", "gnss_ins_sim_file": {"path": os.path.abspath(motion)}},
        "rate_hz": rate_hz,
        "navigation": {"mechanization": "NED"},
        "sensor": {"preset": "gnss-ins-sim-" + accuracy},
        "monte_carlo": {"runs": runs, "seed": 19},
    }
    job_path = os.path.join(workdir, "job.json")
    out_path = os.path.join(workdir, "result.json")
    with open(job_path, "w") as f:
        json.dump(job, f)
    start = time.perf_counter()
    subprocess.run([binary, "run", job_path, "--out", out_path, "--threads", str(threads), "-q"],
                   check=True)
    wall_s = time.perf_counter() - start
    with open(out_path) as f:
        result = json.load(f)
    final = result["epochs"][-1]
    stds = [c.get("std", float("nan")) for c in final["components"][:9]]
    samples = int(round(final["t_s"] * rate_hz)) + 1
    return stds, samples, wall_s, float(result["timings"]["cpu_s"])


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--gnss-ins-sim", required=True, help="gnss-ins-sim checkout")
    p.add_argument("--driftlab", required=True, help="driftlab CLI binary")
    p.add_argument("--motion", required=True, help="gnss-ins-sim motion-definition CSV")
    p.add_argument("--accuracy", default="mid", choices=["low", "mid", "high"])
    p.add_argument("--runs", type=int, default=200)
    p.add_argument("--rate-hz", type=float, default=100.0)
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--numpy-seed", type=int, default=17,
                   help="seed of numpy's global generator, which gnss-ins-sim draws from")
    a = p.parse_args()
    from scipy import stats

    errors, gis_samples, gis_wall, gis_cpu = run_gnss_ins_sim(a.gnss_ins_sim, a.motion, a.accuracy,
                                                     a.runs, a.rate_hz, a.numpy_seed)
    with tempfile.TemporaryDirectory() as workdir:
        dl_std, dl_samples, dl_wall, dl_cpu = run_driftlab(a.driftlab, a.motion, a.accuracy, a.runs,
                                                   a.rate_hz, a.threads, workdir)
    gis_std = errors.std(axis=0, ddof=1)
    lo = stats.f.ppf(0.025, a.runs - 1, a.runs - 1)
    hi = stats.f.ppf(0.975, a.runs - 1, a.runs - 1)
    print(f"motion {os.path.basename(a.motion)}, {a.accuracy} accuracy, {a.runs} runs, "
          f"{a.rate_hz:g} Hz; samples per run: gnss-ins-sim {gis_samples}, driftlab {dl_samples}")
    print(f"{'component':>14} {'gnss-ins-sim std':>17} {'driftlab std':>13} {'var ratio':>10}"
          f"  F-test 95 % [{lo:.3f}, {hi:.3f}]")
    for name, g, d in zip(COMPONENTS, gis_std, dl_std):
        ratio = (d / g) ** 2 if g > 0 else float("nan")
        verdict = "inside" if lo <= ratio <= hi else "OUTSIDE"
        print(f"{name:>14} {g:17.6g} {d:13.6g} {ratio:10.4f}  {verdict}")
    for what, g, d in (("wall", gis_wall, dl_wall), ("CPU", gis_cpu, dl_cpu)):
        gis_rate = gis_samples * a.runs / g
        dl_rate = dl_samples * a.runs / d
        print(f"speed ({what} time): gnss-ins-sim {gis_rate:.4g} samples x runs / s ({g:.2f} s), "
              f"driftlab {dl_rate:.4g} ({d:.2f} s, {a.threads} thread(s)); ratio "
              f"{dl_rate / gis_rate:.1f}")


if __name__ == "__main__":
    main()
