#!/usr/bin/python3
"""ctest `python_client_example`: the Python client's example script against a real server.

Starts driftlab-server (--listen 127.0.0.1:0, a temporary --data directory, --port-file), waits
for it with bounded waits (the port file, then gRPC channel readiness; no fixed sleeps), runs
examples/run_job.py on a small job and checks what it wrote: the result has exactly the runs
asked for (runs, run_count, one per-run value per run at the final checkpoint), its sigmas
are finite and positive, and the plot is a PNG. Then a job with a bad field must exit 2 with
the field path in the message, and the server is stopped (SIGTERM, bounded wait).

    example_test.py --server-binary BUILD/driftlab-server --example clients/python/examples/run_job.py
with PYTHONPATH=BUILD/python:clients/python.
"""

import argparse
import json
import math
import os
import pathlib
import signal
import subprocess
import sys
import tempfile
import time

import grpc

RUNS = 8

# Two minutes at 20 Hz (2 400 samples per run): at rest, then a short drive with a turn; the
# tactical preset. 8 runs keep the test short.
SMALL_JOB = {
    "name": "python_client_small",
    "description": "Python client example test: 2 min at 20 Hz, tactical IMU.",
    "motion": {
        "initial": {"lat_deg": 40.0, "lon_deg": -3.7, "height_m": 650, "yaw_deg": 10},
        "segments": [
            {"static": {"duration_s": 30}},
            {"accelerate": {"acceleration_m_per_s2": 1.0, "target_speed_m_per_s": 12}},
            {"turn": {"rate_deg_per_s": 9, "angle_deg": 90, "transition_s": 1}},
            {"constant_velocity": {"duration_s": 68}},
        ],
    },
    "rate_hz": 20,
    "navigation": {"ned": {"vertical_channel": "TRUTH_HEIGHT"}},
    "sensor": {"preset": "tactical"},
    "monte_carlo": {
        "runs": 40,
        "seed": 3,
        "initial_errors": {"attitude_deg": [0.01, 0.01, 0.05]},
        "epoch_interval_s": 5,
        "checkpoint_times_s": [60],
    },
}

START_TIMEOUT_S = 30.0
EXAMPLE_TIMEOUT_S = 120.0
STOP_TIMEOUT_S = 30.0


def fail(message):
    print(f"FAIL: {message}", file=sys.stderr)
    sys.exit(1)


def wait_for_port(server, port_file):
    """The port the server wrote, polling the file until a deadline (or the server exits)."""
    deadline = time.monotonic() + START_TIMEOUT_S
    while time.monotonic() < deadline:
        if server.poll() is not None:
            fail(f"driftlab-server exited with {server.returncode} before writing its port")
        try:
            text = port_file.read_text().strip()
            if text.isdigit() and int(text) > 0:
                return int(text)
        except FileNotFoundError:
            pass
        time.sleep(0.02)  # polling interval of a bounded wait, not a synchronisation
    fail(f"no port in {port_file} after {START_TIMEOUT_S} s")


def run_example(example, args, env):
    return subprocess.run([sys.executable, str(example)] + args, capture_output=True, text=True,
                          timeout=EXAMPLE_TIMEOUT_S, env=env)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--server-binary", required=True)
    parser.add_argument("--example", required=True)
    args = parser.parse_args()

    env = dict(os.environ, MPLBACKEND="Agg")
    env.pop("DRIFTLAB_TOKEN", None)
    with tempfile.TemporaryDirectory(prefix="driftlab_python_client_") as tmp:
        tmp = pathlib.Path(tmp)
        port_file = tmp / "port"
        server = subprocess.Popen(
            [args.server_binary, "--listen", "127.0.0.1:0", "--data", str(tmp / "data"),
             "--port-file", str(port_file)],
            stdout=open(tmp / "server.log", "w"), stderr=subprocess.STDOUT)
        try:
            port = wait_for_port(server, port_file)
            address = f"127.0.0.1:{port}"
            with grpc.insecure_channel(address) as channel:
                grpc.channel_ready_future(channel).result(timeout=START_TIMEOUT_S)

            job = tmp / "small.json"
            job.write_text(json.dumps(SMALL_JOB))
            plot = tmp / "envelopes.png"
            out = tmp / "result.json"
            r = run_example(args.example, ["--server", address, str(job), "--runs", str(RUNS),
                                           "--plot", str(plot), "--out", str(out)], env)
            if r.returncode != 0:
                fail(f"run_job.py exited {r.returncode}\nstdout:\n{r.stdout}\nstderr:\n{r.stderr}")
            print(r.stdout)
            result = json.loads(out.read_text())
            # The runs asked for, all of them in this one result.
            if int(result["runs"]) != RUNS or int(result["run_count"]) != RUNS:
                fail(f"runs {result['runs']}, run_count {result['run_count']}; expected {RUNS}")
            per_run = result["checkpoints"][-1].get("runs", [])
            if per_run and len(per_run) != RUNS:
                fail(f"{len(per_run)} per-run values at the final checkpoint; expected {RUNS}")
            if int(result["seed"]) != SMALL_JOB["monte_carlo"]["seed"]:
                fail(f"seed {result['seed']}; expected the job's seed 3")
            # With 8 runs of a noisy IMU every free error component has a finite, positive spread
            # at the final epoch (0 or NaN would mean the runs were not distinct); the job's
            # TRUTH_HEIGHT vertical channel pins the down position and velocity errors to 0.
            pinned = ("POSITION_DOWN_M", "VELOCITY_DOWN_M_PER_S")
            for c in result["epochs"][-1]["components"]:
                std = float(c["std"])
                if c["component"] in pinned:
                    if std != 0.0:
                        fail(f"{c['component']} std {std} with the truth height; expected 0")
                elif not (math.isfinite(std) and std > 0):
                    fail(f"final-epoch std of {c['component']} is {c['std']}")
            data = plot.read_bytes()
            if not data.startswith(b"\x89PNG\r\n\x1a\n") or len(data) < 10_000:
                fail(f"{plot} is not a plot PNG ({len(data)} bytes)")
            if "progress: 100%" not in r.stderr:
                fail(f"no final progress line in stderr:\n{r.stderr}")

            # A bad job: the server's INVALID_ARGUMENT names the field; the script exits 2.
            bad = dict(SMALL_JOB, rate_hz=-5)
            bad_job = tmp / "bad.json"
            bad_job.write_text(json.dumps(bad))
            r = run_example(args.example, ["--server", address, str(bad_job)], env)
            if r.returncode != 2 or "rate_hz" not in r.stderr:
                fail(f"bad job: exit {r.returncode} (expected 2), stderr:\n{r.stderr}")
            print(f"bad job rejected: {r.stderr.strip()}")
        finally:
            server.send_signal(signal.SIGTERM)
            try:
                code = server.wait(timeout=STOP_TIMEOUT_S)
            except subprocess.TimeoutExpired:
                server.kill()
                server.wait()
                fail(f"driftlab-server did not stop within {STOP_TIMEOUT_S} s of SIGTERM")
        if code != 0:
            print((tmp / "server.log").read_text(), file=sys.stderr)
            fail(f"driftlab-server exited {code} after SIGTERM")
    print("OK")


if __name__ == "__main__":
    main()
