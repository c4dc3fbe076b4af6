"""A field's cut ray-cast in the page (issue 21): "volume", "mip" and "sections" drawn by the
companion's shader from the grid the kernel sends, in JupyterLab and Notebook 7.

The page's picture (the canvas as a PNG, `w.screenshot`) is compared with the static render of
the same cut through the same camera (`rot4d_widget.keep.pictures.ray_caster.render_grid`, numpy ray casting,
the live view's frustum): the coloured region overlaps (IoU), its colour-weighted centre is in the
same place within a few pixels, and the colours agree.  The key v cycles the renderings in the
page, Shift+v backwards.  Screenshots kept in test-artifacts/volume-<rendering>-<front end>.png.
"""

from __future__ import annotations

import pytest

from jupyter_page import JupyterPage, write_notebook
from test_widget_browser import _bad_console, _canvas, _hover

pytestmark = pytest.mark.browser

CELL = """\
import io, math
import numpy as np
from PIL import Image
from rot4d_widget import Field4D, Rot4DWidget
from rot4d_widget.core import camera
from rot4d_widget.core.camera import view_rotation
from rot4d_widget.keep.pictures.ray_caster import render_grid

# an off-centre blob in x, y, z, t and a second, weaker one: where the values are high and low
x = np.linspace(-1.0, 1.0, 25)
X, Y, Z, T = np.meshgrid(x, x, x, x, indexing="ij")
f = (np.exp(-((X - 0.35) ** 2 + (Y - 0.2) ** 2 + Z ** 2 + T ** 2) * 6.0)
     + 0.5 * np.exp(-((X + 0.4) ** 2 + (Y + 0.3) ** 2 + (Z - 0.3) ** 2 + T ** 2) * 10.0))
field = Field4D(f, axes="xyzw", extent=[(-1.0, 1.0)] * 4, name="density", units="kg/m3")
W, H = 360, 300
w = Rot4DWidget(field, width=W, height=H, rendering="mip", cmap="viridis", clim=(0.0, 1.0), show_bars=False)
for key in "336":
    w.press(key)

def compare(png, rendering):
    '''The page's PNG against render_grid of the widget's cut through the live camera.'''
    page = np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(float) / 255.0
    g = field.sample(w.state.matrix, w.c0)
    half_h = camera.CAMERA_POSITION[2] * math.tan(math.radians(camera.CAMERA_FOV / 2))
    half_w = half_h * W / H
    opts = dict(sections=tuple(w.sections)) if rendering == "sections" else {}
    rgba = render_grid(g, rendering, size=(W, H), limits=((-half_w, half_w), (-half_h, half_h)), cmap=w.cmap,
                       clim=w.clim, scale=w.scene.scale, pixels_per_ray=1,
                       view=view_rotation(w.scene.eye), **opts)
    static = rgba[..., :3] * rgba[..., 3:] + (1.0 - rgba[..., 3:])  # over the white background
    Image.fromarray(np.round(static * 255).astype(np.uint8)).save(f"volume-{rendering}-static.png")
    ink = lambda a: (1.0 - a).sum(axis=2)  # how far from white
    mp, ms = ink(page) > 0.08, ink(static) > 0.08
    iou = float((mp & ms).sum() / max((mp | ms).sum(), 1))
    def centre(a):
        wgt = ink(a)
        if wgt.sum() <= 0:
            return [-1e6, -1e6]
        ys, xs = np.mgrid[: a.shape[0], : a.shape[1]]
        return [float((xs * wgt).sum() / wgt.sum()), float((ys * wgt).sum() / wgt.sum())]
    both = mp & ms
    diff = float(np.median(np.abs(page - static).max(axis=2)[both])) if both.any() else 1.0
    shift = float(np.hypot(*np.subtract(centre(page), centre(static))))
    return dict(shape=list(page.shape), iou=iou, shift=shift, diff=diff, page_ink=int(mp.sum()),
                static_ink=int(ms.sum()))
w"""


def _page_state(jp):
    """What the page says when an update is not acknowledged: the view's canvas (drawn pixels,
    WebGL context lost?) and the console's last messages."""
    sel = jp.kernel("print(w.scene.canvas_class)").strip()
    gl = jp.page.evaluate(
        "(cls) => { const c = document.querySelector('.' + cls + ' canvas'); if (!c) return 'no canvas';"
        " const gl = c.getContext('webgl'); return {w: c.width, h: c.height,"
        " lost: gl ? gl.isContextLost() : null}; }", sel)
    companions = jp.page.evaluate(
        "() => Array.from(document.querySelectorAll('[data-rot4d-companion]'),"
        " (e) => [e.dataset.rot4dCompanion, e.rot4dAcks || null])")
    companions.append({"kernel: last drawn from the page": jp.kernel_json("getattr(w.companion, 'last_drawn', None)"),
                       "kernel: update id": jp.kernel_json("w.scene.update_id")})
    rot4d = [m for m in jp.page.console_messages if "rot4d" in m[1]][-6:]
    return {"companions": companions, "rot4d console": rot4d, "canvas": gl, "stats": jp.canvas_stats(f".{sel} canvas"),
            "console": jp.page.console_messages[-12:],
            "errors": jp.page.page_errors[-5:]}


def _shot(jp, rendering):
    """The page's PNG of the view once it has drawn ``rendering`` (the kernel shows it and the page
    acknowledged every update sent), fresh each time."""
    shown = f"w._painter.shown is not None and w._painter.shown.scale[2] == {rendering!r}"
    if not jp.wait_for(lambda: jp.kernel_json(f"{shown} and not w.in_flight"), timeout=90):
        kernel = jp.kernel_json("[str(w._painter.shown and w._painter.shown.scale), w.in_flight, w.stats.as_dict()]")
        state = _page_state(jp)
        raise AssertionError((kernel, state))
    jp.kernel("w.last_screenshot = None")
    jp.kernel_json("w.screenshot()")
    assert jp.wait_for(lambda: jp.kernel_json("w.last_screenshot is not None"), timeout=30), "no PNG from the page"


def test_volume_mip_sections_in_the_page_agree_with_the_static_render(jupyter_server, page, artifacts):
    write_notebook(jupyter_server.root / "volume.ipynb", [CELL])
    jp = JupyterPage(page, jupyter_server, "volume.ipynb").open()
    jp.run_all(timeout=300)
    sel = _canvas(jp)
    page.locator(sel).scroll_into_view_if_needed()  # in view before the first ray-cast picture
    assert jp.wait_for(lambda: (st := jp.canvas_stats(sel)) and st["count"] > 50, timeout=60), _page_state(jp)
    page.mouse.move(5, 300)  # off the canvas: nothing moves the camera
    results = {}
    for rendering in ("mip", "volume", "sections"):
        jp.kernel(f"w.rendering = {rendering!r}")
        _shot(jp, rendering)
        results[rendering] = r = jp.kernel_json(f"compare(w.last_screenshot, {rendering!r})")
        jp.kernel(f"open('volume-{rendering}.png', 'wb').write(w.last_screenshot)")
        for name in (f"volume-{rendering}", f"volume-{rendering}-static"):
            kept = (jupyter_server.root / f"{name}.png").read_bytes()
            (artifacts / f"{name}-{jupyter_server.kind}.png").write_bytes(kept)
        assert r["shape"][:2] == [300, 360], r
        assert r["page_ink"] > 500, (rendering, r)  # something drawn, not a blank canvas
        # same blob, same place: the coloured regions overlap and their centres agree within 3 px
        assert r["iou"] > 0.85, (rendering, r)
        assert r["shift"] < 3.0, (rendering, r)
        assert r["diff"] < 0.12, (rendering, r)
    # the box's corner and edge ends carry the data coordinates there, over the canvas
    host = page.locator(sel).locator("xpath=..")
    labels = host.locator(".rot4d-label")
    assert jp.wait_for(lambda: labels.count() == 4, timeout=10), labels.count()
    texts = labels.all_inner_texts()
    want = jp.kernel_json("[lab['text'] for lab in w.scene.buffer.labels]")
    assert [t.strip("\u25cf ") for t in texts] == want, (texts, want)
    assert texts[0].strip("\u25cf ").startswith("x ") and " \u2192 " in texts[1], texts  # the corner; an edge
    host.screenshot(path=str(artifacts / f"volume-labelled-{jupyter_server.kind}.png"))
    # the three renderings are different pictures of the same cut
    assert len({round(v["page_ink"], -2) for v in results.values()}) >= 2, results

    # v cycles the rendering in the page: sections -> surface; Shift+v back to sections
    page.locator(sel).scroll_into_view_if_needed()
    _hover(jp, sel)
    page.keyboard.press("v")
    assert jp.wait_for(lambda: jp.kernel_json("w.rendering") == "surface", timeout=10)
    page.keyboard.press("Shift+v")
    assert jp.wait_for(lambda: jp.kernel_json("w.rendering") == "sections", timeout=10)
    page.keyboard.press("a")  # the x section plane moves
    assert jp.wait_for(lambda: jp.kernel_json("w.sections[0]") > 0.5, timeout=10)
    assert not _bad_console(page), _bad_console(page)
    assert jp.kernel_json("len(w.errors.outputs)") == 0
