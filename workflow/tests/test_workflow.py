"""The Snakemake workflow on its tiny configuration: every rule runs (simulate, one sweep run per
kind × value × seed and their merge; one demo per seed and their merge), the merged sweep table
carries the paper's two selection rows with the spread over seeds, the merged demos one row per
seed and the paper's rows per seed, a second invocation has nothing to do, a lost result is
rerun from its run's checkpoint, and the Slurm profile plans the same jobs (dry run; the real
cluster's tests are test_slurm.py); a bad job resource is named before any job. The paper's two configurations plan their 14 runs each (dry run; the size curve's 512 is
the dx 12 run), the fast one with the fast preset; the paper's experiment on three seeds plans
three `demo --full --preset paper-fast` runs (a `true` option is a bare switch)."""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
WORKFLOW = ROOT / "workflow"
FLAPSSM = Path(os.environ.get("FLAPSSM", ROOT / "target" / "release" / "flapssm"))


def snakemake(*args, cwd, config="tiny.yaml", start=False):
    """Runs Snakemake on `config` (a file of workflow/config, or a path) in `cwd`; with `start`,
    returns the running process instead of waiting for it."""
    exe = shutil.which("snakemake", path=str(Path(sys.executable).parent)) or shutil.which(
        "snakemake"
    )
    if exe is None:
        pytest.fail("snakemake is not installed (scripts/test installs it)")
    cmd = [
        exe,
        "--snakefile",
        str(WORKFLOW / "Snakefile"),
        "--configfile",
        str(config if Path(str(config)).is_absolute() else WORKFLOW / "config" / config),
        "--config",
        f"flapssm={FLAPSSM}",
        "--directory",
        str(cwd),
        *args,
    ]
    if start:
        return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    return subprocess.run(cmd, capture_output=True, text=True, timeout=900)


def assert_planned(out, counts):
    """Snakemake's job-stats table in `out` lists each (rule, count)."""
    for rule, count in counts:
        assert any(
            line.split()[:2] == [rule, str(count)] for line in out.splitlines()
        ), out[-4000:]


def test_tiny_workflow_runs_merges_and_resumes(tmp_path):
    assert FLAPSSM.exists(), f"{FLAPSSM}: build it first (cargo build --release -p flapssm)"
    r = snakemake("--profile", str(WORKFLOW / "profiles" / "local"), cwd=tmp_path)
    assert r.returncode == 0, r.stderr[-4000:]
    csv = (tmp_path / "results" / "selections.csv").read_text().splitlines()
    # header + (2 D_x values + 1 size) × 2 seeds
    assert len(csv) == 1 + 3 * 2, csv
    assert {line.split(",")[0] for line in csv[1:]} == {"dx", "data-size"}
    table = json.loads((tmp_path / "results" / "selections.json").read_text())
    rows = table["paper_comparison"]
    assert [row["source"] for row in rows] == ["Methods, line 95"] * 2
    assert rows[0]["flapssm"].startswith("5: ") and "(2 seeds)" in rows[0]["flapssm"]
    assert rows[1]["flapssm"].startswith("4: ")
    assert (tmp_path / "results" / "selections.png").stat().st_size > 0
    assert (tmp_path / "logs" / "dx" / "dx6_seed1.log").exists()

    demos = (tmp_path / "results" / "demo_seeds.csv").read_text().splitlines()
    assert len(demos) == 3 and demos[0].startswith("seed,prssm_F_x"), demos
    assert [line.split(",")[0] for line in demos[1:]] == ["0", "1"]
    summary = json.loads((tmp_path / "demos" / "seed1" / "summary.json").read_text())
    ratio = float(demos[2].split(",")[11])
    assert abs(ratio - summary["rmse_ratio"][0]) < 1e-12
    md = (tmp_path / "results" / "demo_seeds.md").read_text()
    assert "| PR-SSM |" in md and "The paper beside each seed" in md and "seed 1 |" in md

    again = snakemake("--profile", str(WORKFLOW / "profiles" / "local"), cwd=tmp_path)
    assert again.returncode == 0, again.stderr[-4000:]
    assert "Nothing to be done" in again.stdout + again.stderr

    # A lost result (and the merge) reruns from its run's checkpoint (--resume), same errors.
    result = tmp_path / "results" / "dx" / "dx6_seed1.json"
    assert result.with_name("dx6_seed1.ckpt.json").exists()
    before = json.loads(result.read_text())
    result.unlink()
    for merged in (tmp_path / "results").glob("selections.*"):
        merged.unlink()
    rerun = snakemake("--profile", str(WORKFLOW / "profiles" / "local"), cwd=tmp_path)
    assert rerun.returncode == 0, rerun.stderr[-4000:]
    after = json.loads(result.read_text())
    assert after["resumed_at_step"] == before["steps"] == after["steps"]
    assert after["test"] == before["test"]
    assert "resuming dx = 6 at step" in (tmp_path / "logs" / "dx" / "dx6_seed1.log").read_text()


def test_slurm_profile_plans_the_same_jobs(tmp_path):
    r = snakemake(
        "--profile",
        str(WORKFLOW / "profiles" / "slurm"),
        "--default-resources",
        "slurm_account=test",
        "slurm_partition=test",
        "--dry-run",
        cwd=tmp_path,
    )
    assert r.returncode == 0, r.stderr[-4000:]
    assert_planned(
        r.stdout + r.stderr,
        [("simulate", 1), ("sweep_run", 6), ("merge", 1), ("demo_run", 2), ("demo_merge", 1)],
    )


@pytest.mark.parametrize("config,preset", [("paper.yaml", "paper"), ("paper-fast.yaml", "paper-fast")])
def test_the_paper_configurations_plan_fourteen_runs(tmp_path, config, preset):
    r = snakemake("--dry-run", "--printshellcmds", "--cores", "2", cwd=tmp_path, config=config)
    assert r.returncode == 0, r.stderr[-4000:]
    out = r.stdout + r.stderr
    assert_planned(out, [("simulate", 1), ("sweep_run", 14), ("merge", 1)])
    runs = [line for line in out.splitlines() if " sweep run " in line]
    assert len(runs) == 14 and all(f"--preset {preset} " in line for line in runs), runs[:2]


def test_the_full_demo_on_three_seeds_plans_switches(tmp_path):
    r = snakemake(
        "--dry-run", "--printshellcmds", "--cores", "2", cwd=tmp_path, config="paper-full.yaml"
    )
    assert r.returncode == 0, r.stderr[-4000:]
    runs = [line for line in (r.stdout + r.stderr).splitlines() if " demo --out " in line]
    assert len(runs) == 3, runs
    assert all("--full --preset paper-fast" in line and "True" not in line for line in runs), runs


def test_a_bad_job_resource_is_named_before_any_job(tmp_path):
    bad = tmp_path / "bad.yaml"
    text = (WORKFLOW / "config" / "tiny.yaml").read_text().replace("mem_mb: 1000", "mem_mb: 0")
    bad.write_text(text)
    r = snakemake("--profile", str(WORKFLOW / "profiles" / "local"), cwd=tmp_path / "run", config=bad)
    assert r.returncode != 0
    assert "config mem_mb: 0 is not a whole number >= 1" in r.stdout + r.stderr, r.stderr[-2000:]
    assert not (tmp_path / "run" / "data").exists()

