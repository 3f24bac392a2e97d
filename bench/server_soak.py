#!/usr/bin/python3
"""Soak test of driftlab-server on loopback with mixed valid and hostile requests.

    PYTHONPATH=<build>/python:clients/python /usr/bin/python3 bench/server_soak.py \\
        --server-binary build/driftlab-server --minutes 30 [--clients 4] [--max-requests 200000] \\
        [--http [--http-clients 2]]

Starts driftlab-server itself on 127.0.0.1 (ephemeral port, --port-file, a tokens file with two
owners, a temporary data directory), then runs --clients client threads for --minutes (or until
--max-requests requests in all), each drawing requests from a fixed mix with its own seeded
random generator: small valid jobs (Submit, Watch to the end, GetResult), cancels of running jobs,
and hostile requests that must each get one expected status code — oversized or control-byte
names, a 20 KB "(" unit, a YAML alias bomb and a self-reference in a datasheet, 40 000-deep JSON
and YAML, too many checkpoints, a job over its memory limit, a wrong or malformed token, another
owner's job, garbage bytes as a protobuf request, a FitNoiseModel column name of 20 KB. Every 30 s
it records the server's RSS, open file descriptors and database size (driftlab.db + WAL).

With --http the server also serves its web pages (--http-port) and --http-clients more threads mix
web traffic in, each from its own loopback address (127.0.0.10 + i): signed-in page views (job
list and its polled rows, a job page, a report, a result download, the calibrations, the
catalogue) and hostile requests that must each get one expected status — a wrong token (401, or
429 once the address's tries are spent), another owner's job (404), a cancel without the form
token (403), path traversal (404), 100 KB of headers and a 20 KB request line (400/414 or the
connection closed), a connection that sends nothing (closed by the server within its 10 s request
deadline). The web requests count in --max-requests.

Pass (exit 0): the server never died, every request got its expected status, and the RSS and open
files at the end are within the bounds printed (flat: RSS at most 1.5 x its value after the first
minute plus 64 MiB; open files at most their value after the first minute plus 16). The database
grows only by the results of the valid jobs (printed as bytes per stored job).
"""

import argparse
import http.client
import os
import re
import socket
import pathlib
import random
import subprocess
import sys
import tempfile
import threading
import time

import grpc
from driftlab.v1 import job_pb2, service_pb2, service_pb2_grpc
from google.protobuf import json_format

SMALL_JOB = {
    "name": "soak",
    "motion": {"initial": {"lat_deg": 40.0, "lon_deg": -3.7, "height_m": 650},
               "segments": [{"static": {"duration_s": 20}},
                            {"accelerate": {"acceleration_m_per_s2": 1.0,
                                            "target_speed_m_per_s": 10}},
                            {"constant_velocity": {"duration_s": 20}}]},
    "rate_hz": 20,
    "navigation": {"ned": {"vertical_channel": "TRUTH_HEIGHT"}},
    "sensor": {"preset": "tactical"},
    "monte_carlo": {"runs": 4, "seed": 1, "epoch_interval_s": 5},
}

OK = grpc.StatusCode.OK
INVALID = grpc.StatusCode.INVALID_ARGUMENT
EXHAUSTED = grpc.StatusCode.RESOURCE_EXHAUSTED
UNAUTH = grpc.StatusCode.UNAUTHENTICATED
NOT_FOUND = grpc.StatusCode.NOT_FOUND


def job(**changes):
    spec = json_format.ParseDict(SMALL_JOB, job_pb2.Job())
    for key, value in changes.items():
        setattr(spec, key, value)
    return spec


def alias_bomb():
    text = "a0: &a0 [x, x, x, x, x, x, x, x, x]\n"
    for level in range(1, 9):
        prev = f"*a{level - 1}"
        text += f"a{level}: &a{level} [" + ", ".join([prev] * 9) + "]\n"
    return text


class Soak:
    def __init__(self, args, port, tokens):
        self.args = args
        self.address = f"127.0.0.1:{port}"
        self.tokens = tokens
        self.lock = threading.Lock()
        self.requests = 0
        self.counts = {}
        self.failures = []
        self.jobs_stored = 0
        self.stop = threading.Event()
        self.finished = {0: [], 1: []}  # job ids of each owner that finished, for web traffic

    def call(self, kind, expected, function):
        try:
            function()
            code = OK
        except grpc.RpcError as error:
            code = error.code()
            details = error.details() or ""
        else:
            details = ""
        with self.lock:
            self.requests += 1
            self.counts[kind] = self.counts.get(kind, 0) + 1
            if self.requests >= self.args.max_requests:
                self.stop.set()
            if code != expected:
                self.failures.append(f"{kind}: {code.name} (expected {expected.name}): "
                                     f"{details[:200]}")
                if code == grpc.StatusCode.UNAVAILABLE:
                    self.stop.set()
            elif "\n" in details or len(details) > 4096:
                self.failures.append(f"{kind}: message not one bounded line ({len(details)} B)")

    def client(self, index):
        rng = random.Random(1000 + index)  # seeds fixed before the first run
        owner = index % 2
        metadata = (("authorization", f"Bearer {self.tokens[owner]}"),)
        other = (("authorization", f"Bearer {self.tokens[1 - owner]}"),)
        channel = grpc.insecure_channel(self.address,
                                        options=[("grpc.max_receive_message_length", -1)])
        jobs = service_pb2_grpc.JobsStub(channel)
        calibration = service_pb2_grpc.CalibrationStub(channel)
        raw_submit = channel.unary_unary("/driftlab.v1.Jobs/Submit")
        mine = []
        timeout = 120.0

        def valid_job():
            status = jobs.Submit(service_pb2.SubmitJobRequest(job=job(), seed=rng.randrange(1 << 32)),
                                 metadata=metadata, timeout=timeout)
            for _ in jobs.Watch(service_pb2.JobRef(job_id=status.job_id), metadata=metadata,
                                timeout=timeout):
                pass
            jobs.GetResult(service_pb2.JobRef(job_id=status.job_id), metadata=metadata,
                           timeout=timeout)
            mine.append(status.job_id)
            with self.lock:
                self.jobs_stored += 1
                self.finished[owner].append(status.job_id)
                del self.finished[owner][:-10]

        def cancel_job():
            big = job()
            big.monte_carlo.runs = 200
            status = jobs.Submit(service_pb2.SubmitJobRequest(job=big), metadata=metadata,
                                 timeout=timeout)
            jobs.Cancel(service_pb2.JobRef(job_id=status.job_id), metadata=metadata,
                        timeout=timeout)
            with self.lock:
                self.jobs_stored += 1

        def submit(spec, md=metadata):
            return lambda: jobs.Submit(service_pb2.SubmitJobRequest(job=spec), metadata=md,
                                       timeout=timeout)

        def datasheet(text):
            return lambda: calibration.ConvertDatasheet(
                service_pb2.ConvertDatasheetRequest(yaml=text), metadata=metadata, timeout=timeout)

        def fit_with_column(name):
            def requests():
                settings = service_pb2.FitNoiseModelRequest()
                settings.settings.rate_hz = 100.0
                settings.settings.columns.append(name)
                yield settings
            return lambda: calibration.FitNoiseModel(requests(), metadata=metadata,
                                                     timeout=timeout)

        many_checkpoints = job()
        many_checkpoints.monte_carlo.checkpoint_times_s.extend(
            [1.0 + k * 1e-4 for k in range(100001)])
        memory_hog = job()
        memory_hog.rate_hz = 2000
        memory_hog.motion.segments[0].static.duration_s = 99900  # 2e8 samples: ~9.6 GB
        memory_hog.monte_carlo.runs = 1
        cases = [
            ("valid job", OK, valid_job, 1),
            ("cancel", OK, cancel_job, 1),
            ("name 300 B", INVALID, submit(job(name="n" * 300)), 1),
            ("name with control bytes (escaped in the log)", OK, submit(job(name="a\n\x1b[31mINJECTED")), 1),
            ("too many checkpoints", INVALID, submit(many_checkpoints), 1),
            ("memory over the limit", EXHAUSTED, submit(memory_hog), 1),
            ("wrong token", UNAUTH, submit(job(), (("authorization", "Bearer nope"),)), 1),
            ("another owner's job", NOT_FOUND,
             lambda: jobs.Get(service_pb2.JobRef(job_id=mine[-1] if mine else "x"),
                              metadata=other, timeout=timeout), 1),
            ("unknown job", NOT_FOUND,
             lambda: jobs.Cancel(service_pb2.JobRef(job_id="no-such-job"), metadata=metadata,
                                 timeout=timeout), 1),
            ("garbage protobuf", INVALID,
             lambda: raw_submit(b"\xff" * 64,
                                metadata=metadata, timeout=timeout), 1),
            ("datasheet 20 KB (", INVALID,
             datasheet("gyro:\n  arw: \"0.1 " + "(" * 20000 + "deg\"\n"), 1),
            ("datasheet alias bomb", INVALID, datasheet(alias_bomb()), 1),
            ("datasheet 40000-deep", INVALID, datasheet("[" * 40000 + "]" * 40000), 1),
            ("noise-fit column 20 KB", INVALID, fit_with_column("gyro_x_" + "(" * 20000), 1),
        ]
        weights = [case[3] for case in cases]
        # Paced at --rate requests/s per client (0: as fast as the server answers).
        next_at = time.monotonic()
        while not self.stop.is_set():
            kind, expected, function, _ = rng.choices(cases, weights)[0]
            self.call(kind, expected, function)
            if self.args.rate > 0:
                next_at += 1.0 / self.args.rate
                self.stop.wait(timeout=max(0.0, next_at - time.monotonic()))
        channel.close()


class WebClient:
    """Web traffic of one simulated browser from its own loopback address (--http)."""

    def __init__(self, soak, port, index, token, other_token):
        self.soak = soak
        self.port = port
        self.address = f"127.0.0.{10 + index}"
        self.token = token
        self.other_token = other_token
        self.rng = random.Random(2000 + index)  # seeds fixed before the first run
        self.cookie = None
        self.csrf = None

    def request(self, method, path, body=None, headers=None, cookie=True):
        connection = http.client.HTTPConnection("127.0.0.1", self.port, timeout=60,
                                                source_address=(self.address, 0))
        all_headers = dict(headers or {})
        if cookie and self.cookie:
            all_headers["Cookie"] = self.cookie
        if body is not None:
            all_headers["Content-Type"] = "application/x-www-form-urlencoded"
        try:
            connection.request(method, path, body, all_headers)
            response = connection.getresponse()
            data = response.read()
            return response.status, response.getheader("Set-Cookie"), data
        finally:
            connection.close()

    def sign_in(self):
        status, set_cookie, _ = self.request("POST", "/signin", f"token={self.token}",
                                             cookie=False)
        if status != 303 or not set_cookie:
            raise RuntimeError(f"sign-in answered {status}")
        self.cookie = set_cookie.split(";")[0]
        _, _, page = self.request("GET", "/jobs")
        match = re.search(rb'name="csrf" value="([0-9a-f]{64})"', page)
        self.csrf = match.group(1).decode() if match else ""

    def raw(self, data, wait_s=15.0):
        """Sends data on a new connection; the status the server answers (0: closed without an
        answer) once it has closed the connection (bounded by wait_s)."""
        with socket.create_connection(("127.0.0.1", self.port), timeout=wait_s,
                                      source_address=(self.address, 0)) as sock:
            try:
                sock.sendall(data)
            except OSError:
                pass
            received = b""
            deadline = time.monotonic() + wait_s
            while time.monotonic() < deadline:
                try:
                    chunk = sock.recv(65536)
                except OSError:
                    break
                if not chunk:
                    break
                received += chunk
            match = re.match(rb"HTTP/1\.1 (\d{3})", received)
            return int(match.group(1)) if match else 0

    def run(self, own_jobs, other_jobs):
        self.sign_in()
        soak = self.soak

        def get(path, expected):
            def action():
                status, _, _ = self.request("GET", path())
                if status not in expected:
                    raise AssertionError(f"GET {path()} answered {status}")
            return action

        def own():
            return own_jobs[-1] if own_jobs else "job-" + "0" * 24

        def wrong_token():
            status, _, _ = self.request("POST", "/signin", "token=wrong-" + str(self.rng.random()),
                                        cookie=False)
            if status not in (401, 429):
                raise AssertionError(f"wrong token answered {status}")

        def other_owner():
            if other_jobs:
                for suffix in ("", "/report.html", "/result.json", "/job.json", "/status"):
                    status, _, _ = self.request("GET", f"/jobs/{other_jobs[-1]}{suffix}")
                    if status != 404:
                        raise AssertionError(f"another owner's job{suffix} answered {status}")

        def cancel_without_token():
            status, _, _ = self.request("POST", f"/jobs/{own()}/cancel", "csrf=")
            if status != 403:
                raise AssertionError(f"cancel without the form token answered {status}")

        def huge_headers():
            head = b"GET /jobs HTTP/1.1\r\nHost: x\r\n" + b"".join(
                b"X-Filler-%d: %s\r\n" % (i, b"a" * 90) for i in range(1000)) + b"\r\n"
            if self.raw(head) not in (0, 400):
                raise AssertionError("100 KB of headers were not refused")
            if self.raw(b"GET /" + b"p" * 20000 + b" HTTP/1.1\r\nHost: x\r\n\r\n") not in (0, 414):
                raise AssertionError("a 20 KB request line was not refused")

        def silent():
            started = time.monotonic()
            self.raw(b"", wait_s=20.0)
            if time.monotonic() - started > 15.0:
                raise AssertionError("a silent connection was kept past the request deadline")

        cases = [
            ("web: job list", get(lambda: "/jobs", (200,)), 4),
            ("web: polled rows", get(lambda: "/jobs/rows", (200,)), 8),
            ("web: job page", get(lambda: f"/jobs/{own()}", (200, 404)), 4),
            ("web: report", get(lambda: f"/jobs/{own()}/report.html", (200, 404, 409)), 1),
            ("web: result download", get(lambda: f"/jobs/{own()}/result.json", (200, 404, 409)), 1),
            ("web: calibrations", get(lambda: "/calibrations", (200,)), 1),
            ("web: catalogue", get(lambda: "/catalog/tactical", (200,)), 1),
            ("web: path traversal", get(lambda: "/static/..%2f..%2f..%2fetc%2fpasswd", (404,)), 1),
            ("web: wrong token", wrong_token, 1),
            ("web: another owner's job", other_owner, 1),
            ("web: cancel without form token", cancel_without_token, 1),
            ("web: huge headers", huge_headers, 1),
            ("web: silent connection", silent, 0.2),
        ]
        weights = [case[2] for case in cases]
        next_at = time.monotonic()
        while not soak.stop.is_set():
            kind, action, _ = self.rng.choices(cases, weights)[0]
            try:
                action()
                failure = None
            except Exception as error:  # every unexpected answer is a failure of the soak
                failure = f"{kind}: {error}"
            with soak.lock:
                soak.requests += 1
                soak.counts[kind] = soak.counts.get(kind, 0) + 1
                if soak.requests >= soak.args.max_requests:
                    soak.stop.set()
                if failure:
                    soak.failures.append(failure[:300])
            if soak.args.rate > 0:
                next_at += 1.0 / soak.args.rate
                soak.stop.wait(timeout=max(0.0, next_at - time.monotonic()))


def sample(pid, data_dir):
    rss_kib = 0
    with open(f"/proc/{pid}/status") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                rss_kib = int(line.split()[1])
    files = len(os.listdir(f"/proc/{pid}/fd"))
    db = sum(p.stat().st_size for p in pathlib.Path(data_dir).glob("driftlab.db*"))
    return rss_kib, files, db


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--server-binary", required=True)
    parser.add_argument("--minutes", type=float, default=30.0)
    parser.add_argument("--clients", type=int, default=4)
    parser.add_argument("--max-requests", type=int, default=200000)
    parser.add_argument("--rate", type=float, default=10.0,
                        help="requests per second per client (0: unpaced)")
    parser.add_argument("--http", action="store_true",
                        help="serve the web pages and mix web traffic in")
    parser.add_argument("--http-clients", type=int, default=2)
    args = parser.parse_args()

    with tempfile.TemporaryDirectory(prefix="driftlab_soak_") as tmp:
        tmp = pathlib.Path(tmp)
        tokens = ["soak-token-alice", "soak-token-bob"]
        lines = []
        for owner, token in zip(["alice", "bob"], tokens):
            digest = subprocess.run([args.server_binary, "hash-token", token], check=True,
                                    capture_output=True, text=True).stdout.strip()
            lines.append(f"{owner} {digest}")
        (tmp / "tokens.txt").write_text("\n".join(lines) + "\n")
        data = tmp / "data"
        port_file = tmp / "port"
        http_port_file = tmp / "http-port"
        log = open(tmp / "server.log", "w")
        web = ["--http-port", "0", "--http-port-file", str(http_port_file)] if args.http else []
        server = subprocess.Popen(
            [args.server_binary, "--listen", "127.0.0.1:0", "--data", str(data), "--tokens",
             str(tmp / "tokens.txt"), "--port-file", str(port_file), "--max-queued-jobs", "1000"]
            + web, stdout=log, stderr=subprocess.STDOUT)
        for _ in range(300):  # bounded wait for the port file (100 ms steps: 30 s)
            if port_file.exists() or server.poll() is not None:
                break
            time.sleep(0.1)
        if not port_file.exists():
            sys.exit("server did not start")
        soak = Soak(args, int(port_file.read_text()), tokens)
        start = sample(server.pid, data)
        threads = [threading.Thread(target=soak.client, args=(i,)) for i in range(args.clients)]
        if args.http:
            http_port = int(http_port_file.read_text())
            for i in range(args.http_clients):
                owner = i % 2
                web_client = WebClient(soak, http_port, i, tokens[owner], tokens[1 - owner])
                threads.append(threading.Thread(
                    target=web_client.run,
                    args=(soak.finished[owner], soak.finished[1 - owner])))
        t0 = time.monotonic()
        for thread in threads:
            thread.start()
        samples = [(0.0, *start)]
        deadline = t0 + 60.0 * args.minutes
        while not soak.stop.wait(timeout=min(30.0, max(0.0, deadline - time.monotonic()))):
            if server.poll() is not None:
                soak.failures.append(f"server exited with status {server.returncode}")
                break
            samples.append((time.monotonic() - t0, *sample(server.pid, data)))
            print(f"t={samples[-1][0]:7.0f} s  requests={soak.requests:7d}  "
                  f"rss={samples[-1][1] / 1024:7.1f} MiB  fds={samples[-1][2]:4d}  "
                  f"db={samples[-1][3] / 1e6:8.2f} MB", flush=True)
            if time.monotonic() >= deadline:
                break
        soak.stop.set()
        for thread in threads:
            thread.join(timeout=300)
        alive = server.poll() is None
        end = sample(server.pid, data) if alive else (0, 0, 0)
        server.terminate()
        server.wait(timeout=60)

        after_warmup = next((s for s in samples if s[0] >= 60.0), samples[-1])
        rss_bound = 1.5 * after_warmup[1] + 64 * 1024
        fd_bound = after_warmup[2] + 16
        print(f"requests: {soak.requests} in {time.monotonic() - t0:.0f} s from {args.clients} "
              f"gRPC clients" + (f" and {args.http_clients} web clients" if args.http else ""))
        for kind, count in sorted(soak.counts.items()):
            print(f"  {kind:28s} {count:7d}")
        print(f"RSS: start {start[0] / 1024:.1f} MiB, after 1 min {after_warmup[1] / 1024:.1f} MiB,"
              f" end {end[0] / 1024:.1f} MiB (bound {rss_bound / 1024:.1f} MiB)")
        print(f"open files: start {start[1]}, after 1 min {after_warmup[2]}, end {end[1]} "
              f"(bound {fd_bound})")
        growth = end[2] - start[2]
        per_job = growth / soak.jobs_stored if soak.jobs_stored else 0
        print(f"database: start {start[2]} B, end {end[2]} B ({soak.jobs_stored} jobs stored, "
              f"{per_job:.0f} B per stored job)")
        failures = list(soak.failures)
        # Job names go into the log escaped: no line may start with the injected text.
        injected = [line for line in (tmp / "server.log").read_text(errors="replace").splitlines()
                    if line.startswith("\x1b[31mINJECTED")]
        if injected:
            failures.append(f"{len(injected)} log lines injected through a job name")
        if not alive:
            failures.append("the server died")
        if alive and end[0] > rss_bound:
            failures.append("RSS grew past its bound")
        if alive and end[1] > fd_bound:
            failures.append("open files grew past their bound")
        for failure in failures[:50]:
            print("FAIL:", failure)
        print("PASS" if not failures else f"FAILED ({len(failures)} problems)")
        return 0 if not failures else 1


if __name__ == "__main__":
    sys.exit(main())
