#!/usr/bin/env python3
"""Checks of deploy/ that run without Docker or Kubernetes (ctest `deploy_manifests`).

1. Every manifest parses; the server Deployment has one replica and the Recreate strategy
   (SQLite has one writer); its probes and Service use the container's gRPC port.
2. The Indexed Job's shard count K in `--shard=$(JOB_COMPLETION_INDEX)/K` equals `completions`.
3. The shard and merge commands of the manifests, run here with this build's `driftlab` on a small
   job (JOB_COMPLETION_INDEX substituted as Kubernetes does), give a merged result whose
   statistics equal a single-process `driftlab run` of the same job bit for bit (timings aside).
4. Every shared library the built binaries load comes from a Debian package that the Dockerfile's
   runtime stage installs (so the slim image can run them).

Usage: deploy_test.py SOURCE_DIR BUILD_DIR
"""
import json
import os
import re
import shlex
import subprocess
import sys
import tempfile

import yaml


def fail(message):
    print("FAIL:", message)
    sys.exit(1)


def load_all(path):
    with open(path) as f:
        return [d for d in yaml.safe_load_all(f) if d]


def strip_timings(result):
    result.pop("timings", None)
    result.pop("engine_version", None)
    return result


def main():
    source_dir, build_dir = sys.argv[1], sys.argv[2]
    deploy = os.path.join(source_dir, "deploy")
    driftlab = os.path.join(build_dir, "driftlab")

    # 1. Server manifests.
    docs = load_all(os.path.join(deploy, "k8s", "server.yaml"))
    kinds = {d["kind"]: d for d in docs}
    for kind in ("PersistentVolumeClaim", "Deployment", "Service"):
        if kind not in kinds:
            fail(f"server.yaml has no {kind}")
    dep = kinds["Deployment"]["spec"]
    if dep["replicas"] != 1 or dep["strategy"]["type"] != "Recreate":
        fail("server Deployment must be 1 replica with strategy Recreate (one SQLite writer)")
    container = dep["template"]["spec"]["containers"][0]
    port = container["ports"][0]["containerPort"]
    if container["readinessProbe"]["grpc"]["port"] != port:
        fail("readiness probe port differs from the container port")
    listen = [a for a in container["args"] if a.startswith("--listen=")]
    if not listen or not listen[0].endswith(f":{port}"):
        fail(f"server --listen does not use the container port {port}: {listen}")
    claim = [v for v in dep["template"]["spec"]["volumes"] if "persistentVolumeClaim" in v]
    if claim[0]["persistentVolumeClaim"]["claimName"] != kinds["PersistentVolumeClaim"]["metadata"]["name"]:
        fail("Deployment does not mount the volume claim of server.yaml")
    load_all(os.path.join(deploy, "compose.yaml"))

    # 2. Indexed Job.
    job = [d for d in load_all(os.path.join(deploy, "k8s", "sharded-job.yaml")) if d["kind"] == "Job"][0]
    spec = job["spec"]
    if spec.get("completionMode") != "Indexed":
        fail("shard Job is not Indexed")
    args = spec["template"]["spec"]["containers"][0]["args"]
    shard_arg = [a for a in args if a.startswith("--shard=")][0]
    m = re.fullmatch(r"--shard=\$\(JOB_COMPLETION_INDEX\)/(\d+)", shard_arg)
    if not m or int(m.group(1)) != spec["completions"]:
        fail(f"{shard_arg} does not match completions={spec['completions']}")
    k = spec["completions"]
    merge = load_all(os.path.join(deploy, "k8s", "merge-job.yaml"))[0]
    merge_cmd = merge["spec"]["template"]["spec"]["containers"][0]["args"][0]

    # 3. Run the manifests' commands on a small job.
    with tempfile.TemporaryDirectory() as tmp:
        job_dir = os.path.join(tmp, "job")
        shards = os.path.join(tmp, "shards")
        os.makedirs(job_dir)
        os.makedirs(shards)
        with open(os.path.join(source_dir, "examples", "car_drive.json")) as f:
            small = json.load(f)
        small["monte_carlo"]["runs"] = 2 * k + 3  # shards of unequal size
        small["monte_carlo"].pop("checkpoint_times_s", None)
        with open(os.path.join(job_dir, "job.json"), "w") as f:
            json.dump(small, f)
        for index in range(k):
            shard_args = [a.replace("$(JOB_COMPLETION_INDEX)", str(index))
                          .replace("/job/", job_dir + "/").replace("/shards/", shards + "/")
                          for a in args]
            subprocess.run([driftlab] + shard_args, check=True, stdout=subprocess.DEVNULL)
        cmd = merge_cmd.replace("/usr/local/bin/driftlab", shlex.quote(driftlab)).replace("/shards/", shards + "/")
        subprocess.run(["/bin/sh", "-c", cmd], check=True, stdout=subprocess.DEVNULL)
        single = os.path.join(tmp, "single.json")
        subprocess.run([driftlab, "run", os.path.join(job_dir, "job.json"), "--quiet", "--out", single],
                       check=True, stdout=subprocess.DEVNULL)
        with open(os.path.join(shards, "result.json")) as f:
            merged = strip_timings(json.load(f))
        with open(single) as f:
            whole = strip_timings(json.load(f))
        if merged != whole:
            fail("merged shard results differ from the single-process run")
        if not os.path.exists(os.path.join(shards, "report.html")):
            fail("merge step wrote no report")

    # 4. Runtime libraries of the binaries vs the Dockerfile's runtime packages.
    with open(os.path.join(deploy, "Dockerfile")) as f:
        dockerfile = f.read()
    runtime = dockerfile.split("FROM debian:12-slim", 1)[1]
    packages = sorted(set(re.findall(r"\b(lib[a-z0-9.+-]+[0-9]|ca-certificates)\b", runtime)))
    # The runtime stage gets these packages and their Depends closure (what apt-get installs).
    closure_text = subprocess.run(
        ["apt-cache", "depends", "--recurse", "--no-recommends", "--no-suggests", "--no-conflicts",
         "--no-breaks", "--no-replaces", "--no-enhances"] + packages,
        capture_output=True, text=True, check=True).stdout
    closure = {line.strip().split(":")[0] for line in closure_text.splitlines()
               if line and not line.startswith(" ")}
    closure |= {"libc6", "libgcc-s1", "libstdc++6"}  # in every Debian image
    for binary in ("driftlab-server", "driftlab"):
        path = os.path.join(build_dir, binary)
        if not os.path.exists(path):
            fail(f"{path} not built")
        ldd = subprocess.run(["ldd", path], capture_output=True, text=True, check=True).stdout
        libs = sorted({os.path.realpath(lib) for lib in re.findall(r"=> (/\S+)", ldd)})
        # One dpkg query for all of them: "package[:arch]: /path" per line.
        # usrmerge: dpkg records some libraries under /lib (libc6), others under /usr/lib.
        queries = libs + [lib.replace("/usr/lib/", "/lib/", 1) for lib in libs if lib.startswith("/usr/lib/")]
        search = subprocess.run(["dpkg", "-S"] + queries, capture_output=True, text=True).stdout
        owners = {}
        for line in search.splitlines():
            pkg, _, lib = line.partition(": ")
            owners[os.path.basename(lib.strip())] = pkg.split(":")[0]
        for lib in libs:
            pkg = owners.get(os.path.basename(lib))
            if pkg is None:
                fail(f"{binary}: {lib} belongs to no Debian package")
            if pkg not in closure:
                fail(f"{binary}: {lib} ({pkg}) is not installed by the Dockerfile's runtime stage "
                     f"(packages {packages} and their dependencies)")
    print(f"deploy manifests OK: {k} shards merged equal the single run; runtime libraries covered")


if __name__ == "__main__":
    main()
