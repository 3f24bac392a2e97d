"""A one-node Slurm cluster on 127.0.0.1 for the deploy tests, started and stopped by the test:
munged, slurmctld and slurmd (Debian's munge and slurm-wlm) configured in a temporary directory
with free ports. Used by slurm_test.py (`driftlab run --slurm`) and
slurm_server_test.py (driftlab-server --cluster slurm).

    with SlurmCluster() as cluster:      # raises Skip without the packages or root
        subprocess.run([...], env=cluster.env)
"""

import os
import pathlib
import shutil
import signal
import socket
import subprocess
import tempfile
import time

SKIP = 77


class Skip(Exception):
    """The cluster cannot run here; str() says why (the test exits 77)."""


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_until(predicate, timeout_s, what):
    """Polls predicate every 0.2 s for at most timeout_s (a bounded loop)."""
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        if predicate():
            return
        time.sleep(0.2)
    raise AssertionError(f"timed out after {timeout_s} s waiting for {what}")


def check_available():
    """Raises Skip when the Slurm / munge programs are missing or we are not root."""
    missing = [p for p in ("munged", "slurmctld", "slurmd", "sbatch", "squeue", "scancel")
               if shutil.which(p) is None and not pathlib.Path("/usr/sbin", p).exists()]
    if missing:
        raise Skip(f"Slurm packages missing ({', '.join(missing)}): apt-get install slurm-wlm "
                   "munge")
    if os.geteuid() != 0:
        raise Skip("slurmd must run as root to start jobs; run this test as root")


class SlurmCluster:
    def __init__(self):
        check_available()
        self.tmp = pathlib.Path(tempfile.mkdtemp(prefix="driftlab_slurm_"))
        self.env = dict(os.environ)
        self._daemons = []

    def __enter__(self):
        try:
            self._start()
        except BaseException:
            self.stop()
            raise
        return self

    def __exit__(self, *exc):
        self.stop()
        return False

    def _start(self):
        tmp = self.tmp
        (tmp / "munge").mkdir(mode=0o700)
        (tmp / "state").mkdir()
        (tmp / "spool").mkdir()
        key = tmp / "munge" / "munge.key"
        key.write_bytes(os.urandom(1024))
        key.chmod(0o400)
        socket_path = tmp / "munge" / "munge.socket"
        subprocess.run(["/usr/sbin/munged", f"--key-file={key}", f"--socket={socket_path}",
                        f"--pid-file={tmp / 'munge' / 'munged.pid'}",
                        f"--log-file={tmp / 'munge' / 'munged.log'}",
                        f"--seed-file={tmp / 'munge' / 'seed'}", "--force"], check=True)
        host = socket.gethostname().split(".")[0]
        conf = tmp / "slurm.conf"
        conf.write_text(f"""ClusterName=driftlabtest
SlurmctldHost={host}(127.0.0.1)
SlurmctldPort={free_port()}
SlurmdPort={free_port()}
AuthType=auth/munge
AuthInfo=socket={socket_path}
CredType=cred/munge
StateSaveLocation={tmp / 'state'}
SlurmdSpoolDir={tmp / 'spool'}
SlurmctldPidFile={tmp / 'slurmctld.pid'}
SlurmdPidFile={tmp / 'slurmd.pid'}
SlurmctldLogFile={tmp / 'slurmctld.log'}
SlurmdLogFile={tmp / 'slurmd.log'}
SlurmUser=root
SlurmdUser=root
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/builtin
ReturnToService=2
MpiDefault=none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
NodeName={host} NodeAddr=127.0.0.1 CPUs={os.cpu_count()} RealMemory=1000 State=UNKNOWN
PartitionName=test Nodes={host} Default=YES MaxTime=INFINITE State=UP
""")
        self.env["SLURM_CONF"] = str(conf)
        for daemon in ("slurmctld", "slurmd"):
            self._daemons.append(subprocess.Popen(
                [f"/usr/sbin/{daemon}", "-D", "-f", str(conf)], env=self.env,
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))

        def node_idle():
            r = subprocess.run(["sinfo", "-h", "-o", "%T"], env=self.env, capture_output=True,
                               text=True)
            return r.returncode == 0 and "idle" in r.stdout
        wait_until(node_idle, 60, "the Slurm node to be idle")

    def tasks(self, name_prefix="driftlab", state=None):
        """Queue lines "NAME STATE" of the array tasks whose job name starts with name_prefix."""
        q = subprocess.run(["squeue", "-h", "-r", "-o", "%j %T"], env=self.env,
                           capture_output=True, text=True)
        return [line for line in q.stdout.splitlines()
                if line.startswith(name_prefix) and (state is None or line.endswith(state))]

    def stop(self):
        for daemon in self._daemons:
            daemon.terminate()
        for daemon in self._daemons:
            try:
                daemon.wait(timeout=30)
            except subprocess.TimeoutExpired:
                daemon.kill()
        self._daemons = []
        pid_file = self.tmp / "munge" / "munged.pid"
        if pid_file.exists():
            try:
                os.kill(int(pid_file.read_text().strip()), signal.SIGTERM)
            except (OSError, ValueError):
                pass
        shutil.rmtree(self.tmp, ignore_errors=True)
