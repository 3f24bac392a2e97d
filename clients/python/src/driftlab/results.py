"""Monte-Carlo results (driftlab.v1.JobResult) as NumPy arrays and pandas DataFrames.

A result holds, per output epoch, the mean, standard deviation and RMS of 11 error components
(proto/driftlab/v1/result.proto, ErrorComponent: north/east/down position [m], north/east/down
velocity [m/s], roll/pitch/yaw [deg], horizontal and 3-D position [m]) and, at each checkpoint,
percentiles and the per-run values. :class:`Result` gives them as arrays of shape
(epochs, components) and (runs, components), in ErrorComponent order; the protobuf message stays
available as ``Result.message``.
"""

from __future__ import annotations

import os
import pathlib
from dataclasses import dataclass
from typing import Any, Dict, Optional, Tuple, Union

import numpy as np
from google.protobuf import json_format

from driftlab.v1 import result_pb2

# ErrorComponent names in enum order (values 1..11), lower case as in the gate's metric names.
COMPONENTS: Tuple[str, ...] = tuple(
    result_pb2.ErrorComponent.Name(value).lower()
    for value in sorted(result_pb2.ErrorComponent.values())
    if value != result_pb2.ERROR_COMPONENT_UNSPECIFIED)

# Per-epoch statistics of ComponentStatistics, in the order Result.statistics() returns them.
EPOCH_STATISTICS: Tuple[str, ...] = ("mean", "std", "rms", "std_ci95_low", "std_ci95_high",
                                     "rms_ci95_low", "rms_ci95_high")
PERCENTILES: Tuple[str, ...] = ("p50", "p68", "p95", "p99", "max_abs")


def component_index(name: str) -> int:
    """Index of an error component (``"horizontal_position_m"``, case-insensitive) in the arrays."""
    key = name.lower()
    if key not in COMPONENTS:
        raise KeyError(f"unknown error component {name!r}; one of {', '.join(COMPONENTS)}")
    return COMPONENTS.index(key)


def _require_pandas():
    try:
        import pandas
    except ImportError:
        raise ImportError("DataFrames need pandas (Debian: python3-pandas; "
                          "pip: driftlab[pandas])") from None
    return pandas


def _check_components(listed, where: str) -> None:
    names = tuple(result_pb2.ErrorComponent.Name(c.component).lower() for c in listed)
    if names != COMPONENTS:
        raise ValueError(f"{where}: components {names} are not the 11 ErrorComponents in order")


@dataclass(frozen=True)
class Checkpoint:
    """The per-run picture at one time (Checkpoint in result.proto): percentiles of |error| per
    component, CEP50/CEP95/2DRMS [m], and the per-run values when the result keeps them."""

    t_s: float
    percentiles: np.ndarray  # (5, components): p50, p68, p95, p99, max_abs (PERCENTILES)
    cep50_m: float
    cep95_m: float
    drms2_m: float
    run_index: np.ndarray  # (runs,) global run indices, increasing; empty when not kept
    values: np.ndarray  # (runs, components) each run's errors, component units

    def percentile(self, name: str) -> np.ndarray:
        """One row of ``percentiles`` (``"p95"``) over the components."""
        return self.percentiles[PERCENTILES.index(name)]

    def runs_frame(self):
        """pandas DataFrame of the per-run values: index run_index, one column per component."""
        pandas = _require_pandas()
        return pandas.DataFrame(self.values, columns=list(COMPONENTS),
                                index=pandas.Index(self.run_index, name="run_index"))


class Result:
    """A JobResult as arrays. ``t_s`` (epochs,); ``mean``, ``std``, ``rms`` and the 95 %
    confidence bounds (``std_ci95_low`` ...) of shape (epochs, components) in COMPONENTS order;
    ``checkpoints`` in time order; ``predicted_sigma`` (epochs, components) from the covariance
    analysis when the job asked for one (else None); ``average_nees`` (epochs,) for filter jobs
    (NaN where no run was averaged; else None)."""

    def __init__(self, message: result_pb2.JobResult):
        self.message = message
        epochs = message.epochs
        for index, epoch in enumerate(epochs):
            _check_components(epoch.components, f"epochs[{index}]")
        self.t_s = np.array([epoch.t_s for epoch in epochs], dtype=float)
        shape = (len(epochs), len(COMPONENTS))
        for name in EPOCH_STATISTICS:
            array = np.full(shape, np.nan)
            for i, epoch in enumerate(epochs):
                for j, c in enumerate(epoch.components):
                    if c.HasField(name):
                        array[i, j] = getattr(c, name)
            setattr(self, name, array)
        self.checkpoints: Tuple[Checkpoint, ...] = tuple(
            self._checkpoint(index, checkpoint)
            for index, checkpoint in enumerate(message.checkpoints))
        self.predicted_sigma: Optional[np.ndarray] = None
        if message.HasField("covariance") and message.covariance.epochs:
            self.predicted_sigma = np.array([list(e.sigma) for e in message.covariance.epochs],
                                            dtype=float).reshape(-1, len(COMPONENTS))
        self.average_nees: Optional[np.ndarray] = None
        if message.HasField("filter_consistency") and message.filter_consistency.epochs:
            self.average_nees = np.array(
                [e.average_nees if e.HasField("average_nees") else np.nan
                 for e in message.filter_consistency.epochs], dtype=float)

    @staticmethod
    def _checkpoint(index: int, checkpoint) -> Checkpoint:
        _check_components(checkpoint.components, f"checkpoints[{index}]")
        percentiles = np.array([[getattr(c, name) for c in checkpoint.components]
                                for name in PERCENTILES], dtype=float)
        runs = checkpoint.runs
        values = np.array([list(run.values) for run in runs], dtype=float)
        if len(runs) and values.shape != (len(runs), len(COMPONENTS)):
            raise ValueError(f"checkpoints[{index}].runs: each run needs {len(COMPONENTS)} values")
        return Checkpoint(t_s=checkpoint.t_s, percentiles=percentiles,
                          cep50_m=checkpoint.cep50_m, cep95_m=checkpoint.cep95_m,
                          drms2_m=checkpoint.drms2_m,
                          run_index=np.array([run.run_index for run in runs], dtype=np.int64),
                          values=values.reshape(len(runs), len(COMPONENTS)))

    # -- identity ------------------------------------------------------------------------------
    @property
    def name(self) -> str:
        return self.message.job.name

    @property
    def seed(self) -> int:
        return self.message.seed

    @property
    def runs(self) -> int:
        """Total runs of the job (all shards)."""
        return self.message.runs

    @property
    def run_count(self) -> int:
        """Runs in this result (a shard holds fewer than ``runs``)."""
        return self.message.run_count

    @property
    def components(self) -> Tuple[str, ...]:
        return COMPONENTS

    # -- access --------------------------------------------------------------------------------
    def statistic(self, name: str, component: Optional[str] = None) -> np.ndarray:
        """One statistic (EPOCH_STATISTICS) over the epochs: (epochs, components), or (epochs,)
        for one component."""
        if name not in EPOCH_STATISTICS:
            raise KeyError(f"unknown statistic {name!r}; one of {', '.join(EPOCH_STATISTICS)}")
        array = getattr(self, name)
        return array if component is None else array[:, component_index(component)]

    def final(self, name: str = "std") -> Dict[str, float]:
        """The final epoch's statistic per component, e.g. ``final("std")["horizontal_position_m"]``."""
        row = self.statistic(name)[-1]
        return {component: float(value) for component, value in zip(COMPONENTS, row)}

    def checkpoint(self, t_s: Optional[float] = None) -> Checkpoint:
        """The checkpoint at time ``t_s`` (the final one when None); KeyError when there is none."""
        if not self.checkpoints:
            raise KeyError("the result has no checkpoints")
        if t_s is None:
            return self.checkpoints[-1]
        for checkpoint in self.checkpoints:
            if abs(checkpoint.t_s - t_s) <= 1e-9 * max(1.0, abs(t_s)):
                return checkpoint
        raise KeyError(f"no checkpoint at t = {t_s} s; checkpoints at "
                       + ", ".join(f"{c.t_s:g}" for c in self.checkpoints) + " s")

    # -- pandas --------------------------------------------------------------------------------
    def frame(self, name: str = "std"):
        """pandas DataFrame of one statistic: index t_s (epochs), one column per component."""
        pandas = _require_pandas()
        return pandas.DataFrame(self.statistic(name), columns=list(COMPONENTS),
                                index=pandas.Index(self.t_s, name="t_s"))

    def statistics_frame(self):
        """pandas DataFrame of every per-epoch statistic: index t_s, columns (statistic,
        component) as a MultiIndex."""
        pandas = _require_pandas()
        columns = pandas.MultiIndex.from_product([EPOCH_STATISTICS, COMPONENTS],
                                                 names=["statistic", "component"])
        data = np.concatenate([self.statistic(name) for name in EPOCH_STATISTICS], axis=1)
        return pandas.DataFrame(data, columns=columns, index=pandas.Index(self.t_s, name="t_s"))

    def runs_frame(self, t_s: Optional[float] = None):
        """pandas DataFrame of the per-run values at a checkpoint (the final one by default):
        index run_index, one column per component."""
        return self.checkpoint(t_s).runs_frame()

    # -- files ---------------------------------------------------------------------------------
    def to_dict(self) -> Dict[str, Any]:
        """The result as a dict with proto field names (the result file's JSON)."""
        return json_format.MessageToDict(self.message, preserving_proto_field_name=True)

    def write(self, path: Union[str, os.PathLike]) -> pathlib.Path:
        """Writes the result file (JSON, proto field names), readable by ``driftlab report`` and
        ``driftlab gate``."""
        text = json_format.MessageToJson(self.message, preserving_proto_field_name=True, indent=2)
        path = pathlib.Path(path)
        path.write_text(text + "\n")
        return path

    @classmethod
    def read(cls, path: Union[str, os.PathLike]) -> "Result":
        """A result file written by ``driftlab run``/``merge`` or :meth:`write`."""
        return cls.from_json(pathlib.Path(path).read_text())

    @classmethod
    def from_json(cls, text: str) -> "Result":
        message = result_pb2.JobResult()
        # NaN appears in results (the σ of a single run); the JSON mapping spells it "NaN".
        json_format.Parse(text, message)
        return cls(message)

    @classmethod
    def from_dict(cls, data: Dict[str, Any]) -> "Result":
        return cls(json_format.ParseDict(data, result_pb2.JobResult()))

    def __repr__(self) -> str:
        return (f"Result({self.name or '(unnamed)'!r}, seed {self.seed}, runs "
                f"{self.message.first_run}..{self.message.first_run + self.run_count - 1} of "
                f"{self.runs}, {len(self.t_s)} epochs, {len(self.checkpoints)} checkpoints)")
