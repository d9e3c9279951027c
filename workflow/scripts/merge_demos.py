"""Merges the demos' summary.json files (one per seed) into results/demo_seeds.csv (one row per
seed: test RMSE per output of the PR-SSM and the LRQSM and their ratio, σ units) and
results/demo_seeds.md (the same with mean and min–max over seeds, then the paper-vs-flapssm rows
of every seed side by side). Called by the workflow's demo_merge rule."""

import csv
import io
import json
import os
import tempfile
from pathlib import Path


def atomic_write(path, text):
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.")
    with os.fdopen(fd, "w") as f:
        f.write(text)
    os.chmod(tmp, 0o644)  # mkstemp's 0600 is for the temporary only
    os.replace(tmp, path)


def cell(text):
    """A Markdown table cell: pipes escaped."""
    return str(text).replace("|", "\\|")


def merge(summaries, out_csv, out_md):
    runs = []
    for p in summaries:
        s = json.loads(Path(p).read_text())
        if s.get("format") != "flapssm-demo-summary":
            raise ValueError(f"{p}: not a flapssm demo summary (format {s.get('format')!r})")
        runs.append((s["config"]["seed"], s))
    runs.sort(key=lambda r: r[0])
    outputs = runs[0][1]["outputs"]
    fields = ["seed"] + [f"{m}_{o}" for m in ("prssm", "lrqsm", "ratio") for o in outputs]
    fields.append("total_wall_s")
    lines = []
    for seed, s in runs:
        row = [seed, *s["prssm_test_rmse"], *s["lrqsm_test_rmse"], *s["rmse_ratio"], s["total_wall_s"]]
        lines.append(row)
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(fields)
    w.writerows(lines)
    atomic_write(out_csv, buf.getvalue())

    def stat(key, j):
        v = [s[key][j] for _, s in runs]
        return f"{sum(v) / len(v):.3f} ({min(v):.3f}–{max(v):.3f})"

    md = [f"Test RMSE (σ), mean (min–max) over seeds {', '.join(str(r[0]) for r in runs)}:", ""]
    md.append("| | " + " | ".join(outputs) + " |")
    md.append("|---|" + "---|" * len(outputs))
    for label, key in (("PR-SSM", "prssm_test_rmse"), ("LRQSM", "lrqsm_test_rmse"), ("ratio", "rmse_ratio")):
        md.append(f"| {label} | " + " | ".join(stat(key, j) for j in range(len(outputs))) + " |")
    md += ["", "The paper beside each seed:", ""]
    header = "| endpoint | paper | " + " | ".join(f"seed {seed}" for seed, _ in runs) + " |"
    md += [header, "|---|---|" + "---|" * len(runs)]
    first = runs[0][1].get("paper_comparison", [])
    for i, row in enumerate(first):
        cells = []
        for _, s in runs:
            rows = s.get("paper_comparison", [])
            same = i < len(rows) and rows[i]["endpoint"] == row["endpoint"]
            cells.append(cell(rows[i]["flapssm"]) if same else "—")
        md.append(f"| {cell(row['endpoint'])} | {cell(row['paper'])} | " + " | ".join(cells) + " |")
    atomic_write(out_md, "\n".join(md) + "\n")


if "snakemake" in globals():
    merge(snakemake.input, snakemake.output[0], snakemake.output[1])  # noqa: F821
elif __name__ == "__main__":
    import sys

    if len(sys.argv) < 4:
        sys.exit("usage: merge_demos.py OUT.csv OUT.md SUMMARY.json...")
    merge(sys.argv[3:], sys.argv[1], sys.argv[2])
