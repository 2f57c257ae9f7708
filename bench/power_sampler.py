#!/usr/bin/env python3
"""PoWER's importance sampler on the pouring cell: `primo pour` with
`--sampler 2` and `--sampler 3` for power and power-el over both spaces,
both glasses and four bottle/target pairs (the paper's 0.5/0.2 among
them), seeds 1..N, budget 49 roll-outs. Per setting: roll-outs until the
mean's roll-out first reaches reward 0.95 and 0.99 (median over seeds; a
run that never does counts as 999), runs that never reach 0.95, and the
mean regret Σ(1 − r). Standard library only.

    python3 bench/power_sampler.py target/release/primo [--seeds 20] [--jobs 2]
"""

import argparse
import csv
import itertools
import os
import statistics
import subprocess
import tempfile
from concurrent.futures import ThreadPoolExecutor

SPACES = ["joint", "cartesian"]
GLASSES = ["small", "normal"]
VOLUMES = [("0.5", "0.2"), ("0.4", "0.15"), ("0.8", "0.3"), ("0.35", "0.1")]
METHODS = ["power-el", "power"]
SAMPLERS = [2, 3]
BUDGET = 49
NEVER = 999


def run(primo, tmp, job):
    space, glass, (bottle, target), method, sampler, seed = job
    out = os.path.join(tmp, "-".join(map(str, [space, glass, bottle, target, method, sampler, seed])))
    subprocess.run(
        [primo, "pour", "--method", method, "--space", space, "--glass", glass, "--bottle", bottle,
         "--target", target, "--sampler", str(sampler), "--seed", str(seed), "--max-rollouts", str(BUDGET),
         "--out", out, "--force"],
        check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    with open(os.path.join(out, "rollouts.csv")) as f:
        rows = list(csv.DictReader(f))
    means = [(int(r["rollout"]), float(r["reward"])) for r in rows if r["mean"] == "true"]
    first = lambda level: next((n for n, r in means if r >= level), NEVER)  # noqa: E731
    return job, first(0.95), first(0.99), sum(1 - float(r["reward"]) for r in rows)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("primo")
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--jobs", type=int, default=2)
    a = ap.parse_args()
    jobs = list(itertools.product(SPACES, GLASSES, VOLUMES, METHODS, SAMPLERS, range(1, a.seeds + 1)))
    results = {}
    with tempfile.TemporaryDirectory() as tmp, ThreadPoolExecutor(a.jobs) as pool:
        for job, to95, to99, regret in pool.map(lambda j: run(a.primo, tmp, j), jobs):
            results.setdefault(job[:5], []).append((to95, to99, regret))

    def median(counts):
        m = statistics.median(counts)
        return "never" if m > BUDGET else f"{m:g}"  # the median run never got there

    def cell(runs):
        to95, to99, regret = zip(*runs)
        never = sum(t == NEVER for t in to95)
        return f"{median(to95)} ({never}) | {median(to99)} | {statistics.mean(regret):.1f}"

    print(f"{a.seeds} seeds each; median roll-outs to 0.95 (runs that never reach it) | to 0.99 | mean regret\n")
    print("| space | glass | bottle, target (l) | method | sampler 2 | | | sampler 3 | | |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for space, glass, (bottle, target), method in itertools.product(SPACES, GLASSES, VOLUMES, METHODS):
        key = (space, glass, (bottle, target), method)
        print(f"| {space} | {glass} | {bottle}, {target} | {method} | "
              + " | ".join(cell(results[key + (s,)]) for s in SAMPLERS) + " |")


if __name__ == "__main__":
    main()
