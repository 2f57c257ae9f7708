"""Times primo's DMP fit and run from Python, and movement_primitives'
if it is installed (a throw-away venv: `pip install movement_primitives
pytransform3d scipy`), on the same 7-DoF, 30-kernel movement; and the
cell's roll-outs one by one against `rollout_many`. Prints one line each.
"""

import os
import time

import numpy as np

import primo


def best(f, n=5):
    times = []
    for _ in range(n):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return min(times)


t = np.linspace(0.0, 1.0, 1001)
Y = np.column_stack([np.sin((j + 1) * t) + t * t for j in range(7)])

fit = best(lambda: primo.Dmp.fit(t, Y, kernels=30))
dmp = primo.Dmp.fit(t, Y, kernels=30)
theta = dmp.params
theta[-1] = 60.0  # τ: 60 s
dmp.params = theta
run = best(lambda: dmp.run(dt=0.001))
print(f"primo: fit 7x30, 1001 samples {fit * 1e3:.2f} ms; run 60 s at 1 ms {run * 1e3:.0f} ms")

try:
    from movement_primitives.dmp import DMP
except ImportError:
    print("movement_primitives: not installed")
else:
    mp = DMP(n_dims=7, execution_time=1.0, dt=0.001, n_weights_per_dim=30)
    fit = best(lambda: mp.imitate(t, Y))
    long = DMP(n_dims=7, execution_time=60.0, dt=0.001, n_weights_per_dim=30)
    long.set_weights(mp.get_weights())
    long.configure(start_y=Y[0], goal_y=Y[-1])
    run = best(lambda: long.open_loop(run_t=60.0), 3)
    print(f"movement_primitives: fit {fit * 1e3:.2f} ms; open_loop 60 s at 1 ms {run * 1e3:.0f} ms")

cell = primo.Cell(glass="small", kernels=30)
start = cell.start()
rng = np.random.default_rng(1)
thetas = start["start"] + 0.1 * start["std"] * rng.standard_normal((16, len(cell)))
loop = best(lambda: [cell.rollout(x, seed=1 + i) for i, x in enumerate(thetas)], 3)
many = best(lambda: cell.rollout_many(thetas), 3)
print(f"cell: 16 roll-outs, a loop {loop * 1e3:.0f} ms, rollout_many {many * 1e3:.0f} ms "
      f"({os.cpu_count()} cores, load {os.getloadavg()[0]:.1f})")
