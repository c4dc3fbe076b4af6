"""The on-screen key pad (issue 12) in the real browser, with a mouse and with touch.

A click or a tap is one step; a button held down (mouse button, or a touch held through CDP's
``Input.dispatchTouchEvent``: Playwright itself only taps) repeats like a held key and stops on
release, on a touch's end and when the pointer leaves the button.
"""

from __future__ import annotations

import math
import re
import time

import pytest

from jupyter_page import JupyterPage, write_notebook
from test_widget_browser import _bad_console, _canvas, _state

# a small step: the steps counted from the x-w angle stay below half a turn
CELL = """\
import math
from rot4d_widget import Rot4DWidget
w = Rot4DWidget('24-cell', keypad=True, theta0=math.pi / 512)
w"""


def _xw_steps(jp):
    s = _state(jp)
    m = s["m"]
    return round(math.atan2(m[3][0], m[0][0]) / s["theta0"])


def _button(page, label):
    return page.locator("button.rot4d-pad-button").filter(has_text=re.compile(f"^{re.escape(label)}$"))


def _centre(locator):
    box = locator.bounding_box()
    return box["x"] + box["width"] / 2, box["y"] + box["height"] / 2


def _settled_steps(jp, timeout=10.0):
    """Steps once nothing is held and the count stopped changing (the kernel catches up)."""
    deadline = time.monotonic() + timeout
    last = None
    while time.monotonic() < deadline:
        held = jp.kernel_json("len(w.held_keys)")
        now = _xw_steps(jp)
        if held == 0 and now == last:
            return now
        last = now
        time.sleep(0.3)
    raise AssertionError(f"still stepping after {timeout} s: {last}")


def test_keypad_with_mouse_and_touch(jupyter_server, page, artifacts):
    if jupyter_server.kind == "notebook":
        pytest.skip("JupyterLab only: the pad is ipywidgets buttons with ipyevents, the same in Notebook 7")
    write_notebook(jupyter_server.root / "pad.ipynb", [CELL])
    jp = JupyterPage(page, jupyter_server, "pad.ipynb").open()
    jp.run_all(timeout=300)
    _canvas(jp)
    b = _button(page, "R_xw")
    b.wait_for(timeout=30_000)
    b.scroll_into_view_if_needed()

    # 1. a click: one step
    b.click()
    assert jp.wait_for(lambda: _xw_steps(jp) == 1, timeout=10), _xw_steps(jp)
    assert _settled_steps(jp) == 1

    # 2. the mouse button held: repeats, stops on release
    x, y = _centre(b)
    page.mouse.move(x, y)
    page.mouse.down()
    time.sleep(1.5)
    page.mouse.up()
    held = _settled_steps(jp)
    assert held >= 1 + 5, f"{held - 1} steps while held 1.5 s"
    time.sleep(0.5)
    assert _xw_steps(jp) == held  # nothing after the release

    # 3. held, then the pointer leaves the button: stops
    page.mouse.move(x, y)
    page.mouse.down()
    time.sleep(1.0)
    page.mouse.move(x, y + 300)
    left = _settled_steps(jp)
    page.mouse.up()
    assert left > held
    time.sleep(0.5)
    assert _xw_steps(jp) == left

    # 4. touch: a tap is one step (no second step from the emulated mouse events)
    inverse = _button(page, "R_xw\u207b\u00b9")
    tx, ty = _centre(inverse)
    cdp = page.context.new_cdp_session(page)
    cdp.send("Emulation.setTouchEmulationEnabled", {"enabled": True, "maxTouchPoints": 1})
    cdp.send("Input.dispatchTouchEvent", {"type": "touchStart", "touchPoints": [{"x": tx, "y": ty}]})
    cdp.send("Input.dispatchTouchEvent", {"type": "touchEnd", "touchPoints": []})
    assert jp.wait_for(lambda: _xw_steps(jp) == left - 1, timeout=10), (_xw_steps(jp), left)
    assert _settled_steps(jp) == left - 1

    # 5. a touch held: repeats, stops at its end
    cdp.send("Input.dispatchTouchEvent", {"type": "touchStart", "touchPoints": [{"x": tx, "y": ty}]})
    time.sleep(1.5)
    cdp.send("Input.dispatchTouchEvent", {"type": "touchEnd", "touchPoints": []})
    touched = _settled_steps(jp)
    assert touched <= left - 1 - 5, (touched, left)
    time.sleep(0.5)
    assert _xw_steps(jp) == touched
    cdp.send("Emulation.setTouchEmulationEnabled", {"enabled": False})
    # the page stepped the pad's keys itself (issue 34) and ends on the kernel's state
    # (the kernel's id moves on with the last page time it heard, a touch's end a few ms after the
    # last step: the page adopts that id a moment later, so the two are compared once they agree)
    cls = jp.kernel("print(w.scene.canvas_class)").strip()

    def agreed():
        pg = page.evaluate(f"() => document.querySelector('.{cls}').rot4dPage()")
        sid = jp.kernel_json("list(w._keys.page.state_id)")
        return (pg, sid) if pg and [pg["epoch"], pg["upto"]] == sid else None

    found = jp.wait_for(agreed, timeout=10)
    assert found, (page.evaluate(f"() => document.querySelector('.{cls}').rot4dPage()"),
                   jp.kernel_json("list(w._keys.page.state_id)"))
    pg, sid = found
    k = jp.kernel_json("w.state.matrix.reshape(-1).tolist()")
    assert max(abs(a - b) for a, b in zip(pg["matrix"], k)) <= 1e-12, (pg, k)
    assert sid[0] == 0  # every step of the pad was the page's: no change started in the kernel
    page.locator(".rot4d-keypad").screenshot(path=str(artifacts / "keypad.png"))
    assert not _bad_console(page), _bad_console(page)
    assert jp.kernel_json("len(w.errors.outputs)") == 0
