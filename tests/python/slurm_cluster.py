"""A single-node Slurm cluster on this machine for the tests (Debian's slurm-wlm and munge, run as root):
munged, slurmctld and slurmd with every state, spool, log, pid and socket file under one temporary
directory, on free ports, so that it touches no system configuration. Every wait is bounded; whatever
goes wrong raises ClusterError with the daemons' logs."""
import os
import pathlib
import pwd
import shutil
import socket
import subprocess
import tempfile
import time
from typing import Dict, List, Optional


class ClusterError(RuntimeError):
    pass


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class LocalSlurm:
    """`with LocalSlurm() as slurm:` starts the cluster and waits until its node is idle; `slurm.env` is
    the environment for Slurm's commands (SLURM_CONF); leaving the block cancels the jobs and stops it."""

    def __init__(self, start_timeout: float = 60.0):
        self.start_timeout = start_timeout
        self.root = pathlib.Path(tempfile.mkdtemp(prefix="kage-slurm-"))
        self.root.chmod(0o755)  # munged runs as the munge user and must reach its directory
        self.node = subprocess.run(["hostname", "-s"], capture_output=True, text=True, check=True).stdout.strip()
        self.conf = self.root / "slurm.conf"
        self.munge_socket = self.root / "munge" / "munge.socket.2"
        self.env = {**os.environ, "SLURM_CONF": str(self.conf)}
        self.daemons: Dict[str, subprocess.Popen] = {}

    # ---- start and stop ----

    def __enter__(self) -> "LocalSlurm":
        missing = [t for t in ("munged", "slurmctld", "slurmd", "sbatch", "sinfo") if shutil.which(t) is None
                   and not os.path.exists(f"/usr/sbin/{t}")]
        if missing:
            raise ClusterError(f"{', '.join(missing)} not installed: scripts/build.sh installs slurm-wlm and munge")
        if os.geteuid() != 0:
            raise ClusterError("the local Slurm cluster starts its daemons as root (CI runs as root): run as root")
        try:
            self.start_munge()
            self.write_conf()
            self.start("slurmctld", ["/usr/sbin/slurmctld", "-D", "-f", str(self.conf), "-L",
                                     str(self.root / "slurmctld.log")])
            self.start("slurmd", ["/usr/sbin/slurmd", "-D", "-f", str(self.conf), "-L", str(self.root / "slurmd.log"),
                                  "-N", self.node])
            self.wait_idle()
        except BaseException:
            self.__exit__(None, None, None)
            raise
        return self

    def __exit__(self, *exc) -> None:
        if "slurmctld" in self.daemons and self.daemons["slurmctld"].poll() is None:
            subprocess.run(["scancel", "--user", "root"], env=self.env, capture_output=True, timeout=30)
        for name in ("slurmd", "slurmctld", "munged"):
            daemon = self.daemons.pop(name, None)
            if daemon is None or daemon.poll() is not None:
                continue
            daemon.terminate()
            try:
                daemon.wait(timeout=20)
            except subprocess.TimeoutExpired:
                daemon.kill()
                daemon.wait(timeout=10)
        shutil.rmtree(self.root, ignore_errors=True)

    def start_munge(self) -> None:
        munge = pwd.getpwnam("munge")
        directory = self.root / "munge"
        directory.mkdir(mode=0o700)
        key = directory / "munge.key"
        key.write_bytes(os.urandom(1024))
        key.chmod(0o400)
        for path in (directory, key):
            os.chown(path, munge.pw_uid, munge.pw_gid)
        self.start("munged", ["runuser", "-u", "munge", "--", "/usr/sbin/munged", "--foreground", "--force",
                              f"--socket={self.munge_socket}", f"--key-file={key}",
                              f"--log-file={directory / 'munged.log'}", f"--pid-file={directory / 'munged.pid'}",
                              f"--seed-file={directory / 'munged.seed'}"])
        self.wait_for(lambda: self.munge_socket.exists(), "munged to open its socket")

    def write_conf(self) -> None:
        (self.root / "state").mkdir()
        (self.root / "spool").mkdir()
        cpus = os.cpu_count() or 1
        self.conf.write_text("\n".join([
            "ClusterName=kagetest",
            f"SlurmctldHost={self.node}(127.0.0.1)",
            "SlurmUser=root",
            f"SlurmctldPort={free_port()}",
            f"SlurmdPort={free_port()}",
            "AuthType=auth/munge",
            "CredType=cred/munge",
            f"AuthInfo=socket={self.munge_socket}",
            "ProctrackType=proctrack/linuxproc",
            "TaskPlugin=task/none",
            "JobAcctGatherType=jobacct_gather/none",
            "AccountingStorageType=accounting_storage/none",
            "SelectType=select/cons_tres",
            "SelectTypeParameters=CR_CPU",
            "MpiDefault=none",
            "ReturnToService=2",
            "KillWait=5",
            "MinJobAge=600",
            "SchedulerParameters=sched_interval=1",
            f"StateSaveLocation={self.root / 'state'}",
            f"SlurmdSpoolDir={self.root / 'spool'}",
            f"SlurmctldPidFile={self.root / 'slurmctld.pid'}",
            f"SlurmdPidFile={self.root / 'slurmd.pid'}",
            f"NodeName={self.node} NodeAddr=127.0.0.1 CPUs={cpus} State=UNKNOWN",
            f"PartitionName=debug Nodes={self.node} Default=YES MaxTime=INFINITE State=UP",
        ]) + "\n")

    def start(self, name: str, command: List[str]) -> None:
        log = open(self.root / f"{name}.out", "wb")
        self.daemons[name] = subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT, env=self.env)

    def wait_idle(self) -> None:
        def idle() -> bool:
            result = subprocess.run(["sinfo", "-h", "-N", "-o", "%T"], env=self.env, capture_output=True, text=True,
                                    timeout=20)
            return result.returncode == 0 and result.stdout.strip() == "idle"
        self.wait_for(idle, f"sinfo to show node {self.node} idle")

    def wait_for(self, ready, what: str, timeout: Optional[float] = None) -> None:
        deadline = time.monotonic() + (timeout or self.start_timeout)
        while not ready():
            for name, daemon in self.daemons.items():
                if daemon.poll() is not None:
                    raise ClusterError(f"{name} exited with {daemon.returncode} while waiting for {what}\n"
                                       f"{self.logs()}")
            if time.monotonic() > deadline:
                raise ClusterError(f"timed out waiting for {what}\n{self.logs()}")
            time.sleep(0.5)

    # ---- jobs ----

    def command(self, *args: str, timeout: float = 30) -> str:
        result = subprocess.run(list(args), env=self.env, capture_output=True, text=True, timeout=timeout)
        if result.returncode != 0:
            raise ClusterError(f"{' '.join(args)}: exit {result.returncode}: {result.stderr}\n{self.logs()}")
        return result.stdout

    def job_states(self, job: str) -> Dict[str, str]:
        """Array task id -> state (PENDING, RUNNING, COMPLETED, FAILED, CANCELLED, ...), from scontrol."""
        states = {}
        for record in self.command("scontrol", "-o", "show", "job", job).splitlines():
            fields = dict(f.split("=", 1) for f in record.split() if "=" in f)
            if "ArrayTaskId" in fields:
                states[fields["ArrayTaskId"]] = fields["JobState"]
        return states

    def wait_job(self, job: str, done, what: str, timeout: float) -> Dict[str, str]:
        """Polls the job's task states until done(states); returns them."""
        deadline = time.monotonic() + timeout
        while True:
            states = self.job_states(job)
            if done(states):
                return states
            if time.monotonic() > deadline:
                raise ClusterError(f"timed out after {timeout:.0f} s waiting for {what}: tasks {states}\n{self.logs()}")
            time.sleep(1.0)

    def logs(self) -> str:
        parts = []
        for path in sorted(self.root.rglob("*.log")) + sorted(self.root.glob("*.out")):
            text = path.read_text(errors="replace")
            parts.append(f"---- {path.name} (last 4000 characters) ----\n{text[-4000:]}")
        parts.append(f"---- slurm.conf ----\n{self.conf.read_text() if self.conf.exists() else '(not written)'}")
        return "\n".join(parts)
