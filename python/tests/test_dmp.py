"""DMPs: the same fit and run as `primo dmp`, files, pickling, errors."""

import io
import json
import pickle
import threading
import time

import numpy as np
import pytest

import primo
from conftest import ROOT

REACH = ROOT / "examples" / "reach.csv"


def reach():
    data = np.loadtxt(REACH, delimiter=",", skiprows=1)
    return data[:, 0], data[:, 1:]


def test_fit_and_run_equal_the_command_line(run_primo, tmp_path):
    t, y = reach()
    dmp = primo.Dmp.fit(t, y, names=["x", "z"], kernels=30)
    cli = json.loads(run_primo("dmp", "fit", "--demo", str(REACH), "--kernels", "30"))
    ours = json.loads(dmp.to_json())
    assert ours["names"] == cli["names"] == ["x", "z"]
    for key in ["tau", "alpha", "width", "start", "goal", "scaled"]:
        assert ours["dmp"][key] == cli["dmp"][key], key
    np.testing.assert_allclose(ours["dmp"]["weights"], cli["dmp"]["weights"], rtol=1e-4, atol=1e-6)

    (tmp_path / "dmp.json").write_text(json.dumps(cli))
    csv = run_primo("dmp", "run", str(tmp_path / "dmp.json"), "--dt", "0.01", "--goal", "0.5,0.2")
    expected = np.loadtxt(io.StringIO(csv), delimiter=",", skiprows=1)
    times, positions = primo.Dmp.load(tmp_path / "dmp.json").run(dt=0.01, goal=[0.5, 0.2])
    # The command line prints times to the microsecond.
    np.testing.assert_allclose(times, expected[:, 0], atol=1e-6)
    np.testing.assert_array_equal(positions.astype(np.float32), expected[:, 1:].astype(np.float32))
    # The demonstration is reproduced (README: 6.2e-6 on this kind of movement).
    _, replay = dmp.run(dt=0.001)
    assert np.abs(replay - y).max() < 1e-4


def test_margin_is_chosen_or_given():
    t, y = reach()
    for margin in (0, 1, 2.5):
        dmp = primo.Dmp.fit(t, y, names=["x", "z"], margin=margin)
        assert json.loads(dmp.to_json())["dmp"]["margin"] == margin
    chosen = json.loads(primo.Dmp.fit(t, y, names=["x", "z"]).to_json())["dmp"]["margin"]
    assert chosen in (0, 1)


def test_step_by_step_equals_the_whole_run():
    t, y = reach()
    dmp = primo.Dmp.fit(t, y, kernels=20)
    times, positions, velocities = dmp.run(dt=0.002, velocities=True)
    run = dmp.stepper()
    rows = [run.position] + [run.step(0.002) for _ in range(len(times) - 1)]
    np.testing.assert_array_equal(np.array(rows), positions)
    assert velocities.shape == positions.shape
    assert abs(run.time - times[-1]) < 1e-6 and run.phase == pytest.approx(1.0, abs=1e-5)


def test_new_start_goal_and_tau():
    t, y = reach()
    dmp = primo.Dmp.fit(t, y, kernels=30)
    times, positions = dmp.run(dt=0.01, tau=2.0, start=[0.1, 0.1], goal=[1.0, 0.1])
    assert times[-1] == pytest.approx(2.0)
    np.testing.assert_allclose(positions[0], [0.1, 0.1], atol=1e-7)
    np.testing.assert_allclose(positions[-1], [1.0, 0.1], atol=2e-3)


def test_parameters_files_and_pickles(tmp_path):
    t, y = reach()
    dmp = primo.Dmp.fit(t, y, kernels=10)
    theta = dmp.params
    assert theta.shape == (2 * 10 + 2 + 1,) and theta[-1] == pytest.approx(1.0)
    theta[-1] = 2.0
    dmp.params = theta
    assert dmp.tau == 2.0
    dmp.save(tmp_path / "d.json")
    loaded = primo.Dmp.load(tmp_path / "d.json")
    assert loaded == dmp and pickle.loads(pickle.dumps(dmp)) == dmp
    np.testing.assert_array_equal(loaded.run(dt=0.01)[1], dmp.run(dt=0.01)[1])


def test_orientation_columns_are_a_quaternion_dmp():
    t = np.linspace(0.0, 1.0, 201)
    s = t * t * (3 - 2 * t)
    angle = np.radians(170) + np.radians(20) * s  # through 180°
    q = np.stack([np.cos(angle / 2), 0 * t, 0 * t, np.sin(angle / 2)], axis=1)
    dmp = primo.Dmp.fit(t, np.column_stack([s, q]), names=["x", "qw", "qx", "qy", "qz"])
    assert dmp.orientations == [["qw", "qx", "qy", "qz"]] and dmp.dof == 4
    _, rows = dmp.run(dt=0.005)
    np.testing.assert_allclose(np.linalg.norm(rows[:, 1:], axis=1), 1.0, atol=1e-6)
    ends = np.abs(rows[-1, 1:] @ q[-1])
    assert ends == pytest.approx(1.0, abs=1e-6)
    with pytest.raises(ValueError, match="velocities"):
        dmp.run(velocities=True)


def test_rhythmic():
    t = np.linspace(0.0, 0.8, 161)
    y = np.column_stack([np.sin(2 * np.pi * t / 0.8), 0.2 * np.cos(4 * np.pi * t / 0.8)])
    dmp = primo.Dmp.fit_rhythmic(t, y, names=["a", "b"], kernels=25)
    assert dmp.rhythmic and dmp.period == pytest.approx(0.8)
    times, rows = dmp.run(dt=0.01, duration=1.6, frequency=2.5, amplitude=[2.0, 1.0])
    assert times[-1] == pytest.approx(1.6) and rows.shape == (161, 2)
    assert primo.Dmp.from_json(dmp.to_json()) == dmp
    with pytest.raises(ValueError, match="discrete"):
        dmp.run(tau=1.0)


def test_rhythmic_defaults_are_the_command_lines(run_primo, tmp_path):
    # Python's default was 25 kernels where `primo dmp fit --rhythmic` has 30.
    t = np.round(np.linspace(0.0, 0.8, 161), 6)
    y = np.round(np.column_stack([np.sin(2 * np.pi * t / 0.8), 0.2 * np.cos(4 * np.pi * t / 0.8)]), 6)
    demo = tmp_path / "loop.csv"
    np.savetxt(demo, np.column_stack([t, y]), delimiter=",", header="t,a,b", comments="", fmt="%.6f")
    cli = json.loads(run_primo("dmp", "fit", "--demo", str(demo), "--rhythmic"))["rhythmic"]
    ours = json.loads(primo.Dmp.fit_rhythmic(t, y, names=["a", "b"]).to_json())["rhythmic"]
    assert [len(w) for w in ours["weights"]] == [len(w) for w in cli["weights"]] == [30, 30]
    for key in ["period", "alpha", "width"]:
        assert ours[key] == cli[key], key
    np.testing.assert_allclose(ours["weights"], cli["weights"], rtol=1e-4, atol=1e-6)


def recording_at(origin):
    """A 1 kHz recording of two DoF stamped from `origin` s: the same
    instants whatever the origin (those a recorder stamping from 1.7e9 s,
    Unix time, can hold)."""
    since_first = (1.7e9 + np.arange(1001) * 1e-3) - 1.7e9
    s = since_first / since_first[-1]
    return origin + since_first, np.stack([s * s * (3 - 2 * s), 0.25 * np.sin(np.pi * s)], axis=1)


@pytest.mark.parametrize("fit", [primo.Dmp.fit, primo.Dmp.fit_rhythmic])
def test_a_recording_stamped_in_unix_time_fits_as_from_0(fit):
    # Was "times must be strictly increasing" (the stamps cut to float32).
    from_zero = fit(*recording_at(0.0))
    for origin in (1.7e9, 1000.0, -2.5):
        assert fit(*recording_at(origin)) == from_zero, origin


@pytest.mark.parametrize("scaling", ["per-dof", "none", "global"])
def test_scaling_is_the_command_lines(scaling, run_primo, tmp_path):
    t, y = reach()
    dmp = primo.Dmp.fit(t, y, names=["x", "z"], scaling=scaling)
    cli = json.loads(run_primo("dmp", "fit", "--demo", str(REACH), "--scaling", scaling))
    ours = json.loads(dmp.to_json())
    assert ours["version"] == cli["version"] == 6
    for key in ["scaled", "reference", "margin", "width"]:
        assert ours["dmp"].get(key) == cli["dmp"].get(key), key
    assert ("reference" in ours["dmp"]) == (scaling == "global")
    # A new goal runs alike from the file the command line wrote.
    (tmp_path / "dmp.json").write_text(json.dumps(cli))
    csv = run_primo("dmp", "run", str(tmp_path / "dmp.json"), "--goal", "0.6,0.2")
    expected = np.loadtxt(io.StringIO(csv), delimiter=",", skiprows=1)
    _, ran = dmp.run(goal=[0.6, 0.2])
    np.testing.assert_allclose(ran, expected[:, 1:], atol=1e-5)


@pytest.mark.parametrize(
    "t, y, kwargs, message",
    [
        ([0, 1, 2], [[0, 1, 2]], {}, "y has 1 rows, t has 3 samples"),
        ([0, 1, np.nan], [0, 1, 2], {}, r"t\[2\]: NaN is not a finite number"),
        ([0, 1, 2], [0, np.inf, 2], {}, r"y\[1\]: inf is not a finite number"),
        ([0, 1, 1], [0, 1, 2], {}, r"t\[2\] = 1 does not increase: t\[1\] is at t = 1"),
        ([5, 1005, 1005.00001], [0, 1, 2], {}, r"t\[2\] = 1005.00001 is 1.000e-5 s after t\[1\]: 1000.00001 s into the recording, stamps must be at least 6.104e-5 s apart"),
        ([], [], {}, "at least 3 samples"),
        ([0, 1, 2], [0, 1, 2], {"kernels": 1}, "^kernels=1: a DMP needs 2 to 128 kernels per DoF$"),
        ([0, 1, 2], [0, 1, 2], {"kernels": 129}, "^kernels=129: a DMP needs 2 to 128"),
        ([0, 1, 2], [0, 1, 2], {"kernels": -3}, "^kernels=-3: a DMP needs 2 to 128"),
        ([0, 1, 2], [[0, 1], [1, 2], [2, 3]], {"names": ["x"]}, "1 names for 2 columns"),
        ([0, 1, 2], [[0, 1], [1, 2], [2, 3]], {"names": ["x", "x"]}, "repeated"),
        ([[0, 1, 2]], [0, 1, 2], {}, "expected a 1-D array"),
        ([0, 1, 2], np.zeros((3, 2, 2)), {}, "expected a 2-D array"),
        ([0, 1, 2], [1e40, 0, 0], {}, "out of f32 range"),
        ([0, 1, 2], [0, 1, 2], {"kernels": 10, "margin": 4.5}, "margin: 4.5 is not a number of kernel spacings from 0 to 4"),
        ([0, 1, 2], [0, 1, 2], {"margin": -1}, "margin: -1"),
        ([0, 1, 2], [0, 1, 2], {"margin": float("nan")}, "margin: NaN"),
        ([0, 1, 2], [0, 1, 2], {"overlap": 0}, "overlap: 0 must be a positive, finite number"),
        ([0, 1, 2], [0, 1, 2], {"overlap": float("inf")}, "overlap: inf must be"),
        ([0, 1, 2], [0, 1, 2], {"ridge": -1e-6}, "ridge: -0.000001 must be a finite number >= 0"),
        ([0, 1, 2], [0, 1, 2], {"alpha": 0}, "alpha: 0 is outside 0.01 to 10000"),
        ([0, 1, 2], [0, 1, 2], {"alpha": float("nan")}, "alpha: NaN is outside"),
        ([0, 1, 2], [0, 1, 0], {"scaling": "global"}, "global scaling needs the demonstration's goal to differ from its start"),
        ([0, 1, 2], [0, 1, 2], {"scaling": "both"}, r"scaling: \"both\", expected \"per-dof\", \"none\" or \"global\""),
    ],
)
def test_bad_input_is_a_value_error(t, y, kwargs, message):
    with pytest.raises(ValueError, match=message):
        primo.Dmp.fit(t, y, **kwargs)


def test_a_kernel_count_out_of_range_is_said_in_python_terms():
    # Was "kernels: 1 is outside 2..=128", the library's words.
    t = np.linspace(0.0, 1.0, 50)
    y = np.sin(2 * np.pi * t)
    for fit, fewest, kind in [(primo.Dmp.fit, 2, ""), (primo.Dmp.fit_rhythmic, 3, "rhythmic ")]:
        for k in [fewest - 1, 129, -1]:
            with pytest.raises(ValueError) as e:
                fit(t, y, kernels=k)
            assert str(e.value) == f"kernels={k}: a {kind}DMP needs {fewest} to 128 kernels per DoF"
        assert fit(t, y, kernels=fewest).kernels == fewest


@pytest.mark.parametrize("fit", [primo.Dmp.fit, primo.Dmp.fit_rhythmic])
def test_names_of_the_wrong_type_are_a_type_error_that_says_so(fit):
    # Was "Can't extract `str` to `Vec`" (PyO3's words) for a string.
    t, y = [0, 0.5, 1, 1.5], [[0, 1], [1, 2], [2, 3], [0, 1]]
    with pytest.raises(TypeError, match=r"names: a sequence of column names such as \['x', 'z'\], not the string 'ab'"):
        fit(t, y, names="ab")
    with pytest.raises(TypeError, match=r"names: a sequence of column names \(strings\)"):
        fit(t, y, names=["a", 2])
    assert fit(t, y, names=("a", "b")).names == ["a", "b"]


def test_bad_run_arguments_are_value_errors():
    t, y = reach()
    dmp = primo.Dmp.fit(t, y, kernels=10)
    for kwargs, message in [
        ({"dt": 0.0}, "dt: 0 must be a positive"),
        ({"dt": np.nan}, "dt: NaN"),
        ({"dt": 1e-9}, "at most"),
        ({"tau": -1.0}, "tau"),
        ({"goal": [1.0]}, "goal: 1 values, expected one per column"),
        ({"start": [np.nan, 0.0]}, "not a finite number"),
        ({"goal": [1e7, 0.0]}, "the bound on any position"),
        ({"frequency": 1.0}, "rhythmic DMP only"),
    ]:
        with pytest.raises(ValueError, match=message):
            dmp.run(**kwargs)
    with pytest.raises(ValueError, match="parameter vector"):
        dmp.params = [1.0, 2.0]
    with pytest.raises(ValueError, match="primo-dmp"):
        primo.Dmp.from_json('{"format": "other", "version": 2}')
    with pytest.raises(OSError, match="missing.json"):
        primo.Dmp.load("missing.json")


def longest_stall(call) -> float:
    """The longest this thread waited between two steps of a busy loop while
    `call` ran on another thread, as a fraction of `call`'s time alone."""
    began = time.perf_counter()
    call()
    alone = time.perf_counter() - began
    worker = threading.Thread(target=call)
    last, longest = time.perf_counter(), 0.0
    worker.start()
    while worker.is_alive():
        now = time.perf_counter()
        longest, last = max(longest, now - last), now
    worker.join()
    return longest / alone


def test_long_fits_and_runs_let_other_threads_go_on():
    # They held the GIL throughout: the other thread stalled for the whole
    # call (a fraction of 1). Converting the arrays still holds it (about a
    # quarter of a fit of 100,001 x 7 samples); the best of three tries
    # keeps a busy machine's scheduling out of the measure.
    t = np.linspace(0.0, 10.0, 100_001)
    y = np.column_stack([np.sin(t + k) for k in range(7)])
    assert min(longest_stall(lambda: primo.Dmp.fit(t, y)) for _ in range(3)) < 0.6

    def rhythmic():
        return primo.Dmp.fit_rhythmic(t, y, period=10.0)

    assert min(longest_stall(rhythmic) for _ in range(3)) < 0.6
    dmp = primo.Dmp.fit(t, y)
    assert min(longest_stall(lambda: dmp.run(dt=0.0001)) for _ in range(3)) < 0.5
    loop = rhythmic()
    assert min(longest_stall(lambda: loop.run(dt=0.0001, duration=10.0)) for _ in range(3)) < 0.5
