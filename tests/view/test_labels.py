"""A field's box labelled in every rendering and after any turn, with the data's extent, and no
label covering the data (issue 37, problem 1).

A flame-like field (T in K on 0.01-0.05 m, 1-4 ms): the live view's labels (`_rot4d_labels`) and
the static picture's (gid "box-label") name the data's extent -- the box's cut -- never the padded
sampling grid of the ray-cast renderings; after 90 degrees in x-w the horizontal edge is time and
says which way it runs.  The static labels' boxes, measured by matplotlib, lie outside the
rectangle the box's cut (`Field4D.outline`, not the code under test) projects into, and cover
no pixel of a ray-cast image.  The page's placement rule (page/labels.js) and the static one
(`keep.pictures.framing.place_labels`) give the same places for the same labels (Node).
"""

from __future__ import annotations

import numpy as np
import pytest

from rot4d_widget.core.sizes import REFERENCE_RADIUS
from rot4d_widget.core.state import RotationState
from rot4d_widget.keep.pictures.slice_drawing import perspective
from rot4d_widget.keep.pictures.state_picture import render_state
from rot4d_widget.sources.field.container import Field4D

pytestmark = pytest.mark.usefixtures("recording_comms")

RENDERINGS = ("surface", "volume", "mip", "sections")


def flame(n=16, nt=8, **kw):
    """T(x, y, z, t) in K: a hot ball growing and rising, on 0.01-0.05 m over 1-4 ms."""
    x = np.linspace(0.01, 0.05, n)
    t = np.linspace(0.001, 0.004, nt)
    X, Y, Z, T = np.meshgrid(x, x, x, t, indexing="ij")
    r0 = 0.004 + 0.012 * (T - 0.001) / 0.003
    r = np.sqrt((X - 0.03) ** 2 + (Y - 0.03) ** 2 + (Z - 0.02 - 5 * T) ** 2)
    f = 300.0 + 1700.0 / (1.0 + np.exp((r - r0) / 0.0015))
    x_ext = (0.01, 0.05)
    return Field4D(f.astype(np.float32), axes="xyzw", extent=(x_ext, x_ext, x_ext, (0.001, 0.004)), name="T",
                   units="K", space_units="m", w_units="s", w_per_unit=0.1,
                   **{"resolution": 24, "coarse_resolution": 12, **kw})


def turned(steps=32):
    """The state after ``steps`` taps of 4 (R_xw by pi/64 each): 90 degrees in x-w at 32."""
    st = RotationState()
    for _ in range(steps):
        st.press("4")
    st.c0 = 0.0025  # the middle of the record
    return st


@pytest.mark.parametrize("rendering", RENDERINGS)
def test_every_rendering_labels_the_data_extent_after_a_turn(make, rendering):
    f = flame()
    w = make(f, rendering=rendering)
    texts = [lab["text"] for lab in w.scene.buffer.labels]
    assert texts[1:] == ["x 0.01 \u2192 0.05 m", "y 0.01 \u2192 0.05 m", "z 0.01 \u2192 0.05 m"], texts
    w.state.matrix = turned().matrix
    w.refresh()
    labels = w.scene.buffer.labels
    texts = [lab["text"] for lab in labels]
    # the horizontal edge is now time, running backwards from the corner; y and z as before
    assert texts[1] == "time 0.004 \u2192 0.001 s" or texts[1] == "w 0.004 \u2192 0.001 s", texts
    assert texts[2:] == ["y 0.01 \u2192 0.05 m", "z 0.01 \u2192 0.05 m"], texts
    assert [lab["kind"] for lab in labels] == ["corner", "edge", "edge", "edge"]
    # what the page keeps the labels clear of: the box's cut, in displayed units
    box = f.outline(w.state.matrix, w.c0)
    seg = np.unique(np.asarray(box.segments))
    want = np.asarray(box.points)[seg] * w.scene.scale
    got = np.asarray(w.scene.buffer.label_extent)
    np.testing.assert_allclose(np.sort(got, axis=0), np.sort(want, axis=0), atol=1e-12)


def _label_boxes(fig):
    """Window extents (pixels) of the static picture's box labels, their text boxes included."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    r = canvas.get_renderer()
    ax = fig.axes[0]
    return ax, [t.get_bbox_patch().get_window_extent(r) for t in ax.texts if t.get_gid() == "box-label"]


@pytest.mark.parametrize("rendering", RENDERINGS)
@pytest.mark.parametrize("steps", [0, 32, 11])
def test_static_labels_name_the_data_and_cover_none_of_it(rendering, steps):
    f = flame()
    st = turned(steps)
    fig = render_state(st, f, rendering=rendering, progress=False)
    ax, boxes = _label_boxes(fig)
    texts = [t.get_text() for t in ax.texts if t.get_gid() == "box-label"]
    assert len(boxes) == 4, texts
    if steps == 0:
        assert texts[1:] == ["x 0.01 \u2192 0.05 m", "y 0.01 \u2192 0.05 m", "z 0.01 \u2192 0.05 m"], texts
    assert not any("0.00" in t and "m" in t and "0.009" in t for t in texts), texts  # no padded grid
    # the box's cut, projected: no label box reaches into its rectangle
    box = f.outline(st.matrix, st.c0)
    pts = np.asarray(box.points)[np.unique(np.asarray(box.segments))] * (REFERENCE_RADIUS / f.size)
    xy = ax.transData.transform(perspective(pts)[0])
    x0, y0 = xy.min(axis=0)
    x1, y1 = xy.max(axis=0)
    for b, t in zip(boxes, texts):
        assert b.x1 <= x0 + 0.5 or b.x0 >= x1 - 0.5 or b.y1 <= y0 + 0.5 or b.y0 >= y1 - 0.5, (t, b, (x0, y0, x1, y1))
    # and no label box covers a pixel of the ray-cast image
    images = [im for im in ax.images if im.get_gid() == rendering]
    if rendering != "surface":
        (im,) = images
        a = np.asarray(im.get_array())[..., 3]
        rows, cols = np.nonzero(a > 0)
        (ex0, ex1, ey0, ey1) = im.get_extent()
        px = np.column_stack([ex0 + (cols + 0.5) / a.shape[1] * (ex1 - ex0),
                              ey1 - (rows + 0.5) / a.shape[0] * (ey1 - ey0)])
        ink = ax.transData.transform(px)
        for b, t in zip(boxes, texts):
            inside = (ink[:, 0] > b.x0) & (ink[:, 0] < b.x1) & (ink[:, 1] > b.y0) & (ink[:, 1] < b.y1)
            assert not inside.any(), (t, int(inside.sum()))


PLACE_SCRIPT = """
import { placeLabels } from "page:labels.js";
const out = INPUT.map((c) => placeLabels(c.items.map(([x, y, w, h, kind]) => ({ x, y, w, h, kind })), c.keep,
  c.width, c.height).map((b) => [b.left, b.top, b.free]));
console.log(JSON.stringify(out));
"""


def test_the_page_places_labels_by_the_static_pictures_rule():
    from page_node import run_page

    from rot4d_widget.keep.pictures.framing import place_labels

    rng = np.random.default_rng(5)
    cases = []
    for k in range(60):
        width, height = float(rng.integers(200, 700)), float(rng.integers(200, 600))
        x0, y0 = rng.uniform(0.1, 0.4) * width, rng.uniform(0.1, 0.4) * height
        keep = [x0, y0, x0 + rng.uniform(0.2, 0.5) * width, y0 + rng.uniform(0.2, 0.5) * height] if k % 7 else None
        items = []
        for _ in range(int(rng.integers(1, 7))):
            kind = "slice" if k % 5 == 0 else str(rng.choice(["corner", "edge"]))
            items.append([float(rng.uniform(0, width)), float(rng.uniform(0, height)), float(rng.integers(20, 160)),
                          float(rng.integers(10, 50)), kind])
        cases.append({"items": items, "keep": None if keep is None else dict(zip(("x0", "y0", "x1", "y1"), keep)),
                      "width": width, "height": height})
    page = run_page(PLACE_SCRIPT, cases)
    for c, got in zip(cases, page):
        keep = None if c["keep"] is None else tuple(c["keep"][k] for k in ("x0", "y0", "x1", "y1"))
        want = place_labels([tuple(i) for i in c["items"]], keep, c["width"], c["height"])
        assert [[float(a), float(b), bool(f)] for a, b, f in want] == [[float(a), float(b), bool(f)] for a, b, f in got]
        for (_x, _y, w, h, kind), (left, top, free) in zip(c["items"], want):
            if free and keep is not None and kind != "slice":  # a free place is clear of the extent
                assert left + w <= keep[0] or left >= keep[2] or top + h <= keep[1] or top >= keep[3]
