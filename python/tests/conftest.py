"""Shared fixtures: the `primo` binary the package is compared with."""

import json
import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def primo_bin() -> pathlib.Path:
    """The `primo` binary: $PRIMO_BIN, else cargo's (built if missing)."""
    given = os.environ.get("PRIMO_BIN")
    if given:
        return pathlib.Path(given)
    meta = subprocess.run(
        ["cargo", "metadata", "--format-version", "1", "--no-deps"],
        cwd=ROOT, check=True, capture_output=True, text=True,
    )
    binary = pathlib.Path(json.loads(meta.stdout)["target_directory"]) / "debug" / "primo"
    if not binary.exists():
        subprocess.run(["cargo", "build", "--bin", "primo"], cwd=ROOT, check=True)
    return binary


@pytest.fixture(scope="session")
def run_primo(primo_bin):
    """Runs `primo ARGS...` and returns its standard output."""

    def run(*args: str) -> str:
        done = subprocess.run([str(primo_bin), *args], capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        return done.stdout

    return run
