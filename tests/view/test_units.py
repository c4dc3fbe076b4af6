"""The widget's units on their own (issue 20): key repeat, the update pump, readout HTML, trait
types, the view key, kinds read through the source protocol, a user's source's own settings
recorded and replayed, screenshots, the key pad, the key path."""

from __future__ import annotations

import math
import re
import warnings

import numpy as np
import pytest
import traitlets

from rot4d_widget.core.rotation import simple_rotation
from rot4d_widget.sources.protocol import SliceData
from rot4d_widget.view import markup as ro
from rot4d_widget.view import traits as t
from rot4d_widget.view.keyhold import KeyRepeater
from rot4d_widget.view.painter import ViewKey
from rot4d_widget.view.pump import PAGE_BUDGET, UpdatePump
from rot4d_widget.view.screenshots import MAX_PENDING_SCREENSHOTS
from rot4d_widget.view.stacking import is_stack


# ------------------------------------------------------------------ key repeat
def test_a_held_key_repeats_after_the_hold_delay_at_the_tick_rate():
    r = KeyRepeater(hold_delay=0.25, tick_rate=30)
    r.press("Digit4", "xw", False, now=10.0)
    assert r.due(10.2) == [] and r.next_deadline() == pytest.approx(10.25)
    steps = [s for t in np.arange(10.2, 11.0, 0.01) for s in r.due(t)] + r.due(11.0)  # called often
    assert len(steps) == 1 + math.floor((11.0 - 10.25) * 30) == 23
    assert steps[0] == ("xw", False)
    r.release("Digit4")
    assert r.due(20.0) == [] and r.next_deadline() is None and r.held_keys == ()


def test_two_keys_step_in_time_order_then_press_order():
    r = KeyRepeater(hold_delay=0.1, tick_rate=10)
    r.press("a", "A", False, now=0.0)
    r.press("b", "B", True, now=0.0)
    assert r.held_keys == ("a", "b")
    assert r.due(0.25) == [("A", False), ("B", True), ("A", False), ("B", True)]


def test_a_stall_replays_at_most_max_lag_of_ticks():
    r = KeyRepeater(hold_delay=0.1, tick_rate=20, max_lag=0.25)
    r.press("k", "K", False, now=0.0)
    assert len(r.due(100.0)) == math.ceil(0.25 * 20)  # not 2000
    assert r.next_deadline() == pytest.approx(100.05)  # and it goes on from now


@pytest.mark.parametrize("kw, match", [({"hold_delay": 0}, "hold_delay"), ({"tick_rate": 1e6}, "tick_rate"),
                                        ({"tick_rate": "fast"}, "tick_rate"), ({"max_lag": -1}, "max_lag")])
def test_bad_repeat_settings_are_refused(kw, match):
    with pytest.raises((TypeError, ValueError), match=match):
        KeyRepeater(**kw)


# ----------------------------------------------------------------- update pump
class Page:
    """What the pump drives: a counter of sends; each send gets a new id."""

    def __init__(self):
        self.sent = []
        self.changes = 0

    def send(self):
        if self.sent and self.sent[-1][1] == self.changes:
            return None  # nothing new on screen
        self.sent.append((len(self.sent) + 1, self.changes))
        return len(self.sent)


def make_pump(page, clock, **kw):
    return UpdatePump(page.send, clock=clock, autotick=False, **kw)


@pytest.mark.parametrize("max_in_flight", [1, 2, 3])
def test_at_most_max_in_flight_updates_and_the_next_is_the_latest(max_in_flight):
    t = [0.0]
    page = Page()
    pump = make_pump(page, lambda: t[0], ack_timeout=0.5, max_in_flight=max_in_flight)
    for i in range(6):  # six changes, none acknowledged yet
        page.changes += 1
        pump.mark_dirty()
        pump.flush()
    assert [s[1] for s in page.sent] == list(range(1, max_in_flight + 1)) and pump.n_in_flight == max_in_flight
    assert pump.acknowledge(1) is True  # the oldest drawn: the latest state (not the backlog) goes out
    assert page.sent[-1][1] == 6 and pump.n_in_flight == max_in_flight
    assert pump.acknowledge(1) is False  # late duplicate (another view)
    assert pump.acknowledge(99) is False and pump.acknowledge(True) is False  # unknown / not an id
    assert pump.acknowledge(page.sent[-1][0]) is True  # the newest retires every older one
    assert pump.in_flight is None and pump.stats.acks == 2


def test_a_slow_page_gets_fewer_in_flight_but_never_fewer_than_two():
    """What is in flight at a key's release is drawn after it: a page that says it takes 0.12 s an
    update gets two in flight (what fits in PAGE_BUDGET), not three; a quick one three again; a very
    slow one still two (one drawn while the next travels).  What is not a time is ignored."""
    t = [0.0]
    page = Page()
    pump = make_pump(page, lambda: t[0], ack_timeout=5.0, max_in_flight=3)

    def burst():
        for _ in range(5):
            page.changes += 1
            pump.mark_dirty()
            pump.flush()

    def page_says(seconds, times):
        for _ in range(times):
            assert pump.acknowledge(page.sent[-1][0], draw_time=seconds)
            burst()

    burst()
    assert pump.limit == 3 and pump.n_in_flight == 3  # the page said nothing yet
    page_says(0.12, 3)
    assert PAGE_BUDGET / 0.12 < 3 and pump.limit == 2 and pump.n_in_flight == 2
    page_says(0.02, 8)
    assert pump.limit == 3 and pump.n_in_flight == 3
    page_says(3.0, 8)
    assert pump.limit == 2 and pump.n_in_flight == 2
    page_says(0.02, 8)
    for bad in (math.nan, -1.0, math.inf, True, "0.5", None):
        page_says(bad, 1)
    assert pump.limit == 3 and pump.n_in_flight == 3 and pump.stats.timeouts == 0  # held back, none given up
    one = make_pump(Page(), lambda: t[0], max_in_flight=1)
    assert one.acknowledge(1, draw_time=1.0) is False and one.limit == 1  # a bound of one stays one


@pytest.mark.parametrize("rtt, want", [(0.0, 3), (0.05, 3), (0.12, 4), (0.3, 9), (2.0, 12)])
def test_a_page_far_away_gets_a_round_trip_of_updates_in_flight(rtt, want):
    """Issue 34: for a source the page cannot cut, a kernel 120 ms away keeps the page drawing every
    tick with ceil(0.12 x 30) = 4 in flight (three waited a round trip per three ticks); capped."""
    t = [0.0]
    page = Page()
    pump = make_pump(page, lambda: t[0], ack_timeout=5.0, max_in_flight=3, tick_rate=30.0)
    for _ in range(8):  # each update acknowledged a round trip (plus the page's 10 ms) after it left
        page.changes += 1
        pump.mark_dirty()
        pump.flush()
        t[0] += rtt + 0.01
        pump.acknowledge(page.sent[-1][0], draw_time=0.01)
    assert pump.round_trip == pytest.approx(rtt, abs=1e-9)
    assert pump.limit == want
    assert make_pump(Page(), lambda: 0.0, max_in_flight=3).limit == 3  # no tick rate: the fixed bound


def test_without_an_ack_the_oldest_is_given_up_after_the_timeout():
    t = [0.0]
    page = Page()
    pump = make_pump(page, lambda: t[0], ack_timeout=0.5, max_in_flight=2)
    for now in (0.0, 0.1, 0.2):
        t[0] = now
        page.changes += 1
        pump.mark_dirty()
        pump.flush()
    assert len(page.sent) == 2
    assert pump.service(0.4) == pytest.approx(0.5)  # it wants to run when the oldest times out
    pump.service(0.5)
    assert len(page.sent) == 3 and pump.stats.timeouts == 1
    assert pump.service(2.0) is None  # nothing dirty: nothing to wait for


def test_a_slow_page_stretches_the_timeout_to_four_times_its_median_ack():
    t = [0.0]
    page = Page()
    pump = make_pump(page, lambda: t[0], ack_timeout=0.5, max_in_flight=1)
    for i in range(8):  # the page takes 0.3 s per picture
        page.changes += 1
        pump.mark_dirty()
        pump.flush()
        t[0] += 0.3
        assert pump.acknowledge(page.sent[-1][0])
    assert pump.timeout == pytest.approx(1.2)
    page.changes += 1
    pump.mark_dirty()
    pump.flush()
    page.changes += 1
    pump.mark_dirty()
    pump.service(t[0] + 0.6)  # past ack_timeout but not past 4 x 0.3 s: still waiting
    assert pump.stats.timeouts == 0
    pump.service(t[0] + 1.21)
    assert pump.stats.timeouts == 1


def test_errors_go_to_on_error_and_the_failed_picture_is_sent_on_the_next_ack_or_flush():
    # issue 18 item 7: the pump used to clear its dirty flag before a send that raised,
    # so the page never got that picture, not after acks nor a flush
    seen = []
    boom = {"on": True}
    sent = []

    def send():
        if boom["on"]:
            raise RuntimeError("boom")
        sent.append(len(sent) + 1)
        return sent[-1]

    pump = UpdatePump(send, clock=lambda: 0.0, autotick=False, on_error=seen.append)
    pump.mark_dirty()
    pump.service(0.0)
    assert [type(e) for e in seen] == [RuntimeError] and pump.dirty  # the picture is still owed
    assert pump.next_deadline() is None  # and not retried in a busy loop
    boom["on"] = False
    pump.flush(0.0)  # no new change: the owed picture goes out
    assert sent == [1] and pump.stats.updates == 1 and not pump.dirty
    boom["on"] = True
    pump.mark_dirty()
    pump.service(0.0)
    boom["on"] = False
    assert pump.acknowledge(1) is True and sent == [1, 2]  # an ack retries it too


def test_one_very_late_ack_does_not_set_a_huge_timeout():
    # issue 18 item 10: one ack 600 s late among the first two set the timeout to 2,400 s
    t = [0.0]
    page = Page()
    pump = make_pump(page, lambda: t[0], ack_timeout=0.5, max_in_flight=1)
    page.changes += 1
    pump.mark_dirty()
    pump.flush()
    t[0] = 600.0
    assert pump.acknowledge(1)
    assert pump.timeout <= 5.0
    page.changes += 1
    pump.mark_dirty()
    pump.flush()
    t[0] += 0.1
    assert pump.acknowledge(2)
    assert pump.timeout == 0.5  # the lower median of (600 capped, 0.1): the page is fast again


def test_a_slow_tick_releases_the_lock_between_ticks():
    # issue 18 item 1: a tick longer than the period kept the ticker's lock for good (its
    # release happened only inside a wait() that was skipped when the timeout was <= 0)
    import time

    period = 0.01
    due = {"t": time.monotonic()}
    ticks = []

    cost = []

    def tick(now):  # every tick takes 5 periods (a slow observer)
        if due["t"] is not None and due["t"] <= now:
            t0 = time.monotonic()
            time.sleep(5 * period)
            cost.append(time.monotonic() - t0)  # what a tick really cost in this run
            ticks.append(now)
            due["t"] = time.monotonic()  # already due again: it overran

    pump = UpdatePump(lambda: None, tick=tick, deadline=lambda: due["t"])
    pump.wake()
    try:
        limit = time.monotonic() + 10
        while len(ticks) < 2 and time.monotonic() < limit:
            time.sleep(period)
        got = []
        for _ in range(5):
            t0 = time.monotonic()
            assert pump.lock.acquire(timeout=2.0), "the ticker kept the lock"  # what a keyup handler does
            got.append(time.monotonic() - t0)
            pump.lock.release()
            time.sleep(period)
        longest_tick = max(cost)
        assert max(got) < 10 * longest_tick, (got, cost)  # within about one tick, not never
    finally:
        due["t"] = None
        if pump.lock.acquire(timeout=2.0):
            pump.lock.release()
            pump.close()



def test_the_thread_slices_without_the_lock_and_coalesces_changes():
    """A two-phase send: the slow part runs with the lock free; ten changes meanwhile make one picture."""
    import threading
    import time

    state = {"v": 0}
    shown = []
    started = threading.Event()
    slow_for = 0.6  # the slice's own time: a lock held across it would make each tap wait about that

    def send():
        v = state["v"]  # read under the lock
        def slow():
            started.set()
            time.sleep(slow_for)
            return v
        result = yield slow
        shown.append(result)
        return len(shown)

    pump = UpdatePump(send, ack_timeout=0.05)
    try:
        with pump.lock:
            state["v"] += 1
            pump.mark_dirty()
            pump.flush()
        assert started.wait(5)
        for _ in range(10):  # taps while the slice is computed: the lock is free
            t0 = time.monotonic()
            with pump.lock:
                assert time.monotonic() - t0 < slow_for / 2  # not behind the slice
                state["v"] += 1
                pump.mark_dirty()
                pump.flush()
        deadline = time.monotonic() + 10
        while (not shown or shown[-1] != 11) and time.monotonic() < deadline:
            time.sleep(0.02)
        assert shown[-1] == 11 and len(shown) == 2, shown  # the first picture, then only the latest
    finally:
        pump.close()


def test_the_thread_runs_ticks_in_real_time_and_stops_on_close():
    import threading
    import time

    ticks = []
    deadline = {"t": time.monotonic()}

    def tick(now):
        while deadline["t"] is not None and deadline["t"] <= now:
            ticks.append(now)
            deadline["t"] += 0.01
            if len(ticks) >= 20:
                deadline["t"] = None

    pump = UpdatePump(lambda: None, tick=tick, deadline=lambda: deadline["t"])
    pump.wake()
    for _ in range(200):
        if len(ticks) >= 20:
            break
        time.sleep(0.01)
    assert len(ticks) == 20 and pump.thread_alive
    pump.close()
    assert not pump.thread_alive
    assert not any(t.name.startswith("rot4d-ticker") and t.is_alive() for t in threading.enumerate()
                   if t is pump._thread)


# --------------------------------------------------------------------- readout
def test_the_gizmo_shows_each_axis_xy_as_an_arrow_and_w_as_a_bar():
    m = simple_rotation("xw", math.pi / 6)  # x tilts into w: its w part is sin(30°)
    svg = ro.gizmo_svg(m)
    assert len(svg.encode()) < 1000  # sent with the readout
    bars = [float(w) for w in re.findall(r"<rect x=[-\d.]+ y=[-\d.]+ width=([\d.]+)", svg)]
    assert bars == pytest.approx([28 * abs(m[3, i]) for i in range(4)], abs=0.51)
    ends = [(float(x), float(y)) for x, y in re.findall(r"x2=([-\d.]+) y2=([-\d.]+)", svg)]
    assert ends[0] == pytest.approx((30 + 26 * m[0, 0], 30 - 26 * m[1, 0]), abs=0.51)
    assert len(ends) == 5  # four axes and the separator


def test_the_gauge_places_c0_between_the_extremes_and_says_when_outside():
    assert "left:50%" in ro.gauge_html(0.0, -1.0, 1.0)
    assert "left:75%" in ro.gauge_html(0.5, -1.0, 1.0)
    out = ro.gauge_html(3.0, -1.0, 1.0)
    assert "left:100%" in out and "above the object" in out
    assert "below the object" in ro.gauge_html(-3.0, -1.0, 1.0)


def test_angles_read_in_radians_and_degrees():
    assert ro.angle_text(math.pi / 64) == "0.04909 rad (2.81\u00b0)"


def test_readout_escapes_its_title_and_labels():
    html = ro.readout_html("<b>x</b>", [("<i>", "1")])
    assert "&lt;b&gt;x&lt;/b&gt;" in html and "&lt;i&gt;" in html


def test_held_keys_keep_ticking_while_a_slow_slice_is_computed():
    """The slow part of a send runs on a worker: the ticker's ticks are not eaten by it (a held
    key on a slow 6-slice stack made 21 steps in a 1 s hold instead of 25)."""
    import threading
    import time

    period = 0.01
    due = {"t": time.monotonic()}
    ticks = []
    in_slice = threading.Event()
    done = threading.Event()
    box = {}

    def tick(now):
        while due["t"] is not None and due["t"] <= now:
            ticks.append(now)
            due["t"] += period

    def send():
        def slow():
            in_slice.set()
            time.sleep(0.5)
            done.set()
            return 1
        result = yield slow
        return result

    pump = UpdatePump(send, tick=tick, deadline=lambda: due["t"])
    try:
        with pump.lock:
            pump.mark_dirty()
            pump.flush()
        assert in_slice.wait(10)
        box["before"] = len(ticks)
        assert done.wait(10)
        during = len(ticks) - box["before"]
        assert during >= 5, during  # ~50 at 100 Hz; 0 or 1 when the ticker itself sliced
    finally:
        due["t"] = None
        pump.close()


# -- trait types -----------------------------------------------------------------------------------
class _Holder(traitlets.HasTraits):
    radius = t.Positive(0.5, upper=10.0)
    opacity = t.Fraction(0.4)
    flag = t.Flag(True)
    count = t.Count(None, low=1, high=64, allow_none=True)
    spacing = t.Spacing(None, allow_none=True)
    arrangement = t.Choice(None, ("oval", "grid", "stack"), allow_none=True)
    levels = t.Levels(None, allow_none=True)
    angle = t.Angle(0.1)
    colour = t.Colour("#fff")
    color_by = t.ColorBy("group")


@pytest.mark.parametrize("name, value, exc, match", [
    ("radius", -1.0, ValueError, r"`radius` in \(0, 10.0\]"),
    ("radius", "big", TypeError, "`radius` to be a positive number"),
    ("opacity", 1.5, ValueError, r"`opacity` to be a number in \[0, 1\]"),
    ("flag", "no", TypeError, "`flag` to be True or False"),
    ("count", 0, ValueError, "`count` to be an int in 1 \u2026 64 or None"),
    ("count", True, TypeError, "`count` to be an int in 1 \u2026 64 or None"),
    ("count", 2.0, TypeError, "`count`"),
    ("spacing", True, TypeError, "`spacing` to be a finite number > 0 or None"),
    ("spacing", -1, ValueError, "`spacing` to be a finite number > 0 or None"),
    ("arrangement", "spiral", ValueError, "'oval', 'grid', 'stack' or None"),
    ("arrangement", 3, TypeError, "`arrangement`"),
    ("levels", "high", TypeError, "`levels` to be a number or a sequence of numbers"),
    ("levels", [], TypeError, "`levels`"),
    ("angle", -0.1, ValueError, r"\(0, pi\]"),
    ("colour", "sky", ValueError, "#rrggbb"),
    ("color_by", "purple", ValueError, "color_by.*group"),
])
def test_trait_types_refuse_naming_what_is_allowed(name, value, exc, match):
    h = _Holder()
    before = getattr(h, name)
    with pytest.raises(exc, match=match):
        setattr(h, name, value)
    assert getattr(h, name) == before


def test_trait_types_normalise_what_they_accept():
    h = _Holder()
    h.count, h.spacing, h.flag, h.radius = np.int64(5), 2, np.bool_(False), 1
    assert (type(h.count), type(h.spacing), type(h.flag), type(h.radius)) == (int, float, bool, float)
    h.levels = 0.5
    assert h.levels == (0.5,)
    h.levels = np.array([0.1, 0.2])
    assert h.levels == (0.1, 0.2)
    h.count = None
    assert h.count is None
    h.color_by = [1, 0, 0]
    assert h.color_by == (1.0, 0.0, 0.0)


def test_the_widgets_traits_are_typed_in_the_declaration():
    from rot4d_widget.view.widget import Rot4DWidget

    typed = {n for n, tr in Rot4DWidget.class_traits().items() if isinstance(tr, t.Checked)}
    assert typed >= {"theta0", "alpha", "c0", "ball_radius", "bar_radius", "face_opacity", "background",
                     "show_balls", "show_bars", "show_faces", "color_by", "levels", "inside", "caps", "slices",
                     "spacing", "arrangement"}
    assert Rot4DWidget.class_traits()["slices"].high == 64


# -- the view key --------------------------------------------------------------------------------------
def test_view_key_compares_by_name_not_position():
    m = np.eye(4)
    a = ViewKey(m, 0.0, (0, 0, 5), 1, "group", False)
    assert a.same(ViewKey(m.copy(), 0.0, (0, 0, 5), 1, "group", False))
    assert not a.same(ViewKey(m, 0.0, (0, 0, 5), 1, "group", True))  # coarse differs
    assert a.same_cut(ViewKey(simple_rotation("xy", 0.3), 0.0, (0, 0, 5), 1, "group", True))
    assert not a.same_cut(ViewKey(m, 0.1, (0, 0, 5), 1, "group", False))
    turned = ViewKey(simple_rotation("xy", 0.3), 0.0, (0, 0, 5), 1, "group", False)
    np.testing.assert_allclose(turned.turn_from(a), simple_rotation("xy", 0.3)[:3, :3])
    assert ViewKey(simple_rotation("xw", 0.3), 0.0, (0, 0, 5), 1, "group", False).turn_from(a) is None
    with pytest.raises(AttributeError):
        a.c0 = 1.0  # frozen


# -- kinds through the protocol ------------------------------------------------------------------------
class Slab:
    """A user's source with its own setting (thickness), through the protocol's settings/apply_setting."""

    size = math.sqrt(3.0)
    n_groups = 1

    def __init__(self, thickness=0.5):
        self.thickness = thickness

    @property
    def settings(self):
        return {"thickness": self.thickness}

    def apply_setting(self, name, value):
        if name != "thickness":
            raise ValueError(f"A slab's setting is 'thickness', not {name!r}")
        self.thickness = float(value)

    def slice(self, matrix, c0):
        h = self.thickness
        pts = np.array([[x, y, z] for x in (-h, h) for y in (-1, 1) for z in (-1, 1)], dtype=float)
        return SliceData.build(pts, volume=8 * h)

    def describe(self):
        return {"kind": "slab", "thickness": self.thickness, "rebuild": "a test's own class"}


class Wrapper(Slab):
    """Not a StackSource, but a source made around another: the protocol says so (``wraps``)."""

    def __init__(self):
        super().__init__()
        self.wraps = Slab()


def test_a_stack_is_a_source_that_wraps_another_whatever_its_class():
    assert is_stack(Wrapper()) and not is_stack(Slab())


def test_a_user_sources_settings_are_recorded_on_refresh_and_replayed(make):
    slab = Slab()
    w = make(slab)
    assert w.recording.initial_source == {"thickness": 0.5}
    assert w.source.user_object is slab  # the source shown is the UserSource wrapping it (issue 38)
    w.source.thickness = 0.25
    assert slab.thickness == 0.25
    w.refresh()
    rec = w.recording
    assert [(e.name, e.value) for e in rec.events if hasattr(e, "name") and e.name == "thickness"] == [
        ("thickness", 0.25)]
    w.refresh()  # unchanged: not recorded again
    assert sum(getattr(e, "name", None) == "thickness" for e in w.recording.events) == 1
    other = make(Slab())
    other.replay(rec)
    assert other.source.thickness == 0.25 and other.slice.volume == pytest.approx(2.0)


# -- screenshots, key pad, key path ----------------------------------------------------------------------
def test_screenshots_without_a_view_are_bounded_and_say_so(make):
    w = make("5-cell")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for _ in range(3 * MAX_PENDING_SCREENSHOTS):
            assert w.screenshot() is None
    assert len(w._shots.pending) == MAX_PENDING_SCREENSHOTS
    assert "no view is displayed" in w._painter.note and "no view is displayed" in w.readout.value


def test_the_key_pad_is_built_once_when_first_shown(make):
    w = make("5-cell")
    assert w._keypad.box is None
    w.keypad = True
    box = w._keypad.box
    w.keypad = False
    w.keypad = True
    assert w._keypad.box is box and box.layout.display is None and len(w._keypad.events) >= 20


def test_the_key_path_steps_records_and_settles(make):
    w = make("5-cell")
    keys = w._keys
    keys.handle_event({"type": "keydown", "key": "4", "code": "Digit4", "timeStamp": 1000.0})
    assert keys.last.label is not None and keys.last.count == 1 and w.held_keys == ("Digit4",)
    keys.handle_event({"type": "keyup", "key": "4", "code": "Digit4", "timeStamp": 1010.0})
    assert w.held_keys == () and w._painter.settled
    assert len(w.recording.events) == 1
    keys.handle_event("not an event")  # ignored, never raised
    assert w.errors.outputs == ()
