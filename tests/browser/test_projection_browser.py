"""The whole object beside its slice (issue 22, ``projection=True``) in JupyterLab and Notebook 7:
the projection's canvas is drawn (non-background pixels), one key press changes both canvases,
a key pressed over the projection turns the object too,
and a screenshot of the two views is kept in test-artifacts/projection-<front end>.png."""

from __future__ import annotations

import time

import pytest
from jupyter_page import JupyterPage, write_notebook
from test_widget_browser import _bad_console, _canvas, _hover

pytestmark = pytest.mark.browser

CELL = """\
from rot4d_widget import Rot4DWidget
w = Rot4DWidget("24-cell", width=360, height=300, projection=True)
for key in "34":
    w.press(key)
w"""

PROJECTION = ".rot4d-projection canvas"


def test_projection_drawn_and_turned_with_the_slice(jupyter_server, page, artifacts):
    write_notebook(jupyter_server.root / "projection.ipynb", [CELL])
    jp = JupyterPage(page, jupyter_server, "projection.ipynb").open()
    jp.run_all(timeout=300)
    sel = _canvas(jp)
    page.wait_for_selector(PROJECTION, timeout=60_000)
    assert jp.wait_for(lambda: (s := jp.canvas_stats(PROJECTION)) and s["count"] > 200, timeout=30), \
        jp.canvas_stats(PROJECTION)
    time.sleep(1.0)  # the first pictures drawn
    before = jp.canvas_stats(sel)["hash"], jp.canvas_stats(PROJECTION)["hash"]
    page.locator(sel).scroll_into_view_if_needed()
    _hover(jp, sel)
    m0 = jp.kernel_json("w.state.matrix.tolist()")
    page.keyboard.press("8")
    assert jp.wait_for(lambda: jp.kernel_json("w.state.matrix.tolist()") != m0, timeout=10)
    assert jp.wait_for(lambda: jp.canvas_stats(sel)["hash"] != before[0]
                       and jp.canvas_stats(PROJECTION)["hash"] != before[1], timeout=15), \
        "a key press must change both canvases"
    # a key with the mouse over the projection turns the object too
    page.locator(PROJECTION).scroll_into_view_if_needed()
    _hover(jp, PROJECTION)
    m1 = jp.kernel_json("w.state.matrix.tolist()")
    page.keyboard.press("c")
    assert jp.wait_for(lambda: jp.kernel_json("w.state.matrix.tolist()") != m1, timeout=10), \
        "a key over the projection's canvas must turn the object"
    host = page.locator(PROJECTION).locator("xpath=ancestor::div[contains(@class, 'widget-hbox')][1]")
    host.screenshot(path=str(artifacts / f"projection-{jupyter_server.kind}.png"))
    assert "right: the whole object projected" in jp.kernel_json("w.readout.value")
    assert not _bad_console(page), _bad_console(page)
    assert jp.kernel_json("len(w.errors.outputs)") == 0
