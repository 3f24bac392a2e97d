#!/usr/bin/python3
"""Writes the seed corpus of the submit_request fuzz target (fuzz/corpus/submit_request/): the
example and test jobs (JSON) as binary SubmitJobRequest messages, as a client sends them.

Usage: fuzz/make_submit_seeds.py   (Debian's /usr/bin/python3 with python3-protobuf, and protoc)
"""
import glob
import os
import subprocess
import sys
import tempfile

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
out_dir = os.path.join(root, "fuzz", "corpus", "submit_request")
with tempfile.TemporaryDirectory() as gen:
    protos = glob.glob(os.path.join(root, "proto", "driftlab", "v1", "*.proto"))
    subprocess.run(["protoc", "-I", os.path.join(root, "proto"), "--python_out", gen] + protos,
                   check=True)
    sys.path.insert(0, gen)
    from google.protobuf import json_format  # noqa: E402
    from driftlab.v1 import service_pb2  # noqa: E402

    os.makedirs(out_dir, exist_ok=True)
    jobs = sorted(glob.glob(os.path.join(root, "fuzz", "corpus", "job_json", "*.json")))
    for index, path in enumerate(jobs):
        request = service_pb2.SubmitJobRequest()
        try:
            with open(path) as f:
                json_format.Parse(f.read(), request.job)
        except json_format.ParseError:
            continue  # the deliberately broken test jobs
        if index % 3 == 1:
            request.runs = 4
            request.seed = 7
        if index % 3 == 2:
            request.shard = "1/3"
            request.deadline_s = 60.0
        name = os.path.splitext(os.path.basename(path))[0] + ".binpb"
        with open(os.path.join(out_dir, name), "wb") as f:
            f.write(request.SerializeToString())
