#!/usr/bin/env bash
# primo's Python package against movement_primitives and pydmps in one
# process, in a throw-away virtual environment: the peers from PyPI, primo
# built from ./python (about 2 minutes cold). Not part of ./test.sh.
#   bench/compare_python.sh                           # DMP speed: fit, run, argument conversion (python/bench/bench.py)
#   bench/compare_python.sh bench/compare_coupling.py # obstacle avoidance on the same scenes
#   bench/compare_python.sh bench/compare_promp.py    # ProMPs: mean and variance before and after conditioning
set -euo pipefail
cd "$(dirname "$0")/.."
script=${1:-python/bench/bench.py}

venv=$(mktemp -d)
trap 'rm -rf "$venv"' EXIT
python3 -m venv "$venv"
# movement_primitives declares no dependencies; its dmp module imports
# pytransform3d (which brings scipy and matplotlib).
"$venv/bin/pip" install --quiet --disable-pip-version-check \
  movement_primitives==0.9.1 pytransform3d pydmps==0.2 numpy
CARGO_TARGET_DIR="$PWD/target/python" "$venv/bin/pip" install --quiet ./python
"$venv/bin/python" "$script"
