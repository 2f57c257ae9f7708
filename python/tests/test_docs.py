"""The compiled classes' docstring examples run (pytest --doctest-modules
collects only the Python modules')."""

import doctest

import primo._primo


def test_docstring_examples_run():
    result = doctest.testmod(primo._primo, optionflags=doctest.ELLIPSIS)
    assert result.attempted >= 20 and result.failed == 0
