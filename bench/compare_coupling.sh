#!/usr/bin/env bash
# Obstacle avoidance, primo against movement_primitives on the same scenes
# (bench/compare_coupling.py), in a throw-away virtual environment: the
# peer from PyPI, primo built from ./python (about 2 minutes cold). Not
# part of ./test.sh.
#   bench/compare_coupling.sh
set -euo pipefail
cd "$(dirname "$0")/.."

venv=$(mktemp -d)
trap 'rm -rf "$venv"' EXIT
python3 -m venv "$venv"
# movement_primitives declares no dependencies; its dmp module imports
# pytransform3d (which brings scipy and matplotlib).
"$venv/bin/pip" install --quiet --disable-pip-version-check \
  movement_primitives==0.9.1 pytransform3d numpy
CARGO_TARGET_DIR="$PWD/target/python" "$venv/bin/pip" install --quiet ./python
"$venv/bin/python" bench/compare_coupling.py
