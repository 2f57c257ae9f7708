"""Any Gymnasium environment as an episodic task for primo's learners.

``BlackBox`` turns an environment whose actions are joint torques,
velocities, positions or position steps into the black box the
movement-primitive literature learns on (fancy_gym's "black-box"
environments): one parameter vector in, one whole episode out. A DMP,
a ``Generalizer`` over demonstrations or a ProMP's mean gives the
movement; a tracking law turns it into the environment's actions step
by step; the context (for example a goal position) is set at reset and,
with a ``Generalizer``, is also the query of the generalized movement.

Gymnasium is the ``[gym]`` extra: ``pip install "primo-robotics[gym]"``
(MuJoCo tasks also need ``gymnasium[mujoco]``; Metaworld ``metaworld``).

>>> import gymnasium, numpy as np, primo, primo.gym
>>> env = gymnasium.make("Pendulum-v1")  # torque on one joint
>>> t = np.linspace(0.0, 1.0, 21)
>>> dmp = primo.Dmp.fit(t, 0.5 * np.sin(np.pi * t / 2), kernels=10)
>>> box = primo.gym.BlackBox(env, dmp, tracking="pd", kp=10.0, kd=1.0,
...                          state=lambda env, obs: (np.arctan2(obs[1:2], obs[0:1]), obs[2:3]),
...                          dt=0.05)
>>> episode = box.episode(dmp.params, seed=0)
>>> episode.steps, episode.success
(30, None)
"""

from __future__ import annotations

import copy
import pickle
from dataclasses import dataclass
from typing import Any, Callable, Optional, Sequence, Union

import numpy as np

try:
    from gymnasium import spaces
except ImportError as e:  # pragma: no cover - the [gym] extra is missing
    raise ImportError(
        'primo.gym needs Gymnasium: pip install "primo-robotics[gym]" '
        '(and "gymnasium[mujoco]" for the MuJoCo tasks)'
    ) from e

from primo._primo import Dmp, Generalizer, GoldenSection, Illinois, Power, ProMp, Secant

__all__ = ["BlackBox", "Episode", "metaworld_reset", "qpos_reset"]

TRACKING = ("pd", "velocity", "position", "delta")
MAX_SAMPLES = 10_000_000  # of a movement, as Dmp.run allows

State = Callable[[Any, np.ndarray], tuple[Any, Any]]


@dataclass
class Episode:
    """One episode of a ``BlackBox``.

    ``episode_return``: the sum of the environment's rewards;
    ``success``: whether the success test (the environment's
    ``info["success"]`` by default) held at any step, or None when the
    environment reports none; ``error``: the error vector (``desired −
    measured``) of the ``error`` function at the end, or None without
    one; ``steps``: the environment steps taken; ``theta``: the
    parameters it was given (where a goal or via-point change was
    refused, the movement's own: ``initial``); ``rejected``: why the
    movement refused ``theta`` (a DMP's duration under 1 ms, a value
    beyond float32, a conditioning the ProMP cannot take), or None; ``trace``:
    the tracked positions at the start of each step, shape (steps,
    tracked DoFs), or None with ``tracking="position"``. A rejected
    episode takes no step: its return is NaN, its success False and its
    error None (``learn`` tells error learners ``tell_infeasible`` and
    ``Power`` the reward 0).

    >>> import numpy as np, primo.gym
    >>> primo.gym.Episode(episode_return=-1.5, success=True, error=None, steps=3, theta=np.zeros(2),
    ...                   rejected=None, trace=None).steps
    3
    """

    episode_return: float
    success: Optional[bool]
    error: Optional[np.ndarray]
    steps: int
    theta: np.ndarray
    rejected: Optional[str]
    trace: Optional[np.ndarray]


class _Rejected(ValueError):
    """The movement refused the parameters (not a caller's shape error)."""


def _with_params(movement: Union[Dmp, ProMp], theta: np.ndarray) -> Union[Dmp, ProMp]:
    try:
        movement.params = theta
    except ValueError as e:
        raise _Rejected(f"theta: {e}") from e
    return movement


def _rejected(theta: np.ndarray, why: str) -> Episode:
    """The episode of parameters the movement refused: no step taken."""
    return Episode(float("nan"), False, None, 0, theta, why, None)


def _default_reset(env: Any, context: Any, seed: Optional[int]) -> Any:
    """``env.reset(seed=seed, options={"context": context})``."""
    options = None if context is None else {"context": context}
    return env.reset(seed=seed, options=options)[0]


def _mujoco_state(env: Any, obs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The first joints' positions and velocities of a MuJoCo environment
    (sliced to the tracked DoFs by the caller)."""
    data = getattr(env.unwrapped, "data", None)
    if data is None:
        raise ValueError(
            "state: the environment has no MuJoCo data (env.unwrapped.data); "
            "pass state=lambda env, obs: (positions, velocities)"
        )
    return data.qpos, data.qvel


class BlackBox:
    """An environment run as one episode per parameter vector.

    ``env``: a Gymnasium environment with a one-dimensional ``Box``
    action space. ``movement``: a discrete ``primo.Dmp`` (``theta`` is
    its ``params``), a ``primo.Generalizer`` (``theta`` is
    ``[q̂, Δθ]``, the movement ``G(q̂) + Δθ``, the layout of ``Power``
    with ``query=len(q̂)``; see ``dmp`` for the shorter forms) or a
    ``primo.ProMp`` (``theta`` is its ``params``, the mean's weights: the
    movement is the mean over the demonstrations' mean duration).
    ``tracking``: how the movement's desired positions ``y`` and
    velocities ``ẏ`` become actions, clipped to the action space:
    ``"pd"`` torques ``kp (y − x) + kd (ẏ − ẋ)`` toward the next
    sample; ``"velocity"`` the step's mean velocity ``(y_next − y_now) /
    dt + kp (y_now − x)``; ``"position"`` the next ``y``; ``"delta"`` a
    position step ``kp (y_next − x)`` (Metaworld's Cartesian actions, about
    ``kp = 50``). ``state(env, obs) -> (x, ẋ)``: the tracked positions
    and velocities (``ẋ`` may be None unless ``"pd"`` uses ``kd``);
    by default the MuJoCo joints ``env.unwrapped.data.qpos, qvel``. The
    movement's first DoFs are tracked, one per action value; DoFs beyond
    the state's (a gripper command) are passed to the next action values
    as they are, and the actions left over are 0. ``reset(env, context,
    seed) -> obs`` sets the context; by default ``env.reset(seed=seed,
    options={"context": context})``. ``query(context)``: the
    ``Generalizer``'s query for a context (the context itself by
    default). ``success(env, obs, info) -> bool``: the success test
    after each step (default: ``info["success"]``, if given). ``error(env,
    obs, info) -> vector``: the error ``desired − measured`` after the
    last step, for error learning. ``dt``: the environment's step, s
    (default ``env.unwrapped.dt``). ``hold``: steps after the movement
    ends, holding its goal. ``stop_on_success``: end the episode at the
    first success (as Metaworld's evaluation does).

    >>> import gymnasium, numpy as np, primo, primo.gym
    >>> env = gymnasium.make("Reacher-v5")
    >>> t = np.linspace(0.0, 0.6, 31)
    >>> dmp = primo.Dmp.fit(t, np.outer(t / 0.6, [0.5, 1.0]), names=["j0", "j1"], kernels=10)
    >>> box = primo.gym.BlackBox(env, dmp, tracking="pd", kp=2.0, kd=0.1,
    ...                          error=lambda env, obs, info: -obs[8:10])
    >>> episode = box.episode(box.initial(), seed=0)
    >>> episode.steps, episode.error.shape
    (40, (2,))
    """

    def __init__(
        self,
        env: Any,
        movement: Union[Dmp, Generalizer, ProMp],
        tracking: str = "pd",
        kp: float = 1.0,
        kd: float = 0.0,
        state: Optional[State] = None,
        reset: Optional[Callable[[Any, Any, Optional[int]], Any]] = None,
        query: Optional[Callable[[Any], Any]] = None,
        success: Optional[Callable[[Any, np.ndarray, dict], bool]] = None,
        error: Optional[Callable[[Any, np.ndarray, dict], Any]] = None,
        dt: Optional[float] = None,
        hold: int = 10,
        stop_on_success: bool = False,
    ) -> None:
        space = getattr(env, "action_space", None)
        if not isinstance(space, spaces.Box) or len(space.shape) != 1:
            raise TypeError(
                f"env: its action space is {space}; BlackBox drives a one-dimensional Box "
                "of joint torques, velocities, positions or position steps"
            )
        if tracking not in TRACKING:
            raise ValueError(f"tracking: {tracking!r}, one of {', '.join(TRACKING)}")
        self.generalizer: Optional[Generalizer] = None
        example: Union[Dmp, ProMp]
        if isinstance(movement, Generalizer):
            self.generalizer = movement
            example = movement.generalize(np.zeros(movement.query_dim))
        elif isinstance(movement, Dmp):
            if movement.rhythmic:
                raise ValueError("movement: a rhythmic DMP; BlackBox runs discrete movements")
            example = movement
        elif isinstance(movement, ProMp):
            example = movement  # its columns are positions: its fit refuses orientations
        else:
            raise TypeError(
                f"movement: {type(movement).__name__}, expected a primo.Dmp, primo.Generalizer or primo.ProMp"
            )
        names = movement.names
        if isinstance(example, Dmp) and (example.dof != len(names) or example.orientations):
            raise ValueError("movement: orientation DMPs cannot be tracked per action value; use position columns")
        if len(names) > space.shape[0]:
            raise ValueError(
                f"movement: {len(names)} DoFs ({', '.join(names)}) but the action has {space.shape[0]} values"
            )
        if dt is None:
            dt = getattr(env.unwrapped, "dt", None)
            if dt is None:
                raise ValueError("dt: the environment has no dt (env.unwrapped.dt); pass the step in seconds")
        if not (np.isfinite(dt) and dt > 0):
            raise ValueError(f"dt: {dt}, a positive number of seconds")
        if hold < 0:
            raise ValueError(f"hold: {hold}, at least 0 steps")
        if isinstance(example, ProMp) and example.duration / dt > MAX_SAMPLES:
            raise ValueError(
                f"dt: {dt} s over the ProMP's {example.duration:g} s would make "
                f"{example.duration / dt:.0f} samples, at most {MAX_SAMPLES}"
            )
        self.env = env
        self.movement = movement
        self.tracking = tracking
        self.kp = float(kp)
        self.kd = float(kd)
        self.dt = float(dt)
        self.hold = int(hold)
        self.stop_on_success = stop_on_success
        self._example = example
        self._names = list(names)
        self._state = state if state is not None else (None if tracking == "position" else _mujoco_state)
        self._reset = reset if reset is not None else _default_reset
        self._query = query
        self._success = success
        self._error = error
        self._low = np.asarray(space.low, dtype=np.float64)
        self._high = np.asarray(space.high, dtype=np.float64)

    @property
    def size(self) -> int:
        """The movement's parameter count ``n`` (``Δθ``'s length)."""
        return len(self._example.params)

    @property
    def query_dim(self) -> int:
        """The ``Generalizer``'s query length (0 for a plain DMP or a ProMP)."""
        return 0 if self.generalizer is None else self.generalizer.query_dim

    def query(self, context: Any) -> np.ndarray:
        """The query of ``context`` (``query(context)``, or the context).

        >>> import numpy as np, primo, primo.gym, gymnasium
        >>> t = np.linspace(0.0, 1.0, 11)
        >>> g = primo.Generalizer([(q, primo.Dmp.fit(t, q * t, kernels=5, margin=1)) for q in (1.0, 2.0)])
        >>> primo.gym.BlackBox(gymnasium.make("Reacher-v5"), g).query(1.5).tolist()
        [1.5]
        """
        if context is None:
            raise ValueError("context: None; a Generalizer's movement needs the context its query comes from")
        q = np.atleast_1d(np.asarray(self._query(context) if self._query else context, dtype=np.float64))
        if q.shape != (self.query_dim,):
            raise ValueError(f"context: its query has shape {q.shape}, the Generalizer's is ({self.query_dim},)")
        return q

    def initial(self, context: Any = None) -> np.ndarray:
        """The parameters of the movement as given: a DMP's or a ProMP's
        ``params``, or a ``Generalizer``'s ``[q̂, 0…]`` at the query of
        ``context``.

        >>> import numpy as np, primo, primo.gym, gymnasium
        >>> dmp = primo.Dmp.fit(np.linspace(0, 1, 11), np.zeros((11, 2)), kernels=5)
        >>> primo.gym.BlackBox(gymnasium.make("Reacher-v5"), dmp).initial().shape
        (13,)
        """
        if self.generalizer is None:
            return np.asarray(self._example.params, dtype=np.float64).copy()
        return np.concatenate([self.query(context), np.zeros(self.size)])

    def dmp(self, theta: Any, context: Any = None) -> Dmp:
        """The DMP that ``theta`` stands for. A plain DMP's ``theta`` is
        its ``params``. A ``Generalizer``'s is ``[q̂, Δθ]``, or ``Δθ``
        alone (at the query of ``context``), or ``q̂`` alone (``Δθ = 0``:
        the error learners' queries).

        >>> import numpy as np, primo, primo.gym, gymnasium
        >>> t = np.linspace(0.0, 1.0, 11)
        >>> g = primo.Generalizer([(q, primo.Dmp.fit(t, q * t, kernels=5, margin=1)) for q in (1.0, 2.0)])
        >>> box = primo.gym.BlackBox(gymnasium.make("Reacher-v5"), g)
        >>> round(float(box.dmp([1.5]).goal[0]), 3)
        1.5
        """
        theta = np.atleast_1d(np.asarray(theta, dtype=np.float64))
        n, d = self.size, self.query_dim
        if isinstance(self._example, ProMp):
            raise TypeError("dmp: this BlackBox's movement is a ProMp; see promp")
        if self.generalizer is None:
            if theta.shape != (n,):
                raise ValueError(f"theta: shape {theta.shape}, the DMP has {n} parameters")
            return _with_params(Dmp.from_json(self._example.to_json()), theta)
        if theta.shape == (d,):
            return self.generalizer.generalize(theta)
        if theta.shape == (n,):
            q, delta = self.query(context), theta
        elif theta.shape == (d + n,):
            q, delta = theta[:d], theta[d:]
        else:
            raise ValueError(
                f"theta: shape {theta.shape}; expected [q̂, Δθ] ({d + n}), Δθ ({n}) or q̂ ({d})"
            )
        dmp = self.generalizer.generalize(q)
        return _with_params(dmp, np.asarray(dmp.params) + delta)

    def promp(self, theta: Any) -> ProMp:
        """The ProMP whose mean has the weights ``theta`` (a ProMP
        movement's; its spread is the given ProMP's).

        >>> import gymnasium, numpy as np, primo, primo.gym
        >>> t = np.linspace(0.0, 0.4, 21)
        >>> p = primo.ProMp.fit([(t, np.outer(t, [1.0, h])) for h in (0.5, 1.5)], names=["j0", "j1"], kernels=5)
        >>> box = primo.gym.BlackBox(gymnasium.make("Reacher-v5"), p)
        >>> round(float(box.promp(box.initial() + 0.1).mean(1.0)[0, 1]), 2)  # 0.4 + 0.1
        0.5
        """
        if not isinstance(self._example, ProMp):
            raise TypeError("promp: this BlackBox's movement is a DMP; see dmp")
        theta = np.atleast_1d(np.asarray(theta, dtype=np.float64))
        if theta.shape != (self.size,):
            raise ValueError(f"theta: shape {theta.shape}, the ProMP has {self.size} parameters")
        return _with_params(copy.copy(self._example), theta)

    def _run(self, theta: np.ndarray, context: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The movement of ``theta`` every ``dt``: times, positions and
        velocities (a ProMP's from phase 0 to 1, the last step shorter to
        land on its end); ``_Rejected`` where the movement refuses it."""
        if isinstance(self._example, ProMp):
            promp = self.promp(theta)
            duration = promp.duration
            # The duration is a sum of f32 times: a hair over k steps is k steps.
            times = np.minimum(np.arange(int(np.ceil(duration / self.dt - 1e-6)) + 1) * self.dt, duration)
            z = times / duration
            velocity = promp.velocity(z)
            velocity[-1] = 0.0  # the hold keeps the end at rest, as the mean is after it
            return times, promp.mean(z), velocity
        return self.dmp(theta, context).run(dt=self.dt, velocities=True)

    def episode(self, theta: Any, context: Any = None, seed: Optional[int] = None) -> Episode:
        """Runs one episode: resets at ``context`` (with ``seed``), then
        tracks the movement of ``theta`` (see ``dmp`` and ``promp``) step
        by step. A ``theta`` the movement refuses is a rejected episode
        (see ``Episode``); one of the wrong shape is a ``ValueError``.

        >>> import gymnasium, numpy as np, primo, primo.gym
        >>> dmp = primo.Dmp.fit(np.linspace(0, 0.4, 21), np.zeros((21, 2)), kernels=5)
        >>> box = primo.gym.BlackBox(gymnasium.make("Reacher-v5"), dmp, kp=2.0, hold=5)
        >>> box.episode(box.initial(), seed=1).steps
        25
        """
        theta = np.atleast_1d(np.asarray(theta, dtype=np.float64))
        try:
            _, y, yd = self._run(theta, context)
        except _Rejected as e:
            return _rejected(theta, str(e))
        obs = self._reset(self.env, context, seed)
        last = len(y) - 1
        total, ever, reported, steps = 0.0, False, False, 0
        info: dict = {}
        trace = []
        for k in range(last + self.hold):
            now, then = min(k, last), min(k + 1, last)
            x, xd = (None, None) if self._state is None else self._state(self.env, obs)
            if x is not None:
                trace.append(np.array(x, dtype=np.float64)[: len(y[now])])
            action = self._action(x, xd, y[then], yd[then], y[now])
            obs, reward, terminated, truncated, info = self.env.step(action)
            total += float(reward)
            steps += 1
            if self._success is not None:
                ever |= bool(self._success(self.env, obs, info))
                reported = True
            elif "success" in info:
                ever |= bool(info["success"])
                reported = True
            if terminated or truncated or (ever and self.stop_on_success):
                break
        error = None
        if self._error is not None:
            error = np.atleast_1d(np.asarray(self._error(self.env, obs, info), dtype=np.float64))
        return Episode(total, ever if reported else None, error, steps, theta, None, np.array(trace) if trace else None)

    def _action(self, x: Any, xd: Any, y: np.ndarray, yd: np.ndarray, y_now: np.ndarray) -> np.ndarray:
        """The action toward ``y, yd`` (the next sample's) from the state
        ``x, xd`` at the current sample, ``y_now``."""
        action = np.zeros_like(self._low)
        if x is None:  # "position": the desired positions are the action
            action[: len(y)] = y
            return np.clip(action, self._low, self._high)
        m = min(len(np.atleast_1d(x)), len(y))
        x = np.asarray(x, dtype=np.float64)[:m]
        if self.tracking == "pd":
            u = self.kp * (y[:m] - x)
            if self.kd:
                if xd is None:
                    raise ValueError("state: returns no velocities, which tracking='pd' with kd needs")
                u += self.kd * (yd[:m] - np.asarray(xd, dtype=np.float64)[:m])
        elif self.tracking == "velocity":  # the step's mean velocity, corrected where x is now
            u = (y[:m] - y_now[:m]) / self.dt + self.kp * (y_now[:m] - x)
        elif self.tracking == "delta":
            u = self.kp * (y[:m] - x)
        else:
            u = y[:m]
        action[:m] = u
        action[m : len(y)] = y[m:]  # untracked DoFs (a gripper) as they are
        return np.clip(action, self._low, self._high)

    def learn(
        self,
        learner: Union[GoldenSection, Illinois, Secant, Power],
        context: Any = None,
        budget: int = 100,
        reward: Optional[Callable[[Episode], float]] = None,
        seed: Optional[int] = None,
        until_success: bool = True,
        goals: Union[bool, Sequence[int]] = False,
        via: Sequence[tuple[float, int, float]] = (),
    ) -> list[Episode]:
        """Lets a learner of primo's run episodes at ``context`` until it
        is done, ``budget`` episodes are spent or, with
        ``until_success``, an episode succeeds; returns the episodes.

        ``GoldenSection``, ``Illinois`` and ``Secant`` ask queries of the
        ``Generalizer`` and are told the episode's error (the ``error``
        function is needed). ``Power`` asks ``theta`` in any form
        ``dmp`` (or ``promp``) takes and is told ``reward(episode)`` (needed: a reward
        >= 0, larger is better) and the error, when there is one.
        ``seed``: every episode's reset seed.

        ``goals``: an error learner's values change the movement's goals
        instead of asking a query: with True the goals of the first DoFs,
        one per value, or of the DoFs listed, value ``i`` the goal of DoF
        ``goals[i]`` (the generalized movement's, at the query of
        ``context``, or the DMP's; the first ask, zeros, is that movement
        itself); a ProMP's mean is conditioned to end there, the whole
        movement bending as its demonstrations vary together.
        Where few demonstrations generalize poorly beyond themselves, no
        query reaches an outcome that a goal can (a movement ends at its
        goal); the learner learns how the outcome moves with the goals.

        ``via``: via-points ``(time, dof, target)`` an error learner
        learns to pass: DoF ``dof`` should be at ``target`` at ``time`` s
        (a hand at the object it grasps). The learner's first values, one
        per via-point, move them from where the movement passes at their
        time; the movement is bent through them (``Dmp.through``; a ProMP
        is conditioned on them) and the learner is told ``target`` minus
        the tracked position (``state``) at the step nearest ``time``,
        measured, so that a lag of the tracking is learned too. Its values
        after these change the goals (``goals``), told the ``error``
        function's values.

        >>> import gymnasium, numpy as np, primo, primo.gym
        >>> dmp = primo.Dmp.fit(np.linspace(0, 0.4, 21), np.zeros((21, 2)), kernels=5)
        >>> box = primo.gym.BlackBox(gymnasium.make("Reacher-v5"), dmp, kp=2.0)
        >>> power = primo.Power(box.initial(), blocks=[(box.size, 0.1, 1.0)], seed=1)
        >>> episodes = box.learn(power, budget=6, reward=lambda e: np.exp(e.episode_return), seed=0)
        >>> len(episodes), power.rollouts
        (6, 6)
        """
        if budget < 1:
            raise ValueError(f"budget: {budget}, at least 1 episode")
        plan: list = []
        if isinstance(learner, Power):
            if via:
                raise ValueError("via: for the error learners (GoldenSection, Illinois, Secant), not Power")
            if reward is None:
                raise ValueError(
                    "reward: Power needs a reward >= 0 per episode, e.g. "
                    "reward=lambda e: np.exp(-10 * np.linalg.norm(e.error))"
                )
        elif isinstance(learner, (GoldenSection, Illinois, Secant)):
            if via:
                plan = self._via_plan(via, learner, goals, context)
            elif self._error is None or (self.generalizer is None and goals is False):
                raise ValueError(
                    f"learner: {type(learner).__name__} learns a Generalizer's query from the error "
                    "(or, with goals=True, a movement's goals); this BlackBox needs a Generalizer "
                    "movement (or goals=True) and error=..."
                )
        else:
            raise TypeError(f"learner: {type(learner).__name__}, expected GoldenSection, Illinois, Secant or Power")
        episodes: list[Episode] = []
        while len(episodes) < budget:
            theta = learner.ask()
            if theta is None:  # an error learner that is done
                break
            if plan:
                episode = self._via_episode(np.atleast_1d(theta), plan, goals, context, seed)
            elif goals is not False and not isinstance(learner, Power):
                try:
                    moved = self._goal_change(theta, context, None if goals is True else goals)
                except _Rejected as e:
                    episode = _rejected(self.initial(context), str(e))
                else:
                    episode = self.episode(moved, context, seed)
            else:
                episode = self.episode(theta, context, seed)
            episodes.append(episode)
            if until_success and episode.success:
                break
            if episode.rejected and not isinstance(learner, Power):
                learner.tell_infeasible()
            elif isinstance(learner, Power):
                # A rejected roll-out: reward 0 (no weight) and, for a query,
                # a zero error (the query stays). A PoWER without a query
                # takes no error, whatever the episode measured.
                r = 0.0 if episode.rejected else float(reward(episode))  # type: ignore[misc]
                if not learner.query:
                    learner.tell(r)
                elif episode.rejected or episode.error is None:
                    learner.tell(r, np.zeros(learner.query))
                else:
                    learner.tell(r, episode.error)
            elif plan:
                told = self._via_errors(episode, plan, len(np.atleast_1d(theta)) - len(plan))
                if isinstance(learner, Secant):
                    learner.tell(told)
                else:
                    learner.tell(float(told[0]))
            elif isinstance(learner, Secant):
                learner.tell(episode.error)
            else:
                e = episode.error
                if e is None or e.shape != (1,):
                    raise ValueError(f"error: {type(learner).__name__} needs one error value, got {e}")
                learner.tell(float(e[0]))
        return episodes

    def _via_plan(self, via: Sequence[tuple[float, int, float]], learner: Any, goals: Any, context: Any) -> list:
        """``learn``'s via-points, checked: ``(time, dof, target, base)``
        each, ``base`` where the movement passes at ``time``."""
        if self._state is None:
            raise ValueError("via: the tracked positions come from state, which tracking='position' has not")
        dim = learner.dim if isinstance(learner, Secant) else 1
        n = len(via)
        if not 1 <= n <= min(dim, 8):
            raise ValueError(f"via: {n} via-points for a learner of {dim} values (1 to 8, at most one each)")
        if dim > n and (goals is False or self._error is None):
            raise ValueError(
                f"via: {n} via-points for a learner of {dim} values; the other {dim - n} change goals, "
                "which need goals=... and error=..."
            )
        if dim == n and goals is not False:
            raise ValueError(
                f"goals: the learner's {dim} values all move via-points, none is left for goals; "
                f"give it {n} + one value per goal, or leave goals out"
            )
        if goals is not False and goals is not True and len(goals) != dim - n:
            raise ValueError(f"goals: {len(goals)} DoFs for the {dim - n} values left after {n} via-points")
        times, y, _ = self._run(self.initial(context), context)
        dof = len(self._names)
        plan = []
        for i, point in enumerate(via):
            try:
                time, at, target = float(point[0]), int(point[1]), float(point[2])
                ok = len(point) == 3 and 0.0 < time < times[-1] and np.isfinite(target) and 0 <= at < dof
            except (TypeError, ValueError, IndexError):
                ok = False
            if not ok:
                raise ValueError(
                    f"via[{i}]: {point!r}; expected (time, dof, target): a time within the movement "
                    f"(0 to {times[-1]:g} s), a DoF below {dof} and a finite target"
                )
            plan.append((time, at, target, float(np.interp(time, times, y[:, at]))))
        return plan

    def _via_episode(self, values: np.ndarray, plan: list, goals: Any, context: Any, seed: Optional[int]) -> Episode:
        """The episode of the movement with the goals changed by the values
        after the via-points' (``_goal_change``), through the via-points
        moved by theirs (a DMP bent through them, a ProMP conditioned on
        them); a movement that refuses them is a rejected episode."""
        n = len(plan)
        dofs = None if goals is True else goals
        points = [(t, self._names[dof], base + v) for (t, dof, _, base), v in zip(plan, values)]
        if isinstance(self._example, ProMp):
            change = values[n:]
            index = self._goal_dofs(change, dofs) if len(change) else np.zeros(0, dtype=int)
            try:
                theta = self._conditioned(change, index, points)
            except _Rejected as e:
                return _rejected(self.initial(context), f"via-points: {e}")
            return self.episode(theta, context, seed)
        theta = self._goal_change(values[n:], context, dofs) if len(values) > n else self.initial(context)
        try:
            moved = self.dmp(theta, context)
            bent = moved.through(points, dt=self.dt)
        except ValueError as e:
            return _rejected(theta, f"via-points: {e}")
        # The bend changes the weights only: the movement's parameters in
        # theta (its last) take that change.
        theta[len(theta) - self.size :] += np.asarray(bent.params) - np.asarray(moved.params)
        return self.episode(theta, context, seed)

    def _via_errors(self, episode: Episode, plan: list, goal_values: int) -> np.ndarray:
        """``target −`` the tracked position at each via-point's step, then
        the ``error`` function's values for the ``goal_values`` goals."""
        trace = episode.trace
        if trace is None or len(trace) == 0:
            raise ValueError("via: the episode has no tracked positions")
        errors = []
        for time, dof, target, _ in plan:
            if dof >= trace.shape[1]:
                raise ValueError(f"via: DoF {dof} is not tracked (state gives {trace.shape[1]} positions)")
            errors.append(target - trace[min(int(round(time / self.dt)), len(trace) - 1), dof])
        rest = episode.error if goal_values else np.zeros(0)
        if rest is None or len(rest) != goal_values:
            raise ValueError(f"error: {goal_values} values for the goals learned, got {rest}")
        return np.r_[errors, rest]

    def _goal_dofs(self, change: np.ndarray, dofs: Optional[Sequence[int]]) -> np.ndarray:
        """The DoFs whose goals ``change`` changes: ``dofs``, or the first
        ones (``learn(..., goals=...)``), checked."""
        n = len(self._names)
        if len(change) > n:
            raise ValueError(f"goals: {len(change)} values for a movement of {n} DoFs")
        index = np.arange(len(change)) if dofs is None else np.asarray(dofs, dtype=int)
        if index.shape != change.shape or np.any((index < 0) | (index >= n)) or len(set(index)) < len(index):
            raise ValueError(f"goals: DoFs {index.tolist()} for {len(change)} values of a movement of {n} DoFs")
        return index

    def _goal_change(self, change: Any, context: Any, dofs: Optional[Sequence[int]]) -> np.ndarray:
        """The parameters of the movement with the goals of ``dofs`` (the
        first DoFs if None) changed by ``change``: a DMP's goals, or a
        ProMP's mean conditioned to end there."""
        change = np.atleast_1d(np.asarray(change, dtype=np.float64))
        index = self._goal_dofs(change, dofs)
        if isinstance(self._example, ProMp):
            return self._conditioned(change, index, [])
        theta = self.initial(context)
        dmp = self._example
        first = len(theta) - self.size + dmp.dof * dmp.kernels  # θ: weights, goals, τ
        theta[first + index] += change
        return theta

    def _conditioned(self, change: np.ndarray, index: np.ndarray, points: list) -> np.ndarray:
        """A ProMP movement's weights conditioned to end at its mean's end
        moved by ``change`` on the DoFs ``index``, then to pass ``points``
        (``(time, column, position)``), each exactly: the whole movement
        bends as the demonstrations vary together. ``_Rejected`` where the
        distribution cannot take them."""
        promp = self._example
        try:
            if len(change):
                end = promp.mean(1.0)[0]
                promp = promp.condition(1.0, {self._names[i]: float(end[i] + c) for i, c in zip(index, change)})
            for time, name, position in points:
                promp = promp.condition(time / promp.duration, {name: position})
        except ValueError as e:
            raise _Rejected(f"conditioning: {e}") from e
        return np.asarray(promp.params, dtype=np.float64)


def qpos_reset(joints: Union[slice, Sequence[int]]) -> Callable[[Any, Any, Optional[int]], np.ndarray]:
    """A reset hook for a Gymnasium MuJoCo environment that ignores reset
    options (Reacher-v5's target, for one): it resets with the seed, then
    writes the context into the positions ``joints`` of ``data.qpos`` and
    zeroes their velocities, and returns the observation. The joints are
    slide or hinge joints, whose velocity has the index of their position
    (no free or ball joint before them). Pass it as ``BlackBox(...,
    reset=primo.gym.qpos_reset(...))``.

    Args:
        joints: the indices in ``qpos`` the context sets, a slice or a
            sequence of ints, one per context value.

    Returns:
        callable: ``reset(env, context, seed)``, the observation after the
        context is set.

    >>> import gymnasium, primo.gym
    >>> env = gymnasium.make("Reacher-v5")
    >>> reset = primo.gym.qpos_reset(slice(2, 4))  # the target's x, y
    >>> obs = reset(env, [0.1, -0.05], 0)
    >>> [round(float(v), 3) for v in env.unwrapped.data.qpos[2:4]]
    [0.1, -0.05]
    """

    def reset(env: Any, context: Any, seed: Optional[int]) -> np.ndarray:
        env.reset(seed=seed)
        u = env.unwrapped
        qpos, qvel = u.data.qpos.copy(), u.data.qvel.copy()
        qpos[joints] = context
        qvel[joints] = 0
        u.set_state(qpos, qvel)
        return u._get_obs()

    return reset


def metaworld_reset(env: Any, context: Sequence[float], seed: Optional[int] = None) -> np.ndarray:
    """Resets a Metaworld v3 environment at ``context``, its task's
    ``rand_vec`` (reach-v3: object xyz then goal xyz; push-v3: puck xyz
    then goal xyz; button-press-v3: box xyz), with the goal observable,
    through Metaworld's own ``set_task``; ``seed`` is unused (Metaworld
    resets deterministically). Pass it as ``BlackBox(..., reset=primo.gym.metaworld_reset)``.
    The context ``env._random_reset_space`` draws is what Metaworld's own
    tasks use; reach-v3 and push-v3 loop forever on an object within
    0.15 m of the goal (in x, y).

    With Metaworld installed (``bench/suite/run.sh`` installs it):

    >>> from metaworld.env_dict import ALL_V3_ENVIRONMENTS  # doctest: +SKIP
    >>> import primo.gym
    >>> env = ALL_V3_ENVIRONMENTS["reach-v3"]()  # doctest: +SKIP
    >>> obs = primo.gym.metaworld_reset(env, [0.0, 0.6, 0.02, 0.05, 0.85, 0.2])  # doctest: +SKIP
    >>> [round(float(v), 2) for v in obs[-3:]]  # doctest: +SKIP
    [0.05, 0.85, 0.2]
    """
    from metaworld.types import Task

    data = {"rand_vec": np.asarray(context, dtype=np.float64), "env_cls": type(env), "partially_observable": False}
    env.set_task(Task(env_name=type(env).__name__, data=pickle.dumps(data)))
    return env.reset()[0]
