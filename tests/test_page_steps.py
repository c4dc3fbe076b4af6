"""The kernel applies exactly the steps the page makes, in the page's order (issue 34).

A reference "page" here is the schedule itself: each key's steps at its page times (the first at
the keydown, repeats from the hold delay at the tick rate, the last at or before the keyup), all
keys' steps in page-time order, applied to a fresh state.  The kernel gets the same key events,
late and in bursts, with the page's heartbeats (the companion's ``clock`` messages) or without
them (its own estimate), and must end on that state exactly -- also after rebuilding from its
checkpoint when an event arrives stamped before steps it had already made -- and its recording
must replay to it bit for bit.  Fake clock, real scene and companion, no browser.
"""

from __future__ import annotations

import numpy as np
import pytest

from rot4d_widget.core.keymap import DEFAULT_KEYMAP
from rot4d_widget.core.state import RotationState
from rot4d_widget.view.steplog import step_time
from test_widget import down, up
from test_widget_scene import run_ticker

pytestmark = pytest.mark.usefixtures("recording_comms")


def heartbeat(w, t_ms):
    w.companion.comm.handler({"content": {"data": {"method": "custom", "content": {"event": "clock", "t": t_ms}}},
                              "buffers": []})


def reference(w, presses):
    """The page's state after ``presses`` = [(key, shift, down_ms, up_ms)], from the widget's start."""
    hold, period = 1000.0 * w.hold_delay, 1000.0 / w.tick_rate
    steps = []
    for order, (key, shift, t0, t1) in enumerate(presses):
        action, inverted = DEFAULT_KEYMAP.resolve(key, shift)
        repeats = action.kind in ("rotate", "alpha", "c0")
        k = 0
        while True:
            t = step_time(t0, k, hold, period)
            if t > t1 or (k and not repeats):
                break
            steps.append((t, order, action, inverted))
            k += 1
    state = RotationState(theta0=w.state.theta0, c0_step=w.state.c0_step, c0_limit=w.state.c0_limit,
                          c0_origin=w.state.c0_origin)
    for _, _, action, inverted in sorted(steps, key=lambda s: s[:2]):
        state.apply(action, inverted)
    return state


def assert_same(w, ref):
    assert np.array_equal(w.state.matrix, ref.matrix)
    assert (w.state.theta0, w.state.alpha, w.state.c0) == (ref.theta0, ref.alpha, ref.c0)


def assert_replays(w, make):
    again = make(w.source.polytope if hasattr(w.source, "polytope") else "5-cell")
    again.replay(w.recording)
    assert np.array_equal(again.state.matrix, w.state.matrix)
    assert (again.state.theta0, again.state.alpha, again.state.c0) == (w.state.theta0, w.state.alpha, w.state.c0)


def test_two_keys_held_together_with_heartbeats_end_on_the_page_s_state(make, clock):
    w = make("24-cell")
    down(w, "4", t=1.000)
    for t in range(1000, 1401, 33):  # the page's heartbeats while it steps
        heartbeat(w, float(t))
    down(w, "c", t=1.180)  # a second key while the first is held
    for t in range(1401, 2200, 33):
        heartbeat(w, float(t))
    up(w, "4", t=1.900)
    up(w, "c", t=2.100)
    assert_same(w, reference(w, [("4", False, 1000.0, 1900.0), ("c", False, 1180.0, 2100.0)]))
    assert w.held_keys == ()
    assert_replays(w, make)


def test_a_slow_kernel_that_hears_everything_at_once_ends_on_the_same_state(make, clock):
    """No heartbeat and no tick ran during the holds: every step is made when the keyups come."""
    w = make("24-cell")
    down(w, "8", t=5.0)
    down(w, "y", shift=True, t=5.3)
    down(w, "l", t=5.31)
    up(w, "8", t=6.2)
    up(w, "l", t=6.25)
    up(w, "y", shift=True, t=7.0)
    assert_same(w, reference(w, [("8", False, 5000.0, 6200.0), ("y", True, 5300.0, 7000.0),
                                 ("l", False, 5310.0, 6250.0)]))
    assert_replays(w, make)


def test_steps_made_ahead_of_a_late_keyup_are_rebuilt_not_corrected(make, clock):
    """The kernel's own estimate ran ahead (the page went quiet); the keyup then says the hold was
    shorter: the state is rebuilt from the checkpoint -- equal to the page's, bit for bit (taking
    steps back by opposite steps would leave rounding behind) -- and the recording replays to it."""
    w = make("24-cell")
    down(w, "z", t=3.0)
    heartbeat(w, 3050.0)
    run_ticker(w, clock, clock.t + 1.5)  # silent page: the kernel steps on by its estimate
    assert abs(np.trace(w.state.matrix)) < 3.99  # it did step ahead
    up(w, "z", t=3.4)
    assert_same(w, reference(w, [("z", False, 3000.0, 3400.0)]))
    assert_replays(w, make)


def test_a_keyup_stamped_before_steps_heard_of_rebuilds_them(make, clock):
    """A keyup dispatched a moment after a heartbeat stamped later (the page's event queue): the
    kernel had made a step after the keyup's time; it goes."""
    w = make("24-cell")
    down(w, "4", t=1.0)
    heartbeat(w, 1300.0)  # steps at 1000, 1250, 1283.3
    up(w, "4", t=1.26)  # the key was up before the step at 1283.3
    assert_same(w, reference(w, [("4", False, 1000.0, 1260.0)]))


def test_the_state_id_names_the_page_time_and_a_change_from_the_kernel_starts_an_epoch(make, clock):
    w = make("24-cell")
    steps = w._keys.page
    down(w, "4", t=1.0)
    heartbeat(w, 1100.0)
    assert steps.state_id == (0, 1100.0)
    w.theta0 = w.theta0 * 2  # a trait from code, while the key is held
    heartbeat(w, 1200.0)
    assert steps.state_id == (1, 1200.0)
    up(w, "4", t=1.3)
    # the page re-applies its steps after the id's time on the kernel's state: here, the repeats
    # at 1250 and 1283.3 (the keydown's step is in the state the trait change started from)
    assert steps.state_id[0] == 1 and steps.state_id[1] == 1300.0


def test_a_second_keydown_of_a_held_key_is_a_repeat(make, clock):
    w = make("5-cell")
    down(w, "4", t=1.0)
    down(w, "4", t=1.05)
    up(w, "4", t=1.1)
    assert_same(w, reference(w, [("4", False, 1000.0, 1100.0)]))


def test_a_long_hold_keeps_a_bounded_window_of_steps_and_ends_on_the_page_s_state(make, clock):
    """Steps the page said it made more than SETTLED_MS ago are done (a rolling checkpoint): each
    heartbeat costs the same however long the hold, and the end state is still the page's."""
    from rot4d_widget.view.pagesteps import ROLL_STEPS

    w = make("24-cell")
    down(w, "8", t=1.0)
    kept = 0
    for t in range(1000, 21000, 33):  # 20 s of heartbeats
        heartbeat(w, float(t))
        kept = max(kept, len(w._keys.page._applied))
    up(w, "8", t=20.99)
    assert kept <= ROLL_STEPS + 2
    assert_same(w, reference(w, [("8", False, 1000.0, 20990.0)]))
    assert_replays(w, make)
