#!/usr/bin/env python3
"""Compare primo's DMP with movement_primitives' DMP: reproduction accuracy
and replay time. Run through bench/compare_dmp.sh, which makes the venv.

Usage: compare_dmp.py PRIMO_BINARY [--quick] [--timing [--runs N]]
(--timing: only the replay time, printed, no file; N rounds, default 5)

Every demonstration is a closed-form movement, so each replay is compared
with the exact movement at the replay's own times, not with the samples.

movement_primitives settings (read from its source, 0.9.x), chosen to give
it its best accuracy:
- `DMP(n_dims, execution_time=T, dt=0.001, n_weights_per_dim=K)`, then
  `imitate(T, Y)` with the default regularization 0 (the samples are exact,
  nothing to regularize; it solves with a pseudo-inverse).
- Replay with `open_loop` two ways:
  * 'euler-cython' with int_dt = 1e-6 (the compared number): 1000
    semi-implicit Euler sub-steps per 1 ms output step. Measured from a
    1 kHz demo, RMSE by int_dt 1e-3 / 1e-4 / 1e-5 / 1e-6: bump 9.0e-4 /
    8.2e-5 / 1.9e-5 / 2.1e-5, helix 4.1e-4 / 4.1e-5 / 4.5e-6 / 2.4e-6: what
    remains at 1e-6 is its fit, not its integrator.
  * 'rk4-cython', its default (also reported): one RK4 step per dt, int_dt
    ignored; it evaluates the forcing term at t, t+dt/2, t+dt with t already
    the end of the step, i.e. one dt late: 3e-4 to 8e-4 RMSE at dt = 1 ms.
"""
import json
import os
import re
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from datetime import date

import numpy as np
import movement_primitives
from movement_primitives.dmp import DMP, CartesianDMP

HERE = os.path.dirname(os.path.abspath(__file__))
DT = 0.001  # replay step of both libraries (1 kHz control)
MP_INT_DT = 1e-6
RATES = [100, 1000, 10000]


# --- the movements: exact, continuous, evaluable at any t ---------------------

def mj(s):
    """Minimum-jerk 0 -> 1 over s in [0, 1], held outside."""
    s = np.clip(s, 0.0, 1.0)
    return s**3 * (10 - 15 * s + 6 * s**2)


def pour(t):
    """7 joints, 6 s: reach, hold, tilt to pour, hold while pouring, tilt back,
    hold, settle. Each move is minimum jerk, so the arm stands still between."""
    home = np.array([0.0, 0.5, 0.0, -1.2, 0.0, 0.8, 0.0])
    pre = np.array([0.4, 0.7, 0.1, -1.0, 0.2, 0.9, 0.3])
    tilt = pre + np.array([0, 0.05, 0, 0.1, 0, 0.3, 1.8])
    end = np.array([0.3, 0.6, 0.1, -1.1, 0.1, 0.85, 0.3])
    moves = [(0.4, 1.9, home, pre), (2.4, 3.4, pre, tilt),
             (4.2, 5.0, tilt, pre), (5.2, 5.9, pre, end)]
    y = np.tile(home, (len(t), 1))
    for t0, t1, a, b in moves:
        y += np.outer(mj((t - t0) / (t1 - t0)), b - a)
    return y


def helix(t):
    """1.25 turns of a helix in 2 s, slow-fast-slow and faster at the end."""
    u = mj(t / 2.0)
    w = u * (0.6 + 0.4 * u)
    a = 2 * np.pi * 1.25 * w
    return np.column_stack([0.4 + 0.1 * np.cos(a), 0.1 * np.sin(a), 0.2 + 0.25 * w])


def loop(t):
    """1.5 s: x goes out and back, z waves and returns (start == goal on
    both), y moves 0.1 with a wiggle."""
    u = mj(t / 1.5)
    return np.column_stack([0.5 + 0.25 * np.sin(np.pi * u) ** 2,
                            0.1 * u + 0.05 * np.sin(2 * np.pi * u),
                            0.3 + 0.08 * np.sin(2 * np.pi * u)])


def bump(t):
    """examples/reach.csv's kind of movement: minimum jerk 0 -> 0.6 plus 0.15 sin^2(pi t), 1 s."""
    return (0.6 * mj(t) + 0.15 * np.sin(np.pi * t) ** 2)[:, None]


CASES = [  # name, function, duration (s), DoF names
    ("pour 7-DoF", pour, 6.0, [f"j{i}" for i in range(1, 8)]),
    ("helix 3-D", helix, 2.0, ["x", "y", "z"]),
    ("loop 3-D", loop, 1.5, ["x", "y", "z"]),
    ("min-jerk+bump", bump, 1.0, ["x"]),
]


# --- Cartesian movements: position + unit quaternion (w, x, y, z) -------------

def quat_zyx(yaw, pitch, roll):
    """Unit quaternions (w, x, y, z) of Z-Y-X Euler angles, one per row,
    signs made continuous along the rows."""
    cy, sy = np.cos(yaw / 2), np.sin(yaw / 2)
    cp, sp = np.cos(pitch / 2), np.sin(pitch / 2)
    cr, sr = np.cos(roll / 2), np.sin(roll / 2)
    q = np.column_stack([cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
                         cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy])
    for i in range(1, len(q)):
        if q[i] @ q[i - 1] < 0:
            q[i] = -q[i]
    return q


def sweep(t):
    """2 s: yaw 120° -> 240° (through 180°, where rotation vectors and
    Euler angles jump), pitch up 25° and back, a 10° roll wobble; the
    position moves 0.2 m along a curve."""
    u = mj(t / 2.0)
    q = quat_zyx(np.radians(120 + 120 * u), np.radians(25) * np.sin(np.pi * u),
                 np.radians(10) * np.sin(2 * np.pi * u))
    return np.column_stack([0.5 + 0.2 * u, 0.1 * np.sin(np.pi * u), 0.3 + 0.1 * u, q])


def tilt(t):
    """3 s, a pour's wrist: tilt 0 -> 110° about an axis 20° off x while
    the hand moves in, hold, tilt back to 30°."""
    a = np.radians(110) * mj(t / 1.2) - np.radians(80) * mj((t - 2.0) / 1.0)
    axis = np.array([np.cos(np.radians(20)), np.sin(np.radians(20)), 0.0])
    q = np.column_stack([np.cos(a / 2), np.outer(np.sin(a / 2), axis)])
    u = mj(t / 3.0)
    return np.column_stack([0.4 + 0.15 * u, -0.1 + 0.2 * mj(t / 1.2), 0.35 - 0.05 * u, q])


CARTESIAN = [  # name, function, duration (s)
    ("yaw sweep through 180°", sweep, 2.0),
    ("pour tilt 110°", tilt, 3.0),
]
POSE = ["x", "y", "z", "qw", "qx", "qy", "qz"]


def pose_errors(t, y, truth, tau):
    """(position RMSE, max) in m and (angle RMSE, max) in rad."""
    keep = t <= tau + 1e-9
    exact = truth(np.minimum(t[keep], tau))
    dp = np.linalg.norm(y[keep, :3] - exact[:, :3], axis=1)
    q = y[keep, 3:] / np.linalg.norm(y[keep, 3:], axis=1, keepdims=True)
    dot = np.abs(np.sum(q * exact[:, 3:], axis=1))
    angle = 2 * np.arccos(np.minimum(dot, 1.0))
    rms = lambda e: float(np.sqrt(np.mean(e**2)))
    return (rms(dp), float(dp.max())), (rms(angle), float(angle.max()))


def cartesian_accuracy(primo, quick):
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        cases = [(name, fn, tau, POSE) for name, fn, tau in CARTESIAN]
        for name, fn, tau, rate, t, demo in recorded(cases, quick, tmp):
            for k in (30, 10):
                pr = pose_errors(*primo_replay(primo, demo, k, tmp), fn, tau)
                dmp = CartesianDMP(execution_time=tau, dt=DT, n_weights_per_dim=k,
                                   int_dt=MP_INT_DT)
                dmp.imitate(t, fn(t))
                mp = pose_errors(*dmp.open_loop(step_function="euler-cython",
                                                quaternion_step_function="cython"),
                                 fn, tau)
                rows.append(dict(case=name, rate=rate, k=k, primo=pr, mp=mp))
                print(f"{name:24} {rate:>6} Hz K={k:<3} primo {pr[0][0]:.2e} m "
                      f"{pr[1][0]:.2e} rad | mp {mp[0][0]:.2e} m {mp[1][0]:.2e} rad",
                      flush=True)
    return rows


def write_csv(path, t, y, names):
    # 17 significant digits: the file loses nothing, so neither library is
    # judged on the CSV's rounding (primo reads f32 anyway).
    np.savetxt(path, np.column_stack([t, y]), delimiter=",", fmt="%.17g",
               header="t," + ",".join(names), comments="")


def errors(t, y, truth, tau):
    keep = t <= tau + 1e-9  # movement_primitives' arange may run one step past tau
    e = y[keep] - truth(np.minimum(t[keep], tau))
    return float(np.sqrt(np.mean(e**2))), float(np.max(np.abs(e)))


def primo_fit(primo, demo, k, tmp):
    """`primo dmp fit` with K kernels (its other settings default): the DMP's path."""
    dmp = os.path.join(tmp, "dmp.json")
    subprocess.run([primo, "dmp", "fit", "--demo", demo, "--kernels", str(k),
                    "--out", dmp], check=True)
    return dmp


def primo_run(primo, dmp, tmp, *args):
    """`primo dmp run` at DT with extra arguments (`--goal`, `--via` …): (t, y)."""
    run = os.path.join(tmp, "run.csv")
    subprocess.run([primo, "dmp", "run", dmp, "--dt", str(DT), "--out", run, *args],
                   check=True)
    data = np.loadtxt(run, delimiter=",", skiprows=1, ndmin=2)
    return data[:, 0], data[:, 1:]


def primo_replay(primo, demo, k, tmp):
    return primo_run(primo, primo_fit(primo, demo, k, tmp), tmp)


def mp_fit(demo, k, tau):
    data = np.loadtxt(demo, delimiter=",", skiprows=1, ndmin=2)
    dmp = DMP(n_dims=data.shape[1] - 1, execution_time=tau, dt=DT,
              n_weights_per_dim=k, int_dt=MP_INT_DT)
    dmp.imitate(data[:, 0], data[:, 1:])
    return dmp


def recorded(cases, quick, tmp):
    """Each case `(name, fn, tau, columns)` sampled at each rate into
    tmp/demo.csv: yields (name, fn, tau, rate, times, path)."""
    demo = os.path.join(tmp, "demo.csv")
    for name, fn, tau, columns in cases:
        for rate in RATES[:2] if quick else RATES:
            t = np.arange(round(tau * rate) + 1) / rate
            write_csv(demo, t, fn(t), columns)
            yield name, fn, tau, rate, t, demo


def accuracy(primo, quick):
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, fn, tau, rate, t, demo in recorded(CASES, quick, tmp):
            for k in (30, 10):
                pr = errors(*primo_replay(primo, demo, k, tmp), fn, tau)
                dmp = mp_fit(demo, k, tau)
                mp = errors(*dmp.open_loop(step_function="euler-cython"), fn, tau)
                rk4 = errors(*dmp.open_loop(step_function="rk4-cython"), fn, tau)
                rows.append(dict(case=name, rate=rate, k=k, primo=pr, mp=mp, rk4=rk4))
                print(f"{name:14} {rate:>6} Hz K={k:<3} primo RMSE {pr[0]:.2e} "
                      f"max {pr[1]:.2e} | mp RMSE {mp[0]:.2e} max {mp[1]:.2e} "
                      f"| mp rk4 RMSE {rk4[0]:.2e}", flush=True)
    return rows


# --- timing: 60 s, 7 DoF, 30 kernels, replayed at 1 ms to a CSV file ----------

MP_RUN = """
import sys, numpy as np
from movement_primitives.dmp import DMP
z = np.load(sys.argv[1])
dmp = DMP(n_dims=7, execution_time=60.0, dt=0.001, n_weights_per_dim=30,
          int_dt=0.001)
dmp.forcing_term.weights_[:] = z["w"]
dmp.configure(start_y=z["start"], goal_y=z["goal"])
T, Y = dmp.open_loop(step_function=sys.argv[2])
np.savetxt(sys.argv[3], np.column_stack([T, Y]), delimiter=",", fmt="%.9g",
           header="t,j1,j2,j3,j4,j5,j6,j7", comments="")
"""


def walls(cmd, n=5, cpu=None):
    """Whole-process wall times of n runs, s; each run's CPU time (user +
    sys, s) appended to `cpu` when given."""
    times = []
    for _ in range(n):
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        times.append(time.perf_counter() - t0)
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        if cpu is not None:
            cpu.append(r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime)
    return times


def median_wall(cmd, n=5):
    return statistics.median(walls(cmd, n))


def timing(primo, quick, runs=5):
    n = 1 if quick else runs
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        # The pour played 10 times in a row, at 100 Hz: 60 s, 7 DoF.
        t = np.arange(6001) / 100
        demo, dmp_json = os.path.join(tmp, "demo60.csv"), os.path.join(tmp, "dmp60.json")
        write_csv(demo, t, pour(t % 6.0), [f"j{i}" for i in range(1, 8)])
        subprocess.run([primo, "dmp", "fit", "--demo", demo, "--kernels", "30",
                        "--out", dmp_json], check=True)
        fitted = mp_fit(demo, 30, 60.0)
        npz, script = os.path.join(tmp, "mp60.npz"), os.path.join(tmp, "mp_run.py")
        np.savez(npz, w=fitted.forcing_term.weights_, start=fitted.start_y, goal=fitted.goal_y)
        with open(script, "w") as f:
            f.write(MP_RUN)
        csv = os.path.join(tmp, "run60.csv")
        # In turn, primo then each of movement_primitives' steps, n rounds:
        # a change of the machine's load hits both alike.
        cmds = {"primo": [primo, "dmp", "run", dmp_json, "--dt", "0.001", "--out", csv]}
        for step in ("euler-cython", "rk4-cython"):
            cmds["mp " + step] = [sys.executable, script, npz, step, csv]
        for name in cmds:
            out[name + " runs"], out[name + " cpu"] = [], []
        for _ in range(n):
            for name, cmd in cmds.items():
                out[name + " runs"] += walls(cmd, 1, out[name + " cpu"])
                out[name.split()[0] + "_rows"] = sum(1 for _ in open(csv)) - 1
        for name in cmds:
            out[name] = statistics.median(out[name + " runs"])
        out["primo_devnull"] = median_wall(
            [primo, "dmp", "run", dmp_json, "--dt", "0.001", "--out", "/dev/null"], n)
        out["primo_startup"] = median_wall([primo, "--version"], n)
        out["python_import"] = median_wall(
            [sys.executable, "-c", "import movement_primitives.dmp"], n)
        # In-process parts of the fastest movement_primitives run.
        dmp = DMP(n_dims=7, execution_time=60.0, dt=DT, n_weights_per_dim=30, int_dt=DT)
        dmp.forcing_term.weights_[:] = fitted.forcing_term.weights_
        dmp.configure(start_y=fitted.start_y, goal_y=fitted.goal_y)
        t0 = time.perf_counter()
        T, Y = dmp.open_loop(step_function="euler-cython")
        t1 = time.perf_counter()
        np.savetxt(csv, np.column_stack([T, Y]), delimiter=",", fmt="%.9g")
        t2 = time.perf_counter()
        out["mp_loop"], out["mp_savetxt"] = t1 - t0, t2 - t1
        out["profile"] = profile([primo, "dmp", "run", dmp_json, "--dt", "0.001",
                                  "--out", "/dev/null"], tmp)
    return out


def profile(cmd, tmp):
    """Where primo's `dmp run` spends its time: perf's flat profile, its
    symbols sorted into number formatting (CSV writing) and DMP stepping."""
    if shutil.which("perf") is None:
        return None
    data = os.path.join(tmp, "perf.data")
    subprocess.run(["perf", "record", "-q", "-F", "20000", "-o", data] + cmd,
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    text = subprocess.run(["perf", "report", "-i", data, "--no-children", "--stdio",
                           "--sort", "symbol"], capture_output=True, text=True).stdout
    share = {"formatting": 0.0, "DMP": 0.0, "other": 0.0}
    top = []
    for line in text.splitlines():
        m = re.match(r"\s*([\d.]+)%\s+\[.\]\s+(.*?)\s+-\s+-\s*$", line)
        if not m:
            continue
        pct, sym = float(m[1]), m[2]
        if any(k in sym for k in ("fmt", "flt2dec", "csv::", "write_str", "memmove",
                                  "digits_to_dec")):
            share["formatting"] += pct
        elif any(k in sym for k in ("primo_core", "libm::")):
            share["DMP"] += pct
        else:
            share["other"] += pct
        if len(top) < 8:
            top.append(f"{pct:5.1f}%  {sym}")
    return {"share": share, "top": top}


# --- report -------------------------------------------------------------------

def report(rows, cartesian, tm, primo):
    version = subprocess.run([primo, "--version"], capture_output=True, text=True).stdout.strip()
    lines = [
        "# primo vs movement_primitives: DMP reproduction accuracy and replay time",
        "",
        f"Generated by `bench/compare_dmp.sh` on {date.today()}; machine: 2 cores "
        f"(shared; load average {os.getloadavg()[0]:.1f} when the report was written). {version}, movement_primitives "
        f"{movement_primitives.__version__}, numpy {np.__version__}, Python "
        f"{sys.version.split()[0]}.",
        "",
        "## Accuracy",
        "",
        "Each demonstration is a closed-form movement sampled at the given rate "
        "(CSV, 17 digits). Both libraries fit it with K kernels per DoF and "
        f"replay it at dt = {DT} s; errors are against the exact movement at the "
        "replay's times (in the movement's units: rad or m). "
        "movement_primitives: `imitate` (regularization 0), then `open_loop` with "
        f"'euler-cython' and int_dt = {MP_INT_DT} s (integration converged, so "
        "this is its fit's accuracy); ratio = its RMSE / primo's (> 1: primo "
        "is more accurate). Last column: its default 'rk4-cython' at the same "
        "dt, which evaluates the forcing term one step late. Whether primo's "
        "kernel width limits it where movement_primitives is more accurate: "
        "`bench/compare_dmp.sh --kernel-width`.",
        "",
        "| case | rate | K | primo RMSE | primo max | movement_primitives RMSE | "
        "movement_primitives max | ratio | mp 'rk4-cython' RMSE |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rows:
        lines.append(
            f"| {r['case']} | {r['rate']} Hz | {r['k']} | {r['primo'][0]:.2e} | "
            f"{r['primo'][1]:.2e} | {r['mp'][0]:.2e} | {r['mp'][1]:.2e} | "
            f"{r['mp'][0] / r['primo'][0]:.2g} | {r['rk4'][0]:.2e} |")
    lines += [
        "",
        "## Accuracy: position + orientation (movement_primitives' CartesianDMP)",
        "",
        "A pose per row (x, y, z and a unit quaternion w, x, y, z, signs "
        "continuous); primo fits the position columns as a DMP and the "
        "quaternion columns as one orientation DMP (`primo dmp fit`), "
        "movement_primitives as a `CartesianDMP` (`imitate`, then `open_loop` "
        f"with 'euler-cython' and its 'cython' quaternion step, int_dt = {MP_INT_DT} s). "
        "Errors against the exact pose at the replay's times: position in m, "
        "orientation as the angle between the quaternions in rad; ratio = "
        "movement_primitives' RMSE / primo's.",
        "",
        "| case | rate | K | primo position RMSE | primo angle RMSE | primo angle max | "
        "mp position RMSE | mp angle RMSE | mp angle max | ratio position | ratio angle |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in cartesian:
        (pp, pa), (mp, ma) = r["primo"], r["mp"]
        lines.append(
            f"| {r['case']} | {r['rate']} Hz | {r['k']} | {pp[0]:.2e} | {pa[0]:.2e} | "
            f"{pa[1]:.2e} | {mp[0]:.2e} | {ma[0]:.2e} | {ma[1]:.2e} | "
            f"{mp[0] / pp[0]:.2g} | {ma[0] / pa[0]:.2g} |")
    return "\n".join(lines + replay_report(tm))


def spread(times, scale, fmt):
    return f"{format(min(times) * scale, fmt)}–{format(max(times) * scale, fmt)}"


def replay_report(tm):
    """The replay-time section of the report (Markdown lines)."""
    mp_fast = min(("mp euler-cython", "mp rk4-cython"), key=lambda s: tm[s])
    ratio = tm[mp_fast] / tm["primo"]
    rounds = [m / p for m, p in zip(tm[mp_fast + " runs"], tm["primo runs"])]
    lines = [
        "",
        "## Replay time: 60 s, 7 DoF, 30 kernels, dt = 1 ms, to a CSV file",
        "",
        f"Whole-process wall time, median (min–max) of {len(tm['primo runs'])} runs, in turn. primo writes "
        f"{tm['primo_rows']} rows, movement_primitives {tm['mp_rows']} "
        "(`open_loop`, then `np.savetxt` with 9 digits; the process loads the "
        "fitted weights from an .npz, as primo loads its JSON).",
        "",
        "| what | time |",
        "|---|---:|",
        f"| primo `dmp run --out file.csv` | {tm['primo'] * 1e3:.1f} ms "
        f"({spread(tm['primo runs'], 1e3, '.1f')}) |",
        f"| primo `dmp run --out /dev/null` | {tm['primo_devnull'] * 1e3:.1f} ms |",
        f"| primo `--version` (process start-up) | {tm['primo_startup'] * 1e3:.1f} ms |",
        f"| movement_primitives, `open_loop` 'euler-cython' (int_dt = dt) | "
        f"{tm['mp euler-cython'] * 1e3:.0f} ms ({spread(tm['mp euler-cython runs'], 1e3, '.0f')}) |",
        f"| movement_primitives, `open_loop` 'rk4-cython' | {tm['mp rk4-cython'] * 1e3:.0f} ms "
        f"({spread(tm['mp rk4-cython runs'], 1e3, '.0f')}) |",
        f"| of which: Python start-up + `import movement_primitives.dmp` | "
        f"{tm['python_import'] * 1e3:.0f} ms |",
        f"| of which: `open_loop` 'euler-cython' alone (in process) | {tm['mp_loop'] * 1e3:.0f} ms |",
        f"| of which: `np.savetxt` of 60,001 rows (in process) | {tm['mp_savetxt'] * 1e3:.0f} ms |",
        "",
        f"primo is **{ratio:.0f}×** faster than movement_primitives' fastest "
        f"({mp_fast[3:]}), whole process against whole process; the target was "
        f"≥ 30×: {'met' if ratio >= 30 else 'NOT met'}. Round by round (the runs go in turn, "
        f"primo, then movement_primitives): {spread(rounds, 1, '.0f')}×, median "
        f"{statistics.median(rounds):.0f}×. CPU time (user + sys), which the other "
        f"processes on a shared machine disturb less than wall time: primo "
        f"{statistics.median(tm['primo cpu']) * 1e3:.1f} ms, movement_primitives "
        f"{statistics.median(tm[mp_fast + ' cpu']) * 1e3:.0f} ms (medians), "
        f"{statistics.median(tm[mp_fast + ' cpu']) / statistics.median(tm['primo cpu']):.0f}×. In process (the loop "
        f"and savetxt, no start-up or import) movement_primitives takes "
        f"{(tm['mp_loop'] + tm['mp_savetxt']) * 1e3:.0f} ms, "
        f"{(tm['mp_loop'] + tm['mp_savetxt']) / tm['primo']:.0f}× primo's whole process.",
        "",
    ]
    if tm["profile"]:
        sh = tm["profile"]["share"]
        lines += [
            "Where primo's `dmp run --out /dev/null` spends its time (`perf record`, "
            f"flat profile by symbol): number formatting for the CSV {sh['formatting']:.0f}%, "
            f"DMP stepping (`primo_core`, `libm`) {sh['DMP']:.0f}%, other "
            f"(allocation, page faults, start-up) {sh['other']:.0f}%. Top symbols:",
            "",
            "```text",
            *tm["profile"]["top"],
            "```",
            "",
        ]
    return lines


def main():
    primo = os.path.abspath(sys.argv[1])
    quick = "--quick" in sys.argv
    if "--timing" in sys.argv:  # the replay time alone, printed
        runs = int(sys.argv[sys.argv.index("--runs") + 1]) if "--runs" in sys.argv else 5
        tm = timing(primo, quick, runs)
        print(json.dumps({k: v for k, v in tm.items() if k != "profile"}, indent=1))
        print("\n".join(replay_report(tm)))
        return
    rows = accuracy(primo, quick)
    cartesian = cartesian_accuracy(primo, quick)
    tm = timing(primo, quick)
    print(json.dumps({k: v for k, v in tm.items() if k != "profile"}, indent=1))
    text = report(rows, cartesian, tm, primo)
    print(text)
    if not quick:
        os.makedirs(os.path.join(HERE, "results"), exist_ok=True)
        with open(os.path.join(HERE, "results", "dmp_accuracy.md"), "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
