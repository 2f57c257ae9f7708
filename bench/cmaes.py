"""CMA-ES (pycma) on primo's pouring cell, against primo's PoWER.

Usage: python bench/cmaes.py PRIMO_BINARY [--runs 20] [--budget 401] [--space joint] [--out FILE.md]

The cell is `primo experiment power`'s (joint space, small glass, 0.5 l
bottle, 0.2 l target, 30 kernels: 219 parameters), reached through
`primo rollout --serve` (one server per run; line n rolls out with the
scale's seed `--seed + n - 1`). CMA-ES searches z in the space scaled by
`--print-start`'s std (the PoWER exploration's per-block spread), x =
start + std * z, minimizing 1 - reward. After every generation the
distribution's mean is rolled out once, as PoWER rolls out its mean once
per update; both count toward the budget. Reported, as for PoWER: the
roll-outs made when the mean first reached reward 0.95 and 0.99 (median
and a bootstrap 90 % interval over seeds; a run that never did counts as
the budget, a lower bound), the cumulative regret sum(1 - r), and the last
mean's error and spill.
"""

import argparse
import csv
import json
import os
import random
import statistics
import subprocess
import sys
import tempfile
from concurrent.futures import ProcessPoolExecutor
from functools import partial

import cma
import numpy as np

THRESHOLDS = (0.95, 0.99)


class Server:
    """One `primo rollout --serve` process."""

    def __init__(self, primo, seed, space):
        self.proc = subprocess.Popen(
            [primo, "rollout", "--serve", "--seed", str(seed), "--space", space],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, bufsize=1)

    def __call__(self, x):
        self.proc.stdin.write(json.dumps([float(v) for v in x]) + "\n")
        answer = json.loads(self.proc.stdout.readline())
        if "invalid" in answer:
            raise RuntimeError(answer["invalid"])
        return answer

    def close(self):
        self.proc.stdin.close()
        self.proc.wait()


def run(primo, space, start, std, seed, budget, popsize, sigma0, diagonal):
    """One CMA-ES run: per roll-out (number, reward, is the mean)."""
    server = Server(primo, seed, space)
    options = {"seed": seed, "verbose": -9, "popsize": popsize,
               "CMA_diagonal": diagonal}
    es = cma.CMAEvolutionStrategy(np.zeros(len(start)), sigma0, options)
    made, log = 0, []
    try:
        while made + popsize + 1 <= budget:
            zs = es.ask()
            rewards = [server(start + std * z)["reward"] for z in zs]
            made += len(zs)
            log.extend((made - len(zs) + i + 1, r, False) for i, r in enumerate(rewards))
            es.tell(zs, [1.0 - r for r in rewards])
            mean = server(start + std * es.mean)
            made += 1
            log.append((made, mean["reward"], True, abs(mean["error"]), mean["spilled"]))
    finally:
        server.close()
    return log


def summarize(log, budget):
    means = [e for e in log if e[2]]
    reached = [next((e[0] for e in means if e[1] >= level), None) for level in THRESHOLDS]
    last = means[-1]
    return {"rollouts_to": reached, "regret": sum(1 - e[1] for e in log),
            "error": last[3], "spilled": last[4], "reward": last[1], "budget": budget}


def median_ci(values, seed=1, resamples=2000):
    rng = random.Random(seed)
    med = statistics.median(values)
    boot = sorted(statistics.median(rng.choices(values, k=len(values)))
                  for _ in range(resamples))
    return med, boot[int(0.05 * resamples)], boot[int(0.95 * resamples) - 1]


def row(name, runs, budget):
    cells = [name]
    for k, level in enumerate(THRESHOLDS):
        times = [r["rollouts_to"][k] or budget for r in runs]
        never = sum(r["rollouts_to"][k] is None for r in runs)
        med, lo, hi = median_ci(times)
        cells.append(f"{med:g} [{lo:g}, {hi:g}]" + (f" ({never} never)" if never else ""))
    regret = [r["regret"] for r in runs]
    cells.append(f"{statistics.median(regret):.1f}")
    err = [1e3 * r["error"] for r in runs]
    spill = [1e3 * r["spilled"] for r in runs]
    cells.append(f"{statistics.mean(err):.2f} ± {statistics.pstdev(err):.2f}")
    cells.append(f"{statistics.mean(spill):.2f} ± {statistics.pstdev(spill):.2f}")
    return "| " + " | ".join(cells) + " |"


def power_runs(primo, runs, budget):
    """primo's own PoWER (extended and ordinary) from `primo experiment power`."""
    updates = (budget - 1) // 4
    with tempfile.TemporaryDirectory() as out:
        subprocess.run([primo, "experiment", "power", "--runs", str(runs), "--updates",
                        str(updates), "--out", os.path.join(out, "p")], check=True,
                       stdout=subprocess.DEVNULL)
        rows = list(csv.DictReader(open(os.path.join(out, "p", "power_runs.csv"))))
    by = {}
    for r in rows:
        by.setdefault(r["variant"], []).append({
            "rollouts_to": [int(r[f"rollouts_to_{t}"]) if r[f"rollouts_to_{t}"] else None
                            for t in THRESHOLDS],
            "regret": float(r["regret"]), "error": float(r["final_error_l"]),
            "spilled": float(r["final_spilled_l"])})
    return by


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("primo")
    ap.add_argument("--runs", type=int, default=20)
    ap.add_argument("--budget", type=int, default=401)
    ap.add_argument("--space", choices=["joint", "cartesian"], default="joint",
                    help="the cell's space; PoWER's rows come from `primo experiment power`, "
                         "which is joint space only (Cartesian: bench/power_sweep.py)")
    ap.add_argument("--out")
    a = ap.parse_args()
    start_info = json.loads(subprocess.run([a.primo, "rollout", "--print-start", "--space",
                                            a.space], check=True,
                                           capture_output=True, text=True).stdout)
    start, std = np.array(start_info["start"]), np.array(start_info["std"])
    n = len(start)
    default_pop = 4 + int(3 * np.log(n))
    settings = [
        (f"CMA-ES, λ = {default_pop} (default), σ0 = 1", default_pop, 1.0, False),
        (f"CMA-ES, λ = {default_pop}, σ0 = 0.5", default_pop, 0.5, False),
        (f"sep-CMA-ES (diagonal), λ = {default_pop}, σ0 = 1", default_pop, 1.0, True),
        ("CMA-ES, λ = 8, σ0 = 1", 8, 1.0, False),
        ("CMA-ES, λ = 4, σ0 = 1", 4, 1.0, False),  # the suite's small population
    ]
    header = ("| learner | roll-outs to 0.95 | roll-outs to 0.99 | regret Σ(1−r) "
              "| final \\|error\\| ml | final spill ml |\n|---|---|---|---|---|---|")
    lines = [f"Cell: {start_info['space']} space, {start_info['glass']} glass, "
             f"{start_info['bottle']} l bottle, {start_info['target']} l target, {n} parameters; "
             f"budget {a.budget} roll-outs; {a.runs} seeds; medians with bootstrap 90 % intervals "
             f"(a run that never reached a level counts as the budget).", "", header]
    if a.space == "joint":
        for name, runs in power_runs(a.primo, a.runs, a.budget).items():
            lines.append(row(f"primo PoWER, {name}", runs, a.budget))
    # Processes, not threads: pycma draws from NumPy's global generator,
    # which runs in threads would share in an order that timing decides.
    with ProcessPoolExecutor(max_workers=os.cpu_count() or 2) as pool:
        for name, pop, sigma0, diagonal in settings:
            one = partial(run, a.primo, a.space, start, std, budget=a.budget, popsize=pop,
                          sigma0=sigma0, diagonal=diagonal)
            logs = pool.map(one, range(1, a.runs + 1))
            lines.append(row(name, [summarize(l, a.budget) for l in logs], a.budget))
            print(lines[-1], file=sys.stderr, flush=True)
    text = "\n".join(lines) + "\n"
    print(text)
    if a.out:
        with open(a.out, "w") as f:
            f.write(f"# CMA-ES against primo's PoWER on the pouring cell\n\n"
                    f"`bench/compare_cmaes.sh` (pycma {cma.__version__}).\n\n" + text)


if __name__ == "__main__":
    main()
