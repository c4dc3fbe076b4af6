"""A picture of the live view (issue 12), in the real browser: `w.screenshot(path)` and key p.

The PNG comes from the page (the companion reads the WebGL canvas after a render): it has the
canvas's size and shows what the canvas shows -- the bounding box of its non-background pixels
matches the one read from the canvas in the page, and the count of such pixels agrees.
"""

from __future__ import annotations


from jupyter_page import JupyterPage, write_notebook
from test_widget_browser import _bad_console, _canvas, _hover

CELL = """\
import io
import numpy as np
from PIL import Image
from rot4d_widget import Rot4DWidget
w = Rot4DWidget('24-cell', c0=0.4)

def png_stats(png):
    '''Size, count and bbox of pixels away from the top-left (background) colour, as the page counts.'''
    a = np.asarray(Image.open(io.BytesIO(png)).convert('RGB')).astype(int)
    far = np.abs(a - a[0, 0]).sum(axis=2) > 24
    ys, xs = np.nonzero(far)
    bbox = [int(xs.min()), int(ys.min()), int(xs.max()), int(ys.max())] if len(xs) else None
    return dict(width=a.shape[1], height=a.shape[0], count=int(far.sum()), bbox=bbox)
w"""


def test_screenshot_and_key_p_give_the_view_as_a_png(jupyter_server, page, artifacts):
    write_notebook(jupyter_server.root / "shot.ipynb", [CELL])
    jp = JupyterPage(page, jupyter_server, "shot.ipynb").open()
    jp.run_all(timeout=300)
    sel = _canvas(jp)
    page.mouse.move(5, 300)  # off the canvas: nothing changes the view meanwhile
    jp.watch_pixels(sel)
    assert jp.wait_quiet(0.5), "the view kept changing"
    canvas = jp.canvas_stats(sel)

    # 1. from code: returns at once; the PNG arrives after the cell
    rid = jp.kernel_json("w.screenshot('view.png')")
    assert isinstance(rid, int), rid
    got = jp.wait_for(lambda: jp.kernel_json("w.last_screenshot is not None"), timeout=20)
    assert got, f"no PNG arrived; readout: {jp.kernel_json('w._painter.note')}"
    shot = jp.kernel_json("png_stats(w.last_screenshot)")
    assert (shot["width"], shot["height"]) == (canvas["width"], canvas["height"]), (shot, canvas)
    assert shot["bbox"] is not None and canvas["bbox"] is not None
    assert all(abs(a - b) <= 2 for a, b in zip(shot["bbox"], canvas["bbox"])), (shot, canvas)
    assert abs(shot["count"] - canvas["count"]) <= 0.02 * canvas["count"], (shot, canvas)
    assert (jupyter_server.root / "view.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "saved view.png" in jp.kernel_json("w._painter.note")

    # 2. key p over the view: a numbered file next to the notebook, said in the readout
    _hover(jp, sel)
    page.keyboard.press("p")
    target = jupyter_server.root / "rot4d-001.png"
    assert jp.wait_for(lambda: target.exists(), timeout=20), f"no rot4d-001.png; readout: {jp.kernel_json('w._painter.note')}"
    assert jp.kernel_json("png_stats(open('rot4d-001.png', 'rb').read())")["width"] == canvas["width"]
    assert jp.wait_for(lambda: "saved rot4d-001.png" in jp.kernel_json("w.readout.value"), timeout=10)
    (artifacts / "screenshot-24-cell.png").write_bytes((jupyter_server.root / "view.png").read_bytes())
    assert not _bad_console(page), _bad_console(page)
    assert jp.kernel_json("len(w.errors.outputs)") == 0
