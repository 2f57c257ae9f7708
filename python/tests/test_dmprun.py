"""DmpRun: pickled and copied runs continue bit for bit; closed-loop steps."""

import copy
import pickle

import numpy as np
import pytest

import primo
from conftest import ROOT


def reach_dmp():
    data = np.loadtxt(ROOT / "examples" / "reach.csv", delimiter=",", skiprows=1)
    return primo.Dmp.fit(data[:, 0], data[:, 1:], names=["x", "z"], kernels=20)


def steps(run, n, dt=0.002):
    return np.array([run.step(dt) for _ in range(n)])


@pytest.mark.parametrize("duplicate", [
    lambda r: pickle.loads(pickle.dumps(r)),
    copy.copy,
    copy.deepcopy,
])
def test_a_duplicated_run_continues_bit_for_bit(duplicate):
    # Was: TypeError, cannot pickle 'DmpRun' (copy.copy too).
    dmp = reach_dmp()
    run = dmp.stepper(tau=1.5, goal=[0.9, 0.2])
    steps(run, 100)
    run.set_goal([0.8, 0.1])
    run.step(0.001, position=run.position + 0.01, velocity=[0.0, 0.1], coupling=[0.5, -0.5])
    steps(run, 50, dt=0.003)
    twin = duplicate(run)
    assert (twin.time, twin.phase) == (run.time, run.phase)
    np.testing.assert_array_equal(twin.position, run.position)
    np.testing.assert_array_equal(twin.velocity, run.velocity)
    np.testing.assert_array_equal(steps(twin, 400), steps(run, 400))
    # Independent: stepping one leaves the other.
    before = run.position.copy()
    twin.step(0.01)
    np.testing.assert_array_equal(run.position, before)


def test_feeding_back_the_runs_own_state_is_the_open_loop_run():
    dmp = reach_dmp()
    _, open_loop = dmp.run(dt=0.002)
    run = dmp.stepper()
    fed = [run.step(0.002, position=run.position, velocity=run.velocity, coupling=[0.0, 0.0])
           for _ in range(len(open_loop) - 1)]
    np.testing.assert_array_equal(np.array(fed), open_loop[1:])


def test_a_lagging_robot_pulls_the_run_back_and_it_still_converges():
    # A sluggish robot goes half the way to each command: fed back, the
    # run waits for it (as movement_primitives' step(last_y) does), where
    # the open-loop run would run away from it.
    dmp = reach_dmp()
    dt = 0.002
    open_run, closed_run = dmp.stepper(), dmp.stepper()
    robot = closed_run.position.copy()
    gaps = []
    for _ in range(400):
        command = closed_run.step(dt, position=robot)
        robot = robot + 0.5 * (command - robot)
        gaps.append(np.abs(open_run.step(dt) - robot).max())
    assert max(gaps) > 1e-2  # behind the open-loop run
    for _ in range(4000):
        command = closed_run.step(dt, position=robot)
        robot = robot + 0.5 * (command - robot)
    np.testing.assert_allclose(robot, dmp.goal, atol=1e-3)


def test_a_coupling_acceleration_pushes_the_run():
    dmp = reach_dmp()
    plain, pushed = dmp.stepper(), dmp.stepper()
    for _ in range(100):
        plain.step(0.002)
        pushed.step(0.002, coupling=[0.0, 5.0])
    # Only the pushed column moves, and the way it was pushed.
    assert pushed.position[0] == plain.position[0]
    assert pushed.position[1] > plain.position[1] + 1e-3
    assert pushed.velocity[1] > plain.velocity[1]


def test_bad_closed_loop_input_is_a_value_error_and_changes_nothing():
    dmp = reach_dmp()
    run = dmp.stepper()
    run.step(0.002)
    state = (run.time, run.position.copy(), run.velocity.copy())
    for kwargs, message in [
        ({"position": [0.1]}, r"position: 1 values, expected one per column \(x,z\)"),
        ({"velocity": [0.0, np.nan]}, r"velocity\[1\]: NaN is not a finite number"),
        ({"coupling": [[0.0, 0.0]]}, "coupling: expected a 1-D array"),
        ({"position": [2e6, 0.0]}, "measured position beyond ±1e6"),
        ({"coupling": [3e38, 0.0]}, "coupling moves the rest point beyond ±1e6"),
    ]:
        with pytest.raises(ValueError, match=message):
            run.step(0.002, **kwargs)
        assert (run.time, *state[1:]) == (state[0], *state[1:])
        np.testing.assert_array_equal(run.position, state[1])
    # Pickling after refusals replays only what was done.
    np.testing.assert_array_equal(pickle.loads(pickle.dumps(run)).step(0.002), run.step(0.002))
    t = np.linspace(0, 1, 50)
    pose = np.column_stack([t, np.ones(50), np.zeros((50, 3))])
    oriented = primo.Dmp.fit(t, pose, names=["x", "pqw", "pqx", "pqy", "pqz"], kernels=5).stepper()
    with pytest.raises(ValueError, match="for DMPs without orientation columns only"):
        oriented.step(0.01, position=[0, 1, 0, 0, 0])
    copy.copy(oriented).step(0.01)
    pickle.loads(pickle.dumps(oriented)).step(0.01)


def test_a_pickled_run_is_its_state_not_its_history():
    dmp = reach_dmp()
    fresh, long = dmp.stepper(), dmp.stepper()
    steps(long, 5000, dt=0.0005)
    assert len(pickle.dumps(long)) == len(pickle.dumps(fresh))
    # A state that is not a run's is refused in words, not a panic.
    stepper, args, state = long.__reduce__()
    for broken in [state[:-1], [float("nan")] * len(state), [3.0] + state[1:]]:
        run = stepper(*args)
        with pytest.raises(ValueError, match="DmpRun: not a state this run pickled"):
            run.__setstate__(broken)


@pytest.mark.parametrize("scaling", ["per-dof", "none", "global"])
def test_a_pickled_run_of_any_scaling_goes_on_as_the_uninterrupted_one(scaling):
    # Global scaling's turn is not in the state: it is rebuilt from the
    # DMP, the start and the goal, and must come back bit for bit.
    t = np.linspace(0.0, 1.0, 101)
    s = t * t * (3 - 2 * t)
    y = np.column_stack([0.6 * s, 0.1 + 0.15 * np.sin(np.pi * s) ** 2])
    dmp = primo.Dmp.fit(t, y, names=["x", "z"], scaling=scaling)
    whole = dmp.stepper(goal=[0.3, 0.5])
    expected = [whole.step(0.01) for _ in range(80)]
    run = dmp.stepper(goal=[0.3, 0.5])
    for _ in range(30):
        run.step(0.01)
    resumed = pickle.loads(pickle.dumps(run))
    assert np.array_equal([resumed.step(0.01) for _ in range(50)], expected[30:])
