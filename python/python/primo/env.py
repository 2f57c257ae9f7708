"""The simulated pouring cell as a Gymnasium environment.

Episodic, in the movement-primitive convention of fancy_gym: one step is
one roll-out of a whole movement. The observation is the task context,
``[bottle volume, target volume]`` (litres); the action is a vector
``a`` in ``[-1, 1]^n`` that moves the generalized start of the cell
(``Cell.start()``) by ``scale`` exploration standard deviations per
value: ``theta = start + scale * std * a`` (``a = 0`` pours the movement
generalized from the demonstrations). The reward is the paper's,
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

``PouringVectorEnv`` steps ``num_envs`` of them at once, every roll-out
on its own core in Rust (``Cell.rollout_many``):
``gymnasium.make_vec(primo.ENV_ID, num_envs=8,
vectorization_mode="vector_entry_point")``.
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


class _Task:
    """The cell, its start and exploration std, and the spaces."""

    def __init__(self, cell: Optional[Cell], scale: float, **settings: Any) -> None:
        self.cell = cell if cell is not None else Cell(**settings)
        start = self.cell.start()
        self.start = start["start"]
        self.std = start["std"]
        if not (np.isfinite(scale) and scale > 0):
            raise ValueError(f"scale: {scale} must be a positive, finite number")
        self.scale = float(scale)
        n = len(self.start)
        self.action_space = spaces.Box(-1.0, 1.0, shape=(n,), dtype=np.float64)
        # Litres: the cell's bottle holds about 1 l.
        self.observation_space = spaces.Box(0.0, 2.0, shape=(2,), dtype=np.float64)
        self.observation = np.array([self.cell.bottle, self.cell.target], dtype=np.float64)

    def parameters(self, action: Any) -> np.ndarray:
        a = np.asarray(action, dtype=np.float64)
        if a.shape[-1:] != self.start.shape:
            raise ValueError(f"action: shape {a.shape}, expected (..., {len(self.start)})")
        return self.start + self.scale * self.std * np.clip(a, -1.0, 1.0)


class PouringEnv(gymnasium.Env):
    """One roll-out of the pouring cell per episode (see the module docs).

    Keyword arguments are ``Cell``'s (``glass``, ``space``, ``bottle``,
    ``target``, ``kernels``, ``demos``), or a ready ``cell``; ``scale``
    is the action's reach in exploration standard deviations.
    """

    metadata: dict[str, Any] = {"render_modes": []}

    def __init__(self, cell: Optional[Cell] = None, scale: float = 3.0, **settings: Any) -> None:
        self._task = _Task(cell, scale, **settings)
        self.cell = self._task.cell
        self.action_space = self._task.action_space
        self.observation_space = self._task.observation_space

    def parameters(self, action: Any) -> np.ndarray:
        """The cell's parameter vector an action rolls out."""
        return self._task.parameters(action)

    def reset(
        self, *, seed: Optional[int] = None, options: Optional[dict[str, Any]] = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        return self._task.observation.copy(), {}

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        noise = int(self.np_random.integers(0, 2**63))
        r = self.cell.rollout(self.parameters(action), seed=noise)
        info = {k: r[k] for k in _INFO}
        return self._task.observation.copy(), float(r["reward"]), True, False, info


class PouringVectorEnv(VectorEnv):
    """``num_envs`` pouring cells stepped together: the roll-outs run in
    parallel in Rust with the GIL released. Every step ends every
    episode, and the environments reset in the same step."""

    metadata: dict[str, Any] = {"render_modes": [], "autoreset_mode": AutoresetMode.SAME_STEP}

    def __init__(
        self, num_envs: int = 1, cell: Optional[Cell] = None, scale: float = 3.0, **settings: Any
    ) -> None:
        if num_envs < 1:
            raise ValueError(f"num_envs: {num_envs}, at least 1")
        self._task = _Task(cell, scale, **settings)
        self.cell = self._task.cell
        self.num_envs = num_envs
        self.single_action_space = self._task.action_space
        self.single_observation_space = self._task.observation_space
        self.action_space = batch_space(self.single_action_space, num_envs)
        self.observation_space = batch_space(self.single_observation_space, num_envs)

    def _observations(self) -> np.ndarray:
        return np.tile(self._task.observation, (self.num_envs, 1))

    def reset(
        self, *, seed: Optional[int] = None, options: Optional[dict[str, Any]] = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        return self._observations(), {}

    def step(
        self, actions: Any
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        thetas = self._task.parameters(actions)
        if thetas.shape[0] != self.num_envs:
            raise ValueError(f"actions: {thetas.shape[0]} rows for {self.num_envs} environments")
        seeds = [int(s) for s in self.np_random.integers(0, 2**63, size=self.num_envs)]
        results = self.cell.rollout_many(thetas, seeds=seeds)
        rewards = np.array([r["reward"] for r in results], dtype=np.float64)
        infos = {k: np.array([r[k] for r in results]) for k in _INFO}
        done = np.ones(self.num_envs, dtype=bool)
        return self._observations(), rewards, done, ~done, infos
