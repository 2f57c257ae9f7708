"""Generalization over DMPs at task queries."""

import pickle
import shutil

import numpy as np
import pytest

import primo
from conftest import ROOT


def demo(height):
    t = np.linspace(0.0, 1.0, 201)
    s = t * t * (3 - 2 * t)
    return t, np.column_stack([0.6 * s, 0.1 + height * np.sin(np.pi * s) ** 2])


@pytest.mark.parametrize("method", ["lwr", "gpr", "promp"])
def test_two_examples_give_the_line_through_them(method):
    low, high = primo.Dmp.fit(*demo(0.1), names=["x", "z"]), primo.Dmp.fit(*demo(0.3), names=["x", "z"])
    g = primo.Generalizer([(0.1, low), (0.3, high)], method=method)
    assert len(g) == 2 and g.query_dim == 1 and g.names == ["x", "z"]
    np.testing.assert_allclose(g.params(0.1), low.params, rtol=1e-4, atol=1e-4)
    np.testing.assert_allclose(g.params(0.2), (low.params + high.params) / 2, rtol=1e-3, atol=1e-3)
    _, rows = g.generalize(0.2).run(dt=0.01)
    assert rows[:, 1].max() == pytest.approx(0.3, abs=2e-3)  # peak 0.1 + 0.2
    copy = pickle.loads(pickle.dumps(g))
    assert copy.generalize(0.25) == g.generalize(0.25)


def test_vector_queries_and_errors():
    dmps = [primo.Dmp.fit(*demo(h), names=["x", "z"]) for h in (0.1, 0.2, 0.3)]
    g = primo.Generalizer([([0.1, 0.0], dmps[0]), ([0.2, 1.0], dmps[1]), ([0.3, 0.0], dmps[2])])
    assert g.query_dim == 2
    with pytest.raises(ValueError, match="query"):
        g.generalize(0.2)
    with pytest.raises(ValueError, match="its query has 1 values"):
        primo.Generalizer([([0.1, 0.0], dmps[0]), (0.2, dmps[1])])
    with pytest.raises(ValueError, match="columns"):
        primo.Generalizer([(0.1, dmps[0]), (0.2, primo.Dmp.fit(*demo(0.2), names=["a", "b"]))])
    with pytest.raises(ValueError, match="margin"):
        primo.Generalizer([(0.1, primo.Dmp.fit(*demo(0.1), margin=0)), (0.2, primo.Dmp.fit(*demo(0.2), margin=1))])
    with pytest.raises(ValueError, match="method"):
        primo.Generalizer([(0.1, dmps[0])], method="knn")
    with pytest.raises(ValueError, match="at least one"):
        primo.Generalizer([])


def test_a_promp_is_one_linear_model_over_all_examples():
    # Three heights along the query, the middle one off the line through
    # the outer two: LWR and GPR pass through it, the ProMP's conditional
    # mean is the least-squares line through all three.
    qs, heights = [0.0, 0.5, 1.0], [0.1, 0.3, 0.2]
    dmps = [primo.Dmp.fit(*demo(h), names=["x", "z"]) for h in heights]
    promp = primo.Generalizer(list(zip(qs, dmps)), method="promp")
    thetas = np.array([d.params for d in dmps])
    slope = np.polyfit(qs, thetas, 1)
    for q in (-0.5, 0.25, 0.5, 2.0):
        np.testing.assert_allclose(promp.params(q), slope[0] * q + slope[1], rtol=1e-3, atol=1e-3)
    gpr = primo.Generalizer(list(zip(qs, dmps)), method="gpr")
    np.testing.assert_allclose(gpr.params(0.5), dmps[1].params, rtol=1e-3, atol=1e-3)
    copy = pickle.loads(pickle.dumps(promp))
    np.testing.assert_array_equal(copy.params(0.3), promp.params(0.3))
    # Two examples on a two-value query: the ridge keeps it defined.
    two = primo.Generalizer([([0.0, 0.0], dmps[0]), ([1.0, 1.0], dmps[2])], method="promp")
    np.testing.assert_allclose(two.params([0.5, 0.5]), (dmps[0].params + dmps[2].params) / 2, rtol=1e-3, atol=1e-3)
    with pytest.raises(ValueError, match="ridge: for method"):
        primo.Generalizer(list(zip(qs, dmps)), method="lwr", ridge=0.1)
    with pytest.raises(ValueError, match="ridge: -1"):
        primo.Generalizer(list(zip(qs, dmps)), method="promp", ridge=-1.0)


POSE = ["x", "y", "z", "qw", "qx", "qy", "qz"]


def yaw(deg):
    """The unit quaternion [w, x, y, z] of a turn by `deg` about z."""
    half = np.radians(deg) / 2
    return np.stack([np.cos(half), 0 * half, 0 * half, np.sin(half)], axis=-1)


def pose_demo(reach, start_yaw, goal_yaw, names=POSE):
    """A tool's pose: its point from the origin to `reach` along x (y and z
    on arcs), its yaw from `start_yaw` to `goal_yaw` degrees, the
    quaternion's sign flipped on every third row (as some recorders do)."""
    t = np.linspace(0.0, 1.0, 201)
    s = t * t * (3 - 2 * t)
    q = yaw(start_yaw + (goal_yaw - start_yaw) * s)
    q[1::3] *= -1
    point = np.column_stack([reach * s, 0.1 * np.sin(np.pi * s), 0.2 + 0.1 * s])
    return primo.Dmp.fit(t, np.column_stack([point, q]), names=names)


def same_rows(a, b, atol):
    """Rows equal, each quaternion up to its sign."""
    sign = np.sign(np.sum(a[:, 3:] * b[:, 3:], axis=1))[:, None]
    np.testing.assert_allclose(a[:, :3], b[:, :3], atol=atol)
    np.testing.assert_allclose(a[:, 3:], sign * b[:, 3:], atol=atol)


@pytest.mark.parametrize("method", ["lwr", "gpr", "promp"])
def test_orientations_are_generalized_in_the_tangent_space(method):
    # Goal yaws 170° and 190°: the blend must pass through 180°, not turn
    # the long way round through 0°.
    examples = [(0.0, pose_demo(0.3, 120.0, 170.0)), (1.0, pose_demo(0.5, 140.0, 190.0))]
    g = primo.Generalizer(examples, method=method)
    assert g.names == POSE and g.query_dim == 1
    for q, example in examples:
        dmp = g.generalize(q)
        assert dmp.names == POSE and dmp.orientations == [["qw", "qx", "qy", "qz"]]
        assert len(dmp.params) == 6 * dmp.kernels + 6 + 1  # the orientation: 3 DoFs
        t, rows = dmp.run(dt=0.01)
        t_example, rows_example = example.run(dt=0.01)
        np.testing.assert_array_equal(t, t_example)
        same_rows(rows, rows_example, atol=1e-6)
    for q in (0.25, 0.5, 0.75):
        _, rows = g.generalize(q).run(dt=0.01)
        np.testing.assert_allclose(np.linalg.norm(rows[:, 3:], axis=1), 1.0, atol=1e-5)
        end = 170.0 + 20.0 * q
        assert abs(rows[-1, 3:] @ yaw(end)) > 1.0 - 1e-6, (q, rows[-1])
        start = 120.0 + 20.0 * q
        assert abs(rows[0, 3:] @ yaw(start)) > 1.0 - 1e-6, (q, rows[0])
        assert rows[-1, 0] == pytest.approx(0.3 + 0.2 * q, abs=1e-4)
    # A generalized DMP is an ordinary one: it pickles, steps and saves.
    copy = pickle.loads(pickle.dumps(g))
    assert copy.generalize(0.5) == g.generalize(0.5)
    dmp = g.generalize(0.5)
    assert pickle.loads(pickle.dumps(dmp)) == dmp
    assert primo.Dmp.from_json(dmp.to_json()) == dmp
    stepper = dmp.stepper()
    np.testing.assert_array_equal(stepper.step(0.01), dmp.run(dt=0.01)[1][1])


def test_examples_with_other_orientation_columns_are_refused():
    first = pose_demo(0.3, 120.0, 170.0)
    renamed = pose_demo(0.5, 140.0, 190.0, names=["x", "y", "z", "tool_qw", "tool_qx", "tool_qy", "tool_qz"])
    with pytest.raises(ValueError, match=r"examples\[1\]: columns .*tool_qw.*\(orientation tool_qw"):
        primo.Generalizer([(0.0, first), (1.0, renamed)])
    t = np.linspace(0.0, 1.0, 201)
    y = np.column_stack([yaw(np.linspace(120.0, 170.0, 201)), t, 0 * t, 0.2 + 0 * t])
    reordered = primo.Dmp.fit(t, y, names=["qw", "qx", "qy", "qz", "x", "y", "z"])
    with pytest.raises(ValueError, match=r"examples\[1\]: .*the same order"):
        primo.Generalizer([(0.0, first), (1.0, reordered)])
    plain = primo.Dmp.fit(t, np.column_stack([t, 0 * t, 0.2 + 0 * t]), names=["x", "y", "z"])
    with pytest.raises(ValueError, match=r"examples\[1\]: columns \[x, y, z\] \(no orientation\)"):
        primo.Generalizer([(0.0, first), (1.0, plain)])
    with pytest.raises(ValueError, match=r"examples\[2\]: .*\(no orientation\)"):
        primo.Generalizer([(0.0, first), (0.5, first), (1.0, plain)])
    with pytest.raises(ValueError, match=r"examples\[1\]: .*\(orientation qw,qx,qy,qz\)"):
        primo.Generalizer([(0.0, plain), (1.0, first)])
    rhythmic = primo.Dmp.fit_rhythmic(t, np.sin(2 * np.pi * t), names=["x"])
    with pytest.raises(ValueError, match=r"examples\[0\]: a rhythmic DMP"):
        primo.Generalizer([(0.0, rhythmic)])


def throw_task(tmp_path):
    """The example throw in a directory of its own: two roll-outs, and a
    time step given (the run below takes it)."""
    shutil.copytree(ROOT / "examples" / "throw", tmp_path / "throw")
    task = tmp_path / "throw" / "throw.toml"
    text = task.read_text().replace("max_rollouts = 20", "max_rollouts = 2")
    task.write_text(text.replace("[movement]\n", "[movement]\ndt = 0.01\n"))
    return task


def test_from_task_is_the_skill_primo_learn_builds(run_primo, tmp_path):
    # Was not possible: Dmp.fit could not choose primo learn's fit (its
    # skill came out 7.7e-5 apart) and nothing read a task file.
    task = throw_task(tmp_path)
    run_primo("learn", "--task", str(task), "--out", str(tmp_path / "out"))
    g = primo.Generalizer.from_task(task)
    assert (len(g), g.names, g.query_dim) == (2, ["shoulder", "elbow"], 1)
    rollouts = np.genfromtxt(tmp_path / "out" / "rollouts.csv", delimiter=",", names=True)
    assert len(rollouts) == 2
    for r in rollouts:
        handed = np.loadtxt(tmp_path / "out" / "trajectories" / f"rollout-{int(r['rollout']):04}.csv",
                            delimiter=",", skiprows=1)
        times, y = g.generalize(r["query"]).run(dt=0.01)
        np.testing.assert_allclose(times, handed[:, 0], atol=1e-6)
        np.testing.assert_array_equal(y.astype(np.float32), handed[:, 1:].astype(np.float32))
    # The first demonstration's DMP is Dmp.fit's with primo learn's options
    # (the others take the first one's amplitude scaling).
    data = np.loadtxt(task.parent / "demos" / "fast.csv", delimiter=",", skiprows=1)
    fast = primo.Dmp.fit(data[:, 0], data[:, 1:], names=["shoulder", "elbow"], kernels=20,
                         margin=0, overlap=2.0, ridge=1e-6)
    assert g.examples[0][1] == fast
    assert fast != primo.Dmp.fit(data[:, 0], data[:, 1:], names=["shoulder", "elbow"], kernels=20)
    assert [float(q[0]) for q, _ in g.examples] == [np.float32(1.8079), np.float32(1.0639)]
    again = pickle.loads(pickle.dumps(g))
    np.testing.assert_array_equal(again.params(1.5), g.params(1.5))


def test_a_task_that_cannot_be_built_is_refused_in_python_terms(tmp_path):
    with pytest.raises(OSError, match="nothing.toml"):
        primo.Generalizer.from_task(tmp_path / "nothing.toml")
    task = throw_task(tmp_path)
    (task.parent / "demos" / "slow.csv").unlink()
    with pytest.raises(ValueError, match="slow.csv"):
        primo.Generalizer.from_task(task)
    with pytest.raises(ValueError, match="built-in pour builds its skill itself"):
        primo.Generalizer.from_task(ROOT / "examples" / "pour.toml")
