"""primo-robotics' build backend: maturin's, once the Rust it needs is found.

Without cargo on the PATH, maturin's own backend downloads a Rust toolchain
of about 800 MB into a temporary directory (through puccinialin) and builds
with that. This one refuses instead, in whichever hook the frontend calls
first, before maturin's runs, and says which Rust to install; with Rust
found, every hook is maturin's.
"""

from __future__ import annotations

import functools
import re
import shutil
import subprocess

import maturin

try:
    import tomllib
except ModuleNotFoundError:  # Python < 3.11: maturin depends on tomli there
    import tomli as tomllib


def _rust_version() -> tuple[int, ...]:
    """The Rust the extension needs: its crate's `rust-version` (the crate is
    python/Cargo.toml in the sdist, whose root holds the workspace's)."""
    with open("pyproject.toml", "rb") as f:
        maturin_config = tomllib.load(f).get("tool", {}).get("maturin", {})
    with open(maturin_config.get("manifest-path", "Cargo.toml"), "rb") as f:
        return tuple(int(part) for part in tomllib.load(f)["package"]["rust-version"].split("."))


def _check_rust() -> None:
    """Exits with what to install unless cargo is on the PATH and new enough."""
    needed = _rust_version()
    wanted = ".".join(map(str, needed))
    install = (
        f"primo-robotics is built from its Rust source here and needs Rust {wanted} "
        f"or newer (edition 2024) with cargo on the PATH: install it with rustup "
        f"(https://rustup.rs; `rustup update` brings an older one up to date), "
        f"then run pip again from a new shell."
    )
    cargo = shutil.which("cargo")
    if cargo is None:
        raise SystemExit(f"error: cargo was not found on the PATH.\n{install}")
    try:
        done = subprocess.run([cargo, "--version"], capture_output=True, text=True)
    except OSError as e:
        raise SystemExit(f"error: {cargo} --version failed: {e}\n{install}") from None
    found = re.match(r"cargo (\d+)\.(\d+)\.(\d+)", done.stdout)
    if found is None:
        # e.g. rustup without a default toolchain, which says so on stderr
        said = (done.stdout + done.stderr).strip()
        raise SystemExit(f"error: {cargo} --version said {said!r}.\n{install}")
    have = tuple(int(part) for part in found.groups())
    if have[: len(needed)] < needed:
        raise SystemExit(f"error: {cargo} is Rust {'.'.join(found.groups())}, too old.\n{install}")


def _checked(hook):
    """maturin's hook, run once Rust is found."""

    @functools.wraps(hook)
    def checked(*args, **kwargs):
        _check_rust()
        return hook(*args, **kwargs)

    return checked


get_requires_for_build_wheel = _checked(maturin.get_requires_for_build_wheel)
get_requires_for_build_editable = _checked(maturin.get_requires_for_build_editable)
get_requires_for_build_sdist = _checked(maturin.get_requires_for_build_sdist)
prepare_metadata_for_build_wheel = _checked(maturin.prepare_metadata_for_build_wheel)
prepare_metadata_for_build_editable = _checked(maturin.prepare_metadata_for_build_editable)
build_wheel = _checked(maturin.build_wheel)
build_editable = _checked(maturin.build_editable)
build_sdist = _checked(maturin.build_sdist)
