"""Keeping what the widget shows (issue 12): recordings, replay, state files, meshes, pictures --
and the view settings (issue 21: ``rendering``, ``cmap``, ``clim``, ``sections``) kept like every setting.

The functions behind these (rot4d_widget.keep.meshes, .statefile, .recorder, .animation, .pictures) have
their own tests; here the widget's methods are checked against the widget itself: a replay ends
where the live widget ended, a state file rebuilds the same view, the mesh is the slice shown.
The view settings are saved in a state file and loaded back (an older file without them means
their defaults, a bad value is refused naming what is allowed), recorded as `ViewSetting` events
that replay in order among the steps, and drawn by `render_animation` frame by frame with the
rendering and colour scale in effect at that frame (compared with `render_state` of the frame's
own state, pixel for pixel)."""

from __future__ import annotations

import inspect
import json
import warnings

import numpy as np
import pytest
import trimesh
from matplotlib.backends.backend_agg import FigureCanvasAgg
from PIL import Image

from rot4d_widget import Rot4DWidget
from rot4d_widget.core.state import RotationState
from rot4d_widget.keep.animation import animation_states, render_frames
from rot4d_widget.keep.meshes import load_mesh
from rot4d_widget.keep.pictures.state_picture import render_state
from rot4d_widget.keep.recorder import RECORDING_VERSION, VIEW_DEFAULTS, Recorder, Recording, ViewSetting
from rot4d_widget.keep.statefile import SETTING_NAMES, load_state, save_state
from rot4d_widget.sources.field.container import Field4D

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

    readme = (pathlib.Path(__file__).resolve().parents[2] / "README.md").read_text()
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


VIEW = {"rendering": "mip", "sections": (0.2, 0.5, 0.9), "cmap": "magma", "clim": (0, 2)}
BOX = ((-1.0, 1.0),) * 4


def _has_traits(*names) -> bool:
    from rot4d_widget import Rot4DWidget

    return all(n in Rot4DWidget.class_traits() for n in names)


def _render_takes(name) -> bool:
    return name in inspect.signature(render_state).parameters


# ---------------------------------------------------------------- state files
def test_a_state_file_keeps_the_view_settings(tmp_path):
    assert {"rendering", "sections", "cmap", "clim"} <= set(SETTING_NAMES)
    st = RotationState(theta0=0.1)
    doc = save_state(tmp_path / "s.json", st, "5-cell", VIEW)
    assert doc["settings"] == {"rendering": "mip", "sections": [0.2, 0.5, 0.9], "cmap": "magma", "clim": [0.0, 2.0]}
    on_disk = json.loads((tmp_path / "s.json").read_text())["settings"]
    assert on_disk["sections"] == [0.2, 0.5, 0.9] and on_disk["clim"] == [0.0, 2.0]  # tuples as lists
    _, _, settings = load_state(tmp_path / "s.json")
    assert settings == doc["settings"]


def _old_file(tmp_path, **settings):
    """A state file as written before the view settings existed (or with ``settings`` put in)."""
    path = tmp_path / "old.json"
    save_state(path, RotationState(), "5-cell", {"levels": None, "face_opacity": 0.5})
    doc = json.loads(path.read_text())
    assert not set(doc["settings"]) & {"rendering", "sections", "cmap", "clim"}
    doc["settings"].update(settings)
    path.write_text(json.dumps(doc))
    return path


def test_an_older_state_file_without_them_loads_with_the_defaults(tmp_path):
    path = _old_file(tmp_path)
    _, _, settings = load_state(path)
    assert settings == {"levels": None, "face_opacity": 0.5}  # as written: render_state's defaults apply
    assert VIEW_DEFAULTS == {"rendering": "surface", "cmap": "viridis", "clim": None, "sections": [0.5, 0.5, 0.5]}


@pytest.mark.parametrize("name, bad, exc, allowed", [
    ("rendering", "glow", ValueError, "'surface', 'volume', 'mip', 'sections'"),
    ("rendering", 3, ValueError, "'surface', 'volume', 'mip', 'sections'"),
    ("sections", [0.2, 1.5, 0.0], ValueError, r"three numbers in \[0, 1\]"),
    ("sections", [0.2, 0.5], ValueError, r"three numbers in \[0, 1\]"),
    ("sections", "abc", ValueError, r"three numbers in \[0, 1\]"),
    ("cmap", "magmaa", ValueError, "matplotlib colour map name.*'magma'"),
    ("clim", [2, 0], ValueError, "lo < hi"),
    ("clim", "lo", ValueError, "lo < hi"),
])
def test_a_bad_view_setting_in_a_state_file_is_refused_naming_what_is_allowed(tmp_path, name, bad, exc, allowed):
    path = _old_file(tmp_path, **{name: bad})
    with pytest.raises(exc, match=f"bad setting '{name}'.*{allowed}"):
        load_state(path)
    with pytest.raises((TypeError, ValueError), match=allowed):  # nor is such a file written
        save_state(tmp_path / "new.json", RotationState(), "5-cell", {name: bad})
    assert not (tmp_path / "new.json").exists()


# ---------------------------------------------------------------- recordings
def _recorder(view=None):
    rec = Recorder(RotationState(), clock=lambda: 0.0, view_settings=view)
    rec.record("4", False, "xw", t=0.1)
    rec.record_view("rendering", "mip", t=0.2)
    rec.record("4", False, "xw", t=0.3)
    rec.record_view("cmap", "magma", t=0.4)
    rec.record_view("clim", (0, 2), t=0.4)
    rec.record_view("sections", (0.2, 0.5, 0.9), t=0.5)
    rec.record("4", True, "xw", t=0.6)
    return rec


def test_view_settings_are_recorded_saved_and_read_back(tmp_path):
    r = _recorder({"rendering": "surface", "cmap": "viridis"}).recording()
    views = [e for e in r.events if isinstance(e, ViewSetting)]
    assert [(e.t, e.name, e.value) for e in views] == [(0.2, "rendering", "mip"), (0.4, "cmap", "magma"),
                                                       (0.4, "clim", [0.0, 2.0]), (0.5, "sections", [0.2, 0.5, 0.9])]
    assert r.initial_view == {"rendering": "surface", "cmap": "viridis"}
    d = r.to_dict()
    assert RECORDING_VERSION == 3 and d["version"] == 3
    assert d["events"][1] == {"t": 0.2, "view": "rendering", "value": "mip"}
    r.save(tmp_path / "keys.json")
    back = Recording.load(tmp_path / "keys.json")
    assert back.events == r.events and back.initial_view == r.initial_view and back.to_dict() == d


def test_older_recordings_still_load_and_are_still_written_as_before():
    plain = Recorder(RotationState(), clock=lambda: 0.0)
    plain.record("4", False, "xw", t=0.1)
    assert plain.recording().to_dict()["version"] == 1  # nothing of version 3 in it
    plain.record_source("levels", 2.0, t=0.2)
    d2 = plain.recording().to_dict()
    assert d2["version"] == 2 and "initial_view" not in d2
    for d in ({**plain.recording().to_dict(), "events": d2["events"][:1], "version": 1}, d2):
        r = Recording.from_dict(d)
        assert r.initial_view == {} and not any(isinstance(e, ViewSetting) for e in r.events)


@pytest.mark.parametrize("event, match", [
    ({"t": 0.1, "view": "rendering", "value": "glow"}, "'surface', 'volume', 'mip', 'sections'"),
    ({"t": 0.1, "view": "sections", "value": [0, 0, 2]}, r"in \[0, 1\]"),
    ({"t": 0.1, "view": "sections", "value": "abc"}, r"in \[0, 1\]"),
    ({"t": 0.1, "view": "opacity", "value": 1}, "among 'rendering', 'cmap', 'clim', 'sections'"),
])
def test_a_bad_view_event_is_refused(event, match):
    d = Recorder(RotationState()).recording().to_dict()
    with pytest.raises(ValueError, match=match):
        Recording.from_dict({**d, "version": 3, "events": [event]})
    with pytest.raises(ValueError, match=match):
        Recording.from_dict({**d, "version": 3, "initial_view": {event["view"]: event["value"]}})
    with pytest.raises((TypeError, ValueError), match=match):
        Recorder(RotationState()).record_view(event["view"], event["value"])


def test_a_replay_sets_the_view_settings_in_order_among_the_steps():
    r = _recorder({"rendering": "surface"}).recording()
    seen = []
    st = RotationState()

    def set_view(name, value):
        seen.append((name, value, st.matrix.copy()))

    r.replay(st, set_view=set_view)
    # each setting arrives after the steps recorded before it, before those after it
    expect = RotationState()
    steps = {}
    for e in r.events:
        if isinstance(e, ViewSetting):
            steps[e.name] = expect.matrix.copy()
        else:
            expect.apply(e.action, e.inverted)
    assert [(n, v) for n, v, _ in seen] == [("rendering", "surface"), ("rendering", "mip"), ("cmap", "magma"),
                                           ("clim", [0.0, 2.0]), ("sections", [0.2, 0.5, 0.9])]
    for name, _, m in seen[1:]:
        np.testing.assert_array_equal(m, steps[name])
    assert not np.array_equal(steps["rendering"], steps["cmap"])  # a step lies between them
    np.testing.assert_array_equal(st.matrix, expect.matrix)
    assert r.replay(RotationState()).matrix.tolist() == st.matrix.tolist()  # without set_view: skipped


def test_view_settings_past_max_events_fold_into_the_initial_view():
    rec = Recorder(RotationState(), clock=lambda: 0.0, max_events=2, view_settings={"rendering": "surface"})
    rec.record_view("rendering", "volume", t=0.1)
    rec.record_view("cmap", "magma", t=0.2)
    rec.record("4", False, "xw", t=0.3)
    rec.record("4", False, "xw", t=0.4)
    r = rec.recording()
    assert r.initial_view == {"rendering": "volume", "cmap": "magma"} and r.dropped == 2


# ---------------------------------------------------------------- animations
def _pixels(fig) -> np.ndarray:
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())[..., :3].copy()


def _alike(a, b) -> bool:
    """The same picture: an animation's reused canvas antialiases a few edge pixels 1 level apart."""
    d = np.abs(a.astype(int) - b.astype(int)).max(axis=-1)
    return a.shape == b.shape and d.max() <= 2 and (d > 0).mean() < 0.005


def _blob(x, y, z, w):
    return np.exp(-((x - 0.3) ** 2 + (y + 0.2) ** 2 + (z - 0.1) ** 2 + w**2) / 0.08)


def test_each_frame_is_drawn_with_the_rendering_in_effect_then():
    field = Field4D.from_function(_blob, BOX, resolution=12)
    rec = Recorder(RotationState(), clock=lambda: 0.0, view_settings={"rendering": "surface"})
    rec.record("4", False, "xw", t=0.1)
    rec.record_view("rendering", "mip", t=0.2)
    rec.record("4", False, "xw", t=0.3)
    rec.record_view("cmap", "magma", t=0.4)
    rec.record_view("clim", (0.0, 0.5), t=0.4)
    rec.record_view("rendering", "surface", t=0.5)
    r = rec.recording()
    opts = dict(size=(120, 100), frame="camera", annotate=False, levels=[0.5])
    # rendering="volume" given: the recording's own "surface" at the start wins, then its events
    frames = list(render_frames(r, None, field, rendering="volume", **opts))
    looks = [{}, {}, {"rendering": "mip"}, {"rendering": "mip"}, {"rendering": "mip", "cmap": "magma"},
             {"rendering": "mip", "cmap": "magma", "clim": (0.0, 0.5)}, {"cmap": "magma", "clim": (0.0, 0.5)}]
    assert len(frames) == len(looks) == len(r.events) + 1
    for k, ((_t, state, src), look) in enumerate(zip(animation_states(r, None, field), looks)):
        assert _alike(frames[k], _pixels(render_state(state, src, **opts, **look))), (k, look)
        other = {**look, "rendering": "surface" if look.get("rendering") == "mip" else "mip"}
        assert not _alike(frames[k], _pixels(render_state(state, src, **opts, **other))), (k, other)
    assert not _alike(frames[3], frames[4])  # the colour map's change is seen
    assert not _alike(frames[0], _pixels(render_state(RotationState(), field, rendering="volume", **opts)))


def test_a_recording_made_in_volume_renders_volume_frames():
    field = Field4D.from_function(_blob, BOX, resolution=12)
    rec = Recorder(RotationState(), clock=lambda: 0.0, view_settings={"rendering": "volume", "cmap": "magma"})
    rec.record("4", False, "xw", t=0.1)
    opts = dict(size=(100, 80), frame="camera", annotate=False)
    frames = list(render_frames(rec.recording(), None, field, **opts))  # no rendering= given
    states = [s.copy() for _t, s, _src in animation_states(rec.recording(), None, field)]
    for frame, state in zip(frames, states, strict=True):
        assert _alike(frame, _pixels(render_state(state, field, rendering="volume", cmap="magma", **opts)))
        assert not _alike(frame, _pixels(render_state(state, field, **opts)))


# ---------------------------------------------------------------- the widget
@pytest.fixture
def quiet():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # an in-memory field: "not rebuildable"
        yield


def test_the_widget_records_replays_and_saves_its_colour_scale(make, tmp_path, quiet, recording_comms):
    w = make("5-cell", cmap="magma")
    r = w.recording
    assert r.initial_view.get("cmap") == "viridis"  # the trait's default when recording started...
    views = [(e.name, e.value) for e in r.events if isinstance(e, ViewSetting)]
    assert views == [("cmap", "magma")]  # ...then the constructor's value, at once
    assert r.events[-1].t == 0.0
    w.press("4")
    w._keeper.record_view("clim", (0.0, 2.0))  # what the widget's keys and observers call...
    w.clim = (0.0, 2.0)  # ...and the trait it set: recorded once
    w.press("4")
    assert [(e.name, e.value) for e in w.recording.events if isinstance(e, ViewSetting)] == [
        ("cmap", "magma"), ("clim", [0.0, 2.0])]
    other = make("5-cell")
    seen = []
    other.observe(lambda c: seen.append((c["name"], c["new"])), names=["cmap", "clim"])
    other.replay(w.recording)
    assert (other.cmap, other.clim) == ("magma", (0.0, 2.0))
    assert seen == [("cmap", "magma"), ("clim", (0.0, 2.0))]
    np.testing.assert_array_equal(other.state.matrix, w.state.matrix)
    # a state file from before the colour scale existed loads with the defaults
    path = _old_file(tmp_path)
    other.load_state(path)
    assert (other.cmap, other.clim) == ("viridis", None)


@pytest.mark.skipif(not _has_traits("rendering", "sections"), reason="the widget has no rendering/sections yet")
def test_the_widget_saves_and_loads_its_rendering_and_sections(make, tmp_path, quiet, recording_comms):
    from rot4d_widget import Rot4DWidget

    field = Field4D.from_function(_blob, BOX, resolution=12)
    w = make(field, levels=[0.5])
    for name, value in VIEW.items():
        setattr(w, name, tuple(float(v) for v in value) if isinstance(value, tuple) else value)
    w.save_state(tmp_path / "v.json")
    other = make(field, levels=[0.5])
    other.load_state(tmp_path / "v.json")
    assert (other.rendering, other.sections, other.cmap, other.clim) == ("mip", (0.2, 0.5, 0.9), "magma", (0.0, 2.0))
    third = Rot4DWidget.from_state(tmp_path / "v.json", source=field, _autotick=False)
    try:
        assert (third.rendering, third.sections, third.cmap, third.clim) == ("mip", (0.2, 0.5, 0.9), "magma",
                                                                             (0.0, 2.0))
        assert not any(isinstance(e, ViewSetting) for e in third.recording.events)  # it starts there
        assert third.recording.initial_view["rendering"] == "mip"
    finally:
        third.close()
    old = tmp_path / "old.json"
    doc = json.loads((tmp_path / "v.json").read_text())
    for name in VIEW:
        del doc["settings"][name]
    old.write_text(json.dumps(doc))
    other.load_state(old)  # a file from before the view settings: their defaults
    assert (other.rendering, other.sections, other.cmap, other.clim) == ("surface", (0.5, 0.5, 0.5), "viridis", None)
    # recorded, by trait and by key, and replayed in order
    w.start_recording()
    assert w.recording.initial_view == {**VIEW, "sections": [0.2, 0.5, 0.9], "clim": [0.0, 2.0]}
    w.rendering = "volume"
    w.press("4")
    w.sections = (0.1, 0.1, 0.1)
    w.press("v")  # the rendering key: volume -> mip
    assert w.rendering == "mip"
    views = [(e.name, e.value) for e in w.recording.events if isinstance(e, ViewSetting)]
    assert views == [("rendering", "volume"), ("sections", [0.1, 0.1, 0.1]), ("rendering", "mip")]
    seen = []
    other.observe(lambda c: seen.append((c["name"], c["new"])), names=["rendering", "sections"])
    other.replay(w.recording)
    assert seen == [("rendering", "mip"), ("sections", (0.2, 0.5, 0.9)), ("rendering", "volume"),
                    ("sections", (0.1, 0.1, 0.1)), ("rendering", "mip")]
    np.testing.assert_array_equal(other.state.matrix, w.state.matrix)
    # and drawn so: the animation's last frame is the widget's picture
    last = list(render_frames(w.recording, None, field, frame="camera", annotate=False, size=(120, 100)))[-1]
    assert _alike(last, _pixels(w.render(size=(120, 100), frame="camera")))


def test_a_polytope_widget_refusing_a_rendering_records_nothing(make, recording_comms):
    if not _has_traits("rendering"):
        pytest.skip("the widget has no rendering yet")
    w = make("5-cell")
    with pytest.raises(ValueError, match="needs a field"):
        w.rendering = "mip"
    assert w.rendering == "surface"
    assert not any(isinstance(e, ViewSetting) for e in w.recording.events)


@pytest.mark.skipif(not _render_takes("sections"), reason="render_state does not take sections= yet")
def test_the_sections_frames_follow_the_recorded_planes():
    field = Field4D.from_function(_blob, BOX, resolution=12)
    rec = Recorder(RotationState(), clock=lambda: 0.0, view_settings={"rendering": "sections"})
    rec.record_view("sections", (0.7, 0.5, 0.5), t=0.1)
    rec.record_view("sections", (0.7, 0.2, 0.9), t=0.2)
    opts = dict(size=(120, 100), frame="camera", annotate=False)
    frames = list(render_frames(rec.recording(), None, field, **opts))
    planes = [(0.5, 0.5, 0.5), (0.7, 0.5, 0.5), (0.7, 0.2, 0.9)]
    for frame, sections in zip(frames, planes, strict=True):
        assert _alike(frame, _pixels(render_state(RotationState(), field, rendering="sections", sections=sections,
                                                  **opts))), sections
    assert not _alike(frames[0], frames[1]) and not _alike(frames[1], frames[2])
