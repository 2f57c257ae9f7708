"""primo.ProMp: fit, mean and variance, conditioning, blending, pickling,
the file `primo promp run` reads, and the refusals, in Python's terms."""

import copy
import pickle

import numpy as np
import pytest

import primo

T = np.linspace(0.0, 1.0, 101)


def demos(heights):
    s = T * T * (3 - 2 * T)
    return [(T, np.column_stack([h * s, 0.2 * h * np.sin(np.pi * T)])) for h in heights]


def test_mean_and_variance_follow_the_demonstrations():
    heights = [0.8, 0.9, 1.0, 1.1, 1.2]
    p = primo.ProMp.fit(demos(heights), names=["x", "y"], kernels=20)
    assert p.names == ["x", "y"] and p.kernels == 20
    ends = np.array(heights)
    assert abs(p.mean([1.0])[0, 0] - ends.mean()) < 1e-3
    assert abs(p.variance([1.0])[0, 0] - ends.var(ddof=1)) < 0.1 * ends.var(ddof=1)


def test_conditioning_passes_the_point_and_moves_the_correlated_column():
    p = primo.ProMp.fit(demos([0.8, 0.9, 1.0, 1.1, 1.2]), names=["x", "y"], kernels=20)
    q = p.condition(1.0, {"x": 1.15})
    assert abs(q.mean([1.0])[0, 0] - 1.15) < 1e-6
    # y's bump grows with the height: about 0.2 · 1.15 at mid-movement.
    assert abs(q.mean([0.5])[0, 1] - 0.23) < 5e-3
    assert q.variance([1.0])[0, 0] < 1e-3 * p.variance([1.0])[0, 0] + p.variance([0.0])[0, 0]
    # The original is unchanged.
    assert abs(p.mean([1.0])[0, 0] - 1.0) < 1e-3


def test_params_are_the_means_weights_and_velocity_its_slope():
    p = primo.ProMp.fit(demos([0.8, 1.0, 1.2]), names=["x", "y"], kernels=20)
    w = p.params
    assert w.shape == (40,) and w.dtype == np.float64
    q = copy.copy(p)
    q.params = w + np.r_[np.full(20, 0.1), np.zeros(20)]
    assert np.allclose(q.mean(T)[:, 0], p.mean(T)[:, 0] + 0.1, atol=1e-6)
    assert np.array_equal(q.mean(T)[:, 1], p.mean(T)[:, 1])
    assert np.array_equal(q.variance(T), p.variance(T))
    assert np.array_equal(pickle.loads(pickle.dumps(q)).params, q.params)  # kept in f64
    # The smoothstep's slope 6 z (1 − z) at mid-movement, 1 s long.
    assert abs(p.velocity(0.5)[0, 0] - 1.5) < 0.02
    assert np.array_equal(p.velocity([0.0, 1.0]).shape, (2, 2))
    with pytest.raises(ValueError, match="ProMP weights: expected length 40, found 3"):
        q.params = [1.0, 2.0, 3.0]
    with pytest.raises(ValueError, match=r"params\[2\]: NaN is not a finite number"):
        q.params = np.r_[1.0, 2.0, np.nan, np.zeros(37)]
    with pytest.raises(ValueError, match=r"params\[0\]: 1e300 is out of f32 range"):
        q.params = np.full(40, 1e300)  # its positions come out in f32
    assert np.allclose(q.mean(1.0)[0, 0], p.mean(1.0)[0, 0] + 0.1, atol=1e-6)  # unchanged by the refusals


def test_blend_pickle_and_refusals():
    a = primo.ProMp.fit(demos([0.5, 0.6, 0.7]), names=["x", "y"], kernels=10)
    b = primo.ProMp.fit(demos([1.0, 1.5, 2.0]), names=["x", "y"], kernels=10)
    mean, var = a.blend(b, [1.0, 0.0], [1.0, 1.0])
    assert np.allclose(mean[0], a.mean(1.0)[0]) and np.allclose(mean[1], b.mean(1.0)[0])
    again = pickle.loads(pickle.dumps(a.condition(0.5, {"y": 0.13}, variance=1e-4)))
    assert np.array_equal(again.mean(T), a.condition(0.5, {"y": 0.13}, variance=1e-4).mean(T))
    assert np.array_equal(copy.copy(a).variance(T), a.variance(T))
    with pytest.raises(ValueError, match="at least two demonstrations"):
        primo.ProMp.fit(demos([1.0]))
    with pytest.raises(ValueError, match="different lengths"):
        primo.ProMp.fit([(T, T), (T[:50], T[:50])])
    with pytest.raises(ValueError, match=r"demos\[1\]: column `y1` is missing \(the columns of demos\[0\]\)"):
        primo.ProMp.fit([(T, np.column_stack([T, T])), (T, T)])
    with pytest.raises(ValueError, match='no column "w" among x, y'):
        a.condition(0.5, {"w": 1.0})
    with pytest.raises(ValueError, match="phase"):
        a.condition(1.5, {"x": 1.0})
    with pytest.raises(ValueError, match="kernels=1"):
        primo.ProMp.fit(demos([1.0, 2.0]), kernels=1)
    # The same checks as `primo promp fit`: a quaternion is not a ProMP's.
    quaternion = np.column_stack([np.ones_like(T), np.zeros_like(T), np.zeros_like(T), np.zeros_like(T)])
    with pytest.raises(ValueError, match="qw,qx,qy,qz is an orientation"):
        primo.ProMp.fit([(T, quaternion), (T, quaternion)], names=["qw", "qx", "qy", "qz"])
    with pytest.raises(ValueError, match="is not a phase"):
        a.mean([2.0])


def test_a_promp_is_the_file_primo_promp_runs(run_primo, tmp_path):
    p = primo.ProMp.fit(demos([0.8, 0.9, 1.0, 1.1, 1.2]), names=["x", "y"], kernels=15)
    path = tmp_path / "p.json"
    path.write_text(p.to_json())
    z = np.linspace(0.0, 1.0, 11)
    rows = np.loadtxt(run_primo("promp", "run", str(path), "--dt", str(p.duration / 10)).splitlines(), delimiter=",", skiprows=1)
    np.testing.assert_allclose(rows[:, 1:], p.mean(z), atol=1e-5)
    conditioned = p.condition(1.0, {"x": 1.2})
    rows = np.loadtxt(
        run_primo("promp", "run", str(path), "--dt", str(p.duration / 10), "--via", f"{p.duration},x,1.2").splitlines(),
        delimiter=",",
        skiprows=1,
    )
    np.testing.assert_allclose(rows[:, 1:], conditioned.mean(z), atol=1e-4)
    assert primo.ProMp.from_json(p.to_json()).mean(z).tolist() == p.mean(z).tolist()
    with pytest.raises(ValueError, match="not a ProMP file"):
        primo.ProMp.from_json('{"format": "primo-dmp", "version": 1, "names": [], "values": []}')
