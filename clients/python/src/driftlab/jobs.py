"""Job specifications (driftlab.v1.Job) from dicts, JSON files or messages."""

from __future__ import annotations

import os
import pathlib
from typing import Any, Dict, Union

from google.protobuf import json_format

from driftlab.v1 import job_pb2

JobLike = Union[job_pb2.Job, Dict[str, Any], str, os.PathLike]


def load_job(job: JobLike) -> job_pb2.Job:
    """A ``driftlab.v1.Job`` from a dict (the protobuf JSON mapping of a job file), a JSON job
    file's path, or a Job. YAML job files are read by the ``driftlab`` binary (LocalRunner), not
    here: convert them to JSON for the server, or submit them with ``driftlab submit``."""
    if isinstance(job, job_pb2.Job):
        return job
    if isinstance(job, dict):
        return json_format.ParseDict(job, job_pb2.Job())
    path = pathlib.Path(os.fspath(job))
    if path.suffix.lower() in (".yaml", ".yml"):
        raise ValueError(f"{path}: YAML job files are not read by the Python client; "
                         "convert the job to JSON (the protobuf JSON mapping)")
    return json_format.Parse(path.read_text(), job_pb2.Job())


def job_json(job: JobLike) -> str:
    """The job as protobuf JSON text (proto field names), as a job file holds it."""
    return json_format.MessageToJson(load_job(job), preserving_proto_field_name=True, indent=2)
