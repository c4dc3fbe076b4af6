"""A state file, a recording or a 4OFF file is data: loading one imports no module and runs no code
unless the caller says so (``allow_code=True``, or passes the function / source in)."""

import json
import sys
import uuid

import numpy as np
import pytest

from rot4d_widget import RotationState
from rot4d_widget.keep.statefile import load_state
from rot4d_widget.geometry.offfile import read_off
from rot4d_widget.keep.recorder import Recording
from rot4d_widget.core.rotation import random_rotation

from rot4d_widget.keep.rebuild import CodeNotAllowed
EXTENT = [[-1.2, 1.2], [-1.2, 1.2], [-1.2, 1.2], [-1.0, 1.0]]


@pytest.fixture
def planted(tmp_path, monkeypatch):
    """A module beside the files (importable: the folder is on sys.path and is the working directory)
    that leaves a marker file when it is imported and another when its function is called."""
    name = f"planted_{uuid.uuid4().hex}"
    imported, called = tmp_path / "imported.marker", tmp_path / "called.marker"
    (tmp_path / f"{name}.py").write_text(
        "import pathlib\n"
        f"pathlib.Path({str(imported)!r}).write_text('imported')\n"
        "def ball(x, y, z, w):\n"
        f"    pathlib.Path({str(called)!r}).write_text('called')\n"
        "    return 1.0 - (x * x + y * y + z * z) - 0.3 * w\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.chdir(tmp_path)
    yield name, imported, called
    sys.modules.pop(name, None)


def _field_description(function):
    return {"kind": "field", "axes": "xyzw", "extent": EXTENT, "w_per_unit": 1.0, "levels": [0.3],
            "name": "ball", "units": None, "function": function, "resolution": 12, "coarse_resolution": 8,
            "w_units": None, "rebuild": True}


def _state_file(path, source):
    doc = {"format": "rot4d_widget state", "version": 1, "state": RotationState(0.1, c0=0.05).to_dict(),
           "source": source, "settings": {}}
    path.write_text(json.dumps(doc))
    return path


@pytest.mark.parametrize("wrap", ["field", "stack"])
def test_a_state_file_naming_a_module_imports_nothing_unless_allowed(planted, tmp_path, wrap):
    name, imported, called = planted
    desc = _field_description(f"{name}:ball")
    if wrap == "stack":
        desc = {"kind": "stack", "slices": 3, "spacing": 0.2, "arrangement": "oval", "color_by": "w",
                "source": desc, "rebuild": True}
    path = _state_file(tmp_path / "view.json", desc)

    with pytest.raises(CodeNotAllowed, match=rf"{name}:ball.*allow_code=True") as info:
        load_state(path)
    assert isinstance(info.value, ValueError) and "view.json" in str(info.value)
    assert "source=" in str(info.value) and "function=" in str(info.value)  # the other two ways
    assert not imported.exists() and not called.exists() and name not in sys.modules

    # passing the function in: the file's description, the caller's code, nothing imported
    calls = []

    def mine(x, y, z, w):
        calls.append(1)
        return 1.0 - (x * x + y * y + z * z) - 0.3 * w

    _, given, _ = load_state(path, function=mine)
    given.slice(random_rotation(3), 0.1)
    assert calls and not imported.exists() and not called.exists() and name not in sys.modules

    # asked for: imported, and the function runs on the first slice
    _, field, _ = load_state(path, allow_code=True)
    assert imported.exists()
    field.slice(random_rotation(3), 0.1)
    assert called.exists()


def test_a_state_file_with_a_source_passed_in_needs_no_code(planted, tmp_path):
    from rot4d_widget import Field4D

    name, imported, called = planted
    path = _state_file(tmp_path / "view.json", _field_description(f"{name}:ball"))
    mine = Field4D.from_function(lambda x, y, z, w: x, EXTENT)
    assert load_state(path, source=mine).source is mine
    assert not imported.exists() and name not in sys.modules
    with pytest.raises(ValueError, match="`function` rebuilds a field the file describes by a function"):
        load_state(_state_file(tmp_path / "p.json", {"kind": "polytope", "name": "5-cell", "rebuild": True}),
                   function=lambda x, y, z, w: x)
    with pytest.raises(TypeError, match="`source` or `function`, not both"):
        load_state(path, source=mine, function=lambda x, y, z, w: x)


def test_a_recording_naming_a_module_runs_nothing(planted, tmp_path):
    from rot4d_widget.sources.tomography import StackSource

    name, imported, called = planted
    spec = f"{name}:ball"
    doc = {"format": "rot4d_widget recording", "version": 1,
           "initial": RotationState().to_dict(initial=True), "dropped": 0,
           "events": [{"t": 0.0, "key": spec, "shift": False, "action": {"kind": "custom", "name": spec},
                       "inverted": False, "label": spec},
                      {"t": 0.1, "key": "n", "shift": False, "action": {"kind": "custom", "name": "slice +"},
                       "inverted": False},
                      {"t": 0.2, "set": "c0", "value": 0.25}]}
    (tmp_path / "keys.json").write_text(json.dumps(doc))
    rec = Recording.load(tmp_path / "keys.json")
    stack = StackSource("5-cell", slices=2)
    st = rec.replay(None, stack)
    assert st.c0 == 0.25 and stack.slices == 3  # the source's own action, found by name, ran
    assert not imported.exists() and not called.exists() and name not in sys.modules


def test_a_4off_file_naming_a_module_runs_nothing(planted, tmp_path):
    name, imported, called = planted
    text = (f"4OFF\n# {name}:ball\n1 1 0 1\n__import__('{name}') 0 0 0\n1 0\n1 0\n")
    (tmp_path / "m.off").write_text(text)
    with pytest.raises(ValueError, match="vertex 0 has a coordinate that is not a number"):
        read_off(tmp_path / "m.off")
    text = f"4OFF\n1 1 0 1\n0 0 0 0\n1 0 {name}\n1 0\n"
    with pytest.raises(ValueError, match="colour"):
        read_off(text)
    assert not imported.exists() and name not in sys.modules
    np.testing.assert_array_equal(read_off("4OFF\n1 1 0 1\n0 0 0 1\n1 0\n1 0\n").vertices, [[0, 0, 0, 1]])
