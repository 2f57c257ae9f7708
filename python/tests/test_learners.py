"""The learners: convergence, determinism, pickling mid-run, errors."""

import pickle

import numpy as np
import pytest

import primo


@pytest.mark.parametrize("cls, most", [(primo.GoldenSection, 12), (primo.Illinois, 6)])
def test_scalar_learners_converge(cls, most):
    learner = cls(0.0, 2.0, 0.5, precision=1e-3, max_rollouts=40)
    while (q := learner.ask()) is not None:
        learner.tell(0.5 - q * q)
    assert learner.status == "converged" and learner.done
    query, error = learner.best
    assert abs(query - 0.5**0.5) < 1e-3 and abs(error) < 1e-3
    assert learner.rollouts <= most


@pytest.mark.parametrize("cls", [primo.GoldenSection, primo.Illinois])
def test_scalar_learners_pickle_mid_run(cls):
    learner = cls(0.1, 1.5, 0.5, precision=1e-4, max_rollouts=30)
    for _ in range(3):
        learner.tell(0.3 - 0.5 * learner.ask())
    copy = pickle.loads(pickle.dumps(learner))
    assert copy.ask() == learner.ask() and copy.bracket == learner.bracket
    assert copy.rollouts == 3 and copy.best == learner.best


@pytest.mark.parametrize("cls", [primo.GoldenSection, primo.Illinois])
def test_scalar_learners_narrow_past_an_infeasible_query(cls):
    # Queries above 1.2 cannot be rolled out (the trial fails); the root,
    # sqrt(0.5), lies below: the search narrows past them and converges.
    learner = cls(0.0, 2.0, 0.5, precision=1e-3, max_rollouts=40)
    infeasible = 0
    while (q := learner.ask()) is not None:
        if q > 1.2:
            infeasible += 1
            learner.tell_infeasible()
        else:
            learner.tell(0.5 - q * q)
    assert infeasible > 0 and learner.status == "converged"
    assert abs(learner.best[0] - 0.5**0.5) < 1e-3
    # An infeasible first query, the desired one, ends the search.
    first = cls(0.0, 2.0, 1.5)
    assert first.tell_infeasible() == "infeasible" and first.done
    with pytest.raises(ValueError):
        first.tell_infeasible()
    # What it was told, infeasible queries among it, survives a pickle.
    mid = cls(0.0, 2.0, 0.5, precision=1e-4)
    mid.tell(0.5 - 0.25)
    while mid.ask() <= 1.2:
        mid.tell(0.5 - mid.ask() ** 2)
    mid.tell_infeasible()
    copy = pickle.loads(pickle.dumps(mid))
    assert copy.ask() == mid.ask() and copy.bracket == mid.bracket
    assert copy.rollouts == mid.rollouts


def test_secant_steps_back_from_an_infeasible_query():
    learner = primo.Secant([-2], [2], [0.2], gain=4.0, precision=1e-4, max_rollouts=30)
    while (q := learner.ask()) is not None:
        if q[0] > 0.9:
            learner.tell_infeasible()
        else:
            learner.tell([0.6 - q[0]])
    assert learner.status == "converged"
    assert abs(learner.best[0][0] - 0.6) < 1e-4
    copy = pickle.loads(pickle.dumps(learner))
    np.testing.assert_array_equal(copy.best[0], learner.best[0])
    assert primo.Secant([-2], [2], [0.2]).tell_infeasible() == "infeasible"


def test_secant_keeps_running_where_one_wild_update_stalled_it():
    # Issue 28: these errors, told to the first five asks, bounced the
    # queries between the box's corners and ended "stalled".
    learner = primo.Secant([-0.5, -0.5], [0.5, 0.5], desired=[0.2279, -0.3578])
    told = [
        [0.3931, -0.0501],
        [0.3639, -0.264],
        [0.3199, -0.613],
        [0.3725, -0.5377],
        [0.3199, -0.613],
    ]
    asked = []
    for error in told:
        asked.append(tuple(learner.ask()))
        assert learner.tell(error) == "running"
    asked.append(tuple(learner.ask()))
    assert len(set(asked)) == len(asked)
    best, _ = learner.best
    # After its second roll-out, each step from the best is at most half
    # the one before.
    lengths = [np.abs(np.subtract(q, best)).max() for q in asked[2:]]
    assert all(b <= 0.5 * a * (1 + 1e-6) for a, b in zip(lengths, lengths[1:]))


def test_scalar_learner_errors():
    with pytest.raises(ValueError):
        primo.GoldenSection(1.0, 0.0, 0.5)
    learner = primo.GoldenSection(0.0, 1.0, 0.5)
    with pytest.raises(ValueError, match="not a finite"):
        learner.tell(float("nan"))
    assert learner.rollouts == 0


def test_secant_converges_where_a_fixed_gain_diverges():
    a = np.array([[2.5, 0.5], [-0.4, 0.7]])
    b = np.array([0.1, -0.05])
    desired = np.array([0.5, 0.3])
    learner = primo.Secant([-2, -2], [2, 2], desired, precision=1e-4, max_rollouts=20)
    while (q := learner.ask()) is not None:
        learner.tell(desired - (a @ q + b))
    assert learner.status == "converged" and learner.rollouts <= 6
    query, error = learner.best
    assert np.abs(error).max() < 1e-4 and learner.gain.shape == (2, 2)
    copy = pickle.loads(pickle.dumps(learner))
    np.testing.assert_array_equal(copy.best[0], query)
    np.testing.assert_array_equal(copy.gain, learner.gain)
    with pytest.raises(ValueError, match="1 to 4"):
        primo.Secant(np.zeros(5), np.ones(5), np.full(5, 0.5))
    fresh = primo.Secant([-2, -2], [2, 2], desired)
    with pytest.raises(ValueError, match="3 values, the query has 2"):
        fresh.tell([1.0, 2.0, 3.0])
    # The paper's eq. 10 with K = I fixed: I − A has an eigenvalue −1.38.
    fixed = primo.Secant([-2, -2], [2, 2], desired, precision=1e-4, max_rollouts=20, rule="fixed")
    while (q := fixed.ask()) is not None:
        fixed.tell(desired - (a @ q + b))
    assert fixed.status != "converged"
    np.testing.assert_array_equal(fixed.gain, np.eye(2))
    weighted = primo.Secant([-2], [2], [0.2], gain=2.0, rule="weighted")
    weighted.tell([0.4])
    assert abs(weighted.ask()[0] - (0.2 + 2.0 * 0.4 * np.exp(-0.16))) < 1e-6
    again = pickle.loads(pickle.dumps(weighted))
    assert again.ask()[0] == weighted.ask()[0]
    with pytest.raises(ValueError, match="rule"):
        primo.Secant([-2], [2], [0.2], rule="newton")


def power_run(seed, rollouts):
    optimum = np.array([0.7, -0.4, 0.2, 1.1])
    learner = primo.Power(np.zeros(4), [(4, 0.05, 0.98)], seed=seed)
    for _ in range(rollouts):
        theta = learner.ask()
        learner.tell(float(np.exp(-4 * np.sum((theta - optimum) ** 2))))
    return learner, optimum


def test_power_converges_and_is_deterministic_per_seed():
    learner, optimum = power_run(9, 400)
    assert learner.updates == 100 and learner.rollouts == 400
    assert np.exp(-4 * np.sum((learner.mean - optimum) ** 2)) > 0.97
    again, _ = power_run(9, 400)
    np.testing.assert_array_equal(again.mean, learner.mean)
    other, _ = power_run(10, 400)
    assert not np.array_equal(other.mean, learner.mean)
    params, reward = learner.best
    assert reward == max(r for _, r in learner.sampler) and params.shape == (4,)
    assert learner.variances[0] == pytest.approx(0.05 * 0.98**100, rel=1e-4)


def test_power_pickles_mid_update_and_while_asked():
    learner, _ = power_run(3, 7)
    asked = learner.ask()
    copy = pickle.loads(pickle.dumps(learner))
    np.testing.assert_array_equal(copy.ask(), asked)
    for a in (learner, copy):
        a.tell(0.5)
    np.testing.assert_array_equal(copy.ask(), learner.ask())
    np.testing.assert_array_equal(copy.mean, learner.mean)


def test_power_errors():
    with pytest.raises(ValueError, match="sum of block lengths"):
        primo.Power(np.zeros(3), [(2, 0.1, 1.0)])
    with pytest.raises(ValueError, match="decay"):
        primo.Power(np.zeros(2), [(2, 0.1, 0.0)])
    learner = primo.Power(np.zeros(2), [(2, 0.1, 1.0)])
    with pytest.raises(ValueError, match="without a preceding ask"):
        learner.tell(1.0)
    learner.ask()
    with pytest.raises(ValueError, match=">= 0"):
        learner.tell(-1.0)
    with pytest.raises(ValueError, match="capacity"):
        primo.Power(np.zeros(5000), [(5000, 0.1, 1.0)])


def test_power_with_a_query_gain_averages_its_two_best_roll_outs():
    # primo's power-el default: the paper's sampler of 3 without a query
    # gain, 2 with one, unless told.
    def held(**settings):
        learner = primo.Power(np.zeros(3), [(1, 0.0, 1.0), (2, 0.01, 1.0)], query=1, seed=1, **settings)
        for reward in (0.2, 0.5, 0.9, 0.7):
            learner.ask()
            learner.tell(reward, error=[0.0] if "query_gain" in settings else None)
        return [r for _, r in learner.sampler]

    assert held() == pytest.approx([0.9, 0.7, 0.5])
    assert held(query_gain=1.0) == pytest.approx([0.9, 0.7])
    assert held(query_gain=1.0, sampler=3) == pytest.approx([0.9, 0.7, 0.5])


def test_power_names_its_query_and_refuses_an_error_of_another_length():
    # Was: query_gain=K corrected the first len(error) parameters, whatever
    # they were; a query put last corrected kernel weights instead.
    with pytest.raises(ValueError, match="name the query: query=n"):
        primo.Power(np.zeros(3), [(2, 0.1, 1.0), (1, 0.1, 1.0)], query_gain=1.0)
    with pytest.raises(ValueError, match=r"query=-1: the query's length"):
        primo.Power(np.zeros(3), [(3, 0.1, 1.0)], query=-1)
    with pytest.raises(ValueError, match=r"query=1: .* the blocks end at \[2, 3\]"):
        primo.Power(np.zeros(3), [(2, 0.1, 1.0), (1, 0.1, 1.0)], query=1, query_gain=1.0)
    learner = primo.Power(np.zeros(3), [(2, 0.0, 1.0), (1, 0.0, 1.0)], rollouts_per_update=1,
                          roll_out_mean=False, sampler=1, query=2, query_gain=0.5)
    assert learner.query == 2
    learner.ask()
    with pytest.raises(ValueError, match=r"error: 1 values, one per query entry: .*\(query=2\)"):
        learner.tell(1.0, error=[0.2])
    with pytest.raises(ValueError, match="needs each roll-out's error"):
        learner.tell(1.0)
    assert learner.rollouts == 0  # refused tells change nothing
    assert learner.tell(1.0, error=[0.2, -0.4]) is True
    # The query, and only the query, moved by K·error.
    np.testing.assert_array_equal(learner.mean, np.float32([0.1, -0.2, 0.0]))
    copy = pickle.loads(pickle.dumps(learner))
    assert copy.query == 2
    np.testing.assert_array_equal(copy.mean, learner.mean)
    plain = primo.Power(np.zeros(2), [(2, 0.1, 1.0)])
    plain.ask()
    with pytest.raises(ValueError, match=r"no query \(query=0\)"):
        plain.tell(1.0, error=[0.1])


def test_power_defaults_need_a_skill_and_its_query():
    with pytest.raises(TypeError, match="a primo.Cell or a primo.Generalizer"):
        primo.Power.defaults(np.zeros(3))
    cell = primo.Cell(kernels=10, bottle=0.6)
    power = primo.Power.defaults(cell, seed=3)
    assert power.query == 1 and power.mean[0] == np.float32(0.6) and not power.mean[1:].any()
    assert len(power.mean) == len(cell)
    # The query block first, then a block per DoF's weights, the goals, τ.
    assert len(power.variances) == 1 + 7 + 1 + 1
    with pytest.raises(ValueError, match="PoWER's s1 -1: must be finite and >= 0"):
        primo.Power.defaults(cell, s1=-1.0)
    with pytest.raises(ValueError, match="start: 2 values, the skill's query has 1"):
        primo.Power.defaults(cell, start=[0.5, 0.5])
    t = np.linspace(0, 1, 50)
    dmps = [(q, primo.Dmp.fit(t, q * t, names=["x"], kernels=5)) for q in (0.3, 1.0)]
    g = primo.Generalizer(dmps)
    with pytest.raises(ValueError, match="start: the first query, needed for a Generalizer"):
        primo.Power.defaults(g)
    assert primo.Power.defaults(g, start=0.5).mean[0] == 0.5
