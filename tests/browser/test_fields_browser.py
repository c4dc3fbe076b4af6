"""A 4-D field in the page (issue 9): notebook 04, run whole in JupyterLab, and its widget.

The surface is drawn (pixels of the level's colour inside the canvas); a held ``4`` (time into
x) changes the picture while held, drawn by the page from its own copy of the field (issue 36: the
kernel slices only at rest); after the release the view settles on a
full-resolution slice within a bound derived from this run's own tap round trips (as in
test_widget_browser.py: a multiple of the median keydown -> pixels time, never below a floor).
"""

from __future__ import annotations

import math
import pathlib
import time

import numpy as np
import pytest

from jupyter_page import JupyterPage
from rot4d_widget import simple_rotation
from rot4d_widget.core import colours
from test_widget_browser import TAP_KEYS, _bad_console, _canvas, _hover, _state, _timing_bound

#: Screenshots to look at (not test artifacts: the issue asks for them here).
SHOTS = pathlib.Path("/tmp/shots04")

NOTEBOOK_04 = pathlib.Path(__file__).resolve().parents[2] / "notebooks" / "04_time_varying_field.ipynb"

# Appended to a copy of notebook 04 (which the page runs whole): back to the w = c0 snapshot at the
# default step, and every call of the field's slice recorded with its coarse flag.
TAIL_CELL = """\
w.press("r")
w.theta0 = math.pi / 64
calls = []
_slice = field.slice
def _counted(matrix, c0, coarse=False):
    calls.append(bool(coarse))
    return _slice(matrix, c0, coarse=coarse)
field.slice = _counted"""


#: Pixels whose colour is the level's hue: the single level is drawn in viridis(0.75), a green
#: (r, g, b) ~ (0.48, 0.82, 0.32), shaded; the background is white and the box's bars grey.
_SURFACE_PIXELS = """
(sel) => {
  const c = document.querySelector(sel);
  const tmp = document.createElement('canvas'); tmp.width = c.width; tmp.height = c.height;
  const ctx = tmp.getContext('2d'); ctx.drawImage(c, 0, 0);
  const d = ctx.getImageData(0, 0, c.width, c.height).data;
  let n = 0, x0 = c.width, y0 = c.height, x1 = -1, y1 = -1;
  for (let y = 0; y < c.height; y++) for (let x = 0; x < c.width; x++) {
    const i = 4 * (y * c.width + x), r = d[i], g = d[i + 1], b = d[i + 2];
    if (g > r + 25 && g > b + 25) {
      n++; if (x < x0) x0 = x; if (x > x1) x1 = x; if (y < y0) y0 = y; if (y > y1) y1 = y;
    }
  }
  return {count: n, total: c.width * c.height, bbox: n ? [x0, y0, x1, y1] : null};
}
"""


def _surface_pixels(jp, sel):
    return jp.page.evaluate(_SURFACE_PIXELS, sel)


def test_the_level_colour_is_green():
    """What _SURFACE_PIXELS looks for: the colour of a single level."""
    r, g, b = colours.level_colors([0.0], -1.0, 1.0)[0]
    assert g > r + 0.3 and g > b + 0.3, (r, g, b)


def test_phase_separation_field_held_key_then_full_resolution(jupyter_server, page, artifacts):
    if jupyter_server.kind == "notebook":
        pytest.skip("JupyterLab only: the page side of fields is the same in Notebook 7 (one field case is enough)")
    SHOTS.mkdir(exist_ok=True)
    import nbformat

    nb = nbformat.read(NOTEBOOK_04, as_version=4)
    nb.cells.append(nbformat.v4.new_code_cell(TAIL_CELL))
    nbformat.write(nb, jupyter_server.root / "04_field.ipynb")
    jp = JupyterPage(page, jupyter_server, "04_field.ipynb").open()
    jp.run_all(timeout=300)  # notebook 04 whole: a first run simulates (a few seconds) and compiles numba kernels
    sel = _canvas(jp)

    # 1. the isosurface is drawn: many pixels of the level's colour, inside the canvas
    page.mouse.move(5, 300)
    time.sleep(0.5)
    page.locator(sel).screenshot(path=str(SHOTS / "before.png"))
    got = jp.wait_for(lambda: (s := _surface_pixels(jp, sel))["count"] > 0.02 * s["total"] and s, timeout=30)
    before_px = _surface_pixels(jp, sel)
    surface = jp.kernel_json("dict(n=w.scene.surface.get('n_vertices', 0), k=w.scene.surface.get('n_indices', 0))")
    gl = [t for _, t in page.console_messages if "GL_INVALID" in t][:3]  # e.g. a buffer not uploaded
    assert got, f"no surface drawn: {before_px} level-coloured pixels; the kernel sent {surface}; WebGL: {gl}"

    x0, y0, x1, y1 = before_px["bbox"]
    stats = jp.canvas_stats(sel)
    assert 0 < x0 < x1 < stats["width"] - 1 and 0 < y0 < y1 < stats["height"] - 1, (before_px, stats)
    info = jp.kernel_json("dict(n=w.scene.surface.get('n_vertices', 0), shown=bool(w._painter.shown.coarse))")
    assert info["n"] > 1000 and info["shown"] is False, info  # a full-resolution surface at rest

    # 2. this run's round trip: isolated taps of 2 (a turn in space; no resampling)
    _hover(jp, sel)
    jp.watch_pixels(sel)
    taps = jp.tap_round_trips(TAP_KEYS)
    # after the release: the coarse update in flight lands, then one full-resolution slice
    # (resampled in the kernel, 10-30 ms, and a message several times a tap's) is sent and drawn:
    # a few round trips; generous, on a loaded machine
    bound = _timing_bound(taps, 8, 1.5)
    # the page has its own copy of the field by now (issue 36): it draws the held pictures itself
    assert jp.wait_for(lambda: jp.kernel_json("w.companion.page_field.page_draws"), timeout=60), \
        "the page never said it holds the field's copy"
    jp.kernel("calls.clear()")
    before = _state(jp)

    # 3. hold 4 (time into x): the picture changes while held, the page's own (issue 36)
    # long enough for several pictures at this run's own pace (a tap's round trip each, at least)
    page.keyboard.down("4")
    time.sleep(max(1.2, 4 * sorted(taps)[len(taps) // 2]))
    page.keyboard.up("4")
    downs = jp.key_stamps("keydown", "Digit4")
    assert downs, "the page saw no keydown of 4"
    down = downs[-1]
    up = jp.wait_for(lambda: jp.key_stamps("keyup", "Digit4"), timeout=5)[-1]
    held_changes = [t for t in jp.pixel_changes(down) if t <= up]
    assert len(held_changes) >= 3, f"{len(held_changes)} pictures while 4 was held for {(up - down) / 1000:.2f} s"

    # 4. after the release the view settles within the bound, on a full-resolution slice
    settle = jp.settle_after(up, watch=bound + 1.0)
    assert settle < bound, f"view kept changing {settle:.2f} s after release (bound {bound:.2f} s, taps {taps})"
    after = _state(jp)
    r = np.array(after["m"]) @ np.array(before["m"]).T
    angle = math.atan2(r[3, 0], r[0, 0])
    np.testing.assert_allclose(r, simple_rotation("xw", angle), atol=1e-9)  # a pure x-w turn
    assert abs(angle) > 2 * before["theta0"], angle
    calls = jp.kernel_json("calls")
    shown = jp.kernel_json("dict(coarse=bool(w._painter.shown.coarse), rows=w._painter.shown is w._painter.rows_key, held=len(w.held_keys))")
    # the page drew the held pictures from its copy: the kernel sliced only at rest, at full resolution
    assert calls and True not in calls, f"the kernel sliced coarse while the page drew: {calls}"
    assert calls[-1] is False, f"the last slice was coarse: {calls}"
    assert shown == {"coarse": False, "rows": True, "held": 0}, shown
    after_px = _surface_pixels(jp, sel)
    assert after_px["count"] > 0.02 * after_px["total"], after_px
    page.mouse.move(5, 300)
    time.sleep(0.3)
    page.locator(sel).screenshot(path=str(SHOTS / "after.png"))
    page.locator(sel).screenshot(path=str(artifacts / "field-after-xw.png"))
    print(f"field: taps {[round(t, 3) for t in taps]} s, bound {bound:.2f} s, settled {settle:.2f} s; "
          f"{len(held_changes)} pictures while held; slices {calls.count(True)} coarse, {calls.count(False)} full; "
          f"turned {math.degrees(angle):.1f} deg; surface pixels {before_px['count']} -> {after_px['count']}")
    assert jp.kernel_json("len(w.errors.outputs)") == 0
    assert not _bad_console(page), _bad_console(page)

