#!/usr/bin/env bash
# The benchmark suite of issue 28 (bench/suite/README.md) in its own
# virtual environment, target/bench-venv (kept: later runs skip the
# install), with primo from its wheel: $PRIMO_WHEEL, or the one ./test.sh
# builds into target/python-dist. Runs at the lowest priority.
#   bench/suite/run.sh --smoke
#   bench/suite/run.sh --tasks reach-v3 Reacher-v5 --contexts 20 --seeds 3 --budget 50
set -euo pipefail
cd "$(dirname "$0")/../.."
venv=${BENCH_VENV:-target/bench-venv}
wheel=${PRIMO_WHEEL:-$(ls target/python-dist/*.whl 2>/dev/null | head -n 1)}
if [ -z "$wheel" ]; then
  echo "bench/suite/run.sh: no primo wheel; run ./test.sh, or" \
    "pip wheel --no-deps -w target/python-dist ./python, or set PRIMO_WHEEL" >&2
  exit 1
fi
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
"$venv/bin/pip" install -q --disable-pip-version-check -r bench/suite/requirements.txt
"$venv/bin/pip" install -q --disable-pip-version-check --no-deps --force-reinstall "$wheel"
exec nice -n 19 "$venv/bin/python" bench/suite/suite.py "$@"
