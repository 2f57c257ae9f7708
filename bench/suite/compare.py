"""Issue 28's measure from a suite.csv: per task and method, the success
rate and the median roll-outs (a failure counted as the budget) over all
runs and over the contexts the generalized movement misses, each median
also as a share of the best CMA-ES setting's (the one that succeeds most
often, of those the fewest roll-outs).

    target/bench-venv/bin/python bench/suite/compare.py bench/results/suite-goals/suite.csv

Several files are read as one run: a (task, context, seed, method) that
more than one holds counts once, from the first (runs of the same wheel
agree on the methods they share: the learners are seeded).
"""

from __future__ import annotations

import argparse
import csv

import numpy as np


def stats(rows, budget):
    """Success rate, its range over seeds, and the roll-outs with failures
    counted as the budget: median and quartiles."""
    censored = [int(r["rollouts_to_success"]) if r["success"] == "1" else budget for r in rows]
    seeds = sorted({r["seed"] for r in rows})
    per_seed = [np.mean([r["success"] == "1" for r in rows if r["seed"] == s]) for s in seeds]
    q = np.percentile(censored, [50, 25, 75])
    return np.mean([r["success"] == "1" for r in rows]), (min(per_seed), max(per_seed)), q


def table(rows, budget, subset=None):
    """Markdown rows: one per method, over ``subset`` of the contexts."""
    rows = [r for r in rows if subset is None or r["context"] in subset]
    methods = list(dict.fromkeys(r["method"] for r in rows))
    by = {m: stats([r for r in rows if r["method"] == m], budget) for m in methods}
    cma = [m for m in methods if m.startswith("cma")]
    best = min(cma, key=lambda m: (-by[m][0], by[m][2][0])) if cma else None
    lines = ["| method | success (per seed) | roll-outs, failures as the budget | of the best CMA-ES's |",
             "|---|---|---|---|"]
    for m in methods:
        rate, (low, high), q = by[m]
        share = f"{q[0] / by[best][2][0]:.2f}" if best and by[best][2][0] else "–"
        lines.append(f"| {m} | {rate:.0%} ({low:.0%}–{high:.0%}) | {q[0]:g} [{q[1]:g}, {q[2]:g}] | {share} |")
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("csv", nargs="+", help="suite.csv files")
    parser.add_argument("--budget", type=int, default=50, help="the runs' budget of roll-outs")
    args = parser.parse_args(argv)
    rows, seen = [], set()
    for path in args.csv:
        with open(path, newline="") as f:
            for row in csv.DictReader(f):
                key = (row["task"], row["context"], row["seed"], row["method"])
                if key not in seen:
                    seen.add(key)
                    rows.append(row)
    for task in dict.fromkeys(r["task"] for r in rows):
        rs = [r for r in rows if r["task"] == task]
        missed = sorted({r["context"] for r in rs if r["method"] == "generalized" and r["success"] == "0"}, key=int)
        contexts = {r["context"] for r in rs}
        print(f"### {task}\n\nAll {len(contexts)} contexts:\n")
        print("\n".join(table(rs, args.budget)))
        if 0 < len(missed) < len(contexts):
            print(f"\nThe {len(missed)} contexts the generalized movement misses ({', '.join(missed)}):\n")
            print("\n".join(table(rs, args.budget, set(missed))))
        print()


if __name__ == "__main__":
    main()
