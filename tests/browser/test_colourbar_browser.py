"""A field's colour bar in the page (issue 21): the cmap's gradient over clim, the variable's name
and units, ticks at both ends and a mark per iso level, in JupyterLab; a screenshot of the view
and its readout kept in test-artifacts/colourbar-field.png."""

from __future__ import annotations

import pytest

from jupyter_page import JupyterPage, write_notebook
from test_widget_browser import _canvas

pytestmark = pytest.mark.browser

CELLS = [
    '''\
import numpy as np, xarray as xr
from rot4d_widget import Field4D, Rot4DWidget
x = np.linspace(-2, 2, 25); t = np.linspace(0.0, 60.0, 13)
r = 0.6 + 0.8 * np.sin(np.pi * t / 60.0)  # a sphere growing then shrinking, metres
f = r[:, None, None, None] ** 2 - (x[None, None, None, :] ** 2 + x[None, None, :, None] ** 2 + x[None, :, None, None] ** 2)
da = xr.DataArray(f, dims=("time", "z", "y", "x"), name="phi", attrs={"units": "m2", "long_name": "potential"},
                  coords={"time": ("time", t, {"units": "s"}), "z": ("z", x, {"units": "m"}),
                          "y": ("y", x, {"units": "m"}), "x": ("x", x, {"units": "m"})})
field = Field4D.from_xarray(da, w="time", levels=[-1.0, 0.0])
w = Rot4DWidget(field, width=420, height=360, cmap="magma", clim=(-4.0, 1.0))
w''',
]


def test_a_field_shows_its_colour_bar(jupyter_server, page, artifacts):
    if jupyter_server.kind != "lab":
        pytest.skip("JupyterLab only (the readout is the same HTML in Notebook 7)")
    write_notebook(jupyter_server.root / "colourbar.ipynb", CELLS)
    jp = JupyterPage(page, jupyter_server, "colourbar.ipynb").open()
    jp.run_all()
    sel = _canvas(jp, "w")
    jp.page.locator(sel).scroll_into_view_if_needed()
    side = jp.page.locator(".rot4d-side").nth(0)
    bar = side.locator(".rot4d-cbar")
    bar.wait_for()
    label = bar.locator(".rot4d-cbar-label").inner_text()
    # the field keeps xarray's name; its long_name too once Field4D.from_xarray keeps it
    assert label in ("phi [m2]", "potential [m2]"), label
    ticks = bar.locator(".rot4d-cbar-ticks").inner_text().split()
    assert ticks == ["-4", "1", "m2"], ticks
    marks = bar.locator(".rot4d-cbar-mark")
    assert marks.count() == 2
    # each level where its value lies: -1 at 60 %, 0 at 80 % of the bar's width
    strip = bar.locator(".rot4d-cbar-bar").bounding_box()
    for i, want in enumerate((0.6, 0.8)):
        m = marks.nth(i).bounding_box()
        assert abs(m["x"] + m["width"] / 2 - (strip["x"] + want * strip["width"])) < 4, (i, m, strip)
    image = bar.locator(".rot4d-cbar-bar").evaluate("e => getComputedStyle(e).backgroundImage")
    assert image.startswith("linear-gradient") and "rgb(0, 0, 4)" in image, image  # magma's low end
    box, sbox = jp.page.locator(sel).bounding_box(), side.bounding_box()
    clip = {"x": box["x"], "y": min(box["y"], sbox["y"]), "width": sbox["x"] + sbox["width"] - box["x"],
            "height": max(box["y"] + box["height"], sbox["y"] + sbox["height"]) - min(box["y"], sbox["y"])}
    jp.page.screenshot(path=str(artifacts / "colourbar-field.png"), clip=clip)
