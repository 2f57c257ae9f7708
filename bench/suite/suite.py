"""primo's learners against CMA-ES and PI-BB on Metaworld and Gymnasium
MuJoCo tasks (issue 28), every episode run by primo.gym.BlackBox.

    bench/suite/run.sh [--tasks reach-v3 Reacher-v5] [--contexts 20] [--seeds 3] [--budget 50]
    bench/suite/run.sh --smoke

Writes <out>/suite.csv (one row per task, context, seed and method),
<out>/suite.md (the tables, with the command and date) and, with
matplotlib, <out>/suite.png (success within k roll-outs).
"""

from __future__ import annotations

import argparse
import csv
import datetime
import multiprocessing
import os
import sys
import time
import warnings

import numpy as np

from learners import METHODS
from tasks import HELD_OUT_SEED, TASKS

COLUMNS = ["task", "context", "seed", "method", "success", "rollouts", "rollouts_to_success",
           "rejected", "final_return", "best_return", "final_error", "seconds"]

_cache: dict = {}  # per process: (task name, regression) -> (problem, held-out contexts)


def _setup(name: str, contexts: int, regression: str):
    if (name, regression) not in _cache:
        warnings.filterwarnings("ignore")  # Metaworld's and pycma's import chatter
        task = TASKS[name]
        env = task.make()
        _cache[name, regression] = (task.problem(env, regression), task.contexts(env, contexts, HELD_OUT_SEED))
    return _cache[name, regression]


def run_one(job):
    name, contexts, index, seed, method, budget, regression = job
    problem, held_out = _setup(name, contexts, regression)
    start = time.perf_counter()
    episodes = METHODS[method](problem, held_out[index], budget, seed)
    first = next((k for k, e in enumerate(episodes, 1) if e.success), None)
    returns = [e.episode_return for e in episodes if not e.rejected]
    last = episodes[-1]
    return {
        "task": name, "context": index, "seed": seed, "method": method,
        "success": int(first is not None), "rollouts": len(episodes),
        "rollouts_to_success": "" if first is None else first,
        "rejected": sum(1 for e in episodes if e.rejected),
        "final_return": "" if last.rejected else round(last.episode_return, 4),
        "best_return": round(max(returns), 4) if returns else "",
        "final_error": "" if last.rejected else round(float(np.linalg.norm(last.error)), 5),
        "seconds": round(time.perf_counter() - start, 3),
    }


def _median_interval(values):
    if not values:
        return "–"
    q = np.percentile(values, [50, 25, 75])
    return f"{q[0]:g} [{q[1]:g}, {q[2]:g}]"


def summary(rows, budget, seeds):
    """Markdown: per task and method, success rate (and its range over
    seeds), roll-outs to success, and the final episode's return."""
    lines = []
    for task in dict.fromkeys(r["task"] for r in rows):
        lines += [f"### {task}", "",
                  "| method | success | per seed | roll-outs to success, of successes | "
                  "roll-outs, failures counted as the budget | final return | rejected roll-outs |",
                  "|---|---|---|---|---|---|---|"]
        for method in METHODS:
            rs = [r for r in rows if r["task"] == task and r["method"] == method]
            if not rs:
                continue
            ok = [int(r["rollouts_to_success"]) for r in rs if r["success"]]
            censored = [int(r["rollouts_to_success"]) if r["success"] else budget for r in rs]
            per_seed = [np.mean([r["success"] for r in rs if r["seed"] == s]) for s in seeds]
            spread = f"{min(per_seed):.0%}–{max(per_seed):.0%}" if len(seeds) > 1 else "–"
            lines.append(
                f"| {method} | {len(ok)}/{len(rs)} ({len(ok) / len(rs):.0%}) | {spread} | "
                f"{_median_interval(ok)} | {_median_interval(censored)} | "
                f"{np.median([r['final_return'] for r in rs if r['final_return'] != '']):.2f} | "
                f"{sum(r['rejected'] for r in rs)} |"
            )
        lines.append("")
    return "\n".join(lines)


def plot(rows, budget, path):
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return False
    tasks = list(dict.fromkeys(r["task"] for r in rows))
    fig, axes = plt.subplots(1, len(tasks), figsize=(4.5 * len(tasks), 3.6), squeeze=False)
    k = np.arange(1, budget + 1)
    for ax, task in zip(axes[0], tasks):
        for method in METHODS:
            rs = [r for r in rows if r["task"] == task and r["method"] == method]
            if rs:
                hit = [int(r["rollouts_to_success"]) for r in rs if r["success"]]
                ax.step(k, [sum(h <= i for h in hit) / len(rs) for i in k], where="post", label=method)
        ax.set(title=task, xlabel="roll-outs", ylim=(0, 1.02))
    axes[0][0].set_ylabel("contexts × seeds succeeded")
    axes[0][-1].legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return True


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--tasks", nargs="+", default=list(TASKS), choices=list(TASKS))
    parser.add_argument("--methods", nargs="+", default=list(METHODS), choices=list(METHODS))
    parser.add_argument("--contexts", type=int, default=20, help="held-out contexts per task")
    parser.add_argument("--seeds", type=int, default=3, help="seeds of every learner per context")
    parser.add_argument("--first-seed", type=int, default=1, help="seeds run from this one on")
    parser.add_argument("--budget", type=int, default=50, help="roll-outs per learner and context")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--regression", choices=["lwr", "gpr"], default="lwr",
                        help="the Generalizer's regression: primo's default LWR or GPR with a linear mean")
    parser.add_argument("--out", help="default bench/results/suite, with --smoke target/bench-smoke")
    parser.add_argument("--smoke", action="store_true",
                        help="reach-v3, Reacher-v5 and push-v3, one context, 3 roll-outs per method")
    args = parser.parse_args(argv)
    if args.smoke:
        args.tasks, args.contexts, args.seeds, args.budget = ["reach-v3", "Reacher-v5", "push-v3"], 1, 1, 3
    args.out = args.out or ("target/bench-smoke" if args.smoke else "bench/results/suite")
    command = "bench/suite/run.sh " + " ".join(sys.argv[1:] if argv is None else argv)
    seeds = list(range(args.first_seed, args.first_seed + args.seeds))
    # via-learning is for the tasks with via-points (push-v3)
    jobs = [(t, args.contexts, i, s, m, args.budget, args.regression)
            for t in args.tasks for i in range(args.contexts) for s in seeds for m in args.methods
            if not m.endswith("via-learning") or TASKS[t].via]
    start = time.time()
    with multiprocessing.Pool(args.jobs) as pool:
        rows = []
        for row in pool.imap_unordered(run_one, jobs):
            rows.append(row)
            if len(rows) % 100 == 0:
                print(f"{len(rows)}/{len(jobs)} runs, {time.time() - start:.0f} s", file=sys.stderr)
    rows.sort(key=lambda r: (r["task"], r["context"], r["seed"], list(METHODS).index(r["method"])))
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.out, "suite.csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, COLUMNS)
        writer.writeheader()
        writer.writerows(rows)
    plotted = plot(rows, args.budget, os.path.join(args.out, "suite.png"))
    with open(os.path.join(args.out, "suite.md"), "w") as f:
        f.write(f"`{command}` ({datetime.date.today()}, {time.time() - start:.0f} s on {args.jobs} processes): "
                f"{args.contexts} held-out contexts × {args.seeds} seeds per task, budget {args.budget} roll-outs.\n\n")
        f.write(summary(rows, args.budget, seeds))
        if plotted:
            f.write("\n![success within k roll-outs](suite.png)\n")
    if args.smoke:
        assert len(rows) == len(jobs) and all(r["rollouts"] >= 1 for r in rows), rows
        print(f"smoke: {len(rows)} runs written to {args.out}/suite.csv")


if __name__ == "__main__":
    main()
