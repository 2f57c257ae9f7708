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
    """A fitted DMP with its column names, discrete or rhythmic.

    A discrete DMP moves from a start to a goal (four columns
    ``<p>qw, <p>qx, <p>qy, <p>qz`` are one orientation, a quaternion DMP); a
    rhythmic one repeats a period. Its JSON is the DMP file of
    ``primo dmp fit`` and ``primo dmp run``. Computed in float32 (the fit's
    normal equations in float64); arrays come out as float64. Make one with
    ``Dmp.fit``, ``Dmp.fit_rhythmic``, ``Dmp.load`` or ``Dmp.from_json``;
    it pickles, copies and compares (``==``) by value.

    >>> import numpy as np, primo
    >>> t = np.linspace(0.0, 1.0, 101)
    >>> dmp = primo.Dmp.fit(t, t * t * (3 - 2 * t), names=["x"], kernels=20)
    >>> times, x, v = dmp.run(dt=0.01, goal=[2.0], tau=2.0, velocities=True)
    >>> round(float(times[-1]), 6), round(float(x[-1, 0]), 2), x.shape
    (2.0, 2.0, (201, 1))
    >>> run = dmp.stepper()
    >>> bool((run.step(0.01) == dmp.run(dt=0.01)[1][1]).all())
    True
    >>> dmp.params.shape  # [weights, goal, tau]
    (22,)
    """

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
        final_velocity: Literal["rest", "demonstrated"] = "rest",
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
            final_velocity: the velocity at the goal: ``"rest"`` (the
                classic DMP) or ``"demonstrated"`` (the recording's speed at
                its end, for a hit or a throw: the goal moves at it until τ,
                Kober et al. 2010; ``run(goal_velocity=)`` changes it).

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
        """Fits a rhythmic DMP to one period of a recording.

        Args:
            t: sample times, s, shape (n,), strictly increasing, n >= 3.
            y: positions, shape (n, columns), or (n,) for one column (no
                orientation columns).
            names: the column names, one per column of ``y`` (default
                ``y0, y1, ...``).
            kernels: basis functions per DoF, 2 to 128.
            period: the period, s, counted from the first sample; None takes
                the whole recording as one period.

        Returns:
            Dmp: the rhythmic DMP (``rhythmic`` is True).

        Raises:
            ValueError: as ``fit``, or a period that is not positive or longer
                than the recording.
            TypeError: ``names`` a string, or holding something not a string.

        The fit runs with the GIL released.

        >>> import numpy as np, primo
        >>> t = np.linspace(0.0, 1.0, 201)
        >>> dmp = primo.Dmp.fit_rhythmic(t, np.sin(2 * np.pi * t), names=["x"])
        >>> dmp.rhythmic, dmp.kernels, round(dmp.period, 3)
        (True, 30, 1.0)
        """
    @staticmethod
    def from_json(text: str) -> Dmp:
        """The DMP whose file text is ``text`` (DMP file versions 1 to 5).

        Args:
            text: a DMP file's JSON, as ``to_json`` or ``primo dmp fit`` write it.

        Returns:
            Dmp: the DMP it describes.

        Raises:
            ValueError: not JSON, or not a DMP file (the message says where).

        >>> import numpy as np, primo
        >>> dmp = primo.Dmp.fit(np.linspace(0, 1, 11), np.linspace(0, 1, 11))
        >>> primo.Dmp.from_json(dmp.to_json()) == dmp
        True
        """
    @staticmethod
    def load(path: Path) -> Dmp:
        """Reads a DMP file written by ``primo dmp fit`` or ``Dmp.save``.

        Args:
            path: the file's path (str or path-like).

        Returns:
            Dmp: the DMP in the file.

        Raises:
            OSError: the file cannot be read.
            ValueError: not a DMP file (the message names the file and where).

        >>> import numpy as np, os, primo, tempfile
        >>> dmp = primo.Dmp.fit(np.linspace(0, 1, 11), np.linspace(0, 1, 11))
        >>> path = os.path.join(tempfile.mkdtemp(), "dmp.json")
        >>> dmp.save(path)
        >>> primo.Dmp.load(path) == dmp
        True
        """
    def to_json(self) -> str:
        """The DMP file's text (JSON), as ``primo dmp fit`` writes it.

        Returns:
            str: the JSON text (without a final newline).

        >>> import numpy as np, json, primo
        >>> dmp = primo.Dmp.fit(np.linspace(0, 1, 11), np.linspace(0, 1, 11))
        >>> json.loads(dmp.to_json())["names"]
        ['y0']
        """
    def save(self, path: Path) -> None:
        """Writes the DMP file to ``path``, atomically: a reader sees the old file
        or the new one, never half of it.

        Args:
            path: the file's path (str or path-like); an existing file is replaced.

        Raises:
            OSError: the file cannot be written (the old one is kept).

        >>> import numpy as np, os, primo, tempfile
        >>> path = os.path.join(tempfile.mkdtemp(), "dmp.json")
        >>> primo.Dmp.fit(np.linspace(0, 1, 11), np.linspace(0, 1, 11)).save(path)
        >>> os.path.exists(path)
        True
        """
    @property
    def names(self) -> list[str]:
        """The column names, in the order of ``y``'s columns."""
    @property
    def rhythmic(self) -> bool:
        """True for a rhythmic DMP, False for a discrete one."""
    @property
    def kernels(self) -> int:
        """The basis functions per DoF."""
    @property
    def dof(self) -> int:
        """The DMP's DoFs: one per column, an orientation (four columns) counting 3."""
    @property
    def orientations(self) -> list[list[str]]:
        """The orientation groups, each its four column names
        ``[<p>qw, <p>qx, <p>qy, <p>qz]`` (empty for a rhythmic DMP).
        """
    @property
    def tau(self) -> float:
        """The demonstrated duration, s (discrete; ValueError for a rhythmic DMP)."""
    @property
    def period(self) -> float:
        """The demonstrated period, s (rhythmic; ValueError for a discrete DMP)."""
    @property
    def start(self) -> Array:
        """The demonstrated start, per column (discrete; ValueError for a
        rhythmic DMP).
        """
    @property
    def goal(self) -> Array:
        """The goal, per column (discrete; ValueError for a rhythmic DMP)."""
    @property
    def params(self) -> Array:
        """The parameter vector θ = [weights row by row, goals, τ] of the DMP's
        DoFs (discrete): ``dof * kernels + dof + 1`` values, an orientation's
        goal as its 3 DoFs. Assigning it sets the DMP's weights, goal and
        duration (ValueError for a wrong length or a non-finite value, or for a
        rhythmic DMP).
        """
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
        *,
        goal_velocity: Optional[ArrayLike] = None,
        via: Optional[Sequence[tuple[float, str, float]]] = None,
        obstacles: Optional[ArrayLike] = None,
        obstacle_columns: Optional[Sequence[str]] = None,
        limits: Optional[Mapping[str, tuple[float, float]]] = None,
        limit_margin: Optional[float] = None,
        limit_gain: float = 50.0,
    ) -> tuple[Array, Array]:
        """Runs the DMP at a fixed step, from start to goal (discrete) or for a
        duration (rhythmic), with the GIL released.

        Args:
            dt: the step, s (positive).
            tau: the duration, s (discrete; default the demonstrated one).
            start: the start, per column (discrete; default the demonstrated one).
            goal: the goal, per column (discrete; default the demonstrated one).
                A changed goal does not move the start.
            velocities: also return the velocities (discrete, no orientation
                columns).
            duration: how long to run, s (rhythmic; default three periods).
            frequency: the frequency, Hz (rhythmic; default the demonstrated one).
            amplitude: the amplitude, per column (rhythmic; default 1 each:
                as demonstrated).
            anchor: the centre of the oscillation, per column (rhythmic; default
                the demonstrated one).
            goal_velocity: the velocity at the goal, per column, per second
                (discrete, no orientation columns): reached at the goal at τ.
            via: via-points, a list of ``(time, column, value)`` (discrete,
                up to 8): the column passes ``value`` at ``time`` s, strictly
                inside the movement; the weights change least to pass them.
            obstacles: spheres to steer round, shape (n, 4) rows of ``x, y,
                z, radius`` (discrete, n up to 16; Park et al.'s dynamic
                potential); the run goes on past τ until it reaches its goal,
                at most 3τ.
            obstacle_columns: the three position columns of ``x, y, z``
                (default ``["x", "y", "z"]``).
            limits: limits to keep away from, ``{column: (low, high)}``
                (discrete; ``-inf``, ``inf``: none that side): within
                ``limit_margin`` of one the run is pushed back, and goes on
                past τ until it reaches its goal, at most 3τ.
            limit_margin: how near a limit the push starts, in the column's
                units (needed with ``limits``; the goal must lie outside it).
            limit_gain: the push at half the margin, units/s².

        Returns:
            tuple: ``(times, positions)``, shapes (m,) and (m, columns), m the
            number of samples from time 0; with ``velocities``, a third array
            (m, columns) of velocities (not with goal_velocity, via or
            obstacles).

        Raises:
            ValueError: a setting of the other kind of DMP, a value out of range,
                a per-column array of the wrong length, more than a million samples.

        >>> import numpy as np, primo
        >>> t = np.linspace(0.0, 1.0, 101)
        >>> dmp = primo.Dmp.fit(t, t * t * (3 - 2 * t), names=["x"])
        >>> times, x = dmp.run(dt=0.01, goal=[0.5])
        >>> times.shape, round(float(x[-1, 0]), 2)
        ((101,), 0.5)
        >>> times, x = dmp.run(dt=0.01, via=[(0.5, "x", 0.8)])
        >>> round(float(x[50, 0]), 3)
        0.8
        """
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
    def through(self, via: Sequence[tuple[float, str, float]], dt: float = 0.001) -> Dmp:
        """This DMP bent through via-points (discrete): its weights changed
        least so that its run at steps of ``dt`` passes each point, as
        ``run(via=...)`` does, with the start, goal and duration its own.
        Its ``params`` are a movement's with the via-points built in: a
        parameter vector for a learner or ``primo.gym.BlackBox``.

        Args:
            via: via-points, a list of ``(time, column, value)`` (up to 8):
                the column passes ``value`` at ``time`` s, strictly inside the
                movement.
            dt: the step the run is made at, s (positive).

        Returns:
            Dmp: the bent DMP.

        Raises:
            ValueError: a rhythmic DMP, a time outside the movement, an unknown
                column, two values for one column at once, a point no weight
                can reach or that needs weights beyond their bound.

        >>> import numpy as np, primo
        >>> t = np.linspace(0.0, 1.0, 101)
        >>> dmp = primo.Dmp.fit(t, t * t * (3 - 2 * t), names=["x"])
        >>> bent = dmp.through([(0.5, "x", 0.8)], dt=0.01)
        >>> round(float(bent.run(dt=0.01)[1][50, 0]), 3), bent.goal.tolist() == dmp.goal.tolist()
        (0.8, True)
        """
    def stepper(
        self,
        tau: Optional[float] = None,
        start: Optional[ArrayLike] = None,
        goal: Optional[ArrayLike] = None,
    ) -> DmpRun:
        """A step-by-step execution of the DMP (discrete): a ``DmpRun`` at time 0.

        Args:
            tau: the duration, s (default the demonstrated one).
            start: the start, per column (default the demonstrated one).
            goal: the goal, per column (default the demonstrated one).

        Returns:
            DmpRun: the execution, at its start.

        Raises:
            ValueError: a rhythmic DMP, a value out of range, a per-column array
                of the wrong length.

        >>> import numpy as np, primo
        >>> t = np.linspace(0.0, 1.0, 101)
        >>> run = primo.Dmp.fit(t, t, names=["x"]).stepper(tau=2.0)
        >>> run.step(0.001).shape, round(run.time, 6)
        ((1,), 0.001)
        """
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
    True
    """

    def step(
        self,
        dt: float,
        position: Optional[ArrayLike] = None,
        velocity: Optional[ArrayLike] = None,
        coupling: Optional[ArrayLike] = None,
        measured: Optional[ArrayLike] = None,
        phase_stop: Optional[float] = None,
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

        Phase stopping (Ijspeert et al. 2013): with `phase_stop` (the gain
        `k` ≥ 0, per squared unit) and `measured`, the robot's position per
        column, the movement's clock advances by `dt/(1 + k‖measured −
        commanded‖²)` instead of `dt`, so the command waits while the robot
        lags it; `time` is the movement's clock.

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
        >>> _ = run.step(0.01, coupling=[2.0])
        >>> before = run.time
        >>> _ = run.step(0.01, measured=[0.0], phase_stop=100.0)  # the robot lags
        >>> bool(run.time - before < 0.01)
        True
        """
    @property
    def position(self) -> Array:
        """The current position, per column."""
    @property
    def velocity(self) -> Array:
        """The current velocity per second, per column (DMPs without
        orientation columns).
        """
    @property
    def time(self) -> float:
        """Seconds since the start."""
    @property
    def phase(self) -> float:
        """The phase `t/τ`, at most 1."""
    def set_goal(self, goal: ArrayLike) -> None:
        """A new goal from the next step on (DMPs without orientation columns).

        Args:
            goal: the new goal, per column.

        Raises:
            ValueError: a DMP with orientation columns, a wrong length or a
                non-finite value.

        >>> import numpy as np, primo
        >>> run = primo.Dmp.fit(np.linspace(0, 1, 11), np.linspace(0, 1, 11)).stepper()
        >>> run.set_goal([2.0])
        >>> while run.time < 3.0:
        ...     x = run.step(0.01)
        >>> round(float(x[0]), 2)
        2.0
        """
    def __reduce__(self) -> Any: ...
    def __copy__(self) -> DmpRun: ...
    def __deepcopy__(self, memo: Any) -> DmpRun: ...

class ProMp:
    """A probabilistic movement primitive (Paraschos et al. 2013): a Gaussian
    over the weights of normalized Gaussian kernels on the phase (each
    demonstration's time over its duration), fitted to several
    demonstrations; the trajectory's mean and variance at any phase,
    conditioned on positions (via-points, the goal) and blended with
    another. Pickles and copies.

    >>> import numpy as np, primo
    >>> t = np.linspace(0.0, 1.0, 101)
    >>> demos = [(t, h * t * t * (3 - 2 * t)) for h in (0.9, 1.0, 1.1)]
    >>> p = primo.ProMp.fit(demos, names=["x"], kernels=20)
    >>> round(float(p.mean([1.0])[0, 0]), 3)
    1.0
    >>> q = p.condition(1.0, {"x": 1.05})
    >>> round(float(q.mean([1.0])[0, 0]), 3), round(float(q.mean([0.5])[0, 0]), 3)
    (1.05, 0.525)
    """

    @staticmethod
    def fit(
        demos: Sequence[tuple[ArrayLike, ArrayLike]],
        names: Optional[Sequence[str]] = None,
        kernels: int = 20,
        ridge: float = 1e-6,
    ) -> ProMp:
        """Fits a ProMP to several demonstrations of the same columns and the
        same number of samples: each one's kernel weights by least squares,
        their mean and covariance (with a ridge), and the mean squared
        residual as the observation noise.

        Args:
            demos: a sequence of ``(t, y)``: times, s (n, strictly
                increasing; each demonstration's own duration is its phase
                0 to 1) and positions (n, columns), or (n,) for one column.
            names: the columns' names (default ``y0, y1, …``).
            kernels: kernels per column, 2 to 40.
            ridge: the covariance's ridge, relative to its mean variance
                (>= 0): what keeps it invertible with few demonstrations.

        Returns:
            ProMp: the fitted ProMP.

        Raises:
            ValueError: fewer than two demonstrations, ones of different
                lengths or columns, more than 8 columns, an orientation's
                four columns, times that do not increase, a value that is
                not finite, kernels or ridge out of range (as ``primo promp
                fit``).

        >>> import numpy as np, primo
        >>> t = np.linspace(0.0, 1.0, 51)
        >>> p = primo.ProMp.fit([(t, t), (t, 2 * t)], kernels=10)
        >>> p.names, p.kernels, round(p.duration, 6)
        (['y0'], 10, 1.0)
        """
    @property
    def names(self) -> list[str]:
        """The columns' names."""
    @property
    def kernels(self) -> int:
        """Kernels per column."""
    @property
    def duration(self) -> float:
        """The demonstrations' mean duration, s (phase 1)."""
    def mean(self, z: ArrayLike) -> Array:
        """The mean position at each phase.

        Args:
            z: phases in [0, 1], shape (m,) (or one number).

        Returns:
            numpy.ndarray: shape (m, columns).

        Raises:
            ValueError: a phase outside [0, 1] or not finite.

        >>> import numpy as np, primo
        >>> t = np.linspace(0.0, 1.0, 51)
        >>> p = primo.ProMp.fit([(t, t), (t, 3 * t)], kernels=10)
        >>> p.mean([0.0, 1.0]).round(2).tolist()
        [[0.0], [2.0]]
        """
    def velocity(self, z: ArrayLike) -> Array:
        """The mean velocity at each phase, per second.

        Args:
            z: phases in [0, 1], shape (m,) (or one number).

        Returns:
            numpy.ndarray: shape (m, columns).

        Raises:
            ValueError: a phase outside [0, 1] or not finite.

        >>> import numpy as np, primo
        >>> t = np.linspace(0.0, 2.0, 51)
        >>> p = primo.ProMp.fit([(t, t), (t, 3 * t)], kernels=10)
        >>> p.velocity([0.5]).round(1).tolist()  # the mean 2 t: 2 per second
        [[2.0]]
        """
    @property
    def params(self) -> Array:
        """The mean's kernel weights, column by column (``kernels`` each): the
        parameters a learner changes (``primo.gym.BlackBox``'s ``theta``).
        Assigning them moves the mean and keeps the spread (ValueError for
        a wrong length or a value that is not finite).

        >>> import numpy as np, primo
        >>> t = np.linspace(0.0, 1.0, 51)
        >>> p = primo.ProMp.fit([(t, t), (t, 3 * t)], kernels=10)
        >>> p.params = p.params + 0.5  # the normalized kernels: every position + 0.5
        >>> p.mean([0.0, 1.0]).round(2).tolist()
        [[0.5], [2.5]]
        """
    @params.setter
    def params(self, weights: ArrayLike) -> None: ...
    def variance(self, z: ArrayLike) -> Array:
        """The variance of the position at each phase: the weights' spread and
        the observation noise.

        Args:
            z: phases in [0, 1], shape (m,) (or one number).

        Returns:
            numpy.ndarray: shape (m, columns).

        Raises:
            ValueError: a phase outside [0, 1] or not finite.

        >>> import numpy as np, primo
        >>> t = np.linspace(0.0, 1.0, 51)
        >>> p = primo.ProMp.fit([(t, t), (t, 3 * t)], kernels=10)
        >>> round(float(p.variance(1.0)[0, 0]), 2)  # the ends 1 and 3
        2.0
        """
    def condition(self, z: float, positions: Mapping[str, float], variance: float = 0.0) -> ProMp:
        """This ProMP conditioned on positions at a phase: the columns pass
        them (a via-point, the goal), the rest moves with its correlations.

        Args:
            z: the phase, in [0, 1].
            positions: ``{column: position}``.
            variance: how sure the positions are (>= 0; 0 is exact).

        Returns:
            ProMp: the conditioned ProMP (this one is unchanged).

        Raises:
            ValueError: an unknown column, a phase outside [0, 1], a
                negative variance, a position that is not finite, or one the
                distribution cannot take (no spread there to move by).

        >>> import numpy as np, primo
        >>> t = np.linspace(0.0, 1.0, 51)
        >>> p = primo.ProMp.fit([(t, t), (t, 3 * t)], kernels=10)
        >>> round(float(p.condition(0.5, {"y0": 1.25}).mean(1.0)[0, 0]), 2)
        2.5
        """
    def blend(self, other: ProMp, alpha: ArrayLike, z: ArrayLike) -> tuple[Array, Array]:
        """Blends this ProMP (activation ``alpha``) with ``other`` (``1 −
        alpha``) at phases: per column, the product of the two positions'
        distributions with each precision weighted by its activation.

        Args:
            other: a ProMP of the same columns.
            alpha: this one's activation, in [0, 1]: one number, or one per
                phase.
            z: phases in [0, 1], shape (m,).

        Returns:
            tuple: ``(mean, variance)``, each (m, columns).

        Raises:
            ValueError: other columns, an activation or phase out of range.

        >>> import numpy as np, primo
        >>> t = np.linspace(0.0, 1.0, 51)
        >>> a = primo.ProMp.fit([(t, t), (t, 1.1 * t)], kernels=10)
        >>> b = primo.ProMp.fit([(t, -t), (t, -1.1 * t)], kernels=10)
        >>> mean, var = a.blend(b, [1.0, 0.5, 0.0], [1.0, 1.0, 1.0])
        >>> mean.round(2).ravel().tolist()
        [1.05, 0.0, -1.05]
        """
    def to_json(self) -> str:
        """The ProMP file's JSON, as ``primo promp fit`` writes it.

        >>> import numpy as np, json, primo
        >>> t = np.linspace(0.0, 1.0, 51)
        >>> p = primo.ProMp.fit([(t, t), (t, 2 * t)], names=["x"], kernels=10)
        >>> json.loads(p.to_json())["names"]
        ['x']
        """
    @staticmethod
    def from_json(text: str) -> ProMp:
        """The ProMP of a ProMP file's JSON (``primo promp fit``'s, or
        ``to_json``'s): ``primo promp run`` runs the same.

        Args:
            text: the JSON.

        Raises:
            ValueError: not a ProMP file, or one whose numbers are not a
                ProMP's.

        >>> import numpy as np, primo
        >>> t = np.linspace(0.0, 1.0, 51)
        >>> p = primo.ProMp.fit([(t, t), (t, 2 * t)], kernels=10)
        >>> primo.ProMp.from_json(p.to_json()).mean([1.0]).tolist() == p.mean([1.0]).tolist()
        True
        """

class Generalizer:
    """``G(q)``: a DMP for any task query, generalized from examples.

    Examples are ``(query, dmp)`` pairs (a query is a float or 1 to 4 values);
    a regression on the DMPs' parameter vectors gives the DMP for a new query,
    the start generalized with the same coefficients. With two examples both
    methods give the straight line through them; ``"promp"`` conditions a
    ProMP over the parameters (Paraschos et al. 2013: the examples'
    parameters and queries as one Gaussian) on the query, a global linear
    model. Every example is a discrete
    DMP with the first one's columns, in order. Orientation groups
    (``<p>qw, <p>qx, <p>qy, <p>qz``) are generalized as ``primo learn`` does:
    goals and starts as rotation vectors at the mean of the examples' goals,
    weights as they are, so every ``generalize(q)`` is an orientation DMP
    whose quaternions are unit-norm, equal to each example at its query where
    the regression interpolates. It pickles with its examples.

    Args:
        examples: a sequence of ``(query, dmp)``: query a float or 1 to 4
            values, the same count in every example; dmp a discrete ``Dmp``.
        method: ``"lwr"`` (locally weighted regression), ``"gpr"``
            (Gaussian process regression) or ``"promp"`` (a ProMP
            conditioned on the query).
        bandwidth: LWR's kernel bandwidth, or GPR's length scale, in query
            units (positive; default from the examples' spacing).
        noise: GPR's noise variance (>= 0; 0 interpolates the examples).
        ridge: the ProMP's ridge on the query covariance, relative to its
            mean variance (>= 0; default 1e-6).

    Raises:
        ValueError: no example, a rhythmic DMP, columns that differ from the
            first example's, queries of different lengths, a setting out of
            range.

    >>> import numpy as np, primo
    >>> t = np.linspace(0.0, 1.0, 101)
    >>> low = primo.Dmp.fit(t, 0.2 * t, names=["x"])
    >>> high = primo.Dmp.fit(t, 1.0 * t, names=["x"])
    >>> g = primo.Generalizer([(0.2, low), (1.0, high)])
    >>> round(float(g.generalize(0.6).goal[0]), 4)
    0.6
    """

    def __init__(
        self,
        examples: Sequence[tuple[Union[float, ArrayLike], Dmp]],
        method: Literal["lwr", "gpr", "promp"] = "lwr",
        bandwidth: Optional[float] = None,
        noise: float = 0.0,
        ridge: Optional[float] = None,
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
        """The DMP for query ``q``.

        Args:
            q: the query: a float, or ``query_dim`` values.

        Returns:
            Dmp: the generalized discrete DMP, with the examples' columns.

        Raises:
            ValueError: a query of the wrong length or not finite.

        >>> import numpy as np, primo
        >>> t = np.linspace(0.0, 1.0, 101)
        >>> g = primo.Generalizer([(q, primo.Dmp.fit(t, q * t)) for q in (0.5, 1.0)])
        >>> round(float(g.generalize(0.75).goal[0]), 4)
        0.75
        """
    def params(self, q: Union[float, ArrayLike]) -> Array:
        """``G(q)``, the generalized parameter vector, laid out as ``Dmp.params``
        (an orientation group's three goal values: its goal's rotation vector
        from the examples' mean goal).

        Args:
            q: the query: a float, or ``query_dim`` values.

        Returns:
            numpy.ndarray: the parameter vector θ.

        Raises:
            ValueError: a query of the wrong length or not finite.

        >>> import numpy as np, primo
        >>> t = np.linspace(0.0, 1.0, 101)
        >>> g = primo.Generalizer([(q, primo.Dmp.fit(t, q * t)) for q in (0.5, 1.0)])
        >>> g.params(0.5).shape == g.generalize(0.5).params.shape
        True
        """
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
    def query_dim(self) -> int:
        """The number of values in a query (1 to 4)."""
    @property
    def names(self) -> list[str]:
        """The examples' column names."""
    def __len__(self) -> int: ...

class _ErrorLearner:
    def tell_infeasible(self) -> Status:
        """Tells that the asked query could not be rolled out or measured (it was
        rejected, or the trial failed): it bounds the search on its side, and
        counts against the budget. At the first query, ``desired``, the search
        ends as ``"infeasible"``.

        Returns:
            str: the status after it.

        Raises:
            ValueError: told after the search finished.

        >>> import primo
        >>> learner = primo.GoldenSection(0.0, 2.0, desired=0.5)
        >>> _ = learner.ask()
        >>> learner.tell_infeasible()
        'infeasible'
        """
    @property
    def status(self) -> Status:
        """The search's status: ``"running"``, ``"converged"`` (|error| <
        ``precision``), ``"budget_exhausted"`` (``max_rollouts`` told),
        ``"bracket_collapsed"`` (the bracket narrower than the query's float32
        resolution) or ``"infeasible"``.
        """
    @property
    def done(self) -> bool:
        """True once the search has finished (``status`` is not ``"running"``)."""
    @property
    def rollouts(self) -> int:
        """The roll-outs told so far, feasible or not."""

class _ScalarSearch(_ErrorLearner):
    def __init__(
        self, low: float, high: float, desired: float, precision: float = 0.002, max_rollouts: int = 30
    ) -> None: ...
    def ask(self) -> Optional[float]:
        """The query to roll out next, or None once the search has finished.

        Returns:
            float or None: the query, within ``[low, high]``; asking again
            before telling gives the same query.

        >>> import primo
        >>> primo.GoldenSection(0.0, 2.0, desired=0.5).ask()
        0.5
        """
    def tell(self, error: float) -> Status:
        """Tells the error of the asked query and moves the search on.

        Args:
            error: the asked query's error, finite; > 0 means the query must
                grow, < 0 that it must shrink.

        Returns:
            str: the status after it (``"running"``, ``"converged"``,
            ``"budget_exhausted"``, ``"bracket_collapsed"``, ``"infeasible"``).

        Raises:
            ValueError: a non-finite error, or told after the search finished.

        >>> import primo
        >>> learner = primo.GoldenSection(0.0, 2.0, desired=0.5)
        >>> learner.tell(0.3 - learner.ask())
        'running'
        """
    @property
    def best(self) -> Optional[tuple[float, float]]:
        """``(query, error)`` of the smallest |error| so far, or None before the
        first error.
        """
    @property
    def bracket(self) -> tuple[float, float]:
        """``(low, high)``: the interval that still holds the answer."""

class GoldenSection(_ScalarSearch):
    """The paper's error learning: golden-section search on a scalar query
    within ``[low, high]``, from ``desired``, until |error| < ``precision``.
    ``tell(error)`` takes the error of the asked query (> 0: the query must
    grow); only its sign is used.

    Args:
        low: the smallest query the search may ask.
        high: the largest query the search may ask (> low).
        desired: the first query, strictly between ``low`` and ``high``.
        precision: the search has converged when |error| < precision.
        max_rollouts: the budget of roll-outs (>= 1).

    Raises:
        ValueError: a non-finite setting, not ``low < desired < high``, a
            precision or budget that is not positive.

    >>> import primo
    >>> learner = primo.GoldenSection(0.0, 2.0, desired=0.5, precision=1e-3)
    >>> while (q := learner.ask()) is not None:
    ...     _ = learner.tell(0.5 - q * q)
    >>> learner.status, round(learner.best[0], 3)
    ('converged', 0.707)
    """

class Illinois(_ScalarSearch):
    """Bracketed error learning that also uses the error's magnitude (secant
    steps, then Illinois regula falsi); golden section's settings and interface.

    Args:
        low: the smallest query the search may ask.
        high: the largest query the search may ask (> low).
        desired: the first query, strictly between ``low`` and ``high``.
        precision: the search has converged when |error| < precision.
        max_rollouts: the budget of roll-outs (>= 1).

    Raises:
        ValueError: a non-finite setting, not ``low < desired < high``, a
            precision or budget that is not positive.

    >>> import primo
    >>> learner = primo.Illinois(0.0, 2.0, desired=0.5, precision=1e-3)
    >>> while (q := learner.ask()) is not None:
    ...     _ = learner.tell(0.5 - q * q)
    >>> learner.status, learner.rollouts <= 6
    ('converged', True)
    """

class Secant(_ErrorLearner):
    """The paper's eq. 10, ``q ← q + K ε``, on a query of 1 to 4 values in the
    box ``[low, high]``; the gain ``K`` starts at ``gain · I`` and is learned by
    Broyden updates (``rule="broyden"``), or stays fixed (``"fixed"``: eq. 10;
    ``"weighted"``: eq. 11, steps weighted by ``exp(−εᵀε)``). ``tell`` takes
    ``ε = desired − measured``.

    Args:
        low: the smallest query the search may ask, 1 to 4 values.
        high: the largest query, as many values, each > low's.
        desired: the first query, within the box.
        precision: the search has converged when every |error_i| < precision.
        max_rollouts: the budget of roll-outs (>= 1).
        gain: the initial gain's diagonal, ``K = gain · I`` (non-zero).
        rule: ``"broyden"``, ``"fixed"`` or ``"weighted"``.

    Raises:
        ValueError: vectors of different lengths or more than 4 values, a
            non-finite setting, an empty box, ``desired`` outside it, an
            unknown rule.

    >>> import numpy as np, primo
    >>> a = np.array([[2.5, 0.5], [-0.4, 0.7]])
    >>> learner = primo.Secant([-2, -2], [2, 2], desired=[0.5, 0.3], precision=1e-4)
    >>> while (q := learner.ask()) is not None:
    ...     _ = learner.tell(np.array([0.5, 0.3]) - a @ q)
    >>> learner.status, learner.rollouts <= 6
    ('converged', True)
    """

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
    def ask(self) -> Optional[Array]:
        """The query to roll out next, or None once the search has finished.

        Returns:
            numpy.ndarray or None: the query, ``dim`` values within
            ``[low, high]``; asking again before telling gives the same query.

        >>> import primo
        >>> primo.Secant([-1, -1], [1, 1], desired=[0.5, 0.0]).ask()
        array([0.5, 0. ])
        """
    def tell(self, error: ArrayLike) -> Status:
        """Tells the error vector of the asked query and moves the search on.

        Args:
            error: ``desired - measured`` of the asked query, ``dim`` finite
                values.

        Returns:
            str: the status after it (``"running"``, ``"converged"``,
            ``"budget_exhausted"``, ``"stalled"``, ``"infeasible"``).

        Raises:
            ValueError: a wrong length, a non-finite value, or told after the
                search finished.

        >>> import primo
        >>> learner = primo.Secant([-1], [1], desired=[0.5], precision=1e-3)
        >>> learner.tell([0.5 - 0.5 * float(learner.ask()[0])])
        'running'
        """
    @property
    def dim(self) -> int:
        """The number of values in a query (1 to 4)."""
    @property
    def best(self) -> Optional[tuple[Array, Array]]:
        """``(query, error)`` of the smallest max |error_i| so far (ties broken by
        the sum of squares), or None before the first error.
        """
    @property
    def gain(self) -> Array:
        """The present gain ``K`` (dim × dim): ``q ← q + K ε``."""

class Power:
    """PoWER (Kober & Peters) as in the paper, with ``ask()`` and ``tell()``.

    Exploration is Gaussian per contiguous block of parameters, each
    ``(len, variance, decay)`` (the variance multiplied by ``decay`` at every
    update); ``rollouts_per_update`` explorations make an update, the mean
    rolled out once per update when ``roll_out_mean``; an importance sampler
    keeps the best ``sampler`` roll-outs. Deterministic per ``seed``; it
    pickles with what it was told. At most 2066 parameters (a 16-DoF,
    128-kernel DMP and its query).

    The query: ``query`` = n says the first n parameters are a query (whole
    blocks: n ends where a block ends), as in primo's extended vector
    ``[q̂, Δθ]``. With ``query_gain`` K ≠ 0 it is learned from the error as
    well: ``tell(reward, error)`` with n error values keeps each roll-out's
    query as ``q + K·error`` (the paper's eq. 10 inside PoWER).
    ``Power.defaults`` builds primo's exploration for a skill.

    Args:
        initial: the initial parameters (the mean), finite.
        blocks: ``(len, variance, decay)`` per block, covering ``initial``
            in order; variance >= 0, decay in (0, 1].
        rollouts_per_update: explorations per update (>= 1).
        roll_out_mean: roll out the mean once per update as well.
        sampler: roll-outs the importance sampler keeps (1 to 10; default
            the paper's 3, and 2 with a query gain, as ``primo pour
            --method power-el``).
        seed: the exploration's random seed (an integer in 0..2**64).
        query_gain: K, the gain of the error on the query (0: the query is
            explored like the rest).
        query: the query's length n (0: none).

    Raises:
        ValueError: blocks that do not cover ``initial``, a ``query`` that
            does not end on a block, a query gain without a query, a setting
            out of range, too many parameters.

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
    False
    """

    def __init__(
        self,
        initial: ArrayLike,
        blocks: Sequence[tuple[int, float, float]],
        rollouts_per_update: int = 3,
        roll_out_mean: bool = True,
        sampler: Optional[int] = None,
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
        a sampler of 3 (2 with a query gain). `primo pour --method power-el`
        is `s1=0.0, query_gain=1.0` (its `--gain`).

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
        (True, 0.5)
        """
    def ask(self) -> Array:
        """The parameters to roll out next; the same until told.

        Returns:
            numpy.ndarray: the parameters (the mean, or an exploration of it).

        >>> import primo
        >>> power = primo.Power([1.0, 2.0], blocks=[(2, 0.01, 1.0)])
        >>> power.ask()  # the mean first
        array([1., 2.])
        """
    def tell(self, reward: float, error: Optional[ArrayLike] = None) -> bool:
        """Tells the asked roll-out's reward (and error, with a query).

        Args:
            reward: the roll-out's reward, finite and >= 0 (larger is better).
            error: the roll-out's error over the query, ``query`` values
                (> 0 asks for a larger query): needed with a query gain,
                refused without a query; else None.

        Returns:
            bool: True when this roll-out completed an update.

        Raises:
            ValueError: a negative or non-finite reward, an error of another
                length than the query, or a missing one with a gain.

        >>> import primo
        >>> power = primo.Power([1.0], blocks=[(1, 0.01, 1.0)], rollouts_per_update=1)
        >>> _ = power.ask(); power.tell(0.5)
        False
        """
    @property
    def query(self) -> int:
        """The query's length: the first `query` parameters (0: none)."""
    @property
    def mean(self) -> Array:
        """The present mean of the parameters."""
    @property
    def updates(self) -> int:
        """The updates made so far."""
    @property
    def rollouts(self) -> int:
        """The roll-outs told so far."""
    @property
    def variances(self) -> Array:
        """The present exploration variance, per parameter."""
    @property
    def next_is_mean(self) -> bool:
        """True when the next ``ask()`` gives the mean (rolled out once per update)."""
    @property
    def best(self) -> Optional[tuple[Array, float]]:
        """``(parameters, reward)`` of the best roll-out so far, or None before the
        first.
        """
    @property
    def sampler(self) -> list[tuple[Array, float]]:
        """The importance sampler, best first: ``(parameters, reward)`` pairs."""

class Cell:
    """The simulated pouring cell as an objective, as ``primo rollout`` uses it.

    A vector ``[weights (dof × kernels, row by row), goals, τ, q̂]`` is
    executed as ``G(q̂) + θ − G(bottle)``: the skill generalized from the
    demonstrations to the query ``q̂``, plus the offset ``θ`` from the
    movement generalized to the bottle. The robot pours from the bottle into
    the glass; the scale measures. ``start()`` gives the generalized start
    and PoWER's exploration std. ``rollout_many`` runs rows on every core with
    the GIL released. It pickles with its settings.

    Args:
        glass: ``"small"`` or ``"normal"``, the glass poured into.
        space: ``"joint"`` (the arm's 7 joints) or ``"cartesian"`` (the
            bottle's mouth and orientation).
        bottle: the liquid in the bottle, l.
        target: the volume to pour, l.
        kernels: basis functions per DoF, 2 to 128.
        seed: the scale's noise seed of ``rollout`` by default.
        demos: ``(path, volume)`` pairs: demonstration CSVs and the volume
            each was recorded for (default: the built-in demonstrations).

    Raises:
        ValueError: an unknown glass or space, a volume or setting out of
            range, a demonstration that does not parse (naming its file and
            line).
        OSError: a demonstration file that cannot be read.

    >>> import primo
    >>> cell = primo.Cell(glass="small", kernels=10, bottle=0.5, target=0.2)
    >>> start = cell.start()
    >>> len(start["start"]) == len(cell) == 7 * 10 + 7 + 1 + 1
    True
    >>> result = cell.rollout(start["start"])
    >>> sorted(result), result["safe"]
    (['error', 'poured', 'rejected', 'reward', 'safe', 'spilled'], True)
    """

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
    def size(self) -> int:
        """The length of a vector the cell takes: ``dof * kernels + dof + 2``."""
    def __len__(self) -> int: ...
    @property
    def glass(self) -> str:
        """The glass: ``"small"`` or ``"normal"``."""
    @property
    def space(self) -> str:
        """The space: ``"joint"`` or ``"cartesian"``."""
    @property
    def bottle(self) -> float:
        """The liquid in the bottle, l."""
    @property
    def target(self) -> float:
        """The volume to pour, l."""
    @property
    def kernels(self) -> int:
        """The basis functions per DoF."""
    @property
    def glass_holds(self) -> float:
        """What the glass holds to its rim, litres: `primo pour`'s
        `glass_holds` in summary.json. Error learning searches only queries
        that let no more than this leave the bottle: from
        `max(0.1, bottle + target − glass_holds)` (in float32) to 1.5 l.

        >>> import primo
        >>> round(primo.Cell(glass="small", kernels=10).glass_holds, 3)
        0.423
        """
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
        True
        """
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
        (0.8, 0.2, True)
        """
    @property
    def seed(self) -> int:
        """The scale's noise seed of ``rollout`` by default."""
    @property
    def names(self) -> list[str]:
        """The commanded columns: ``a1..a7``, or in Cartesian space the mouth and
        the bottle's orientation, ``x, y, z, qw, qx, qy, qz``.
        """
    def start(self) -> dict[str, Any]:
        """What ``primo rollout --print-start`` prints, and the cell it is for.

        Returns:
            dict: ``layout`` (the vector's blocks), ``space``, ``glass``,
            ``bottle``, ``target``, ``dof``, ``kernels``, ``start`` (the vector
            of the movement generalized to the bottle) and ``std`` (PoWER's
            exploration std per entry).

        Raises:
            ValueError: the skill cannot be generalized to the bottle.

        >>> import primo
        >>> start = primo.Cell(kernels=10).start()
        >>> start["dof"], start["kernels"], len(start["std"]) == len(start["start"])
        (7, 10, True)
        """
    def rollout(
        self, theta: ArrayLike, seed: Optional[int] = None, series: bool = False
    ) -> dict[str, Any]:
        """One roll-out of ``theta`` on the cell.

        Args:
            theta: the vector, ``size`` values (see the class).
            seed: the scale's noise seed (an integer below 2**64; default the
                cell's).
            series: also return the roll-out's time series.

        Returns:
            dict: ``poured`` and ``spilled`` (l), ``error`` (target − poured,
            l), ``reward``, ``safe`` (bool) and ``rejected`` (None, or why the
            safety gate refused the movement before it ran); with ``series``,
            ``series``: a dict of arrays (time, the commanded columns, the
            measured volume).

        Raises:
            ValueError: a wrong shape or length, a non-finite value, a bad seed.

        >>> import primo
        >>> cell = primo.Cell(kernels=10)
        >>> result = cell.rollout(cell.start()["start"], seed=7)
        >>> result["rejected"] is None, result["poured"] > 0
        (True, True)
        """
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
        True
        """
    def rollout_many(
        self, thetas: ArrayLike, seeds: Optional[Sequence[int]] = None
    ) -> list[dict[str, Any]]:
        """Roll-outs of every row of ``thetas`` on all cores, the GIL released.

        Args:
            thetas: the vectors, one per row: shape (m, ``size``).
            seeds: one noise seed per row (default: the cell's seed + i, as
                ``primo rollout --serve`` numbers its lines).

        Returns:
            list: one dict per row, as ``rollout`` returns (without series).

        Raises:
            ValueError: a wrong shape, a row that is not a vector of the cell,
                a seed count that does not match the rows.

        >>> import numpy as np, primo
        >>> cell = primo.Cell(kernels=10)
        >>> rows = np.tile(cell.start()["start"], (3, 1))
        >>> [r["safe"] for r in cell.rollout_many(rows)]
        [True, True, True]
        """

class Robot:
    """A serial arm from its base link to a tip (a link, or a tool frame in
    it), with its joints' limits: forward kinematics, the geometric
    Jacobian and inverse kinematics, in float64 (metres, radians; poses are
    4 × 4 homogeneous matrices in the base frame). Read from a URDF
    (``Robot.from_urdf``; xacro files and mimic joints in the chain are
    refused) or the built-in KUKA LWR 4 (``Robot.lwr4()``, joints
    ``a1``…``a7``). Bad input (a shape, a length, NaN) is a ``ValueError``,
    an unreadable file an ``OSError``, an inverse kinematics that does not
    converge a ``RuntimeError`` naming the errors reached. Pickles as its
    URDF text and settings.

    >>> import numpy as np, primo
    >>> robot = primo.Robot.lwr4()
    >>> robot.dof, robot.joint_names[:2], robot.tip
    (7, ['a1', 'a2'], 'flange')
    >>> q = np.array([0.3, 0.6, -0.2, -1.2, 0.4, 0.7, -0.5])
    >>> pose = robot.forward(q)
    >>> pose.shape, robot.jacobian(q).shape
    ((4, 4), (6, 7))
    >>> solved = robot.inverse(pose, seed=q + 0.05)
    >>> bool(np.abs(robot.forward(solved) - pose).max() < 1e-9)
    True
    >>> import pickle
    >>> pickle.loads(pickle.dumps(robot)) == robot
    True
    """

    @staticmethod
    def from_urdf(
        path: Path,
        base: Optional[str] = None,
        tip: Optional[str] = None,
        tool: Optional[ArrayLike] = None,
        limits: Optional[Mapping[str, tuple[float, float, float]]] = None,
    ) -> Robot:
        """The chain of the URDF at ``path``, from ``base`` to ``tip``.

        Args:
            path: the URDF file (str or path-like; plain URDF, not xacro).
            base: the chain's base link (default: the URDF's root link).
            tip: the chain's last link (default: the one leaf below the base;
                name it when there are several).
            tool: a 4 × 4 homogeneous transform from the tip link to the tool
                frame (default: the identity).
            limits: joint name → ``(lower, upper, velocity)`` (rad or m, rad/s
                or m/s), for joints the URDF gives none or to narrow them.

        Returns:
            Robot: the chain with its joints' limits.

        Raises:
            OSError: the file cannot be read.
            ValueError: a xacro file, a mimic, floating or planar joint in the
                chain, a joint without limits, a malformed URDF (naming its line
                and column), a bad tool or limit.

        >>> import os, primo, tempfile
        >>> urdf = '''<robot name="arm"><link name="base"/><link name="tip"/>
        ... <joint name="j1" type="revolute"><parent link="base"/><child link="tip"/>
        ... <origin xyz="0 0 0.5"/><axis xyz="0 0 1"/>
        ... <limit lower="-1" upper="1" velocity="2" effort="10"/></joint></robot>'''
        >>> path = os.path.join(tempfile.mkdtemp(), "arm.urdf")
        >>> with open(path, "w") as f:
        ...     _ = f.write(urdf)
        >>> robot = primo.Robot.from_urdf(path)
        >>> robot.name, robot.joint_names, robot.tip
        ('arm', ['j1'], 'tip')
        """
    @staticmethod
    def from_urdf_text(
        text: str,
        base: Optional[str] = None,
        tip: Optional[str] = None,
        tool: Optional[ArrayLike] = None,
        limits: Optional[Mapping[str, tuple[float, float, float]]] = None,
        file: str = "<string>",
    ) -> Robot:
        """``from_urdf`` of a URDF's text.

        Args:
            text: the URDF's XML text.
            base: the chain's base link (default: the URDF's root link).
            tip: the chain's last link (default: the one leaf below the base).
            tool: a 4 × 4 transform from the tip link to the tool frame.
            limits: joint name → ``(lower, upper, velocity)``.
            file: the name errors give the text.

        Returns:
            Robot: the chain with its joints' limits.

        Raises:
            ValueError: as ``from_urdf``, the place named in ``file``.

        >>> import primo
        >>> primo.Robot.from_urdf_text("<robot>", file="arm.urdf")
        Traceback (most recent call last):
        ...
        ValueError: arm.urdf:1:8: ...
        """
    @staticmethod
    def lwr4() -> Robot:
        """The built-in KUKA LWR 4 (its DH table, the flange as tip, joints
        ``a1`` to ``a7``).

        Returns:
            Robot: the arm.

        >>> import primo
        >>> primo.Robot.lwr4().dof
        7
        """
    @property
    def name(self) -> str:
        """The URDF's robot name."""
    @property
    def base(self) -> str:
        """The chain's base link."""
    @property
    def tip(self) -> str:
        """The chain's tip link."""
    @property
    def joint_names(self) -> list[str]:
        """The moving joints, base to tip: the order of every ``q``."""
    @property
    def dof(self) -> int:
        """The number of moving joints."""
    @property
    def lower(self) -> Array:
        """The lowest positions, rad or m (−inf for a continuous joint)."""
    @property
    def upper(self) -> Array:
        """The highest positions, rad or m (+inf for a continuous joint)."""
    @property
    def velocity(self) -> Array:
        """The fastest speeds, rad/s or m/s."""
    def forward(self, q: ArrayLike) -> Array:
        """The tool's pose at ``q``.

        Args:
            q: the joint positions, ``dof`` values, rad or m.

        Returns:
            numpy.ndarray: the pose, a 4 × 4 homogeneous matrix in the base frame.

        Raises:
            ValueError: a wrong length or a value that is not finite.

        >>> import numpy as np, primo
        >>> primo.Robot.lwr4().forward(np.zeros(7))[:3, 3].round(3)
        array([0.   , 0.   , 1.178])
        """
    def forward_many(self, qs: ArrayLike) -> Array:
        """The tool's poses at each row of ``qs``, with the GIL released.

        Args:
            qs: joint positions, shape (m, dof).

        Returns:
            numpy.ndarray: the poses, shape (m, 4, 4).

        Raises:
            ValueError: a wrong shape, a value that is not finite, more than
                3.6 million rows.

        >>> import numpy as np, primo
        >>> primo.Robot.lwr4().forward_many(np.zeros((5, 7))).shape
        (5, 4, 4)
        """
    def jacobian(self, q: ArrayLike) -> Array:
        """The geometric Jacobian at ``q``.

        Args:
            q: the joint positions, ``dof`` values.

        Returns:
            numpy.ndarray: 6 × dof; rows vx, vy, vz, wx, wy, wz of the tool
            frame's origin, in the base frame.

        Raises:
            ValueError: a wrong length or a value that is not finite.

        >>> import numpy as np, primo
        >>> primo.Robot.lwr4().jacobian(np.zeros(7)).shape
        (6, 7)
        """
    def inverse(
        self,
        target: ArrayLike,
        seed: ArrayLike,
        rest: Optional[ArrayLike] = None,
        tolerance: float = 1e-9,
        iterations: int = 200,
    ) -> Array:
        """Joint positions within the limits that put the tool at ``target``.

        Damped least squares from ``seed``, pulled toward ``rest`` in the null
        space. A local search: seed it near the answer (a path's previous
        sample).

        Args:
            target: the tool's pose, 4 × 4 homogeneous (an orthonormal, proper
                rotation).
            seed: the joint positions to start from, ``dof`` values.
            rest: the posture the null space pulls toward (default: each joint's
                mid-range, 0 if continuous).
            tolerance: the position (m) and orientation (rad) error to reach.
            iterations: the most iterations.

        Returns:
            numpy.ndarray: the joint positions, ``dof`` values.

        Raises:
            RuntimeError: no convergence within ``iterations``, naming the
                smallest position and orientation errors reached.
            ValueError: a wrong shape or length, a value that is not finite.

        >>> import numpy as np, primo
        >>> robot = primo.Robot.lwr4()
        >>> q = np.array([0.3, 0.6, -0.2, -1.2, 0.4, 0.7, -0.5])
        >>> solved = robot.inverse(robot.forward(q), seed=q + 0.05)
        >>> bool(np.abs(robot.forward(solved) - robot.forward(q)).max() < 1e-9)
        True
        """
    def inverse_path(
        self,
        targets: ArrayLike,
        seed: ArrayLike,
        rest: Optional[ArrayLike] = None,
        tolerance: float = 1e-9,
        iterations: int = 200,
        on_failure: Literal["raise", "nan"] = "raise",
    ) -> Array:
        """Each of ``targets`` solved as ``inverse`` does, from the previous
        sample's solution (the first from ``seed``), with the GIL released.

        Args:
            targets: the tool's poses, shape (m, 4, 4).
            seed: the joint positions the first sample starts from.
            rest: the posture the null space pulls toward.
            tolerance: the position (m) and orientation (rad) error to reach.
            iterations: the most iterations per sample.
            on_failure: ``"raise"``: a sample that does not converge is a
                ``RuntimeError`` naming it; ``"nan"``: its row is NaN and the
                next sample starts from the last solution.

        Returns:
            numpy.ndarray: the joint positions, shape (m, dof).

        Raises:
            RuntimeError: a sample that does not converge (with ``"raise"``).
            ValueError: a wrong shape or length, a value that is not finite.

        >>> import numpy as np, primo
        >>> robot = primo.Robot.lwr4()
        >>> q = np.array([0.3, 0.6, -0.2, -1.2, 0.4, 0.7, -0.5])
        >>> path = robot.forward_many(q + np.linspace(0, 0.1, 4)[:, None])
        >>> robot.inverse_path(path, seed=q).shape
        (4, 7)
        """
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
    """One seeded run of the golden experiment (Fig. 3), as
    ``primo experiment golden --volumes VOLUME --seed SEED --precision
    PRECISION`` runs it: the error learner ``method`` (``"golden"``,
    ``"illinois"``, ``"secant"``, ``"fixed-gain"``, ``"weighted-gain"``)
    learns to pour 0.2 l from a bottle holding ``volume`` l into the normal
    glass (Cartesian space, 30 kernels) until |error| < ``precision`` l,
    the scale's noise from ``seed``. Runs on one core with the GIL
    released.

    Returns a dict: ``volume``, ``method``, ``seed``, ``precision``,
    ``rollouts_to_precision`` (int or None), ``worst_overpour`` (l) and
    ``rollouts``, the roll-outs as columns (``rollout``, ``update``,
    ``mean``, ``query``, ``poured``, ``spilled``, ``error``, ``reward``:
    NumPy arrays; ``rejected``: a list of None or why the gate refused).

    >>> from primo.experiments import golden_run
    >>> run = golden_run(0.5, method="secant", seed=1)
    >>> run["rollouts_to_precision"], len(run["rollouts"]["error"])
    (3, 3)
    >>> bool(abs(run["rollouts"]["error"][-1]) < 0.002)
    True
    """

def power_run(
    seed: Optional[int] = None,
    variant: Variant = "extended",
    kernels: int = 30,
    updates: int = 100,
    glass: Literal["normal", "small"] = "small",
) -> PowerRun:
    """One seeded run of the power experiment (Figs. 5 and 6), as
    ``primo experiment power --seed SEED --runs 1 --kernels KERNELS
    --updates UPDATES --glass GLASS`` runs it for ``variant``
    (``"extended"``: PoWER over ``[q̂, Δθ]``, s1 = 0.2; ``"ordinary"``:
    s1 = 0; ``"error-learned"``: the query learned from the error,
    ``primo pour --method power-el``): from the generalized start for a 0.5 l bottle, pouring
    0.2 l, ``updates`` updates of 4 roll-outs each, then one roll-out of
    the final mean, in joint space. Runs on one core with the GIL
    released.

    Returns a dict: ``variant``, ``seed``, ``kernels``, ``updates``,
    ``glass``, ``parameters`` (learned: ``[q̂, Δθ]``), the figures of
    ``power_runs.csv`` (``rollouts_to`` and ``updates_to``: ``{0.95: n,
    0.99: n}``, None where the mean policy never got there; ``regret``;
    ``final_error``, ``final_spilled``, ``final_reward``: the final
    mean's |error| and spill in l, its reward) and ``rollouts``, every
    roll-out as columns (as ``golden_run``'s; the mean policy's are
    those with ``mean``: its learning curve).

    >>> from primo.experiments import power_run
    >>> run = power_run(seed=1, variant="ordinary", kernels=10, updates=2)
    >>> run["parameters"], len(run["rollouts"]["reward"])
    (79, 9)
    >>> run["rollouts"]["rollout"][run["rollouts"]["mean"]].tolist()
    [1, 5, 9]
    """

def check_out(out: Path, kind: Literal["golden", "power"], force: bool = False) -> None:
    """Checks, creating nothing, that the experiment ``kind`` (``"golden"``
    or ``"power"``) may write its files into ``out``: a directory or none
    yet, in use by no other primo, and holding no earlier result unless
    ``force`` (then it is replaced). A sweep asks before its runs begin,
    so that hours of runs are not lost to a directory that is taken.

    >>> import tempfile, pathlib
    >>> from primo.experiments import check_out
    >>> out = pathlib.Path(tempfile.mkdtemp())
    >>> (out / "summary.json").write_text("an earlier result")
    17
    >>> try:
    ...     check_out(out, "golden")
    ... except ValueError as e:
    ...     print(str(e).removeprefix(str(out / "summary.json")))
    : an earlier result is here: choose another directory, or give force=True to replace it
    >>> check_out(out, "golden", force=True)
    """

def write_golden(out: Path, runs: Sequence[Mapping[str, Any]], force: bool = False) -> None:
    """Writes what ``primo experiment golden`` writes (``golden.csv``,
    ``summary.json``, ``golden.png``) into the directory ``out`` (made if
    missing; one holding an earlier result is refused unless ``force``,
    and one another primo is writing into always, as by ``check_out``)
    for ``runs``, dicts of ``golden_run`` (all of one
    ``precision`` and seed), in order: those of ``primo experiment golden
    --volumes V1,V2,… --seed S`` are each volume's five learners in the
    order golden, illinois, secant, fixed-gain, weighted-gain, and the
    files are then the command's, byte for byte. The figures are computed
    again from the roll-outs.

    >>> import tempfile, pathlib
    >>> from primo.experiments import golden_run, write_golden
    >>> out = pathlib.Path(tempfile.mkdtemp())
    >>> write_golden(out, [golden_run(0.5, m) for m in ["golden", "secant"]])
    >>> (out / "golden.csv").read_text().splitlines()[1]
    '0.5,golden,1,0.5,0.228517,0.028517'
    """

def write_power(
    out: Path, runs: Sequence[Mapping[str, Any]], seconds: float = 0.0, force: bool = False
) -> None:
    """Writes what ``primo experiment power`` writes (``power_runs.csv``,
    ``power.csv``, ``summary.json``, ``power.png``) into the directory
    ``out`` (made if missing; refused as by ``write_golden``) for ``runs``,
    dicts of ``power_run`` of one
    setting (kernels, updates, glass): each variant's runs in the order
    given, the variants on the same seeds in the same order (they are
    compared seed by seed). ``seconds`` is the wall-clock time the summary
    reports. For the runs of ``primo experiment power --seed S --runs N``
    (seeds S, S + 1, …) the files are the command's, byte for byte, but
    for that time. The figures are computed again from the roll-outs.
    ``force`` replaces an earlier result in ``out``.

    >>> import tempfile, pathlib
    >>> from primo.experiments import power_run, write_power
    >>> out = pathlib.Path(tempfile.mkdtemp())
    >>> runs = [power_run(s, v, kernels=10, updates=2) for v in ["extended", "ordinary"] for s in [1, 2]]
    >>> write_power(out, runs)
    >>> (out / "power_runs.csv").read_text().splitlines()[0]
    'variant,seed,rollouts_to_0.95,updates_to_0.95,rollouts_to_0.99,updates_to_0.99,regret,final_error_l,final_spilled_l,final_reward'
    """
