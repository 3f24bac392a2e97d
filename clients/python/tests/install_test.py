#!/usr/bin/python3
"""ctest `python_package_install`: the package installs with pip and the README's script runs.

1. A fresh virtual environment that sees Debian's packages (python3 -m venv
   --system-site-packages: grpcio, protobuf, numpy, pandas).
2. `pip install --no-build-isolation ./clients/python` into it, from a copy of the repository's
   clients/python and proto/ (the same relative layout; pip builds in the source directory, so
   the copy keeps the checkout clean). --no-index as well: nothing may come from a package index.
3. The installed package is the one imported (outside the source tree), with its generated
   gRPC modules; its metadata names the version and the runtime dependencies.
4. clients/python/examples/quickstart.py (the README's 10-line script) against a driftlab-server
   on 127.0.0.1 prints the final horizontal sigma of the car drive; the number equals the
   in-process run of the same job, runs and seed with this build's `driftlab` (same bits).

Usage: install_test.py SOURCE_DIR   (env DRIFTLAB_SERVER_BINARY, DRIFTLAB_BINARY; PYTHONPATH
holds <build>/python for the comparison run)
"""

import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from server_fixture import ServerProcess  # noqa: E402

PIP_TIMEOUT_S = 300
SCRIPT_TIMEOUT_S = 300


def fail(message):
    print(f"FAIL: {message}", file=sys.stderr)
    sys.exit(1)


def run(command, **kwargs):
    print("$ " + " ".join(str(c) for c in command), flush=True)
    done = subprocess.run([str(c) for c in command], capture_output=True, text=True, **kwargs)
    if done.stdout.strip():
        print(done.stdout.strip())
    if done.stderr.strip():
        print(done.stderr.strip())
    return done


def main():
    source = pathlib.Path(sys.argv[1]).resolve()
    clean_env = {k: v for k, v in os.environ.items()
                 if k not in ("PYTHONPATH", "PIP_INDEX_URL", "DRIFTLAB_TOKEN")}
    with tempfile.TemporaryDirectory(prefix="driftlab-pip-") as scratch:
        scratch = pathlib.Path(scratch)
        checkout = scratch / "checkout"
        shutil.copytree(source / "clients" / "python", checkout / "clients" / "python",
                        ignore=shutil.ignore_patterns("build", "*.egg-info", "__pycache__"))
        shutil.copytree(source / "proto", checkout / "proto")
        venv = scratch / "venv"
        done = run(["/usr/bin/python3", "-m", "venv", "--system-site-packages", venv],
                   env=clean_env, timeout=PIP_TIMEOUT_S)
        if done.returncode != 0:
            fail("python3 -m venv failed (Debian: python3-venv)")
        python = venv / "bin" / "python"
        done = run([python, "-m", "pip", "install", "--no-build-isolation", "--no-index",
                    "./clients/python"], cwd=checkout, env=clean_env, timeout=PIP_TIMEOUT_S)
        if done.returncode != 0:
            fail("pip install --no-build-isolation ./clients/python failed")

        # The installed package, not a source tree, and its generated modules.
        probe = ("import driftlab, driftlab.v1.service_pb2_grpc as g, importlib.metadata as m; "
                 "print(driftlab.__file__); print(m.version('driftlab')); "
                 "print(sorted(m.requires('driftlab')))")
        done = run([python, "-c", probe], cwd=scratch, env=clean_env, timeout=60)
        if done.returncode != 0:
            fail("the installed package does not import")
        location, version, requires = done.stdout.strip().splitlines()
        if not location.startswith(str(venv)):
            fail(f"driftlab imported from {location}, not from the virtual environment")
        if version != "0.1.0" or not all(any(r.startswith(n) for r in eval(requires))
                                         for n in ("grpcio", "protobuf", "numpy")):
            fail(f"metadata: version {version}, requires {requires}")

        runs_job = source / "examples" / "car_drive.json"
        with ServerProcess(os.environ["DRIFTLAB_SERVER_BINARY"]) as server:
            done = run([python, source / "clients" / "python" / "examples" / "quickstart.py",
                        server.address, runs_job], cwd=scratch, env=clean_env,
                       timeout=SCRIPT_TIMEOUT_S)
        if done.returncode != 0:
            fail(f"quickstart.py exited {done.returncode}")
        match = re.search(r"final horizontal sigma: (\S+) m at t = (\S+) s", done.stdout)
        if not match:
            fail("quickstart.py printed no final horizontal sigma")
        if "progress: 100%" not in done.stderr:
            fail("quickstart.py printed no progress")
        sigma = float(match.group(1))

    # The same job, runs and seed in-process: the same bits (DESIGN.md invariant 3).
    import driftlab
    local = driftlab.LocalRunner(os.environ["DRIFTLAB_BINARY"]).run(runs_job, runs=50)
    expected = float(local.std[-1, driftlab.component_index("horizontal_position_m")])
    if sigma != expected:
        fail(f"quickstart.py printed sigma {sigma!r} m; the local run gives {expected!r} m")
    print(f"PASS: pip install into a fresh venv; quickstart.py printed the final horizontal "
          f"sigma {sigma!r} m (= the local run)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
