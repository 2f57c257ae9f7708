"""The simulated pouring cell as a Gymnasium environment.

Episodic, in the movement-primitive convention of fancy_gym: one step is
one roll-out of a whole movement. The observation is the task context,
``[bottle volume, target volume]`` (litres), chosen at reset with
``options={"bottle": b, "target": t}`` (either key; a reset without them
keeps the current context, first the constructor's); the action is a vector
``a`` in ``[-1, 1]^n`` that moves the generalized start of the cell
(``Cell.start()``) by ``scale`` exploration standard deviations per
value: ``theta = start + scale * std * a`` (``a = 0`` pours the movement
generalized from the demonstrations for the context's bottle). The reward is the paper's,
``max(0, 1 - 5 |target - poured| - 5 spilled)``; every episode ends
after its one step. The scale's noise of a roll-out is drawn from the
environment's seeded generator.

>>> import gymnasium
>>> import numpy as np
>>> import primo
>>> env = gymnasium.make(primo.ENV_ID, kernels=10)
>>> obs, info = env.reset(seed=1)
>>> obs.tolist()
[0.5, 0.2]
>>> obs, reward, terminated, truncated, info = env.step(np.zeros(env.action_space.shape))
>>> terminated, 0.0 <= reward <= 1.0, sorted(info)
(True, True, ['error', 'poured', 'rejected', 'safe', 'spilled'])
>>> env.reset(options={"bottle": 0.8, "target": 0.25})[0].tolist()
[0.8, 0.25]

``PouringVectorEnv`` steps ``num_envs`` of them at once, every roll-out
on its own core in Rust (``Cell.rollout_many``):
``gymnasium.make_vec(primo.ENV_ID, num_envs=8,
vectorization_mode="vector_entry_point")``. Its reset's ``options`` give
one context for all, or an array of ``num_envs`` values per key; its
``info`` follows Gymnasium's vector convention, each key ``k`` with a
boolean mask ``_k`` of the environments that report it (all, every step).
"""

from __future__ import annotations

from typing import Any, Optional

import gymnasium
import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from primo._primo import Cell

__all__ = ["PouringEnv", "PouringVectorEnv"]

_INFO = ("poured", "spilled", "error", "safe", "rejected")


# Contexts a task keeps built: each is a cell (its skill generalized to
# the bottle), rebuilt otherwise.
_CACHED = 16


class _Task:
    """The cells of the contexts met (built on demand), the action's
    scale, and the spaces; the action's length is the same in every
    context (the skill's layout)."""

    def __init__(self, cell: Optional[Cell], scale: float, **settings: Any) -> None:
        if not (np.isfinite(scale) and scale > 0):
            raise ValueError(f"scale: {scale} must be a positive, finite number")
        self.scale = float(scale)
        first = cell if cell is not None else Cell(**settings)
        self.context = (first.bottle, first.target)
        self._cells: dict[tuple[float, float], tuple[Cell, np.ndarray, np.ndarray]] = {}
        self._keep(first)
        n = len(first)
        self.action_space = spaces.Box(-1.0, 1.0, shape=(n,), dtype=np.float64)
        # Litres: the cell's bottle holds about 1 l.
        self.observation_space = spaces.Box(0.0, 2.0, shape=(2,), dtype=np.float64)

    def _keep(self, cell: Cell) -> tuple[Cell, np.ndarray, np.ndarray]:
        if len(self._cells) >= _CACHED:
            self._cells.pop(next(iter(self._cells)))
        start = cell.start()
        entry = (cell, start["start"], start["std"])
        self._cells[(cell.bottle, cell.target)] = entry
        return entry

    def cell(self, context: tuple[float, float]) -> tuple[Cell, np.ndarray, np.ndarray]:
        """The cell of `context`, its start and exploration std."""
        entry = self._cells.get(context)
        if entry is None:
            some = next(iter(self._cells.values()))[0]
            entry = self._keep(some.with_context(bottle=context[0], target=context[1]))
        return entry

    def chosen(
        self, options: Optional[dict[str, Any]], current: list[tuple[float, float]], vector: bool
    ) -> list[tuple[float, float]]:
        """The contexts `options` choose, one per environment of `current`
        (a key left out keeps each one's); a vector env's may be arrays."""
        options = dict(options or {})
        unknown = sorted(set(options) - {"bottle", "target"})
        if unknown:
            raise ValueError(
                f"options: {unknown} unknown; a context is given as 'bottle' and 'target' (litres)"
            )
        n = len(current)
        columns = []
        for j, key in enumerate(("bottle", "target")):
            value = np.asarray(options.get(key, [c[j] for c in current]), dtype=np.float64)
            if value.ndim == 0:
                value = np.full(n, float(value))
            elif value.shape != (n,) or (key in options and not vector):
                per_env = f" or one per environment ({n},)" if vector else ""
                raise ValueError(
                    f"options: {key} has shape {value.shape}, expected a number{per_env}"
                )
            columns.append(value)
        contexts = [(float(b), float(t)) for b, t in zip(*columns)]
        for c in contexts:
            self.cell(c)  # a context the cell refuses is refused at reset
        return contexts

    def parameters(self, action: Any, context: tuple[float, float]) -> np.ndarray:
        _, start, std = self.cell(context)
        a = np.asarray(action, dtype=np.float64)
        if a.shape[-1:] != start.shape:
            raise ValueError(f"action: shape {a.shape}, expected (..., {len(start)})")
        return start + self.scale * std * np.clip(a, -1.0, 1.0)


class PouringEnv(gymnasium.Env):
    """One roll-out of the pouring cell per episode (see the module docs).

    Args:
        cell: a ready ``Cell`` (default: one built from ``settings``).
        scale: the action's reach in exploration standard deviations.
        settings: ``Cell``'s keyword arguments (``glass``, ``space``,
            ``bottle``, ``target``, ``kernels``, ``demos``); ``bottle`` and
            ``target`` are the first context, ``reset(options=...)``
            changes it.

    Raises:
        ValueError: a ``scale`` that is not positive, a setting ``Cell``
            refuses.

    >>> import numpy as np, primo
    >>> from primo.env import PouringEnv
    >>> env = PouringEnv(kernels=10, bottle=0.6)
    >>> env.reset(seed=3)[0].tolist(), env.action_space.shape
    ([0.6, 0.2], (79,))
    """

    metadata: dict[str, Any] = {"render_modes": []}

    def __init__(self, cell: Optional[Cell] = None, scale: float = 3.0, **settings: Any) -> None:
        self._task = _Task(cell, scale, **settings)
        self.action_space = self._task.action_space
        self.observation_space = self._task.observation_space

    @property
    def cell(self) -> Cell:
        """The cell of the current context."""
        return self._task.cell(self._task.context)[0]

    @property
    def context(self) -> tuple[float, float]:
        """``(bottle, target)``, litres: what the observation shows."""
        return self._task.context

    def parameters(self, action: Any) -> np.ndarray:
        """The cell's parameter vector an action rolls out in the current context.

        Args:
            action: ``n`` values in [-1, 1] (clipped): ``start + scale *
                std * action``.

        Returns:
            numpy.ndarray: the vector ``Cell.rollout`` takes.

        Raises:
            ValueError: an action of the wrong length.

        >>> import numpy as np
        >>> from primo.env import PouringEnv
        >>> env = PouringEnv(kernels=10)
        >>> bool((env.parameters(np.zeros(79)) == env.cell.start()["start"]).all())
        True
        """
        return self._task.parameters(action, self._task.context)

    def reset(
        self, *, seed: Optional[int] = None, options: Optional[dict[str, Any]] = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Starts an episode, in the context ``options`` choose.

        Args:
            seed: seeds the scale's noise of the roll-outs that follow.
            options: ``{"bottle": b, "target": t}``, litres (either key; a
                key left out keeps the current value).

        Returns:
            tuple: the observation ``[bottle, target]`` and an empty info.

        Raises:
            ValueError: an unknown key, a context the cell refuses.

        >>> from primo.env import PouringEnv
        >>> PouringEnv(kernels=10).reset(options={"target": 0.3})[0].tolist()
        [0.5, 0.3]
        """
        super().reset(seed=seed)
        (self._task.context,) = self._task.chosen(options, [self._task.context], vector=False)
        return np.array(self._task.context, dtype=np.float64), {}

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """One roll-out of the movement ``action`` gives: the episode's
        only step.

        Args:
            action: ``n`` values in [-1, 1] (see ``parameters``).

        Returns:
            tuple: observation, reward (the paper's, 0 to 1), terminated
            (True), truncated (False), info (``poured``, ``spilled``,
            ``error``, ``safe``, ``rejected``).

        Raises:
            ValueError: an action of the wrong length.

        >>> import numpy as np
        >>> from primo.env import PouringEnv
        >>> env = PouringEnv(kernels=10)
        >>> _ = env.reset(seed=1)
        >>> env.step(np.zeros(79))[2:4]
        (True, False)
        """
        noise = int(self.np_random.integers(0, 2**63))
        r = self.cell.rollout(self.parameters(action), seed=noise)
        info = {k: r[k] for k in _INFO}
        return np.array(self._task.context, dtype=np.float64), float(r["reward"]), True, False, info


class PouringVectorEnv(VectorEnv):
    """``num_envs`` pouring cells stepped together: the roll-outs run in
    parallel in Rust with the GIL released (one batch per context). Every
    step ends every episode, and the environments reset in the same step,
    each keeping its context.

    Args:
        num_envs: the number of environments (>= 1).
        cell: a ready ``Cell`` (default: one built from ``settings``).
        scale: the action's reach in exploration standard deviations.
        settings: ``Cell``'s keyword arguments, as ``PouringEnv``'s.

    Raises:
        ValueError: ``num_envs`` below 1, a ``scale`` that is not positive,
            a setting ``Cell`` refuses.

    >>> import numpy as np
    >>> from primo.env import PouringVectorEnv
    >>> env = PouringVectorEnv(num_envs=2, kernels=10)
    >>> obs, _ = env.reset(seed=1, options={"bottle": [0.5, 0.7]})
    >>> obs.tolist()
    [[0.5, 0.2], [0.7, 0.2]]
    >>> rewards = env.step(np.zeros((2, 79)))[1]
    >>> rewards.shape
    (2,)
    """

    metadata: dict[str, Any] = {"render_modes": [], "autoreset_mode": AutoresetMode.SAME_STEP}

    def __init__(
        self, num_envs: int = 1, cell: Optional[Cell] = None, scale: float = 3.0, **settings: Any
    ) -> None:
        if num_envs < 1:
            raise ValueError(f"num_envs: {num_envs}, at least 1")
        self._task = _Task(cell, scale, **settings)
        self.num_envs = num_envs
        self.contexts = [self._task.context] * num_envs
        self.single_action_space = self._task.action_space
        self.single_observation_space = self._task.observation_space
        self.action_space = batch_space(self.single_action_space, num_envs)
        self.observation_space = batch_space(self.single_observation_space, num_envs)

    @property
    def cell(self) -> Cell:
        """The cell of the first environment's context."""
        return self._task.cell(self.contexts[0])[0]

    def _observations(self) -> np.ndarray:
        return np.array(self.contexts, dtype=np.float64)

    def reset(
        self, *, seed: Optional[int] = None, options: Optional[dict[str, Any]] = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        if options is not None:
            self.contexts = self._task.chosen(options, self.contexts, vector=True)
        return self._observations(), {}

    def step(
        self, actions: Any
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        a = np.asarray(actions, dtype=np.float64)
        if a.ndim != 2 or a.shape[0] != self.num_envs:
            raise ValueError(
                f"actions: shape {a.shape}, expected {self.num_envs} rows, one per environment"
            )
        seeds = [int(s) for s in self.np_random.integers(0, 2**63, size=self.num_envs)]
        results: list[dict[str, Any]] = [{}] * self.num_envs
        for context in dict.fromkeys(self.contexts):
            rows = [i for i, c in enumerate(self.contexts) if c == context]
            thetas = self._task.parameters(a[rows], context)
            done = self._task.cell(context)[0].rollout_many(thetas, seeds=[seeds[i] for i in rows])
            for i, r in zip(rows, done):
                results[i] = r
        rewards = np.array([r["reward"] for r in results], dtype=np.float64)
        infos: dict[str, Any] = {}
        for k in _INFO:
            infos[k] = np.array([r[k] for r in results])
            infos[f"_{k}"] = np.ones(self.num_envs, dtype=bool)
        done = np.ones(self.num_envs, dtype=bool)
        return self._observations(), rewards, done, ~done, infos
