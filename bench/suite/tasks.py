"""The suite's tasks: each makes its environment, draws contexts, records
demonstrations at other contexts and builds the primo.gym.BlackBox that
runs its episodes.

Choices, made once as a user would (docs in bench/suite/README.md):
contexts are seeded draws from the task's own reset distribution (seed
1234 held out, seed 7 for the demonstrations); the demonstrations are
few (reach 3, push 4, button 2, Reacher 4) so that the generalized
movement alone leaves room to learn; DMPs have 20 kernels and margin 1,
the ProMP of the same demonstrations 20 kernels.
"""

from __future__ import annotations

import json
import warnings
from dataclasses import dataclass
from typing import Any, Callable, Optional

import numpy as np

import primo
import primo.gym

HELD_OUT_SEED = 1234
DEMO_SEED = 7
KERNELS = 20


def unscaled(dmp: primo.Dmp) -> primo.Dmp:
    """The same DMP without amplitude scaling (weights times g − y0 on
    scaled DoFs), so that demos Dmp.fit scaled differently generalize
    together. Goes for Dmp.fit(..., scaling="none"), merged from main
    with issue 30 but not yet in a wheel the suite was run on."""
    j = json.loads(dmp.to_json())
    m = j["dmp"]
    for i, scaled in enumerate(m["scaled"]):
        if scaled:
            a = m["goal"][i] - m["start"][i]
            m["weights"][i] = [w * a for w in m["weights"][i]]
            m["scaled"][i] = False
    return primo.Dmp.from_json(json.dumps(j))


@dataclass
class Problem:
    """What a method learns on: the episodes' ``box``, the success
    radius ``tolerance`` (m or rad, which scales rewards), the query's
    bounds ``low``, ``high`` (the box contexts are drawn from) and the
    robot's ``limits`` (low, high) of the DMP's DoFs (m or rad); for
    error learning on the movement, ``goal_box`` (``box`` with the error
    of the goals), the DoFs whose goals its error's values measure,
    ``goal_dofs``, and ``via(context, times, y)``, the via-points ``(time,
    dof, target)`` of a movement that passes ``y`` at ``times`` (None:
    none); ``promp_box`` and ``promp_goal_box``, the same two boxes
    running a ProMP of the same demonstrations."""

    box: primo.gym.BlackBox
    tolerance: float
    low: np.ndarray
    high: np.ndarray
    limits: tuple[np.ndarray, np.ndarray]
    goal_dofs: tuple[int, ...]
    goal_box: primo.gym.BlackBox
    promp_box: primo.gym.BlackBox
    promp_goal_box: primo.gym.BlackBox
    via: Optional[Callable[[Any, np.ndarray, np.ndarray], list]] = None


@dataclass
class Task:
    """A contextual task: ``make()`` its environment, ``contexts(env, n,
    seed)``, ``space(env) -> (low, high)`` of the contexts,
    ``query(context)``, ``demo(env, context) -> (t, y)``, ``box(env,
    generalizer, query, error=None)`` (the task's error unless another
    is given), ``tolerance`` (the success radius), ``demos``
    (how many), the DMPs' ``columns``, ``limits(env) -> (low, high)``
    of their DoFs, ``goal_dofs``, the DoF whose goal each error value
    measures (None: the first ones), ``goal_error(env, obs)``, the error
    those values are (None: the query's error) and ``via``, the
    via-points of error learning on the movement (``Problem``)."""

    name: str
    make: Callable[[], Any]
    contexts: Callable[[Any, int, int], list]
    space: Callable[[Any], tuple[np.ndarray, np.ndarray]]
    query: Callable[[Any], np.ndarray]
    demo: Callable[[Any, Any], tuple[np.ndarray, np.ndarray]]
    box: Callable[..., primo.gym.BlackBox]
    tolerance: float
    demos: int
    columns: tuple[str, ...]
    limits: Callable[[Any], tuple[np.ndarray, np.ndarray]]
    goal_dofs: Optional[tuple[int, ...]] = None
    goal_error: Optional[Callable[[Any, np.ndarray], np.ndarray]] = None
    via: Optional[Callable[[Any, np.ndarray, np.ndarray], list]] = None

    def demonstrations(self, env: Any) -> list:
        """``(context, t, y)`` of each demonstration."""
        return [(c, *self.demo(env, c)) for c in self.contexts(env, self.demos, DEMO_SEED)]

    def problem(self, env: Any, regression: str = "lwr") -> Problem:
        low, high = self.space(env)
        demos = self.demonstrations(env)
        names = list(self.columns)
        examples = [
            (self.query(c), unscaled(primo.Dmp.fit(t, y, names=names, kernels=KERNELS, margin=1)))
            for c, t, y in demos
        ]
        generalizer = primo.Generalizer(examples, method=regression)
        promp = primo.ProMp.fit([(t, y) for _, t, y in demos], names=names, kernels=KERNELS)
        boxes = []
        for movement in (generalizer, promp):
            box = self.box(env, movement, self.query)
            boxes += [box, box if self.goal_error is None else self.box(env, movement, self.query, self.goal_error)]
        dofs = self.goal_dofs or tuple(range(len(self.query(low))))
        return Problem(
            boxes[0], self.tolerance, self.query(low), self.query(high), self.limits(env), dofs, *boxes[1:], self.via
        )


# Metaworld: the context is the task's rand_vec, the DMP moves the hand
# (obs[:3]) by position steps, as fancy_gym's Metaworld controller does.

SCRIPT_STEPS = {"reach-v3": 120, "push-v3": 200, "button-press-v3": 150}


def _metaworld_env(name: str) -> Callable[[], Any]:
    def make() -> Any:
        from metaworld.env_dict import ALL_V3_ENVIRONMENTS

        return ALL_V3_ENVIRONMENTS[name]()

    return make


def _metaworld_space(env: Any) -> tuple[np.ndarray, np.ndarray]:
    return env._random_reset_space.low, env._random_reset_space.high


def _metaworld_limits(env: Any) -> tuple[np.ndarray, np.ndarray]:
    """The hand's box (Metaworld clips its mocap into it), then the
    gripper's command, -1 to 1."""
    return np.r_[env.mocap_low, -1.0], np.r_[env.mocap_high, 1.0]


def _metaworld_contexts(env: Any, n: int, seed: int) -> list:
    rng = np.random.default_rng(seed)
    space = env._random_reset_space
    out = []
    while len(out) < n:
        v = rng.uniform(space.low, space.high)
        # reach and push reset forever on an object within 0.15 m of the goal
        if len(v) == 6 and np.linalg.norm(v[:2] - v[3:5]) < 0.15:
            continue
        out.append(v)
    return out


def _scripted(name: str, grip: bool) -> Callable[[Any, Any], tuple[np.ndarray, np.ndarray]]:
    def demo(env: Any, context: Any) -> tuple[np.ndarray, np.ndarray]:
        from metaworld import policies

        policy = {
            "reach-v3": policies.SawyerReachV3Policy,
            "push-v3": policies.SawyerPushV3Policy,
            "button-press-v3": policies.SawyerButtonPressV3Policy,
        }[name]()
        obs = primo.gym.metaworld_reset(env, context)
        rows = []
        action = np.zeros(4)
        for _ in range(SCRIPT_STEPS[name] + 1):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # "Constant(s) may be too high"
                action = policy.get_action(obs)
            rows.append(np.r_[obs[:3], action[3]] if grip else obs[:3].copy())
            obs = env.step(action)[0]
        return np.arange(len(rows)) * env.dt, np.array(rows)

    return demo


def _metaworld_box(task_error: Callable[[Any, np.ndarray], np.ndarray]) -> Callable[..., primo.gym.BlackBox]:
    def box(env: Any, movement: Any, query: Callable, error: Optional[Callable] = None) -> primo.gym.BlackBox:
        error = error or task_error
        return primo.gym.BlackBox(
            env,
            movement,
            query=query,
            tracking="delta",
            kp=50.0,  # 1 cm off is half the largest step
            state=lambda env, obs: (obs[:3], None),
            reset=primo.gym.metaworld_reset,
            error=lambda env, obs, info: error(env, obs),
            hold=60,
        )

    return box


def _reach_error(env: Any, obs: np.ndarray) -> np.ndarray:
    # Success is measured at the finger pads' centre, 4.5 cm below the hand.
    return obs[36:39] - env.tcp_center


def _push_error(env: Any, obs: np.ndarray) -> np.ndarray:
    # Only the goal part of the query (puck xy, goal xy) is measurable.
    return np.r_[0.0, 0.0, _push_miss(env, obs)]


def _push_miss(env: Any, obs: np.ndarray) -> np.ndarray:
    """Goal − puck, xy: what the hand's x and y goals move."""
    return obs[36:38] - obs[4:6]


def _push_grasp(context: Any, times: np.ndarray, y: np.ndarray) -> list:
    """The hand over the puck where the movement comes down to it (the
    first time its z is within 5 mm of its lowest), in x and y."""
    at = float(times[np.argmax(y[:, 2] <= y[:, 2].min() + 0.005)])
    return [(at, 0, float(context[0])), (at, 1, float(context[1]))]


def _button_error(env: Any, obs: np.ndarray) -> np.ndarray:
    return obs[4:6] - env.tcp_center[:2]


# Reacher-v5: the target's xy is the context; joint-space DMPs from
# analytic inverse kinematics, tracked by a PD law on the torques.

L1, L2 = 0.1, 0.11  # link 0 and the fingertip's offset on link 1 (reacher.xml)
REACHER_STEPS = 40  # of the episode's 50


def _reacher_make() -> Any:
    import gymnasium

    return gymnasium.make("Reacher-v5")


def _reacher_contexts(env: Any, n: int, seed: int) -> list:
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < n:  # Reacher's own draw: uniform in the 0.2 m disc
        g = rng.uniform(-0.2, 0.2, 2)
        if np.linalg.norm(g) < 0.2:
            out.append(g)
    return out


def _reacher_space(env: Any) -> tuple[np.ndarray, np.ndarray]:
    return np.full(2, -0.2), np.full(2, 0.2)


def _reacher_limits(env: Any) -> tuple[np.ndarray, np.ndarray]:
    """joint1's range (reacher.xml); joint0 has none: one turn."""
    return np.array([-np.pi, -3.0]), np.array([np.pi, 3.0])


def _reacher_demo(env: Any, context: Any) -> tuple[np.ndarray, np.ndarray]:
    x, y = context
    c = (x * x + y * y - L1 * L1 - L2 * L2) / (2 * L1 * L2)
    q2 = np.arccos(np.clip(c, -1, 1))
    q1 = np.arctan2(y, x) - np.arctan2(L2 * np.sin(q2), L1 + L2 * np.cos(q2))
    q1 = (q1 + np.pi) % (2 * np.pi) - np.pi  # the shorter way round from 0
    s = np.linspace(0, 1, REACHER_STEPS + 1)
    s = s * s * (3 - 2 * s)
    return np.arange(REACHER_STEPS + 1) * env.unwrapped.dt, s[:, None] * np.array([q1, q2])


def _reacher_success(env: Any, obs: np.ndarray, info: dict) -> bool:
    """Reacher has no flag: the fingertip within 1 cm of the target at
    rest (joint speeds under 0.5 rad/s), not swinging through it."""
    return bool(np.linalg.norm(obs[8:10]) < 0.01 and np.abs(obs[6:8]).max() < 0.5)


def _reacher_box(env: Any, movement: Any, query: Callable, error: Optional[Callable] = None) -> primo.gym.BlackBox:
    return primo.gym.BlackBox(
        env,
        movement,
        query=query,
        tracking="pd",
        kp=2.0,
        kd=0.1,
        reset=primo.gym.qpos_reset(slice(2, 4)),  # the target's slide joints
        success=_reacher_success,
        error=(lambda env, obs, info: error(env, obs)) if error else (lambda env, obs, info: -obs[8:10]),
        hold=10,
    )


TASKS = {
    "reach-v3": Task(
        "reach-v3", _metaworld_env("reach-v3"), _metaworld_contexts, _metaworld_space, lambda v: v[3:6],
        _scripted("reach-v3", False), _metaworld_box(_reach_error), 0.05, 3, ("x", "y", "z"), _metaworld_limits,
    ),
    "push-v3": Task(
        "push-v3", _metaworld_env("push-v3"), _metaworld_contexts, _metaworld_space, lambda v: np.r_[v[0:2], v[3:5]],
        _scripted("push-v3", True), _metaworld_box(_push_error), 0.05, 4, ("x", "y", "z", "grip"), _metaworld_limits,
        # the puck's miss is the hand's x and y goals' to fix; the hand
        # must come down over the puck first
        (0, 1), _push_miss, _push_grasp,
    ),
    "button-press-v3": Task(
        "button-press-v3", _metaworld_env("button-press-v3"), _metaworld_contexts, _metaworld_space, lambda v: v[0:2],
        _scripted("button-press-v3", False), _metaworld_box(_button_error), 0.02, 2, ("x", "y", "z"),
        _metaworld_limits,
    ),
    "Reacher-v5": Task(
        "Reacher-v5", _reacher_make, _reacher_contexts, _reacher_space, np.asarray,
        _reacher_demo, _reacher_box, 0.01, 4, ("joint0", "joint1"), _reacher_limits,
    ),
}
