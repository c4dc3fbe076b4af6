"""Keeping what the widget shows (issue 12): recordings, replay, state files, meshes, pictures.

The functions behind these (rot4d_widget.keep.meshes, .statefile, .recorder, .animation, .picture) have their
own tests; here the widget's methods are checked against the widget itself: a replay ends
where the live widget ended, a state file rebuilds the same view, the mesh is the slice shown.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import trimesh
from PIL import Image

from rot4d_widget import Rot4DWidget
from rot4d_widget.keep.meshes import load_mesh
from rot4d_widget.keep.recorder import Recording

pytestmark = pytest.mark.usefixtures("recording_comms")


def _drive(w):
    """Keys, a slider-like trait set, and a state set from code then refresh()."""
    for k in "44488":
        w.press(k)
    w.press("y", shift=True)
    w.press("k")
    w.press("+")
    w.state.c0_step = 0.05
    w.refresh()
    w.c0 = 0.25
    w.theta0 = 0.07
    w.press("l")


def test_a_recording_replays_to_the_same_state_bit_for_bit(make, tmp_path):
    w = make("24-cell")
    w.press("4")
    w.start_recording()  # from here on
    start = w.state.matrix.copy()
    _drive(w)
    rec = w.recording
    assert isinstance(rec, Recording) and len(rec) >= 11
    np.testing.assert_array_equal(rec.initial_state().matrix, start)
    other = make("24-cell")
    other.replay(rec)
    np.testing.assert_array_equal(other.state.matrix, w.state.matrix)
    assert (other.c0, other.theta0, other.alpha, other.state.c0_step) == (w.c0, w.theta0, w.alpha, w.state.c0_step)
    np.testing.assert_array_equal(other.slice.points, w.slice.points)  # the same slice
    rec.save(tmp_path / "keys.json")
    third = make("24-cell")
    third.replay(tmp_path / "keys.json")
    np.testing.assert_array_equal(third.state.matrix, w.state.matrix)
    with pytest.raises(TypeError, match="Recording"):
        third.replay(42)


def test_a_stack_s_own_keys_replay_on_the_stack(make):
    w = make("24-cell", slices=3)
    w.press("n")
    w.press("4")
    w.press("g")
    other = make("24-cell", slices=3)
    other.replay(w.recording)
    assert (other.slices, other.spacing) == (4, pytest.approx(w.spacing))
    np.testing.assert_array_equal(other.state.matrix, w.state.matrix)


def test_state_files_round_trip_and_reset_to_the_loaded_state(make, tmp_path):
    w = make("24-cell", slices=5, arrangement="grid", face_opacity=0.3)
    _drive(w)
    path = tmp_path / "view.json"
    w.save_state(path)
    doc = json.loads(path.read_text())
    assert doc["settings"]["slices"] == 5 and doc["settings"]["arrangement"] == "grid"

    back = Rot4DWidget.from_state(path, _autotick=False)
    try:
        assert (back.slices, back.arrangement, back.face_opacity) == (5, "grid", 0.3)
        np.testing.assert_array_equal(back.state.matrix, w.state.matrix)
        assert (back.c0, back.theta0, back.alpha) == (w.c0, w.theta0, w.alpha)
        back.press("2")
        back.press("r")  # r returns to the loaded state, not the identity
        np.testing.assert_allclose(back.state.matrix, w.state.matrix, atol=0)
        assert back.c0 == w.c0
    finally:
        back.close()

    into = make("24-cell", slices=5)
    into.load_state(path)
    np.testing.assert_array_equal(into.state.matrix, w.state.matrix)
    assert into.arrangement == "grid" and into.face_opacity == 0.3
    with pytest.raises(ValueError, match="5-cell|24-cell"):
        make("5-cell").load_state(path)


def test_a_loaded_orientation_is_checked(make, tmp_path):
    w = make("8-cell")
    w.press("4")
    path = tmp_path / "s.json"
    w.save_state(path)
    doc = json.loads(path.read_text())
    doc["state"]["orientation"][0][0] += 1e-8  # rounding in a hand-edited file: re-orthonormalised
    path.write_text(json.dumps(doc))
    w2 = make("8-cell")
    w2.load_state(path)
    m = w2.state.matrix
    np.testing.assert_allclose(m @ m.T, np.eye(4), atol=1e-14)
    doc["state"]["orientation"][0][0] += 1e-3  # not a rotation any more
    path.write_text(json.dumps(doc))
    with pytest.raises(ValueError, match="orientation"):
        w2.load_state(path)
    np.testing.assert_array_equal(w2.state.matrix, m)  # refused before any change


def test_slice_mesh_is_the_slice_shown_and_survives_ply(make, tmp_path):
    w = make("24-cell", c0=0.3)
    w.press("4")
    mesh = w.slice_mesh()
    s = w.slice
    assert isinstance(mesh, trimesh.Trimesh) and mesh.is_watertight
    assert mesh.volume == pytest.approx(s.volume, rel=1e-9)  # the slicer's own volume, independent
    assert set(np.unique(mesh.face_attributes["group"])) == set(np.unique(s.groups))
    mesh.export(tmp_path / "slice.ply")
    back = load_mesh(tmp_path / "slice.ply")
    assert back.volume == pytest.approx(s.volume, rel=1e-6)
    np.testing.assert_array_equal(np.sort(back.face_attributes["group"]), np.sort(mesh.face_attributes["group"]))

    stack = make("24-cell", slices=3, spacing=0.3)  # |w| <= 0.3: no slice empty
    m3 = stack.slice_mesh()
    assert len(np.unique(m3.face_attributes["group"])) == 3  # coloured by w: a group per slice


def test_render_and_render_animation(make, tmp_path):
    w = make("5-cell", width=320, height=240)
    for k in "448":
        w.press(k)
    w.render(tmp_path / "view.png")
    assert Image.open(tmp_path / "view.png").size == (320, 240)
    n = w.render_animation(tmp_path / "keys.gif", size=(160, 120))
    assert n == len(w.recording) + 1  # the start and one frame per step
    gif = Image.open(tmp_path / "keys.gif")
    assert gif.size == (160, 120) and gif.n_frames >= 2


def test_the_readme_keep_what_you_see_block_runs(make, tmp_path, monkeypatch):
    """The README's block, as written, on a widget made by the test (no page: no screenshot)."""
    import pathlib
    import re

    readme = (pathlib.Path(__file__).resolve().parents[1] / "README.md").read_text()
    section = readme.split("## Keep what you see", 1)[1]
    block = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    monkeypatch.chdir(tmp_path)
    w = make("24-cell")
    w.press("4")
    ns = {"w": w, "Rot4DWidget": lambda *a, **k: make(*a, **k)}
    ns["Rot4DWidget"].from_state = lambda path: Rot4DWidget.from_state(path, _autotick=False)
    exec(compile(block, "README.md", "exec"), ns)
    for name in ("view.pdf", "slice.ply", "view.json", "keys.json", "turn.gif"):
        assert (tmp_path / name).stat().st_size > 0, name
    np.testing.assert_array_equal(ns["w2"].state.matrix, w.state.matrix)
    ns["w2"].close()
