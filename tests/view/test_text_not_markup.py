"""Text from users and files is shown as text (issue 32), in the widget's HTML and in pictures.

Hostile strings go in through every text a user or a file supplies -- a field's name, long name and
units, its coordinates' units and dimension names (xarray), a state file's ``space_units`` and
``w_units``, a polytope's name and a 4OFF file's name, a user source's name, readout rows and key
actions, a keymap's custom action, a screenshot's note, an error quoting its input -- and every
HTML widget of the widget is parsed: only the package's own tags, no event handler, and the
hostile text there literally once unescaped.  Pictures (PNG, SVG, PDF, GIF frames) are drawn
with the same strings and a mathtext trap, without an exception, the text as written.

Before the fix (issue 32) the volume row put ``space_units`` into the readout unescaped: the
field and state-file cases failed, and every picture with ``$\\bad$`` raised ValueError.
"""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from html import unescape
from html.parser import HTMLParser

import ipywidgets
import matplotlib
import numpy as np
import pytest
import xarray as xr

from rot4d_widget import Polytope, SliceData, SourceAction, polytope
from rot4d_widget.core.keymap import DEFAULT_KEYMAP, Action
from rot4d_widget.sources.field.container import Field4D
from test_widget import down, up

pytestmark = pytest.mark.usefixtures("recording_comms")

IMG = '<img src=x onerror="window.__rot4d_pwned=1">'
SCRIPT = "<script>window.__rot4d_pwned=1</script>"
SVG = '"><svg onload=window.__rot4d_pwned=1>'
MATH = "$\\bad$"
HOSTILE = (IMG, SCRIPT, SVG)

#: The tags the package's own HTML uses (view/markup.py)
OWN_TAGS = {"div", "b", "table", "tr", "td", "span", "i", "svg", "line", "text", "rect", "g", "title", "br",
            "small", "style", "kbd"}


class _Page(HTMLParser):
    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.tags, self.handlers, self.text = [], [], []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        self.handlers += [f"<{tag} {k}=...>" for k, v in attrs
                          if k.startswith("on") or "javascript:" in (v or "").lower()]

    def handle_data(self, data):
        self.text.append(data)


def parsed(value: str) -> _Page:
    page = _Page()
    page.feed(value)
    page.close()
    return page


def html_widgets(widget):
    """Every ipywidgets.HTML under ``widget`` (its children, recursively)."""
    out, todo, seen = [], [widget], set()
    while todo:
        x = todo.pop()
        if id(x) in seen:
            continue
        seen.add(id(x))
        if isinstance(x, ipywidgets.HTML):
            out.append(x)
        todo += list(getattr(x, "children", ()))
    return out


def shown_text(w) -> str:
    """The text of every HTML widget of ``w``, checked to be the package's own markup only."""
    texts = []
    for h in html_widgets(w):
        page = parsed(h.value)
        assert set(page.tags) <= OWN_TAGS, f"tags not the package's own: {set(page.tags) - OWN_TAGS}"
        assert not page.handlers, page.handlers
        texts.append("".join(page.text))
    return "\n".join(texts)


def assert_literal(text: str, *wanted) -> None:
    for s in wanted:
        assert s in text, f"{s!r} not shown literally"


# ----------------------------------------------------------------------------- fields
def hostile_dataarray(units=IMG, name=SCRIPT, long_name=SVG, coord_units=IMG + MATH, dims=None):
    n = 6
    dims = dims or ("time", "x", "y", "z")
    t = np.linspace(0.0, 1.0, n)
    a = np.fromfunction(lambda i, j, k, m: ((j - 2.5) ** 2 + (k - 2.5) ** 2 + (m - 2.5) ** 2) / 9.0 + i * 0.1,
                        (n, n, n, n)).astype("float32")
    da = xr.DataArray(a, dims=dims, coords={d: t for d in dims}, name=name,
                      attrs={"units": units, "long_name": long_name})
    for d in dims:
        da[d].attrs["units"] = coord_units
    return da


def test_a_field_s_names_and_units_from_a_file_are_text_in_every_row(make):
    f = Field4D.from_xarray(hostile_dataarray(), levels=0.5)
    w = make(f)
    w.press("4")  # turned: the volume row counts w and names its units too
    text = shown_text(w)
    assert_literal(text, IMG, SCRIPT, SVG, IMG + MATH)
    assert "volume" in text


def test_dimension_names_are_text(make):
    dims = (SCRIPT, IMG, SVG, "<b>z</b>")
    f = Field4D.from_xarray(hostile_dataarray(dims=dims), x=IMG, y=SVG, z="<b>z</b>", w=SCRIPT, levels=0.5)
    w = make(f)
    assert_literal(shown_text(w), IMG, SVG, "<b>z</b>")


def test_a_state_file_s_units_are_text(make, tmp_path):
    da = hostile_dataarray(units="K", name="T", long_name="temperature", coord_units="m")
    da.to_dataset().to_netcdf(tmp_path / "flame.nc", engine="scipy")
    w = make(Field4D.open(tmp_path / "flame.nc", "T", levels=0.5))
    path = tmp_path / "view.json"
    w.save_state(path)
    d = json.loads(path.read_text())
    found = []

    def poison(node):  # every units field the file has, wherever the format keeps it
        if isinstance(node, dict):
            for k in list(node):
                if k in ("space_units", "w_units", "units"):
                    node[k] = IMG if k == "space_units" else SVG if k == "w_units" else SCRIPT
                    found.append(k)
                else:
                    poison(node[k])
        elif isinstance(node, list):
            for x in node:
                poison(x)

    poison(d)
    assert {"space_units", "w_units", "units"} <= set(found)
    path.write_text(json.dumps(d))
    from rot4d_widget.view.widget import Rot4DWidget

    again = Rot4DWidget.from_state(path, _autotick=False)
    try:
        again.press("4")
        assert_literal(shown_text(again), IMG, SVG, SCRIPT)
    finally:
        again.close()


# ----------------------------------------------------------------------------- polytopes and user sources
def test_polytope_names_and_4off_file_names_are_text(make, tmp_path):
    p = polytope("5-cell")
    named = Polytope(p.vertices, p.faces, p.cells, name=IMG)
    assert_literal(shown_text(make(named)), IMG)
    off = tmp_path / (SVG + ".off")  # a file's name becomes the polytope's
    off.write_text(p.to_off())
    assert_literal(shown_text(make(Polytope.from_off(off))), SVG)


class HostileSource:
    """A user's source whose every text is hostile."""

    size = 1.0
    n_groups = 1
    name = SCRIPT

    def __init__(self):
        self.actions = {"o": SourceAction(IMG, SVG, lambda sign: True)}

    def slice(self, matrix, c0):
        p = np.array([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]]) @ np.asarray(matrix)[:3, :3].T * 0.8
        return SliceData.build(p, segments=[[0, 1], [1, 2], [2, 0]], triangles=[[0, 1, 2]],
                               readout=((IMG, SVG), ("note", SCRIPT)))

    def describe(self):
        return {"kind": SVG}


def test_a_user_source_s_name_rows_and_actions_are_text(make):
    w = make(HostileSource())
    w.press("o")  # its action: the "last" row shows its name
    w.keypad = True
    text = shown_text(w)
    assert_literal(text, IMG, SVG, SCRIPT)


def test_a_keymap_s_custom_action_is_text(make):
    keymap = DEFAULT_KEYMAP.extended({"o": Action("custom", name=IMG, sign=1, text=SVG)})
    w = make("5-cell", keymap=keymap)
    assert_literal(shown_text(w), IMG, SVG)


def test_a_note_is_text(make):
    w = make("5-cell")
    w._painter.set_note(f"saved {IMG}{SVG}.png")
    assert_literal(shown_text(w), f"saved {IMG}{SVG}.png")


class QuotingSource(HostileSource):
    """A source whose slice fails, once told to, with an error that quotes its input."""

    broken = False

    def slice(self, matrix, c0):
        if self.broken:
            raise ValueError(f"Expected a level among 1, 2, got {IMG}{SCRIPT}{SVG}")
        return super().slice(matrix, c0)


def test_an_error_quoting_input_is_text(make):
    src = QuotingSource()
    w = make(src)
    src.broken = True
    down(w, "4", t=1.0)  # a key in the page: the error goes under the readout
    up(w, "4", t=1.05)
    errors = "".join(o.get("text", "") for o in w.errors.outputs)
    assert IMG in errors and SCRIPT in errors  # a stream output: the front end shows it as text
    assert all(o["output_type"] == "stream" for o in w.errors.outputs)
    shown_text(w)


# ----------------------------------------------------------------------------- pictures
@pytest.fixture
def flame(make):
    f = Field4D.from_xarray(hostile_dataarray(units=IMG + MATH, name=SCRIPT + MATH, long_name=SVG + MATH,
                                              coord_units=MATH + IMG), levels=0.5)
    w = make(f)
    w.press("4")
    return w


@pytest.mark.parametrize("suffix", [".png", ".svg", ".pdf"])
def test_pictures_draw_hostile_text_and_mathtext_traps_as_written(flame, tmp_path, suffix):
    path = tmp_path / f"picture{suffix}"
    with matplotlib.rc_context({"svg.fonttype": "none"}):  # SVG text as <text>, to read it back
        flame.render(path)
    assert path.stat().st_size > 0
    if suffix == ".svg":
        root = ET.parse(path).getroot()  # well-formed XML
        tags = {el.tag.rsplit("}", 1)[-1] for el in root.iter()}
        assert not tags & {"script", "img", "foreignObject", "iframe"}
        assert not [k for el in root.iter() for k in el.attrib if k.lower().startswith("on")]
        text = "\n".join("".join(el.itertext()) for el in root.iter() if el.tag.endswith("}text"))
        assert_literal(unescape(text), MATH + IMG, SVG + MATH)


def test_pictures_stay_literal_under_usetex(flame, tmp_path):
    """A user's ``text.usetex`` would hand file text to LaTeX (which reads files): never."""
    with matplotlib.rc_context({"text.usetex": True, "svg.fonttype": "none"}):
        flame.render(tmp_path / "p.svg")
    assert MATH + IMG in unescape((tmp_path / "p.svg").read_text())


def test_an_animation_draws_hostile_text_as_written(flame, tmp_path):
    from rot4d_widget.keep.animation import render_animation

    rec = flame.recording
    n = render_animation(rec, source=flame.source, path=tmp_path / "a.gif", progress=False, size=(160, 120))
    assert n >= 2 and (tmp_path / "a.gif").stat().st_size > 0


def test_a_recording_s_fields_are_text_when_replayed(make, tmp_path):
    w = make(HostileSource())
    w.press("o")
    w.press("4")
    path = tmp_path / "keys.json"
    w.recording.save(path)
    again = make(HostileSource())
    again.replay(path)
    again.press("o")  # the replayed keymap's action, shown as the last step
    assert_literal(shown_text(again), IMG, SVG)
