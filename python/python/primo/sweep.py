"""Sweeps of the paper's experiments: methods × settings × seeds, run on
local processes, threads, or Ray, gathered into ``primo experiment``'s
files.

A ``Sweep`` is a grid of seeded runs; each run is one call of
``primo.experiments.golden_run`` or ``power_run``, the very function
``primo experiment`` calls for that run, so each seed's result is the
command line's, bit for bit, wherever it ran. ``Sweep.run`` spreads the
runs over a backend and gathers them in the grid's order;
``Results.write`` writes them with the command's writers: one directory
per setting the command takes as a single value (golden: precision and
seed; power: kernels, updates, glass), holding what the command writes
for it (``golden.csv`` … or ``power_runs.csv`` …), byte for byte but for
the wall-clock time in the power summary.

Backends: ``"processes"`` (the default: one local process per core,
``concurrent.futures``), ``"threads"`` (the runs release the GIL, so
threads run in parallel too), ``"serial"``, and ``"ray"``: one Ray task
per run, ``ray.init()`` locally by default or ``address="ray://host:10001"``
(or ``"auto"``) for a cluster whose nodes have primo installed. Ray is an
optional extra of primo-robotics: ``pip install './python[ray]'``.

>>> import tempfile, pathlib
>>> from primo.sweep import Sweep
>>> sweep = Sweep("golden", grid={"volume": [0.4, 0.6], "method": ["golden", "secant"]},
...               seeds=[1, 2])
>>> len(sweep)
8
>>> results = sweep.run(backend="threads")
>>> [(r["seed"], r["volume"], r["method"], r["rollouts_to_precision"]) for r in results][:2]
[(1, 0.4, 'golden', 9), (1, 0.4, 'secant', 3)]
>>> out = pathlib.Path(tempfile.mkdtemp())
>>> [p.name for p in results.write(out)]
['seed=1', 'seed=2']
>>> sorted(p.name for p in (out / "seed=1").iterdir())
['golden.csv', 'golden.png', 'primo.lock', 'summary.json']

A directory that holds an earlier result is refused (``ValueError``)
unless ``force=True``, as ``primo experiment`` refuses it without
``--force``; ``Sweep.check_out`` asks before the runs begin.

From a shell (``python -m primo.sweep --help``)::

    python -m primo.sweep power --seeds 1-20 --out experiment-power
    python -m primo.sweep power --kernels 10,30 --seeds 1-20 --backend ray --address auto
    python -m primo.sweep golden --seeds 1-10 --backend processes --workers 2

With the "processes" backend a script must start the sweep under
``if __name__ == "__main__":`` (the workers import the main module when
Python starts them by spawning, as on macOS and Windows).
"""

from __future__ import annotations

import argparse
import concurrent.futures
import itertools
import json
import os
import pathlib
import sys
import time
from typing import Any, Dict, Iterable, Iterator, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from primo.experiments import (
    METHODS,
    VARIANTS,
    check_out,
    golden_run,
    power_run,
    write_golden,
    write_power,
)

__all__ = ["AXES", "BACKENDS", "Results", "Sweep"]

#: Each experiment's axes and their defaults (the command's), in the order
#: the runs are made: the command's single-valued settings first (one
#: directory of files each), then what one invocation of the command runs.
AXES: Dict[str, Dict[str, Tuple[Any, ...]]] = {
    "golden": {
        "precision": (0.002,),
        "seed": (1,),
        "volume": (0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0),
        "method": METHODS,
    },
    "power": {
        "kernels": (30,),
        "updates": (100,),
        "glass": ("small",),
        "variant": VARIANTS,
        "seed": tuple(range(1, 21)),
    },
}
#: Per experiment, the axes of which one invocation of the command takes
#: one value: the runs of each combination are written into one directory.
FILES_PER = {"golden": ("precision", "seed"), "power": ("kernels", "updates", "glass")}
BACKENDS = ("processes", "threads", "serial", "ray")


def _values(name: str, value: Any) -> Tuple[Any, ...]:
    """An axis's values: a scalar is one value; a string is one value."""
    if isinstance(value, (str, bytes)) or not isinstance(value, Iterable):
        return (value,)
    values = tuple(value)
    if not values:
        raise ValueError(f"{name}: no values")
    return values


def _run_task(kind: str, settings: Mapping[str, Any]) -> Dict[str, Any]:
    """One run of the sweep (a module-level function: it pickles by name)."""
    if kind == "golden":
        return golden_run(**settings)
    return power_run(**settings)


class Sweep:
    """A grid of seeded runs of one of the paper's experiments.

    ``kind`` is ``"golden"`` (axes ``volume``, ``method``, ``precision``)
    or ``"power"`` (axes ``variant``, ``kernels``, ``updates``,
    ``glass``); ``grid`` maps axes to a value or a list of values (the
    others keep the command's defaults, ``AXES``); ``seeds`` are the seeds
    (golden: 1; power: 1–20, as ``primo experiment``).

    >>> sweep = Sweep("power", grid={"kernels": [10, 30], "updates": 50}, seeds=range(1, 4))
    >>> len(sweep), sweep.tasks()[0]
    (18, {'kernels': 10, 'updates': 50, 'glass': 'small', 'variant': 'extended', 'seed': 1})
    """

    def __init__(
        self,
        kind: str,
        grid: Optional[Mapping[str, Any]] = None,
        seeds: Union[int, Iterable[int], None] = None,
    ) -> None:
        if kind not in AXES:
            raise ValueError(f"kind: `{kind}`, expected \"golden\" or \"power\"")
        axes = dict(AXES[kind])
        for name, value in dict(grid or {}).items():
            if name not in axes or name == "seed":
                settable = ", ".join(a for a in axes if a != "seed")
                raise ValueError(f"grid: no axis `{name}` in the {kind} experiment ({settable}; "
                                 "seeds are given as seeds=)")
            axes[name] = _values(name, value)
        if seeds is not None:
            axes["seed"] = _values("seeds", seeds)
        choices = {"method": METHODS, "variant": VARIANTS, "glass": ("normal", "small")}
        for name, allowed in choices.items():
            for v in axes.get(name, ()):
                if v not in allowed:
                    raise ValueError(f"{name}: `{v}`, expected one of {', '.join(allowed)}")
        for name, values in axes.items():
            if len(set(values)) != len(values):
                raise ValueError(f"{name}: {list(values)} repeats a value")
        self.kind = kind
        self.axes: Dict[str, Tuple[Any, ...]] = axes

    def tasks(self) -> List[Dict[str, Any]]:
        """Every run's settings (keyword arguments of ``golden_run`` or
        ``power_run``), in the order the runs are gathered."""
        names = list(self.axes)
        return [dict(zip(names, combo)) for combo in itertools.product(*self.axes.values())]

    def directories(self, out: Union[str, os.PathLike]) -> List[pathlib.Path]:
        """Where ``Results.write(out)`` writes each group of runs (see
        ``Results.groups``), in order: ``out`` itself if there is one
        group, else ``out/NAME=VALUE,…`` naming the settings that vary.

        >>> sweep = Sweep("power", grid={"kernels": [10, 30]}, seeds=[1, 2])
        >>> [p.as_posix() for p in sweep.directories("out")]
        ['out/kernels=10', 'out/kernels=30']
        """
        out = pathlib.Path(out)
        keys = FILES_PER[self.kind]
        varying = [k for k in keys if len(self.axes[k]) > 1]
        seen: Dict[Tuple[Any, ...], pathlib.Path] = {}
        for task in self.tasks():
            name = ",".join(f"{k}={task[k]}" for k in varying)
            seen.setdefault(tuple(task[k] for k in keys), out / name if name else out)
        return list(seen.values())

    def check_out(self, out: Union[str, os.PathLike], force: bool = False) -> None:
        """Refuses (``ValueError``) before any run an ``out`` whose
        directories (``directories``) hold an earlier result, unless
        ``force``, or that another primo is writing into.

        >>> import tempfile
        >>> Sweep("golden", seeds=[1]).check_out(tempfile.mkdtemp())  # empty: fine
        """
        for where in self.directories(out):
            check_out(where, self.kind, force)

    def __len__(self) -> int:
        n = 1
        for values in self.axes.values():
            n *= len(values)
        return n

    def __repr__(self) -> str:
        axes = ", ".join(f"{k}={list(v)}" for k, v in self.axes.items())
        return f"Sweep({self.kind!r}, {axes})"

    def run(
        self,
        backend: str = "processes",
        workers: Optional[int] = None,
        address: Optional[str] = None,
    ) -> Results:
        """Runs every task on ``backend`` and gathers the results in order.

        ``workers``: processes or threads (default: one per core; for a
        local Ray, its CPUs). ``address``: the Ray cluster to join
        (``None``: a local one, started if none is running; ``"auto"``:
        the cluster this machine belongs to; ``"ray://host:10001"``: a
        remote one through Ray Client). A Ray session already started by
        ``ray.init`` is used as it is, and one this starts is left running
        for the next sweep (``ray.shutdown()`` ends it).

        >>> sweep = Sweep("golden", grid={"volume": 0.5, "method": "golden"}, seeds=[1, 2])
        >>> [(r["seed"], r["rollouts_to_precision"]) for r in sweep.run(backend="serial")]
        [(1, 8), (2, 8)]
        """
        if backend not in BACKENDS:
            raise ValueError(f"backend: `{backend}`, expected one of {', '.join(BACKENDS)}")
        if workers is not None and workers < 1:
            raise ValueError(f"workers: {workers}, must be at least 1")
        if address is not None and backend != "ray":
            raise ValueError(f"address: only the \"ray\" backend joins a cluster, not {backend!r}")
        tasks = self.tasks()
        started = time.perf_counter()
        if backend == "serial":
            runs = [_run_task(self.kind, t) for t in tasks]
        elif backend == "threads":
            with concurrent.futures.ThreadPoolExecutor(workers or os.cpu_count()) as pool:
                runs = list(pool.map(lambda t: _run_task(self.kind, t), tasks))
        elif backend == "processes":
            with concurrent.futures.ProcessPoolExecutor(workers) as pool:
                runs = list(pool.map(_run_task, itertools.repeat(self.kind), tasks))
        else:
            runs = _on_ray(self.kind, tasks, workers, address)
        return Results(self, runs, time.perf_counter() - started)


def _on_ray(
    kind: str, tasks: List[Dict[str, Any]], workers: Optional[int], address: Optional[str]
) -> List[Dict[str, Any]]:
    """The runs as Ray tasks, one CPU each, gathered in order."""
    try:
        import ray
    except ImportError as e:
        raise ImportError(
            "the \"ray\" backend needs Ray: pip install './python[ray]' (or 'ray'); "
            "without it use backend=\"processes\""
        ) from e
    if not ray.is_initialized():
        options: Dict[str, Any] = {"address": address}
        if address is None:
            options.update(num_cpus=workers, include_dashboard=False)
        ray.init(**options)
    remote = ray.remote(num_cpus=1)(_run_task)
    runs = ray.get([remote.remote(kind, t) for t in tasks])
    # Ray hands NumPy arrays back read-only (views of its object store):
    # writable copies, as the other backends give.
    for run in runs:
        run["rollouts"] = {k: np.array(v) if isinstance(v, np.ndarray) else v
                           for k, v in run["rollouts"].items()}
    return runs


class Results:
    """A sweep's runs, in the order of ``Sweep.tasks()``; iterable.

    ``sweep``: the sweep that ran; ``runs``: the dicts of ``golden_run``
    or ``power_run``; ``seconds``: the sweep's wall-clock time.

    >>> results = Sweep("golden", grid={"volume": 0.5, "method": "secant"}, seeds=[1]).run(backend="serial")
    >>> len(results), results.groups()[0][0]
    (1, {'precision': 0.002, 'seed': 1})
    """

    def __init__(self, sweep: Sweep, runs: List[Dict[str, Any]], seconds: float) -> None:
        self.sweep = sweep
        self.runs = runs
        self.seconds = seconds

    def __iter__(self) -> Iterator[Dict[str, Any]]:
        return iter(self.runs)

    def __len__(self) -> int:
        return len(self.runs)

    def groups(self) -> List[Tuple[Dict[str, Any], List[Dict[str, Any]]]]:
        """The runs by the settings the command takes one value of
        (``FILES_PER``): ``(settings, runs)`` in order."""
        keys = FILES_PER[self.sweep.kind]
        out: Dict[Tuple[Any, ...], List[Dict[str, Any]]] = {}
        for task, run in zip(self.sweep.tasks(), self.runs):
            out.setdefault(tuple(task[k] for k in keys), []).append(run)
        return [(dict(zip(keys, k)), runs) for k, runs in out.items()]

    def write(self, out: Union[str, os.PathLike], force: bool = False) -> List[pathlib.Path]:
        """Writes the files ``primo experiment`` writes, one directory per
        group (``groups()``, into ``Sweep.directories(out)``); an earlier
        result there is replaced only with ``force``. Returns the
        directories.

        >>> import tempfile
        >>> results = Sweep("golden", grid={"volume": 0.5, "method": "secant"}, seeds=[1]).run(backend="serial")
        >>> [p.name for p in results.write(tempfile.mkdtemp() + "/out")]
        ['out']
        """
        written = []
        for (_, runs), where in zip(self.groups(), self.sweep.directories(out)):
            if self.sweep.kind == "golden":
                write_golden(where, runs, force)
            else:
                write_power(where, runs, self.seconds, force)
            written.append(where)
        return written


def _seeds(text: str) -> List[int]:
    """``1-20`` or ``1,2,5`` (or both: ``1-3,7``)."""
    seeds: List[int] = []
    for part in text.split(","):
        first, dash, last = part.partition("-")
        try:
            seeds += range(int(first), int(last) + 1) if dash else [int(first)]
        except ValueError:
            raise argparse.ArgumentTypeError(f"`{part}`: a seed or a range FIRST-LAST") from None
    return seeds


def _list(kind: type):
    def parse(text: str) -> List[Any]:
        try:
            return [kind(v) for v in text.split(",")]
        except ValueError:
            raise argparse.ArgumentTypeError(f"`{text}`: comma-separated {kind.__name__}s") from None

    return parse


def _report(kind: str, settings: Mapping[str, Any], where: pathlib.Path) -> str:
    """One line from a group's summary.json."""
    summary = json.loads((where / "summary.json").read_text())
    label = " ".join(f"{k} {v}" for k, v in settings.items())
    if kind == "golden":
        medians = ", ".join(
            f"{m} {'-' if v is None else f'{v:g}'}" for m, v in summary["median_rollouts"]
        )
        return f"{label}: median roll-outs to precision: {medians}; wrote {where}"
    parts = []
    for variant in VARIANTS:
        c = summary[variant.replace("-", "_")]
        if c["error"]["mean"]:
            parts.append(f"{variant} final |error| {c['error']['mean'][-1] * 1e3:.2f} ml, "
                         f"reward {c['reward']['mean'][-1]:.3f}")
    return f"{label}: {'; '.join(parts)}; wrote {where}"


def main(argv: Optional[Sequence[str]] = None) -> int:
    """``python -m primo.sweep``: a sweep from the shell."""
    p = argparse.ArgumentParser(
        prog="python -m primo.sweep",
        description="The paper's experiments as sweeps (methods × settings × seeds) on local "
        "processes or Ray, written as `primo experiment` writes them. Lists are "
        "comma-separated; each seed's runs equal `primo experiment ... --seed S`'s.",
    )
    p.add_argument("kind", choices=sorted(AXES))
    p.add_argument("--seeds", type=_seeds, help="e.g. 1-20 or 1,4,9 (golden: 1; power: 1-20)")
    p.add_argument("--volumes", type=_list(float), help="golden: bottle volumes, l")
    p.add_argument("--methods", type=_list(str), help=f"golden: of {','.join(METHODS)}")
    p.add_argument("--precision", type=_list(float), help="golden: stop at |error| below, l")
    p.add_argument("--variants", type=_list(str), help=f"power: of {','.join(VARIANTS)}")
    p.add_argument("--kernels", type=_list(int), help="power: kernels per joint")
    p.add_argument("--updates", type=_list(int), help="power: updates per run")
    p.add_argument("--glass", type=_list(str), help="power: small, normal")
    p.add_argument("--backend", choices=BACKENDS, default="processes")
    p.add_argument("--workers", type=int, help="processes or threads (default: one per core)")
    p.add_argument("--address", help="ray: the cluster (\"auto\", ray://host:10001)")
    p.add_argument("--out", type=pathlib.Path, help="default: experiment-KIND")
    p.add_argument("--force", action="store_true", help="replace an earlier result in --out")
    args = p.parse_args(argv)
    flags = {"volumes": "volume", "methods": "method", "precision": "precision",
             "variants": "variant", "kernels": "kernels", "updates": "updates", "glass": "glass"}
    grid = {}
    for flag, axis in flags.items():
        value = getattr(args, flag)
        if value is None:
            continue
        if axis not in AXES[args.kind]:
            p.error(f"--{flag} is not a setting of the {args.kind} experiment")
        grid[axis] = value
    try:
        sweep = Sweep(args.kind, grid, args.seeds)
        out = args.out or pathlib.Path(f"experiment-{args.kind}")
        sweep.check_out(out, args.force)
        results = sweep.run(args.backend, args.workers, args.address)
        dirs = results.write(out, args.force)
    except (ValueError, OSError, ImportError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2 if isinstance(e, ValueError) else 1
    for (settings, _), where in zip(results.groups(), dirs):
        print(_report(args.kind, settings, where))
    print(f"{len(results)} runs on {args.backend} in {results.seconds:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
