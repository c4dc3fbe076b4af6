"""A field from xarray in the page: the readout in the data's units (cubic metres, seconds) and
parallel slices labelled by their time (issue 19); screenshots kept in test-artifacts/."""

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
da = xr.DataArray(f, dims=("time", "z", "y", "x"), name="phi", attrs={"units": "m2"},
                  coords={"time": ("time", t, {"units": "s"}), "z": ("z", x, {"units": "m"}),
                          "y": ("y", x, {"units": "m"}), "x": ("x", x, {"units": "m"})})
field = Field4D.from_xarray(da, w="time", levels=0.0)
w = Rot4DWidget(field, width=420, height=360)
w''',
    '''\
s = Rot4DWidget(Field4D.from_xarray(da, w="time", levels=0.0), slices=3, spacing=30.0, arrangement="grid",
                width=420, height=360)
s''',
]


def test_a_field_s_readout_and_stack_labels_are_in_the_data_s_units(jupyter_server, page, artifacts):
    if jupyter_server.kind != "lab":
        pytest.skip("JupyterLab only (the readout is the same HTML in Notebook 7)")
    write_notebook(jupyter_server.root / "units.ipynb", CELLS)
    jp = JupyterPage(page, jupyter_server, "units.ipynb").open()
    jp.run_all()
    for var, name in (("w", "units-field"), ("s", "units-stack")):
        sel = _canvas(jp, var)
        jp.page.locator(sel).scroll_into_view_if_needed()
        side = jp.page.locator(".rot4d-side").nth(0 if var == "w" else 1)
        text = side.inner_text()
        if var == "w":
            assert "m\u00b3" in text and "phi [m2]" in text and "s per m" in text, text
            assert "30.0000 s" in text, text  # c0 is the data's time: the middle, 30 s
        else:
            # the spacing in seconds, like c0 (issue 37); each slice named by its dim, time
            for label in ("time 0 s", "time 30 s", "time 60 s", "\u0394 = 30 s", "vol 11.35 m\u00b3"):
                assert label in text, text
        box, sbox = jp.page.locator(sel).bounding_box(), side.bounding_box()
        clip = {"x": box["x"], "y": min(box["y"], sbox["y"]), "width": sbox["x"] + sbox["width"] - box["x"],
                "height": max(box["y"] + box["height"], sbox["y"] + sbox["height"]) - min(box["y"], sbox["y"])}
        jp.page.screenshot(path=str(artifacts / f"{name}.png"), clip=clip)
