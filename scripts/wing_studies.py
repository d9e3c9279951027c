#!/usr/bin/env python3
"""Runs the virtual wing's studies and writes what they print to docs/lab/wing-studies.md.

The studies are the tests of crates/wing/tests whose figures the docs quote: each checks its
figures against the values recorded here (with a tolerance) and prints them. The quick ones run
with the test suite; the long ones (minutes of simulation) are `#[ignore]`d there and run here.
The lab record cites their figures from the page this script writes: each study's command,
wall time and output, with the date and the machine. The page is written whole (temporary file, then
rename), so an interrupted run leaves the previous one in place.

    python3 scripts/wing_studies.py                  # all studies (about 15 minutes on 2 cores)
    python3 scripts/wing_studies.py --only l3_study  # one, merged into the existing page
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PAGE = ROOT / "docs" / "lab" / "wing-studies.md"

# (test file, study), in the order of the page.
STUDIES = [
    ("physics", "l2_sensitivity_study"),
    ("physics", "l2_burst_study"),
    ("physics", "repeatability_study"),
    ("physics", "l2_wake_motion_study"),
    ("physics", "l3_study"),
    ("vortex", "study_hover_spikes"),
    ("vortex", "study_wake_capture"),
    ("vortex", "study_wing_hover_trace"),
    ("vortex", "study_wake_capture_paper"),
    ("vortex", "study_chordwise_force_with_lev_shedding"),
    ("vortex", "study_strip_bursts_paper"),
    ("memory", "study_l2_memory_evidence"),
    ("memory", "paper_memory_study"),
    ("lattice", "l3_wake_capture_study"),
]

HEADER = """# Virtual wing studies: their current output

Written by `python3 scripts/wing_studies.py` (do not edit by hand): each study of
`crates/wing/tests` whose figures the docs quote, run with the command shown, its wall time and
what it printed. Each checks its figures against the values recorded in its test (with a
tolerance), so a change that moves them fails it. The lab record's rounds quote earlier outputs of the same studies; the
figures below are the current ones.

"""


def command(test: str, study: str) -> list[str]:
    return [
        "cargo", "test", "--release", "-q", "-p", "flapssm-wing", "--test", test, study,
        "--", "--include-ignored", "--exact", "--nocapture", "--test-threads", "1",
    ]


def machine() -> str:
    model = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{model}, {os.cpu_count()} cores"


def run(test: str, study: str) -> str:
    """The study's section: its command, wall time and printed lines."""
    cmd = command(test, study)
    start = time.monotonic()
    done = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    wall = time.monotonic() - start
    if done.returncode != 0:
        sys.stderr.write(done.stdout + done.stderr)
        raise SystemExit(f"error: study {study} ({test}.rs) failed with status {done.returncode}")
    printed = [
        line for line in done.stdout.splitlines()
        if line.strip()
        and not re.match(r"^(running \d+ tests?|test result:|test \S+ \.\.\. ok|\.+$)", line)
    ]
    if not printed:
        raise SystemExit(f"error: study {study} ({test}.rs) printed nothing")
    day = datetime.date.today().isoformat()
    return (
        f"## `{study}` ({test}.rs)\n\n"
        f"`{' '.join(cmd)}`: {wall:.1f} s on {machine()}, {day}.\n\n"
        "```text\n" + "\n".join(printed) + "\n```\n"
    )


def sections(text: str) -> dict[str, str]:
    """The existing page's sections by study name."""
    out = {}
    for block in re.split(r"(?m)^(?=## `)", text):
        m = re.match(r"## `(\w+)`", block)
        if m:
            out[m.group(1)] = block.rstrip() + "\n"
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", action="append", default=[], metavar="STUDY",
                        help="run only this study (repeatable); the others keep their section")
    args = parser.parse_args()
    names = [s for _, s in STUDIES]
    unknown = [s for s in args.only if s not in names]
    if unknown:
        raise SystemExit(f"error: --only {unknown[0]}: not a study (one of {', '.join(names)})")
    old = sections(PAGE.read_text()) if PAGE.exists() else {}
    page = {}
    for test, study in STUDIES:
        if args.only and study not in args.only:
            if study in old:
                page[study] = old[study]
            continue
        print(f"{study} ({test}.rs) …", file=sys.stderr, flush=True)
        page[study] = run(test, study)
    text = HEADER + "\n".join(page[s] for _, s in STUDIES if s in page)
    with tempfile.NamedTemporaryFile("w", dir=PAGE.parent, delete=False, suffix=".tmp") as f:
        f.write(text)
    os.replace(f.name, PAGE)
    print(f"wrote {PAGE.relative_to(ROOT)}", file=sys.stderr)


if __name__ == "__main__":
    main()
