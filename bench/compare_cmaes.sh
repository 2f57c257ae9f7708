#!/usr/bin/env bash
# CMA-ES (pycma) against primo's PoWER on the pouring cell, same cell, same
# budget; writes bench/results/cmaes.md. Needs PyPI; not part of ./test.sh.
#   bench/compare_cmaes.sh [--runs 20] [--budget 401]
set -euo pipefail
cd "$(dirname "$0")/.."
venv=$(mktemp -d)
trap 'rm -rf "$venv"' EXIT
python3 -m venv "$venv"
"$venv/bin/pip" install --quiet cma==4.4.0 numpy
CARGO_TARGET_DIR="$PWD/target" cargo build --release --locked --bin primo
"$venv/bin/python" bench/cmaes.py target/release/primo --out bench/results/cmaes.md "$@"
