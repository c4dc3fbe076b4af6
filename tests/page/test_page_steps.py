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
from rot4d_widget.view.keys import key_id
from test_widget import down, key_event, up
from test_widget_scene import run_ticker

pytestmark = pytest.mark.usefixtures("recording_comms")


def heartbeat(w, t_ms, edges=None):
    """The companion's ``clock`` message; ``edges``: the page's key events it repeats (`edge`)."""
    content = {"event": "clock", "t": t_ms}
    if edges is not None:
        content["edges"] = edges
    w.companion.comm.handler({"content": {"data": {"method": "custom", "content": content}}, "buffers": []})


def edge(key, is_down, t_ms, shift=False):
    """A key event as the page repeats it with its heartbeats (``page/turning.js``)."""
    ev = key_event("keydown", key, shift=shift)
    out = {"kid": key_id(ev), "down": is_down, "t": t_ms}
    if is_down:
        out.update(key=ev["key"], code=ev["code"], shift=shift)
    return out


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


def test_key_events_that_come_with_the_heartbeats_before_ipyevents_forwards_them_count_once(make, clock):
    """A busy kernel (JupyterLab 4.4+ on ipykernel 7): the companion's messages are handled on a
    subshell while ipyevents' wait for the cell to end.  The heartbeats carry the page's key events,
    so the kernel releases the key when the page did, however long the heartbeats go on after it
    (past the rolling checkpoint's `SETTLED_MS`), and ipyevents' events, when they come, are heard
    already: the state is the page's, bit for bit."""
    w = make("24-cell")
    pressed = [edge("4", True, 1000.0)]
    for t in range(1000, 2500, 33):  # held 1.5 s: ipyevents' keydown not handled yet
        heartbeat(w, float(t), pressed)
    events = pressed + [edge("4", False, 2500.0)]
    for t in range(2500, 6000, 33):  # released; the page's clock goes on 3.5 s (it sends the events)
        heartbeat(w, float(t), events)
    assert w.held_keys == ()
    ref = reference(w, [("4", False, 1000.0, 2500.0)])
    assert_same(w, ref)
    down(w, "4", t=1.0)  # the cell ended: ipyevents' events, heard already
    up(w, "4", t=2.5)
    assert_same(w, ref)
    assert w.held_keys == ()
    assert_replays(w, make)


def test_a_key_pressed_again_before_ipyevents_forwards_its_release_stays_held(make, clock):
    """The heartbeats bring press, release and a second press of one key; ipyevents' late release
    of the first press is older than the second press: heard already, the key stays down."""
    w = make("5-cell")
    events = [edge("c", True, 1000.0), edge("c", False, 1100.0), edge("c", True, 1500.0)]
    heartbeat(w, 1500.0, events)
    down(w, "c", t=1.0)
    up(w, "c", t=1.1)
    assert w.held_keys == (key_id(key_event("keydown", "c")),)
    heartbeat(w, 1900.0, [])
    up(w, "c", t=1.9)
    assert w.held_keys == ()
    assert_same(w, reference(w, [("c", False, 1000.0, 1100.0), ("c", False, 1500.0, 1900.0)]))


def test_a_keyup_stamped_a_moment_before_its_keydown_is_a_tap_not_a_stuck_key(make, clock):
    """A page whose stamps jitter (the soak's, seed 20240: keyup 0.28 ms before its keydown): the
    release is the press's own, never one heard already -- one step, nothing held.  Compared with
    the last press, as before, it was taken for an old release and the key stayed held for good."""
    w = make("5-cell")
    down(w, "2", t=368.48166)
    up(w, "2", t=368.48138)
    assert w.held_keys == ()
    heartbeat(w, 369000.0, [])
    assert_same(w, reference(w, [("2", False, 368481.66, 368481.66)]))
    down(w, "2", t=369.5)  # the key works again
    up(w, "2", t=369.55)
    assert w.held_keys == ()


def test_ipyevents_first_then_the_same_events_with_the_heartbeats(make, clock):
    """The usual order (ipyevents' event handled first): the heartbeat's copy changes nothing."""
    w = make("24-cell")
    down(w, "y", shift=True, t=2.0)
    heartbeat(w, 2300.0, [edge("y", True, 2000.0, shift=True)])
    up(w, "y", shift=True, t=2.4)
    heartbeat(w, 2400.0, [edge("y", True, 2000.0, shift=True), edge("y", False, 2400.0)])
    heartbeat(w, 2900.0, [edge("y", True, 2000.0, shift=True), edge("y", False, 2400.0)])
    assert_same(w, reference(w, [("y", True, 2000.0, 2400.0)]))
    assert_replays(w, make)


@pytest.mark.parametrize("bad", [
    None, 3, "edge", [], {"kid": 4, "down": True, "t": 1.0}, {"kid": "Digit4", "down": 1, "t": 1.0},
    {"kid": "Digit4", "down": True, "t": float("nan")}, {"kid": "Digit4", "down": True, "t": True},
    {"kid": "x" * 65, "down": True, "t": 1.0}, {"kid": "", "down": False, "t": 1.0},
    {"kid": "Digit4", "down": True, "t": 1000.0, "key": "4", "code": "Digit8"},  # kid not the event's
    {"kid": "pad:4", "down": True, "t": 1000.0, "key": "8", "pad": True},  # pad id not the key's
    {"kid": "KeyQ", "down": True, "t": 1000.0, "key": "q", "code": "KeyQ"},  # not bound
    {"kid": "KeyP", "down": True, "t": 1000.0, "key": "p", "code": "KeyP"},  # bound, not the page's kind
])
def test_a_malformed_or_foreign_key_event_in_a_heartbeat_is_left_out(make, clock, bad):
    w = make("5-cell")
    before = w.state.matrix.copy()
    heartbeat(w, 1200.0, [bad])
    heartbeat(w, 1300.0, bad)  # not even a list
    assert w.held_keys == () and np.array_equal(w.state.matrix, before)
    assert w.errors.outputs == ()  # left out, not an error: the page sends only what it stepped


def test_a_pad_button_held_in_the_heartbeats_steps_as_the_page_does(make, clock):
    w = make("24-cell")
    pad = [{"kid": "pad:8+shift", "down": True, "t": 1000.0, "key": "8", "shift": True, "pad": True}]
    for t in range(1000, 1600, 33):
        heartbeat(w, float(t), pad)
    heartbeat(w, 1700.0, pad + [{"kid": "pad:8+shift", "down": False, "t": 1600.0}])
    assert w.held_keys == ()
    assert_same(w, reference(w, [("8", True, 1000.0, 1600.0)]))


def test_the_kernel_s_state_names_the_keys_it_holds(make, clock):
    """``kernel_state["keys"]``: the page's keys the state holds as held, with their press times --
    what the page checks it against (``Prediction.agrees``)."""
    w = make("24-cell")
    down(w, "4", t=1.0)
    heartbeat(w, 1400.0)
    assert w.companion.kernel_state["keys"] == [["Digit4", 1000.0]]
    up(w, "4", t=1.5)
    assert w.companion.kernel_state["keys"] == [] and w.companion.kernel_state["upto"] == 1500.0


def test_the_kernel_s_id_moved_on_without_a_step_reaches_the_page(make, clock):
    """A heartbeat heard after the last step (at rest) names the same state by a later page time:
    the page is told, the picture named as before (CI once saw the page rest on the older id for a
    minute, waiting for a change that never came), and never for a state the picture does not show."""
    w = make("24-cell")
    down(w, "4", t=1.0)
    up(w, "4", t=1.1)
    before = dict(w.companion.kernel_state)
    assert before["upto"] == 1100.0
    clock.t += 1.0
    heartbeat(w, 1100.4)
    after = w.companion.kernel_state
    assert after["upto"] == 1100.4 and after["epoch"] == before["epoch"]
    assert after["state"] == before["state"] and after["picture"] == before["picture"]
    # a change from the kernel not drawn yet: the id is not sent with the old picture's name
    w.state.apply(*DEFAULT_KEYMAP.resolve("2", False))
    heartbeat(w, 1100.8)
    assert w.companion.kernel_state["upto"] == 1100.4


def test_a_step_the_page_made_counts_while_the_kernel_has_heard_of_no_view(make, clock):
    """The page steps only for a key over a canvas of this widget it shows, so the steps its
    heartbeats repeat are kept whatever view count the kernel last heard (the canvas's count comes
    on another comm, which may be handled after the companion's): none dropped that the page has
    shown.  ipyevents' own keydown from a leaked listener still acts on nothing."""
    from test_widget import front_end_view_count, xw_steps
    w = make("24-cell")
    front_end_view_count(w, 1)  # displayed
    front_end_view_count(w, 0)  # the kernel hears of no view (a view re-made: its count comes late)
    down(w, "4", t=1.0)  # ipyevents: a listener a destroyed view may have left behind
    up(w, "4", t=1.05)
    assert xw_steps(w) == 0
    heartbeat(w, 2000.0, [edge("4", True, 2000.0)])  # the page stepped a key over its canvas
    heartbeat(w, 2050.0, [edge("4", True, 2000.0), edge("4", False, 2050.0)])
    assert xw_steps(w) == 1 and w.held_keys == ()
    assert w.companion.kernel_state["upto"] == 2050.0


ADOPT = """
import { Prediction } from "page:predict.js";
const p = new Prediction(INPUT.config, INPUT.start);
const mine = p.ours({ key: "4", code: "Digit4", shiftKey: false }, "Digit4");
const out = [];
let now = -Infinity;
for (const [what, arg] of INPUT.script) {
  if (what === "press") p.press("Digit4", mine.action, mine.inverted, (now = arg));
  else if (what === "release") p.release("Digit4", (now = arg));
  else if (what === "advance") p.advance((now = arg));
  else out.push({ adopted: p.adopt(arg), matrix: (p.advance(now), Array.from(p.state.matrix)) });
}
console.log(JSON.stringify(out));
"""


def test_the_page_keeps_its_own_steps_over_a_kernel_state_its_keys_say_is_wrong(make, clock):
    """The kernel went on by its estimate of a silent page past the page's keyup (ipyevents' way
    held up): its state holds the key the page released.  The page keeps its own steps
    (``Prediction.agrees``), and adopts the kernel's state once the kernel has the keyup -- the
    same state.  A state that lacks a key the page pressed by its time is not adopted either."""
    from page_node import run_page

    w = make("24-cell")
    start = dict(w.companion.kernel_state)
    down(w, "4", t=1.0)
    heartbeat(w, 1100.0)
    held = dict(w.companion.kernel_state)
    run_ticker(w, clock, clock.t + 1.5)  # the page silent: the kernel's estimate goes on
    ahead = dict(w.companion.kernel_state)
    assert ahead["keys"] == [["Digit4", 1000.0]] and ahead["upto"] > 1400.0
    up(w, "4", t=1.4)
    final = dict(w.companion.kernel_state)
    assert final["keys"] == [] and final["upto"] >= 1400.0
    ref = reference(w, [("4", False, 1000.0, 1400.0)])
    lacking = dict(held, upto=1200.0, keys=[])  # past the page's press without it
    script = [["press", 1000.0], ["advance", 1100.0], ["adopt", held], ["adopt", lacking],
              ["release", 1400.0], ["advance", 1400.0], ["adopt", ahead], ["adopt", final]]
    page = run_page(ADOPT, {"config": w.companion.config, "start": start, "script": script})
    assert [r["adopted"] for r in page] == [True, False, False, True]
    matrices = [np.array(r["matrix"]).reshape(4, 4) for r in page]
    assert np.allclose(matrices[1], reference(w, [("4", False, 1000.0, 1100.0)]).matrix, atol=1e-12)
    assert np.allclose(matrices[2], ref.matrix, atol=1e-12)  # its own steps, not the kernel's 40-odd
    assert not np.allclose(np.array(ahead["state"]["matrix"]).reshape(4, 4), ref.matrix, atol=1e-6)
    assert np.array_equal(matrices[3], ref.matrix)  # the kernel's, adopted: exact


REMADE = """
import { Prediction } from "page:predict.js";
const first = new Prediction(INPUT.config, INPUT.start);
const mine = first.ours({ key: "4", code: "Digit4", shiftKey: false }, "Digit4");
first.press("Digit4", mine.action, mine.inverted, 1000.0);
first.advance(1300.0);
// the key table changes while "4" is held (a field's keys become the page's when it holds its copy)
const next = new Prediction(INPUT.changed, INPUT.start, first);
next.advance(1600.0);
console.log(JSON.stringify({ held: next.held, matrix: Array.from(next.state.matrix) }));
"""


def test_a_key_held_when_the_page_s_key_table_changes_goes_on_stepping(make, clock):
    """The page remakes its prediction when the key table changes -- a field's view keys become
    the page's once it holds its copy, often while a key is held (the user turned as soon as the
    picture showed).  The keys held go on: the page's "4" steps to 1600 ms as the kernel's does.
    Before, the new prediction forgot them, the page stopped stepping and drew only the kernel's
    states as they arrived (a 2 GB store: 5 pictures a second instead of 15,
    benchmarks/store_timeline.py)."""
    from page_node import run_page

    w = make("24-cell")
    start = dict(w.companion.kernel_state)
    config = w.companion.config
    changed = dict(config, predicted_kinds=sorted(set(config["predicted_kinds"]) | {"rendering"}))
    page = run_page(REMADE, {"config": config, "changed": changed, "start": start})
    assert page["held"] == ["Digit4"]
    ref = reference(w, [("4", False, 1000.0, 1600.0)])
    assert np.allclose(np.array(page["matrix"]).reshape(4, 4), ref.matrix, atol=1e-12)
