"""Times primo.Robot against Pinocchio (`pip install pin example-robot-data`)
on the Franka Panda of example-robot-data (7 joints, panda_link0 to
panda_hand; Pinocchio's model reduced to those 7 joints, the fingers
locked), from Python, one call at a time as a Python caller makes them:

- forward kinematics and the geometric Jacobian of the hand, per call
  (the median of many calls, per repeat);
- inverse kinematics along a path: a random smooth joint path of 1000
  samples within the limits, its FK as the targets, each sample solved
  from the previous sample's solution (the first from the path's start);
  the success rate to 1e-6 m and 1e-6 rad (checked by Pinocchio's FK for
  both) and the median time per solve.

Pinocchio's IK is the CLIK loop of its documentation (examples/inverse-
kinematics.py: `log6` of the error, damped pseudo-inverse through
`Jlog6`, `integrate`), run twice: with the docs' settings (step 0.1,
damping 1e-12, 1000 iterations) and with a full Gauss-Newton step (1.0),
both stopping at |log6| < 1e-7. It does not know the joint limits (the
docs' loop has none); solutions outside them are counted separately.
primo's is `Robot.inverse` (its defaults: 1e-9, 200 iterations, within
the limits, pulled toward mid-range) and `inverse_path` (the same loop in
Rust, the GIL released).

    python python/bench/robot_models.py [--repeats 3]
"""

import argparse
import importlib.metadata
import os
import pathlib
import platform
import statistics
import time

import numpy as np
import pinocchio as pin

import primo

TOL = 1e-6


def panda_urdf() -> pathlib.Path:
    dist = importlib.metadata.distribution("example-robot-data")
    for f in dist.files or []:
        if str(f).endswith("robots/panda_description/urdf/panda.urdf"):
            return pathlib.Path(dist.locate_file(f))
    raise SystemExit("example-robot-data ships no panda.urdf")


def per_call(f, args, repeats):
    """Per repeat, the median time of one call over `args`, seconds."""
    medians = []
    for _ in range(repeats):
        times = []
        for a in args:
            t0 = time.perf_counter()
            f(a)
            times.append(time.perf_counter() - t0)
        medians.append(statistics.median(times))
    return medians


def show(what, medians, unit=1e6, suffix="µs"):
    lo, mid, hi = min(medians) * unit, statistics.median(medians) * unit, max(medians) * unit
    print(f"  {what}: {mid:.2f} {suffix} (repeats {lo:.2f}–{hi:.2f})")
    return mid


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--calls", type=int, default=10000)
    parser.add_argument("--samples", type=int, default=1000)
    args = parser.parse_args()

    path = panda_urdf()
    robot = primo.Robot.from_urdf(path, tip="panda_hand")
    full = pin.buildModelFromUrdf(str(path))
    fingers = [full.getJointId(n) for n in ("panda_finger_joint1", "panda_finger_joint2")]
    model = pin.buildReducedModel(full, fingers, pin.neutral(full))
    data = model.createData()
    frame = model.getFrameId("panda_hand")
    assert [model.names[i] for i in range(1, model.njoints)] == robot.joint_names

    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
          f"load {os.getloadavg()[0]:.1f}; Python {platform.python_version()}, "
          f"pinocchio {pin.__version__}, numpy {np.__version__}")

    rng = np.random.default_rng(1)
    qs = rng.uniform(robot.lower, robot.upper, size=(args.calls, robot.dof))

    def pin_forward(q):
        pin.framesForwardKinematics(model, data, q)
        return data.oMf[frame].homogeneous

    def pin_jacobian(q):
        return pin.computeFrameJacobian(model, data, q, frame, pin.LOCAL_WORLD_ALIGNED)

    for q in qs[:100]:  # the same numbers, before timing them
        assert np.abs(robot.forward(q) - pin_forward(q)).max() < 1e-9
        assert np.abs(robot.jacobian(q) - pin_jacobian(q)).max() < 1e-9

    print(f"FK and Jacobian, one call ({args.calls} calls per repeat, median):")
    show("primo forward", per_call(robot.forward, qs, args.repeats))
    show("pinocchio framesForwardKinematics + oMf[hand].homogeneous",
         per_call(pin_forward, qs, args.repeats))
    show("primo jacobian", per_call(robot.jacobian, qs, args.repeats))
    show("pinocchio computeFrameJacobian (LOCAL_WORLD_ALIGNED)",
         per_call(pin_jacobian, qs, args.repeats))
    batch = []
    for _ in range(args.repeats):
        t0 = time.perf_counter()
        robot.forward_many(qs)
        batch.append((time.perf_counter() - t0) / len(qs))
    show("primo forward_many, per row", batch)

    # A smooth random path within the limits.
    n = args.samples
    t = np.linspace(0.0, 1.0, n)[:, None]
    mid, half = 0.5 * (robot.lower + robot.upper), 0.5 * (robot.upper - robot.lower)
    phase = rng.uniform(0, 2 * np.pi, (3, robot.dof))
    wave = sum(np.sin(2 * np.pi * (k + 1) * t + phase[k]) / (k + 1) for k in range(3)) / 1.84
    path_q = mid + 0.6 * half * wave
    targets = robot.forward_many(path_q)
    placements = [pin.SE3(m[:3, :3].copy(), m[:3, 3].copy()) for m in targets]
    step = np.linalg.norm(np.diff(path_q, axis=0), axis=1)
    print(f"IK along a path: {n} samples, joint steps {step.mean():.3f} rad on average "
          f"(largest {step.max():.3f})")

    def reached(q, i):
        pose = pin_forward(q)
        position = np.linalg.norm(pose[:3, 3] - targets[i][:3, 3])
        rotation = np.linalg.norm(pin.log3(pose[:3, :3].T @ targets[i][:3, :3]))
        return position <= TOL and rotation <= TOL

    def run_primo():
        q, solved, within, times = path_q[0], 0, 0, []
        for i, target in enumerate(targets):
            t0 = time.perf_counter()
            try:
                answer = robot.inverse(target, q)
            except RuntimeError:
                times.append(time.perf_counter() - t0)
                continue
            times.append(time.perf_counter() - t0)
            q = answer
            if reached(q, i):
                solved += 1
                within += bool(np.all(q >= robot.lower) and np.all(q <= robot.upper))
        return solved, within, statistics.median(times)

    def clik(dt, damp, iterations):
        def solve(q, target):
            for _ in range(iterations):
                pin.framesForwardKinematics(model, data, q)
                d = data.oMf[frame].actInv(target)
                err = pin.log(d).vector
                if np.linalg.norm(err) < 1e-7:
                    return q, True
                jac = pin.computeFrameJacobian(model, data, q, frame, pin.LOCAL)
                jac = -pin.Jlog6(d.inverse()) @ jac
                v = -jac.T @ np.linalg.solve(jac @ jac.T + damp * np.eye(6), err)
                q = pin.integrate(model, q, v * dt)
            return q, False

        def run():
            q, solved, within, times = path_q[0].copy(), 0, 0, []
            for i, target in enumerate(placements):
                t0 = time.perf_counter()
                answer, ok = solve(q, target)
                times.append(time.perf_counter() - t0)
                if ok:
                    q = answer
                    if reached(q, i):
                        solved += 1
                        within += bool(np.all(q >= robot.lower) and np.all(q <= robot.upper))
            return solved, within, statistics.median(times)

        return run

    def run_path():
        t0 = time.perf_counter()
        solved = robot.inverse_path(targets, path_q[0], on_failure="nan")
        seconds = time.perf_counter() - t0
        ok = sum(1 for i, q in enumerate(solved) if not np.isnan(q).any() and reached(q, i))
        return ok, ok, seconds / n  # the mean: one call for the whole path

    for name, run in [
        ("primo inverse, one call per sample", run_primo),
        ("primo inverse_path (one call for the path), per sample", run_path),
        ("pinocchio CLIK, the docs' settings (step 0.1, damping 1e-12)", clik(0.1, 1e-12, 1000)),
        ("pinocchio CLIK, full step (1.0, damping 1e-12)", clik(1.0, 1e-12, 200)),
    ]:
        results = [run() for _ in range(args.repeats)]
        solved, within, _ = results[0]
        print(f"  {name}: {solved}/{n} reached to 1e-6 m and rad ({within} within the limits)")
        per = "mean per sample (the path's time / samples)" if run is run_path else "median per solve"
        show(f"    {per}", [r[2] for r in results])


if __name__ == "__main__":
    main()
