"""The companion's leak guard, in JupyterLab 4 and Notebook 7 (each case runs in both).

Re-running the widget cell while the pointer is over the canvas destroys the
canvas view without a mouseleave.  ipyevents' capture key listener on
``document`` then stayed behind and, in JupyterLab, swallowed every later key
on the page.  The companion's guard element makes the destroyed canvas send
itself a mouseleave, so ipyevents removes that listener.
"""

from __future__ import annotations

import time

import numpy as np

from jupyter_page import JupyterPage, write_notebook

_RUN_WIDGET_CELL = (
    "() => { const p = window.jupyterapp.shell.currentWidget; p.content.activeCellIndex = 1;"
    " return window.jupyterapp.commands.execute('notebook:run-cell'); }"
)


def _canvas(jp, var):
    cls = jp.kernel(f"print({var}.scene.canvas_class)").strip()
    sel = f".{cls} canvas"
    jp.page.wait_for_selector(sel, timeout=60_000)
    return sel


def _hover(page, sel):
    box = page.locator(sel).bounding_box()
    page.mouse.move(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
    time.sleep(0.3)
    return box


def _document_key_listeners(page):
    """Capture-phase key listeners on ``document`` (ipyevents adds them while a canvas is hovered)."""
    cdp = page.context.new_cdp_session(page)
    try:
        doc = cdp.send("Runtime.evaluate", {"expression": "document"})["result"]["objectId"]
        found = cdp.send("DOMDebugger.getEventListeners", {"objectId": doc})["listeners"]
    finally:
        cdp.detach()
    return sorted(x["type"] for x in found if x["type"].startswith("key") and x["useCapture"])


def test_rerun_while_hovered_leaves_no_key_listener_behind(jupyter_server, page):
    name = "leak.ipynb"
    write_notebook(
        jupyter_server.root / name,
        [
            "from rot4d_widget import Rot4DWidget\nws = []",
            "w = Rot4DWidget('5-cell')\nws.append(w)\nw",
            "x = 1",
        ],
    )
    jp = JupyterPage(page, jupyter_server, name).open()
    jp.run_all()
    sel = _canvas(jp, "ws[0]")
    _hover(page, sel)
    page.keyboard.press("4")  # ipyevents is listening: the widget turns
    assert jp.wait_for(lambda: jp.kernel_json("ws[0].state.matrix.tolist()") != np.eye(4).tolist(), timeout=5)
    # re-run the widget cell with the pointer still over the canvas (twice)
    for n in (2, 3):
        page.evaluate(_RUN_WIDGET_CELL)
        jp.wait_idle()
        assert jp.kernel_json("len(ws)") == n
        sel = _canvas(jp, f"ws[{n - 1}]")
        _hover(page, sel)
    # the pointer leaves for the last cell's prompt: a click there selects that cell
    # in command mode, where "b" inserts a cell below
    page.locator(".jp-Cell").nth(2).locator(".jp-InputPrompt").click()
    page.keyboard.press("Escape")
    time.sleep(0.3)
    page.evaluate("() => { window.__executed.length = 0; }")
    old = jp.kernel_json("[x.state.matrix.tolist() for x in ws]")
    cells_before = jp.notebook_model()["cells"]
    page.keyboard.press("b")  # insert a cell below
    time.sleep(0.5)
    inserted = jp.wait_for(lambda: jp.notebook_model()["cells"] == cells_before + 1, timeout=3)
    executed = jp.executed_commands()
    # the widgets whose views are gone never stepped on these keys
    page.keyboard.press("4")
    time.sleep(0.5)
    assert jp.kernel_json("[x.state.matrix.tolist() for x in ws]") == old
    diag = dict(
        commands=executed,
        cells=jp.notebook_model()["cells"],
        capture_key_listeners=_document_key_listeners(page),
        active=page.evaluate("() => [document.activeElement.tagName, document.activeElement.className]"),
    )
    assert inserted, f"'b' was swallowed: {diag}"
    assert "notebook:insert-cell-below" in executed
