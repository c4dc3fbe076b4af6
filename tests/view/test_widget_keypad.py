"""The on-screen key pad (issue 12), without a browser: the ipyevents dicts of its buttons fed in.

A click is one step; a button held repeats exactly like the key it stands for (same hold delay,
tick rate and steps), and stops on release, on leaving the button or on a touch's end.  The
real browser (mouse and touch) is tests/browser/test_keypad_browser.py.
"""

from __future__ import annotations

import numpy as np
import pytest

from rot4d_widget import simple_rotation
from test_widget import down, up
from test_widget_scene import run_ticker

pytestmark = pytest.mark.usefixtures("recording_comms")


def _button(w, label):
    for row in w._keypad.box.children:
        for b in row.children[1:]:
            if b.description == label:
                return b
    raise AssertionError(f"no key pad button {label!r}: {[b.description for r in w._keypad.box.children for b in r.children[1:]]}")


def pad(w, key, kind, shift=False, **extra):
    w._keypad.handle(key, shift, {"type": kind, "button": 0, **extra})


def test_off_by_default_on_by_keyword_or_trait(make):
    w = make("5-cell")
    assert w.keypad is False and w._keypad.box is None
    w.keypad = True
    assert w._keypad.box is not None and w._keypad.box in w._canvas_box.children and w._keypad.box.layout.display is None
    labels = [b.description for row in w._keypad.box.children for b in row.children[1:]]
    for want in ("R_xy", "R_zw", "R_xy\u207b\u00b9", "R_xw,yz", "R_xz,yw\u207b\u00b9", "\u03b1+", "c0\u2212",
                 "\u03b80+", "reset"):
        assert want in labels, labels
    assert "Shift+4" in _button(w, "R_xw\u207b\u00b9").tooltip
    w.keypad = False
    assert w._keypad.box.layout.display == "none"
    assert make("5-cell", keypad=True)._keypad.box is not None
    with pytest.raises(TypeError, match="keypad"):
        make("5-cell", keypad="yes")


def test_a_click_is_one_step_and_shift_buttons_invert(make):
    w = make("5-cell", keypad=True)
    t = w.state.theta0
    pad(w, "4", "mousedown")
    pad(w, "4", "mouseup")
    np.testing.assert_allclose(w.state.matrix, simple_rotation("xw", t), atol=1e-12)
    pad(w, "4", "mousedown", shift=True)
    pad(w, "4", "mouseup", shift=True)
    np.testing.assert_allclose(w.state.matrix, np.eye(4), atol=1e-12)
    pad(w, "l", "mousedown")
    pad(w, "l", "mouseup")
    assert w.state.c0 == pytest.approx(w.state.c0_step)
    pad(w, "r", "mousedown")
    pad(w, "r", "mouseup")
    assert w.state.c0 == 0
    pad(w, "4", "mousedown", button=2)  # a right click: nothing
    assert w.held_keys == () and np.allclose(w.state.matrix, np.eye(4))


@pytest.mark.parametrize("release", ["mouseup", "mouseleave"])
def test_a_held_button_repeats_exactly_like_the_held_key(make, clock, release):
    ck, cp = clock, type(clock)(clock.t)  # two fake clocks, one per widget
    by_key = make("24-cell", _clock=ck)
    by_pad = make("24-cell", _clock=cp, keypad=True)
    down(by_key, "8")
    pad(by_pad, "8", "mousedown")
    assert by_pad.held_keys == ("pad:8",)
    end = ck.t + by_key.hold_delay + 0.5
    run_ticker(by_key, ck, end)
    run_ticker(by_pad, cp, end)
    up(by_key, "8")
    pad(by_pad, "8", release)
    run_ticker(by_key, ck, end + 1.0)
    run_ticker(by_pad, cp, end + 1.0)  # released: no more steps
    assert by_pad.held_keys == ()
    m = by_pad.state.matrix
    steps = round(np.arctan2(m[3, 1], m[1, 1]) / by_pad.state.theta0)
    assert steps >= 1 + int(0.5 * by_pad.tick_rate) - 1, steps  # repeated after the hold delay
    np.testing.assert_allclose(m, by_key.state.matrix, atol=1e-12)


def test_a_touch_presses_once_and_its_end_releases(make, clock):
    w = make("5-cell", keypad=True)
    pad(w, "c", "touchstart")
    pad(w, "c", "mousedown")  # a browser's emulated mouse event after the touch: ignored
    np.testing.assert_allclose(w.state.matrix, simple_rotation("zw", w.state.theta0), atol=1e-12)
    assert w.held_keys == ("pad:c",)
    pad(w, "c", "touchcancel")
    assert w.held_keys == ()


def test_hiding_the_pad_releases_its_buttons_and_bad_events_are_harmless(make):
    w = make("5-cell", keypad=True)
    pad(w, "2", "mousedown")
    assert w.held_keys == ("pad:2",)
    w.keypad = False
    assert w.held_keys == ()
    w._keypad.handle("2", False, None)
    w._keypad.handle("2", False, {"type": "wheel"})
    assert w.errors.outputs == ()


def test_hiding_the_pad_releases_its_buttons_even_when_the_layout_s_send_fails(make, monkeypatch):
    """The soak (issue 33, seed 1): a pad button held while the pad was hidden during a comm failure
    stayed held for ever (the layout's send raised before the release)."""
    w = make("5-cell", keypad=True)
    pad(w, "z", "mousedown", shift=True)
    assert w.held_keys == ("pad:z+shift",)

    def fail(*args, **kwargs):
        raise ConnectionError("injected: the comm is down")

    monkeypatch.setattr(w._keypad.box.layout.comm, "send", fail)
    with pytest.raises(ConnectionError):
        w.keypad = False
    assert w.held_keys == ()
