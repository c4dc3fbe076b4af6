"""Rot4DWidget with the real pythreejs Scene and anywidget Companion, no browser.

What goes over the comms per update (count, size, dtype, shape), what the
companion's front-end messages do, bad scene options, close().  Messages are
recorded by a comm that serialises like ipykernel's (tests/test_widget.py).
"""

from __future__ import annotations

import math
from collections import Counter

import numpy as np
import pytest
from ipywidgets.widgets import widget as ipywidget_module

from rot4d_widget import buffers as bf
from rot4d_widget import slice_polytope
from rot4d_widget.polytopes import POLYTOPE_NAMES
from rot4d_widget.widget import Rot4DWidget
from test_widget import down, run_ticker, up, xw_steps


# comms, clock and `make`: tests/conftest.py
pytestmark = pytest.mark.usefixtures("recording_comms")


def companion_says(w, content):
    """A message from the companion's JavaScript, as the front end delivers it."""
    w.companion.comm.handler({"content": {"data": {"method": "custom", "content": content}}, "buffers": []})


def drawn(w, seq=None):
    companion_says(w, {"event": "drawn", "seq": w.scene.update_id if seq is None else seq})


def buffer_messages(w, log):
    bid = w.scene.buffer_model_id
    return [(data, n) for cid, data, n, _ in log if cid == bid]


# --------------------------------------------------------------------- tests
def test_layout_holds_canvas_companion_readout_help_and_errors(make):
    w = make()
    canvas, side = w.children
    assert canvas.children == (w.scene.renderer, w.companion)
    assert side.children == (w.readout, w.help_panel, w.errors)
    assert w.events.source is w.scene.renderer
    assert w.companion.canvas_class == w.scene.canvas_class
    assert w.scene.canvas_class in w.scene.renderer._dom_classes
    assert w.companion.layout.display == "none"  # invisible, but displayed with the canvas
    assert w.companion.buffer_model_id == w.scene.buffer_model_id


@pytest.mark.parametrize("name", POLYTOPE_NAMES)
def test_one_update_is_one_new_float32_array_and_one_readout_message(make, recording_comms, name):
    w = make(name)
    rng = np.random.default_rng(7)
    before_ids = set(ipywidget_module._instances)
    for i in range(12):
        q, _ = np.linalg.qr(rng.normal(size=(4, 4)))
        q[:, 0] *= np.sign(np.linalg.det(q))  # a rotation, not a reflection
        w.state.matrix = q
        drawn(w)  # the previous update was drawn
        old = w.scene.rows
        n0 = len(recording_comms)
        down(w, "w")
        up(w, "w")
        msgs = recording_comms[n0:]
        by_widget = Counter(cid for cid, *_ in msgs)
        assert by_widget == {w.scene.buffer_model_id: 1, w.readout.model_id: 1}, by_widget
        total = sum(n for _, _, n, _ in msgs)
        assert total <= 64 * 1024
        (data, nbytes), = buffer_messages(w, msgs)
        assert set(data["state"]) == {"array", "_rot4d_seq"}
        assert data["state"]["_rot4d_seq"] == w.scene.update_id == w._in_flight
        rows = w.scene.rows
        assert rows is not old and rows.base is not old
        assert rows.dtype == np.float32 and rows.flags.c_contiguous
        assert rows.shape == (w.scene.capacity, bf.ROW_FLOATS)
        assert nbytes >= rows.nbytes
        s = w.slice
        assert np.allclose(rows[: len(s.vertices), 0:3], s.vertices * w.scene.scale, atol=1e-5)
        assert np.all(rows[: len(s.vertices), 3] == 1.0) and np.all(rows[len(s.vertices):, 3] == 0.0)
    assert set(ipywidget_module._instances) == before_ids  # updates never create widgets


def _tap_and_draw(w, keys):
    """Tap each key; the page acknowledges each update."""
    for key in keys:
        down(w, key)
        up(w, key)
        drawn(w)


def _sent_triangles(rows):
    """Corners (k, 3, 3) and normals (k, 3) of the triangles in a row table, in row order."""
    corners = rows[:, 10:19].astype(np.float64).reshape(-1, 3, 3)
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    used = np.linalg.norm(normal, axis=1) > 1e-9  # hidden rows have no area
    return corners[used], normal[used]


def _front_facing(rows, eye):
    corners, normal = _sent_triangles(rows)
    return np.einsum("ij,ij->i", normal, np.asarray(eye) - corners[:, 0]) > 0


def test_an_orbit_re_sends_the_faces_ordered_for_the_new_eye_through_flow_control(make, recording_comms):
    w = make("24-cell")
    down(w, "z")
    up(w, "z")  # an update in flight
    before = w.scene.rows
    assert not np.diff(_front_facing(before, (0.0, 0.0, 5.0)).astype(int)).clip(max=0).any()  # back first
    n_updates = w.n_updates
    # OrbitControls syncs the camera position to the kernel when a drag ends
    eye = (3.0, -4.0, 1.0)
    w.scene.camera.position = eye
    assert w.n_updates == n_updates  # one update in flight: this one waits for the ack
    drawn(w)
    assert w.n_updates == n_updates + 1 and w.scene.rows is not before
    facing = _front_facing(w.scene.rows, eye)
    assert 0 < facing.sum() < len(facing)
    assert not np.diff(facing.astype(int)).clip(max=0).any()  # away-facing first, then facing
    assert not np.array_equal(facing, _front_facing(before, eye))  # the old order was wrong for it
    # the same picture for the eye it was made for: nothing more is sent
    drawn(w)
    w.scene.camera.position = eye
    assert w.n_updates == n_updates + 1


def test_the_faces_sent_are_wound_counter_clockwise_seen_from_outside(make):
    # ordering the faces for the eye (away-facing first) relies on it
    w = make("600-cell")
    _tap_and_draw(w, "4z8c")
    corners, normal = _sent_triangles(w.scene.rows)
    centre = w.slice.vertices.mean(axis=0) * w.scene.scale  # inside the convex slice
    outward = np.einsum("ij,ij->i", normal, corners.mean(axis=1) - centre)
    assert len(corners) == len(w.slice.triangles) and np.all(outward > 0)


def test_the_faces_sent_form_a_closed_mesh(make):
    w = make("24-cell")
    _tap_and_draw(w, "4z8")
    tris, _ = _sent_triangles(w.scene.rows)
    assert len(tris) == len(w.slice.triangles) > 0
    keys = {}

    def vid(p):
        return keys.setdefault(tuple(np.round(p, 4)), len(keys))

    edges = Counter()
    for t in tris:
        a, b, c = (vid(p) for p in t)
        for e in ((a, b), (b, c), (c, a)):
            edges[tuple(sorted(e))] += 1
    assert set(edges.values()) == {2}  # every edge shared by exactly two triangles
    assert len(keys) == len(w.slice.vertices)


def test_the_companion_acknowledgement_releases_the_next_update(make, clock, recording_comms):
    w = make()
    t0 = clock.t
    down(w, "4")
    first = w.scene.update_id
    run_ticker(w, clock, t0 + 0.45)
    assert len(buffer_messages(w, recording_comms)) == 2  # the initial picture + the first step
    drawn(w, first - 1)  # an acknowledgement of an older update: ignored
    assert w.scene.update_id == first
    drawn(w, first)
    assert w.scene.update_id == first + 1 and w.in_flight
    assert np.allclose(
        w.scene.rows[: len(w.slice.vertices), 0:3],
        slice_polytope(w.polytope, w.state.matrix, 0.0).vertices * w.scene.scale,
        atol=1e-5,
    )
    drawn(w, first)  # a second view's late acknowledgement: the first one counted
    assert w.in_flight
    companion_says(w, {"event": "drawn", "seq": "soon"})  # malformed: ignored
    companion_says(w, {"event": "drawn"})
    assert w.in_flight and w.errors.outputs == ()
    up(w, "4")


@pytest.mark.parametrize("reason", ["blur", "hidden"])
def test_focus_loss_from_the_page_stops_rotation(make, clock, reason):
    w = make()
    t0 = clock.t
    down(w, "4")
    run_ticker(w, clock, t0 + 0.5)
    n = xw_steps(w)
    companion_says(w, {"event": "focus_lost", "reason": reason})
    run_ticker(w, clock, t0 + 2.0)
    assert xw_steps(w) == n and w.held_keys == ()


def test_a_held_key_without_acknowledgements_sends_one_update_per_timeout(make, clock, recording_comms):
    w = make("600-cell")
    t0 = clock.t
    down(w, "8")
    run_ticker(w, clock, t0 + 2.0)
    up(w, "8")
    run_ticker(w, clock, t0 + 3.0)
    n = len(buffer_messages(w, recording_comms))
    # initial + keydown + one per ack_timeout while held (at 0.5, 1.0, 1.5, 2.0 s) + the rest
    assert n <= 2 + math.ceil(2.0 / w.ack_timeout) + 1
    assert xw_steps(w) == 0 and w.state.matrix[1, 3] != 0  # R_yw turned, many steps
    assert np.allclose(
        w.scene.rows[: len(w.slice.vertices), 0:3], w.slice.vertices * w.scene.scale, atol=1e-5
    )


def test_parameter_keys_change_the_readout_only(make, recording_comms):
    w = make()
    n0 = len(recording_comms)
    down(w, "j")
    up(w, "j")
    assert [cid for cid, *_ in recording_comms[n0:]] == [w.readout.model_id]
    assert not w.in_flight  # no picture sent, so no acknowledgement to wait for
    down(w, "l")
    up(w, "l")
    assert len(buffer_messages(w, recording_comms[n0:])) == 1


def test_refresh_after_a_direct_state_change(make, recording_comms):
    w = make()
    n0 = len(recording_comms)
    w.refresh()  # nothing changed: nothing sent
    assert recording_comms[n0:] == []
    w.state.c0 = 0.3
    w.refresh()
    assert len(buffer_messages(w, recording_comms[n0:])) == 1
    assert "0.3000" in w.readout.value


@pytest.mark.parametrize(
    "kwargs, exc, match",
    [
        ({"width": -10}, ValueError, r"width.*\[16, 8192\]"),
        ({"height": 0}, ValueError, r"height.*\[16, 8192\]"),
        ({"width": 300.5}, TypeError, "width.*int"),
        ({"ball_radius": -0.1}, ValueError, "ball_radius"),
        ({"bar_radius": float("nan")}, ValueError, "bar_radius"),
        ({"face_opacity": 1.5}, ValueError, r"face_opacity.*\[0, 1\]"),
        ({"background": "sky"}, ValueError, "background.*#rrggbb"),
        ({"cell_colors": ["#fff"]}, ValueError, "cell_colors.*one per cell"),
        ({"not_an_option": 1}, TypeError, "not_an_option"),
    ],
)
def test_bad_scene_options_raise_and_leave_nothing_open(kwargs, exc, match):
    before = len(ipywidget_module._instances)
    with pytest.raises(exc, match=match):
        Rot4DWidget(autotick=False, **kwargs)
    assert len(ipywidget_module._instances) == before


def test_rerun_makes_an_independent_widget(make):
    w1, w2 = make(), make()
    assert w1.scene.renderer is not w2.scene.renderer and w1.events.source is not w2.events.source
    down(w2, "4")
    up(w2, "4")
    assert xw_steps(w2) == 1 and xw_steps(w1) == 0


def test_close_releases_every_widget(recording_comms):
    before = set(ipywidget_module._instances)
    w = Rot4DWidget("16-cell", autotick=False)
    assert len(set(ipywidget_module._instances) - before) > 10
    # the renderer's own sub-widgets are the Scene's to close (Scene.close)
    renderer_parts = {w.scene.renderer.layout.model_id, w.scene.renderer.shadowMap.model_id}
    w.close()
    left = set(ipywidget_module._instances) - before
    assert left <= renderer_parts, [type(ipywidget_module._instances[k]).__name__ for k in left]
    w.close()
