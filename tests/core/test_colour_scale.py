"""The colour scale: `cmap` / `clim` checks and colours (core.colours), the widget's traits, and the
colour bar in the readout."""

from __future__ import annotations

import numpy as np
import pytest

from rot4d_widget.core import colours, text


# -- core.colours ---------------------------------------------------------------------------------
def test_default_level_colours_are_todays_viridis_by_rank():
    from matplotlib import colormaps

    levels = [0.3, -0.2, 0.9]
    want = np.asarray(colormaps["viridis"]([0.52, 0.12, 0.92]))[:, :3]
    np.testing.assert_allclose(colours.level_colors(levels, -1.0, 1.0), want)
    np.testing.assert_allclose(colours.level_colors([0.1], -1.0, 1.0), np.asarray(colormaps["viridis"]([0.75]))[:, :3])


def test_level_colours_take_the_cmap_and_by_value_the_limits():
    from matplotlib import colormaps

    got = colours.level_colors([0.0, 5.0, 20.0], 0.0, 10.0, "magma", by_value=True)
    np.testing.assert_allclose(got, np.asarray(colormaps["magma"]([0.0, 0.5, 1.0]))[:, :3])  # clamped above
    assert not np.allclose(colours.level_colors([0.0, 1.0], 0, 1, "magma"), colours.level_colors([0.0, 1.0], 0, 1))


@pytest.mark.parametrize("bad, exc, match", [
    ("virdis", ValueError, r"matplotlib colour map name.*did you mean 'viridis'.*sorted\(matplotlib.colormaps\)"),
    ("no such map at all", ValueError, r"sorted\(matplotlib.colormaps\).*'no such map at all'"),
    (3, TypeError, r"`cmap` to be a matplotlib colour map name \(a str; list them with sorted\(matplotlib.colormaps\)"),
    (None, TypeError, "colour map name"),
])
def test_bad_cmap_names_how_to_list_them(bad, exc, match):
    with pytest.raises(exc, match=match):
        colours.check_cmap(bad)


@pytest.mark.parametrize("bad, exc", [
    ((1.0, 1.0), ValueError), ((2.0, 1.0), ValueError), ((0.0, float("nan")), ValueError),
    ((float("-inf"), 1.0), ValueError), (3.0, TypeError), ("0,1", TypeError), ((0, 1, 2), TypeError),
    ((True, 2), TypeError), (("0", "1"), TypeError),
])
def test_bad_clim_names_what_is_allowed(bad, exc):
    with pytest.raises(exc, match=r"`clim` to be None \(the data's range\) or \(lo, hi\), two finite numbers "
                                  r"with lo < hi"):
        colours.check_clim(bad)


def test_good_clim_and_stops():
    assert colours.check_clim(np.array([1, 2])) == (1.0, 2.0)
    assert colours.check_clim(None) is None
    assert colours.cmap_stops("viridis", 2) == ("#440154", "#fde725")
    assert colours.cmap_stops("viridis") != colours.cmap_stops("magma")


# -- the widget's traits --------------------------------------------------------------------------
def _field(**kw):
    from rot4d_widget.sources.field.container import Field4D

    x = np.linspace(-1.0, 1.0, 8)
    X, Y, Z, W = np.meshgrid(x, x, x, x, indexing="ij")
    return Field4D(X**2 + Y**2 + Z**2 + W**2, axes="xyzw", **{"name": "r2", "units": "m²", **kw})


@pytest.fixture
def widget():
    from rot4d_widget import Rot4DWidget

    made = []

    def make(source=None, **kw):
        w = Rot4DWidget(_field() if source is None else source, _autotick=False, **kw)
        made.append(w)
        return w

    yield make
    for w in made:
        w.close()


def test_traits_default_to_todays_colours(widget):
    w = widget(levels=[0.5, 1.0, 2.0])
    assert (w.cmap, w.clim) == ("viridis", None)
    np.testing.assert_allclose(w._painter.colours()[0], colours.level_colors([0.5, 1.0, 2.0], *w.source.data_range))


def test_cmap_and_clim_recolour_the_surfaces(widget):
    w = widget(levels=[0.5, 1.0])
    sent = w.scene.update_id
    w.cmap = "magma"
    assert w.scene.update_id > sent  # a new picture
    np.testing.assert_allclose(w._painter.colours()[0], colours.level_colors([0.5, 1.0], 0, 1, "magma"))
    w.clim = [0.0, 2.0]
    assert w.clim == (0.0, 2.0)
    np.testing.assert_allclose(w._painter.colours()[0],
                               colours.level_colors([0.5, 1.0], 0.0, 2.0, "magma", by_value=True))


@pytest.mark.parametrize("name, bad, exc, match", [
    ("cmap", "virdis", ValueError, r"did you mean 'viridis'.*sorted\(matplotlib.colormaps\)"),
    ("cmap", 7, TypeError, r"colour map name"),
    ("clim", (1.0, 0.0), ValueError, r"two finite numbers with lo < hi"),
    ("clim", (0.0, float("inf")), ValueError, r"two finite numbers with lo < hi"),
    ("clim", "0 1", TypeError, r"None \(the data's range\) or \(lo, hi\)"),
])
def test_bad_values_are_refused_and_the_trait_kept(widget, name, bad, exc, match):
    w = widget(levels=[0.5])
    before = getattr(w, name)
    with pytest.raises(exc, match=match):
        setattr(w, name, bad)
    assert getattr(w, name) == before
    from rot4d_widget import Rot4DWidget

    with pytest.raises(exc, match=match):
        Rot4DWidget(_field(), **{name: bad})


def test_saved_and_loaded_with_the_state(widget, tmp_path):
    import warnings

    w = widget(levels=[0.5], cmap="magma", clim=(0.0, 3.0))
    path = tmp_path / "s.json"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # an in-memory field: "not rebuildable"
        doc = w.save_state(path)
    assert (doc["settings"]["cmap"], doc["settings"]["clim"]) == ("magma", [0.0, 3.0])
    w.cmap, w.clim = "viridis", None
    w.load_state(path)
    assert (w.cmap, w.clim) == ("magma", (0.0, 3.0))
    from rot4d_widget import Rot4DWidget

    w2 = Rot4DWidget.from_state(path, source=w.source, _autotick=False)
    try:
        assert (w2.cmap, w2.clim) == ("magma", (0.0, 3.0))
        w.clim = None  # None (the data's range) is a value that is saved and loaded too
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            w.save_state(path)
        w2.load_state(path)
        assert w2.clim is None
    finally:
        w2.close()


# -- the colour bar in the readout ----------------------------------------------------------------
def _bar(w) -> str:
    html = w.readout.value
    assert html.count("class='rot4d-cbar'") == 1
    return html[html.index("<div class='rot4d-cbar'"):html.index("</td>", html.index("<div class='rot4d-cbar'"))]


def _marks(bar):
    import re

    found = re.findall(r"class='rot4d-cbar-mark' style='left:([0-9.]+)%;border-color:(#[0-9a-f]{6})'", bar)
    return [(float(a), b) for a, b in found]


def test_the_bar_names_the_variable_its_units_the_limits_and_marks_each_level(widget):
    w = widget(levels=[1.0, 2.0, 3.0], clim=(0.0, 4.0))
    bar = _bar(w)
    assert "r2 [m²]" in bar
    assert "<span>0</span><span>4 m²</span>" in bar  # ticks at lo and hi, in the data's units
    marks = _marks(bar)
    assert [m[0] for m in marks] == [25.0, 50.0, 75.0]  # (level - lo) / (hi - lo)
    assert [m[1] for m in marks] == [colours.hex_color(c) for c in w._painter.colours()[0]]  # the surfaces' colours
    assert "title='level 2 m²'" in bar


def test_the_bar_spans_the_data_range_when_clim_is_none(widget):
    w = widget(levels=[1.0])
    lo, hi = w.source.data_range
    bar = _bar(w)
    assert f"<span>{text.number_text(lo, hi)}</span><span>{text.number_text(hi, hi)} m²</span>" in bar
    assert _marks(bar)[0][0] == pytest.approx(100 * (1.0 - lo) / (hi - lo), abs=0.01)


def test_a_level_outside_clim_is_marked_at_the_end_and_says_so(widget):
    w = widget(levels=[0.5, 3.5], clim=(1.0, 3.0))
    bar = _bar(w)
    assert [m[0] for m in _marks(bar)] == [0.0, 100.0]
    assert "(below the scale)" in bar and "(above the scale)" in bar


def test_cmap_changes_the_gradient_stops(widget):
    w = widget(levels=[1.0])
    before = _bar(w)
    assert "data-cmap='viridis'" in before and "#440154 0.0%" in before and "#fde725 100.0%" in before
    w.cmap = "gray"
    after = _bar(w)
    assert "data-cmap='gray'" in after and "#000000 0.0%" in after and "#ffffff 100.0%" in after
    assert "#440154" not in after


def test_long_name_when_the_field_keeps_it(widget):
    f = _field()
    f.long_name = "squared radius"  # what from_xarray would keep of attrs["long_name"]
    assert "squared radius [m²]" in _bar(widget(f, levels=[1.0]))


def test_polytopes_have_no_bar(widget):
    from rot4d_widget import Rot4DWidget

    w = Rot4DWidget("24-cell", _autotick=False)
    try:
        assert "rot4d-cbar" not in w.readout.value
    finally:
        w.close()


def test_a_stack_of_a_field_keeps_the_scale_with_black_marks(widget):
    w = widget(levels=[1.0, 2.0], slices=3, clim=(0.0, 4.0))
    assert [m for m in _marks(_bar(w))] == [(25.0, "#000000"), (50.0, "#000000")]
