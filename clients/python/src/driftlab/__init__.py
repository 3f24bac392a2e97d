"""driftlab: Python client of driftlab (Monte-Carlo error analysis of inertial navigation).

    import driftlab
    client = driftlab.connect("127.0.0.1:50051")            # a driftlab-server
    result = client.run("examples/car_drive.json", runs=50, progress=True)
    sigma = result.std[-1, driftlab.component_index("horizontal_position_m")]

    result = driftlab.LocalRunner().run("examples/car_drive.json")   # no server: the binary

Results are :class:`Result` objects: NumPy arrays per epoch and component, per-run values at
checkpoints, pandas DataFrames when pandas is installed (``result.frame("std")``,
``result.runs_frame()``). The protobuf modules are ``driftlab.v1.*_pb2``.
"""

from driftlab.client import (FINAL_STATES, Client, DriftlabError, JobFailed, Progress,
                             ProgressPrinter, connect)
from driftlab.jobs import job_json, load_job
from driftlab.local import LocalRunError, LocalRunner, find_binary
from driftlab.plot import plot_envelopes, summary_lines
from driftlab.results import (COMPONENTS, EPOCH_STATISTICS, PERCENTILES, Checkpoint, Result,
                              component_index)

__version__ = "0.1.0"

__all__ = ["COMPONENTS", "EPOCH_STATISTICS", "FINAL_STATES", "PERCENTILES", "Checkpoint",
           "Client", "DriftlabError", "JobFailed", "LocalRunError", "LocalRunner", "Progress",
           "ProgressPrinter", "Result", "component_index", "connect", "find_binary", "job_json",
           "load_job", "plot_envelopes", "summary_lines"]
