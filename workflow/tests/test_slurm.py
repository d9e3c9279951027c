"""The workflow through a real Slurm cluster with accounting (workflow/tests/slurm_cluster.py):
the tiny configuration submitted job by job with sbatch through workflow/profiles/slurm ends with
the local run's results; a sweep run requeued mid-training (`scontrol requeue`) resumes from its
checkpoint and ends with the uninterrupted run's results; a wrong partition ends the workflow
with Slurm's message instead of a wait.

Without Slurm or root these tests are skipped, unless FLAPSSM_REQUIRE_SLURM=1 (as .ci/run sets
it), which makes that a failure. On a cluster of your own, from a login node, set
FLAPSSM_SLURM_PARTITION (and FLAPSSM_SLURM_ACCOUNT, if your site needs one): the tests then
submit there instead of starting a cluster (docs/workflow.md)."""

import csv
import json
import os
import subprocess
import time

import pytest

from slurm_cluster import ACCOUNT, PARTITION, SlurmCluster, missing, run
from test_workflow import FLAPSSM, WORKFLOW, snakemake

REQUIRE = os.environ.get("FLAPSSM_REQUIRE_SLURM") == "1"
LOCAL = ["--profile", str(WORKFLOW / "profiles" / "local")]


class ExistingCluster:
    """A cluster of the user's (FLAPSSM_SLURM_PARTITION, FLAPSSM_SLURM_ACCOUNT)."""

    def __init__(self, partition, account):
        self.partition, self.account = partition, account

    def version(self):
        return run("sbatch", "--version").stdout.strip()


def slurm(cluster, partition=None):
    resources = [f"slurm_partition={partition or cluster.partition}"]
    if cluster.account:
        resources.append(f"slurm_account={cluster.account}")
    return [
        "--profile", str(WORKFLOW / "profiles" / "slurm"),
        "--default-resources", *resources,
        "--slurm-init-seconds-before-status-checks", "5",
    ]


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    partition = os.environ.get("FLAPSSM_SLURM_PARTITION")
    if partition:
        yield ExistingCluster(partition, os.environ.get("FLAPSSM_SLURM_ACCOUNT"))
        return
    why = missing()
    if why:
        if REQUIRE:
            pytest.fail(why)
        pytest.skip(why)
    c = SlurmCluster(tmp_path_factory.mktemp("slurm"))
    c.partition, c.account = PARTITION, ACCOUNT
    try:
        c.start()
        yield c
    finally:
        c.stop()


def my_jobs(since, *fields):
    """This user's jobs since `since` (seconds since the epoch) in the accounting, as rows."""
    start = time.strftime("%Y-%m-%dT%H:%M:%S", time.localtime(since - 5))
    out = run("sacct", "-X", "-n", "-P", "-u", os.environ.get("USER", "root"), "-S", start,
              "-o", ",".join(fields)).stdout
    return [line.split("|") for line in out.splitlines() if line]


def rows(path, drop):
    """The CSV's rows without the columns `drop` (wall times, paths)."""
    with open(path) as f:
        return [{k: v for k, v in r.items() if k not in drop} for r in csv.DictReader(f)]


def test_tiny_workflow_through_slurm_equals_the_local_run(cluster, tmp_path):
    assert FLAPSSM.exists(), f"{FLAPSSM}: build it first"
    local, on_slurm = tmp_path / "local", tmp_path / "slurm"
    r = snakemake(*LOCAL, cwd=local)
    assert r.returncode == 0, r.stderr[-4000:]
    started = time.time()
    r = snakemake(*slurm(cluster), cwd=on_slurm)
    assert r.returncode == 0, r.stderr[-6000:]
    print(f"tiny workflow on Slurm ({cluster.version()}): {time.time() - started:.1f} s")
    # Every job went through the cluster and its accounting: simulate, 6 sweep runs, their
    # merge, 2 demos and their merge, all COMPLETED in the partition.
    jobs = my_jobs(started, "JobID", "Partition", "State")
    done = [j for j in jobs if j[1] == cluster.partition and j[2] == "COMPLETED"]
    assert len(done) == 11, jobs
    assert rows(local / "results" / "selections.csv", {"train_wall_s", "source"}) == rows(
        on_slurm / "results" / "selections.csv", {"train_wall_s", "source"}
    )
    assert rows(local / "results" / "demo_seeds.csv", {"total_wall_s"}) == rows(
        on_slurm / "results" / "demo_seeds.csv", {"total_wall_s"}
    )
    for seed in (0, 1):
        model = f"demos/seed{seed}/prssm.json"
        assert (local / model).read_bytes() == (on_slurm / model).read_bytes(), model


def requeue_config(path):
    """One sweep run long enough to be requeued mid-training, checkpointing every 5 epochs."""
    path.write_text(json.dumps({
        "flapssm": str(FLAPSSM),
        "dataset": {"source": "generator", "n": 8, "seed": 5, "fidelity": "l0"},
        "sweeps": {"dx": [5]},
        "seeds": [0],
        "training": {"epochs": 1500, "inducing": 8, "particles": 4, "eval-particles": 4,
                     "checkpoint-every": 5},
        "threads": 1,
        "runtime_min": 10,
        "mem_mb": 1000,
    }))
    return path


def test_a_requeued_run_resumes_from_its_checkpoint(cluster, tmp_path):
    config = requeue_config(tmp_path / "requeue.json")
    on_slurm, local = tmp_path / "slurm", tmp_path / "local"
    cmd = snakemake(*slurm(cluster), cwd=on_slurm, config=config, start=True)
    checkpoint = on_slurm / "results" / "dx" / "dx5_seed0.ckpt.json"
    deadline = time.time() + 300
    while not checkpoint.exists():
        assert cmd.poll() is None, cmd.communicate()[1][-4000:]
        assert time.time() < deadline, "the sweep run never wrote a checkpoint"
        time.sleep(0.5)
    user = os.environ.get("USER", "root")
    job = next(
        line.split()[0]
        for line in run("squeue", "-h", "-u", user, "-o", "%i %T").stdout.splitlines()
        if line.split()[1] == "RUNNING"
    )
    run("scontrol", "requeue", job)
    out, err = cmd.communicate(timeout=900)
    assert cmd.returncode == 0, err[-6000:]
    states = run("sacct", "-D", "-X", "-n", "-P", "-j", job, "-o", "State").stdout.split()
    assert "REQUEUED" in states and states[-1] == "COMPLETED", states
    result = json.loads((on_slurm / "results" / "dx" / "dx5_seed0.json").read_text())
    assert result["resumed_at_step"] > 0, result.get("resumed_at_step")
    r = snakemake(*LOCAL, cwd=local, config=config)
    assert r.returncode == 0, r.stderr[-4000:]
    drop = {"train_wall_s", "resumed_at_step", "source"}
    assert rows(local / "results" / "selections.csv", drop) == rows(
        on_slurm / "results" / "selections.csv", drop
    )


def test_a_wrong_partition_is_named_not_waited_for(cluster, tmp_path):
    started = time.time()
    r = snakemake(*slurm(cluster, "nosuch"), cwd=tmp_path)
    assert r.returncode != 0
    assert "invalid partition specified: nosuch" in r.stdout + r.stderr, r.stderr[-4000:]
    assert time.time() - started < 300
