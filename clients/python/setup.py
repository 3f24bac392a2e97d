"""Build step of the driftlab package: the gRPC modules of proto/driftlab/v1/*.proto.

pyproject.toml holds the package's metadata. This file adds one step to setuptools' build_py:
protoc's Python generator and gRPC's Python plugin write driftlab/v1/*_pb2.py and *_pb2_grpc.py
into the build directory, next to the package's own modules. It uses Debian's `protoc`
(protobuf-compiler) and `grpc_python_plugin` (protobuf-compiler-grpc), or grpc_tools.protoc where
those are missing. The .proto files are found in $DRIFTLAB_PROTO_DIR or ../../proto (the
repository's proto/, two levels above clients/python).
"""

import importlib.util
import os
import pathlib
import shutil
import subprocess
import sys

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = pathlib.Path(__file__).resolve().parent


def proto_root():
    candidates = []
    if os.environ.get("DRIFTLAB_PROTO_DIR"):
        candidates.append(pathlib.Path(os.environ["DRIFTLAB_PROTO_DIR"]))
    candidates.append(HERE.parent.parent / "proto")
    for candidate in candidates:
        if (candidate / "driftlab" / "v1" / "service.proto").is_file():
            return candidate
    raise SystemExit("driftlab: proto/driftlab/v1/*.proto not found in "
                     + ", ".join(str(c) for c in candidates)
                     + " (install from a repository checkout, or set DRIFTLAB_PROTO_DIR)")


def generate_stubs(out_dir):
    root = proto_root()
    protos = sorted(str(p) for p in (root / "driftlab" / "v1").glob("*.proto"))
    protoc = shutil.which("protoc")
    plugin = shutil.which("grpc_python_plugin")
    if protoc and plugin:
        command = [protoc, f"-I{root}", f"--python_out={out_dir}", f"--grpc_out={out_dir}",
                   f"--plugin=protoc-gen-grpc={plugin}", *protos]
    else:
        if importlib.util.find_spec("grpc_tools") is None:  # pip's grpcio-tools
            raise SystemExit("driftlab: generating the gRPC modules needs protoc and "
                             "grpc_python_plugin (Debian: protobuf-compiler, "
                             "protobuf-compiler-grpc) or grpcio-tools")
        command = [sys.executable, "-m", "grpc_tools.protoc", f"-I{root}",
                   f"--python_out={out_dir}", f"--grpc_python_out={out_dir}", *protos]
    subprocess.run(command, check=True)


class BuildPyWithStubs(build_py):
    def run(self):
        super().run()
        out_dir = pathlib.Path(self.build_lib)
        (out_dir / "driftlab" / "v1").mkdir(parents=True, exist_ok=True)
        generate_stubs(out_dir)


setup(cmdclass={"build_py": BuildPyWithStubs})
