"""The source protocol: polytopes, a user's own source (the README's), parameters as traits.

Runs the real Scene on a recording comm (no browser): what the widget sends
is read back from the comm messages.
"""

from __future__ import annotations

import math
import pathlib
import re

import ipywidgets
import numpy as np

from rot4d_widget.core.rotation import random_rotation
import pytest

from rot4d_widget import SliceData, polytope, simple_rotation, slice_polytope
from rot4d_widget.core.sizes import REFERENCE_RADIUS
from rot4d_widget import PolytopeSource, SourceAction
from rot4d_widget.sources.protocol import PolytopeSlice, as_slice, as_source, census_text
from rot4d_widget.view.widget import Rot4DWidget

from widget_time import sent, service

pytestmark = pytest.mark.usefixtures("recording_comms")

README = pathlib.Path(__file__).resolve().parents[2] / "README.md"


def readme_source():
    """Execute the README's user-written source; returns its namespace."""
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(), re.S)
    code = [b for b in blocks if "class CliffordTorus" in b]
    assert len(code) == 1, "the README shows one complete user-written source"
    assert len(code[0].strip().splitlines()) <= 25
    ns = {}
    exec(compile(code[0], "README.md", "exec"), ns)
    return ns


def buffer_rows(w):
    return np.asarray(w.scene.rows)


# -------------------------------------------------------------- the protocol
def test_a_polytope_is_a_source_whose_slice_is_the_exact_slice():
    src = as_source("24-cell")
    assert isinstance(src, PolytopeSource) and src.size == polytope("24-cell").circumradius
    assert src.n_groups == 24 and src.describe() == {"kind": "polytope", "name": "24-cell"}
    m = random_rotation(np.random.default_rng(3))
    data, s = src.slice(m, 0.2), slice_polytope("24-cell", m, 0.2)
    assert np.array_equal(data.points, s.vertices) and np.array_equal(data.triangles, s.triangles)
    assert np.array_equal(data.groups, s.triangle_cells) and data.volume == s.volume and data.convex
    assert data.slice.face_census() == s.face_census()  # the full Slice stays reachable
    assert dict(data.readout) == {"slice": census_text(s)}
    assert census_text(s) == ", ".join(
        f"{c} {({3: 'triangle', 4: 'quadrilateral', 5: 'pentagon', 6: 'hexagon'})[n]}{'' if c == 1 else 's'}"
        for n, c in sorted(s.face_census().items())
    )


def test_as_slice_takes_a_user_slice_s_optional_members_once_with_the_defaults():
    """A user's slice object becomes a `SliceData` where it enters: its optional members as given,
    the ones it lacks at `SliceData`'s defaults; a `SliceData` passes as it is."""
    from types import SimpleNamespace

    bare = SimpleNamespace(points=[[0.0, 0, 0], [1, 0, 0], [0, 1, 0]], segments=[[0, 1]], triangles=[[0, 1, 2]],
                           groups=[0])
    data = as_slice(bare)
    assert type(data) is SliceData and not data.points.flags.writeable
    assert (data.normals, data.volume, data.readout, data.convex, data.show_points, data.corner_only) == (
        None, None, (), False, True, None)
    full = SimpleNamespace(**vars(bare), normals=np.eye(3), volume=0.5, readout=[("k", "v")], convex=1,
                           show_points=0, corner_only=[False, False, True])
    data = as_slice(full)
    assert data.volume == 0.5 and data.readout == (("k", "v"),) and data.convex is True and data.show_points is False
    np.testing.assert_array_equal(data.corner_only, [False, False, True])
    assert as_slice(data) is data
    with pytest.raises(ValueError, match="volume"):
        as_slice(SimpleNamespace(**vars(bare), volume=float("nan")))
    with pytest.raises(TypeError, match="points"):
        as_slice(object())


def test_turned_keeps_a_subclass_s_fields():
    data = PolytopeSource("24-cell").slice(random_rotation(np.random.default_rng(5)), 0.1)
    r = simple_rotation("xy", 0.3)[:3, :3]
    turned = data.turned(r)
    assert isinstance(turned, PolytopeSlice) and turned.slice is data.slice  # the unturned cut kept
    np.testing.assert_allclose(turned.points, data.points @ r.T)
    assert turned.readout == data.readout and turned.convex == data.convex


@pytest.mark.parametrize(
    "bad, exc, match",
    [(5, TypeError, "polytope name"), (object(), TypeError, "slice.*size"),
     (type("S", (), {"slice": lambda s, m, c: None, "describe": lambda s: {}, "size": -1, "n_groups": 1})(),
      ValueError, "size"),
     (type("S", (), {"slice": lambda s, m, c: None, "describe": lambda s: {}, "size": 1.0, "n_groups": 0})(),
      ValueError, "n_groups")],
)
def test_what_is_not_a_source_is_refused_naming_what_is_allowed(bad, exc, match):
    with pytest.raises(exc, match=match):
        as_source(bad)


def test_slice_data_is_validated_and_read_only():
    d = SliceData.build([[0, 0, 0], [1, 0, 0], [0, 1, 0]], segments=[[0, 1]], triangles=[[0, 1, 2]])
    for a in (d.points, d.segments, d.triangles, d.groups):
        assert not a.flags.writeable
    with pytest.raises(ValueError, match="points"):
        SliceData.build([[0, 0]])
    with pytest.raises(ValueError, match="segments"):
        SliceData.build([[0, 0, 0]], segments=[[0, 3]])
    with pytest.raises(ValueError, match="groups"):
        SliceData.build([[0, 0, 0]] * 3, triangles=[[0, 1, 2]], groups=[0, 1])
    with pytest.raises(ValueError, match="finite"):
        SliceData.build([[0, np.nan, 0]])


@pytest.mark.parametrize("name", ["5-cell", "24-cell", "600-cell"])
@pytest.mark.parametrize("plane", ["xy", "xz", "yz"])
def test_rotations_that_leave_w_alone_only_turn_the_slice(name, plane):
    """Geometry: the slice at R3 @ M is the slice at M turned by R3 (same cut of the object)."""
    rng = np.random.default_rng(7)
    m = random_rotation(rng)
    r3 = simple_rotation(plane, 0.7)
    a, b = slice_polytope(name, m, 0.1), slice_polytope(name, r3 @ m, 0.1)
    turned = a.vertices @ r3[:3, :3].T
    assert len(a.vertices) == len(b.vertices) and a.face_census() == b.face_census()
    d = np.linalg.norm(turned[:, None] - b.vertices[None], axis=2)
    assert d.min(axis=1).max() < 1e-9 and a.volume == pytest.approx(b.volume)


# ------------------------------------------------------------ a user's source
def test_the_readme_source_runs_in_the_widget_and_keys_change_the_buffers():
    ns = readme_source()
    w = ns["w"]
    try:
        torus = w.source
        assert isinstance(w, Rot4DWidget) and w.polytope is None
        rows0 = buffer_rows(w).copy()
        near = np.abs(torus.points[:, 3]) < torus.thickness  # at the identity orientation, c0 = 0
        shown = rows0[rows0[:, 3] == 1.0, :3]
        assert len(shown) == near.sum() > 50
        scale = REFERENCE_RADIUS / torus.size
        assert np.allclose(shown, torus.points[near, :3] * scale, atol=1e-6)  # float32
        assert f"{near.sum()}" in w.readout.value
        w.press("4")
        sent(w)  # no view: the timeout sends the latest (the ticker thread may be sending it)
        m = w.state.matrix
        q = torus.points @ m.T
        near = np.abs(q[:, 3]) < torus.thickness
        rows = buffer_rows(w)
        assert not np.array_equal(rows, rows0)
        assert np.allclose(rows[rows[:, 3] == 1.0, :3], q[near, :3] * scale, atol=1e-6)
    finally:
        w.close()


class Tube:
    """A user source with its own key: a 4-D box whose thickness o/i change (a SourceAction)."""

    size = math.sqrt(3.0)
    n_groups = 1

    def __init__(self):
        self.half = 0.5
        self.actions = {"o": SourceAction("thicker", "make the box thicker", self.grow),
                        "i": SourceAction("thinner", "make it thinner", lambda s: self.grow(-s), repeat=False)}

    def grow(self, sign):
        self.half = max(0.1, self.half + 0.1 * sign)

    def slice(self, matrix, c0):
        h = self.half
        pts = np.array([[x, y, z] for x in (-h, h) for y in (-h, h) for z in (-h, h)])
        return SliceData.build(pts, volume=(2 * h) ** 3, readout=[("half", f"{h:.2f}")])

    def describe(self):
        return {"kind": "tube", "half": self.half}


def test_a_source_brings_its_own_keys_to_the_keymap_and_help(make):
    w = make(Tube())
    assert w.state.keymap["o"].kind == "custom" and "make the box thicker" in w.help_panel.value
    w._handle_event({"type": "keydown", "key": "o", "code": "KeyO"})
    assert w.source.half == pytest.approx(0.6) and w.slice.volume == pytest.approx(1.2**3)
    assert w.held_keys == ("KeyO",)  # repeats while held
    w._handle_event({"type": "keyup", "key": "o", "code": "KeyO"})
    assert "half</td><td>0.60" in w.readout.value and "thicker" in w.readout.value  # at rest: exact
    w._handle_event({"type": "keydown", "key": "i", "code": "KeyI"})
    assert w.source.half == pytest.approx(0.5) and w.held_keys == ()  # repeat=False


def test_a_source_action_may_not_take_a_paper_key():
    class Bad(Tube):
        def __init__(self):
            super().__init__()
            self.actions = {"4": SourceAction("x", "steals R_xw", self.grow)}

    with pytest.raises(ValueError, match="4"):
        Rot4DWidget(Bad(), _autotick=False)


# ----------------------------------------------------------------- as traits
def test_c0_links_both_ways_with_a_slider_and_redraws(make):
    w = make("24-cell")
    s = ipywidgets.FloatSlider(min=-2.0, max=2.0, step=0.001)
    link = ipywidgets.link((s, "value"), (w, "c0"))
    try:
        rows0 = buffer_rows(w).copy()
        s.value = 0.5  # the slider moves: the state follows and the view redraws, no refresh()
        assert w.state.c0 == 0.5 and w.c0 == 0.5
        assert not np.array_equal(buffer_rows(w), rows0)
        w.press("l")  # a key moves the slider
        assert s.value == pytest.approx(0.5 + w.state.c0_step)
    finally:
        link.unlink()


def test_observers_fire_on_key_presses_and_orientation_is_read_only(make):
    w = make()
    seen = []
    w.observe(lambda ch: seen.append((ch["name"], ch["new"])), names=["c0", "alpha", "theta0", "orientation"])
    w.press("l")
    w.press("k")
    w.press("4")
    names = [n for n, _ in seen]
    assert names.count("c0") == 1 and names.count("alpha") == 1 and "orientation" in names
    assert np.allclose(w.orientation, w.state.matrix)
    with pytest.raises(Exception):
        w.orientation = np.eye(4)
    with pytest.raises(ValueError):
        w.orientation[0, 0] = 2.0  # the array handed out is read-only
    w.theta0 = w.theta0 * 2  # alpha keeps its ratio to theta0
    assert w.alpha == pytest.approx(w.state.alpha) and w.state.theta0 == w.theta0


@pytest.mark.parametrize("name, value, exc", [("theta0", 4.0, ValueError), ("theta0", "x", TypeError),
                                               ("c0", float("nan"), ValueError), ("alpha", None, TypeError),
                                               ("face_opacity", 1.5, ValueError), ("color_by", "mauve-ish", ValueError),
                                               ("show_balls", 1, TypeError)])
def test_bad_trait_values_are_refused_and_change_nothing(make, name, value, exc):
    w = make()
    before = getattr(w, name)
    with pytest.raises(exc, match=name):
        setattr(w, name, value)
    assert getattr(w, name) == before


def test_display_traits_reach_the_scene_and_color_by_repaints_the_faces(make):
    w = make("24-cell")
    w.show_faces = False
    w.face_opacity = 0.8
    w.background = "#000000"
    assert w.scene.display["show_faces"] is False and w.scene.display["face_opacity"] == 0.8
    assert w.scene.display["background"] == "#000000"
    rows = buffer_rows(w)
    nt = int((np.abs(rows[:, 10:19]).sum(axis=1) > 0).sum())
    assert len(set(rows[:nt, 19].tolist())) > 1  # coloured by cell
    w.color_by = "#ff0000"
    service(w, w._pump.clock() + 1.0)
    rows = buffer_rows(w)
    assert set(rows[:nt, 19].tolist()) == {float(0xFF0000)}


class SlowTube(Tube):
    """A Tube whose slice takes a while (a big field's would): the ticker thread is mid-send for long."""

    def slice(self, matrix, c0):
        import time

        time.sleep(0.15)
        return super().slice(matrix, c0)


def test_press_from_code_returns_once_its_step_is_in_the_readout():
    # the real ticker thread: with a slow slice, the send it computes outside the lock is under way
    # when `press` has flushed; `press` waits for it, so the readout read next shows the new c0
    w = Rot4DWidget(SlowTube())
    try:
        for key, want in (("l", 1), ("l", 2), ("h", 1)):
            assert w.press(key)
            c0 = w.c0
            assert c0 == pytest.approx(want * w.state.c0_step)
            assert f"{c0:.4f}" in w.readout.value, (c0, w.readout.value)
    finally:
        w.close()
