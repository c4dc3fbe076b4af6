"""The examples in the docstrings run (issue 20): every module of rot4d_widget.core, and the
geometry modules that carry examples, through `doctest.testmod`; a failing example fails here.

(The pytest configuration is not changed: this file is the ``--doctest-modules`` of the core.)
"""

from __future__ import annotations

import doctest
import importlib
import pathlib

import numpy as np
import pytest

PKG = pathlib.Path(__file__).resolve().parents[2] / "rot4d_widget"
CORE = sorted(f"rot4d_widget.core.{p.stem}" for p in (PKG / "core").glob("*.py") if p.stem != "__init__")
#: geometry modules with examples (each is listed so that one losing its examples is noticed)
GEOMETRY = ["rot4d_widget.geometry._ragged", "rot4d_widget.geometry.catalogue",
            "rot4d_widget.geometry.regular", "rot4d_widget.geometry.star_regular", "rot4d_widget.geometry.uniform",
            "rot4d_widget.geometry.wythoff"]
#: the core's public functions that must carry an example
MUST_HAVE = {
    "rot4d_widget.core.rotation": ["simple_rotation", "double_rotation", "as_rotation_matrix"],
    "rot4d_widget.core.keymap": ["Action.parse", "Keymap"],
    "rot4d_widget.core.state": ["RotationState.press", "RotationState.to_dict"],
    "rot4d_widget.core.text": ["number_text"],
}


@pytest.mark.parametrize("name", CORE + GEOMETRY)
def test_the_examples_in_the_docstrings_run(name):
    module = importlib.import_module(name)
    with np.printoptions(legacy=False):
        result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE,
                                 extraglobs={"np": np}, verbose=False, report=True)
    assert result.failed == 0, f"{result.failed} of {result.attempted} examples in {name} failed (see above)"
    if name in GEOMETRY:
        assert result.attempted > 0, f"{name} has no examples any more: take it off the list"


@pytest.mark.parametrize("module_name, names", sorted(MUST_HAVE.items()))
def test_the_cores_public_functions_carry_examples(module_name, names):
    module = importlib.import_module(module_name)
    finder = doctest.DocTestFinder()
    for qualname in names:
        obj = module
        for part in qualname.split("."):
            obj = getattr(obj, part)
        tests = [t for t in finder.find(obj, qualname, module=module, globs={}) if t.name == qualname]
        assert tests and tests[0].examples, f"{module_name}.{qualname} has no example in its docstring"


def test_a_failing_example_fails(tmp_path, monkeypatch):
    """The check itself: a module whose example is wrong is counted as failed."""
    (tmp_path / "wrong_example.py").write_text('def f():\n    """\n    >>> 1 + 1\n    3\n    """\n')
    monkeypatch.syspath_prepend(str(tmp_path))
    module = importlib.import_module("wrong_example")
    result = doctest.testmod(module, report=False)
    assert (result.failed, result.attempted) == (1, 1)
