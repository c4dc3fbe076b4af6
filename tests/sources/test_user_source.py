"""A user's own source gets what a built-in one gets, through the source protocol alone (issue 20).

`ThickTorus` below is written as a user would write it, following the protocol's docstring
(`rot4d_widget.sources.protocol`): points on the Clifford torus within ``thickness`` of w = c0 (as
in README.md's example), each drawn as a small triangle so that there is a mesh to export, with
its own setting ``thickness`` (``settings`` + ``apply_setting``) and coarse steps
(``coarse_steps``, ``slice(..., coarse=...)``).  Nothing in the package knows its class: it gets a
static render, a mesh export, a recording of its own setting replayed, an animation that follows
the setting, a stack of parallel slices around it and a state file that says it cannot be rebuilt.

The widget's part (``Rot4DWidget.refresh()`` recording a change of ``thickness``) belongs to the
view wing and is tested there.
"""

from __future__ import annotations

import copy

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg

from rot4d_widget import RotationState, SliceData
from rot4d_widget.keep.meshes import slice_mesh
from rot4d_widget.keep.rebuild import SourceNotRebuildable, describe_source
from rot4d_widget.keep.statefile import load_state, save_state
from rot4d_widget.keep.pictures.state_picture import render_state, state_source
from rot4d_widget.keep.recorder import Recorder, Recording
from rot4d_widget.keep.animation import animation_states, render_frames
from rot4d_widget.sources.protocol import as_source, inner_source, settings_of, takes_coarse


class ThickTorus:
    """Points on the Clifford torus; the slice shows those within `thickness` of w = c0, each as a
    small triangle.  Held keys (``coarse=True``) draw every fourth point."""

    size = 1.0
    n_groups = 1
    coarse_steps = True

    def __init__(self, n=1500, thickness=0.04, seed=0):
        a, b = np.random.default_rng(seed).uniform(0, 2 * np.pi, (2, n))
        self.points = np.stack([np.cos(a), np.sin(a), np.cos(b), np.sin(b)], 1) / np.sqrt(2)
        self.thickness = thickness
        self.coarse_calls = 0

    @property
    def settings(self) -> dict:
        return {"thickness": self.thickness}

    def apply_setting(self, name, value) -> None:
        if name != "thickness":
            raise ValueError(f"A thick torus's only setting is 'thickness', not {name!r}")
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0:
            raise ValueError(f"Expected 'thickness' to be a number > 0, got {value!r}")
        self.thickness = float(value)

    def slice(self, matrix, c0, coarse=False):
        pts = self.points[::4] if coarse else self.points
        self.coarse_calls += bool(coarse)
        q = pts @ np.asarray(matrix).T
        near = q[np.abs(q[:, 3] - c0) < self.thickness, :3]
        corners = (near[:, None, :] + 0.03 * np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1]])).reshape(-1, 3)
        triangles = np.arange(len(corners)).reshape(-1, 3)
        return SliceData.build(corners, triangles=triangles, readout=[("points", str(len(near)))],
                               show_points=False)

    def describe(self):
        return {"kind": "thick-torus", "n": len(self.points), "thickness": self.thickness}


def _pixels(fig) -> np.ndarray:
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())[..., :3].copy()


def _turned_recording(thickness_at_start=0.04):
    """Keys 4 and 8 pressed, the thickness set twice between them."""
    st = RotationState()
    rec = Recorder(st, clock=lambda: 0.0, source_settings={"thickness": thickness_at_start})
    for k, key in enumerate("48"):
        st.press(key)
        rec.record(key, False, *st.keymap.resolve(key), t=0.1 * (2 * k + 1))
        rec.record_source("thickness", 0.08 + 0.04 * k, t=0.1 * (2 * k + 2))
    return rec.recording(), st


def test_the_source_follows_the_protocol_and_takes_coarse_steps():
    src = as_source(ThickTorus())
    assert settings_of(src) == {"thickness": 0.04} and takes_coarse(src) and inner_source(src) is src
    fine, coarse = src.slice(np.eye(4), 0.0), src.slice(np.eye(4), 0.0, coarse=True)
    assert 0 < len(coarse.triangles) < len(fine.triangles)
    stack = state_source(src, slices=3)  # parallel slices around it, as the widget makes them
    assert inner_source(stack) is src and takes_coarse(stack)
    assert settings_of(stack) == {"slices": 3, "spacing": None, "arrangement": "oval", "thickness": 0.04}


def test_a_static_render_of_a_user_source():
    src = ThickTorus()
    state = RotationState()
    thin = _pixels(render_state(state, src, size=(160, 120), dpi=40))
    assert thin.shape == (120, 160, 3)
    background = thin[0, 0]
    drawn = np.any(thin != background, axis=-1).sum()
    assert drawn > 100  # the triangles are there
    src.apply_setting("thickness", 0.2)
    thick = _pixels(render_state(state, src, size=(160, 120), dpi=40, frame="camera"))
    thin_camera = _pixels(render_state(state, ThickTorus(), size=(160, 120), dpi=40, frame="camera"))
    assert np.any(thick != background, axis=-1).sum() > np.any(thin_camera != background, axis=-1).sum()
    # parallel slices of it, and the settings a stack takes, through render_state's keywords
    fig = render_state(state, src, slices=3, arrangement="grid", size=(160, 120), dpi=40)
    assert np.any(_pixels(fig) != background, axis=-1).sum() > 100
    with pytest.raises(TypeError, match="`levels` applies to sources with iso levels"):
        render_state(state, src, levels=(0.5,))


def test_a_mesh_export_of_a_user_source(tmp_path):
    src = ThickTorus()
    data = src.slice(np.eye(4), 0.0)
    mesh = slice_mesh(data)
    assert len(mesh.faces) == len(data.triangles) > 0
    assert np.array_equal(mesh.face_attributes["group"], np.zeros(len(data.triangles)))
    np.testing.assert_allclose(mesh.vertices, data.points[np.unique(data.triangles)], atol=1e-12)
    mesh.export(tmp_path / "torus.ply")
    assert (tmp_path / "torus.ply").stat().st_size > 0


def test_a_recording_keeps_and_replays_the_sources_own_setting(tmp_path):
    r, st = _turned_recording()
    assert r.initial_source == {"thickness": 0.04}
    assert [(e.name, e.value) for e in r.events if type(e).__name__ == "SourceSetting"] == [
        ("thickness", 0.08), ("thickness", 0.12)]
    r.save(tmp_path / "keys.json")
    back = Recording.load(tmp_path / "keys.json")
    assert back.to_dict() == r.to_dict()
    src = ThickTorus(thickness=0.5)
    got = back.replay(None, src)
    assert src.thickness == 0.12 and np.array_equal(got.matrix, st.matrix)
    # the start setting comes first, then each in order with the keys (set_source sees them all)
    calls = []
    back.replay(None, None, set_source=lambda name, value: calls.append((name, value)))
    assert calls == [("thickness", 0.04), ("thickness", 0.08), ("thickness", 0.12)]
    # a value the source refuses is its own error, when replayed
    bad = Recorder(RotationState(), clock=lambda: 0.0)
    bad.record_source("thickness", -1.0)
    with pytest.raises(ValueError, match="'thickness' to be a number > 0"):
        bad.recording().replay(None, ThickTorus())


def test_a_replay_on_a_source_without_the_setting_is_refused_before_any_change():
    from rot4d_widget.sources.protocol import PolytopeSource

    r, _ = _turned_recording()
    state = RotationState()
    with pytest.raises(ValueError, match="sets 'thickness', which 24-cell does not have; its settings: none"):
        r.replay(state, PolytopeSource("24-cell"))
    assert np.array_equal(state.matrix, np.eye(4))
    # a stack around the torus passes the setting on to it
    stack = state_source(ThickTorus(), slices=2)
    r.replay(None, stack)
    assert inner_source(stack).thickness == 0.12


def test_animations_follow_the_sources_own_setting_on_a_copy():
    r, _ = _turned_recording()
    src = ThickTorus(thickness=0.3)
    seen = [s.thickness for _, _, s in animation_states(r, None, src)]
    assert seen == [0.04, 0.04, 0.08, 0.08, 0.12]
    assert src.thickness == 0.3  # the source given is left alone (its copy changed: copy.copy)
    frames = list(render_frames(r, None, src, size=(80, 60), dpi=20, annotate=False))
    assert len(frames) == len(r) + 1 and frames[0].shape == (60, 80, 3)
    assert copy.copy(src) is not src


def test_a_state_file_says_the_user_source_cannot_be_rebuilt(tmp_path):
    src = ThickTorus()
    d = describe_source(src)
    assert d["kind"] == "thick-torus" and d["thickness"] == 0.04
    assert d["rebuild"] == "a source of kind 'thick-torus' cannot be rebuilt from its description"
    st = RotationState()
    st.press("4")
    with pytest.warns(SourceNotRebuildable):
        save_state(tmp_path / "s.json", st, src)
    state, source, _ = load_state(tmp_path / "s.json", source=src)
    assert source is src and np.array_equal(state.matrix, st.matrix)
    # a stack around it is described with it, and is no more rebuildable
    stack = describe_source(state_source(src, slices=3))
    assert stack["kind"] == "stack" and stack["source"]["kind"] == "thick-torus" and stack["rebuild"] == d["rebuild"]


def test_a_user_source_is_wrapped_once_and_read_through_every_time():
    from rot4d_widget.sources.protocol import OPTIONAL_MEMBERS, SourceBase, UserSource, w_frame

    torus = ThickTorus()
    src = as_source(torus)
    assert isinstance(src, UserSource) and src.user_object is torus and as_source(src) is src
    assert src.describe() == torus.describe() and src.size == torus.size
    # what the object has is read from it each time; what it lacks is SourceBase's default
    assert src.levels is None and src.extent is None and w_frame(src) == (0.0, 1.0) and src.actions == {}
    assert src.w_range(np.eye(4)) == (-1.0, 1.0) and src.prepare() is None and src.sample is None
    torus.name = "torus"
    assert src.name == "torus"
    src.thickness = 0.3  # sets go to the object
    assert torus.thickness == 0.3 and src.settings == {"thickness": 0.3}
    outline = src.outline(np.eye(4), 0.0)  # the default outline is the object's own slice
    assert len(outline.triangles) == len(torus.slice(np.eye(4), 0.0).triangles)
    twin = copy.copy(src)
    assert isinstance(twin, UserSource) and twin.user_object is not torus
    twin.apply_setting("thickness", 0.5)
    assert torus.thickness == 0.3
    # every optional member has its default on the base, none only on the wrapper
    assert all(hasattr(SourceBase, name) for name in OPTIONAL_MEMBERS)
