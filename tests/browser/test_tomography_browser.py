"""Parallel slices in the page (issue 10): the 24-cell's oval view.

Each slice is drawn where the layout puts it: something inside each slice's projected
bounding box (computed in the kernel from `StackSource.layout()`, the scene's scale and the
camera); a held key changes the pixels inside every one of them (all slices turn together);
n / b add and remove slices.
"""

from __future__ import annotations

import time

import pytest

from jupyter_page import JupyterPage, write_notebook
from test_widget_browser import _bad_console, _canvas, _hover

# spacing 0.3: the 5 levels span w in [-0.6, 0.6], inside the 24-cell's |w| < sqrt(2) at the
# identity, so no slice is empty
CELL = """\
import itertools
import numpy as np
from rot4d_widget import Rot4DWidget
from rot4d_widget.core import camera
w = Rot4DWidget('24-cell', slices=5, spacing=0.3, arrangement='oval')

def slice_boxes():
    '''Each slice's bounding box on the canvas, in canvas pixels [x0, y0, x1, y1].'''
    centres, scales = w.source.layout()
    k, r = w.scene.scale, w.source.size
    eye = np.array(w.scene.eye)
    f = 1.0 / np.tan(np.radians(camera.CAMERA_FOV) / 2)
    W, H = w.scene.width, w.scene.height
    out = []
    for c, s in zip(np.asarray(centres), np.asarray(scales)):
        p = np.array([(c + s * r * np.array(d)) * k for d in itertools.product([-1, 1], repeat=3)])
        zc = eye[2] - p[:, 2]
        x = (f * H / W * p[:, 0] / zc + 1) / 2 * W
        y = (1 - f * p[:, 1] / zc) / 2 * H
        out.append([float(x.min()), float(y.min()), float(x.max()), float(y.max())])
    return out
w"""

#: Per box: pixels that are not the white background, and a hash of the box's pixels.
_BOXES = """
([sel, boxes]) => {
  const c = document.querySelector(sel);
  const tmp = document.createElement('canvas'); tmp.width = c.width; tmp.height = c.height;
  const ctx = tmp.getContext('2d'); ctx.drawImage(c, 0, 0);
  const d = ctx.getImageData(0, 0, c.width, c.height).data;
  return boxes.map(([bx0, by0, bx1, by1]) => {
    const x0 = Math.max(0, Math.floor(bx0)), y0 = Math.max(0, Math.floor(by0));
    const x1 = Math.min(c.width - 1, Math.ceil(bx1)), y1 = Math.min(c.height - 1, Math.ceil(by1));
    let n = 0, h = -2128831035;
    for (let y = y0; y <= y1; y++) for (let x = x0; x <= x1; x++) {
      const i = 4 * (y * c.width + x);
      if (d[i] < 245 || d[i + 1] < 245 || d[i + 2] < 245) n++;
      h = Math.imul(h ^ (d[i] | (d[i + 1] << 8) | (d[i + 2] << 16)), 16777619);
    }
    return {n, h, area: (x1 - x0 + 1) * (y1 - y0 + 1)};
  });
}
"""


def test_oval_view_draws_every_slice_in_its_place_and_they_turn_together(jupyter_server, page, artifacts):
    if jupyter_server.kind == "notebook":
        pytest.skip("JupyterLab only: the page side of a stack is the rows of any source")
    write_notebook(jupyter_server.root / "oval.ipynb", [CELL])
    jp = JupyterPage(page, jupyter_server, "oval.ipynb").open()
    jp.run_all(timeout=300)
    sel = _canvas(jp)
    boxes = jp.kernel_json("slice_boxes()")
    assert len(boxes) == 5
    stats = jp.canvas_stats(sel)
    for x0, y0, x1, y1 in boxes:  # every slice's centre on the canvas (the boxes bound a slice's
        # ball by a cube, so they reach past what is drawn; the pixels below are read within the canvas)
        assert 0 < (x0 + x1) / 2 < stats["width"] and 0 < (y0 + y1) / 2 < stats["height"], (boxes, stats)

    # 1. something is drawn inside each slice's box
    def per_box():
        return page.evaluate(_BOXES, [sel, boxes])

    def all_drawn():
        r = per_box()
        return r if all(b["n"] > 0.02 * b["area"] for b in r) else None

    got = jp.wait_for(all_drawn, timeout=30)
    assert got, f"a slice's box is (nearly) empty: {per_box()}"
    before = per_box()
    page.locator(sel).screenshot(path=str(artifacts / "oval-24-cell.png"))

    # 2. a held key changes the pixels inside every box (all slices turn together)
    _hover(jp, sel)
    page.keyboard.down("4")
    time.sleep(1.0)
    page.keyboard.up("4")
    assert jp.wait_for(lambda: jp.kernel_json("len(w.held_keys)") == 0, timeout=10)
    # the updates still on their way land within a few round trips; wait for them, not a fixed time
    after = jp.wait_for(lambda: (r := per_box()) and all(a["h"] != b["h"] for a, b in zip(r, before)) and r,
                        timeout=10) or per_box()
    changed = [a["h"] != b["h"] for a, b in zip(after, before)]
    assert all(changed), f"pixels unchanged in boxes {[i for i, c in enumerate(changed) if not c]}"
    assert all(a["n"] > 0 for a in after)

    # 3. n adds a slice, b removes one: the kernel's stack follows and the picture changes
    n0 = jp.kernel_json("w.slices")
    h0 = per_box()
    page.keyboard.press("n")
    assert jp.wait_for(lambda: jp.kernel_json("w.slices") == n0 + 1, timeout=10)
    assert jp.wait_for(lambda: per_box() != h0, timeout=10), "the picture did not change after n"
    page.keyboard.press("b")
    page.keyboard.press("b")
    assert jp.wait_for(lambda: jp.kernel_json("[w.slices, w.source.slices]") == [n0 - 1, n0 - 1], timeout=10)
    assert jp.kernel_json("len(w.errors.outputs)") == 0
    assert not _bad_console(page), _bad_console(page)
