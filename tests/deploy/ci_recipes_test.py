#!/usr/bin/env python3
"""The CI recipes of deploy/ci run end to end (ctest `ci_recipes`).

Each recipe (GitHub Actions: deploy/ci/github-actions.yml; GitLab CI: deploy/ci/gitlab-ci.yml) is
read with PyYAML and its shell steps are run as the CI system would run them, in a clean clone of
a repository laid out as the recipes expect (the recipe file, accuracy/job.json from
deploy/ci/accuracy). The one step that builds driftlab (GitHub: the step with id `driftlab`;
GitLab: the `.driftlab` template's before_script) is replaced by this build's `driftlab` on PATH;
`uses:` steps (checkout, JUnit publishing, artifact upload) are not run, but the files they name
must exist afterwards. Steps run with bash -eo pipefail in the clone, with the workflow's env /
variables, GITHUB_PATH and GITHUB_ENV honoured; `if:` conditions of the forms the recipe uses
(always(), github.event_name, inputs.*) are evaluated.

1. The baseline: GitHub's workflow_dispatch with refresh_baseline writes accuracy/baseline.json;
   it is committed; GitLab's manual driftlab-baseline job writes the same statistics.
2. Rerun: both recipes' gate jobs pass in a clean clone (the job's own seed: paired mode), and
   pass with GATE_SEED set to another seed (independent mode).
3. Degraded IMU: the job's gyro angle random walk x3 committed; both gate jobs fail with exit 1
   from the gate step, and the JUnit file (what the systems upload) parses with failures > 0.

Seeds are fixed before the first run. False alarms of the independent rerun: at most alpha =
0.05 per gate; the seed below was fixed before the test first ran and its outcome is kept.

Usage: ci_recipes_test.py SOURCE_DIR BUILD_DIR
"""
import json
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ElementTree

import yaml

INDEPENDENT_SEED = "20261128"
STEP_TIMEOUT_S = 300


def fail(message):
    print("FAIL:", message)
    sys.exit(1)


def git(cwd, *args):
    subprocess.run(["git", "-c", "user.name=ci-recipes-test", "-c", "user.email=test@localhost",
                    *args], cwd=cwd, check=True, capture_output=True, text=True)


def run_shell(script, cwd, env, what):
    """Runs a step as the CI systems do (bash, errexit, pipefail); returns the exit status."""
    print(f"--- {what}\n{script.rstrip()}")
    done = subprocess.run(["bash", "--noprofile", "--norc", "-eo", "pipefail", "-c", script],
                          cwd=cwd, env=env, capture_output=True, text=True,
                          timeout=STEP_TIMEOUT_S)
    for stream in (done.stdout, done.stderr):
        if stream.strip():
            print("    " + stream.strip().replace("\n", "\n    "))
    print(f"--- exit {done.returncode}")
    return done.returncode


def junit_failures(path):
    """(tests, failures) of the JUnit file, checked for the structure CI systems read."""
    if not path.is_file():
        fail(f"{path}: no JUnit file")
    root = ElementTree.parse(path).getroot()
    suites = [root] if root.tag == "testsuite" else root.findall("testsuite")
    if not suites:
        fail(f"{path}: no <testsuite>")
    tests = failures = 0
    for suite in suites:
        cases = suite.findall("testcase")
        if int(suite.get("tests")) != len(cases):
            fail(f"{path}: tests={suite.get('tests')} but {len(cases)} <testcase>")
        counted = sum(1 for case in cases if case.find("failure") is not None)
        if int(suite.get("failures")) != counted:
            fail(f"{path}: failures={suite.get('failures')} but {counted} <failure>")
        tests += len(cases)
        failures += counted
    if tests == 0:
        fail(f"{path}: no test cases")
    return tests, failures


def statistics(path):
    result = json.loads(pathlib.Path(path).read_text())
    for key in ("timings", "engine_version"):
        result.pop(key, None)
    return result


# ------------------------------------------------------------------------------------------
# GitHub Actions

class GitHubWorkflow:
    def __init__(self, path, build_dir):
        self.doc = yaml.safe_load(path.read_text())
        self.build_dir = build_dir
        # PyYAML reads the key `on` as True (YAML 1.1); the workflow's triggers are not needed.
        self.jobs = self.doc["jobs"]

    def _if(self, condition, context, failed):
        if condition is None:
            return not failed
        text = str(condition).strip()
        if text.startswith("${{") and text.endswith("}}"):
            text = text[3:-2].strip()
        names = {"always()": "True", "success()": str(not failed), "failure()": str(failed),
                 "&&": " and ", "||": " or "}
        for key, value in names.items():
            text = text.replace(key, value)
        text = re.sub(r"github\.event_name", repr(context["event_name"]), text)
        text = re.sub(r"inputs\.(\w+)", lambda m: repr(context["inputs"].get(m.group(1), "")),
                      text)
        if re.search(r"[A-Za-z_]+\.[A-Za-z_]", text):
            fail(f"if: {condition}: an expression this test does not evaluate")
        return bool(eval(text, {"__builtins__": {}}, {}))  # only literals remain

    def run_job(self, name, clone, context, env_overrides=None):
        """Runs job `name`'s steps in `clone`; returns (failed step name or None, exit status)."""
        job = self.jobs[name]
        env = dict(os.environ)
        for source in (self.doc.get("env", {}), job.get("env", {})):
            env.update({k: str(v) for k, v in source.items()})
        env.update(env_overrides or {})
        runner_temp = clone.parent / (clone.name + "-runner-temp")
        runner_temp.mkdir(exist_ok=True)
        github_path = runner_temp / "github_path"
        github_env = runner_temp / "github_env"
        env.update(RUNNER_TEMP=str(runner_temp), GITHUB_WORKSPACE=str(clone),
                   GITHUB_PATH=str(github_path), GITHUB_ENV=str(github_env), CI="true")
        failed, status = None, 0
        for step in job["steps"]:
            what = step.get("name") or step.get("uses") or step.get("id")
            if not self._if(step.get("if"), context, failed is not None):
                print(f"--- skipped (if: {step.get('if')}): {what}")
                continue
            if step.get("id") == "driftlab":
                # The build of driftlab: this build's binary on PATH instead.
                github_path.write_text(f"{self.build_dir}\n")
            elif "run" in step:
                github_path.touch()
                github_env.touch()
                step_env = dict(env)
                step_env.update({k: str(v) for k, v in step.get("env", {}).items()})
                extra = [line for line in github_path.read_text().splitlines() if line]
                step_env["PATH"] = os.pathsep.join(reversed(extra)) + os.pathsep + env["PATH"]
                for line in github_env.read_text().splitlines():
                    if "=" in line:
                        key, value = line.split("=", 1)
                        step_env[key] = value
                status = run_shell(step["run"], clone, step_env, f"github: {what}")
                if status != 0:
                    failed = what
            elif "uses" in step:
                self._check_uses(step, clone, env)
        return failed, status

    @staticmethod
    def _check_uses(step, clone, env):
        uses = step["uses"]
        given = step.get("with", {})
        paths = []
        if uses.startswith("mikepenz/action-junit-report"):
            paths = [given["report_paths"]]
        elif uses.startswith("actions/upload-artifact"):
            paths = [p.strip() for p in given["path"].splitlines() if p.strip()]
        for path in paths:
            path = re.sub(r"\$\{\{\s*env\.(\w+)\s*\}\}", lambda m: env[m.group(1)], path)
            if not (clone / path).exists():
                fail(f"github: step `{uses}` names {path}, which the steps did not write")
        print(f"--- checked (not run): {uses} {paths}")


# ------------------------------------------------------------------------------------------
# GitLab CI

class GitLabPipeline:
    def __init__(self, path, build_dir):
        self.doc = yaml.safe_load(path.read_text())
        self.build_dir = build_dir

    def _resolved(self, name):
        job = dict(self.doc[name])
        parent = job.pop("extends", None)
        if parent:
            merged = self._resolved(parent)
            merged.update(job)
            return merged
        return job

    def run_job(self, name, clone, env_overrides=None):
        """Runs job `name`'s script (before_script replaced: the driftlab build); returns
        (failed or None, exit status). GitLab runs before_script and script in one shell."""
        job = self._resolved(name)
        if job.get("before_script") != self.doc[".driftlab"]["before_script"]:
            fail(f"gitlab: {name}: before_script is not the driftlab build of .driftlab")
        env = dict(os.environ)
        env.update({k: str(v) for k, v in self.doc.get("variables", {}).items()})
        env.update({k: str(v) for k, v in job.get("variables", {}).items()})
        env.update(env_overrides or {})
        env.update(CI="true", CI_PROJECT_DIR=str(clone), CI_PIPELINE_ID="4242")
        script = f'export PATH="{self.build_dir}:$PATH"\n' + "\n".join(job["script"]) + "\n"
        status = run_shell(script, clone, env, f"gitlab: {name}")
        self._check_artifacts(job, clone, env)
        return (name if status else None), status

    @staticmethod
    def _check_artifacts(job, clone, env):
        artifacts = job.get("artifacts", {})
        paths = list(artifacts.get("paths", []))
        junit = artifacts.get("reports", {}).get("junit")
        if junit:
            paths.append(junit)
        for path in paths:
            path = re.sub(r"\$(\w+)", lambda m: env[m.group(1)], path)
            if not (clone / path).exists():
                fail(f"gitlab: artifact {path} not written by the script")


# ------------------------------------------------------------------------------------------

def clean_clone(origin, dest):
    subprocess.run(["git", "clone", "-q", str(origin), str(dest)], check=True)
    return dest


def main():
    if len(sys.argv) != 3:
        fail("usage: ci_recipes_test.py SOURCE_DIR BUILD_DIR")
    source = pathlib.Path(sys.argv[1]).resolve()
    build = pathlib.Path(sys.argv[2]).resolve()
    if not (build / "driftlab").is_file():
        fail(f"{build}/driftlab not built")
    recipes = source / "deploy" / "ci"
    github = GitHubWorkflow(recipes / "github-actions.yml", build)
    gitlab = GitLabPipeline(recipes / "gitlab-ci.yml", build)

    with tempfile.TemporaryDirectory(prefix="driftlab-ci-recipes-") as scratch:
        scratch = pathlib.Path(scratch)
        origin = scratch / "origin"
        (origin / ".github" / "workflows").mkdir(parents=True)
        (origin / "accuracy").mkdir()
        shutil.copy(recipes / "github-actions.yml", origin / ".github/workflows/driftlab-gate.yml")
        shutil.copy(recipes / "gitlab-ci.yml", origin / ".gitlab-ci.yml")
        shutil.copy(recipes / "accuracy" / "job.json", origin / "accuracy" / "job.json")
        git(origin, "init", "-q", "-b", "main")
        git(origin, "add", ".")
        git(origin, "commit", "-q", "-m", "accuracy job and CI recipes")

        # 1. The baseline, by the recipes' own baseline jobs; committed.
        work = clean_clone(origin, scratch / "baseline-github")
        failed, status = github.run_job(
            "gate", work, {"event_name": "workflow_dispatch", "inputs": {"refresh_baseline": True}})
        if failed:
            fail(f"github baseline run: step '{failed}' exited {status}")
        baseline = work / "accuracy" / "baseline.json"
        shutil.copy(baseline, origin / "accuracy" / "baseline.json")
        git(origin, "add", "accuracy/baseline.json")
        git(origin, "commit", "-q", "-m", "accuracy baseline")
        work = clean_clone(origin, scratch / "baseline-gitlab")
        (work / "accuracy" / "baseline.json").unlink()
        failed, status = gitlab.run_job("driftlab-baseline", work)
        if failed:
            fail(f"gitlab driftlab-baseline exited {status}")
        if statistics(work / "accuracy" / "baseline.json") != statistics(baseline):
            fail("the GitLab baseline job's result differs from the GitHub one (timings aside)")
        print("PASS: baseline written by both recipes' baseline jobs and committed")

        push = {"event_name": "push", "inputs": {}}
        # 2. Rerun of the unchanged job: the job's seed (paired), then another seed.
        for label, overrides in (("paired", {}), ("independent", {"GATE_SEED": INDEPENDENT_SEED})):
            work = clean_clone(origin, scratch / f"rerun-github-{label}")
            failed, status = github.run_job("gate", work, push, overrides)
            if failed:
                fail(f"github rerun ({label}): step '{failed}' exited {status}")
            tests, failures = junit_failures(work / "gate" / "gate.xml")
            if failures:
                fail(f"github rerun ({label}): {failures} failures in gate.xml")
            work = clean_clone(origin, scratch / f"rerun-gitlab-{label}")
            failed, status = gitlab.run_job("driftlab-gate", work, overrides)
            if failed:
                fail(f"gitlab rerun ({label}) exited {status}")
            junit_failures(work / "gate" / "gate.xml")
            print(f"PASS: rerun ({label}) passes the gate in both recipes ({tests} metrics)")

        # 3. Degraded IMU: gyro ARW x3 committed to the job file.
        degraded = clean_clone(origin, scratch / "degrade")
        job_path = degraded / "accuracy" / "job.json"
        job = json.loads(job_path.read_text())
        job["sensor"]["gyro"]["arw_deg_per_sqrt_h"] *= 3
        job_path.write_text(json.dumps(job, indent=2) + "\n")
        git(degraded, "commit", "-q", "-am", "cheaper gyro")
        git(degraded, "push", "-q", "origin", "HEAD:degraded")
        for name, runner in (("github", lambda w: github.run_job("gate", w, push)),
                             ("gitlab", lambda w: gitlab.run_job("driftlab-gate", w))):
            work = scratch / f"degraded-{name}"
            subprocess.run(["git", "clone", "-q", "-b", "degraded", str(origin), str(work)],
                           check=True)
            failed, status = runner(work)
            if status != 1:
                fail(f"{name} with the degraded IMU: exit {status} (step '{failed}'), expected 1")
            if name == "github" and failed != "Gate against the baseline":
                fail(f"github with the degraded IMU: step '{failed}' failed, expected the gate")
            tests, failures = junit_failures(work / "gate" / "gate.xml")
            if failures == 0:
                fail(f"{name} with the degraded IMU: gate.xml has no failure")
            print(f"PASS: {name}: degraded IMU fails the gate with exit 1 "
                  f"({failures} of {tests} metrics regressed)")
    print("PASS: ci_recipes")
    return 0


if __name__ == "__main__":
    sys.exit(main())
