"""The page's own picture of a state and the kernel's are the same picture (issue 34), in
JupyterLab 4 and Notebook 7.

While it is ahead of the kernel the page draws the slice of its predicted state itself; at rest it
shows the kernel's.  For each case the view is turned to a state, left to rest (the kernel's
picture), read back, then drawn from the page's own rows of the same state (the canvas's
``rot4dForceOwn`` test hook) and read back again: at most 2/255 per channel on at least 99.5 % of
the pixels (the issue's bound; the rows are equal bit for bit, so the pictures are expected to be
identical).  A screenshot of each pair is kept in test-artifacts/.
"""

from __future__ import annotations

import time

import numpy as np
import pytest

from jupyter_page import JupyterPage, write_notebook
from test_widget_browser import _canvas, _hover

pytestmark = pytest.mark.browser

CASES = ["5-cell", "8-cell", "16-cell", "24-cell", "120-cell", "600-cell", "omnitruncated 120-cell"]

def _pixels(jp, sel):
    time.sleep(0.4)  # a few frames drawn
    return jp.canvas_rgba(sel).reshape(-1, 4)[:, :3].astype(np.int16)


def _host(sel):
    return sel.rsplit(" canvas", 1)[0]


def test_the_page_s_picture_of_a_state_is_the_kernel_s(jupyter_server, page, artifacts):
    cells = ["from rot4d_widget import Rot4DWidget\nws = {}"]
    cells += [f"ws[{name!r}] = Rot4DWidget({name!r}, width=320, height=260)\nws[{name!r}]" for name in CASES]
    write_notebook(jupyter_server.root / "page_pictures.ipynb", cells)
    jp = JupyterPage(page, jupyter_server, "page_pictures.ipynb").open()
    jp.run_all()
    worst = {}
    for name in CASES:
        jp.kernel(f"w = ws[{name!r}]")
        sel = _canvas(jp, "w")
        jp.page.locator(sel).scroll_into_view_if_needed()
        _hover(jp, sel)
        for key in ("4", "y", "l"):  # a turned state, off the centre
            jp.page.keyboard.press(key)
        assert jp.wait_for(lambda: jp.page.evaluate(f"() => document.querySelector({_host(sel)!r}).rot4dDrawsOwn()")
                           is False, timeout=30), f"{name}: the kernel's picture never came"
        jp.page.mouse.move(2, 2)  # the pointer away: nothing hovered
        kernel = _pixels(jp, sel)
        jp.page.evaluate(f"() => document.querySelector({_host(sel)!r}).rot4dForceOwn(true)")
        assert jp.wait_for(lambda: jp.page.evaluate(f"() => document.querySelector({_host(sel)!r}).rot4dDrawsOwn()"),
                           timeout=10), f"{name}: the page does not hold the polytope"
        own = _pixels(jp, sel)
        jp.page.locator(sel).screenshot(path=str(artifacts / f"page-own-{name.replace(' ', '-')}-{jupyter_server.kind}.png"))
        jp.page.evaluate(f"() => document.querySelector({_host(sel)!r}).rot4dForceOwn(false)")
        diff = np.abs(own - kernel).max(axis=1)
        worst[name] = (int(diff.max()), float((diff <= 2).mean()))
        assert (diff <= 2).mean() >= 0.995, (name, worst[name])
        assert (kernel != kernel[0]).any(axis=1).sum() > 500, f"{name}: nothing drawn"
    print("page vs kernel, worst channel difference and share within 2/255:", worst)


def test_a_star_polychoron_turns_as_balls_and_bars_and_rests_on_the_kernel_s_fills(jupyter_server, page, artifacts):
    """A star polychoron's fills are the kernel's: while keys are held the page draws the balls and
    bars of its own state (never fills of another state), at rest the kernel's whole picture."""
    if jupyter_server.kind != "lab":
        pytest.skip("JupyterLab only: the same page code in Notebook 7 (the test above runs there)")
    name = "great grand stellated 120-cell"
    write_notebook(jupyter_server.root / "page_star.ipynb",
                   [f"from rot4d_widget import Rot4DWidget\nw = Rot4DWidget({name!r}, width=320, height=260)\nw"])
    jp = JupyterPage(page, jupyter_server, "page_star.ipynb").open()
    jp.run_all()
    sel = _canvas(jp, "w")
    host = _host(sel)
    assert jp.wait_for(lambda: jp.kernel_json("w.companion.page_cut.page_draws"), timeout=60), "the page never held it"
    _hover(jp, sel)
    jp.page.keyboard.down("4")
    time.sleep(0.6)
    assert jp.page.evaluate(f"() => document.querySelector({host!r}).rot4dDrawsOwn()")
    jp.page.locator(sel).screenshot(path=str(artifacts / "page-star-held.png"))
    held = jp.page.evaluate(f"() => document.querySelector({host!r}).rot4dCounts()")
    jp.page.keyboard.up("4")
    assert jp.wait_for(lambda: jp.page.evaluate(f"() => document.querySelector({host!r}).rot4dDrawsOwn()") is False,
                       timeout=60)
    jp.page.mouse.move(2, 2)
    time.sleep(0.4)
    rest = jp.page.evaluate(f"() => document.querySelector({host!r}).rot4dCounts()")
    jp.page.locator(sel).screenshot(path=str(artifacts / "page-star-rest.png"))
    # held: the page's balls and bars, no fill; at rest: the kernel's picture, its fills too
    assert held[0] > 0 and held[1] > 0 and held[2] == 0, held
    assert rest[2] > 1000, rest
