"""Rot4DWidget with the real pythreejs Scene and anywidget Companion, no browser.

What goes over the comms per update (count, size, dtype, shape), what the
companion's front-end messages do, bad scene options, close().  Messages are
recorded by a comm that serialises like ipykernel's (tests/recording_comm.py).
The widget is read through public behaviour: the recorded messages,
``scene.rows`` / ``scene.update_id``, ``w.stats``, ``w.in_flight``; what the
page sends (acknowledgements, OrbitControls' camera position) arrives on the
comms as the front end sends it.  Time is the fake clock of tests/conftest.py,
advanced by `run_ticker` through `service`, the one place here that reaches
into the widget (its update pump).
"""

from __future__ import annotations

import math
from collections import Counter

import numpy as np

from rot4d_widget.core.rotation import random_rotation
import pytest
from ipywidgets.widgets import widget as ipywidget_module

from rot4d_widget.view import buffers as bf
from rot4d_widget import polytope
from rot4d_widget.core import sizes
from rot4d_widget.geometry.regular import POLYTOPE_NAMES
from rot4d_widget.view.widget import Rot4DWidget
from test_widget import down, up, xw_steps
from widget_time import service


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


def orbit_ends_at(w, eye):
    """OrbitControls syncs the camera's position to the kernel when a drag ends."""
    camera = w.scene.canvas.camera
    camera.comm.handler(
        {"content": {"data": {"method": "update", "state": {"position": list(eye)}, "buffer_paths": []}}, "buffers": []}
    )


def run_ticker(w, clock, until):
    """Wake at each deadline the widget asks for, up to ``until``, moving the fake clock."""
    while True:
        deadline = service(w, clock.t)
        if deadline is None or deadline > until:
            clock.t = until
            service(w, clock.t)
            return
        clock.t = max(clock.t, deadline)


def scaled_points(w, data=None):
    """The points of a slice as the view shows them: every source the pentachoron's size."""
    data = w.slice if data is None else data
    return np.asarray(data.points) * (sizes.REFERENCE_RADIUS / w.source.size)


# --------------------------------------------------------------------- tests
def test_layout_holds_canvas_companion_readout_help_and_errors(make):
    w = make()
    canvas, side = w.children
    assert canvas.children == (w.scene.canvas, w.companion)
    assert side.children == (w.progress_bar.box, w.readout, w.help_panel, w.errors)  # the bar hidden until a read
    assert w.events.source is w.scene.canvas
    assert w.companion.canvas_class == w.scene.canvas_class
    assert w.scene.canvas_class in w.scene.canvas._dom_classes
    assert w.companion.layout.display == "none"  # invisible, but displayed with the canvas
    assert w.companion.buffer_model_id == w.scene.buffer_model_id
    assert w.companion.scene_model_id == w.scene.scene_model_id


@pytest.mark.parametrize("name", POLYTOPE_NAMES)
def test_one_update_is_one_new_float32_array_a_readout_and_a_state_message(make, recording_comms, name):
    w = make(name)
    rng = np.random.default_rng(7)
    before_ids = set(ipywidget_module._instances)
    for i in range(12):
        q, _ = np.linalg.qr(rng.normal(size=(4, 4)))
        q[:, 0] *= np.sign(np.linalg.det(q))  # a rotation, not a reflection
        w.state.matrix = q
        drawn(w)  # the previous update was drawn
        old = w.scene.rows
        updates = w.stats.updates
        n0 = len(recording_comms)
        down(w, "w")
        up(w, "w")
        assert w.stats.updates == updates + 1
        msgs = recording_comms[n0:]
        by_widget = Counter(cid for cid, *_ in msgs)
        # the picture, the readout, and the kernel's state with its id naming the picture (issue 34)
        assert by_widget == {w.scene.buffer_model_id: 1, w.readout.model_id: 1, w.companion.model_id: 1}, by_widget
        total = sum(n for _, _, n, _ in msgs)
        assert total <= 64 * 1024
        (data, nbytes), = buffer_messages(w, msgs)
        assert {"array", "_rot4d_seq"} <= set(data["state"]) <= {"array", "_rot4d_seq", "_rot4d_counts", "_rot4d_turn"}
        assert data["state"]["_rot4d_seq"] == w.scene.update_id
        assert w.in_flight  # awaiting the page's acknowledgement of this update
        rows = w.scene.rows
        assert rows is not old and not np.shares_memory(rows, old)
        assert rows.dtype == np.float32 and rows.flags.c_contiguous
        assert rows.shape == (w.scene.capacity, bf.ROW_FLOATS)
        assert rows.nbytes <= nbytes <= rows.nbytes + 256  # the array and a little JSON
        s = w.slice
        assert np.allclose(rows[: len(s.points), 0:3], scaled_points(w, s), atol=1e-5)
        assert np.all(rows[: len(s.points), 3] == 1.0) and np.all(rows[len(s.points):, 3] == 0.0)
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
    for _ in range(3):  # three updates in flight (the most allowed)
        down(w, "z")
        up(w, "z")
    before = w.scene.rows
    assert not np.diff(_front_facing(before, (0.0, 0.0, 5.0)).astype(int)).clip(max=0).any()  # back first
    n_updates = w.stats.updates
    eye = (3.0, -4.0, 1.0)
    orbit_ends_at(w, eye)
    assert w.scene.eye == eye
    assert w.stats.updates == n_updates  # three updates in flight: this one waits for an ack
    drawn(w)
    assert w.stats.updates == n_updates + 1 and w.scene.rows is not before
    facing = _front_facing(w.scene.rows, eye)
    assert 0 < facing.sum() < len(facing)
    assert not np.diff(facing.astype(int)).clip(max=0).any()  # away-facing first, then facing
    assert not np.array_equal(facing, _front_facing(before, eye))  # the old order was wrong for it
    # the same picture for the eye it was made for: nothing more is sent
    drawn(w)
    orbit_ends_at(w, eye)
    assert w.stats.updates == n_updates + 1 and not w.in_flight


def test_the_faces_sent_are_wound_counter_clockwise_seen_from_outside(make):
    # ordering the faces for the eye (away-facing first) relies on it
    w = make("600-cell")
    _tap_and_draw(w, "4z8c")
    corners, normal = _sent_triangles(w.scene.rows)
    centre = scaled_points(w).mean(axis=0)  # inside the convex slice
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
    assert len(keys) == len(w.slice.points)


def test_the_companion_acknowledgement_releases_the_next_update(make, clock, recording_comms):
    w = make()
    t0 = clock.t
    down(w, "4")
    first = w.scene.update_id
    run_ticker(w, clock, t0 + 0.45)
    # the initial picture, the first step, two repeats; then three are in flight
    assert len(buffer_messages(w, recording_comms)) == 4
    acks = w.stats.acks
    drawn(w, first - 1)  # an acknowledgement of an older update: ignored
    assert w.scene.update_id == first + 2 and w.stats.acks == acks
    drawn(w, first)
    assert w.scene.update_id == first + 3 and w.in_flight and w.stats.acks == acks + 1
    assert np.allclose(
        w.scene.rows[: len(w.slice.points), 0:3],
        scaled_points(w, w.source.slice(w.state.matrix, 0.0)),
        atol=1e-5,
    )
    drawn(w, first)  # a second view's late acknowledgement: the first one counted
    assert w.in_flight and w.stats.acks == acks + 1
    companion_says(w, {"event": "drawn", "seq": "soon"})  # malformed: ignored
    companion_says(w, {"event": "drawn"})
    assert w.in_flight and w.errors.outputs == () and w.stats.acks == acks + 1
    assert w.stats.timeouts == 0
    up(w, "4")


def test_a_page_slow_to_draw_gets_fewer_updates_in_flight(make, clock, recording_comms):
    """The page's "drawn" says how long it took since the update arrived (``draw_ms``); the
    widget hands that to its pump: at 0.12 s an update, two in flight while a key is held (at its
    release two frames still to come, not three), none given up."""
    w = make()
    t0 = clock.t
    down(w, "4")
    run_ticker(w, clock, t0 + 0.45)
    assert w._pump.n_in_flight == 3
    for k in range(4):
        companion_says(w, {"event": "drawn", "seq": w.scene.update_id, "draw_ms": 120.0})
        run_ticker(w, clock, t0 + 0.5 + 0.1 * k)
    assert w._pump.limit == 2 and w._pump.n_in_flight == 2 and w.stats.timeouts == 0
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
    # initial + keydown + first repeat + one per ack_timeout while held (at 0.5, 0.75, 1.0, ... s:
    # each timeout gives up the oldest of the two in flight) + the rest
    assert n <= 3 + w.stats.timeouts + 1
    assert w.stats.updates == n  # every buffer message is a counted update (the initial one too)
    assert w.stats.acks == 0 and 1 <= w.stats.timeouts <= 2 * math.ceil(3.0 / w.ack_timeout)
    assert xw_steps(w) == 0 and w.state.matrix[1, 3] != 0  # R_yw turned, many steps
    assert np.allclose(w.scene.rows[: len(w.slice.points), 0:3], scaled_points(w), atol=1e-5)


def test_parameter_keys_change_the_readout_only(make, recording_comms):
    w = make()
    n0 = len(recording_comms)
    down(w, "j")
    up(w, "j")
    # the kernel's new state goes to the page (issue 34), then the readout: no picture
    assert [cid for cid, *_ in recording_comms[n0:]] == [w.companion.model_id, w.readout.model_id]
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
        ({"group_colors": ["#fff"]}, ValueError, r"group_colors.*at least 5 colours \(one per group\)"),
        ({"show_faces": "yes"}, TypeError, "show_faces.*True or False"),
        ({"not_an_option": 1}, TypeError, "not_an_option"),
    ],
)
def test_bad_scene_options_raise_and_leave_nothing_open(kwargs, exc, match):
    before = len(ipywidget_module._instances)
    with pytest.raises(exc, match=match):
        Rot4DWidget(_autotick=False, **kwargs)
    assert len(ipywidget_module._instances) == before


def test_default_radii_follow_the_displayed_edge(make):
    assert make("5-cell").scene.display["ball_radius"] == pytest.approx(0.07)
    w = make("120-cell")
    edge = 2.0 * sizes.REFERENCE_RADIUS / polytope("120-cell").circumradius  # edge 2, shown scaled
    d = w.scene.display
    assert d["ball_radius"] == pytest.approx(0.1 * edge) == pytest.approx(w.ball_radius)
    assert d["bar_radius"] == pytest.approx(0.4 * d["ball_radius"]) == pytest.approx(w.bar_radius)


def test_display_traits_reach_the_page_as_one_synced_trait_each(make, recording_comms):
    w = make("24-cell")
    parts = {m.name: m for m in w.scene.canvas.scene.children if getattr(m, "name", "")}
    shown = w.scene.update_id
    n0 = len(recording_comms)
    w.face_opacity = 0.8
    w.show_balls = False
    w.background = "#000000"
    sent = [(cid, data["state"]) for cid, data, *_ in recording_comms[n0:]]
    assert [cid for cid, _ in sent] == [parts["faces"].material.model_id, parts["balls"].model_id, w.scene.canvas.model_id]
    assert sent[0][1]["uniforms"]["u_opacity"]["value"] == pytest.approx(0.8)
    assert sent[1][1] == {"visible": False}
    assert sent[2][1] == {"background": "#000000", "clearColor": "#000000"}
    assert w.scene.display["face_opacity"] == 0.8 and w.scene.update_id == shown  # no rows re-sent
    n0 = len(recording_comms)
    with pytest.raises(ValueError, match=r"`face_opacity` to be a number in \[0, 1\]"):
        w.face_opacity = 3
    with pytest.raises(TypeError, match="`show_bars` to be True or False"):
        w.show_bars = "no"
    assert w.face_opacity == 0.8 and w.show_bars is True and recording_comms[n0:] == []


def test_color_by_one_colour_re_sends_every_face_in_it(make, recording_comms):
    w = make("24-cell")
    nt = len(w.slice.triangles)
    assert len(np.unique(w.scene.rows[:nt, 19])) > 1  # by group (4-D cell)
    n0 = len(recording_comms)
    w.color_by = "#9fb6cd"
    assert len(buffer_messages(w, recording_comms[n0:])) == 1
    assert np.all(bf.unpack_rgb(w.scene.rows[:nt, 19]) == [0x9F, 0xB6, 0xCD])


def test_rerun_makes_an_independent_widget(make):
    w1, w2 = make(), make()
    assert w1.scene.canvas is not w2.scene.canvas and w1.events.source is not w2.events.source
    down(w2, "4")
    up(w2, "4")
    assert xw_steps(w2) == 1 and xw_steps(w1) == 0


def test_close_releases_every_widget(recording_comms):
    before = set(ipywidget_module._instances)
    w = Rot4DWidget("16-cell", _autotick=False)
    assert len(set(ipywidget_module._instances) - before) > 10
    # the renderer's own sub-widgets are the Scene's to close (Scene.close)
    renderer_parts = {w.scene.canvas.layout.model_id, w.scene.canvas.shadowMap.model_id}
    w.close()
    left = set(ipywidget_module._instances) - before
    assert left <= renderer_parts, [type(ipywidget_module._instances[k]).__name__ for k in left]
    w.close()


# ------------------------------------------------------- less work per update
def test_each_layer_draws_only_its_rows_in_use_set_in_the_same_message(make, recording_comms):
    w = make("24-cell")
    n0 = len(recording_comms)
    _tap_and_draw(w, "4z")
    data, _ = buffer_messages(w, recording_comms[n0:])[-1]
    s = w.slice
    counts = w.scene.counts
    assert counts == [len(s.points), len(s.segments), len(s.triangles)]
    assert max(counts) <= w.scene.capacity
    # sent with the rows whenever they change (the companion applies both as one)
    sent = [d["state"]["_rot4d_counts"] for d, _ in buffer_messages(w, recording_comms[n0:]) if "_rot4d_counts" in d["state"]]
    assert sent and sent[-1] == counts
    assert all("array" in d["state"] for d, _ in buffer_messages(w, recording_comms[n0:]) if "_rot4d_counts" in d["state"])


class CountingSource:
    """A polytope source that counts its slices (the resampling a field would do)."""

    def __init__(self, name):
        from rot4d_widget import PolytopeSource

        self.inner = PolytopeSource(name)
        self.size, self.n_groups, self.calls = self.inner.size, self.inner.n_groups, 0

    def slice(self, m, c0):
        self.calls += 1
        return self.inner.slice(m, c0)

    def describe(self):
        return self.inner.describe()


@pytest.mark.parametrize("key", ["2", "3", "6"])
def test_held_keys_that_leave_w_alone_turn_the_view_without_slicing(make, clock, recording_comms, key):
    src = CountingSource("24-cell")
    w = make(src)
    w.state.matrix = m0 = random_rotation(np.random.default_rng(5))  # w already mixed in
    w.refresh()
    drawn(w)
    t0 = clock.t
    rows0 = w.scene.rows
    n0, calls0 = len(recording_comms), src.calls
    down(w, key)
    for i in range(20):
        run_ticker(w, clock, t0 + 0.25 + i / 30)
        drawn(w)
    assert src.calls == calls0  # no new slice while the key turns the view ...
    msgs = buffer_messages(w, recording_comms[n0:])
    assert len(msgs) >= 10 and all(set(d["state"]) == {"_rot4d_turn", "_rot4d_seq"} for d, _ in msgs)
    assert max(n for _, n in msgs) < 600  # a few hundred bytes, not the rows
    turn = np.array(msgs[-1][0]["state"]["_rot4d_turn"]).reshape(4, 4, order="F")
    m = w.state.matrix
    r3 = (m @ m0.T)[:3, :3]  # m = R3 @ m0: a turn of x, y, z only
    assert np.allclose(turn[:3, :3], r3, atol=1e-12) and np.allclose(turn[:3, :3] @ turn[:3, :3].T, np.eye(3))
    # the rows made at m0, turned, are the slice at m
    turned = rows0[: len(w.slice.points), 0:3].astype(float) @ r3.T
    d = np.linalg.norm(turned[:, None] - scaled_points(w)[None], axis=2)
    assert d.min(axis=1).max() < 1e-5
    assert np.array_equal(w.scene.rows, rows0) and w.scene.turned
    up(w, key)  # at rest: the rows in the new frame, faces ordered for the eye, turn reset
    drawn(w)
    last = buffer_messages(w, recording_comms[n0:])[-1][0]["state"]
    assert "array" in last and last["_rot4d_turn"] == list(np.eye(4).flatten())
    assert not w.scene.turned and src.calls == calls0 + 1 and w.errors.outputs == ()
    assert np.allclose(w.scene.rows[: len(w.slice.points), 0:3], scaled_points(w), atol=1e-5)


def test_held_keys_that_move_w_send_new_rows(make, clock, recording_comms):
    w = make("24-cell")
    t0 = clock.t
    n0 = len(recording_comms)
    down(w, "4")
    for i in range(10):
        run_ticker(w, clock, t0 + 0.25 + i / 30)
        drawn(w)
    msgs = buffer_messages(w, recording_comms[n0:])
    assert msgs and all("array" in d["state"] and "_rot4d_turn" not in d["state"] for d, _ in msgs)
    assert not w.scene.turned


def _page_copy(log, bid, name):
    """The value of buffer trait ``name`` the page holds: the last message that carried it."""
    value = None
    for cid, data, _, _ in log:
        if cid == bid and isinstance(data, dict) and name in data.get("state", {}):
            value = data["state"][name]
    return value


@pytest.mark.parametrize("there, back", [("l", "h"), ("2", "Shift+2")])
def test_a_failed_send_then_a_step_back_to_the_picture_shown_leaves_the_page_in_step(
        make, clock, recording_comms, monkeypatch, there, back):
    """Issue 33, item 6 (the soak): a send that failed, then a step back to the state the page
    shows (a late keyup taking steps back), left the kernel's copy of the buffer holding the
    unsent picture while nothing was owed, so a view opened later drew it (painter.send's
    no-change branch ignored the scene's unsent part)."""
    w = make("24-cell")
    w.state.c0_step = 0.015625  # out and back is exact
    bid = w.scene.buffer_model_id
    comm = ipywidget_module._instances[bid].comm
    drawn(w)

    def fail(*args, **kwargs):
        raise ConnectionError("injected: the comm is down")

    real = comm.send
    monkeypatch.setattr(comm, "send", fail)
    shift = back.startswith("Shift+")
    key = back.removeprefix("Shift+")
    down(w, there, t=10.0)  # its picture (or turn) fails to leave
    monkeypatch.setattr(comm, "send", real)
    down(w, key, shift=shift, t=10.02)  # while the first is held: back to the state the page shows
    up(w, there, t=10.04)
    up(w, key, shift=shift, t=10.06)
    drawn(w)
    run_ticker(w, clock, clock.t + 1.0)
    assert not w.scene.unsent
    held = {"_rot4d_seq": w.scene.buffer.seq, "_rot4d_turn": w.scene.buffer.turn, "_rot4d_counts": w.scene.buffer.counts}
    for name, kernel in held.items():  # as the page holds them (if ever sent)
        page = _page_copy(recording_comms, bid, name)
        assert page is None or page == kernel, name
    assert _page_copy(recording_comms, bid, "_rot4d_seq") == w.scene.update_id
