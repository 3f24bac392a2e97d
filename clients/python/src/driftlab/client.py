"""Client of driftlab-server (proto/driftlab/v1/service.proto): jobs, calibration, catalogue.

    import driftlab
    with driftlab.connect("127.0.0.1:50051") as client:
        result = client.run("examples/car_drive.json", runs=50, progress=True)
        print(result.std[-1, driftlab.component_index("horizontal_position_m")])

Jobs are dicts in the protobuf JSON mapping, JSON job-file paths or ``driftlab.v1.Job``
messages. Server errors arrive as :class:`DriftlabError` with the gRPC status code and the
server's message (INVALID_ARGUMENT names the field path, the value and the allowed range).
"""

from __future__ import annotations

import os
import pathlib
import sys
from dataclasses import dataclass
from typing import (Callable, Dict, Iterable, Iterator, List, Optional, Sequence, Union)

import grpc
import numpy as np

from driftlab.jobs import JobLike, load_job
from driftlab.results import Result
from driftlab.v1 import calibration_pb2
from driftlab.v1 import job_pb2
from driftlab.v1 import result_pb2
from driftlab.v1 import service_pb2
from driftlab.v1 import service_pb2_grpc

FINAL_STATES = (service_pb2.SUCCEEDED, service_pb2.FAILED, service_pb2.CANCELLED)

# The server takes at most this many bytes of sample rows per streamed message (the CLI's
# kMaxRowsMessageBytes, clients/cli/remote.h); 64 bytes for the message's own framing.
_MAX_ROWS_MESSAGE_BYTES = 1 << 20
_ROWS_ALLOWANCE_BYTES = 64


class DriftlabError(Exception):
    """A failed call: ``code`` is the grpc.StatusCode, ``details`` the server's message."""

    def __init__(self, code: grpc.StatusCode, details: str, server: str):
        self.code = code
        self.details = details
        self.server = server
        super().__init__(f"{server}: {code.name}: {details}")


class JobFailed(Exception):
    """A job that ended FAILED or CANCELLED; ``status`` is its final JobStatus."""

    def __init__(self, status: service_pb2.JobStatus):
        self.status = status
        state = service_pb2.JobState.Name(status.state)
        super().__init__(f"job {status.job_id} {state}: {status.error}")


@dataclass(frozen=True)
class Progress:
    """A job's progress: runs and IMU samples done of the total, wall time of the attempt."""

    job_id: str
    state: str  # QUEUED, RUNNING, SUCCEEDED, FAILED, CANCELLED
    runs_done: int
    runs_total: int
    samples_done: int
    samples_total: int
    elapsed_s: float

    @property
    def fraction(self) -> float:
        return self.runs_done / self.runs_total if self.runs_total else 0.0

    @classmethod
    def from_status(cls, status: service_pb2.JobStatus) -> "Progress":
        return cls(job_id=status.job_id, state=service_pb2.JobState.Name(status.state),
                   runs_done=status.runs_done, runs_total=status.runs_total,
                   samples_done=status.samples_done, samples_total=status.samples_total,
                   elapsed_s=status.elapsed_s)


ProgressCallback = Callable[[Progress], None]


class ProgressPrinter:
    """A progress callback that prints a line at every 10 % of the runs on ``stream``
    (stderr), as ``driftlab run`` does when stderr is not a terminal."""

    def __init__(self, stream=None):
        self.stream = stream or sys.stderr
        self.last_decile = -1

    def __call__(self, progress: Progress) -> None:
        if not progress.runs_total:
            return
        decile = 10 * progress.runs_done // progress.runs_total
        if decile > self.last_decile:
            self.last_decile = decile
            print(f"progress: {10 * decile:3d}% ({progress.runs_done}/{progress.runs_total} runs, "
                  f"{progress.elapsed_s:.1f} s)", file=self.stream, flush=True)


def _progress_callback(progress: Union[None, bool, ProgressCallback]) -> Optional[ProgressCallback]:
    if progress is True:
        return ProgressPrinter()
    if progress in (None, False):
        return None
    return progress  # type: ignore[return-value]


def _table(data, columns: Optional[Sequence[str]]):
    """(column names, float64 row-major array) from a DataFrame, a 2-D array with ``columns``, or
    a CSV path (header row of names, as `driftlab calibrate`/`allan` read)."""
    if hasattr(data, "columns") and hasattr(data, "to_numpy"):  # pandas DataFrame
        names = [str(c) for c in data.columns] if columns is None else list(columns)
        values = data.to_numpy(dtype=float)
    elif isinstance(data, (str, os.PathLike)):
        path = pathlib.Path(data)
        with path.open() as handle:
            header = handle.readline().strip()
        names = [c.strip() for c in header.split(",")] if columns is None else list(columns)
        values = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    else:
        if columns is None:
            raise ValueError("columns: give the column names of a 2-D array")
        names = list(columns)
        values = np.asarray(data, dtype=float)
        if values.ndim != 2:
            raise ValueError(f"data: a 2-D array (rows x {len(names)} columns), got shape "
                             f"{values.shape}")
    if values.shape[1] != len(names):
        raise ValueError(f"columns: {len(names)} names for {values.shape[1]} data columns")
    return names, np.ascontiguousarray(values, dtype=float)


def _row_chunks(values: np.ndarray) -> Iterator[List[float]]:
    columns = max(1, values.shape[1])
    rows = max(1, (_MAX_ROWS_MESSAGE_BYTES - _ROWS_ALLOWANCE_BYTES) // 8 // columns)
    for start in range(0, values.shape[0], rows):
        yield values[start:start + rows].ravel().tolist()


class Client:
    """A connection to one driftlab-server. Use :func:`connect` to make one."""

    def __init__(self, server: str, channel: grpc.Channel, token: Optional[str] = None):
        self.server = server
        self._channel = channel
        self._jobs = service_pb2_grpc.JobsStub(channel)
        self._calibration = service_pb2_grpc.CalibrationStub(channel)
        self._catalog = service_pb2_grpc.CatalogStub(channel)
        self._metadata = (("authorization", f"Bearer {token}"),) if token else ()

    def close(self) -> None:
        self._channel.close()

    def __enter__(self) -> "Client":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def _call(self, method, request, timeout_s: Optional[float] = None):
        try:
            return method(request, metadata=self._metadata, timeout=timeout_s)
        except grpc.RpcError as error:
            raise DriftlabError(error.code(), error.details(), self.server) from None

    # -- jobs ----------------------------------------------------------------------------------
    def submit(self, job: JobLike, runs: Optional[int] = None, seed: Optional[int] = None,
               shard: Optional[str] = None, deadline_s: Optional[float] = None) -> str:
        """Queues the job; ``runs``, ``seed`` and ``shard`` ("i/K") override its monte_carlo
        section as the CLI's options do. Returns the job id."""
        request = service_pb2.SubmitJobRequest(job=load_job(job))
        if runs is not None:
            request.runs = runs
        if seed is not None:
            request.seed = seed
        if shard is not None:
            request.shard = shard
        if deadline_s is not None:
            request.deadline_s = deadline_s
        return self._call(self._jobs.Submit, request).job_id

    def status(self, job_id: str) -> service_pb2.JobStatus:
        """The job's current JobStatus."""
        return self._call(self._jobs.Get, service_pb2.JobRef(job_id=job_id))

    def watch(self, job_id: str, timeout_s: Optional[float] = None
              ) -> Iterator[service_pb2.JobStatus]:
        """Yields the job's JobStatus messages (progress, then the final state) until the
        server ends the stream. ``timeout_s`` bounds the whole stream (DriftlabError
        DEADLINE_EXCEEDED)."""
        stream = self._jobs.Watch(service_pb2.JobRef(job_id=job_id), metadata=self._metadata,
                                  timeout=timeout_s)
        try:
            for status in stream:
                yield status
        except grpc.RpcError as error:
            raise DriftlabError(error.code(), error.details(), self.server) from None
        finally:
            stream.cancel()

    def wait(self, job_id: str, timeout_s: Optional[float] = None,
             progress: Union[None, bool, ProgressCallback] = None) -> service_pb2.JobStatus:
        """Blocks until the job is final and returns its final JobStatus; ``progress`` is
        called with a :class:`Progress` per update (True: print a line every 10 %).
        TimeoutError after ``timeout_s`` seconds (the job goes on)."""
        callback = _progress_callback(progress)
        last = None
        try:
            for last in self.watch(job_id, timeout_s=timeout_s):
                if callback:
                    callback(Progress.from_status(last))
        except DriftlabError as error:
            if error.code == grpc.StatusCode.DEADLINE_EXCEEDED:
                raise TimeoutError(f"job {job_id} not finished after {timeout_s} s") from None
            raise
        if last is None or last.state not in FINAL_STATES:
            last = self.status(job_id)
        return last

    def cancel(self, job_id: str) -> service_pb2.JobStatus:
        """Cancels a queued or running job; returns its final JobStatus."""
        return self._call(self._jobs.Cancel, service_pb2.JobRef(job_id=job_id))

    def jobs(self, states: Iterable[int] = ()) -> Iterator[service_pb2.JobStatus]:
        """This token's jobs, newest first; ``states`` filters by JobState (service_pb2.RUNNING...)."""
        request = service_pb2.ListJobsRequest(states=list(states))
        while True:
            page = self._call(self._jobs.List, request)
            yield from page.jobs
            if not page.next_page_token:
                return
            request.page_token = page.next_page_token

    def result_message(self, job_id: str) -> result_pb2.JobResult:
        """The JobResult message of a SUCCEEDED job (DriftlabError FAILED_PRECONDITION
        otherwise)."""
        return self._call(self._jobs.GetResult, service_pb2.JobRef(job_id=job_id))

    def result(self, job_id: str) -> Result:
        """The result of a SUCCEEDED job as arrays (:class:`driftlab.Result`)."""
        return Result(self.result_message(job_id))

    def run(self, job: JobLike, runs: Optional[int] = None, seed: Optional[int] = None,
            timeout_s: Optional[float] = None,
            progress: Union[None, bool, ProgressCallback] = None) -> Result:
        """Submit, wait (with ``progress``) and fetch the result; JobFailed when the job ends
        FAILED or CANCELLED."""
        job_id = self.submit(job, runs=runs, seed=seed)
        final = self.wait(job_id, timeout_s=timeout_s, progress=progress)
        if final.state != service_pb2.SUCCEEDED:
            raise JobFailed(final)
        return self.result(job_id)

    def metrics(self) -> service_pb2.ServerMetrics:
        return self._call(self._jobs.GetMetrics, service_pb2.GetMetricsRequest())

    # -- calibration ---------------------------------------------------------------------------
    def calibrate(self, kind: str, data, columns: Optional[Sequence[str]] = None,
                  rate_hz: Optional[float] = None, lat_deg: float = 0.0, height_m: float = 0.0,
                  loss: str = "", data_name: str = "", timeout_s: Optional[float] = None,
                  **settings) -> calibration_pb2.CalibrationResult:
        """Fits a calibration as ``driftlab calibrate KIND DATA.csv`` does. ``kind``: accel,
        gyro, imu or reference; ``data``: a CSV path, a DataFrame, or a 2-D array with
        ``columns`` (t_s, gx, gy, gz, ax, ay, az ...). Further CalibrateSettings fields
        (init_static_s, window_s, min_pose_s, matrix, input_unit, output_unit) as keywords."""
        names, values = _table(data, columns)
        first = service_pb2.CalibrateSettings(kind=kind, lat_deg=lat_deg, height_m=height_m,
                                              loss=loss, columns=names,
                                              data_name=data_name or _data_name(data),
                                              **settings)
        if rate_hz is not None:
            first.rate_hz = rate_hz

        def requests():
            yield service_pb2.CalibrateRequest(settings=first)
            for chunk in _row_chunks(values):
                yield service_pb2.CalibrateRequest(rows=service_pb2.SampleRows(values=chunk))

        return self._call(self._calibration.Calibrate, requests(), timeout_s)

    def fit_noise_model(self, data, rate_hz: float, columns: Optional[Sequence[str]] = None,
                        bias_model: str = "", datasheet_yaml: str = "",
                        timeout_s: Optional[float] = None,
                        **settings) -> calibration_pb2.NoiseModelFit:
        """Allan deviation and noise-model fit of a static recording, as ``driftlab allan
        DATA.csv --rate HZ --fit``. Columns named with their unit suffix (omega_x_rad_per_s,
        gyro_deg_per_h, ...). Further NoiseFitSettings fields (points_per_octave,
        flicker_tau_min_s, flicker_tau_max_s) as keywords."""
        names, values = _table(data, columns)
        first = service_pb2.NoiseFitSettings(rate_hz=rate_hz, columns=names,
                                             bias_model=bias_model,
                                             datasheet_yaml=datasheet_yaml, **settings)

        def requests():
            yield service_pb2.FitNoiseModelRequest(settings=first)
            for chunk in _row_chunks(values):
                yield service_pb2.FitNoiseModelRequest(rows=service_pb2.SampleRows(values=chunk))

        return self._call(self._calibration.FitNoiseModel, requests(), timeout_s)

    def convert_datasheet(self, datasheet: Union[str, os.PathLike]
                          ) -> service_pb2.ConvertDatasheetResponse:
        """A datasheet summary (YAML text or a path to one, the format ``driftlab datasheet``
        reads) as a sensor model, with each figure as printed and in SI."""
        text = datasheet
        if isinstance(datasheet, os.PathLike) or (isinstance(datasheet, str)
                                                  and "\n" not in datasheet
                                                  and pathlib.Path(datasheet).is_file()):
            text = pathlib.Path(datasheet).read_text()
        return self._call(self._calibration.ConvertDatasheet,
                          service_pb2.ConvertDatasheetRequest(yaml=str(text)))

    # -- catalogue -----------------------------------------------------------------------------
    def presets(self) -> List[service_pb2.PresetSummary]:
        """The IMU presets the server knows (name, grade, description, source)."""
        return list(self._call(self._catalog.ListPresets, service_pb2.ListPresetsRequest()).presets)

    def preset(self, name: str) -> service_pb2.Preset:
        """One preset with every sensor parameter explicit (datasheet units)."""
        return self._call(self._catalog.GetPreset, service_pb2.GetPresetRequest(name=name))

    def examples(self) -> Dict[str, job_pb2.Job]:
        """The example jobs the server can run as they are, by name."""
        response = self._call(self._catalog.ListExamples, service_pb2.ListExamplesRequest())
        return {example.name: example.job for example in response.examples}


def _data_name(data) -> str:
    return pathlib.Path(data).name if isinstance(data, (str, os.PathLike)) else "python"


def connect(server: str, token: Optional[str] = None, tls_ca: Optional[str] = None,
            wait_s: Optional[float] = None) -> Client:
    """A Client of the driftlab-server at ``server`` (HOST:PORT). ``token``: bearer token
    (default: environment DRIFTLAB_TOKEN); ``tls_ca``: PEM file of the CA that signed the
    server's certificate (TLS), else a plaintext channel. ``wait_s``: wait up to that long for
    the channel to be ready (ConnectionError after it); None connects lazily."""
    token = token if token is not None else os.environ.get("DRIFTLAB_TOKEN") or None
    # Results of large jobs exceed gRPC's default 4 MB receive limit; the server bounds them.
    options = [("grpc.max_receive_message_length", -1)]
    if tls_ca:
        credentials = grpc.ssl_channel_credentials(
            root_certificates=pathlib.Path(tls_ca).read_bytes())
        channel = grpc.secure_channel(server, credentials, options=options)
    else:
        channel = grpc.insecure_channel(server, options=options)
    if wait_s is not None:
        try:
            grpc.channel_ready_future(channel).result(timeout=wait_s)
        except grpc.FutureTimeoutError:
            channel.close()
            raise ConnectionError(f"{server}: not reachable within {wait_s} s") from None
    return Client(server, channel, token)
