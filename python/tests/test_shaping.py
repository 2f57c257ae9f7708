"""Dmp.fit(final_velocity=) and Dmp.run's shaping: a velocity at the goal,
via-points, obstacles and joint limits, as the command line does them; and
DmpRun.step's phase stopping."""

import math
import pickle

import numpy as np
import pytest

import primo


def throw():
    t = np.linspace(0.0, 1.0, 501)
    x = -0.5 * np.sin(np.pi * t) + 0.8 * t**3
    y = 0.1 * t * t * (3 - 2 * t)
    return t, np.column_stack([x, y])


def test_a_throw_keeps_its_speed_and_takes_a_new_one():
    t, y = throw()
    dmp = primo.Dmp.fit(t, y, names=["x", "y"], final_velocity="demonstrated")
    for velocity, speed in [(None, 0.5 * math.pi + 2.4), ([1.5, 0.0], 1.5)]:
        times, x = dmp.run(dt=0.002, goal_velocity=velocity) if velocity else dmp.run(dt=0.002)
        end = (x[-1, 0] - x[-2, 0]) / (times[-1] - times[-2])
        assert abs(x[-1, 0] - 0.8) < 5e-3
        assert abs(end - speed) < 0.2, (velocity, end)
    # Pickled, it keeps its goal velocity.
    again = pickle.loads(pickle.dumps(dmp))
    assert np.array_equal(again.run(dt=0.002)[1], dmp.run(dt=0.002)[1])


def test_via_points_and_obstacles_match_the_command_line_rules():
    t, y = throw()
    dmp = primo.Dmp.fit(t, y, names=["x", "y"])
    times, x = dmp.run(dt=0.002, via=[(0.5, "y", 0.3), (0.8, "x", 0.2)])
    assert abs(times[250] - 0.5) < 1e-9 and abs(x[250, 1] - 0.3) < 1e-4
    assert abs(x[400, 0] - 0.2) < 1e-4
    with pytest.raises(ValueError, match="no position column `w`"):
        dmp.run(via=[(0.5, "w", 0.3)])
    with pytest.raises(ValueError, match="within the movement"):
        dmp.run(via=[(1.5, "y", 0.3)])
    with pytest.raises(ValueError, match="not with goal_velocity, via, obstacles or limits"):
        dmp.run(via=[(0.5, "y", 0.3)], velocities=True)
    # A reach in x, y, z past a ball.
    s = t**3 * (10 - 15 * t + 6 * t * t)
    reach = primo.Dmp.fit(t, np.column_stack([0.6 * s, 0 * s + 0.1, 0 * s + 0.2]), names=["x", "y", "z"])
    ball = np.array([[0.3, 0.11, 0.2, 0.05]])
    times, p = reach.run(dt=0.002, obstacles=ball)
    clearance = np.linalg.norm(p - ball[0, :3], axis=1) - 0.05
    assert clearance.min() > 0.0 and times[-1] > 1.0
    assert np.allclose(p[-1], [0.6, 0.1, 0.2], atol=1e-3)
    with pytest.raises(ValueError, match="holds the movement's start"):
        reach.run(obstacles=[[0.0, 0.1, 0.2, 0.05]])
    with pytest.raises(ValueError, match=r"expected \(n, 4\)"):
        reach.run(obstacles=[[0.3, 0.1, 0.2]])
    with pytest.raises(ValueError, match="obstacle_columns: given without obstacles"):
        reach.run(obstacle_columns=["x", "y", "z"])
    with pytest.raises(ValueError, match="final_velocity"):
        primo.Dmp.fit(t, y, final_velocity="fast")


def overshoot():
    """A joint that overshoots to 1.09 on its way to 0.8, and another."""
    t = np.linspace(0.0, 1.0, 201)
    a1 = 0.8 * t * t * (3 - 2 * t) + np.sin(np.pi * t) ** 2 * t
    return primo.Dmp.fit(t, np.column_stack([a1, -0.5 * t]), names=["a1", "a2"])


def test_through_returns_the_bent_movement_as_a_dmp():
    t, y = throw()
    dmp = primo.Dmp.fit(t, y, names=["x", "y"])
    via = [(0.5, "y", 0.3), (0.8, "x", 0.2)]
    bent = dmp.through(via, dt=0.002)
    # The same run as run(via=...), from a DMP of its own: only the
    # weights changed, its start, goal and duration kept.
    assert np.allclose(bent.run(dt=0.002)[1], dmp.run(dt=0.002, via=via)[1], atol=1e-6)
    n = dmp.dof * dmp.kernels
    assert np.array_equal(bent.params[n:], dmp.params[n:]) and not np.array_equal(bent.params, dmp.params)
    assert np.array_equal(pickle.loads(pickle.dumps(bent)).params, bent.params)
    for bad, message in [
        ([(1.5, "x", 0.1)], "within the movement"),
        ([(0.5, "w", 0.1)], "no position column `w`"),
        ([(0.5, "x", math.nan)], "needs a finite time and value"),
        ([(0.5, "x", 0.1)] * 9, "9 via-points, at most 8"),
    ]:
        with pytest.raises(ValueError, match=message):
            dmp.through(bad)
    with pytest.raises(ValueError, match="dt"):
        dmp.through(via, dt=0.0)


def test_joint_limits_hold_an_overshoot_back():
    dmp = overshoot()
    _, free = dmp.run(dt=0.002)
    assert free[:, 0].max() > 1.0
    _, held = dmp.run(dt=0.002, limits={"a1": (-1.0, 0.95)}, limit_margin=0.1)
    assert held[:, 0].max() < 0.95
    assert np.allclose(held[-1], [0.8, -0.5], atol=1e-3)
    _, above = dmp.run(dt=0.002, limits={"a1": (-math.inf, 0.95)}, limit_margin=0.1)
    assert np.array_equal(above, held)
    with pytest.raises(ValueError, match="within the margin of a joint limit"):
        dmp.run(limits={"a1": (-1.0, 0.85)}, limit_margin=0.1)
    with pytest.raises(ValueError, match="no position column `a3`"):
        dmp.run(limits={"a3": (-1.0, 1.0)}, limit_margin=0.1)
    with pytest.raises(ValueError, match="needs limit_margin"):
        dmp.run(limits={"a1": (-1.0, 0.95)})
    with pytest.raises(ValueError, match="needs low < high"):
        dmp.run(limits={"a1": (1.0, -1.0)}, limit_margin=0.1)
    with pytest.raises(ValueError, match="limit_margin: given without limits"):
        dmp.run(limit_margin=0.1)


def test_phase_stopping_waits_for_a_held_robot():
    t = np.linspace(0.0, 1.0, 101)
    s = t**3 * (10 - 15 * t + 6 * t * t)
    dmp = primo.Dmp.fit(t, 0.6 * s, names=["x"])
    free, held = dmp.stepper(), dmp.stepper()
    for _ in range(1000):
        free.step(0.002)
        held.step(0.002, measured=[0.0], phase_stop=1e4)  # the robot does not move
    assert abs(free.position[0] - 0.6) < 1e-3
    assert held.position[0] < 0.1 and held.time < 1.0
    # A robot that follows exactly changes nothing.
    follow, plain = dmp.stepper(), dmp.stepper()
    for _ in range(100):
        x = plain.step(0.002)
        follow.step(0.002, measured=follow.position, phase_stop=1e4)
    assert np.array_equal(follow.position, x)
    with pytest.raises(ValueError, match="give both or neither"):
        plain.step(0.002, phase_stop=1.0)
    with pytest.raises(ValueError, match="phase_stop: -1"):
        plain.step(0.002, measured=[0.0], phase_stop=-1.0)
