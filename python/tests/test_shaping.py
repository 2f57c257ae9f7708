"""Dmp.fit(final_velocity=) and Dmp.run's shaping: a velocity at the goal,
via-points and obstacles, as the command line does them."""

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
    with pytest.raises(ValueError, match="not with goal_velocity, via or obstacles"):
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
