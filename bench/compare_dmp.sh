#!/usr/bin/env bash
# Compare primo's DMP with the Python package movement_primitives (accuracy
# and replay time); writes bench/results/dmp_accuracy.md. Needs PyPI, takes
# about 8 minutes, and is not part of ./test.sh.
#   bench/compare_dmp.sh [--quick]   (--quick: fewer rates, 1 timing run, no file)
#   bench/compare_dmp.sh --timing [--runs N]   (the replay time alone, printed, no file)
#   bench/compare_dmp.sh --kernel-width   (the diagnostic bench/kernel_width.py)
#   bench/compare_dmp.sh --turns   (long turns, goal changes, via-points:
#                                   bench/compare_turns.py, about 5 minutes)
set -euo pipefail
cd "$(dirname "$0")/.."

# A throw-away virtual environment: nothing of movement_primitives is kept.
venv=$(mktemp -d)
trap 'rm -rf "$venv"' EXIT
python3 -m venv "$venv"
# movement_primitives declares no dependencies; its dmp module imports
# pytransform3d (which brings scipy and matplotlib). Its Cython step
# functions are built from the source package at install.
"$venv/bin/pip" install --quiet movement_primitives==0.9.1 numpy pytransform3d

if [ "${1:-}" = --kernel-width ]; then
    "$venv/bin/python" bench/kernel_width.py
    exit
fi
CARGO_TARGET_DIR="$PWD/target" cargo build --release --locked --bin primo
if [ "${1:-}" = --turns ]; then
    shift
    "$venv/bin/python" bench/compare_turns.py target/release/primo "$@"
    exit
fi
"$venv/bin/python" bench/compare_dmp.py target/release/primo "$@"
