"""Type stubs of the compiled module ``primo._primo`` (see ``primo``)."""

from os import PathLike
from typing import Any, Literal, Mapping, Optional, Sequence, TypedDict, Union, overload

import numpy as np
import numpy.typing as npt

__version__: str

Array = npt.NDArray[np.float64]
ArrayLike = npt.ArrayLike
Status = Literal["running", "converged", "budget_exhausted", "bracket_collapsed", "stalled", "infeasible"]
Path = Union[str, PathLike[str]]

class Dmp:
    """A fitted DMP with its column names: discrete (columns ``<p>qw,
    <p>qx, <p>qy, <p>qz`` are one orientation, a quaternion DMP) or
    rhythmic. The JSON DMP file of ``primo dmp fit`` / ``run``."""

    @staticmethod
    def fit(
        t: ArrayLike,
        y: ArrayLike,
        names: Optional[Sequence[str]] = None,
        kernels: int = 30,
        margin: Optional[float] = None,
    ) -> Dmp:
        """Fits ``y`` (n × columns, or n) sampled at times ``t`` (n, strictly
        increasing): least squares on the positions, ``kernels`` (2–128) per DoF.
        ``margin``: kernel spacings the outer kernels lie beyond the movement's
        ends (0 to (kernels − 2)/2); ``None`` tries 0 and 1 and keeps the one
        that reproduces ``y`` better. DMPs generalized together need the same."""
    @staticmethod
    def fit_rhythmic(
        t: ArrayLike,
        y: ArrayLike,
        names: Optional[Sequence[str]] = None,
        kernels: int = 30,
        period: Optional[float] = None,
    ) -> Dmp:
        """Fits one period (``period`` s from the first sample, or all of it)."""
    @staticmethod
    def from_json(text: str) -> Dmp:
        """Reads the DMP file format (versions 1 and 2)."""
    @staticmethod
    def load(path: Path) -> Dmp:
        """Reads a DMP file written by ``primo dmp fit`` or ``Dmp.save``."""
    def to_json(self) -> str:
        """The DMP file's text."""
    def save(self, path: Path) -> None:
        """Writes the DMP file (atomically)."""
    @property
    def names(self) -> list[str]: ...
    @property
    def rhythmic(self) -> bool: ...
    @property
    def kernels(self) -> int: ...
    @property
    def dof(self) -> int:
        """DMP DoFs (an orientation counts 3)."""
    @property
    def orientations(self) -> list[list[str]]: ...
    @property
    def tau(self) -> float:
        """The demonstrated duration, s (discrete)."""
    @property
    def period(self) -> float:
        """The demonstrated period, s (rhythmic)."""
    @property
    def start(self) -> Array:
        """The demonstrated start, per column (discrete)."""
    @property
    def goal(self) -> Array:
        """The goal, per column (discrete)."""
    @property
    def params(self) -> Array:
        """θ = [weights row by row, goals, τ] of the DMP's DoFs (discrete)."""
    @params.setter
    def params(self, theta: ArrayLike) -> None: ...
    @overload
    def run(
        self,
        dt: float = 0.001,
        tau: Optional[float] = None,
        start: Optional[ArrayLike] = None,
        goal: Optional[ArrayLike] = None,
        velocities: Literal[False] = False,
    ) -> tuple[Array, Array]: ...
    @overload
    def run(
        self,
        dt: float = 0.001,
        tau: Optional[float] = None,
        start: Optional[ArrayLike] = None,
        goal: Optional[ArrayLike] = None,
        *,
        velocities: Literal[True],
    ) -> tuple[Array, Array, Array]: ...
    @overload
    def run(
        self,
        dt: float = 0.001,
        *,
        duration: Optional[float] = None,
        frequency: Optional[float] = None,
        amplitude: Optional[ArrayLike] = None,
        anchor: Optional[ArrayLike] = None,
    ) -> tuple[Array, Array]: ...
    def stepper(
        self,
        tau: Optional[float] = None,
        start: Optional[ArrayLike] = None,
        goal: Optional[ArrayLike] = None,
    ) -> DmpRun:
        """A step-by-step execution (discrete)."""
    def __reduce__(self) -> Any: ...

class DmpRun:
    """A discrete DMP executed one control step at a time (`Dmp.stepper()`):
    open loop it gives the same samples as `Dmp.run`, bit for bit. Closed
    loop, each `step` may take the robot's measured `position` and
    `velocity` (the run goes on from them; its own values change nothing)
    and a `coupling` acceleration for that step. Pickles and copies (the
    copy continues bit for bit).

    >>> import copy, numpy as np, primo
    >>> t = np.linspace(0.0, 1.0, 101)
    >>> dmp = primo.Dmp.fit(t, t * t * (3 - 2 * t), names=["x"], kernels=20)
    >>> open_loop = dmp.run(dt=0.01)[1]
    >>> run = dmp.stepper()
    >>> fed_back = [run.step(0.01, position=run.position, velocity=run.velocity)
    ...             for _ in range(100)]
    >>> bool((np.array(fed_back) == open_loop[1:]).all())
    True
    >>> twin = copy.copy(run)
    >>> bool((twin.step(0.01) == run.step(0.01)).all())
    True"""

    def step(
        self,
        dt: float,
        position: Optional[ArrayLike] = None,
        velocity: Optional[ArrayLike] = None,
        coupling: Optional[ArrayLike] = None,
    ) -> Array:
        """Advances by `dt` seconds and returns the position, per column.

        Closed loop (DMPs without orientation columns): `position` and
        `velocity` (per second), one value per column, are the robot's
        measured state now; the step starts from them instead of the run's
        own (movement_primitives' `step(last_y, last_yd)`; either may be
        left out, and the run's own values change nothing, bit for bit).
        `coupling`: an acceleration per column (units per s²) added over
        this step, `τ²ÿ = K(g − y) − ατẏ + f + τ²·coupling`, where
        obstacle-avoidance or joint-limit terms enter.

        Returns: the position after the step, per column (float64).
        Raises: `ValueError` for a `dt` that is not positive and finite, a
        wrong length, a non-finite value, a position beyond ±1e6, or
        closed-loop values for a DMP with orientation columns; the run is
        then unchanged.

        >>> import numpy as np, primo
        >>> t = np.linspace(0.0, 1.0, 101)
        >>> run = primo.Dmp.fit(t, t, names=["x"], kernels=10).stepper()
        >>> x = run.step(0.01, position=[0.5], velocity=[0.0])  # on from the robot
        >>> bool(abs(x[0] - 0.5) < 0.01)
        True
        >>> _ = run.step(0.01, coupling=[2.0])"""
    @property
    def position(self) -> Array:
        """The current position, per column."""
    @property
    def velocity(self) -> Array:
        """The current velocity per second, per column (DMPs without
        orientation columns)."""
    @property
    def time(self) -> float:
        """Seconds since the start."""
    @property
    def phase(self) -> float:
        """The phase `t/τ`, at most 1."""
    def set_goal(self, goal: ArrayLike) -> None:
        """A new goal from the next step on (DMPs without orientation columns)."""
    def __reduce__(self) -> Any: ...
    def __copy__(self) -> DmpRun: ...
    def __deepcopy__(self, memo: Any) -> DmpRun: ...

class Generalizer:
    """``G(q)`` over examples ``(query, dmp)``: LWR or GPR on the DMPs'
    parameter vectors, the start generalized alike. Every example is a
    discrete DMP with the first one's columns, in order; orientation groups
    (``<p>qw,<p>qx,<p>qy,<p>qz``) are generalized as ``primo learn`` does:
    goals and starts as rotation vectors at the mean of the examples' goals,
    so each ``generalize(q)`` runs with unit quaternions and equals each
    example at its query where the regression interpolates."""

    def __init__(
        self,
        examples: Sequence[tuple[Union[float, ArrayLike], Dmp]],
        method: Literal["lwr", "gpr"] = "lwr",
        bandwidth: Optional[float] = None,
        noise: float = 0.0,
    ) -> None: ...
    def generalize(self, q: Union[float, ArrayLike]) -> Dmp:
        """The DMP for query ``q``."""
    def params(self, q: Union[float, ArrayLike]) -> Array:
        """``G(q)``, the parameter vector (an orientation group's three goal
        values: its goal's rotation vector from the examples' mean goal)."""
    @property
    def query_dim(self) -> int: ...
    @property
    def names(self) -> list[str]: ...
    def __len__(self) -> int: ...

class _ErrorLearner:
    def tell_infeasible(self) -> Status:
        """The asked query could not be rolled out or measured: it bounds
        the search, and counts against the budget."""
    @property
    def status(self) -> Status: ...
    @property
    def done(self) -> bool: ...
    @property
    def rollouts(self) -> int: ...

class _ScalarSearch(_ErrorLearner):
    def __init__(
        self, low: float, high: float, desired: float, precision: float = 0.002, max_rollouts: int = 30
    ) -> None: ...
    def ask(self) -> Optional[float]:
        """The query to roll out next, or None once finished."""
    def tell(self, error: float) -> Status:
        """The asked query's error; > 0 means the query must grow."""
    @property
    def best(self) -> Optional[tuple[float, float]]:
        """``(query, error)`` with the smallest |error| so far."""
    @property
    def bracket(self) -> tuple[float, float]: ...

class GoldenSection(_ScalarSearch):
    """The paper's error learning: golden-section search on the query."""

class Illinois(_ScalarSearch):
    """Bracketed error learning using the error's magnitude (Illinois)."""

class Secant(_ErrorLearner):
    """The paper's eq. 10, ``q ← q + K ε``, on a query of 1 to 4 values,
    ``K`` starting at ``gain · I``: learned by Broyden updates
    (``rule="broyden"``), or fixed (``"fixed"``: eq. 10; ``"weighted"``:
    eq. 11)."""

    def __init__(
        self,
        low: ArrayLike,
        high: ArrayLike,
        desired: ArrayLike,
        precision: float = 0.002,
        max_rollouts: int = 30,
        gain: float = 1.0,
        rule: Literal["broyden", "fixed", "weighted"] = "broyden",
    ) -> None: ...
    def ask(self) -> Optional[Array]: ...
    def tell(self, error: ArrayLike) -> Status:
        """The error vector ``desired − measured`` of the asked query."""
    @property
    def dim(self) -> int: ...
    @property
    def best(self) -> Optional[tuple[Array, Array]]: ...
    @property
    def gain(self) -> Array: ...

class Power:
    """PoWER (Kober & Peters) as in the paper: contiguous `blocks` of
    `(len, variance, decay)`, the mean rolled out once per update
    (`roll_out_mean`), `rollouts_per_update` explorations, an importance
    sampler of the best `sampler` roll-outs; deterministic per `seed`.
    At most 2066 parameters (a 16-DoF, 128-kernel DMP and its query).

    The query: `query` = n says the first n parameters are a query (whole
    blocks: n ends where a block ends), as in primo's extended vector `[q̂,
    Δθ]`. With `query_gain` K ≠ 0 it is learned from the error as well:
    `tell(reward, error)` with n error values keeps each roll-out's query
    as `q + K·error` (the paper's eq. 10 inside PoWER). `Power.defaults`
    builds primo's exploration for a skill.

    Parameters: `initial` (the parameters' start), `blocks` (each `(len,
    variance, decay)`: `len` parameters explored with `variance`, times
    `decay` after each update; the lengths sum to `len(initial)`),
    `rollouts_per_update` (explorations per update), `roll_out_mean`,
    `sampler` (1 to 10), `seed` (int in 0..2**64), `query_gain` (K),
    `query` (the query's length n, 0 for none).
    Raises: `ValueError` for blocks that do not cover `initial`, a
    `query` that does not end on a block, or a query gain without a query.

    >>> import numpy as np, primo
    >>> power = primo.Power([1.0, -1.0], blocks=[(2, 0.04, 1.0)], seed=42)
    >>> for _ in range(200):
    ...     theta = power.ask()
    ...     _ = power.tell(1.0 / (1.0 + float(theta @ theta)))
    >>> power.updates, bool(np.abs(power.mean).max() < 0.3)
    (50, True)
    >>> learned = primo.Power([0.5, 1.0, -1.0], blocks=[(1, 0.01, 0.9), (2, 0.04, 1.0)],
    ...                       query=1, query_gain=1.0)
    >>> theta = learned.ask()
    >>> learned.tell(0.5, error=[0.1])
    False"""

    def __init__(
        self,
        initial: ArrayLike,
        blocks: Sequence[tuple[int, float, float]],
        rollouts_per_update: int = 3,
        roll_out_mean: bool = True,
        sampler: int = 3,
        seed: int = 0,
        query_gain: float = 0.0,
        query: int = 0,
    ) -> None: ...
    @staticmethod
    def defaults(
        skill: Union[Cell, Generalizer],
        start: Optional[Union[float, ArrayLike]] = None,
        seed: int = 0,
        s1: float = 0.2,
        s2: float = 0.05,
        query_gain: float = 0.0,
    ) -> Power:
        """PoWER with primo's defaults on a skill, as `primo learn` and
        `primo pour --method power` build it: the extended vector `[q̂, Δθ]`
        starting at `[start, 0, …]`; one block for the query (its variance
        decaying by 0.9 per update), one for each DoF's kernel weights, one
        for the goals, one for τ, each exploring with the standard deviation
        `s · (the examples' widest distance over the block) / √len` (`s1` for
        the query, `s2` for the rest); 3 roll-outs per update plus the mean,
        a sampler of 3. `primo pour --method power-el` is `s1=0.0,
        query_gain=1.0` (its `--gain`).

        Parameters: `skill` (a `Cell`, or a `Generalizer` over examples),
        `start` (the first query: default the cell's bottle, required for a
        Generalizer; one value per query entry), `seed` (the run's seed),
        `s1`, `s2` (exploration scales, >= 0), `query_gain` (K).
        Returns: a `Power` with `query` = the skill's query length.
        Raises: `TypeError` for another `skill`; `ValueError` for a missing or
        wrong-length start, or scales the examples cannot give a spread.

        >>> import primo
        >>> cell = primo.Cell(kernels=10)
        >>> power = primo.Power.defaults(cell, seed=1)
        >>> len(power.ask()) == len(cell), float(power.mean[0])
        (True, 0.5)"""
    def ask(self) -> Array:
        """The parameters to roll out next (the same until told)."""
    def tell(self, reward: float, error: Optional[ArrayLike] = None) -> bool:
        """The reward (finite, >= 0) of the asked roll-out; True when it
        completed an update. `error`: the roll-out's error over the query
        (`query` values, > 0 asks for a larger query), needed with a query
        gain, refused without a query.

        Raises: `ValueError` for a negative or non-finite reward, an error
        of another length than the query, or a missing one with a gain."""
    @property
    def query(self) -> int:
        """The query's length: the first `query` parameters (0: none)."""
    @property
    def mean(self) -> Array: ...
    @property
    def updates(self) -> int: ...
    @property
    def rollouts(self) -> int: ...
    @property
    def variances(self) -> Array: ...
    @property
    def next_is_mean(self) -> bool: ...
    @property
    def best(self) -> Optional[tuple[Array, float]]: ...
    @property
    def sampler(self) -> list[tuple[Array, float]]: ...

class Cell:
    """The simulated pouring cell as an objective (``primo rollout``)."""

    def __init__(
        self,
        glass: Literal["normal", "small"] = "small",
        space: Literal["joint", "cartesian"] = "joint",
        bottle: float = 0.5,
        target: float = 0.2,
        kernels: int = 30,
        seed: int = 1,
        demos: Optional[Sequence[tuple[Path, float]]] = None,
    ) -> None: ...
    @property
    def size(self) -> int: ...
    def __len__(self) -> int: ...
    @property
    def glass(self) -> str: ...
    @property
    def space(self) -> str: ...
    @property
    def bottle(self) -> float: ...
    @property
    def target(self) -> float: ...
    @property
    def kernels(self) -> int: ...
    @property
    def glass_holds(self) -> float:
        """What the glass holds to its rim, litres: `primo pour`'s
        `glass_holds` in summary.json. Error learning searches only queries
        that let no more than this leave the bottle: from
        `max(0.1, bottle + target − glass_holds)` (in float32) to 1.5 l.

        >>> import primo
        >>> round(primo.Cell(glass="small", kernels=10).glass_holds, 3)
        0.423"""
    def pour_seed(self, rollout: int, seed: Optional[int] = None) -> int:
        """The seed of the scale's noise that `primo pour --seed SEED` uses
        for roll-out `rollout` (numbered from 1, as rollouts.csv's); `seed`
        defaults to the cell's. `cell.rollout(theta, seed=cell.pour_seed(k))`
        is roll-out k of that run when `theta` is what it rolled out.

        Parameters: `rollout` (int >= 1), `seed` (int in 0..2**64, or None).
        Returns: the seed, an int in 0..2**64.
        Raises: `ValueError` for a roll-out below 1 or beyond 2**32 − 1, or a
        seed out of range.

        >>> import primo
        >>> cell = primo.Cell(kernels=10, seed=7)
        >>> cell.pour_seed(1) == cell.pour_seed(1, seed=7) != cell.pour_seed(2)
        True"""
    def with_context(self, bottle: Optional[float] = None, target: Optional[float] = None) -> Cell:
        """The same cell (glass, space, kernels, seed, demonstrations) for
        another context: `bottle` litres in the bottle, `target` litres to
        pour (each by default this cell's). Its skill is generalized to the
        new bottle, so its `start()` differs.

        Raises: `ValueError` for a bottle or target the cell refuses (as
        the constructor).

        >>> import primo
        >>> cell = primo.Cell(kernels=10, bottle=0.5, target=0.2)
        >>> other = cell.with_context(bottle=0.8)
        >>> other.bottle, other.target, len(other) == len(cell)
        (0.8, 0.2, True)"""
    @property
    def seed(self) -> int: ...
    @property
    def names(self) -> list[str]:
        """The commanded columns: ``a1..a7``, or in Cartesian space the
        mouth and the bottle's orientation, ``x, y, z, qw, qx, qy, qz``."""
    def start(self) -> dict[str, Any]:
        """``primo rollout --print-start``: layout, space, glass, bottle,
        target, dof, kernels, start and std."""
    def rollout(
        self, theta: ArrayLike, seed: Optional[int] = None, series: bool = False
    ) -> dict[str, Any]:
        """poured, spilled, error, reward, safe, rejected (and series)."""
    def rollout_delta(
        self,
        query: Union[float, ArrayLike],
        delta: ArrayLike,
        seed: Optional[int] = None,
        series: bool = False,
    ) -> dict[str, Any]:
        """One roll-out of `G(query) + delta`: PoWER's extended vector `[q̂,
        Δθ]` executed as `primo pour` and `primo learn` execute it (`rollout`
        takes `θ = G(bottle) + Δθ` instead, whose float32 sum rounds Δθ).
        With `Power.defaults(cell)` and `pour_seed` this repeats a PoWER run
        of `primo pour` roll-out by roll-out.

        Parameters: `query` (the skill's query, 1 value: litres in the
        bottle), `delta` (`len(cell) − 1` values, the layout of
        `start()["start"][:-1]`), `seed` (the scale's noise, default the
        cell's), `series` (add the time series).
        Returns: the dict of `rollout`.
        Raises: `ValueError` for wrong lengths or non-finite values.

        >>> import numpy as np, primo
        >>> cell = primo.Cell(kernels=10)
        >>> start = cell.start()["start"]
        >>> cell.rollout_delta([0.5], np.zeros(len(cell) - 1)) == cell.rollout(start)
        True"""
    def rollout_many(
        self, thetas: ArrayLike, seeds: Optional[Sequence[int]] = None
    ) -> list[dict[str, Any]]:
        """Every row on all cores, the GIL released."""

class Robot:
    """A serial arm from its base link to a tip (a link, or a tool frame in
    it), with its joints' limits: forward kinematics, the geometric
    Jacobian and inverse kinematics in float64 (metres, radians; poses are
    4 × 4 homogeneous matrices in the base frame). Pickles as its URDF text
    and settings."""

    @staticmethod
    def from_urdf(
        path: Path,
        base: Optional[str] = None,
        tip: Optional[str] = None,
        tool: Optional[ArrayLike] = None,
        limits: Optional[Mapping[str, tuple[float, float, float]]] = None,
    ) -> Robot:
        """The chain of the URDF at ``path`` from ``base`` (default: the
        root link) to ``tip`` (default: the one leaf below the base), ending
        at ``tool`` (4 × 4, tip link → tool frame). ``limits``: joint name →
        (lower, upper, velocity), for joints the URDF gives none or to
        narrow them. A file that cannot be read: ``OSError``; a xacro file,
        a mimic, floating or planar joint in the chain, a joint without
        limits, a malformed URDF: ``ValueError`` naming its line and column."""
    @staticmethod
    def from_urdf_text(
        text: str,
        base: Optional[str] = None,
        tip: Optional[str] = None,
        tool: Optional[ArrayLike] = None,
        limits: Optional[Mapping[str, tuple[float, float, float]]] = None,
        file: str = "<string>",
    ) -> Robot:
        """``from_urdf`` of a URDF's text (``file`` names it in errors)."""
    @staticmethod
    def lwr4() -> Robot:
        """The built-in KUKA LWR 4 (DH table, flange tip, joints a1..a7)."""
    @property
    def name(self) -> str:
        """The URDF's robot name."""
    @property
    def base(self) -> str: ...
    @property
    def tip(self) -> str: ...
    @property
    def joint_names(self) -> list[str]:
        """The moving joints, base to tip: the order of every q."""
    @property
    def dof(self) -> int: ...
    @property
    def lower(self) -> Array:
        """Lowest positions (−inf for a continuous joint)."""
    @property
    def upper(self) -> Array:
        """Highest positions (+inf for a continuous joint)."""
    @property
    def velocity(self) -> Array:
        """Fastest speeds, rad/s or m/s."""
    def forward(self, q: ArrayLike) -> Array:
        """The tool's pose at ``q`` (dof), 4 × 4 homogeneous."""
    def forward_many(self, qs: ArrayLike) -> Array:
        """The tool's poses at each row of ``qs`` (m × dof): m × 4 × 4,
        the GIL released."""
    def jacobian(self, q: ArrayLike) -> Array:
        """The geometric Jacobian at ``q``: 6 × dof, rows vx, vy, vz, wx,
        wy, wz of the tool frame's origin, in the base frame."""
    def inverse(
        self,
        target: ArrayLike,
        seed: ArrayLike,
        rest: Optional[ArrayLike] = None,
        tolerance: float = 1e-9,
        iterations: int = 200,
    ) -> Array:
        """Joint positions within the limits putting the tool at ``target``
        (4 × 4) to ``tolerance`` (m and rad), searched from ``seed``
        (damped least squares, pulled toward ``rest`` in the null space;
        default rest: each joint's mid-range, 0 if continuous). A local
        search: seed it near the answer (a path's previous sample). Not
        converging within ``iterations`` is a ``RuntimeError`` naming the
        smallest position and orientation errors reached; a wrong shape,
        length or a non-finite value is a ``ValueError``."""
    def inverse_path(
        self,
        targets: ArrayLike,
        seed: ArrayLike,
        rest: Optional[ArrayLike] = None,
        tolerance: float = 1e-9,
        iterations: int = 200,
        on_failure: Literal["raise", "nan"] = "raise",
    ) -> Array:
        """Each of ``targets`` (m × 4 × 4) solved as ``inverse`` does from
        the previous sample's solution (the first from ``seed``): m × dof,
        the GIL released. A sample that does not converge is a
        ``RuntimeError`` naming it, or with ``on_failure="nan"`` a row of
        NaN (the next sample then starts from the last solution)."""
    def __reduce__(self) -> Any: ...

Method = Literal["golden", "illinois", "secant", "fixed-gain", "weighted-gain"]
Variant = Literal["extended", "ordinary", "error-learned"]

class Rollouts(TypedDict):
    """A run's roll-outs as columns (``rollouts.csv``'s)."""

    rollout: npt.NDArray[np.int64]
    update: npt.NDArray[np.int64]
    mean: npt.NDArray[np.bool_]
    query: Array
    poured: Array
    spilled: Array
    error: Array
    reward: Array
    rejected: list[Optional[str]]

class GoldenRun(TypedDict):
    """One run of the golden experiment (``summary.json``'s ``runs``)."""

    volume: float
    method: Method
    seed: int
    precision: float
    rollouts_to_precision: Optional[int]
    worst_overpour: float
    rollouts: Rollouts

class PowerRun(TypedDict):
    """One run of the power experiment (a row of ``power_runs.csv``)."""

    variant: Variant
    seed: int
    kernels: int
    updates: int
    glass: Literal["normal", "small"]
    parameters: int
    rollouts_to: dict[float, Optional[int]]
    updates_to: dict[float, Optional[int]]
    regret: float
    final_error: float
    final_spilled: float
    final_reward: float
    rollouts: Rollouts

def golden_run(
    volume: float, method: Method = "golden", seed: Optional[int] = None, precision: float = 0.002
) -> GoldenRun:
    """One seeded run of the golden experiment, as ``primo experiment
    golden --volumes VOLUME --seed SEED`` runs it (seed 1 by default)."""

def power_run(
    seed: Optional[int] = None,
    variant: Variant = "extended",
    kernels: int = 30,
    updates: int = 100,
    glass: Literal["normal", "small"] = "small",
) -> PowerRun:
    """One seeded run of the power experiment, as ``primo experiment power
    --seed SEED --runs 1`` runs it for ``variant`` (seed 1 by default)."""

def check_out(out: Path, kind: Literal["golden", "power"], force: bool = False) -> None:
    """Refuses (ValueError) an ``out`` that holds an earlier result, unless
    ``force``, or that another primo is writing into."""

def write_golden(out: Path, runs: Sequence[Mapping[str, Any]], force: bool = False) -> None:
    """``primo experiment golden``'s files for runs of one precision and seed."""

def write_power(
    out: Path, runs: Sequence[Mapping[str, Any]], seconds: float = 0.0, force: bool = False
) -> None:
    """``primo experiment power``'s files for runs of one setting."""
