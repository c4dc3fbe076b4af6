"""Hostile use in the page (issue 18): a stack taken down to one slice, and a user source whose
slice goes bad and recovers, seen as a user sees them (screenshots kept in test-artifacts/).

Before the fix, the stack of the 24-cell at one slice raised "Expected group_rgb to have a
colour for group 22, got 5 colours" on every key (nothing drawn); a bad slice (NaN points)
was sent to the page silently, and an error, once shown, stayed under the readout.
"""

from __future__ import annotations

import time

import pytest

from jupyter_page import JupyterPage, write_notebook
from test_widget_browser import _canvas, _hover

pytestmark = pytest.mark.browser

CELLS = [
    '''\
import numpy as np
from rot4d_widget import Rot4DWidget, SliceData

class Flaky:
    """A user's source: a triangle, or NaN points when told to break."""
    size = 1.0
    n_groups = 1
    broken = False

    def slice(self, matrix, c0):
        p = np.array([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]]) @ np.asarray(matrix)[:3, :3].T * 0.8
        if self.broken:
            p[0, 1] = np.nan
            return SliceData(p, np.zeros((0, 2), int), np.array([[0, 1, 2]]), np.zeros(1, int))
        return SliceData.build(p, segments=[[0, 1], [1, 2], [2, 0]], triangles=[[0, 1, 2]])

    def describe(self):
        return {"kind": "flaky"}

w = Rot4DWidget("24-cell", slices=5, width=420, height=360)
w''',
    '''\
src = Flaky()
u = Rot4DWidget(src, width=420, height=360, ball_radius=0.06)
u''',
]


def _errors_text(jp, var):
    return jp.kernel(f"print(''.join(o.get('text', '') for o in {var}.errors.outputs))").strip()


def test_a_stack_down_to_one_slice_and_a_bad_user_slice_in_the_page(jupyter_server, page, artifacts):
    if jupyter_server.kind != "lab":
        pytest.skip("JupyterLab only (the key path is the same in Notebook 7)")
    write_notebook(jupyter_server.root / "hostile.ipynb", CELLS)
    jp = JupyterPage(page, jupyter_server, "hostile.ipynb").open()
    jp.run_all()
    sel = _canvas(jp, "w")
    jp.page.locator(sel).scroll_into_view_if_needed()
    _hover(jp, sel)
    for _ in range(4):
        jp.page.keyboard.press("b")
        time.sleep(0.3)
    assert jp.wait_for(lambda: jp.kernel("print(w.slices)").strip() == "1", timeout=30)
    jp.page.keyboard.down("4")
    time.sleep(0.6)
    jp.page.keyboard.up("4")
    assert jp.wait_for(lambda: jp.kernel("print(bool(w._pump.dirty or w._pump.n_in_flight))").strip() == "False",
                       timeout=30)
    time.sleep(0.5)  # the last picture drawn
    assert _errors_text(jp, "w") == ""
    stats = jp.canvas_stats(sel)
    assert stats and stats["count"] > 500  # the one slice is drawn
    n_colours = int(jp.kernel("print(len(set(map(tuple, np.round(w._painter.group_colors(), 3)))))").strip())
    assert n_colours >= 24  # a colour for each of the 24-cell's cells, not the stack's five
    jp.page.locator(sel).screenshot(path=str(artifacts / "hostile-stack-down-to-one.png"))

    sel_u = _canvas(jp, "u")
    before = jp.canvas_stats(sel_u)
    jp.kernel("src.broken = True")
    jp.page.locator(sel_u).scroll_into_view_if_needed()
    _hover(jp, sel_u)
    jp.page.keyboard.press("4")
    assert jp.wait_for(lambda: "Flaky.slice" in _errors_text(jp, "u"), timeout=30)
    text = _errors_text(jp, "u")
    assert "`points`" in text and "finite" in text
    jp.page.locator(".rot4d-side").last.scroll_into_view_if_needed()
    box = jp.page.locator(sel_u).bounding_box()
    side = jp.page.locator(".rot4d-side").last.bounding_box()
    clip = {"x": box["x"], "y": box["y"], "width": side["x"] + side["width"] - box["x"],
            "height": max(box["height"], side["height"])}
    jp.page.screenshot(path=str(artifacts / "hostile-bad-slice-error.png"), clip=clip)
    assert jp.canvas_stats(sel_u)["count"] == pytest.approx(before["count"], rel=0.5)  # the last good picture stays
    jp.kernel("src.broken = False")
    _hover(jp, sel_u)
    jp.page.keyboard.press("4")
    assert jp.wait_for(lambda: _errors_text(jp, "u") == "", timeout=30)
    jp.page.screenshot(path=str(artifacts / "hostile-bad-slice-recovered.png"), clip=clip)
