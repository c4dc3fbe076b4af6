"""rot4d_widget.view.buffers: the row table every update sends, the palette, the template shapes.

Slices come from the source protocol (`rot4d_widget.sources.protocol`): a polytope's
through `PolytopeSource`, made-up ones as plain objects with ``points``,
``segments``, ``triangles``, ``groups`` (and optionally ``convex``,
``show_points``).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from rot4d_widget.core.rotation import random_rotation
import pytest

from rot4d_widget.view import buffers as bf
from rot4d_widget import polytope
from rot4d_widget.geometry.regular import POLYTOPE_NAMES
from rot4d_widget.sources.protocol import PolytopeSource, SliceData


def fake_slice(n_points=5, n_segments=7, n_triangles=4, n_groups=3, seed=0):
    """A slice's members as a `SliceData` has them (the optional ones at their defaults: what
    `as_slice` makes of a slice with only the four required ones), unvalidated and writable, so a
    test can hand the buffers a bad shape."""
    rng = np.random.default_rng(seed)
    return SimpleNamespace(
        points=rng.standard_normal((n_points, 3)),
        segments=rng.integers(0, max(n_points, 1), (n_segments, 2)).astype(np.intp),
        triangles=rng.integers(0, max(n_points, 1), (n_triangles, 3)).astype(np.intp),
        groups=rng.integers(0, n_groups, n_triangles).astype(np.intp),
        normals=None, volume=None, readout=(), convex=False, show_points=True, corner_only=None,
    )


def polytope_slice(p, matrix, c0):
    return PolytopeSource(p).slice(matrix, c0)


def real_slices():
    rng = np.random.default_rng(11)
    out = []
    for name in POLYTOPE_NAMES:
        p = polytope(name)
        for c in (0.0, 0.5 * p.circumradius):
            out.append((name, p, polytope_slice(p, random_rotation(rng), c)))
    return out


SLICES = real_slices()


# ------------------------------------------------------------------ the table
@pytest.mark.parametrize("name,p,s", SLICES, ids=[f"{n}-{i % 2}" for i, (n, _, _) in enumerate(SLICES)])
def test_every_ball_bar_and_triangle_is_in_its_row_scaled(name, p, s):
    scale = 1.2649 / p.circumradius
    palette = bf.group_palette(len(p.cells))
    rows = bf.slice_rows(s, scale=scale, group_rgb=palette, capacity=bf.rows_needed(s) + 5)
    v = s.points * scale
    nv, ne, nt = len(s.points), len(s.segments), len(s.triangles)
    assert nv and ne and nt  # these slices are solid
    c = {k: slice(col, col + size) for k, (col, size) in bf.COLUMNS.items()}
    np.testing.assert_allclose(rows[:nv, c["ball"]][:, :3], v, rtol=1e-6, atol=1e-6)
    assert np.all(rows[:nv, 3] == 1.0)
    np.testing.assert_allclose(rows[:ne, c["bar_a"]], v[s.segments[:, 0]], rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(rows[:ne, c["bar_b"]], v[s.segments[:, 1]], rtol=1e-6, atol=1e-6)
    for key, k in (("tri_a", 0), ("tri_b", 1), ("tri_c", 2)):
        np.testing.assert_allclose(rows[:nt, c[key]], v[s.triangles[:, k]], rtol=1e-6, atol=1e-6)
    rgb = bf.unpack_rgb(rows[:nt, 19])
    expected = np.rint(palette[s.groups].astype(np.float64) * 255).astype(np.uint8)
    np.testing.assert_array_equal(rgb, expected)


def test_dtype_shape_and_contiguity():
    s = fake_slice()
    rows = bf.slice_rows(s, capacity=32)
    assert rows.dtype == np.float32
    assert rows.shape == (32, bf.ROW_FLOATS) == (32, 20)
    assert rows.flags["C_CONTIGUOUS"]
    assert rows.nbytes == 32 * bf.ROW_BYTES
    # default capacity: exactly the rows needed
    assert bf.slice_rows(s).shape == (bf.rows_needed(s), 20) == (7, 20)


def test_columns_tile_the_row_without_overlap():
    used = np.zeros(bf.ROW_FLOATS, dtype=int)
    for col, size in bf.COLUMNS.values():
        used[col : col + size] += 1
    assert np.all(used == 1)


def test_rows_past_each_count_are_hidden():
    s = fake_slice(n_points=3, n_segments=9, n_triangles=5)
    rows = bf.slice_rows(s, capacity=16)
    # balls: flag 0 past the point count
    assert np.all(rows[3:, 3] == 0.0) and np.all(rows[:3, 3] == 1.0)
    # bars: zero length past the segment count
    assert np.all(np.linalg.norm(rows[9:, 4:7] - rows[9:, 7:10], axis=1) == 0.0)
    # triangles: zero area past the triangle count
    a, b, c = rows[5:, 10:13], rows[5:, 13:16], rows[5:, 16:19]
    assert np.all(np.linalg.norm(np.cross(b - a, c - a), axis=1) == 0.0)
    # rows past all counts are all zero
    assert not rows[9:].any()


def test_hidden_rows_of_real_slices():
    name, p, s = SLICES[-1]  # 600-cell off-centre
    rows = bf.slice_rows(s, capacity=bf.capacity_for(bf.rows_needed(s)))
    nv, ne, nt = len(s.points), len(s.segments), len(s.triangles)
    assert not rows[nv:, 0:4].any() and not rows[ne:, 4:10].any() and not rows[nt:, 10:20].any()


def test_empty_slice_is_all_hidden():
    s = SliceData.build(np.zeros((0, 3)))
    assert bf.rows_needed(s) == 0
    rows = bf.slice_rows(s, capacity=16)
    assert rows.shape == (16, 20) and not rows.any()
    p = polytope("5-cell")
    far = polytope_slice(p, np.eye(4), 2.0 * p.circumradius)
    assert not bf.slice_rows(far, capacity=16).any()


def test_capacity_too_small_and_bad_shapes_raise():
    s = fake_slice(n_segments=9)
    with pytest.raises(ValueError, match=r"`capacity` >= 9"):
        bf.slice_rows(s, capacity=8)
    bad = fake_slice()
    bad.points = np.zeros((5, 4))
    with pytest.raises(ValueError, match=r"`points` to have shape \(n, 3\), got \(5, 4\)"):
        bf.slice_rows(bad)
    bad = fake_slice()
    bad.segments = np.zeros((7, 3), np.intp)
    with pytest.raises(ValueError, match=r"`segments` to have shape \(m, 2\), got \(7, 3\)"):
        bf.slice_rows(bad)
    bad = fake_slice()
    bad.groups = bad.groups[:-1]
    with pytest.raises(ValueError, match="`groups`"):
        bf.slice_rows(bad)
    with pytest.raises(ValueError, match="colour for group 2"):
        bf.slice_rows(fake_slice(n_groups=3, n_triangles=40), group_rgb=bf.group_palette(2))
    empty = polytope_slice(polytope("5-cell"), np.eye(4), 10.0)  # no triangles: the eye is still checked
    for eye in [(0.0, 5.0), (0.0, 0.0, float("nan")), "eye"]:
        for s_ in (fake_slice(), empty):
            with pytest.raises(ValueError, match="`eye` to be three finite numbers"):
                bf.slice_rows(s_, capacity=16, eye=eye)


def _row_triangles(rows, n):
    """Corners (n, 3, 3) and packed colours (n,) of the first ``n`` triangle rows, float64."""
    return rows[:n, 10:19].astype(np.float64).reshape(n, 3, 3), rows[:n, 19]


def test_non_convex_slice_sorts_triangles_farthest_first_from_the_eye():
    """No back/front rule holds for a non-convex surface: blend in depth order (centroids)."""
    rng = np.random.default_rng(3)
    n = 40
    centres = rng.uniform(-2.0, 2.0, (n, 3))
    points = (centres[:, None, :] + 0.1 * rng.standard_normal((n, 3, 3))).reshape(-1, 3)
    triangles = np.arange(3 * n).reshape(n, 3)
    groups = rng.integers(0, 6, n)
    data = SliceData.build(points, None, triangles, groups, convex=False)
    palette = bf.group_palette(6)
    for eye in [(0.0, 0.0, 5.0), (4.0, -3.0, 1.0), (0.5, 0.2, -0.3)]:  # the last one among the triangles
        rows = bf.slice_rows(data, scale=1.5, group_rgb=palette, eye=eye)
        corners, rgb = _row_triangles(rows, n)
        depth = np.linalg.norm(corners.mean(axis=1) - eye, axis=1)
        assert np.all(np.diff(depth) <= 1e-9), "triangles must come farthest first"
        # each triangle kept its corners and the colour of its group
        want = {tuple(np.round((points[t] * 1.5).astype(np.float32), 4).ravel()): bf.pack_rgb(palette[g : g + 1])[0]
                for t, g in zip(triangles, groups)}
        got = {tuple(np.round(c.astype(np.float32), 4).ravel()): col for c, col in zip(corners, rgb)}
        assert got == want
    # without an eye the slice's own order is kept
    corners, _ = _row_triangles(bf.slice_rows(data), n)
    np.testing.assert_allclose(corners, points[triangles], atol=1e-6)


def test_convex_and_non_convex_orders_differ_for_the_same_triangles():
    p = polytope("24-cell")
    s = polytope_slice(p, random_rotation(np.random.default_rng(9)), 0.0)
    assert s.convex
    loose = SliceData.build(s.points, s.segments, s.triangles, s.groups, convex=False)
    eye = (3.0, -4.0, 1.0)
    nt = len(s.triangles)
    convex_rows, depth_rows = bf.slice_rows(s, eye=eye), bf.slice_rows(loose, eye=eye)
    (a, _), (b, _) = _row_triangles(convex_rows, nt), _row_triangles(depth_rows, nt)
    assert not np.array_equal(a, b)
    assert np.all(np.diff(np.linalg.norm(b.mean(axis=1) - eye, axis=1)) <= 1e-9)
    normal = np.cross(a[:, 1] - a[:, 0], a[:, 2] - a[:, 0])
    facing = np.einsum("ij,ij->i", normal, np.asarray(eye) - a[:, 0]) > 0
    assert 0 < facing.sum() < nt and not np.diff(facing.astype(int)).clip(max=0).any()  # away-facing first


@pytest.mark.parametrize("single", [(1.0, 0.0, 0.0), (0.623, 0.714, 0.804)])
def test_single_rgb_paints_every_triangle_that_colour(single):
    s = fake_slice(n_points=9, n_segments=4, n_triangles=12, n_groups=5)
    # the group palette is ignored, even one too short for the groups
    rows = bf.slice_rows(s, capacity=16, single_rgb=single, group_rgb=bf.group_palette(1))
    packed = bf.pack_rgb([single])[0]
    assert np.all(rows[:12, 19] == packed) and not rows[12:, 19].any()
    np.testing.assert_array_equal(bf.unpack_rgb(rows[:12, 19])[0], np.rint(np.asarray(single) * 255))
    # everything else is as with group colours
    np.testing.assert_array_equal(rows[:, :19], bf.slice_rows(s, capacity=16)[:, :19])


def test_show_points_false_sends_no_ball_rows():
    """Points that only carry corners (an isosurface's vertices) are not drawn as balls."""
    s = fake_slice(n_points=30, n_segments=4, n_triangles=6)
    hidden = SliceData.build(s.points, s.segments, s.triangles, s.groups, show_points=False)
    assert bf.rows_needed(hidden) == 6 and bf.rows_needed(s) == 30
    rows = bf.slice_rows(hidden, capacity=16)
    assert not rows[:, 0:4].any()  # every ball flag 0: no ball drawn
    shown = bf.slice_rows(s, capacity=32)
    np.testing.assert_array_equal(rows[:, 4:], shown[:16, 4:])  # bars and triangles unchanged
    assert np.all(shown[:30, 3] == 1.0)


def test_capacity_for_rounds_up_with_headroom():
    assert bf.capacity_for(0) == 16
    for rows in (1, 15, 16, 17, 100, 360, 1000):
        cap = bf.capacity_for(rows)
        assert cap % 16 == 0
        assert cap >= rows * (1 + bf.HEADROOM)
        assert cap < rows * (1 + bf.HEADROOM) + 16
    with pytest.raises(ValueError):
        bf.capacity_for(-1)


def test_estimate_capacity_covers_central_slices():
    rng = np.random.default_rng(5)
    for name in ("24-cell", "120-cell"):
        p = polytope(name)
        cap = bf.estimate_capacity(PolytopeSource(p))
        assert cap % 16 == 0
        most = max(bf.rows_needed(polytope_slice(p, random_rotation(rng), 0.0)) for _ in range(20))
        assert most <= cap <= 2 * most


# ------------------------------------------------------------------ sizes
def test_bytes_per_update_within_budget_for_every_polychoron():
    """Central slices are the largest; 64 KB is the issue's budget per update."""
    rng = np.random.default_rng(2)
    for name in POLYTOPE_NAMES:
        p = polytope(name)
        most = max(bf.rows_needed(polytope_slice(p, random_rotation(rng), 0.0)) for _ in range(30))
        nbytes = bf.capacity_for(most) * bf.ROW_BYTES
        assert nbytes <= 64 * 1024, (name, nbytes)
        if name == "120-cell":
            assert nbytes <= 40 * 1024


# ------------------------------------------------------------------ colours
def test_palette_is_deterministic_distinct_and_in_range():
    a = bf.cell_palette(600)
    assert a.shape == (600, 3) and a.dtype == np.float32
    assert a.min() >= 0.0 and a.max() <= 1.0
    np.testing.assert_array_equal(a, bf.cell_palette(600))
    np.testing.assert_array_equal(a[:5], bf.cell_palette(5))  # prefix-stable
    packed = bf.pack_rgb(a)
    assert len(np.unique(packed)) == 600
    # neighbours in index order differ clearly (cells numbered nearby often touch)
    d = np.abs(np.diff(a.astype(np.float64), axis=0)).sum(axis=1)
    assert d.min() > 0.1
    assert bf.cell_palette(0).shape == (0, 3)


def test_pack_rgb_is_exact_in_float32():
    rng = np.random.default_rng(0)
    ints = np.concatenate([[0, 1, 255, 256, 65535, 65536, 2**24 - 1], rng.integers(0, 2**24, 1000)])
    rgb = np.stack([ints // 65536, (ints // 256) % 256, ints % 256], 1) / 255.0
    packed = bf.pack_rgb(rgb)
    assert packed.dtype == np.float32
    np.testing.assert_array_equal(packed.astype(np.int64), ints)
    np.testing.assert_array_equal(bf.unpack_rgb(packed), np.stack([ints // 65536, (ints // 256) % 256, ints % 256], 1))
    with pytest.raises(ValueError, match=r"\[0, 1\]"):
        bf.pack_rgb([[0.0, 1.5, 0.0]])
    with pytest.raises(ValueError, match=r"shape \(n, 3\)"):
        bf.pack_rgb([0.1, 0.2, 0.3])


@pytest.mark.parametrize(
    "value,expected",
    [("#ff0000", (1.0, 0.0, 0.0)), ("#0F0", (0.0, 1.0, 0.0)), ((0.0, 0.5, 1.0), (0.0, 0.5, 1.0))],
)
def test_as_rgb_accepts(value, expected):
    np.testing.assert_allclose(bf.as_rgb(value), expected)


@pytest.mark.parametrize("value", ["red", "#12345", "ff0000", (1, 2, 3), (0.1, 0.2), None, 3])
def test_as_rgb_rejects_naming_the_allowed_forms(value):
    with pytest.raises(ValueError, match=r"'#rgb', '#rrggbb' or three floats in \[0, 1\]"):
        bf.as_rgb(value, "ball_color")


# ------------------------------------------------------------------ templates
def test_quad_and_triangle_templates():
    q = bf.quad_template()
    assert q.shape == (6, 3) and q.dtype == np.float32
    assert set(map(tuple, q[:, :2].tolist())) == {(-1, -1), (1, -1), (1, 1), (-1, 1)}
    t = bf.triangle_template()
    np.testing.assert_array_equal(t, np.eye(3))
    assert t.dtype == np.float32
