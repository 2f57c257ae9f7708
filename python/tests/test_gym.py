"""primo.gym.BlackBox on real Gymnasium tasks: Reacher-v5 (MuJoCo, joint
torques through the PD law) and, when Metaworld is installed, reach-v3
(Cartesian position steps). Skipped without gymnasium[mujoco]."""

import numpy as np
import pytest

pytest.importorskip("gymnasium")
pytest.importorskip("mujoco")

import gymnasium  # noqa: E402

import primo  # noqa: E402
import primo.gym  # noqa: E402

L1, L2 = 0.1, 0.11  # Reacher-v5's link and fingertip offset (reacher.xml)
STEPS = 40  # of Reacher's 50; the rest holds the goal


def reacher_box(movement, **settings):
    task = dict(
        tracking="pd",
        kp=2.0,
        kd=0.1,
        reset=primo.gym.qpos_reset(slice(2, 4)),  # the target's slide joints
        success=lambda env, obs, info: bool(np.linalg.norm(obs[8:10]) < 0.01),
        error=lambda env, obs, info: -obs[8:10],  # target − fingertip, the query's units
    )
    return primo.gym.BlackBox(gymnasium.make("Reacher-v5"), movement, **{**task, **settings})


def ik_demo(target):
    """A smoothstep joint path from the reset pose to analytic IK (elbow up)."""
    x, y = target
    c = (x * x + y * y - L1 * L1 - L2 * L2) / (2 * L1 * L2)
    q2 = np.arccos(np.clip(c, -1, 1))
    q1 = np.arctan2(y, x) - np.arctan2(L2 * np.sin(q2), L1 + L2 * np.cos(q2))
    s = np.linspace(0, 1, STEPS + 1)
    s = s * s * (3 - 2 * s)
    t = np.arange(STEPS + 1) * 0.02
    return t, s[:, None] * np.array([q1, q2])


def fit(target):
    t, y = ik_demo(target)
    return primo.Dmp.fit(t, y, names=["joint0", "joint1"], kernels=10, margin=1)


DEMOS = [(0.12, 0.12), (-0.12, 0.12), (-0.12, -0.12), (0.12, -0.12)]


@pytest.fixture(scope="module")
def generalizer():
    return primo.Generalizer([(np.array(c), fit(c)) for c in DEMOS], method="gpr")


def test_the_demonstrated_movement_succeeds_at_its_context():
    box = reacher_box(fit(DEMOS[0]))
    episode = box.episode(box.initial(), context=DEMOS[0], seed=0)
    assert episode.success is True
    assert np.linalg.norm(episode.error) < 0.01
    assert episode.steps == 50  # Reacher's time limit cuts the hold
    assert episode.episode_return < 0  # Reacher's reward: minus distance and effort


def test_a_wrong_movement_fails_and_its_error_points_at_the_target():
    box = reacher_box(fit(DEMOS[0]))
    episode = box.episode(box.initial(), context=DEMOS[1], seed=0)
    assert episode.success is False
    # The fingertip ends near DEMOS[0]: the error is the way to DEMOS[1].
    assert np.allclose(episode.error, np.subtract(DEMOS[1], DEMOS[0]), atol=0.02)


def test_secant_learns_the_query_without_glue(generalizer):
    box = reacher_box(generalizer)
    context = np.array([0.05, 0.16])  # inside the demonstrations' square
    q0 = box.query(context)
    learner = primo.Secant(low=q0 - 0.1, high=q0 + 0.1, desired=q0, precision=0.002, max_rollouts=20)
    episodes = box.learn(learner, context, budget=20, seed=0)
    assert 1 <= len(episodes) <= 20 and learner.rollouts >= len(episodes) - 1
    errors = [np.linalg.norm(e.error) for e in episodes]
    assert episodes[-1].success, errors
    assert errors[-1] < errors[0]


def test_power_learns_query_and_shape_together(generalizer):
    box = reacher_box(generalizer)
    context = np.array([0.05, 0.16])
    d, n = box.query_dim, box.size
    power = primo.Power(
        box.initial(context),
        blocks=[(d, 1e-4, 1.0), (n - 3, 1.0, 1.0), (3, 1e-6, 1.0)],
        seed=3,
        query_gain=0.5,
        query=d,
    )
    episodes = box.learn(
        power, context, budget=12, reward=lambda e: float(np.exp(-20 * np.linalg.norm(e.error))), seed=0
    )
    assert len(episodes) == power.rollouts + (1 if episodes[-1].success else 0)
    assert all(e.theta.shape == (d + n,) for e in episodes)


def at_rest(env, obs, info):
    """The fingertip within 1 cm of the target, the joints under 0.5 rad/s."""
    return bool(np.linalg.norm(obs[8:10]) < 0.01 and np.abs(obs[6:8]).max() < 0.5)


def test_secant_learns_the_goals_where_no_query_reaches(generalizer):
    # Beyond the demonstrations' square the generalized movement misses
    # and no query nearby comes to rest on the target; the goals (joint
    # angles) move the fingertip anywhere in reach.
    box = reacher_box(generalizer, success=at_rest)
    context = np.array([-0.02, -0.19])
    q = box.query(context)
    by_query = box.learn(primo.Secant(low=q - 0.1, high=q + 0.1, desired=q), context, budget=30, seed=0)
    assert not by_query[-1].success
    learner = primo.Secant(low=[-np.pi] * 2, high=[np.pi] * 2, desired=[0.0, 0.0], max_rollouts=30)
    episodes = box.learn(learner, context, budget=30, seed=0, goals=True)
    assert episodes[-1].success, [np.linalg.norm(e.error) for e in episodes]
    first = box.dmp(episodes[0].theta).params
    assert np.allclose(first, box.dmp(box.query(context)).params)  # the generalized movement
    changed = box.dmp(episodes[-1].theta).params != first
    assert changed.sum() == 2 and changed[-3:-1].all()  # its two goals, not its weights or τ
    # A plain DMP's goals too; more values than DoFs are refused.
    plain = reacher_box(fit(DEMOS[0]), success=at_rest)
    learner = primo.Secant(low=[-np.pi] * 2, high=[np.pi] * 2, desired=[0.0, 0.0], max_rollouts=30)
    assert plain.learn(learner, DEMOS[1], budget=30, seed=0, goals=True)[-1].success
    with pytest.raises(ValueError, match="goals: 3 values for a movement of 2 DoFs"):
        plain.learn(primo.Secant(low=[-1] * 3, high=[1] * 3, desired=[0] * 3), DEMOS[1], goals=True)
    # The DoFs listed, one per value: joint1's goal alone, told the y error.
    single = reacher_box(fit(DEMOS[0]), error=lambda env, obs, info: -obs[9:10])
    one = single.learn(primo.GoldenSection(low=-1, high=1, desired=0.5), DEMOS[1], budget=1, goals=[1])
    assert np.allclose(single.dmp(one[0].theta).goal - fit(DEMOS[0]).goal, [0.0, 0.5])
    with pytest.raises(ValueError, match=r"goals: DoFs \[2\]"):
        single.learn(primo.GoldenSection(low=-1, high=1, desired=0.5), DEMOS[1], goals=[2])


def test_secant_learns_via_points_the_arm_passes(generalizer):
    # joint0 should be 0.3 rad beyond its demonstrated path halfway: the
    # movement is bent through a via-point, which the learner moves until
    # the measured joint (lagging behind the PD law's setpoint) is there.
    dmp = fit(DEMOS[0])
    box = reacher_box(dmp)
    times, y = dmp.run(dt=box.dt)
    target = float(np.interp(0.4, times, y[:, 0])) + 0.3
    learner = primo.Secant(low=[-1.0], high=[1.0], desired=[0.0], precision=0.005, max_rollouts=20)
    episodes = box.learn(learner, DEMOS[0], budget=20, seed=0, until_success=False, via=[(0.4, 0, target)])
    assert learner.status == "converged", learner.status
    measured = [target - e.trace[20, 0] for e in episodes]  # step 20 starts at 0.4 s
    assert abs(measured[-1]) < 0.005 and abs(measured[1]) < abs(measured[0]), measured
    assert np.allclose(episodes[0].theta, dmp.params)  # the first ask: the movement itself
    assert episodes[-1].trace.shape == (episodes[-1].steps, 2)
    # Via-points and goals together on a generalized movement: the
    # fingertip comes to rest on a target beyond the demonstrations while
    # joint1 passes 0.5 rad halfway.
    box = reacher_box(generalizer, success=at_rest)
    context = np.array([-0.02, -0.19])
    learner = primo.Secant(low=[-np.pi] * 3, high=[np.pi] * 3, desired=[0.0] * 3, precision=0.005, max_rollouts=40)
    episodes = box.learn(learner, context, budget=40, seed=0, goals=True, via=[(0.4, 1, 0.5)])
    # one via-point on joint1, then the goals of joint0 and joint1 (the
    # error's two values)
    assert episodes[-1].success, [e.error for e in episodes]
    assert abs(0.5 - episodes[-1].trace[20, 1]) < 0.05


def test_via_points_are_checked_before_anything_runs(generalizer):
    box = reacher_box(fit(DEMOS[0]))
    one = primo.Secant(low=[-1.0], high=[1.0], desired=[0.0])
    two = primo.Secant(low=[-1.0] * 2, high=[1.0] * 2, desired=[0.0] * 2)
    power = primo.Power(box.initial(), blocks=[(box.size, 0.1, 1.0)], seed=1)
    cases = [
        (one, [(0.4, 0, 0.1), (0.5, 0, 0.1)], {}, "2 via-points for a learner of 1 values"),
        (two, [(0.4, 0, 0.1)], {}, "the other 1 change goals, which need goals="),
        (one, [(0.9, 0, 0.1)], {}, r"via\[0\]: .*a time within the movement \(0 to 0.8 s\)"),
        (one, [(0.4, 2, 0.1)], {}, "a DoF below 2"),
        (one, [(0.4, 0)], {}, "expected \\(time, dof, target\\)"),
        (one, [(0.4, 0, 0.1)], {"goals": True}, "none is left for goals"),
        (two, [(0.4, 0, 0.1)], {"goals": [0, 1]}, "goals: 2 DoFs for the 1 values left after 1 via-points"),
        (power, [(0.4, 0, 0.1)], {"reward": lambda e: 1.0}, "via: for the error learners"),
    ]
    for learner, via, extra, message in cases:
        with pytest.raises(ValueError, match=message):
            box.learn(learner, DEMOS[0], via=via, **extra)
    position = reacher_box(fit(DEMOS[0]), tracking="position")
    with pytest.raises(ValueError, match="tracking='position' has not"):
        position.learn(one, DEMOS[0], via=[(0.4, 0, 0.1)])


def test_theta_forms_agree(generalizer):
    box = reacher_box(generalizer)
    context = np.array([0.0, 0.15])
    q = box.query(context)
    full = box.dmp(np.r_[q, np.zeros(box.size)]).params
    assert np.allclose(box.dmp(q).params, full)
    assert np.allclose(box.dmp(np.zeros(box.size), context).params, full)


def test_stop_on_success_ends_the_episode_early():
    box = reacher_box(fit(DEMOS[0]), stop_on_success=True)
    episode = box.episode(box.initial(), context=DEMOS[0], seed=0)
    assert episode.success and episode.steps < 50


def test_bad_input_is_refused_in_the_users_terms(generalizer):
    with pytest.raises(TypeError, match="action space is Discrete"):
        primo.gym.BlackBox(gymnasium.make("CartPole-v1"), fit(DEMOS[0]))
    with pytest.raises(ValueError, match="3 DoFs .* but the action has 2 values"):
        t = np.linspace(0, 1, 11)
        primo.gym.BlackBox(gymnasium.make("Reacher-v5"), primo.Dmp.fit(t, np.zeros((11, 3)), kernels=5))
    with pytest.raises(ValueError, match="tracking: 'torque'"):
        reacher_box(fit(DEMOS[0]), tracking="torque")
    box = reacher_box(generalizer)
    with pytest.raises(ValueError, match="needs the context"):
        box.episode(np.zeros(box.size))
    with pytest.raises(ValueError, match=r"theta: shape \(5,\)"):
        box.episode(np.zeros(5), context=DEMOS[0])
    with pytest.raises(ValueError, match="Power needs a reward"):
        box.learn(primo.Power(box.initial(DEMOS[0]), blocks=[(box.query_dim + box.size, 1.0, 1.0)]), DEMOS[0])
    plain = reacher_box(fit(DEMOS[0]))
    with pytest.raises(ValueError, match="needs a Generalizer movement"):
        plain.learn(primo.Secant(low=[0, 0], high=[1, 1], desired=[0.5, 0.5]), DEMOS[0])


def test_metaworld_reach_succeeds_with_the_scripted_demonstration():
    pytest.importorskip("metaworld")
    import warnings

    from metaworld.env_dict import ALL_V3_ENVIRONMENTS
    from metaworld.policies import SawyerReachV3Policy

    env = ALL_V3_ENVIRONMENTS["reach-v3"]()
    context = [0.0, 0.65, 0.02, -0.05, 0.85, 0.2]  # object xyz, goal xyz
    obs = primo.gym.metaworld_reset(env, context)
    policy, hand = SawyerReachV3Policy(), [obs[:3]]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the policy's "Constant(s) may be too high"
        for _ in range(120):
            obs = env.step(policy.get_action(obs))[0]
            hand.append(obs[:3])
    dmp = primo.Dmp.fit(np.arange(121) * env.dt, np.array(hand), names=["x", "y", "z"], kernels=20, margin=1)
    box = primo.gym.BlackBox(
        env, dmp, tracking="delta", kp=50.0, state=lambda env, obs: (obs[:3], None), reset=primo.gym.metaworld_reset
    )
    episode = box.episode(box.initial(), context)
    assert episode.success is True and episode.steps == 130
    # Another goal, the same movement: Metaworld's flag stays unset.
    assert box.episode(box.initial(), [0.0, 0.65, 0.02, 0.1, 0.9, 0.05]).success is False


def test_golden_section_learns_a_one_value_query():
    # The target on the line y = 0.12; the query is its x.
    g = primo.Generalizer([(x, fit((x, 0.12))) for x in (-0.12, 0.0, 0.12)])
    box = reacher_box(g, query=lambda c: c[0], error=lambda env, obs, info: -obs[8:9])
    context = (0.07, 0.12)
    learner = primo.GoldenSection(low=0.0, high=0.15, desired=0.07, max_rollouts=20)
    episodes = box.learn(learner, context, budget=20, seed=0)
    assert episodes[-1].success or learner.status == "converged", [e.error for e in episodes]
    assert abs(episodes[-1].error[0]) < abs(episodes[0].error[0])
    assert all(e.theta.shape == (1,) for e in episodes)


class Point(gymnasium.Env):
    """A point on a line whose action is its velocity, or its position."""

    def __init__(self, velocity=True):
        self.velocity, self.dt, self.x = velocity, 0.01, 0.0
        self.action_space = gymnasium.spaces.Box(-5.0, 5.0, shape=(1,))
        self.observation_space = gymnasium.spaces.Box(-5.0, 5.0, shape=(1,))

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.x = 0.0
        return np.array([self.x]), {}

    def step(self, action):
        self.x = self.x + action[0] * self.dt if self.velocity else action[0]
        return np.array([self.x]), -abs(self.x - 0.8), False, False, {}


@pytest.mark.parametrize("tracking", ["velocity", "position"])
def test_velocity_and_position_actions_follow_the_movement(tracking):
    t = np.linspace(0.0, 1.0, 101)
    s = t * t * (3 - 2 * t)
    dmp = primo.Dmp.fit(t, 0.8 * s, kernels=20)
    env = Point(velocity=tracking == "velocity")
    box = primo.gym.BlackBox(env, dmp, tracking=tracking, kp=5.0, hold=0,
                             state=lambda env, obs: (obs, None),
                             error=lambda env, obs, info: 0.8 - obs)
    episode = box.episode(box.initial())
    assert episode.steps == 100 and episode.success is None
    assert abs(episode.error[0]) < 1e-3


def test_parameters_the_dmp_refuses_are_a_rejected_episode(generalizer):
    box = reacher_box(generalizer)
    theta = box.initial(DEMOS[0])
    theta[-1] = -1.0  # Δτ: a negative duration
    episode = box.episode(theta, DEMOS[0])
    assert episode.rejected and "tau" in episode.rejected
    assert episode.steps == 0 and episode.success is False and np.isnan(episode.episode_return)
    d, n = box.query_dim, box.size
    power = primo.Power(theta, blocks=[(d, 1e-4, 1.0), (n, 1e-6, 1.0)], query_gain=0.5, query=d)
    episodes = box.learn(power, DEMOS[0], budget=4, reward=lambda e: 1.0)
    assert all(e.rejected for e in episodes) and power.rollouts == 4


@pytest.fixture(scope="module")
def promp():
    """A ProMP of the four demonstrations: its mean ends between them."""
    return primo.ProMp.fit([ik_demo(c) for c in DEMOS], names=["joint0", "joint1"], kernels=10)


def test_a_promp_is_a_movement_of_its_weights(promp):
    box = reacher_box(promp)
    assert (box.size, box.query_dim) == (20, 0)
    assert np.array_equal(box.initial(), promp.params)
    moved = box.promp(box.initial() + 0.1)
    assert np.allclose(moved.mean([0.5, 1.0]), promp.mean([0.5, 1.0]) + 0.1, atol=1e-6)
    assert np.allclose(moved.variance(0.5), promp.variance(0.5))
    # Conditioned to end at a demonstration's joint angles, its mean is
    # that demonstration's reach.
    goal = ik_demo(DEMOS[0])[1][-1]
    there = reacher_box(promp.condition(1.0, {"joint0": goal[0], "joint1": goal[1]}))
    episode = there.episode(there.initial(), context=DEMOS[0], seed=0)
    assert episode.success is True and episode.steps == 50, episode.error
    assert not box.episode(box.initial(), context=DEMOS[0], seed=0).success  # the mean ends between them
    with pytest.raises(TypeError, match="movement is a ProMp; see promp"):
        box.dmp(box.initial())
    with pytest.raises(TypeError, match="movement is a DMP; see dmp"):
        reacher_box(fit(DEMOS[0])).promp(np.zeros(20))
    with pytest.raises(ValueError, match=r"theta: shape \(3,\), the ProMP has 20 parameters"):
        box.episode(np.zeros(3))
    theta = box.initial()
    theta[4] = np.nan
    rejected = box.episode(theta)
    assert rejected.rejected and "not a finite number" in rejected.rejected and rejected.steps == 0


def test_secant_learns_a_promps_goals_and_via_points(promp):
    # Beyond the demonstrations' square: the ProMP's mean conditioned on
    # the learned end comes to rest on the target.
    box = reacher_box(promp, success=at_rest)
    context = np.array([-0.02, -0.19])
    learner = primo.Secant(low=[-np.pi] * 2, high=[np.pi] * 2, desired=[0.0, 0.0], max_rollouts=30)
    episodes = box.learn(learner, context, budget=30, seed=0, goals=True)
    assert episodes[-1].success, [np.linalg.norm(e.error) for e in episodes]
    assert np.allclose(episodes[0].theta, promp.params)  # the first ask: the mean itself
    end = box.promp(episodes[-1].theta).mean(1.0)[0] - promp.mean(1.0)[0]
    assert np.linalg.norm(end) > 0.1
    # A via-point on joint0 halfway, learned until the measured joint
    # passes it.
    box = reacher_box(promp)
    target = float(promp.mean(0.4 / promp.duration)[0, 0]) + 0.3
    learner = primo.Secant(low=[-1.0], high=[1.0], desired=[0.0], precision=0.005, max_rollouts=20)
    episodes = box.learn(learner, DEMOS[0], budget=20, seed=0, until_success=False, via=[(0.4, 0, target)])
    assert learner.status == "converged", learner.status
    measured = [target - e.trace[20, 0] for e in episodes]
    assert abs(measured[-1]) < 0.005 and abs(measured[0]) > 0.2, measured


def test_power_learns_a_promps_weights(promp):
    box = reacher_box(promp)
    power = primo.Power(box.initial(), blocks=[(box.size, 0.3, 1.0)], seed=1)
    episodes = box.learn(
        power, [0.05, 0.16], budget=30, reward=lambda e: float(np.exp(-20 * np.linalg.norm(e.error))), seed=0
    )
    errors = [np.linalg.norm(e.error) for e in episodes]
    assert episodes[-1].success and errors[0] > 0.1, errors
    assert all(e.theta.shape == (20,) for e in episodes)
