#!/usr/bin/python3
"""`driftlab run --slurm` on a real one-node Slurm cluster started by this test.

    slurm_test.py SOURCE_DIR BUILD_DIR

Configures munged, slurmctld and slurmd (Debian's munge and slurm-wlm) for one node on 127.0.0.1
in a temporary directory with free ports, starts them, and checks:
  1. a 4-shard job through Slurm: the merged result equals the in-process result of the same job
     byte for byte, the timings object aside;
  2. a shard whose task cannot write its result is resubmitted once, then the run fails (exit 1)
     naming the shard and its log, and writes nothing;
  3. Ctrl-C (SIGINT) of `driftlab run --slurm` cancels the array: exit 130 and no task of it left
     in the queue.
Everything is stopped at the end. Exits 77 (ctest: skipped) with a message when the packages are
missing or the test does not run as root (slurmd must); CI installs them (.ci/run).
"""

import pathlib
import re
import signal
import subprocess
import sys

from slurm_cluster import SKIP, Skip, SlurmCluster, wait_until


def without_timings(text):
    return re.sub(r'"timings": \{[^}]*\}', "", text)


def main():
    source, build = map(pathlib.Path, sys.argv[1:3])
    driftlab = build / "driftlab"
    try:
        cluster = SlurmCluster()
    except Skip as reason:
        print(f"SKIP: {reason}")
        return SKIP
    with cluster:
        tmp = cluster.tmp
        env = cluster.env
        job = source / "tests" / "cli" / "data" / "mc_small.json"
        # 1. Four shards through Slurm equal one in-process run.
        slurm_out = tmp / "slurm.json"
        r = subprocess.run([str(driftlab), "run", str(job), "--runs", "8", "--slurm", "--shards",
                            "4", "--out", str(slurm_out)], env=env, capture_output=True,
                           text=True, timeout=300)
        assert r.returncode == 0, r.stderr
        assert "slurm: 4/4 shards done" in r.stderr, r.stderr
        local_out = tmp / "local.json"
        r = subprocess.run([str(driftlab), "run", str(job), "--runs", "8", "--out",
                            str(local_out)], env=env, capture_output=True, text=True,
                           timeout=300)
        assert r.returncode == 0, r.stderr
        assert without_timings(slurm_out.read_text()) == without_timings(local_out.read_text()), \
            "the Slurm result differs from the in-process result"
        print("ok: 4 shards through Slurm equal the in-process result byte for byte "
              "(timings aside)")

        # 1b. The same by hand: deploy/slurm/submit.sh (array + dependent merge step).
        by_hand = tmp / "by_hand.json"
        hand_env = dict(env, DRIFTLAB=str(driftlab))
        r = subprocess.run(["sh", str(source / "deploy" / "slurm" / "submit.sh"), str(job), "4",
                            str(tmp / "by_hand"), str(by_hand), "--", "--export=ALL"],
                           env=hand_env, capture_output=True, text=True, timeout=60)
        assert r.returncode == 0, r.stderr
        wait_until(by_hand.exists, 120, "the merge step's result")
        local_40 = tmp / "local_40.json"  # the job's own 40 runs, in-process
        r2 = subprocess.run([str(driftlab), "run", str(job), "--out", str(local_40)], env=env,
                            capture_output=True, text=True, timeout=300)
        assert r2.returncode == 0, r2.stderr
        assert without_timings(by_hand.read_text()) == without_timings(local_40.read_text()), \
            "the by-hand Slurm result differs from the in-process result"
        print("ok: deploy/slurm/submit.sh ran the array and the merge step:", r.stdout.strip())

        # 2. A shard cancelled with scancel is resubmitted once; cancelled again, the run fails
        # naming it and writes nothing. car_drive, 200 runs in 4 shards: tasks of seconds, two
        # at a time on this node, so the last task is still queued or running when cancelled.
        long_job = source / "examples" / "car_drive.json"
        failing_out = tmp / "failing.json"
        process = subprocess.Popen([str(driftlab), "run", str(long_job), "--runs", "200",
                                    "--slurm", "--shards", "4", "--out", str(failing_out)],
                                   env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                   text=True)
        lines = []

        def read_until(pattern):
            """Reads stderr lines (at most 200) until one matches; returns the match."""
            for _ in range(200):
                line = process.stderr.readline()
                if not line:
                    break
                lines.append(line)
                found = re.search(pattern, line)
                if found:
                    return found
            raise AssertionError(f"no line matching {pattern!r} in: {''.join(lines)}")
        first = read_until(r"submitted job (\d+)").group(1)
        subprocess.run(["scancel", f"{first}_3"], env=env, check=True)
        again = read_until(r"shard 3/4 ended without a result .*resubmitted as job (\d+)").group(1)
        subprocess.run(["scancel", again], env=env, check=True)
        read_until(r"error: shard 3/4 failed 2 times")
        process.communicate(timeout=120)
        assert process.returncode == 1, (process.returncode, "".join(lines))
        assert not failing_out.exists()
        print("ok: a shard cancelled with scancel is resubmitted once, then named:",
              lines[-1].strip()[:200])

        # 3. SIGINT cancels the array.
        cancel_out = tmp / "cancel.json"
        process = subprocess.Popen([str(driftlab), "run", str(long_job), "--runs", "2000",
                                    "--slurm", "--shards", "4", "--out", str(cancel_out)],
                                   env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                   text=True)

        def our_tasks(state=None):
            return cluster.tasks("driftlab ", state)
        wait_until(lambda: our_tasks("RUNNING"), 60, "a running task")
        process.send_signal(signal.SIGINT)
        _, err = process.communicate(timeout=60)
        assert process.returncode == 130, (process.returncode, err)
        assert "cancelled: scancel" in err, err
        wait_until(lambda: not our_tasks(), 60, "the array to leave the queue")
        assert not cancel_out.exists()
        print("ok: SIGINT cancelled the array (exit 130, queue empty)")
        return 0


if __name__ == "__main__":
    sys.exit(main())
