"""The guide's commands, run as a reader would type them.

Every ``sh`` block of the pages in ``GUIDE_PAGES`` carries an HTML comment just above it (invisible
on the site) that says how the test treats it:

- ``<!-- guide-test: run -->`` runs the block as written;
- ``<!-- guide-test: append ARGS -->`` runs it with ARGS added to its one command (a smaller size,
  so that the demo fits in the test suite);
- ``<!-- guide-test: skip REASON -->`` leaves it out, for a reason the page's reader can check.

A block without a comment fails the test, so a new command cannot slip into the guide untested.
The blocks of a page run in order in one fresh directory, with ``target/release/flapssm`` first on
PATH (the test command builds it before pytest runs), then the Python that runs the tests.
"""
import os
import pathlib
import re
import subprocess
import sys

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]
GUIDE_PAGES = ["getting-started.md", "own-rig.md"]
FENCE = re.compile(r"^<!-- guide-test: (run|append|skip)\s*(.*?)\s*-->\n```sh\n(.*?)^```", re.M | re.S)
ANY_SH = re.compile(r"^```sh\n", re.M)


def blocks(page, root=REPO):
    text = (root / "docs" / page).read_text()
    found = [(m.group(1), m.group(2), m.group(3)) for m in FENCE.finditer(text)]
    assert len(found) == len(ANY_SH.findall(text)), (
        f"docs/{page}: every ```sh block needs a <!-- guide-test: run|append ARGS|skip REASON --> line above it"
    )
    return found


def script(kind, args, body):
    if kind == "append":
        lines = [line for line in body.strip().splitlines() if line.strip() and not line.startswith("#")]
        assert len(lines) == 1, f"'append' needs a block of one command, got {lines}"
        return lines[0] + " " + args + "\n"
    return body


@pytest.mark.parametrize("page", GUIDE_PAGES)
def test_the_guides_commands_run(page, tmp_path):
    binary = REPO / "target" / "release" / "flapssm"
    assert binary.exists(), f"{binary} not built: run `cargo build --release -p flapssm` first"
    # The built binary first on PATH, then the Python running the tests (with numpy).
    python_bin = pathlib.Path(sys.executable).parent
    env = dict(os.environ, PATH=os.pathsep.join([str(binary.parent), str(python_bin), os.environ["PATH"]]))
    ran = 0
    for kind, args, body in blocks(page):
        if kind == "skip":
            assert args, f"docs/{page}: a skipped block must say why"
            continue
        run = subprocess.run(
            ["bash", "-euo", "pipefail", "-c", script(kind, args, body)],
            cwd=tmp_path, env=env, capture_output=True, text=True, timeout=900,
        )
        assert run.returncode == 0, f"docs/{page}, block:\n{body}\nstdout:\n{run.stdout[-3000:]}\nstderr:\n{run.stderr[-3000:]}"
        ran += 1
    assert ran > 0


def test_an_unmarked_block_is_refused(tmp_path):
    page = tmp_path / "docs" / "p.md"
    page.parent.mkdir()
    page.write_text("# P\n\n```sh\nflapssm --help\n```\n")
    with pytest.raises(AssertionError, match="needs a <!-- guide-test"):
        blocks("p.md", root=tmp_path)
