"""A real, throw-away Slurm cluster on localhost for the sweep tests.

Debian's slurm-wlm (slurmctld, slurmd) and munge, started by the test as root with a minimal
configuration in a temporary folder: its own munge key and socket, its own ports, state and
spool folders, no cgroups (proctrack/linuxproc, task/none), no accounting, one node with the
machine's CPUs, one partition. Nothing under /etc is read or changed: the clients (sbatch,
squeue, scontrol, scancel) find the configuration through SLURM_CONF, which `env` carries.

    cluster = LocalSlurm(folder)
    reason = cluster.unavailable()      # None, or why it cannot run here (the test skips)
    cluster.start()                     # raises ClusterError with the daemons' logs
    ...
    cluster.stop()                      # ends the daemons this object started, by pid
"""
import os
import pathlib
import shutil
import socket
import subprocess
import tempfile
import time

BINARIES = ("munged", "slurmctld", "slurmd", "slurmstepd", "sbatch", "srun", "squeue",
            "scontrol", "scancel", "sinfo")


class ClusterError(RuntimeError):
    """The daemons did not come up (the message holds the tail of their logs)."""


def _free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _tail(path, n=15):
    try:
        lines = pathlib.Path(path).read_text(errors="replace").splitlines()
    except OSError:
        return f"({path}: no log)"
    return "\n".join(f"    {line}" for line in lines[-n:])


class LocalSlurm:
    """munged + slurmctld + slurmd in `folder`, one node `NODE`, partition `PARTITION`."""

    NODE = "multicor1"
    PARTITION = "sweep"

    def __init__(self, folder, max_time_minutes=10, cred_expire=5):
        self.dir = pathlib.Path(folder).resolve()
        self.max_time = max_time_minutes
        # seconds a requeued job waits before it may start again (Slurm default 120)
        self.cred_expire = cred_expire
        self.conf = self.dir / "slurm.conf"
        self.procs = {}
        self.run_dir = None
        self.env = dict(os.environ, SLURM_CONF=str(self.conf))
        for var in list(self.env):
            # a surrounding Slurm job (CI inside a cluster) must not leak into ours
            if var.startswith(("SLURM_", "SBATCH_", "SRUN_", "SALLOC_")) and var != "SLURM_CONF":
                del self.env[var]

    def unavailable(self):
        """Why this cluster cannot run here, or None."""
        if not hasattr(os, "geteuid") or os.geteuid() != 0:
            return "not root: slurmd must run as root to start jobs (CI runs ./test.sh as root)"
        missing = [b for b in BINARIES if shutil.which(b) is None
                   and not pathlib.Path("/usr/sbin", b).exists()]
        if missing:
            return ("missing " + ", ".join(missing)
                    + ": apt-get install slurm-wlm munge (scripts/bootstrap.sh does as root)")
        return None

    def _which(self, name):
        return shutil.which(name) or str(pathlib.Path("/usr/sbin", name))

    def _write_conf(self):
        host = socket.gethostname().split(".")[0]
        d, r = self.dir, self.run_dir
        (d / "log").mkdir(parents=True, exist_ok=True)
        for sub in ("state", "spool"):
            (r / sub).mkdir(parents=True, exist_ok=True)
        cpus = os.cpu_count() or 1
        self.conf.write_text(f"""\
# Minimal single-node Slurm for the MULTICOR sweep tests (tests/regression/slurm_local.py)
ClusterName=multicortest
SlurmctldHost={host}(127.0.0.1)
SlurmUser=root
SlurmdUser=root
SlurmctldPort={_free_port()}
SlurmdPort={_free_port()}
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket={r / 'munge.socket'},cred_expire={self.cred_expire}
StateSaveLocation={r / 'state'}
SlurmdSpoolDir={r / 'spool'}
SlurmctldPidFile={d / 'slurmctld.pid'}
SlurmdPidFile={d / 'slurmd.pid'}
SlurmctldLogFile={d / 'log' / 'slurmctld.log'}
SlurmdLogFile={d / 'log' / 'slurmd.log'}
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/builtin
SchedulerParameters=sched_interval=1
MpiDefault=none
SwitchType=switch/none
ReturnToService=2
MinJobAge=5
KillWait=5
InactiveLimit=0
JobRequeue=0
NodeName={self.NODE} NodeHostname={host} NodeAddr=127.0.0.1 CPUs={cpus} State=UNKNOWN
PartitionName={self.PARTITION} Nodes={self.NODE} Default=YES MaxTime={self.max_time} State=UP
""")

    def _start(self, name, args):
        log = open(self.dir / "log" / f"{name}.stdout", "w")
        self.procs[name] = subprocess.Popen(args, stdout=log, stderr=subprocess.STDOUT,
                                            env=self.env, start_new_session=True)
        log.close()

    def _wait(self, what, test, timeout):
        t0 = time.monotonic()
        while time.monotonic() - t0 < timeout:
            for name, proc in self.procs.items():
                if proc.poll() is not None:
                    raise ClusterError(f"{name} exited with {proc.returncode} while waiting for "
                                       f"{what}\n{self.logs()}")
            if test():
                return
            time.sleep(0.2)
        raise ClusterError(f"timeout ({timeout} s) waiting for {what}\n{self.logs()}")

    def logs(self):
        log = self.dir / "log"
        return "\n".join(f"  {p.name}:\n{_tail(p)}" for p in sorted(log.glob("*")))

    def start(self, timeout=30):
        """Start munged, slurmctld and slurmd; on failure, end what started and raise."""
        try:
            self._start_all(timeout)
        except ClusterError:
            self.stop()
            raise
        except (OSError, subprocess.SubprocessError) as e:
            logs = self.logs()
            self.stop()
            raise ClusterError(f"{e}\n{logs}") from None

    def _start_all(self, timeout):
        self.dir.mkdir(parents=True, exist_ok=True)
        os.chmod(self.dir, 0o700)
        # sockets (munge, slurmstepd's in the spool) need a short path (108 bytes at most):
        # they live in a folder under /tmp, removed by stop()
        self.run_dir = pathlib.Path(tempfile.mkdtemp(prefix="mcslurm-", dir="/tmp"))
        self._write_conf()
        key = self.dir / "munge.key"
        key.write_bytes(os.urandom(1024))
        os.chmod(key, 0o400)
        sock = self.run_dir / "munge.socket"
        self._start("munged", [self._which("munged"), "--foreground", "--force",
                               f"--key-file={key}", f"--socket={sock}",
                               f"--pid-file={self.dir / 'munged.pid'}",
                               f"--log-file={self.dir / 'log' / 'munged.log'}",
                               f"--seed-file={self.dir / 'munged.seed'}"])
        self._wait("the munge socket", sock.exists, timeout)
        self._start("slurmctld", [self._which("slurmctld"), "-D", "-i", "-f", str(self.conf)])
        self._wait("slurmctld", lambda: self.query(["scontrol", "ping"]).find("UP") >= 0, timeout)
        self._start("slurmd", [self._which("slurmd"), "-D", "-N", self.NODE, "-f", str(self.conf)])
        self._wait(f"node {self.NODE} idle", lambda: self.query(
            ["sinfo", "-h", "-n", self.NODE, "-o", "%T"]).strip() == "idle", timeout)

    def query(self, args, check=False):
        """Run a Slurm client with this cluster's configuration; its stdout ('' on failure)."""
        proc = subprocess.run(args, capture_output=True, text=True, env=self.env, timeout=30)
        if check and proc.returncode != 0:
            raise ClusterError(f"{' '.join(args)}: exit {proc.returncode}: {proc.stderr.strip()}")
        return proc.stdout if proc.returncode == 0 else ""

    def stop(self):
        """Cancel the jobs left, then end the daemons this object started (by pid: slurmd,
        slurmctld, then munged)."""
        if self.procs.get("slurmctld") and self.procs["slurmctld"].poll() is None:
            self.query(["scancel", f"--partition={self.PARTITION}"])
            t0 = time.monotonic()
            while time.monotonic() - t0 < 15 and self.query(["squeue", "-h", "-o", "%i"]).strip():
                time.sleep(0.2)
        for name in ("slurmd", "slurmctld", "munged"):
            proc = self.procs.pop(name, None)
            if proc is None or proc.poll() is not None:
                continue
            proc.terminate()
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        if self.run_dir is not None:
            shutil.rmtree(self.run_dir, ignore_errors=True)
            self.run_dir = None

    def __enter__(self):
        self.start()
        return self

    def __exit__(self, *exc):
        self.stop()
