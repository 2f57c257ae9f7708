#!/usr/bin/env bash
# Host per-step time of a 7-DoF × 30-kernel DMP, plain and with one
# obstacle's coupling term on three of its DoFs (what the M4F probe counts
# in instructions): criterion's `dmp step 7x30` benches, RUNS times in
# turn (default 5). Per run: criterion's median ns/step, and the 10th
# percentile of its 100 samples (the least disturbed by other processes
# on a shared machine); then the median and the range over the runs, and
# the ratio coupled / plain run by run. Not part of ./test.sh.
#   bench/coupled_step.sh [RUNS]
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-5}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
out=$tmp/runs
for i in $(seq "$runs"); do
    cargo bench --locked -q -p primo-core --bench dmp -- 'dmp step 7x30' >/dev/null
    for name in 'dmp step 7x30' 'dmp step 7x30 with one obstacle'; do
        mkdir -p "$tmp/$i/$name"
        cp "target/criterion/$name/new/estimates.json" "target/criterion/$name/new/sample.json" "$tmp/$i/$name/"
        echo "$tmp/$i/$name"$'\t'"$name" >>"$out"
    done
    echo "run $i of $runs done" >&2
done
python3 - "$out" <<'PY'
import json, statistics, sys
runs = {}
for line in open(sys.argv[1]):
    path, name = line.rstrip("\n").split("\t")
    median = json.load(open(path + "/estimates.json"))["median"]["point_estimate"]
    sample = json.load(open(path + "/sample.json"))
    per = sorted(t / n for t, n in zip(sample["times"], sample["iters"]))
    runs.setdefault(name, []).append((median, per[len(per) // 10]))
names = list(runs)
for i, what in enumerate(["criterion's median", "10th percentile of the samples"]):
    print(f"\n{what}, ns/step, per run: median of the runs (min–max)\n")
    print("| what | ns/step | runs |")
    print("|---|---:|---:|")
    for name in names:
        ns = [r[i] for r in runs[name]]
        print(f"| {name} | {statistics.median(ns):.1f} ({min(ns):.1f}–{max(ns):.1f}) | {len(ns)} |")
    ratios = [c[i] / p[i] for p, c in zip(*runs.values())]
    print(f"\ncoupled / plain run by run: median {statistics.median(ratios):.2f} "
          f"({min(ratios):.2f}–{max(ratios):.2f}); per run (plain, coupled): "
          + "; ".join(f"{p[i]:.0f}, {c[i]:.0f}" for p, c in zip(*runs.values())))
PY
