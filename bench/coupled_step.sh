#!/usr/bin/env bash
# Host per-step time of a 7-DoF × 30-kernel DMP, plain and with one
# obstacle's coupling term on three of its DoFs (what the M4F probe counts
# in instructions): criterion's `dmp step 7x30` benches, RUNS times in
# turn (default 5), each run's median ns/step, then the median and the
# range over the runs. Not part of ./test.sh.
#   bench/coupled_step.sh [RUNS]
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-5}
out=$(mktemp)
trap 'rm -f "$out"' EXIT
for i in $(seq "$runs"); do
    cargo bench --locked -q -p primo-core --bench dmp -- 'dmp step 7x30' >/dev/null
    for name in 'dmp step 7x30' 'dmp step 7x30 with one obstacle'; do
        python3 -c 'import json, sys; print(sys.argv[2] + "\t" + str(json.load(open(sys.argv[1]))["median"]["point_estimate"]))' \
            "target/criterion/$name/new/estimates.json" "$name" >>"$out"
    done
    echo "run $i of $runs done" >&2
done
python3 - "$out" <<'EOF'
import statistics, sys
runs = {}
for line in open(sys.argv[1]):
    name, ns = line.rstrip("\n").split("\t")
    runs.setdefault(name, []).append(float(ns))
print("| what | median of the runs' medians | min–max | runs |")
print("|---|---:|---:|---:|")
for name, ns in runs.items():
    print(f"| {name} | {statistics.median(ns):.1f} ns | {min(ns):.1f}–{max(ns):.1f} ns | {len(ns)} |")
plain, coupled = runs.values()
ratios = [c / p for p, c in zip(plain, coupled)]
print(f"\nThe obstacle's term adds {statistics.median(coupled) - statistics.median(plain):.1f} ns "
      f"a step (medians); coupled / plain run by run: median {statistics.median(ratios):.2f}, "
      f"{min(ratios):.2f}–{max(ratios):.2f}.")
print("Per run (plain, coupled, ns): " + "; ".join(f"{p:.0f}, {c:.0f}" for p, c in zip(plain, coupled)))
EOF
