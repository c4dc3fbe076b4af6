"""State files and a recording written by the code before issue 38 (main at 4b0edfb, with the old
module paths and their import hook) load with today's code and give what was saved.

The files are in tests/fixtures, written by tests/fixtures/make_fixtures.py; ``expected.json``
holds what the objects held when they were saved (read from the objects, not from the files).
The rotations are also checked against the same keys pressed here, on a fresh `RotationState`.
"""

from __future__ import annotations

import importlib
import json
import pathlib
import warnings

import numpy as np
import pytest

from rot4d_widget import Field4D, Recording, RotationState, StackSource, load_state
from rot4d_widget.keep import rebuild
from rot4d_widget.sources import datasets
from rot4d_widget.sources.protocol import PolytopeSource

HERE = pathlib.Path(__file__).resolve().parents[1] / "fixtures"
EXPECTED = json.loads((HERE / "expected.json").read_text())


def _same_state(state: RotationState, want: dict) -> None:
    np.testing.assert_allclose(state.matrix, np.array(want["matrix"]), rtol=0, atol=1e-15)
    for name in ("c0", "theta0", "alpha", "beta", "c0_step"):
        assert getattr(state, name) == pytest.approx(want[name], abs=1e-15), name


def _pressed(keys: str) -> RotationState:
    st = RotationState()
    for k in keys:
        st.press(k)
    return st


def test_the_fixtures_were_written_by_the_code_before_issue_38():
    assert EXPECTED["written_by"]["commit"].startswith("4b0edfb")


def test_a_widget_s_state_file_loads_into_a_widget():
    want = EXPECTED["widget_24cell"]
    from rot4d_widget import Rot4DWidget

    w = Rot4DWidget.from_state(HERE / "widget_24cell.json", _autotick=False)
    try:
        _same_state(w.state, want["state"])
        assert w.face_opacity == want["face_opacity"] == 0.3
        assert w.source.polytope.counts == (24, 96, 96, 24)  # the 24-cell's vertices, edges, faces, cells
        assert w.theta0 == 0.07
    finally:
        w.close()


def test_a_state_file_of_a_polytope_loads_without_a_widget():
    state, source, settings = load_state(HERE / "widget_24cell.json")
    assert isinstance(source, PolytopeSource) and source.polytope.counts == (24, 96, 96, 24)
    _same_state(state, EXPECTED["widget_24cell"]["state"])
    assert settings["face_opacity"] == 0.3


def test_a_recording_replays_to_the_state_it_ended_in(make):
    want = EXPECTED["recording_24cell"]
    rec = Recording.load(HERE / "recording_24cell.json")
    assert len(rec) == want["events"]
    w = make("24-cell")
    w.replay(rec)
    np.testing.assert_array_equal(w.state.matrix, np.array(want["state"]["matrix"]))  # bit for bit
    assert (w.c0, w.theta0, w.alpha) == (want["state"]["c0"], want["state"]["theta0"], want["state"]["alpha"])


def test_a_stack_s_state_file_rebuilds_the_stack():
    want = EXPECTED["stack_tesseract"]
    state, source, settings = load_state(HERE / "stack_tesseract.json")
    assert isinstance(source, StackSource)
    assert (source.slices, source.spacing, source.arrangement) == (4, pytest.approx(0.3), "grid")
    assert (want["slices"], want["spacing"], want["arrangement"]) == (4, 0.3, "grid")
    assert source.wraps.polytope.counts == (16, 32, 24, 8)  # the tesseract's
    _same_state(state, want["state"])
    np.testing.assert_allclose(state.matrix, _pressed("2266j").matrix, rtol=0, atol=1e-15)
    assert settings == {"slices": 4, "spacing": 0.3, "arrangement": "grid"}


def test_a_field_named_by_its_function_is_rebuilt_with_that_function():
    import saved_fields

    want = EXPECTED["field_function"]
    state, field, settings = load_state(HERE / "field_function.json", allow_code=True)
    assert isinstance(field, Field4D) and field.function is saved_fields.ball
    assert want["function"] == "saved_fields:ball"
    assert list(field.levels) == want["levels"] == [1.0, 2.0]
    assert (field.resolution, field.coarse_resolution) == (12, 8)
    assert [list(e) for e in field.extent] == want["extent"] == [[-2.0, 2.0]] * 4
    _same_state(state, want["state"])
    np.testing.assert_allclose(state.matrix, _pressed("48").matrix, rtol=0, atol=1e-15)
    assert settings == {"rendering": "surface", "cmap": "viridis"}


def test_a_field_opened_from_a_file_is_reopened_beside_the_state_file():
    want = EXPECTED["field_file"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        state, field, _ = load_state(HERE / "field_file.json")
    values = np.asarray(field.values)
    assert values.shape == tuple(want["shape"]) == (5, 5, 5, 5)
    ax = np.linspace(-1.0, 1.0, 5)  # the file's values, made again: 1 - |xyz|^2 - w/4
    X, Y, Z, W = np.meshgrid(ax, ax, ax, ax, indexing="ij")
    np.testing.assert_allclose(values, 1.0 - (X * X + Y * Y + Z * Z) - 0.25 * W, rtol=0, atol=1e-12)
    assert float(values.sum()) == pytest.approx(want["sum"])
    assert list(field.levels) == want["levels"] == [0.5]
    np.testing.assert_allclose(state.matrix, _pressed("6").matrix, rtol=0, atol=1e-15)


@pytest.mark.parametrize("old", sorted(rebuild.OLD_MODULES))
def test_every_old_module_path_names_a_module_of_today(old):
    new = rebuild.OLD_MODULES[old]
    assert rebuild.module_now(old) == new and importlib.import_module(new)
    with pytest.raises(ModuleNotFoundError):  # the old path itself is gone
        importlib.import_module(old)


def test_a_field_function_named_by_an_old_module_path_is_found_where_it_lives(monkeypatch, tmp_path):
    """A file from before the wings names package code as ``rot4d_widget.datasets:...``."""
    import saved_fields

    monkeypatch.setattr(datasets, "saved_ball", saved_fields.ball, raising=False)
    doc = json.loads((HERE / "field_function.json").read_text())
    doc["source"]["function"] = "rot4d_widget.datasets:saved_ball"
    (tmp_path / "old.json").write_text(json.dumps(doc))
    _, field, _ = load_state(tmp_path / "old.json", allow_code=True)
    assert field.function is saved_fields.ball
    assert rebuild.module_now("mylab.rot4d_widget.fields") == "mylab.rot4d_widget.fields"
