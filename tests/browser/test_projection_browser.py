"""The whole object beside its slice (issue 22, ``projection=True``) in JupyterLab and Notebook 7:
the projection's canvas is drawn (non-background pixels), one key press changes both canvases,
a key pressed over the projection turns the object too, what the page projected (the companion,
in JavaScript) equals `projection_arrays` computed in the kernel for the same rotation,
and a screenshot of the two views is kept in test-artifacts/projection-<front end>.png."""

from __future__ import annotations

import time

import numpy as np
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
    _check_page_projection(jp)
    # a key with the mouse over the projection turns the object too
    page.locator(PROJECTION).scroll_into_view_if_needed()
    _hover(jp, PROJECTION)
    m1 = jp.kernel_json("w.state.matrix.tolist()")
    page.evaluate("() => { window.__executed.length = 0; }")
    page.keyboard.press("c")
    assert jp.wait_for(lambda: jp.kernel_json("w.state.matrix.tolist()") != m1, timeout=10), \
        "a key over the projection's canvas must turn the object"
    # and no notebook shortcut fired (Notebook 7's "c" copies the cell unless the companion guards)
    assert not [c for c in jp.executed_commands() if c.startswith("notebook:")], jp.executed_commands()
    host = page.locator(PROJECTION).locator("xpath=ancestor::div[contains(@class, 'widget-hbox')][1]")
    host.screenshot(path=str(artifacts / f"projection-{jupyter_server.kind}.png"))
    assert "right: the whole object projected" in jp.kernel_json("w.readout.value")
    assert not _bad_console(page), _bad_console(page)
    assert jp.kernel_json("len(w.errors.outputs)") == 0


def _check_page_projection(jp):
    """The page's projection (read through the hook the companion puts on the projection's canvas
    element) for the kernel's current rotation equals the kernel's `projection_arrays`."""
    cls = jp.kernel_json("w._projection.canvas_class")
    matrix = jp.kernel_json("w.state.matrix.reshape(-1).tolist()")
    read = ("(cls) => { const h = document.querySelector('.' + cls);"
            " return h && h.rot4dProjection ? h.rot4dProjection() : null; }")
    got = None

    def current():
        nonlocal got
        got = jp.page.evaluate(read, cls)
        return got is not None and got["state"]["matrix"] == matrix

    assert jp.wait_for(current, timeout=15), f"the page's projection is not of the kernel's rotation: {got}"
    want = jp.kernel_json(
        "{k: v.tolist() for k, v in __import__('rot4d_widget.view.projection', fromlist=['x'])"
        ".projection_arrays(w.source, w.state.matrix, w.state.c0, w._showing.scale).items() if k != 'distance'}")
    np.testing.assert_allclose(np.reshape(got["positions"], (-1, 3)), want["positions"], rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(np.reshape(got["rgb"], (-1, 3)), want["rgb"], rtol=1e-6, atol=1e-6)
    assert got["index"] == want["index"]
    assert len(want["points"]) > 0
    np.testing.assert_allclose(np.reshape(got["points"], (-1, 3)), want["points"], rtol=1e-6, atol=1e-6)


FIELD_CELL = """\
import numpy as np
from rot4d_widget import Rot4DWidget
from rot4d_widget.sources.field.container import Field4D
x = np.linspace(-1, 1, 17)
q = np.stack(np.meshgrid(x, x, x, x, indexing="ij"), -1)
f = Field4D((0.6 - (q ** 2).sum(-1)).astype(np.float32), axes="xyzw", extent=((-1, 1),) * 4, name="ball")
f.levels = 0.0
w = Rot4DWidget(f, width=360, height=300, projection=True, slices=3, spacing=0.5)
w"""


def test_projection_of_a_field_stack_in_the_page(jupyter_server, page, artifacts):
    """A field's data box (a tesseract) with a stack's three hyperplanes: the page's projection and
    every slice's crossings equal the kernel's after a rotation in w and a step of c0."""
    write_notebook(jupyter_server.root / "projection_field.ipynb", [FIELD_CELL])
    jp = JupyterPage(page, jupyter_server, "projection_field.ipynb").open()
    jp.run_all(timeout=300)
    sel = _canvas(jp)
    page.wait_for_selector(PROJECTION, timeout=60_000)
    assert jp.wait_for(lambda: (s := jp.canvas_stats(PROJECTION)) and s["count"] > 200, timeout=30), \
        jp.canvas_stats(PROJECTION)
    page.locator(sel).scroll_into_view_if_needed()
    _hover(jp, sel)
    for key in ("4", "4", "l"):
        page.keyboard.press(key)
        time.sleep(0.3)
    assert jp.wait_for(lambda: jp.kernel_json("len(w._projection.arrays['offsets'])") == 3, timeout=10)
    _check_page_projection(jp)
    n_points = jp.kernel_json("len(w._projection.arrays['points'])")
    assert n_points > 8, "more than one hyperplane cuts the box"
    host = page.locator(PROJECTION).locator("xpath=ancestor::div[contains(@class, 'widget-hbox')][1]")
    host.screenshot(path=str(artifacts / f"projection-field-stack-{jupyter_server.kind}.png"))
    assert not _bad_console(page), _bad_console(page)
    assert jp.kernel_json("len(w.errors.outputs)") == 0
