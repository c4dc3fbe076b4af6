"""Stacks of parallel slices (issue 10): the batched polytope slicer, StackSource, the arrangements,
render_tomography.

Every slice of a stack must equal the single slice at its level; Cavalieri's principle over a
stack must converge like the midpoint rule (|error| <= C Δ^2, one C per object); the layouts
must put each slice where docs/design.md ("Parallel slices") says, without overlaps.
"""

import math

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from reference_geometry import random_rotation
from rot4d_widget import polytope, slice_polytope
from rot4d_widget.core import camera, sizes
from rot4d_widget.sources.field.container import Field4D
from rot4d_widget.keep.pictures.state_picture import render_tomography
from rot4d_widget.core.rotation import simple_rotation
from rot4d_widget.sources.protocol import PolytopeSource
from rot4d_widget.sources.arrangements import ARRANGEMENTS, GAP, OVAL_PARABOLA, arrangement_layout
from rot4d_widget.sources.tomography import (
    SPACING_FACTOR,
    StackSource,
    highlighted_index,
    stack_levels,
)

NAMES = ["5-cell", "8-cell", "16-cell", "24-cell", "120-cell", "600-cell"]
SLICE_ARRAYS = ("vertices", "edges", "polygon_indices", "polygon_offsets", "cell_ids", "triangles", "triangle_cells")
R_D = sizes.REFERENCE_RADIUS
D = camera.CAMERA_POSITION[2]
HALF_H = D * math.tan(math.radians(camera.CAMERA_FOV) / 2)


def assert_same_slice(a, b, where=""):
    for name in SLICE_ARRAYS:
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=f"{where} {name}")
    assert a.dim == b.dim, where
    assert a.face_census() == b.face_census(), where
    assert abs(a.volume - b.volume) <= 1e-12 * max(1.0, abs(b.volume)), where


# -- the batched call ----------------------------------------------------------------------------

@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_each_level_of_a_batch_equals_its_single_slice(name, seed):
    p = polytope(name)
    m = random_rotation(seed)
    w = (p.vertices @ m.T)[:, 3]
    rng = np.random.default_rng(seed)
    levels = np.concatenate([
        np.linspace(-1.1, 1.1, 23) * p.circumradius,  # across and past the polytope
        rng.choice(w, min(6, len(w)), replace=False),  # exactly at vertex heights (on-H cases)
        [w.max(), w.min()],  # touching
    ])
    rng.shuffle(levels)
    many = slice_polytope(p, m, levels)
    assert isinstance(many, tuple) and len(many) == len(levels)
    for c, s in zip(levels, many):
        assert_same_slice(s, slice_polytope(p, m, float(c)), f"{name} seed {seed} c0 {c}")


def test_identity_orientation_levels_at_vertex_heights_and_whole_cells():
    # identity: many vertices share a height, the 8-cell has whole cells in w = +-1
    for name in ("8-cell", "24-cell", "600-cell"):
        p = polytope(name)
        levels = np.unique(p.vertices[:, 3])
        levels = np.concatenate([levels, (levels[1:] + levels[:-1]) / 2])
        for c, s in zip(levels, slice_polytope(p, np.eye(4), levels)):
            assert_same_slice(s, slice_polytope(p, np.eye(4), float(c)), f"{name} {c}")


def test_scalar_zero_d_and_one_d_levels():
    m = random_rotation(7)
    single = slice_polytope("24-cell", m, 0.25)
    assert type(slice_polytope("24-cell", m, np.float64(0.25))).__name__ == "Slice"
    assert_same_slice(slice_polytope("24-cell", m, np.array(0.25)), single)
    (one,) = slice_polytope("24-cell", m, [0.25])
    assert_same_slice(one, single)
    assert slice_polytope("24-cell", m, []) == ()


@pytest.mark.parametrize("bad, exc, match", [
    (np.zeros((2, 2)), ValueError, r"1-D array of levels, got shape \(2, 2\)"),
    ([0.0, float("nan")], ValueError, "finite"),
    (["a"], TypeError, "c0"),
    (True, TypeError, "c0"),
])
def test_bad_levels(bad, exc, match):
    with pytest.raises(exc, match=match):
        slice_polytope("5-cell", np.eye(4), bad)


def test_batched_slices_are_read_only_and_cannot_be_unlocked():
    many = slice_polytope("600-cell", random_rotation(3), np.linspace(-2, 2, 8))
    for s in many:
        for name in SLICE_ARRAYS:
            a = getattr(s, name)
            with pytest.raises(ValueError):
                a[...] = 0
            try:
                a.flags.writeable = True
            except ValueError:
                continue
            # only an array the slice owns alone may be unlocked (polygon_offsets is per slice)
            assert name == "polygon_offsets", name


# -- Cavalieri over a stack ------------------------------------------------------------------------

# C in units of V4 / W^2 (W the w-extent): |error| <= C V4 / N^2.  Observed over 4 orientations
# per object the largest normalised error was 0.16 (5-cell), 0.09 (8-cell), 0.54 (16-cell),
# 0.31 (24-cell), 0.21 (600-cell), mostly at N = 8.
CAVALIERI_C = {"5-cell": 1.0, "8-cell": 1.0, "16-cell": 1.0, "24-cell": 1.0, "600-cell": 1.0}


@pytest.mark.parametrize("name", list(CAVALIERI_C))
@pytest.mark.parametrize("seed", [11, 12])
def test_cavalieri_sum_of_stack_volumes_converges_like_delta_squared(name, seed):
    """Σ volume_k Δ over N slices at the midpoints of N bins covering the w-range -> the
    4-volume (scipy's hull), |error| <= C V4 / W^2 Δ^2 for every N = 8 ... 256 (midpoint rule)."""
    p = polytope(name)
    m = random_rotation(seed)
    v4 = ConvexHull(p.vertices).volume
    w = (p.vertices @ m.T)[:, 3]
    lo, hi = w.min(), w.max()
    width = hi - lo
    for n in (8, 16, 32, 64, 128, 256):
        delta = width / n
        levels = stack_levels((lo + hi) / 2, n, delta)
        total = sum(s.volume for s in slice_polytope(p, m, levels)) * delta
        assert abs(total - v4) <= CAVALIERI_C[name] * v4 / width**2 * delta**2, (name, n, total, v4)


def test_cavalieri_through_stack_source():
    src = StackSource("24-cell", slices=64)
    m = random_rotation(5)
    lo, hi = src.w_range(m)
    src.spacing = (hi - lo) / 64
    data = src.slice(m, (lo + hi) / 2)
    total = sum(data.volumes) * src.spacing
    v4 = ConvexHull(polytope("24-cell").vertices).volume
    assert abs(total - v4) <= 1.0 * v4 / (hi - lo) ** 2 * src.spacing**2


# -- StackSource ---------------------------------------------------------------------------------------

@pytest.mark.parametrize("arrangement", ARRANGEMENTS)
@pytest.mark.parametrize("name", ["8-cell", "600-cell"])
def test_stack_slices_equal_single_slices_placed(arrangement, name):
    src = StackSource(name, slices=7, arrangement=arrangement, color_by="cell")
    m = random_rotation(4)
    c0 = 0.1
    data = src.slice(m, c0)
    np.testing.assert_allclose(data.cuts, c0 + (np.arange(7) - 3) * src.spacing)
    off = data.point_offsets
    toff = data.triangle_offsets
    for k, w in enumerate(data.cuts):
        single = slice_polytope(name, m, float(w))
        assert_same_slice(data.slices[k], single, f"k={k}")
        np.testing.assert_array_equal(data.points[off[k]:off[k + 1]],
                                      single.vertices * data.scales[k] + data.centres[k])
        np.testing.assert_array_equal(data.triangles[toff[k]:toff[k + 1]] - off[k], single.triangles)
        np.testing.assert_array_equal(data.groups[toff[k]:toff[k + 1]], single.triangle_cells)
        assert data.volumes[k] == pytest.approx(single.volume, rel=1e-12, abs=1e-15)


def test_color_by_w_groups_are_slice_indices_with_a_colormap():
    src = StackSource("24-cell", slices=5)
    data = src.slice(random_rotation(1), 0.0)
    toff = data.triangle_offsets
    for k in range(5):
        assert set(data.groups[toff[k]:toff[k + 1]].tolist()) <= {k}
    assert src.n_groups == 5
    rgb = src.group_colors()
    assert rgb.shape == (5, 3) and len({tuple(c) for c in rgb.round(3)}) == 5
    np.testing.assert_array_equal(data.group_rgb, rgb)
    src.color_by = "cell"
    assert src.n_groups == 24 and src.group_colors() is None


@pytest.mark.parametrize("arrangement", ARRANGEMENTS)
@pytest.mark.parametrize("color_by", ["w", "cell"])
def test_one_slice_is_todays_view(arrangement, color_by):
    m = random_rotation(9)
    today = PolytopeSource("24-cell").slice(m, 0.3)
    one = StackSource("24-cell", slices=1, arrangement=arrangement, color_by=color_by).slice(m, 0.3)
    for name in ("points", "segments", "triangles", "groups"):
        np.testing.assert_array_equal(getattr(one, name), getattr(today, name))
    assert one.volume == today.volume and one.readout == today.readout and one.convex


def test_highlighted_slice_is_at_c0():
    m = random_rotation(2)
    for n in (1, 3, 5, 9, 63):
        data = StackSource("16-cell", slices=n, spacing=0.3).slice(m, 0.7)
        hi = data.highlighted
        assert data.cuts[hi] == 0.7  # exactly
    for n in (2, 4, 64):  # even: no slice at c0, the first above it
        data = StackSource("16-cell", slices=n, spacing=0.3).slice(m, 0.7)
        hi = data.highlighted
        assert data.cuts[hi] == pytest.approx(0.85)
        assert hi == highlighted_index(n) == n // 2


def test_readout_lists_each_slice_compactly():
    data = StackSource("24-cell", slices=5).slice(random_rotation(1), 0.0)
    labels = [k for k, _ in data.readout]
    assert labels[0] == "stack" and len(labels) == 6
    assert labels[3].startswith("\u25b8 w")  # the slice at c0 is marked
    assert all("vol" in v for _, v in data.readout[1:])
    many = StackSource("24-cell", slices=40).slice(random_rotation(1), 0.0)
    assert [k for k, _ in many.readout] == ["stack", "w", "volumes"]


def test_actions_change_n_and_spacing():
    src = StackSource("5-cell", slices=5)
    assert set(src.actions) == {"n", "b", "g", "f"}
    size = src.size
    assert src.spacing == pytest.approx(2 * size / 5)
    src.actions["n"].run(1)
    assert src.slices == 6 and src.spacing == pytest.approx(2 * size / 6)  # the default follows N
    src.actions["b"].run(1)
    src.actions["b"].run(1)
    assert src.slices == 4
    src.actions["n"].run(-1)  # Shift+n removes
    assert src.slices == 3
    d = src.spacing
    src.actions["g"].run(1)
    assert src.spacing == pytest.approx(d * SPACING_FACTOR)
    src.actions["f"].run(1)
    src.actions["f"].run(1)
    assert src.spacing == pytest.approx(d / SPACING_FACTOR)
    src.actions["n"].run(1)
    assert src.spacing == pytest.approx(d / SPACING_FACTOR)  # explicit now: N no longer moves it
    for _ in range(80):
        src.step_slices(1)
    assert src.slices == 64
    for _ in range(80):
        src.step_slices(-1)
    assert src.slices == 1
    assert src.slice(np.eye(4), 0.0).points.shape[1] == 3


@pytest.mark.parametrize("kwargs, match", [
    ({"slices": 0}, r"`slices` to be an int in 1 \u2026 64, got 0"),
    ({"slices": 65}, "1 \u2026 64"),
    ({"slices": 2.5}, "int"),
    ({"slices": True}, "int"),
    ({"spacing": -1.0}, "`spacing` to be a finite number > 0"),
    ({"spacing": float("nan")}, "finite"),
    ({"spacing": "wide"}, "spacing"),
    ({"arrangement": "ring"}, "one of 'oval', 'grid', 'stack', got 'ring'"),
    ({"color_by": "x"}, "one of 'w', 'cell'"),
])
def test_bad_arguments_are_named(kwargs, match):
    with pytest.raises(ValueError, match=match):
        StackSource("5-cell", **kwargs)


def test_bad_source_and_c0():
    with pytest.raises(TypeError, match="polytope name"):
        StackSource(42)
    with pytest.raises(ValueError, match="c0"):
        StackSource("5-cell").slice(np.eye(4), float("inf"))


def test_turned_stack_turns_each_slice_about_its_centre():
    src = StackSource("24-cell", slices=5, arrangement="grid")
    m = random_rotation(6)
    r3 = simple_rotation("xz", 0.4) @ simple_rotation("xy", 0.3)
    turned = src.slice(m, 0.2).turned(r3[:3, :3])
    direct = src.slice(r3 @ m, 0.2)
    np.testing.assert_allclose(turned.points, direct.points, atol=1e-12)  # same corners, same order
    assert {tuple(sorted(e)) for e in turned.segments.tolist()} == {tuple(sorted(e)) for e in direct.segments.tolist()}
    # (the triangles may fan each polygon from another corner: angles start from fixed axes)
    assert len(turned.triangles) == len(direct.triangles)


# -- fields and user sources ---------------------------------------------------------------------------

def test_field_stack_keeps_normals_and_coarse():
    f = Field4D.from_function(lambda x, y, z, w: 0.6**2 - (x * x + y * y + z * z + w * w), ((-1, 1),) * 4,
                              resolution=12, coarse_resolution=8)
    src = StackSource(f, slices=3, spacing=0.3, arrangement="stack")
    assert "coarse" in __import__("inspect").signature(src.slice).parameters
    m = random_rotation(1)
    data = src.slice(m, 0.05)
    off = data.point_offsets
    for k, w in enumerate(data.cuts):
        single = f.slice(m, float(w))
        np.testing.assert_allclose(data.points[off[k]:off[k + 1]],
                                   single.points * data.scales[k] + data.centres[k])
        np.testing.assert_array_equal(data.normals[off[k]:off[k + 1]], single.normals)
        assert data.volumes[k] == single.volume
    assert data.normals is not None and not data.show_points
    coarse = src.slice(m, 0.05, coarse=True)
    assert len(coarse.points) < len(data.points)


def test_user_source_without_coarse():
    class Dots:
        size = 1.0
        n_groups = 1

        def slice(self, matrix, c0):
            from rot4d_widget import SliceData

            return SliceData.build(np.array([[c0, 0.0, 0.0]]))

        def describe(self):
            return {"kind": "dots"}

    src = StackSource(Dots(), slices=3, arrangement="stack")
    assert list(__import__("inspect").signature(src.slice).parameters) == ["matrix", "c0"]
    data = src.slice(np.eye(4), 0.0)
    assert data.points.shape == (3, 3) and data.volumes == (None, None, None)
    assert src.describe() == {"kind": "stack", "source": {"kind": "dots"}, "slices": 3, "spacing": None,
                              "arrangement": "stack", "color_by": "w"}


# -- arrangements ----------------------------------------------------------------------------------------

def images_in_frame(centres, radii):
    f = D / (D - centres[:, 2])
    lim_y = HALF_H
    lim_x = 600 / 500 * lim_y
    return bool(np.all(np.abs(centres[:, 0] * f) + radii * f <= lim_x)
                and np.all(np.abs(centres[:, 1] * f) + radii * f <= lim_y))


def spheres_disjoint(centres, radii):
    d = np.linalg.norm(centres[:, None] - centres[None], axis=2)
    iu = np.triu_indices(len(centres), 1)
    return bool(np.all(d[iu] >= (radii[:, None] + radii[None])[iu] * (1 + GAP) * (1 - 1e-9)))


@pytest.mark.parametrize("name", ARRANGEMENTS)
def test_one_slice_is_the_identity_layout(name):
    centres, scales = arrangement_layout(name, 1, 3.7)
    assert centres.tolist() == [[0.0, 0.0, 0.0]] and scales.tolist() == [1.0]


@pytest.mark.parametrize("n", [2, 3, 5, 8, 12, 16, 33, 64])
def test_oval_centres_on_the_documented_parabola(n):
    A, B, C = (OVAL_PARABOLA[k] for k in ("A", "B", "C"))
    centres, scales = arrangement_layout("oval", n)
    u = centres[:, 0] / A
    y0 = centres[:, 1] - C * u * u  # one Y0 for every slice: they lie on one parabola
    np.testing.assert_allclose(y0, y0[0], atol=1e-12)
    # centred: the spheres' images reach as far above the frame's middle as below it
    f = camera.CAMERA_POSITION[2] / (camera.CAMERA_POSITION[2] - centres[:, 2])
    r = R_D * scales
    assert ((centres[:, 1] + r) * f).max() == pytest.approx(-((centres[:, 1] - r) * f).min(), abs=1e-9)
    np.testing.assert_allclose(centres[:, 2], -B * u * u, atol=1e-12)
    assert np.all(np.abs(u) <= OVAL_PARABOLA["U_MAX"] + 1e-12)
    assert np.all(np.diff(u) > 0)  # higher w to the right
    # the highlighted slice is nearest the eye (for even n, tied with its neighbour below c0)
    hi = highlighted_index(n)
    assert centres[hi, 2] == pytest.approx(centres[:, 2].max())
    # scales fall away from the centre, at most 0.6
    tau = np.abs(np.arange(n) - (n - 1) / 2)
    assert np.all(np.diff(scales[np.argsort(tau, kind="stable")]) <= 1e-12) and scales.max() <= 0.6 + 1e-12
    assert spheres_disjoint(centres, R_D * scales)
    assert images_in_frame(centres, R_D * scales)


@pytest.mark.parametrize("n", [2, 3, 4, 5, 7, 9, 10, 16, 17, 40, 64])
def test_grid_rows_top_to_bottom_equal_scale_no_overlap(n):
    centres, scales = arrangement_layout("grid", n)
    cols = math.ceil(math.sqrt(n))
    assert np.all(scales == scales[0]) and scales[0] <= 1
    assert np.all(centres[:, 2] == 0)
    rows = np.arange(n) // cols
    for r in np.unique(rows):
        row = centres[rows == r]
        assert np.all(row[:, 1] == row[0, 1]) and np.all(np.diff(row[:, 0]) > 0)
    assert np.all(np.diff(centres[np.arange(0, n, cols), 1]) < 0)  # top to bottom
    assert len(np.unique(centres[:, 0].round(9))) == min(cols, n)
    assert spheres_disjoint(centres, R_D * scales)
    assert images_in_frame(centres, R_D * scales)


@pytest.mark.parametrize("n", [2, 3, 6, 16, 64])
def test_stack_one_row_along_x(n):
    centres, scales = arrangement_layout("stack", n)
    assert np.all(scales == scales[0]) and np.all(centres[:, 1:] == 0) and np.all(np.diff(centres[:, 0]) > 0)
    np.testing.assert_allclose(centres[:, 0], -centres[::-1, 0])  # centred
    assert spheres_disjoint(centres, R_D * scales)
    assert images_in_frame(centres, R_D * scales)


def test_layout_scales_with_the_radius():
    for name in ARRANGEMENTS:
        c1, s1 = arrangement_layout(name, 7)
        c2, s2 = arrangement_layout(name, 7, 2 * R_D)
        np.testing.assert_allclose(c2, 2 * c1)
        np.testing.assert_array_equal(s1, s2)


def test_bad_layout_arguments():
    with pytest.raises(ValueError, match="arrangement"):
        arrangement_layout("circle", 3)
    with pytest.raises(ValueError, match="slices"):
        arrangement_layout("grid", 0)
    with pytest.raises(ValueError, match="radius"):
        arrangement_layout("grid", 3, -1.0)


# -- static figures ------------------------------------------------------------------------------------------

@pytest.mark.parametrize("ext, magic", [(".png", b"\x89PNG"), (".svg", b"<?xml"), (".pdf", b"%PDF")])
def test_render_tomography_writes_files(tmp_path, ext, magic):
    path = tmp_path / f"stack{ext}"
    fig = render_tomography("24-cell", random_rotation(3), 0.0, 5, None, "oval", path, dpi=40)
    assert path.read_bytes()[:5].startswith(magic)
    texts = [t.get_text() for t in fig.axes[0].texts]
    # each slice's w as the readout and the page write it (issue 37: `data_w_text`)
    assert sorted(t for t in texts if t.startswith("w ")) == sorted(["w -1.6", "w -0.8", "w +0", "w +0.8", "w +1.6"])
    bold = [t.get_text() for t in fig.axes[0].texts if t.get_fontweight() == "bold"]
    assert bold == ["w +0"]
    rings = [p for p in fig.axes[0].patches if p.get_gid() == "highlight-ring"]
    assert len(rings) == 1


def test_render_tomography_field_grid_and_bad_path(tmp_path):
    f = Field4D.from_function(lambda x, y, z, w: 0.6**2 - (x * x + y * y + z * z + w * w), ((-1, 1),) * 4,
                              resolution=10)
    fig = render_tomography(f, np.eye(4), 0.0, 4, 0.3, "grid", tmp_path / "f.png", dpi=30)
    assert any(c.get_gid() == "surface" for c in fig.axes[0].collections)
    with pytest.raises(ValueError, match=r"\.png, \.pdf, \.svg"):
        render_tomography("5-cell", None, 0.0, 3, None, "stack", tmp_path / "x.gif")


def test_a_stack_tells_the_protocol_what_it_wraps_its_settings_and_copies_its_inner_source():
    import copy

    from rot4d_widget import Field4D
    from rot4d_widget.sources.protocol import apply_setting, inner_source, settings_of, takes_coarse

    f = Field4D.from_function(lambda x, y, z, w: x + w, ((-1, 1),) * 4, levels=[0.1])
    st = StackSource(f, slices=3)
    assert inner_source(st) is f and inner_source(f) is f and takes_coarse(st) and takes_coarse(f)
    assert settings_of(st) == {"slices": 3, "spacing": None, "arrangement": "oval", "levels": [0.1],
                               "inside": "above", "caps": True}
    apply_setting(st, "levels", [0.2, 0.3])
    apply_setting(st, "slices", 5)
    assert f.levels == (0.2, 0.3) and st.slices == 5
    with pytest.raises(ValueError, match="no setting 'thickness'"):
        apply_setting(st, "thickness", 1.0)
    twin = copy.copy(st)
    assert twin.source is not f and settings_of(twin) == settings_of(st)
    twin.source.levels = [0.5]
    assert f.levels == (0.2, 0.3)  # the original's inner source is untouched
    poly = StackSource("5-cell", slices=2)
    assert not takes_coarse(poly) and settings_of(poly) == {"slices": 2, "spacing": None, "arrangement": "oval"}


def test_a_stack_s_cuts_keep_their_old_names():
    """``cuts_at`` (the w of each slice, a stack slice's ``cuts``) was ``levels_at``, a name a field
    uses for its iso values: the old name still gives the same numbers."""
    src = StackSource("8-cell", slices=5, spacing=0.1)
    np.testing.assert_array_equal(src.levels_at(0.2), src.cuts_at(0.2))
    np.testing.assert_allclose(src.slice(np.eye(4), 0.2).cuts, 0.2 + (np.arange(5) - 2) * 0.1)
