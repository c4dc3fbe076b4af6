"""The page's own picture of a field's state and the kernel's are the same picture (issue 36), in
JupyterLab 4 and Notebook 7.

A closed-form field on a 64^4 grid (two Gaussian blobs moving through time and a slow wave) is held
by the page.  For each rendering the view is turned to a state off the axes (a rotation that
mixes w in, a double rotation, c0 raised), left to rest (the kernel's full-resolution picture),
read back; then the page's own picture of the same state is drawn (the canvas's
``rot4dForceOwn`` test hook) and read back:

* volume, maximum intensity, sections: at most 4/255 per channel on at least 99 % of the pixels
  (the issue's bound);
* isosurfaces: the page's first hit along each pixel's ray (``rot4dFieldDepth``: field.frag writes
  the distance) against the kernel's surface -- marching cubes of the full data, ray-cast here in
  numpy through the camera the page drew with -- within half a cell of the page's copy on at least
  99 % of the pixels both hit, the hit pixels themselves the same within 1 %.

The figures are printed; screenshots of each pair are kept in test-artifacts/.
"""

from __future__ import annotations

import time

import numpy as np
import pytest

from jupyter_page import JupyterPage, write_notebook
from test_widget_browser import _canvas, _hover

pytestmark = pytest.mark.browser

CELL = """\
import numpy as np
from rot4d_widget import Field4D, Rot4DWidget
x = np.linspace(-1.0, 1.0, 64)
X, Y, Z, T = np.meshgrid(x, x, x, x, indexing="ij", sparse=True)
a = (np.exp(-((X - 0.45 * T) ** 2 + (Y - 0.1) ** 2 + Z ** 2) / 0.12)
     + 0.7 * np.exp(-((X + 0.4) ** 2 + (Y + 0.3 * T) ** 2 + (Z - 0.35) ** 2) / 0.06)
     + 0.15 * np.sin(2.5 * X + 1.5 * T) * np.cos(2.0 * Y)).astype(np.float32)
field = Field4D(a, axes="xyzw", extent=[(-1.0, 1.0)] * 4, levels=[0.3], name="blobs")
w = Rot4DWidget(field, width=360, height=300, show_bars=False, rendering="volume")
w
"""

def _pixels(jp, sel):
    time.sleep(0.5)  # a few frames drawn
    return jp.canvas_rgba(sel).astype(np.int16)


def _host(sel):
    return sel.rsplit(" canvas", 1)[0]


def _hook(jp, sel, call):
    return jp.page.evaluate(f"() => document.querySelector({_host(sel)!r}).{call}")


def _at_rest_on_the_kernel_s_picture(jp, sel, name):
    assert jp.wait_for(lambda: _hook(jp, sel, "rot4dDrawsOwn()") is False, timeout=60), \
        f"{name}: the kernel's picture never came"


def _rays(cam, w, h):
    """(eye (3,), unit directions (h, w, 3)) of each pixel centre through the page's camera."""
    world = np.asarray(cam["world"], dtype=np.float64).reshape(4, 4).T  # three.js: column-major
    proj = np.asarray(cam["projection"], dtype=np.float64).reshape(4, 4).T
    i, j = np.meshgrid(np.arange(w) + 0.5, np.arange(h) + 0.5)
    ndc = np.stack([i / w * 2 - 1, 1 - j / h * 2, np.ones_like(i), np.ones_like(i)], axis=-1)
    p = ndc @ np.linalg.inv(proj).T
    p = p[..., :3] / p[..., 3:]
    far = p @ world[:3, :3].T + world[:3, 3]
    eye = world[:3, 3]
    d = far - eye
    return eye, d / np.linalg.norm(d, axis=-1, keepdims=True)


def kernel_depth(points, triangles, eye, dirs):
    """The distance to the first triangle along each ray (inf where none): Möller-Trumbore, each
    triangle tested against the pixels of its bounding box on screen (found by projecting)."""
    h, w, _ = dirs.shape
    depth = np.full((h, w), np.inf)
    v = points[triangles]  # (k, 3, 3)
    # screen position of each vertex: the pixel whose ray is nearest its direction
    rel = points - eye
    dn = rel / np.linalg.norm(rel, axis=1, keepdims=True)
    flat = dirs.reshape(-1, 3)
    near = np.empty(len(points), dtype=np.intp)
    for s in range(0, len(points), 2048):
        near[s:s + 2048] = np.argmax(dn[s:s + 2048] @ flat.T, axis=1)
    py, px = np.divmod(near, w)
    ty, tx = py[triangles], px[triangles]
    y0, y1 = np.maximum(ty.min(1) - 2, 0), np.minimum(ty.max(1) + 3, h)
    x0, x1 = np.maximum(tx.min(1) - 2, 0), np.minimum(tx.max(1) + 3, w)
    for k in range(len(triangles)):
        d = dirs[y0[k]:y1[k], x0[k]:x1[k]].reshape(-1, 3)
        a, b, c = v[k]
        e1, e2 = b - a, c - a
        pv = np.cross(d, e2)
        det = pv @ e1
        ok = np.abs(det) > 1e-14
        inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
        s = eye - a
        u = (pv @ s) * inv
        q = np.cross(s, e1)
        vv = (d @ q) * inv
        t = (q @ e2) * inv
        hit = ok & (u >= 0) & (vv >= 0) & (u + vv <= 1) & (t > 0)
        block = depth[y0[k]:y1[k], x0[k]:x1[k]].reshape(-1)
        block[hit] = np.minimum(block[hit], t[hit])
        depth[y0[k]:y1[k], x0[k]:x1[k]] = block.reshape(y1[k] - y0[k], x1[k] - x0[k])
    return depth


def test_the_page_s_picture_of_a_field_state_is_the_kernel_s(jupyter_server, page, artifacts):
    write_notebook(jupyter_server.root / "field_page.ipynb", [CELL])
    jp = JupyterPage(page, jupyter_server, "field_page.ipynb").open()
    jp.run_all()
    sel = _canvas(jp, "w")
    assert jp.wait_for(lambda: "page draws" in jp.kernel("print(w.readout.value)"), timeout=120), \
        "the page never took its copy of the field"
    jp.page.locator(sel).scroll_into_view_if_needed()
    _hover(jp, sel)
    for key in ("4", "y", "l", "l"):  # a turned state: w mixed into x, a double rotation, c0 raised
        jp.page.keyboard.press(key)
    _at_rest_on_the_kernel_s_picture(jp, sel, "turn")
    jp.page.mouse.move(2, 2)
    results = {}
    kind = jupyter_server.kind
    for rendering in ("volume", "mip", "sections", "surface"):
        jp.kernel(f"w.rendering = {rendering!r}")
        time.sleep(0.3)
        _at_rest_on_the_kernel_s_picture(jp, sel, rendering)
        kernel = _pixels(jp, sel)
        jp.page.locator(sel).screenshot(path=str(artifacts / f"field-kernel-{rendering}-{kind}.png"))
        _hook(jp, sel, "rot4dForceOwn(true)")
        assert jp.wait_for(lambda: _hook(jp, sel, "rot4dDrawsOwn()"), timeout=10), f"{rendering}: the page does not draw"
        own = _pixels(jp, sel)
        jp.page.locator(sel).screenshot(path=str(artifacts / f"field-page-{rendering}-{kind}.png"))
        drawn = (kernel[..., :3] != kernel[0, 0, :3]).any(axis=2).sum()
        assert drawn > 1000, f"{rendering}: nothing drawn"
        if rendering != "surface":
            diff = np.abs(own[..., :3] - kernel[..., :3]).max(axis=2)
            results[rendering] = (int(diff.max()), float((diff <= 4).mean()))
            _hook(jp, sel, "rot4dForceOwn(false)")
            assert (diff <= 4).mean() >= 0.99, (rendering, results[rendering])
            continue
        cam = _hook(jp, sel, "rot4dFieldDepth(true)")
        enc = _pixels(jp, sel)
        _hook(jp, sel, "rot4dFieldDepth(false)")
        _hook(jp, sel, "rot4dForceOwn(false)")
        q = (enc[..., 0].astype(np.int64) << 16) | (enc[..., 1].astype(np.int64) << 8) | enc[..., 2]
        page_t = np.where(q < 16777215, q / 16777215.0 * cam["scale"], np.inf)
        h, wd = page_t.shape
        eye, dirs = _rays(cam, wd, h)
        pts = np.asarray(jp.kernel_json("(w.slice.points * w._showing.scale).tolist()"), dtype=np.float64)
        tri = np.asarray(jp.kernel_json("w.slice.triangles.tolist()"), dtype=np.intp)
        kern_t = kernel_depth(pts, tri, eye, dirs)
        cell = float(jp.kernel("print(w._showing.scale * 2.0 / 63.0)"))
        both = np.isfinite(page_t) & np.isfinite(kern_t)
        either = np.isfinite(page_t) | np.isfinite(kern_t)
        dt = np.abs(page_t[both] - kern_t[both])  # the pixels both hit (no inf - inf)
        within = dt <= 0.5 * cell
        results["surface"] = {"pixels hit by both": int(both.sum()), "hit by one only": int((either & ~both).sum()),
                              "within half a cell": float(within.mean()),
                              "median |dt| / cell": float(np.median(dt) / cell),
                              "worst |dt| / cell": float(dt.max() / cell)}
        assert both.sum() > 1000 and within.mean() >= 0.99, results["surface"]
        assert (either & ~both).sum() <= 0.01 * either.sum(), results["surface"]
    print(f"page vs kernel ({kind}):", results)
