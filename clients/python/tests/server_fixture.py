"""A driftlab-server for the Python package's tests: started on 127.0.0.1 with an ephemeral port
(--listen 127.0.0.1:0 --port-file F), its data in a temporary directory, stopped with SIGTERM.
Bounded waits only: the port file is polled until a deadline (or until the server exits), then
the gRPC channel's readiness is awaited with a timeout; no sleep is used as synchronisation."""

import pathlib
import signal
import subprocess
import tempfile
import time

import grpc

START_TIMEOUT_S = 30.0
STOP_TIMEOUT_S = 30.0
POLL_INTERVAL_S = 0.02


class ServerProcess:
    def __init__(self, binary, extra_args=()):
        self.binary = str(binary)
        self.extra_args = list(extra_args)
        self._scratch = None
        self.process = None
        self.address = None

    def __enter__(self):
        self._scratch = tempfile.TemporaryDirectory(prefix="driftlab-python-server-")
        tmp = pathlib.Path(self._scratch.name)
        port_file = tmp / "port"
        self.log_path = tmp / "server.log"
        with open(self.log_path, "w") as log:
            self.process = subprocess.Popen(
                [self.binary, "--listen", "127.0.0.1:0", "--data", str(tmp / "data"),
                 "--port-file", str(port_file), *self.extra_args],
                stdout=log, stderr=subprocess.STDOUT)
        deadline = time.monotonic() + START_TIMEOUT_S
        port = None
        while time.monotonic() < deadline:
            if self.process.poll() is not None:
                raise RuntimeError(f"driftlab-server exited with {self.process.returncode}: "
                                   + self.log_path.read_text())
            try:
                text = port_file.read_text().strip()
                if text.isdigit() and int(text) > 0:
                    port = int(text)
                    break
            except FileNotFoundError:
                pass
            time.sleep(POLL_INTERVAL_S)  # polling interval of a bounded wait
        if port is None:
            self.stop()
            raise RuntimeError(f"driftlab-server wrote no port within {START_TIMEOUT_S} s")
        self.address = f"127.0.0.1:{port}"
        with grpc.insecure_channel(self.address) as channel:
            grpc.channel_ready_future(channel).result(timeout=START_TIMEOUT_S)
        return self

    def stop(self):
        """SIGTERM and a bounded wait; returns the exit status (killed after the timeout)."""
        if self.process is None:
            return None
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGTERM)
            try:
                self.process.wait(timeout=STOP_TIMEOUT_S)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        status = self.process.returncode
        self.process = None
        return status

    def __exit__(self, *exc):
        status = self.stop()
        if self._scratch is not None:
            self._scratch.cleanup()
        if status not in (0, None) and exc[0] is None:
            raise RuntimeError(f"driftlab-server exited with {status} after SIGTERM")
