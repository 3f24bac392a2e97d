#!/usr/bin/python3
"""driftlab-server --cluster slurm on a real one-node Slurm cluster started by this test.

    slurm_server_test.py SOURCE_DIR BUILD_DIR

The cluster is slurm_cluster.py's (munged, slurmctld, slurmd on 127.0.0.1 in a temporary
directory). A reference server without --cluster runs two jobs in-process; a server with
--cluster slurm --cluster-threshold-samples 0 (every job to Slurm, 4 shards) then:
  1. runs the small job: progress seen through `driftlab status`, result equal to the
     in-process one byte for byte (timings aside);
  2. cancels a long job from the client while its array runs: CANCELLED, and no task of it left in
     the queue;
  3. is killed (SIGKILL) while the array of a job runs and started again on the same store: it
     re-attaches to the array (no second submission), the job finishes (attempt 2) and its result
     equals the in-process one.
Servers listen on 127.0.0.1 with an ephemeral port. Exits 77 (skipped) as slurm_test.py does.
"""

import pathlib
import re
import signal
import subprocess
import sys

from slurm_cluster import SKIP, Skip, SlurmCluster, wait_until


def without_timings(text):
    return re.sub(r'"timings": \{[^}]*\}', "", text)


class Server:
    """driftlab-server on 127.0.0.1:0; log in LOG (appended)."""

    def __init__(self, binary, data, log, env, extra=()):
        self.log = log
        with open(log, "a") as err:
            self.process = subprocess.Popen(
                [str(binary), "--listen", "127.0.0.1:0", "--data", str(data), *extra],
                env=env, stdout=subprocess.PIPE, stderr=err, text=True)
        line = self.process.stdout.readline()  # "listening on 127.0.0.1:PORT", or EOF on error
        found = re.match(r"listening on (\S+)", line)
        assert found, f"server did not start: {line!r}\n{pathlib.Path(log).read_text()}"
        self.address = found.group(1)

    def stop(self, sig=signal.SIGTERM):
        if self.process.poll() is None:
            self.process.send_signal(sig)
            self.process.wait(timeout=60)


def main():
    source, build = map(pathlib.Path, sys.argv[1:3])
    driftlab = build / "driftlab"
    server_binary = build / "driftlab-server"
    try:
        cluster = SlurmCluster()
    except Skip as reason:
        print(f"SKIP: {reason}")
        return SKIP
    servers = []
    with cluster:
        tmp = cluster.tmp
        env = cluster.env

        def cli(*args, check=True, timeout=120):
            r = subprocess.run([str(driftlab), *map(str, args)], env=env, capture_output=True,
                               text=True, timeout=timeout)
            if check:
                assert r.returncode == 0, (args, r.returncode, r.stdout, r.stderr)
            return r

        def status(server, job_id):
            line = cli("status", job_id, "--server", server.address).stdout
            found = re.search(r"\s(QUEUED|RUNNING|SUCCEEDED|FAILED|CANCELLED)\s.*?(\d+)/(\d+) runs",
                              line)
            assert found, line
            return found.group(1), int(found.group(2)), int(found.group(3)), line

        def result(server, job_id, name):
            out = tmp / name
            cli("result", job_id, "--server", server.address, "--out", out)
            return without_timings(out.read_text())

        small = source / "tests" / "cli" / "data" / "mc_small.json"
        long_job = source / "examples" / "car_drive.json"
        try:
            # Reference: the same jobs in-process.
            reference = Server(server_binary, tmp / "data_local", tmp / "local.log", env)
            servers.append(reference)
            ref_small = cli("submit", small, "--runs", 8, "--server",
                            reference.address).stdout.strip()
            ref_long = cli("submit", long_job, "--runs", 200, "--server",
                           reference.address).stdout.strip()
            cli("watch", ref_small, "--server", reference.address, timeout=300)
            cli("watch", ref_long, "--server", reference.address, timeout=300)
            expected_small = result(reference, ref_small, "ref_small.json")
            expected_long = result(reference, ref_long, "ref_long.json")
            reference.stop()

            log = tmp / "cluster.log"
            cluster_args = ["--cluster", "slurm", "--cluster-threshold-samples", "0",
                            "--cluster-shards", "4", "--cluster-dir", tmp / "cluster",
                            "--cluster-driftlab", driftlab]
            server = Server(server_binary, tmp / "data", log, env, cluster_args)
            servers.append(server)

            # 1. Submit, watch the progress, result equal to the in-process one.
            job = cli("submit", small, "--runs", 8, "--server", server.address).stdout.strip()
            seen = []

            def finished():
                state, done, total, line = status(server, job)
                seen.append((state, done, total))
                assert state in ("QUEUED", "RUNNING", "SUCCEEDED"), line
                return state == "SUCCEEDED"
            wait_until(finished, 120, "the small job through Slurm")
            assert seen[-1][0] == "SUCCEEDED", seen
            assert result(server, job, "small.json") == expected_small, \
                "the Slurm result differs from the in-process result"
            progress = re.findall(rf"job={job} slurm: (\d)/4 shards done", log.read_text())
            assert progress and progress[-1] == "4", progress
            assert [int(p) for p in progress] == sorted(int(p) for p in progress), progress
            print(f"ok: small job through Slurm: progress {' -> '.join(progress)}/4 shards "
                  f"(server log), status lines {len(seen)}, result equal to the in-process one")

            # 2. Cancel from the client while the array runs: the queue is emptied.
            job = cli("submit", long_job, "--runs", 2000, "--server",
                      server.address).stdout.strip()
            wait_until(lambda: cluster.tasks(f"driftlab-{job}", "RUNNING"), 60,
                       "a running task of the job")
            r = cli("cancel", job, "--server", server.address, check=False)
            state = status(server, job)
            assert state[0] == "CANCELLED", (r.stdout, r.stderr, state)
            wait_until(lambda: not cluster.tasks(f"driftlab-{job}"), 60,
                       "the cancelled array to leave the queue")
            print("ok: cancel from the client: CANCELLED, no task left in the queue")

            # 3. kill -9 while the array runs; a new server re-attaches and finishes the job.
            job = cli("submit", long_job, "--runs", 200, "--server",
                      server.address).stdout.strip()
            wait_until(lambda: cluster.tasks(f"driftlab-{job}", "RUNNING"), 60,
                       "a running task of the job")
            server.stop(signal.SIGKILL)
            assert cluster.tasks(f"driftlab-{job}"), "the array should outlive the server"
            submissions = len(re.findall(rf"job={job} .*cluster=", log.read_text()))
            server = Server(server_binary, tmp / "data", log, env, cluster_args)
            servers.append(server)
            wait_until(lambda: status(server, job)[0] == "SUCCEEDED", 180,
                       "the job to finish after the restart")
            text = log.read_text()
            assert re.search(rf"job={job} .*\(re-attached\)", text), text[-2000:]
            assert "attempt 2" in status(server, job)[3], status(server, job)
            assert not cluster.tasks(f"driftlab-{job}")
            assert result(server, job, "restarted.json") == expected_long, \
                "the result after the restart differs from the in-process result"
            print(f"ok: server killed (SIGKILL) while the array ran ({submissions} submission), "
                  "restarted, re-attached; result equal to the in-process one")
            server.stop()
            return 0
        finally:
            for s in servers:
                s.stop(signal.SIGKILL)


if __name__ == "__main__":
    sys.exit(main())
