"""A real single-node Slurm cluster with accounting for the workflow's tests: slurmctld, slurmd,
slurmdbd with its MariaDB database and munge, from Debian's packages (`.ci/run` installs them),
started on localhost for the test session and stopped after it.

Everything the cluster writes (its database, state, spool, logs) lives in a temporary
directory; its configuration goes where every Slurm command and job step looks for it,
`/etc/slurm/slurm.conf` (Snakemake's job steps drop SLURM_CONF from their environment, so a
configuration elsewhere is not found inside the jobs). A configuration already there that this
harness did not write is never touched: the tests then stop with a message. The daemons need
root (slurmd runs the jobs as their submitter, munged's key is root's).
"""

import os
import shutil
import socket
import subprocess
import time
from pathlib import Path

CONF_DIR = Path("/etc/slurm")
MARKER = "# written by flapssm's workflow tests (workflow/tests/slurm_cluster.py)"
CLUSTER = "flapssmtest"
ACCOUNT = "flapssm"
PARTITION = "debug"
NODE = "flapssmnode"
PROGRAMS = [
    "sbatch", "squeue", "sacct", "sacctmgr", "scontrol", "sinfo",
    "slurmctld", "slurmd", "slurmdbd", "munged", "munge", "unmunge",
    "mariadbd", "mariadb", "mariadb-install-db",
]


def missing():
    """Why this machine cannot run the cluster, or None."""
    absent = [p for p in PROGRAMS if shutil.which(p) is None]
    if absent:
        return (
            "Slurm is not installed (missing: " + ", ".join(absent) + "); install Debian's "
            "slurm-wlm slurmdbd munge mariadb-server, as .ci/run does"
        )
    if os.geteuid() != 0:
        return "the test cluster's daemons need root"
    conf = CONF_DIR / "slurm.conf"
    if conf.exists() and MARKER not in conf.read_text(errors="replace"):
        return f"{conf} belongs to another Slurm installation; the tests do not overwrite it"
    return None


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def run(*cmd, check=True, **kwargs):
    return subprocess.run(
        [str(c) for c in cmd], capture_output=True, text=True, check=check, timeout=120, **kwargs
    )


class SlurmCluster:
    """The cluster; `start()` returns once its node is idle and its account exists."""

    def __init__(self, root: Path):
        self.root = root
        self.logs = root / "log"
        self.ports = {k: free_port() for k in ("mysql", "slurmctld", "slurmd", "slurmdbd")}
        self.processes = []
        self.started_munged = False

    def log_tail(self, name, lines=20):
        path = self.logs / name
        if not path.exists():
            return f"({path} missing)"
        return "\n".join(path.read_text(errors="replace").splitlines()[-lines:])

    def wait(self, what, ready, timeout=60):
        deadline = time.time() + timeout
        while time.time() < deadline:
            if ready():
                return
            time.sleep(0.5)
        raise RuntimeError(
            f"test cluster: {what} not ready after {timeout} s\n"
            + "\n".join(f"--- {n}\n{self.log_tail(n)}" for n in sorted(os.listdir(self.logs)))
        )

    def start(self):
        for d in ("db", "state", "spool", "log"):
            (self.root / d).mkdir(parents=True, exist_ok=True)
        self.start_database()
        self.start_munge()
        self.write_configs()
        self.processes.append(subprocess.Popen(["slurmdbd", "-D"], stdout=subprocess.DEVNULL,
                                               stderr=subprocess.DEVNULL))
        self.wait("slurmdbd", lambda: run("sacctmgr", "-n", "show", "cluster", check=False).returncode == 0)
        for args in (
            ["add", "cluster", CLUSTER],
            ["add", "account", ACCOUNT, f"Cluster={CLUSTER}"],
            ["add", "user", "root", f"Account={ACCOUNT}", f"Cluster={CLUSTER}"],
        ):
            run("sacctmgr", "-i", *args, check=False)
        self.processes.append(subprocess.Popen(["slurmctld", "-D"], stdout=subprocess.DEVNULL,
                                               stderr=subprocess.DEVNULL))
        self.wait("slurmctld", lambda: run("sinfo", check=False).returncode == 0)
        self.processes.append(subprocess.Popen(["slurmd", "-D", "-N", NODE],
                                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        self.wait("the node", lambda: run("sinfo", "-h", "-o", "%t", check=False).stdout.strip() == "idle")
        return self

    def start_database(self):
        db = self.root / "db"
        run("mariadb-install-db", f"--datadir={db}", "--user=root",
            "--auth-root-authentication-method=normal", "--skip-test-db")
        sock = self.root / "mysql.sock"
        self.processes.append(subprocess.Popen(
            ["mariadbd", f"--datadir={db}", f"--socket={sock}", f"--port={self.ports['mysql']}",
             "--bind-address=127.0.0.1", "--user=root", f"--pid-file={self.root / 'mysql.pid'}",
             f"--log-error={self.logs / 'mysql.err'}"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        self.wait("MariaDB", lambda: run("mariadb", "-S", sock, "-u", "root", "-e", "SELECT 1",
                                         check=False).returncode == 0)
        grants = "".join(
            f"CREATE USER 'slurm'@'{h}' IDENTIFIED BY 'slurmtest';"
            f"GRANT ALL ON slurm_acct_db.* TO 'slurm'@'{h}';"
            for h in ("127.0.0.1", "localhost")
        )
        run("mariadb", "-S", sock, "-u", "root", "-e", grants + "FLUSH PRIVILEGES;")

    def start_munge(self):
        works = lambda: subprocess.run("munge -n | unmunge", shell=True, capture_output=True,
                                       timeout=30).returncode == 0
        if works():
            return
        Path("/run/munge").mkdir(parents=True, exist_ok=True)
        key = Path("/etc/munge/munge.key")
        if not key.exists():
            key.parent.mkdir(parents=True, exist_ok=True)
            key.write_bytes(os.urandom(1024))
            key.chmod(0o600)
        run("munged", "--force", f"--log-file={self.logs / 'munged.log'}",
            f"--pid-file={self.root / 'munged.pid'}")
        self.started_munged = True
        self.wait("munged", works)

    def write_configs(self):
        host = socket.gethostname().split(".")[0]
        memory = int(int(next(l.split()[1] for l in open("/proc/meminfo") if l.startswith("MemTotal"))) / 1024 * 0.8)
        cpus = os.cpu_count() or 1
        r, p = self.root, self.ports
        slurm = f"""{MARKER}
ClusterName={CLUSTER}
SlurmctldHost={host}(127.0.0.1)
SlurmctldPort={p['slurmctld']}
SlurmdPort={p['slurmd']}
AuthType=auth/munge
CredType=cred/munge
SlurmUser=root
SlurmdUser=root
StateSaveLocation={r / 'state'}
SlurmdSpoolDir={r / 'spool'}
SlurmctldPidFile={r / 'slurmctld.pid'}
SlurmdPidFile={r / 'slurmd.pid'}
SlurmctldLogFile={self.logs / 'slurmctld.log'}
SlurmdLogFile={self.logs / 'slurmd.log'}
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/linux
AccountingStorageType=accounting_storage/slurmdbd
AccountingStorageHost=127.0.0.1
AccountingStoragePort={p['slurmdbd']}
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
ReturnToService=2
MpiDefault=none
KillWait=10
NodeName={NODE} NodeAddr=127.0.0.1 NodeHostname={host} CPUs={cpus} RealMemory={memory} State=UNKNOWN
PartitionName={PARTITION} Nodes={NODE} Default=YES MaxTime=INFINITE State=UP
"""
        dbd = f"""{MARKER}
AuthType=auth/munge
DbdHost=localhost
DbdAddr=127.0.0.1
DbdPort={p['slurmdbd']}
SlurmUser=root
PidFile={r / 'slurmdbd.pid'}
LogFile={self.logs / 'slurmdbd.log'}
StorageType=accounting_storage/mysql
StorageHost=127.0.0.1
StoragePort={p['mysql']}
StorageUser=slurm
StoragePass=slurmtest
StorageLoc=slurm_acct_db
"""
        CONF_DIR.mkdir(parents=True, exist_ok=True)
        (CONF_DIR / "slurm.conf").write_text(slurm)
        (CONF_DIR / "slurmdbd.conf").write_text(dbd)
        (CONF_DIR / "slurmdbd.conf").chmod(0o600)

    def stop(self):
        for proc in reversed(self.processes):
            proc.terminate()
        for proc in reversed(self.processes):
            try:
                proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                proc.kill()
        if self.started_munged:
            pid = self.root / "munged.pid"
            if pid.exists():
                try:
                    os.kill(int(pid.read_text().strip()), 15)
                except (ProcessLookupError, ValueError):
                    pass
        for name in ("slurm.conf", "slurmdbd.conf"):
            path = CONF_DIR / name
            if path.exists() and MARKER in path.read_text(errors="replace"):
                path.unlink()

    def version(self):
        return run("sbatch", "--version").stdout.strip()
