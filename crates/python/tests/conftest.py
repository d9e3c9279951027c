"""Shared fixtures: the repository, the CLI binary built by `cargo test --release` (the
README's test command builds it before pytest runs) and ../shared/reference."""

import pathlib
import signal
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[3]
SHARED = REPO.parent / "shared"


@pytest.fixture(scope="session")
def cli():
    exe = REPO / "target" / "release" / "flapssm"
    assert exe.exists(), f"{exe} missing: build it with cargo build --release -p flapssm"

    def run(*args):
        return subprocess.run([str(exe), *map(str, args)], check=True, capture_output=True, text=True)

    return run


@pytest.fixture(scope="session")
def published():
    return SHARED / "reference" / "bayiz2021-prssm" / "reference.npz"


@pytest.fixture
def sigint_raises():
    """SIGINT raises KeyboardInterrupt during the test, whatever the process inherited: a job
    that a non-interactive shell starts in the background (`cmd &`, `nohup cmd &`) ignores
    SIGINT, Python keeps that disposition, and a test that sends SIGINT would then wait for
    a training that never stops."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)
