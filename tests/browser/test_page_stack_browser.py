"""A 12-slice oval of the 24-cell turned by a held key: the page draws its own pictures (issue 34).

The page holds the 24-cell (the one-time transfer) and the stack's layout (``draw_config``): while
a key is held it cuts and draws the stack of its own state (``page/stack.js``), frame after frame,
and the kernel makes no picture (its pump sends no update).  At the release the kernel's slice is
made slow for a moment (the stack's ``slice`` wrapped in the notebook: still a `StackSource`), so
the page's own picture of the final state stays up long enough to be photographed; then the
kernel's picture of that state comes, and the canvas does not change: the page's rows of the
final state equal the kernel's and the two screenshots agree.
"""

from __future__ import annotations

import time

import numpy as np
import pytest
from jupyter_page import JupyterPage, write_notebook
from test_page_pictures_browser import _pixels
from test_widget_browser import _canvas, _hover

pytestmark = pytest.mark.browser

CELLS = [
    """\
import time
from rot4d_widget import Rot4DWidget

w = Rot4DWidget('24-cell', slices=12, arrangement='oval', width=480, height=400)
delay = [0.0]  # seconds each kernel picture takes (set at the release)
fast = w.source.slice


def slow(matrix, c0):
    time.sleep(delay[0])
    return fast(matrix, c0)


w.source.slice = slow
w""",
]


def _page(jp, sel, rows=False):
    host = sel.rsplit(" canvas", 1)[0]
    return jp.page.evaluate(f"(rows) => document.querySelector({host!r}).rot4dPage(rows)", rows)


def _shot(jp, sel, path):
    jp.page.locator(sel).screenshot(path=str(path))
    from PIL import Image

    return np.asarray(Image.open(path).convert("RGB"), dtype=int)


def test_a_held_key_turns_a_12_slice_oval_in_the_page(jupyter_server, page):
    _held_oval(jupyter_server, page)


@pytest.mark.remote
def test_a_held_key_turns_a_12_slice_oval_on_a_remote_kernel(remote_server, page):
    """The same through a proxy delaying every byte (a kernel `REMOTE_RTT_MS` away)."""
    _held_oval(remote_server, page)


def _held_oval(jupyter_server, page):
    if jupyter_server.kind != "lab":
        pytest.skip("JupyterLab only: the page's pictures are the same code in Notebook 7 (test_page_turns runs there)")
    write_notebook(jupyter_server.root / "page_stack.ipynb", CELLS)
    jp = JupyterPage(page, jupyter_server, "page_stack.ipynb").open()
    jp.run_all()
    sel = _canvas(jp)
    jp.page.locator(sel).scroll_into_view_if_needed()
    _hover(jp, sel)
    assert jp.wait_for(lambda: jp.kernel_json("w.companion.page_cut.page_draws"), timeout=30), \
        "the page never said it holds the 24-cell"
    jp.watch_pixels(sel)
    before = jp.kernel_json("w.stats.as_dict()")
    built = _page(jp, sel)["own"]["built"]
    t0 = jp.page_now()
    jp.page.keyboard.down("4")
    time.sleep(1.5)
    held = jp.kernel_json("w.stats.as_dict()")
    during = _page(jp, sel)
    frames = len(jp.pixel_changes(t0))
    # the page drew the held key's pictures itself; the kernel sent none
    assert held["updates"] == before["updates"], (before, held)
    assert during["own"]["built"] - built >= 10 and frames >= 10, (during["own"], frames)

    rtt = f"{getattr(jupyter_server, 'rtt_ms', 0):g}"  # the local and remote runs share the server's folder
    shots = [jupyter_server.root / f"stack-{n}-{rtt}.png" for n in ("page", "kernel")]
    jp.kernel("delay[0] = 1.5")  # the kernel's picture of the final state comes 1.5 s late
    jp.page.keyboard.up("4")
    up = jp.wait_for(lambda: jp.key_stamps("keyup", "Digit4"), timeout=5)[-1]
    time.sleep(0.5)
    mine = _page(jp, sel, rows=True)
    assert not mine["held"] and mine["own"]["version"] == mine["version"], mine["own"]  # its final state's
    page_px = _shot(jp, sel, shots[0])
    changes_then = jp.pixel_changes(up)
    # the kernel catches up: its state, then its picture drawn (acknowledged)
    assert jp.wait_for(lambda: (k := jp.kernel_json(
        "dict(sid=list(w._keys.page.state_id), pic=w.companion.kernel_state.get('picture'), busy=w.in_flight)"))
        and isinstance(k["pic"], int) and not k["busy"] and _page(jp, sel)["upto"] == k["sid"][1], timeout=30)
    time.sleep(0.5)
    kernel_px = _shot(jp, sel, shots[1])
    after = jp.kernel_json("w.stats.as_dict()")
    state = _page(jp, sel)
    kernel = jp.kernel_json("dict(m=w.state.matrix.reshape(-1).tolist(), c0=w.state.c0, "
                            "rows=w.scene.rows[:max(w.scene.counts)].reshape(-1).tolist(), counts=list(w.scene.counts))")
    np.testing.assert_allclose(state["matrix"], kernel["m"], rtol=0, atol=1e-12)
    np.testing.assert_allclose(mine["matrix"], kernel["m"], rtol=0, atol=1e-12)  # no jump: the same state
    # the page's own rows of the final state are the kernel's
    assert mine["own"]["counts"] == kernel["counts"]
    ours = np.asarray(mine["own"]["rows"], dtype=np.float32)
    theirs = np.asarray(kernel["rows"], dtype=np.float32)
    differ = int((ours.view(np.uint32) != theirs.view(np.uint32)).sum())
    late = jp.pixel_changes(up)
    diff = np.abs(page_px - kernel_px).max(axis=2)
    print(f"12-slice oval, round trip {rtt} ms: {during['own']['built'] - built} own pictures and {frames} changed frames in 1.5 s held, "
          f"kernel updates {before['updates']} -> {held['updates']} held -> {after['updates']} after; "
          f"final rows {ours.size} floats, {differ} differ; pixels over 2/255: {int((diff > 2).sum())} of {diff.size}; "
          f"changed frames after keyup: {len(changes_then)} before the kernel's picture, {len(late)} in all; "
          f"screenshots {shots[0]}, {shots[1]}")
    assert differ == 0 or np.allclose(ours, theirs, rtol=1e-6, atol=1e-6)
    assert after["updates"] >= held["updates"] + 1  # the picture the keys rest on
    assert (diff <= 2).mean() >= 0.995, "the kernel's picture of the final state differs from the page's"
    assert len(late) == len(changes_then), "the canvas changed when the kernel's picture came"


#: label -> the widget's source: stacks in the other arrangements, coloured by cell
AT_REST = {"8-cell, 5-slice grid by cell": "StackSource('8-cell', slices=5, arrangement='grid', color_by='cell')",
           "600-cell, 2-slice stack by cell": "StackSource('600-cell', slices=2, arrangement='stack', color_by='cell')"}


def test_the_page_s_picture_of_a_stack_at_rest_is_the_kernel_s(jupyter_server, page, artifacts):
    """As test_page_pictures_browser for single polytopes: a turned state at rest, the kernel's
    picture read back, then the page's own rows of it (``rot4dForceOwn``): the same pixels."""
    if jupyter_server.kind != "lab":
        pytest.skip("JupyterLab only: the page's pictures are the same code in Notebook 7")
    cells = ["from rot4d_widget import Rot4DWidget, StackSource\nws = {}"]
    cells += [f"ws[{name!r}] = Rot4DWidget({args}, width=320, height=260)\nws[{name!r}]"
              for name, args in AT_REST.items()]
    write_notebook(jupyter_server.root / "page_stack_rest.ipynb", cells)
    jp = JupyterPage(page, jupyter_server, "page_stack_rest.ipynb").open()
    jp.run_all()
    worst = {}
    for name in AT_REST:
        jp.kernel(f"w = ws[{name!r}]")
        sel = _canvas(jp, "w")
        host = sel.rsplit(" canvas", 1)[0]
        jp.page.locator(sel).scroll_into_view_if_needed()
        _hover(jp, sel)
        for key in ("4", "y", "l"):  # a turned state, off the centre
            jp.page.keyboard.press(key)
        assert jp.wait_for(lambda: jp.page.evaluate(f"() => document.querySelector({host!r}).rot4dDrawsOwn()")
                           is False, timeout=30), f"{name}: the kernel's picture never came"
        jp.page.mouse.move(2, 2)  # the pointer away: nothing hovered
        kernel = _pixels(jp, sel)
        jp.page.evaluate(f"() => document.querySelector({host!r}).rot4dForceOwn(true)")
        assert jp.wait_for(lambda: jp.page.evaluate(f"() => document.querySelector({host!r}).rot4dDrawsOwn()"),
                           timeout=10), f"{name}: the page does not hold the polytope"
        own = _pixels(jp, sel)
        label = name.replace(", ", "-").replace(" ", "-")
        jp.page.locator(sel).screenshot(path=str(artifacts / f"page-own-{label}-{jupyter_server.kind}.png"))
        jp.page.evaluate(f"() => document.querySelector({host!r}).rot4dForceOwn(false)")
        diff = np.abs(own - kernel).max(axis=1)
        worst[name] = (int(diff.max()), float((diff <= 2).mean()))
        assert (diff <= 2).mean() >= 0.995, (name, worst[name])
        assert (kernel != kernel[0]).any(axis=1).sum() > 500, f"{name}: nothing drawn"
    print("stack at rest, page vs kernel, worst channel difference and share within 2/255:", worst)
