"""Local mode: runs the ``driftlab`` binary in-process on this machine, for users without a
server. The same engine and the same bits as a server (a job with a given seed gives the same
result either way); progress comes from the binary's progress lines.

    runner = driftlab.LocalRunner()                    # $DRIFTLAB_BINARY, or `driftlab` on PATH
    result = runner.run("examples/car_drive.json", runs=50, progress=True)

YAML job files work here (the binary reads them); dicts and Job messages are written to a
temporary JSON job file first.
"""

from __future__ import annotations

import os
import pathlib
import re
import shutil
import subprocess
import tempfile
import threading
from typing import List, Optional, Sequence, Union

from driftlab.client import Progress, ProgressCallback, _progress_callback
from driftlab.jobs import JobLike, job_json
from driftlab.results import Result

# `driftlab run`'s progress line when stderr is not a terminal (clients/cli/progress.h).
_PROGRESS_LINE = re.compile(
    r"^progress:\s+(\d+)% \((\d+)/(\d+) runs, ([0-9.]+) s, ([0-9.]+) M samples/s\)$")


class LocalRunError(RuntimeError):
    """``driftlab`` exited non-zero: ``status`` 2 for a bad job (its message names the field),
    1 for anything else; ``message`` is what it printed on stderr, progress lines left out."""

    def __init__(self, status: int, message: str, command: Sequence[str]):
        self.status = status
        self.message = message
        self.command = list(command)
        super().__init__(f"driftlab exited with status {status}: {message.strip()}")


def find_binary(binary: Union[None, str, os.PathLike] = None) -> pathlib.Path:
    """The ``driftlab`` binary: ``binary``, else $DRIFTLAB_BINARY, else ``driftlab`` on PATH."""
    candidate = binary or os.environ.get("DRIFTLAB_BINARY") or shutil.which("driftlab")
    if not candidate:
        raise FileNotFoundError("driftlab binary not found: pass binary=, set DRIFTLAB_BINARY, "
                                "or put build/driftlab on PATH")
    path = pathlib.Path(candidate)
    if not (path.is_file() and os.access(path, os.X_OK)):
        raise FileNotFoundError(f"{path}: not an executable driftlab binary")
    return path


class LocalRunner:
    """Runs jobs with a local ``driftlab`` binary (see :func:`find_binary`)."""

    def __init__(self, binary: Union[None, str, os.PathLike] = None,
                 threads: Optional[int] = None):
        self.binary = find_binary(binary)
        self.threads = threads

    def _command(self, *args: str) -> List[str]:
        return [str(self.binary), *args]

    def run(self, job: JobLike, runs: Optional[int] = None, seed: Optional[int] = None,
            shard: Optional[str] = None, progress: Union[None, bool, ProgressCallback] = None,
            timeout_s: Optional[float] = None) -> Result:
        """``driftlab run JOB --out RESULT`` with the given overrides; the result as arrays.
        LocalRunError when the binary fails, TimeoutError after ``timeout_s`` (the process is
        killed)."""
        callback = _progress_callback(progress)
        with tempfile.TemporaryDirectory(prefix="driftlab-local-") as scratch:
            scratch_dir = pathlib.Path(scratch)
            if isinstance(job, (str, os.PathLike)):
                job_path = pathlib.Path(job)
            else:
                job_path = scratch_dir / "job.json"
                job_path.write_text(job_json(job))
            out = scratch_dir / "result.json"
            command = self._command("run", str(job_path), "--out", str(out))
            if runs is not None:
                command += ["--runs", str(runs)]
            if seed is not None:
                command += ["--seed", str(seed)]
            if shard is not None:
                command += ["--shard", shard]
            if self.threads is not None:
                command += ["--threads", str(self.threads)]
            if callback is None:
                command.append("--quiet")
            self._stream(command, callback, timeout_s, job_path.name)
            return Result.read(out)

    def _stream(self, command: List[str], callback: Optional[ProgressCallback],
                timeout_s: Optional[float], job_name: str) -> List[str]:
        """Runs ``command``, feeding its progress lines to ``callback``; returns its other
        stderr lines."""
        other: List[str] = []
        killed = threading.Event()
        with subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                              text=True) as process:
            timer = None
            if timeout_s is not None:
                def kill():
                    killed.set()
                    process.kill()
                timer = threading.Timer(timeout_s, kill)
                timer.daemon = True
                timer.start()
            try:
                assert process.stderr is not None
                for line in process.stderr:
                    match = _PROGRESS_LINE.match(line.strip())
                    if match is None:
                        other.append(line)
                    elif callback is not None:
                        callback(Progress(job_id=job_name, state="RUNNING",
                                          runs_done=int(match.group(2)),
                                          runs_total=int(match.group(3)), samples_done=0,
                                          samples_total=0, elapsed_s=float(match.group(4))))
                status = process.wait()
            finally:
                if timer is not None:
                    timer.cancel()
        if killed.is_set():
            raise TimeoutError(f"driftlab run not finished after {timeout_s} s (killed)")
        if status != 0:
            raise LocalRunError(status, "".join(other), command)
        return other

    def validate(self, job: JobLike) -> None:
        """``driftlab validate``: returns when the job is valid, LocalRunError (status 2, the
        message naming the field path, value and allowed range) when not."""
        with tempfile.TemporaryDirectory(prefix="driftlab-local-") as scratch:
            job_path = pathlib.Path(job) if isinstance(job, (str, os.PathLike)) else None
            if job_path is None:
                job_path = pathlib.Path(scratch) / "job.json"
                job_path.write_text(job_json(job))
            command = self._command("validate", str(job_path))
            done = subprocess.run(command, capture_output=True, text=True)
            if done.returncode != 0:
                raise LocalRunError(done.returncode, done.stderr, command)

    def version(self) -> str:
        done = subprocess.run(self._command("--version"), capture_output=True, text=True,
                              check=True)
        return done.stdout.strip()
