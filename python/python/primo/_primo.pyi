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
        overlap: float = 0.7,
        ridge: float = 1e-9,
        alpha: float = 25.0,
        scaling: Literal["per-dof", "none", "global"] = "per-dof",
    ) -> Dmp:
        """Fits a discrete DMP to one demonstration: least squares on the
        positions, so that its run reproduces ``y`` (no derivative of the
        recording is taken; any sampling fits).

        Args:
            t: the sample times, s: n values, strictly increasing, any
                spacing and any origin (Unix time is fine: they are counted
                from the first sample in float64 before they are rounded to
                the float32 the fit computes in).
            y: the positions, n × columns (or n for one column), any unit.
                Four columns ``<p>qw, <p>qx, <p>qy, <p>qz`` are one
                orientation, a quaternion DMP.
            names: the columns' names (default ``y0, y1, …``).
            kernels: kernels per DoF, 2 to 128.
            margin: kernel spacings the outer kernels lie beyond the
                movement's ends, 0 to (kernels − 2)/2; ``None`` tries 0 and
                1 and keeps the one that reproduces ``y`` better. DMPs
                generalized together need the same.
            overlap: the kernels' overlap ``h·Δc²`` (> 0; larger is
                narrower: neighbours cross at ``exp(−overlap/4)``).
            ridge: the ridge regularization, relative to the mean diagonal
                of the Gram matrix (>= 0).
            alpha: the spring gain α, 0.01 to 10000 (β = α/4).
            scaling: how the forcing term scales to a new start and goal:
                ``"per-dof"`` (each column by its own (g − y0)/(g_d − y0_d);
                a column that starts and ends together unscaled),
                ``"none"`` (the shape as demonstrated) or ``"global"`` (the
                position columns turned by the smallest rotation taking the
                demonstrated g − y0 onto the new one and stretched by the
                ratio of their lengths, Koutras & Doulgeri 2020).

        ``primo learn`` fits a task's demonstrations with ``margin=0,
        overlap=2.0, ridge=1e-6`` (``Generalizer.from_task`` builds that
        skill itself).

        Returns:
            Dmp: the fitted DMP, as ``primo dmp fit`` writes it.

        Raises:
            ValueError: an argument out of its range (named), times that do
                not increase, fewer than 3 samples, or weights beyond the
                DMP's bounds.
            TypeError: ``names`` not a sequence of strings.

        >>> import numpy as np, primo
        >>> t = 1.7e9 + np.linspace(0.0, 1.0, 101)  # stamped in Unix time
        >>> dmp = primo.Dmp.fit(t, np.sin(t - t[0]), names=["x"], kernels=20, overlap=2.0)
        >>> dmp.tau, dmp.names
        (1.0, ['x'])
        """
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
        """Reads the DMP file format (versions 1 to 4)."""
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
    """A discrete DMP executed one control step at a time."""

    def step(self, dt: float) -> Array:
        """Advances by ``dt`` s; the new position, per column."""
    @property
    def position(self) -> Array: ...
    @property
    def velocity(self) -> Array: ...
    @property
    def time(self) -> float: ...
    @property
    def phase(self) -> float: ...
    def set_goal(self, goal: ArrayLike) -> None:
        """A new goal from the next step on (no orientation columns)."""

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
    @staticmethod
    def from_task(path: Path) -> Generalizer:
        """The skill a task file builds, exactly as ``primo learn --task``
        builds it: the task's demonstrations read and checked (their
        columns and the task's limits), each fitted as ``primo learn``
        fits it (``margin=0, overlap=2.0, ridge=1e-6``, the task's
        ``kernels``, every example with the first one's amplitude scaling)
        and generalized by the task's ``generalization``.

        Args:
            path: the task file (TOML, the book's task file reference); its
                demonstrations are found beside it.

        Returns:
            Generalizer: one example per ``[[demo]]``, in the file's order,
            at its ``query``.

        Raises:
            OSError: the task file cannot be read.
            ValueError: the task file or a demonstration is refused or
                missing (the message names the file, the line and the key),
                or the task is the built-in pour (its cell builds its own
                skill).

        >>> import primo
        >>> g = primo.Generalizer.from_task("examples/throw/throw.toml")  # doctest: +SKIP
        >>> len(g), g.names, g.query_dim  # doctest: +SKIP
        (2, ['shoulder', 'elbow'], 1)
        """
    def generalize(self, q: Union[float, ArrayLike]) -> Dmp:
        """The DMP for query ``q``."""
    def params(self, q: Union[float, ArrayLike]) -> Array:
        """``G(q)``, the parameter vector (an orientation group's three goal
        values: its goal's rotation vector from the examples' mean goal)."""
    @property
    def examples(self) -> list[tuple[Array, Dmp]]:
        """The examples ``(query, dmp)``, in order: the queries as float64
        arrays (1 to 4 values), the DMPs as given (or, from a task file, as
        ``primo learn`` fits them).

        >>> import numpy as np, primo
        >>> t = np.linspace(0.0, 1.0, 101)
        >>> g = primo.Generalizer([(0.2, primo.Dmp.fit(t, 0.2 * t)), (1.0, primo.Dmp.fit(t, t))])
        >>> [float(q[0]) for q, _ in g.examples]
        [0.2, 1.0]
        """
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
    """PoWER with per-block exploration ``(len, variance, decay)`` and an
    importance sampler of the best ``sampler`` roll-outs."""

    def __init__(
        self,
        initial: ArrayLike,
        blocks: Sequence[tuple[int, float, float]],
        rollouts_per_update: int = 3,
        roll_out_mean: bool = True,
        sampler: int = 3,
        seed: int = 0,
        query_gain: float = 0.0,
    ) -> None: ...
    def ask(self) -> Array:
        """The parameters to roll out next (the same until told)."""
    def tell(self, reward: float, error: Optional[ArrayLike] = None) -> bool:
        """The asked roll-out's reward (finite, >= 0) and, with a query
        gain, its error; True after an update."""
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
