"""A single-node SLURM cluster on localhost, made of Debian's packages (munge, slurmctld,
slurmd) for the slurm engine's test: key, configuration, state and logs in one temporary
folder, the three daemons started in the foreground as this process's children (no systemd,
no files outside the folder), and stopped -- jobs cancelled first -- when the `with` block
ends, whatever ends it. Each daemon also gets PR_SET_PDEATHSIG, so it dies with this
process even if this process is killed with SIGKILL (a CTest timeout).

Runs as root (CI's container) or as any user: SlurmUser and SlurmdUser are the current
user. No cgroups: proctrack/linuxproc and task/none.
"""
import ctypes
import os
import shutil
import signal
import socket
import subprocess
import tempfile
import time
from pathlib import Path

DAEMONS = ["munged", "slurmctld", "slurmd"]


def _die_with_parent():
    """preexec_fn: the child gets SIGKILL when the process that started it dies."""
    libc = ctypes.CDLL("libc.so.6", use_errno=True)
    libc.prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _sbin(name):
    for d in ("/usr/sbin", "/usr/bin", "/sbin"):
        if os.access(f"{d}/{name}", os.X_OK):
            return f"{d}/{name}"
    found = shutil.which(name)
    if not found:
        raise RuntimeError(f"{name} is not installed (Debian: munge, slurmctld, slurmd, slurm-client; "
                           f"`bash .ci/deps.sh` installs them)")
    return found


class LocalCluster:
    def __init__(self, log=print):
        self.log = log
        self.procs = {}
        # A short path: munge's socket path must fit in a sockaddr_un (108 bytes).
        self.dir = Path(tempfile.mkdtemp(prefix="sbslurm-", dir="/tmp"))
        self.conf = self.dir / "slurm.conf"
        self.env = dict(os.environ, SLURM_CONF=str(self.conf))

    # -- setup ---------------------------------------------------------------------------
    def _write_config(self):
        d = self.dir
        for sub in ("state", "spool", "munge"):
            (d / sub).mkdir(mode=0o700)
        key = d / "munge" / "munge.key"
        key.write_bytes(os.urandom(1024))
        key.chmod(0o600)
        user = subprocess.run(["id", "-un"], capture_output=True, text=True, check=True).stdout.strip()
        # This machine's CPUs, boards, sockets, cores and memory as slurmd sees them.
        hw = subprocess.run([_sbin("slurmd"), "-C"], capture_output=True, text=True, check=True).stdout.split()
        hw = [w for w in hw if w.split("=")[0] in ("CPUs", "Boards", "SocketsPerBoard", "CoresPerSocket",
                                                   "ThreadsPerCore", "RealMemory")]
        self.conf.write_text(f"""# written by tests/slurm/local_cluster.py
ClusterName=sbtest
SlurmctldHost=localhost(127.0.0.1)
SlurmctldPort={_free_port()}
SlurmdPort={_free_port()}
SlurmUser={user}
SlurmdUser={user}
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket={d}/munge/munge.socket
StateSaveLocation={d}/state
SlurmdSpoolDir={d}/spool
SlurmctldPidFile={d}/slurmctld.pid
SlurmdPidFile={d}/slurmd.pid
SlurmctldLogFile={d}/slurmctld.log
SlurmdLogFile={d}/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SlurmdParameters=config_overrides
MpiDefault=none
ReturnToService=2
MinJobAge=600
KillWait=2
NodeName=sbnode NodeAddr=127.0.0.1 NodeHostname={socket.gethostname()} {' '.join(hw)} State=UNKNOWN
PartitionName=sbtest Nodes=sbnode Default=YES MaxTime=INFINITE State=UP
""")

    def _start(self, name, argv):
        out = open(self.dir / f"{name}.stdout", "w")
        self.procs[name] = subprocess.Popen(argv, stdout=out, stderr=subprocess.STDOUT, env=self.env,
                                            preexec_fn=_die_with_parent, cwd=self.dir)
        self.log(f"cluster: started {name} (pid {self.procs[name].pid})")

    def _wait_for(self, what, check, timeout=60):
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            for name, p in self.procs.items():
                if p.poll() is not None:
                    raise RuntimeError(f"{name} exited ({p.returncode}) while waiting for {what}:\n{self.logs()}")
            if check():
                return
            time.sleep(0.3)
        raise RuntimeError(f"timed out after {timeout} s waiting for {what}:\n{self.logs()}")

    def start(self):
        self._write_config()
        d = self.dir / "munge"
        self._start("munged", [_sbin("munged"), "--foreground", "--force", f"--socket={d}/munge.socket",
                               f"--key-file={d}/munge.key", f"--pid-file={d}/munged.pid",
                               f"--log-file={d}/munged.log", f"--seed-file={d}/munged.seed"])
        self._wait_for("munged's socket", lambda: (d / "munge.socket").exists())
        self._start("slurmctld", [_sbin("slurmctld"), "-D", "-i", "-f", str(self.conf)])
        self._wait_for("slurmctld", lambda: self.run(["scontrol", "ping"], check=False).returncode == 0)
        self._start("slurmd", [_sbin("slurmd"), "-D", "-N", "sbnode", "-f", str(self.conf)])
        self._wait_for("the node to be idle",
                       lambda: "idle" in self.run(["sinfo", "--noheader", "--format=%T"], check=False).stdout)
        self.log(f"cluster: up, configuration in {self.conf}")

    # -- use -----------------------------------------------------------------------------
    def run(self, argv, check=True):
        """A SLURM client command against this cluster."""
        return subprocess.run(argv, capture_output=True, text=True, env=self.env, check=check)

    def logs(self):
        text = []
        for f in sorted(self.dir.glob("*.log")) + sorted(self.dir.glob("*.stdout")) + [self.dir / "munge/munged.log"]:
            if f.exists():
                text.append(f"--- {f.name}\n{f.read_text()[-3000:]}")
        return "\n".join(text)

    # -- teardown ------------------------------------------------------------------------
    def stop(self):
        """Cancels every job, stops the daemons (SIGTERM, then SIGKILL), removes the folder;
        returns the names of daemons that had to be killed or would not die."""
        trouble = []
        if "slurmctld" in self.procs and self.procs["slurmctld"].poll() is None:
            self.run(["scancel", "--full", "--partition=sbtest"], check=False)
            end = time.monotonic() + 20
            while time.monotonic() < end and self.run(["squeue", "--noheader"], check=False).stdout.strip():
                time.sleep(0.5)
        for name in reversed(DAEMONS):
            p = self.procs.get(name)
            if p is None or p.poll() is not None:
                continue
            p.send_signal(signal.SIGTERM)
            try:
                p.wait(timeout=15)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
                trouble.append(name)
            self.log(f"cluster: stopped {name} (pid {p.pid})")
        alive = [n for n, p in self.procs.items() if p.poll() is None]
        shutil.rmtree(self.dir, ignore_errors=True)
        return trouble + alive

    def __enter__(self):
        try:
            self.start()
        except BaseException:
            self.stop()
            raise
        return self

    def __exit__(self, *exc):
        self.stop()
