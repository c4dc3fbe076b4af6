"""Text from files and users is shown as text in the page (issue 32), in JupyterLab 4 and Notebook 7.

Three payloads, each of which sets ``window.__rot4d_pwned`` if the page ever treats it as markup
(an ``<img onerror>``, a ``<script>`` and an ``"><svg onload>`` breaking out of an attribute), go
in through every text a user or a file supplies: a field's name, long name, units, coordinate
units and dimension names (xarray; the readout, the colour bar and the box labels), a state
file's ``space_units`` / ``w_units`` / ``units``, a polytope's name and a 4OFF file's name, a
user source's name, readout rows, key actions (help and key pad), a keymap's custom action, a
screenshot's file name (the note) and an error that quotes its input (the errors area).  The
page must run no handler and show each text literally.  Then a raw ``ipywidgets.HTML`` with the
same payload must set the flag: the check can fail in this browser.

Before the fix the volume row ran the field's ``space_units`` (the flag was set by the readout).
"""

from __future__ import annotations

import time

import pytest

from jupyter_page import JupyterPage, write_notebook
from test_widget_browser import _canvas, _hover

pytestmark = pytest.mark.browser

IMG = '<img src=x onerror="window.__rot4d_pwned=(window.__rot4d_pwned||0)+1">'
SCRIPT = "<script>window.__rot4d_pwned=(window.__rot4d_pwned||0)+1</script>"
SVG = '"><svg onload=window.__rot4d_pwned=(window.__rot4d_pwned||0)+1>'

CELLS = [
    f'''\
import json, pathlib
import numpy as np
import xarray as xr
from rot4d_widget import Rot4DWidget, Field4D, Polytope, SliceData, SourceAction, polytope
from rot4d_widget.core.keymap import DEFAULT_KEYMAP, Action
IMG, SCRIPT, SVG = {IMG!r}, {SCRIPT!r}, {SVG!r}

def flame(units, name, long_name, coord_units, dims=("time", "x", "y", "z")):
    n = 8
    t = np.linspace(0.0, 1.0, n)
    a = np.fromfunction(lambda i, j, k, m: ((j - 3.5) ** 2 + (k - 3.5) ** 2 + (m - 3.5) ** 2) / 12.0 + i * 0.1,
                        (n, n, n, n)).astype("float32")
    da = xr.DataArray(a, dims=dims, coords={{d: t for d in dims}}, name=name,
                      attrs={{"units": units, "long_name": long_name}})
    for d in dims:
        da[d].attrs["units"] = coord_units
    return da

da = flame(IMG, SCRIPT, SVG, SVG, dims=("time", IMG, SVG, "z"))
w = Rot4DWidget(Field4D.from_xarray(da, x=IMG, y=SVG, z="z", w="time", levels=0.5), width=360, height=300)
w.press("4")
w''',
    '''\
clean = flame("K", "T", "temperature", "m")
clean.to_dataset().to_netcdf("flame.nc", engine="scipy")
Rot4DWidget(Field4D.open("flame.nc", "T", levels=0.5)).save_state("view.json")
d = json.loads(pathlib.Path("view.json").read_text())
def poison(node):
    if isinstance(node, dict):
        for k in list(node):
            if k in ("space_units", "w_units", "units"):
                node[k] = {"space_units": IMG, "w_units": SVG, "units": SCRIPT}[k]
            else:
                poison(node[k])
    elif isinstance(node, list):
        for x in node:
            poison(x)
poison(d)
pathlib.Path("view.json").write_text(json.dumps(d))
s = Rot4DWidget.from_state("view.json", width=360, height=300)
s.press("4")
s''',
    '''\
p5 = polytope("5-cell")
pathlib.Path(SVG + ".off").write_text(p5.to_off())
p = Rot4DWidget(Polytope(p5.vertices, p5.faces, p5.cells, name=IMG), width=300, height=240)
o = Rot4DWidget(Polytope.from_off(SVG + ".off"), width=300, height=240)
widgets_shown = [p, o]
p''',
    "o",
    '''\
class Hostile:
    size = 1.0
    n_groups = 1
    name = SCRIPT
    broken = False

    def __init__(self):
        self.actions = {"o": SourceAction(IMG, SVG, lambda sign: True)}

    def slice(self, matrix, c0):
        if self.broken:
            raise ValueError(f"Expected a level among 1, 2, got {IMG}{SCRIPT}{SVG}")
        q = np.array([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]]) @ np.asarray(matrix)[:3, :3].T * 0.8
        return SliceData.build(q, segments=[[0, 1], [1, 2], [2, 0]], triangles=[[0, 1, 2]],
                               readout=((IMG, SVG), ("note", SCRIPT)))

    def describe(self):
        return {"kind": SVG}

src = Hostile()
keymap = DEFAULT_KEYMAP.extended({"e": Action("custom", name=SVG, sign=1, text=IMG)})
u = Rot4DWidget(src, keymap=keymap, keypad=True, width=300, height=240)
u''',
]

PWNED = "() => window.__rot4d_pwned || 0"


def _shown(jp, cls):
    """The text of the side panel (readout, help, errors) of the widget whose canvas has class ``cls``."""
    return jp.page.evaluate(
        "(cls) => { const c = document.querySelector('.' + cls); let n = c;"
        " while (n && !(n.querySelector && n.querySelector('.rot4d-side'))) n = n.parentElement;"
        " const side = n ? n.querySelector('.rot4d-side') : null;"
        " return side ? side.textContent : ''; }", cls)


def _labels(jp, cls):
    return jp.page.evaluate(
        "(cls) => Array.from(document.querySelectorAll('.' + cls + ' .rot4d-label')).map(e => e.textContent)",
        cls)


def test_hostile_text_from_files_and_users_is_shown_as_text(jupyter_server, page, artifacts):
    write_notebook(jupyter_server.root / "hostile_text.ipynb", CELLS)
    jp = JupyterPage(page, jupyter_server, "hostile_text.ipynb").open()
    jp.run_all()
    cls = {}
    for var in ("w", "s", "p", "o", "u"):
        _canvas(jp, var)
        cls[var] = jp.kernel(f"print({var}.scene.canvas_class)").strip()
    # the key pad's and the help's rows, a key of the user's source, a screenshot whose name is hostile,
    # and an error quoting its input
    sel_u = _canvas(jp, "u")
    jp.page.locator(sel_u).scroll_into_view_if_needed()
    _hover(jp, sel_u)
    jp.page.keyboard.press("o")  # its action: the "last" row names it
    assert jp.wait_for(lambda: "last</td><td>&lt;img" in jp.kernel("print(u.readout.value)"), timeout=30)
    jp.kernel("u.screenshot(IMG + '.png')")
    assert jp.wait_for(lambda: IMG + ".png" in _shown(jp, cls["u"]), timeout=30)
    jp.kernel("src.broken = True")
    _hover(jp, sel_u)
    jp.page.keyboard.press("4")
    assert jp.wait_for(lambda: "Expected a level" in _shown(jp, cls["u"]), timeout=30)
    time.sleep(1.0)  # any handler that would run has run

    assert jp.page.evaluate(PWNED) == 0, "a handler from a file's or a user's text ran"
    field = _shown(jp, cls["w"])
    for text in (IMG, SCRIPT, SVG):
        assert text in field, f"{text!r} not shown literally in the field's readout"
    assert any(IMG in t for t in _labels(jp, cls["w"])) and any(SVG in t for t in _labels(jp, cls["w"]))
    state = _shown(jp, cls["s"])
    for text in (IMG, SVG, SCRIPT):
        assert text in state, f"{text!r} from the state file not shown literally"
    assert IMG in _shown(jp, cls["p"]) and SVG in _shown(jp, cls["o"])
    user = _shown(jp, cls["u"])
    for text in (IMG, SCRIPT, SVG, IMG + ".png"):
        assert text in user, f"{text!r} not shown literally in the user source's panel"
    assert jp.page.evaluate("() => document.querySelectorAll('.jp-OutputArea img, .jp-OutputArea script').length") == 0
    jp.page.locator(".rot4d-side").first.scroll_into_view_if_needed()
    jp.page.screenshot(path=str(artifacts / f"text-not-markup-{jupyter_server.kind}.png"))

    # the control: the same payload as raw HTML does run here, so the check above could fail
    jp.kernel("import ipywidgets\nu.children = (*u.children, ipywidgets.HTML(IMG))")
    assert jp.wait_for(lambda: jp.page.evaluate(PWNED) > 0, timeout=30), "the control payload did not run"
