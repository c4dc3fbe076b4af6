"""Hostile use (issue 18): what broke when the widget was driven as a hostile user would.

Each test names the item it covers; each failed on the code before the fix (7ba6e62).
The widgets here are real (real Scene and companion, no browser), on the fake clock without a
ticker thread unless the test is about the thread.
"""

from __future__ import annotations

import math
import os
import threading
import time

import ipywidgets
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rot4d_widget import Rot4DWidget, SliceData
from rot4d_widget.sources.field.container import Field4D
from rot4d_widget.view.keyhold import steps_for
from rot4d_widget.core.keymap import DEFAULT_KEYMAP
from rot4d_widget.core.state import ALPHA_MAX, THETA0_MAX, THETA0_MIN, RotationState
from rot4d_widget.sources.tomography import SPACING_MAX, SPACING_MIN
from test_widget import deliver, down, key_event, run_ticker, up, xw_steps

pytestmark = pytest.mark.usefixtures("recording_comms")


def ball_field():
    return Field4D.from_function(lambda x, y, z, w: 1.0 - (x * x + y * y + z * z + w * w),
                                 extent=[(-1.5, 1.5)] * 4, levels=0.0, resolution=16)


def c0_steps(w, start=0.0):
    return round((w.state.c0 - start) / w.state.c0_step)


# ------------------------------------------------------- item 0: keys by the page's clock
def test_a_tap_whose_keyup_the_kernel_handles_late_is_one_step(make, clock):
    """The kernel, busy, handles the keyup 1 s after the keydown; the page says it was a tap."""
    w = make()
    page = 5000.0  # the page's clock has nothing to do with the kernel's
    down(w, "4", t=page)
    run_ticker(w, clock, clock.t + 1.0)  # meanwhile the ticker repeats: 1 + 23 steps
    assert xw_steps(w) > 1
    up(w, "4", t=page + 0.06)
    assert xw_steps(w) == 1
    # the steps taken back are in the recording: a replay ends where the view ended
    again = make()
    again.replay(w.recording)
    np.testing.assert_allclose(again.state.matrix, w.state.matrix, atol=1e-12)


@pytest.mark.parametrize("held, kernel_late", [(0.6, 0.9), (1.0, 0.4), (0.25, 0.5), (2.0, 0.0)])
def test_a_hold_makes_the_steps_the_page_s_duration_gives(make, clock, held, kernel_late):
    w = make()
    t0 = clock.t
    down(w, "4", t=77.0)
    run_ticker(w, clock, t0 + held + kernel_late)
    up(w, "4", t=77.0 + held)
    assert xw_steps(w) == steps_for(held, w.hold_delay, w.tick_rate)


def test_a_kernel_behind_adds_every_step_the_page_made(make, clock):
    """Issue 34: the page showed every step of the hold; the kernel, busy the whole hold, makes them
    all at the keyup (it dropped those beyond a quarter second before)."""
    w = make()
    down(w, "4", t=0.0)  # the ticker never ran: the kernel was busy the whole hold
    up(w, "4", t=2.0)
    assert xw_steps(w) == steps_for(2.0, w.hold_delay, w.tick_rate)


def test_a_late_keyup_of_l_takes_back_the_c0_steps_and_mouseleave_corrects_too(make, clock):
    w = make()
    down(w, "l", t=10.0)
    run_ticker(w, clock, clock.t + 0.8)
    up(w, "l", t=10.1)
    assert c0_steps(w) == 1
    down(w, "4", t=20.0)
    run_ticker(w, clock, clock.t + 0.8)
    from test_widget import deliver

    deliver(w, {"type": "mouseleave", "event": "mouseleave", "timeStamp": 20.1e3})
    assert xw_steps(w) == 1 and w.held_keys == ()


def test_a_key_pad_click_the_kernel_sees_late_is_one_step(make, clock):
    w = make(keypad=True)
    [button_4] = [ev for ev in w._keypad.events if ev.source.description == "R_xw"]

    def send(event):  # as the front end does: a custom message on the button's Event comm
        button_4.comm.handler({"content": {"data": {"method": "custom", "content": event}}, "buffers": []})

    send({"event": "mousedown", "type": "mousedown", "button": 0, "timeStamp": 1e3})
    run_ticker(w, clock, clock.t + 1.0)
    send({"event": "mouseup", "type": "mouseup", "button": 0, "timeStamp": 1.05e3})
    assert xw_steps(w) == 1


def test_a_slow_observer_does_not_freeze_the_keyup():
    """Item 1: an observer slower than the tick period kept the ticker's lock for good."""
    w = Rot4DWidget("5-cell", hold_delay=0.01, tick_rate=240, ack_timeout=0.01)
    cost = []

    def slow(change):
        t = time.monotonic()
        time.sleep(0.05)
        cost.append(time.monotonic() - t)

    try:
        w.observe(slow, names="orientation")
        now_ms = time.monotonic() * 1e3
        down(w, "4", t=now_ms / 1e3)
        time.sleep(0.5)
        done = threading.Event()
        took = []

        def keyup():
            t = time.monotonic()
            up(w, "4", t=time.monotonic())
            took.append(time.monotonic() - t)
            done.set()

        threading.Thread(target=keyup, daemon=True).start()
        tick = max(cost)  # what one tick cost in this run
        assert done.wait(60 * tick + 5), "the keyup was not handled: the ticker kept the lock"
        # handled within about one tick (plus the steps the keyup corrects, each one tick)
        assert took[0] < (w._repeater.max_steps + 4) * tick + 1.0, (took, tick)
        assert w.held_keys == ()
        m = w.state.matrix
        time.sleep(10 * tick)
        assert w.state.matrix is m  # nothing turns after the keyup
    finally:
        if w._pump.lock.acquire(timeout=5):  # (before the fix the ticker never let it go)
            w._pump.lock.release()
            w.close()


def test_taps_queued_behind_a_slow_source_coalesce():
    """Item 0: ten taps while a 0.3 s slice is computed draw two pictures, not ten."""
    class Slow:
        def __init__(self):
            self.inner = ball_field()
            self.calls = 0

        def __getattr__(self, name):
            return getattr(self.inner, name)

        def slice(self, matrix, c0, coarse=False):
            self.calls += 1
            time.sleep(0.3)
            return self.inner.slice(matrix, c0, coarse=coarse)

    src = Slow()
    w = Rot4DWidget(src, ack_timeout=0.05)
    try:
        calls = src.calls
        # taps from the page (`press` from code waits for its step to be sent), each with its page
        # time: 50 ms down, a second apart, so each is one step however late this (busy) machine
        # hands the events over (without a timeStamp the kernel's clock would count the steps)
        for i in range(10):
            w._handle_event(key_event("keydown", "l", t=10.0 + i))
            w._handle_event(key_event("keyup", "l", t=10.05 + i))
        limit = time.monotonic() + 60
        while (w._pump.dirty or w._pump._sending or w.stats.updates < 1) and time.monotonic() < limit:
            time.sleep(0.05)
        assert c0_steps(w) == 10
        assert src.calls - calls <= 3, src.calls - calls  # the first, then the latest (not all ten)
        np.testing.assert_allclose(w._painter.rows_data.points, w.slice.points)  # what is shown is the latest
    finally:
        w.close()


# ------------------------------------------------------- item 2: the palette follows the source
def test_a_stack_taken_down_to_one_slice_keeps_working(make):
    w = make("24-cell", slices=5)
    for _ in range(4):
        assert w.press("b")
    assert w.slices == 1 and w.errors.outputs == ()
    assert w.press("4") and w.errors.outputs == ()
    w.slices = 5
    w.slices = 1
    w.press("8")
    w.release_keys()
    assert w.errors.outputs == ()
    groups = int(np.max(w.slice.groups)) + 1
    assert len(w._painter.group_colors()) >= groups  # a colour for each of the 24-cell's cells


def test_a_field_stack_down_to_one_slice_takes_new_levels_and_keeps_its_colours(make):
    w = make(ball_field(), levels=(0.0, 0.3))
    colours = w._painter.group_colors().copy()
    w.press("n")
    w.press("b")
    w.levels = (0.2, 0.4, 0.6)
    assert w.levels == (0.2, 0.4, 0.6) and w.source.source.levels == (0.2, 0.4, 0.6)
    assert w.errors.outputs == ()
    w.levels = (0.0, 0.3)
    np.testing.assert_allclose(w._painter.group_colors(), colours)  # level colours, not the cells' cyan
    assert "colours" in w.readout.value  # the legend is still there


# ------------------------------------------------------- item 5: p with no view
def test_p_with_no_view_does_not_pile_up(make, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    w = make()
    for _ in range(1000):
        down(w, "p", code="KeyP")
        up(w, "p", code="KeyP")
    assert len(w._shots.pending) <= 8
    assert os.listdir(tmp_path) == []


# ------------------------------------------------------- item 6 and the bounds: finite, undone
def test_g_held_stays_finite_and_f_brings_it_back(make):
    w = make("24-cell", slices=3)
    start = w.spacing
    made = sum(bool(w.press("g")) for _ in range(5000))
    size = w.source.size
    assert math.isfinite(w.spacing) and w.spacing <= SPACING_MAX * size
    for _ in range(made):
        assert w.press("f")
    assert w.spacing == pytest.approx(start, rel=1e-9)
    made = sum(bool(w.press("f")) for _ in range(5000))
    assert w.spacing >= SPACING_MIN * size
    w.press("4")
    assert w.errors.outputs == ()
    with pytest.raises(ValueError, match="spacing"):
        w.spacing = 1e300


@settings(max_examples=60, deadline=None)
@given(st.lists(st.sampled_from("+-kjlh"), min_size=1, max_size=400))
def test_parameter_keys_stay_bounded_and_the_opposite_key_undoes_each_step(keys):
    opposite = {"+": "-", "-": "+", "k": "j", "j": "k", "l": "h", "h": "l"}
    s = RotationState(c0_limit=1.0)
    start = (s.theta0, s.alpha, s.c0)
    made = []
    for k in keys:
        if s.press(k):
            made.append(k)
        assert THETA0_MIN <= s.theta0 <= THETA0_MAX
        assert abs(s.alpha) <= ALPHA_MAX and abs(s.beta) <= ALPHA_MAX
        assert abs(s.c0) <= 1.0
    for k in reversed(made):
        assert s.press(opposite[k]), k
    np.testing.assert_allclose((s.theta0, s.alpha, s.c0), start, rtol=1e-9, atol=1e-12)


def test_plus_held_stops_below_pi_and_minus_undoes_it_and_k_l_stay_bounded():
    s = RotationState(c0_limit=1.0)
    start = (s.theta0, s.alpha)
    made = sum(bool(s.press("+")) for _ in range(40))
    assert s.theta0 <= THETA0_MAX and not s.press("+")
    for _ in range(made):
        assert s.press("-")
    np.testing.assert_allclose((s.theta0, s.alpha), start, rtol=1e-12)
    for _ in range(20000):
        s.press("k")
        s.press("l")
    assert abs(s.alpha) <= ALPHA_MAX and abs(s.beta) <= ALPHA_MAX and abs(s.c0) <= 1.0


def test_minus_held_for_ever_keeps_theta0_positive():
    s = RotationState()
    for _ in range(5000):
        s.press("-")
    assert s.theta0 >= THETA0_MIN and s.press("+")


# ------------------------------------------------------- item 8: leaks
def _models():
    from ipywidgets.widgets.widget import _instances

    return len(_instances)


def test_a_source_failing_in_construction_leaves_no_models():
    class Fails:
        """Slices while the widget sizes its buffers, then fails (the first picture)."""

        size = 1.0
        n_groups = 1
        calls = 0

        def slice(self, matrix, c0):
            self.calls += 1
            if self.calls > 6:
                raise RuntimeError("no data")
            return SliceData.build(np.eye(3), segments=[[0, 1]])

        def describe(self):
            return {"kind": "fails"}

    before = _models()
    with pytest.raises(RuntimeError, match="no data"):
        Rot4DWidget(Fails(), _autotick=False, ball_radius=0.05)
    assert _models() == before


@pytest.mark.parametrize("options", [{"keypad": True}, {"projection": True}])
def test_create_and_close_leaves_no_models(options):
    """With ``projection=True`` 20 cycles left 20 models before (its renderer's own WebGLShadowMap)."""
    Rot4DWidget(_autotick=False, **options).close()  # warm-up (module-level widgets)
    before = _models()
    for _ in range(20):
        Rot4DWidget(_autotick=False, **options).close()
    assert _models() == before


# ------------------------------------------------------- item 11: a user source's bad slice
class Flaky:
    """A user source that returns NaN points, None or a good slice, as told."""

    size = 1.0
    n_groups = 2

    def __init__(self):
        self.mode = "good"

    def slice(self, matrix, c0):
        if self.mode == "nan":
            return SliceData(np.array([[0.0, np.nan, 0.0]]), np.zeros((0, 2), int), np.zeros((0, 3), int),
                             np.zeros(0, int))
        if self.mode == "none":
            return None
        if self.mode == "group":
            return SliceData.build(np.eye(3), triangles=[[0, 1, 2]], groups=[5])
        return SliceData.build(np.eye(3) * (1 + c0), segments=[[0, 1]])

    def describe(self):
        return {"kind": "flaky"}


@pytest.mark.parametrize("mode, field", [("nan", "points"), ("none", "points"), ("group", "groups")])
def test_a_bad_user_slice_is_named_and_the_widget_recovers(make, mode, field):
    src = Flaky()
    w = make(src, ball_radius=0.05)
    src.mode = mode
    rows = w.scene.rows
    with pytest.raises((TypeError, ValueError), match=f"Flaky.slice.*`{field}`"):
        w.press("l")  # from code the error is raised; from a key it is shown (below)
    down(w, "l", code="KeyL")
    up(w, "l", code="KeyL")
    assert w.errors.outputs, "the bad slice went through silently"
    text = w.errors.outputs[-1]["text"]
    assert "Flaky.slice" in text and f"`{field}`" in text
    assert np.shares_memory(w.scene.rows, rows)  # nothing of it reached the page
    src.mode = "good"
    down(w, "l", code="KeyL")
    up(w, "l", code="KeyL")
    assert w.errors.outputs == ()  # recovered: the error is cleared


# ------------------------------------------------------- item 13: smaller ones
def test_p_never_writes_through_a_dangling_link_and_screenshot_refuses_a_link(make, tmp_path, monkeypatch):
    from test_widget_screenshot import _answer, _asked, _data_url, _png

    monkeypatch.chdir(tmp_path)
    target = tmp_path / "elsewhere.png"
    os.symlink(target, tmp_path / "rot4d-001.png")
    from test_widget import front_end_view_count

    w = make()
    front_end_view_count(w, 1)
    down(w, "p", code="KeyP")
    up(w, "p", code="KeyP")
    rid = w._shots.seq
    _answer(w, rid, png=_data_url(_png()))
    assert not target.exists()
    assert (tmp_path / "rot4d-002.png").is_file()
    link = tmp_path / "link.png"
    os.symlink(target, link)
    rid = w.screenshot(str(link))
    _answer(w, rid, png=_data_url(_png()))
    assert not target.exists() and "not saved" in w.readout.value


def test_a_field_stacked_at_construction_keeps_its_level_keys(make):
    w = make(ball_field(), slices=3)
    before = w.levels
    assert w.press("o") and w.levels != before
    assert "level up" in w.help_panel.value


def test_a_keymap_binding_c_and_keyc_differently_is_refused():
    with pytest.raises(ValueError, match="'c' and 'KeyC'"):
        DEFAULT_KEYMAP.replace(KeyC="xy")
    assert DEFAULT_KEYMAP.replace(KeyC="zw")["KeyC"] == DEFAULT_KEYMAP["c"]  # the same action: fine


def test_o_held_stays_in_the_data_range_and_i_undoes_each_step(make):
    w = make(ball_field(), levels=0.0)
    lo, hi = w.source.data_range
    step = w.source.level_step
    made = sum(bool(w.press("o")) for _ in range(500))
    assert w.levels[0] <= hi + step
    for _ in range(made):
        assert w.press("i")
    assert w.levels[0] == pytest.approx(0.0, abs=1e-9)
    w.levels = (hi + 10 * step,)  # set outside by hand: i still steps back towards the range
    assert not w.press("o") and w.press("i")


def test_a_replay_sets_a_stack_setting_the_keys_had_changed_since_it_was_last_set(make):
    w = make("5-cell")
    w.slices = 4
    w.press("b")  # 3 (a step: the trait follows, the recording has the step)
    w.slices = 4  # set again: a change from 3
    w.press("b")
    again = make("5-cell")
    again.replay(w.recording)
    assert again.slices == w.slices == 3


def test_a_replay_ends_at_the_levels_and_spacing_set_as_traits(make):
    """Item 9: after `w.levels = (...)` / `w.spacing = 0.3` a replay ended at the old values."""
    w = make(ball_field())
    w.levels = (0.2, 0.5)
    w.press("4")
    again = make(ball_field())
    again.replay(w.recording)
    assert again.levels == (0.2, 0.5)
    s = make("24-cell", slices=3)
    s.spacing = 0.3
    s.press("g")
    again = make("24-cell")
    again.replay(s.recording)
    assert again.slices == 3 and again.spacing == pytest.approx(s.spacing)


def test_a_bool_is_not_a_slice_count_or_a_spacing_even_when_it_equals_the_value(make):
    w = make("5-cell", slices=1, spacing=1.0)
    with pytest.raises(TypeError, match="slices"):
        w.slices = True  # True == 1: traitlets would see no change and keep True
    with pytest.raises(TypeError, match="spacing"):
        w.spacing = True
    assert w.slices == 1 and type(w.slices) is int and w.spacing == 1.0 and type(w.spacing) is float


def test_a_keyup_80_s_late_takes_back_every_step_with_one_observer_call(make, clock):
    """Item 0: a released key kept turning for 82 s; the take-back must not cost a step's
    observers per step taken back (2,400 calls of a slow observer would freeze the keyup)."""
    w = make()
    down(w, "4", t=0.0)
    run_ticker(w, clock, clock.t + 80.0)
    assert xw_steps(w) != 1 and len(w.recording.events) > 2000
    calls = []
    w.observe(lambda change: calls.append(1), names="orientation")
    up(w, "4", t=0.05)
    assert len(calls) == 1
    m = w.state.matrix
    expected = np.eye(4)
    c, s = math.cos(w.state.theta0), math.sin(w.state.theta0)
    expected[0, 0] = expected[3, 3] = c
    expected[3, 0], expected[0, 3] = s, -s
    np.testing.assert_allclose(m, expected, atol=1e-9)
    from test_widget_scene import drawn

    drawn(w)  # the page drew what is in flight: the readout catches up
    assert "<td>last</td><td>R_xw</td>" in w.readout.value  # one step, not "R_xw ×2400"


# ------------------------------------------------------- issue 33, item 7: small ones (each failed before)
def test_a_page_timestamp_past_float_range_is_no_page_time_not_an_error(make):
    w = make()
    deliver(w, {"type": "keydown", "key": "4", "code": "Digit4", "repeat": False, "timeStamp": 10**400,
                "shiftKey": False, "altKey": False, "ctrlKey": False, "metaKey": False})
    deliver(w, {"type": "keyup", "key": "4", "code": "Digit4", "repeat": False, "timeStamp": 10**400,
                "shiftKey": False, "altKey": False, "ctrlKey": False, "metaKey": False})
    assert w.errors.outputs == ()  # an OverflowError was shown under the readout
    assert xw_steps(w) == 1


def test_a_second_keydown_without_repeat_during_a_tap_is_a_repeat_not_a_step(make):
    w = make()
    down(w, "4", t=1.0)
    down(w, "4", t=1.03)  # no keyup between, no repeat flag (some browsers and OSes)
    up(w, "4", t=1.05)
    assert xw_steps(w) == 1  # it made 2


def test_a_state_file_whose_c0_its_step_cannot_move_is_refused(make, tmp_path):
    import json

    from rot4d_widget.keep.statefile import load_state

    w = make()
    path = tmp_path / "view.json"
    w.save_state(path)
    d = json.loads(path.read_text())
    d["state"]["c0"] = 1e308  # h could never step back from there
    path.write_text(json.dumps(d))
    with pytest.raises(ValueError, match=r"Expected `c0` where its step .* moves it .*got 1e\+308"):
        load_state(path)
    with pytest.raises(ValueError, match="could never bring it back"):
        w.state.c0 = 1e308
    w.state.c0 = 1e6  # far outside, but the keys step it back
    assert w.press("h") and w.state.c0 < 1e6


@pytest.mark.parametrize("what", ["state", "recording"])
def test_a_deeply_nested_json_file_is_a_value_error(tmp_path, what):
    from rot4d_widget.keep.statefile import load_state
    from rot4d_widget.keep.recorder import Recording

    path = tmp_path / "deep.json"
    path.write_text("[" * 100_000 + "]" * 100_000)  # RecursionError before
    with pytest.raises(ValueError, match="nested deeper than 64 levels"):
        (load_state if what == "state" else Recording.load)(path)
    path.write_text('{"format": "rot4d_widget state", "a": ' + "[" * 70 + "]" * 70 + "}")
    with pytest.raises(ValueError, match="nested deeper"):
        (load_state if what == "state" else Recording.load)(path)


def test_an_object_scaled_to_the_coordinate_bound_is_in_and_one_past_it_says_by_how_much():
    from rot4d_widget import Polytope, polytope

    p = polytope("5-cell")
    v = p.vertices / np.abs(p.vertices).max()
    top = np.nextafter(1e150, np.inf)  # 1e150 as a scaling rounds to
    Polytope(v * top, p.faces, p.cells)  # refused before: "is 1e+150; expected 1e-150 to 1e+150"
    with pytest.raises(ValueError, match=r"is 1\.01e\+150; expected 1e-150 to 1e\+150"):
        Polytope(v * 1.01e150, p.faces, p.cells)


def test_float_indices_in_a_user_slice_are_refused():
    with pytest.raises(ValueError, match="`segments` to be integer indices, got an array of float64"):
        SliceData.build(np.eye(3), segments=[[0.0, 1.7]])  # 1.7 pointed at point 1 before
    with pytest.raises(ValueError, match="`triangles` to be integer indices"):
        SliceData.build(np.eye(3), triangles=[[0.0, 1.0, 2.0]])
    with pytest.raises(ValueError, match="`groups` to be integer indices"):
        SliceData.build(np.eye(3), triangles=[[0, 1, 2]], groups=[0.5])
    assert SliceData.build(np.eye(3), segments=np.zeros((0, 2))).segments.shape == (0, 2)  # empty: any dtype
