"""Building the package without the Rust it needs is refused, in the
user's terms, before anything is downloaded (maturin's own backend would
fetch a toolchain of about 800 MB)."""

import os
import pathlib
import re
import stat
import subprocess
import sys

import pytest

from conftest import ROOT

SOURCE = ROOT / "python"


def rust_version() -> str:
    manifest = (SOURCE / "Cargo.toml").read_text()
    return re.search(r'^rust-version = "([^"]+)"', manifest, re.MULTILINE).group(1)


def pip_wheel(tmp_path: pathlib.Path, path: str) -> subprocess.CompletedProcess:
    """`pip wheel ./python` with PATH = `path`, offline: with no index and no
    build isolation nothing can be installed, so a refusal that comes too late
    shows as another error, not as a download."""
    pytest.importorskip(
        "maturin", reason="maturin is not installed here (the backend runs without build isolation)"
    )
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PIP_", "MATURIN_", "CARGO"))}
    env.update(PATH=path, PIP_NO_INDEX="1", PIP_DISABLE_PIP_VERSION_CHECK="1")
    return subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation",
         "-w", str(tmp_path / "wheels"), str(SOURCE)],
        env=env, capture_output=True, text=True, timeout=120,
    )


def assert_refused(done: subprocess.CompletedProcess, reason: str) -> None:
    said = done.stdout + done.stderr
    assert done.returncode != 0, said
    assert reason in said, said
    assert f"needs Rust {rust_version()} or newer (edition 2024)" in said, said
    assert "https://rustup.rs" in said, said
    # maturin's bootstrap was never reached.
    assert "puccinialin" not in said and "Rust not found" not in said, said


def test_without_cargo_the_build_names_the_rust_to_install(tmp_path):
    empty = tmp_path / "bin"
    empty.mkdir()
    assert_refused(pip_wheel(tmp_path, str(empty)), "cargo was not found on the PATH")


@pytest.mark.parametrize("cargo_says, reason", [
    ("echo 'cargo 1.84.1 (66221abde 2024-11-19)'", "is Rust 1.84.1, too old"),
    # rustup's proxy without a default toolchain
    ("echo 'error: rustup could not choose a version of cargo to run' >&2; exit 1",
     "rustup could not choose a version of cargo to run"),
])
def test_a_cargo_that_is_too_old_or_has_no_toolchain_is_refused(tmp_path, cargo_says, reason):
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    cargo = bin_dir / "cargo"
    cargo.write_text(f"#!/bin/sh\n{cargo_says}\n")
    cargo.chmod(cargo.stat().st_mode | stat.S_IXUSR)
    assert_refused(pip_wheel(tmp_path, str(bin_dir)), reason)
