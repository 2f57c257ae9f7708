"""PoWER's settings swept on the joint-space task and a Cartesian control.

Usage: python bench/power_sweep.py [--runs 20] [--budget 121] [--out FILE.md]

Needs the `primo` Python package (`pip install ./python`, the
distribution primo-robotics; ./test.sh installs it into
target/python-venv). Each run is primo's PoWER (the
core's learner through `primo.Power`) on the cell objective of `primo
rollout` (`primo.Cell`: small glass, 0.5 l bottle, 0.2 l target, 30
kernels), its exploration blocks built as `primo pour` builds them (the
query; each DoF's weights; the goals; tau), each with `s` times the
demonstrations' spread over the block. Variants: extended (s1 > 0),
ordinary (s1 = 0), error-learned (s1 = 0, the query moved by the error
with gain 1: `--method power-el`). Every update rolls out the mean once
and explores 3 times; the mean's roll-outs are the learning curve.

Reported per setting (median and a bootstrap 90 % interval over seeds; a
run that never got there counts as the budget + 1, a lower bound): the
roll-outs until the mean first reached reward 0.95 and 0.99, the runs
that did, the cumulative regret sum(1 - r), the last mean's |error| and
spill. The scale's noise seeds differ from `primo experiment power`'s,
so single runs differ from the command's; the learner and cell are the
same code.
"""

import argparse
import sys
import time

import numpy as np

import primo

THRESHOLDS = (0.95, 0.99)
QUERY_DECAY = 0.9
# The spreads of Cell.start()'s std are PoWER's at these scales.
S1_START, S2_START = 0.2, 0.05


def blocks(start, s1, s2):
    """PoWER's blocks over [q, theta] for the cell's start at scales s1, s2."""
    std = np.asarray(start["std"])
    dof, kernels = start["dof"], start["kernels"]
    theta = std[:-1] * (s2 / S2_START)
    out = [(1, float((std[-1] * s1 / S1_START) ** 2), QUERY_DECAY)]
    bounds = [d * kernels for d in range(dof + 1)] + [dof * kernels + dof, len(theta)]
    for lo, hi in zip(bounds, bounds[1:]):
        out.append((hi - lo, float(theta[lo] ** 2), 1.0))
    return out


def run(cell, start, seeds, budget, s1, s2, sampler, gain):
    """Runs the seeds in lockstep; returns per seed (mean?, reward, error, spill) rows."""
    x0 = np.asarray(start["start"])
    initial = np.concatenate([x0[-1:], x0[:-1]])
    learners = [
        primo.Power(initial, blocks(start, s1, s2), sampler=sampler, seed=s, query_gain=gain,
                    query=1)
        for s in seeds
    ]
    rows = [[] for _ in seeds]
    made = 0
    while made < budget:
        # One update of every run: the mean, then 3 explorations.
        batch = 4 if made + 4 <= budget else budget - made
        for _ in range(batch):
            asked = [learner.ask() for learner in learners]
            means = [learner.next_is_mean for learner in learners]
            xs = np.array([np.concatenate([a[1:], a[:1]]) for a in asked])
            got = cell.rollout_many(xs, seeds=[s * 100_000 + made for s in seeds])
            for i, (learner, r) in enumerate(zip(learners, got)):
                rows[i].append((means[i], r["reward"], r["error"], r["spilled"]))
                if gain:
                    learner.tell(r["reward"], [r["error"]])
                else:
                    learner.tell(r["reward"])
            made += 1
    return rows


def figures(rows, budget):
    """Per run: roll-outs to each threshold, regret, last mean's |error|, spill (ml)."""
    out = []
    for r in rows:
        to = []
        for level in THRESHOLDS:
            n = next((i + 1 for i, (m, rew, _, _) in enumerate(r) if m and rew >= level), None)
            to.append(n)
        last = [x for x in r if x[0]][-1]
        out.append((to, sum(1 - x[1] for x in r), abs(last[2]) * 1e3, last[3] * 1e3))
    return out


def estimate(values, stat=np.median, seed=0, draws=2000):
    """The statistic and a bootstrap 90 % interval."""
    values = np.asarray(values, dtype=float)
    rng = np.random.default_rng(seed)
    boots = [stat(values[rng.integers(0, len(values), len(values))]) for _ in range(draws)]
    return stat(values), np.quantile(boots, 0.05), np.quantile(boots, 0.95)


def row(label, figs, budget):
    cells = [label]
    for k in range(len(THRESHOLDS)):
        to = [f[0][k] if f[0][k] is not None else budget + 1 for f in figs]
        v, lo, hi = estimate(to)
        reached = sum(f[0][k] is not None for f in figs)
        cells.append(f"{v:.0f} [{lo:.0f}, {hi:.0f}] ({reached}/{len(figs)})")
    v, lo, hi = estimate([f[1] for f in figs], np.mean)
    cells.append(f"{v:.1f} [{lo:.1f}, {hi:.1f}]")
    cells.append(f"{np.mean([f[2] for f in figs]):.2f}")
    cells.append(f"{np.mean([f[3] for f in figs]):.2f}")
    return "| " + " | ".join(cells) + " |"


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--runs", type=int, default=20)
    p.add_argument("--budget", type=int, default=121)
    p.add_argument("--out", default=None)
    a = p.parse_args()
    if a.runs < 1 or a.budget < 1:
        p.error("--runs and --budget must be at least 1")
    seeds = list(range(1, a.runs + 1))
    header = (
        "| setting | to 0.95 | to 0.99 | regret | final error ml | final spill ml |\n"
        "|---|---|---|---|---|---|"
    )
    variants = {"extended": (0.2, 0.0), "ordinary": (0.0, 0.0), "error-learned": (0.0, 1.0)}
    lines = [
        f"# PoWER settings swept ({a.runs} seeds, {a.budget} roll-outs each)",
        "",
        "`python bench/power_sweep.py --runs %d --budget %d` (median [bootstrap 90 %%] "
        "roll-outs until the mean policy first reached the reward; runs that did; mean "
        "regret; mean final |error| and spill)." % (a.runs, a.budget),
    ]
    started = time.time()
    for space in ("joint", "cartesian"):
        cell = primo.Cell(space=space, glass="small")
        start = cell.start()
        sweeps = [("variants (s2 = 0.05, sampler 3)", [
            (name, s1, 0.05, 3, gain) for name, (s1, gain) in variants.items()
        ])]
        sweeps.append(("s1 of extended PoWER (s2 = 0.05, sampler 3)", [
            (f"s1 = {s1}", s1, 0.05, 3, 0.0) for s1 in (0.1, 0.2, 0.4)
        ]))
        # Ordinary is extended at s1 = 0: its sweeps would repeat these.
        for name in ("extended", "error-learned"):
            s1, gain = variants[name]
            sweeps.append((f"s2 of {name} (sampler 3)", [
                (f"s2 = {s2}", s1, s2, 3, gain) for s2 in (0.025, 0.05, 0.1)
            ]))
            sweeps.append((f"sampler of {name} (s2 = 0.05)", [
                (f"sampler {n}", s1, 0.05, n, gain) for n in (1, 3, 10)
            ]))
        lines += ["", f"## {space} space ({len(start['start'])} values)"]
        for title, settings in sweeps:
            lines += ["", f"### {title}", "", header]
            for label, s1, s2, sampler, gain in settings:
                figs = figures(run(cell, start, seeds, a.budget, s1, s2, sampler, gain), a.budget)
                lines.append(row(label, figs, a.budget))
                print(f"{space} {title}: {lines[-1]}  ({time.time() - started:.0f} s)",
                      file=sys.stderr, flush=True)
    text = "\n".join(lines) + "\n"
    if a.out:
        with open(a.out, "w") as f:
            f.write(text)
    print(text)


if __name__ == "__main__":
    main()
