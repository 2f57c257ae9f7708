"""Times primo's DMP fit, run and argument conversion from Python against
movement_primitives and pydmps, in one process on the same data: a
7-DoF movement of 1,001 and 10,001 samples, 30 kernels per DoF, run for
60 s at 1 ms; and the cell's roll-outs one by one against
`rollout_many`. Prints a Markdown table; a peer that is not installed is
said so. `bench/compare_python.sh` runs it in a throw-away virtual
environment with both peers.

The conversion is what `Dmp.fit` spends turning the arrays into the
library's: timed as a call that converts both arrays and is then refused
(one column name short), so no fit runs.
"""

import os
import time

import numpy as np

import primo

KERNELS = 30
RUN_SECONDS = 60.0
DT = 0.001


def best(f, n):
    """The shortest of `n` timings of `f()`, s."""
    times = []
    for _ in range(n):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return min(times)


def recording(n):
    t = np.linspace(0.0, 1.0, n)
    return t, np.column_stack([np.sin((j + 1) * t) + t * t for j in range(7)])


def refused(t, y):
    try:
        primo.Dmp.fit(t, y, names=[f"y{j}" for j in range(y.shape[1] - 1)], kernels=KERNELS)
    except ValueError:
        return
    raise AssertionError("the conversion probe was not refused")


def primo_times(t, y, repeat):
    dmp = primo.Dmp.fit(t, y, kernels=KERNELS)
    theta = dmp.params
    theta[-1] = RUN_SECONDS  # τ
    dmp.params = theta
    return {
        "convert": best(lambda: refused(t, y), repeat),
        "copy": best(lambda: np.array(y, dtype=np.float32), repeat),
        "fit": best(lambda: primo.Dmp.fit(t, y, kernels=KERNELS), repeat),
        "run": best(lambda: dmp.run(dt=DT), 3),
    }


def movement_primitives_times(t, y, repeat):
    from movement_primitives.dmp import DMP

    dmp = DMP(n_dims=y.shape[1], execution_time=1.0, dt=t[1] - t[0], n_weights_per_dim=KERNELS)
    fit = best(lambda: dmp.imitate(t, y), repeat)
    long = DMP(n_dims=y.shape[1], execution_time=RUN_SECONDS, dt=DT, n_weights_per_dim=KERNELS)
    long.set_weights(dmp.get_weights())
    long.configure(start_y=y[0], goal_y=y[-1])
    return {"fit": fit, "run": best(lambda: long.open_loop(run_t=RUN_SECONDS), 1)}


def pydmps_times(t, y, repeat):
    from pydmps.dmp_discrete import DMPs_discrete

    # pydmps resamples the path to its own steps of dt over 1 s: the samples' spacing.
    dmp = DMPs_discrete(n_dmps=y.shape[1], n_bfs=KERNELS, dt=t[1] - t[0])
    fit = best(lambda: dmp.imitate_path(y_des=y.T), repeat)
    long = DMPs_discrete(n_dmps=y.shape[1], n_bfs=KERNELS, dt=DT, w=dmp.w, y0=dmp.y0, goal=dmp.goal)
    steps = int(RUN_SECONDS / DT)
    return {"fit": fit, "run": best(lambda: long.rollout(timesteps=steps, tau=1.0 / RUN_SECONDS), 1)}


def ms(seconds):
    return f"{seconds * 1e3:.2f} ms" if seconds < 0.1 else f"{seconds:.2f} s"


def main():
    rows = []
    for n, repeat in ((1001, 20), (10001, 5)):
        t, y = recording(n)
        p = primo_times(t, y, repeat)
        rows.append((f"primo {primo.__version__}", n, p))
        for name, times in (("movement_primitives", movement_primitives_times),
                            ("pydmps", pydmps_times)):
            try:
                peer = times(t, y, repeat)
            except ImportError:
                print(f"{name}: not installed")
                continue
            rows.append((name, n, peer))
    print(f"7 DoF × {KERNELS} kernels; run: {RUN_SECONDS:.0f} s at {DT * 1e3:.0f} ms; "
          f"{os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}\n")
    print("| library | samples | fit | of it, conversion | run | fit + run | vs primo |")
    print("|---|---|---|---|---|---|---|")
    ours = {}
    for name, n, r in rows:
        total = r["fit"] + r["run"]
        if name.startswith("primo"):
            ours[n] = total
        convert = f"{ms(r['convert'])} (a float32 copy: {ms(r['copy'])})" if "convert" in r else ""
        ratio = f"{total / ours[n]:.0f}×" if not name.startswith("primo") else ""
        print(f"| {name} | {n} | {ms(r['fit'])} | {convert} | {ms(r['run'])} | {ms(total)} | {ratio} |")

    cell = primo.Cell(glass="small", kernels=30)
    start = cell.start()
    rng = np.random.default_rng(1)
    thetas = start["start"] + 0.1 * start["std"] * rng.standard_normal((16, len(cell)))
    loop = best(lambda: [cell.rollout(x, seed=1 + i) for i, x in enumerate(thetas)], 3)
    many = best(lambda: cell.rollout_many(thetas), 3)
    print(f"\ncell: 16 roll-outs, a loop {loop * 1e3:.0f} ms, rollout_many {many * 1e3:.0f} ms")


if __name__ == "__main__":
    main()
