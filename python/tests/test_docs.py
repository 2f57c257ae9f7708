"""Docstrings a Python user reads: the compiled classes' examples run
(pytest --doctest-modules collects only the Python modules'), every
public name is documented at run time with its parameters and an example,
and the type stubs carry the very same docstrings."""

import doctest
import importlib.util
import inspect
import pathlib

import pytest

import primo
import primo._primo
import primo.experiments
import primo.sweep

STUBDOCS = pathlib.Path(__file__).resolve().parent.parent / "tools" / "stubdocs.py"


def test_docstring_examples_run():
    result = doctest.testmod(primo._primo, optionflags=doctest.ELLIPSIS)
    assert result.attempted >= 100 and result.failed == 0


def _modules():
    modules = [primo, primo.experiments, primo.sweep]
    try:
        modules.append(importlib.import_module("primo.env"))
        modules.append(importlib.import_module("primo.gym"))
    except ImportError:  # Gymnasium is the [gym] extra
        pass
    return modules


def _public():
    """(qualified name, object) of every public class, method, property
    and function of the package, each once."""
    seen = set()
    for module in _modules():
        names = getattr(module, "__all__", None) or [n for n in dir(module) if not n.startswith("_")]
        for name in names:
            obj = getattr(module, name)
            if not callable(obj) or not getattr(obj, "__module__", "").startswith("primo"):
                continue  # data, or imported from elsewhere
            if id(obj) in seen:
                continue
            seen.add(id(obj))
            yield f"{module.__name__}.{name}", obj
            if inspect.isclass(obj):
                for attr, member in vars(obj).items():
                    if not attr.startswith("_"):
                        yield f"{module.__name__}.{name}.{attr}", member


def _parameters(obj):
    """The parameter names a caller passes, or None without a signature."""
    try:
        signature = inspect.signature(obj)
    except (TypeError, ValueError):  # a compiled class without a constructor
        return None
    return [p for p in signature.parameters if p not in ("self", "cls")]


def test_every_public_name_has_a_docstring_with_its_parameters_and_an_example():
    problems = []
    count = 0
    for name, member in _public():
        count += 1
        target = member.__func__ if isinstance(member, (staticmethod, classmethod)) else member
        doc = inspect.getdoc(target) or ""
        if not doc.strip():
            problems.append(f"{name}: no docstring")
            continue
        if not callable(target) or isinstance(target, property):
            continue  # a property: its docstring says what it holds
        parameters = _parameters(target) or []
        missing = [p for p in parameters if p not in doc]
        if missing:
            problems.append(f"{name}: the docstring does not name {', '.join(missing)}")
        if (inspect.isclass(target) or parameters) and ">>>" not in doc:
            problems.append(f"{name}: no example")
    assert count > 100
    assert not problems, "\n".join(problems)


def test_the_stubs_carry_the_runtime_docstrings():
    spec = importlib.util.spec_from_file_location("stubdocs", STUBDOCS)
    stubdocs = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(stubdocs)
    text = stubdocs.STUBS.read_text()
    rewritten = stubdocs.rewritten(text, primo._primo)
    assert rewritten == text, f"run python {STUBDOCS} to write the runtime docstrings into the stubs"


def test_help_shows_the_signature_and_the_docstring():
    text = pydoc_text(primo.Dmp.fit)
    assert "fit(t, y, names=None, kernels=30" in text
    assert "Raises:" in text and ">>> " in text


def pydoc_text(obj):
    import pydoc

    return pydoc.render_doc(obj, renderer=pydoc.plaintext)
