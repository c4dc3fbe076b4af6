"""The page's ray-cast renderings, kernel side (issue 21): the atlas the shader reads, the colour
table, the one message per update, the `rendering` and `sections` traits and their keys.

The shader's pictures are compared with the static renders in the browser
(tests/browser/test_volume_browser.py); here: what travels, checked against an independent
reading of the grid (a loop over nodes, matplotlib's own colour map, the field's `sample`).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from rot4d_widget.core import renderings
from rot4d_widget.sources.field.container import Field4D
from rot4d_widget.view import volume_layer as vl
from test_widget import down, up
from test_widget_fields import ball_field, settle

pytestmark = pytest.mark.usefixtures("recording_comms")


def blob(**kw):
    x = np.linspace(-1.0, 1.0, 12)
    X, Y, Z, T = np.meshgrid(x, x, x, x, indexing="ij")
    f = np.exp(-((X - 0.3) ** 2 + Y ** 2 + Z ** 2 + T ** 2) * 4.0)
    return Field4D(f, axes="xyzw", extent=[(-1.0, 1.0)] * 4, name="blob", units="kg/m3",
                   **{"resolution": 20, "coarse_resolution": 10, **kw})


# -- the atlas, the colour table ------------------------------------------------------------------
def atlas_value(atlas, place, shape, i, j, k):
    """(luminance, alpha) the shader reads for node (i, j, k): tile k at row k // cols, column k % cols."""
    u0, v0, cols = place
    nx, ny, _ = shape
    return tuple(atlas[v0 + (k // cols) * ny + j, u0 + (k % cols) * nx + i])


def test_every_node_is_where_the_shader_reads_it():
    rng = np.random.default_rng(1)
    grids = [rng.uniform(-1.0, 3.0, size=s).astype(np.float32) for s in ((7, 5, 11), (4, 9, 3), (6, 6, 2))]
    grids[1][2, 3, 1] = np.nan
    atlas, places = vl.pack_atlas(grids, (0.0, 2.0))
    for g, place in zip(grids, places):
        for i, j, k in np.ndindex(*g.shape):
            lum, alpha = atlas_value(atlas, place, g.shape, i, j, k)
            if np.isnan(g[i, j, k]):
                assert alpha == 0
                continue
            assert alpha == 255
            assert lum == int(np.rint(np.clip((g[i, j, k] - 0.0) / 2.0, 0.0, 1.0) * 255.0)), (i, j, k)


def test_the_atlas_stays_within_a_webgl1_texture_and_says_when_it_cannot():
    big = [np.zeros((64, 64, 64), dtype=np.float32)] * 40
    atlas, places = vl.pack_atlas(big, (0.0, 1.0))
    assert max(atlas.shape[:2]) <= vl.ATLAS_MAX
    tiles = {(u0, v0) for u0, v0, _ in places}
    assert len(tiles) == 40  # no two grids share a place
    with pytest.raises(ValueError, match="sample them more coarsely"):
        vl.pack_atlas([np.zeros((128, 128, 128), dtype=np.float32)] * 40, (0.0, 1.0))


@pytest.mark.parametrize("cmap", ["viridis", "magma_r", "coolwarm"])
def test_the_colour_table_is_matplotlibs(cmap):
    from matplotlib import colormaps

    table = vl.colour_table(cmap)
    x = np.random.default_rng(2).uniform(0.0, 1.0, 200)
    # the shader's lookup: entry min(floor(256 x), 255)
    got = table[np.minimum(np.floor(x * 256.0).astype(int), 255), :3] / 255.0
    np.testing.assert_allclose(got, np.asarray(colormaps[cmap](x))[:, :3], atol=0.5 / 255 + 1e-9)


# -- the widget: one message, the cut's grid and place ---------------------------------------------
def test_a_mip_view_sends_the_cut_grid_with_the_rows_in_one_message(make, recording_comms):
    f = blob()
    w = make(f, c0=0.1, rendering="mip", clim=(0.0, 1.0))
    recording_comms.clear()
    w.press("4")  # a step that moves w: a new cut
    msgs = [d for cid, d, *_ in recording_comms if cid == w.scene.buffer_model_id
            and "state" in d.get("data", d)]
    states = [d.get("data", d)["state"] for d in msgs]
    assert len(states) == 1 and {"array", "_rot4d_volume", "_rot4d_seq"} <= set(states[0])
    v = w.scene.buffer.volume
    assert v["n_boxes"] == 1 and v["mode"] == vl.MODES["mip"]
    # the grid is the field's cut at this state, placed at the view's scale
    g = f.sample(w.state.matrix, w.c0)
    boxes = np.frombuffer(v["boxes"], dtype="<f4").reshape(-1, 12)
    np.testing.assert_allclose(boxes[0, 0:3], w.scene.scale * np.asarray(g.origin), rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(boxes[0, 3:6], w.scene.scale * g.spacing * (np.asarray(g.values.shape) - 1), rtol=1e-6)
    assert tuple(boxes[0, 6:9]) == g.values.shape
    atlas = np.frombuffer(v["atlas"], dtype=np.uint8).reshape(v["atlas_size"][1], v["atlas_size"][0], 2)
    i, j, k = np.unravel_index(np.nanargmax(g.values), g.values.shape)
    assert atlas_value(atlas, tuple(boxes[0, 9:12].astype(int)), g.values.shape, i, j, k)[0] == \
        int(np.rint(np.clip(g.values[i, j, k], 0, 1) * 255))
    # no surface meanwhile; the bars are the box's cut, no balls
    assert w.scene.surface == {}
    balls, bars, faces = w.scene.counts
    assert balls == 0 and faces == 0 and bars == len(g.outline[1]) >= 12


def test_back_to_surface_hides_the_volume_in_the_same_message(make):
    w = make(blob(), rendering="volume")
    assert w.scene.buffer.volume["n_boxes"] == 1 and w.scene.surface == {}
    w.rendering = "surface"
    assert w.scene.buffer.volume == {} and w.scene.surface["n_indices"] > 0


def test_default_clim_is_the_cuts_1st_to_99th_percentile(make):
    from rot4d_widget.core.colours import default_clim

    f = blob()
    w = make(f, rendering="mip")
    g = f.sample(w.state.matrix, w.c0)
    assert w._painter.cast_clim == pytest.approx(default_clim(g.values))
    w.clim = (0.2, 0.4)
    assert w._painter.cast_clim == (0.2, 0.4)


def test_held_keys_cast_the_coarse_grid_and_rest_the_full_one(make, clock):
    f = blob()
    w = make(f, rendering="mip")
    full = w.scene.buffer.volume["boxes"]
    full_shape = tuple(np.frombuffer(full, dtype="<f4")[6:9])
    down(w, "4")
    settle(w, clock, 0.6)
    held = tuple(np.frombuffer(w.scene.buffer.volume["boxes"], dtype="<f4")[6:9])
    assert max(held) < max(full_shape)  # coarse while held
    up(w, "4")
    settle(w, clock, 0.5)
    rest = tuple(np.frombuffer(w.scene.buffer.volume["boxes"], dtype="<f4")[6:9])
    assert max(rest) == max(full_shape) and w._painter.shown.coarse is False


def test_a_stack_casts_every_slice(make):
    w = make(blob(), rendering="mip", slices=3, spacing=0.5)
    v = w.scene.buffer.volume
    assert v["n_boxes"] == 3
    boxes = np.frombuffer(v["boxes"], dtype="<f4").reshape(-1, 12)
    assert len({tuple(b[0:3]) for b in boxes}) == 3  # each slice at its own place


# -- the traits and the keys ---------------------------------------------------------------------
def test_v_cycles_the_renderings_and_shift_goes_back(make):
    w = make(blob())
    seen = [w.rendering]
    for _ in range(4):
        w.press("v")
        seen.append(w.rendering)
    assert seen == ["surface", "volume", "mip", "sections", "surface"]
    w.press("V")
    assert w.rendering == "sections"
    assert w.scene.buffer.volume["mode"] == vl.MODES["sections"]


def test_section_keys_move_their_plane_and_stop_at_the_edge(make):
    w = make(blob(), rendering="sections")
    w.press("a")
    w.press("S")
    assert w.sections == (0.5 + 1 / 32, 0.5 - 1 / 32, 0.5)
    assert w.scene.buffer.volume["sections"] == list(w.sections)
    for _ in range(40):
        w.press("d")
    assert w.sections[2] == 1.0
    assert w.press("d") is False  # refused at the edge, not clamped


def test_help_lists_the_rendering_and_section_keys(make):
    w = make(blob())
    text = w.help_panel.value
    assert "surface, volume, mip, sections" in text and "Shift" in text
    assert "section plane" in text


def test_a_polytope_has_only_the_surface(make):
    w = make("24-cell")
    assert w.press("v") is False and w.rendering == "surface"
    with pytest.raises(ValueError, match="needs a field.*rendering='surface'"):
        w.rendering = "mip"
    assert w.rendering == "surface"
    with pytest.raises(ValueError, match="needs a field"):
        make("5-cell", rendering="volume")


@pytest.mark.parametrize("name, bad, exc, match", [
    ("rendering", "isosurface", ValueError, r"one of 'surface', 'volume', 'mip', 'sections'"),
    ("rendering", 3, TypeError, r"one of 'surface'"),
    ("sections", (0.5, 0.5), TypeError, r"three numbers in \[0, 1\]"),
    ("sections", (0.5, 1.5, 0.5), ValueError, r"three numbers in \[0, 1\]"),
    ("sections", (0.5, float("nan"), 0.5), ValueError, r"three numbers in \[0, 1\]"),
])
def test_bad_values_are_refused_and_the_trait_kept(make, name, bad, exc, match):
    w = make(blob())
    before = getattr(w, name)
    with pytest.raises(exc, match=match):
        setattr(w, name, bad)
    assert getattr(w, name) == before


def test_the_default_sections_are_the_middle():
    assert renderings.DEFAULT_SECTIONS == (0.5, 0.5, 0.5)
    assert ball_field().n_groups >= 1


def test_a_cut_that_misses_the_data_shows_no_volume_and_no_error(make):
    w = make(blob(), rendering="volume")
    w.c0 = 5.0  # w = 5 is beyond the data's box [-1, 1]
    assert w.scene.buffer.volume == {} and len(w.errors.outputs) == 0
    w.c0 = 0.0
    assert w.scene.buffer.volume["n_boxes"] == 1


def test_the_colour_bar_spans_the_limits_the_ray_cast_colours_used(make):
    w = make(blob(), rendering="mip")
    lo, hi = w._painter.cast_clim
    bar = w._painter.colourbar()
    assert "rot4d-cbar-mark" not in bar  # no iso level drawn: none marked
    assert f"{lo:.3g}"[:3] in bar and "blob" in bar and "kg/m3" in bar
    w.clim = (0.25, 0.75)
    bar = w._painter.colourbar()
    assert "0.25" in bar and "0.75" in bar
    w.rendering = "surface"
    assert "rot4d-cbar-mark" in w._painter.colourbar()  # the level is marked again


def test_a_single_field_labels_its_box_with_data_coordinates(make):
    from rot4d_widget.sources.field_labels import box_labels

    f = blob()
    w = make(f, rendering="mip")
    labels = w.scene.buffer.labels
    # the data's extent (the box's cut), not the ray-cast grid's padding (issue 37)
    pts, _ = f.sample(w.state.matrix, w.c0).outline
    box = SimpleNamespace(origin=pts.min(axis=0), extent=tuple(zip(pts.min(axis=0), pts.max(axis=0))))
    want = box_labels(f, w.state.matrix, w.c0, box)
    assert [lab["text"] for lab in labels] == [t for _, t in want] and len(labels) == 4
    np.testing.assert_allclose([lab["p"] for lab in labels], [w.scene.scale * np.asarray(p) for p, _ in want])
    w.press("4")  # x and w mix: the edge labels name both
    assert any("w " in lab["text"] and "x " in lab["text"] for lab in w.scene.buffer.labels[1:])
    w.rendering = "surface"
    assert len(w.scene.buffer.labels) == 4  # the surface view is labelled too
    p = make("24-cell")
    assert p.scene.buffer.labels == []
