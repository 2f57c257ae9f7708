"""Obstacle avoidance, primo against movement_primitives on the same scenes.

A minimum-jerk reach of 0.6 m along x in one second (101 samples), fitted
with 30 weights per DoF by both; a ball of radius r whose centre lies
halfway, `off` metres beside the path. primo steers round the sphere
(Park et al.'s dynamic potential on the distance to its surface, its
defaults); movement_primitives' CouplingTermObstacleAvoidance3D (Hoffmann
et al.'s steering angle, its defaults gamma=1000, beta=20/pi) takes the
centre as a point obstacle, the only kind it has. Both run at 2 ms for
3 s. Per scene: the clearance kept (the closest approach to the sphere's
surface, negative inside), the largest deviation from each library's own
unperturbed run, and the distance from the goal at the end.

Run by `bench/compare_python.sh bench/compare_coupling.py`; prints a Markdown
table.
"""

import numpy as np
from movement_primitives.dmp import DMP, CouplingTermObstacleAvoidance3D

import primo

T = np.linspace(0.0, 1.0, 101)
S = T**3 * (10 - 15 * T + 6 * T * T)
Y = np.column_stack([0.6 * S, 0.0 * S + 0.1, 0.0 * S + 0.2])
GOAL = Y[-1]
DT, HORIZON = 0.002, 3.0


def theirs(ball=None):
    dmp = DMP(n_dims=3, execution_time=1.0, dt=DT, n_weights_per_dim=30)
    dmp.imitate(T, Y)
    dmp.configure(start_y=Y[0], goal_y=GOAL)
    coupling = None if ball is None else CouplingTermObstacleAvoidance3D(ball[:3])
    _, path = dmp.open_loop(run_t=HORIZON, coupling_term=coupling)
    return path


OURS = primo.Dmp.fit(T, Y, names=["x", "y", "z"], kernels=30)


def ours(ball=None):
    if ball is None:
        _, path = OURS.run(dt=DT, tau=1.0)
    else:
        _, path = OURS.run(dt=DT, obstacles=[ball])
    return path


def deviation(path, free):
    n = min(len(path), len(free))
    far = np.linalg.norm(path[:n] - free[:n], axis=1).max()
    # A longer run (primo's goes on past τ round the obstacle) ends at rest
    # where the unperturbed one did: measure its tail against that end.
    if len(path) > n:
        far = max(far, np.linalg.norm(path[n:] - free[-1], axis=1).max())
    return far


def measure(run, free, ball):
    try:
        path = run(ball)
    except ValueError as e:
        return None, str(e)
    clearance = (np.linalg.norm(path - ball[:3], axis=1) - ball[3]).min()
    return (clearance, deviation(path, free), np.linalg.norm(path[-1] - GOAL)), None


def main():
    free = {"primo": ours(), "movement_primitives": theirs()}
    runs = {"primo": ours, "movement_primitives": theirs}
    print("| off (m) | r (m) | library | clearance (m) | deviation (m) | end from goal (m) |")
    print("|---|---|---|---|---|---|")
    for off in [0.001, 0.01, 0.03, 0.1, 0.3]:
        for r in [0.0, 0.02, 0.05]:
            ball = np.array([0.3, 0.1 + off, 0.2, r])
            for name in runs:
                got, why = measure(runs[name], free[name], ball)
                if got is None:
                    print(f"| {off} | {r} | {name} | refused: {why} | | |")
                else:
                    c, d, e = got
                    print(f"| {off} | {r} | {name} | {c:.4f} | {d:.4f} | {e:.5f} |")


main()
