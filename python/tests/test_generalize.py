"""Generalization over DMPs at task queries."""

import pickle

import numpy as np
import pytest

import primo


def demo(height):
    t = np.linspace(0.0, 1.0, 201)
    s = t * t * (3 - 2 * t)
    return t, np.column_stack([0.6 * s, 0.1 + height * np.sin(np.pi * s) ** 2])


@pytest.mark.parametrize("method", ["lwr", "gpr"])
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
    with pytest.raises(ValueError, match="method"):
        primo.Generalizer([(0.1, dmps[0])], method="knn")
    with pytest.raises(ValueError, match="at least one"):
        primo.Generalizer([])
