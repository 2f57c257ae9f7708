"""The Python README's tour runs as pasted."""

import re

import pytest

from conftest import ROOT


def test_the_readmes_python_example_runs(tmp_path, monkeypatch):
    readme = (ROOT / "python" / "README.md").read_text()
    section = readme[readme.index("\n## A tour\n"):]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    monkeypatch.chdir(tmp_path)
    scope: dict = {}
    exec(compile(code, "python/README.md (the tour)", "exec"), scope)
    assert scope["learner"].status == "converged"
    q, error = scope["learner"].best
    assert abs(q - 0.2) < 0.01 and abs(error) < 0.002
    assert len(scope["cell"].rollout_many(scope["thetas"][:2])) == 2
    assert (tmp_path / "reach.json").exists()


def test_the_readmes_gym_example_runs():
    pytest.importorskip("gymnasium")
    pytest.importorskip("mujoco")
    readme = (ROOT / "python" / "README.md").read_text()
    section = readme[readme.index("\n## Any Gymnasium task: `primo.gym`\n"):]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    scope: dict = {}
    exec(compile(code, "python/README.md (primo.gym)", "exec"), scope)
    # the last learner's first value moved j0's via-point: measured at 0.4 s
    assert scope["episodes"][-1].trace.shape[1] == 2
