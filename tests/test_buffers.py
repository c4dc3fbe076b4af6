"""rot4d_widget.buffers: the row table every update sends, the palette, the template shapes."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from rot4d_widget import buffers as bf
from rot4d_widget import polytope, slice_polytope
from rot4d_widget.polytopes import POLYTOPE_NAMES


def random_rotation(rng):
    q, r = np.linalg.qr(rng.standard_normal((4, 4)))
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    return q


def fake_slice(n_vertices=5, n_edges=7, n_triangles=4, n_cells=3, seed=0):
    rng = np.random.default_rng(seed)
    return SimpleNamespace(
        vertices=rng.standard_normal((n_vertices, 3)),
        edges=rng.integers(0, max(n_vertices, 1), (n_edges, 2)).astype(np.intp),
        triangles=rng.integers(0, max(n_vertices, 1), (n_triangles, 3)).astype(np.intp),
        triangle_cells=rng.integers(0, n_cells, n_triangles).astype(np.intp),
    )


def real_slices():
    rng = np.random.default_rng(11)
    out = []
    for name in POLYTOPE_NAMES:
        p = polytope(name)
        for c in (0.0, 0.5 * p.circumradius):
            out.append((name, p, slice_polytope(p, random_rotation(rng), c)))
    return out


SLICES = real_slices()


# ------------------------------------------------------------------ the table
@pytest.mark.parametrize("name,p,s", SLICES, ids=[f"{n}-{i % 2}" for i, (n, _, _) in enumerate(SLICES)])
def test_every_ball_bar_and_triangle_is_in_its_row_scaled(name, p, s):
    scale = 1.2649 / p.circumradius
    palette = bf.cell_palette(len(p.cells))
    rows = bf.slice_rows(s, scale=scale, cell_rgb=palette, capacity=bf.rows_needed(s) + 5)
    v = s.vertices * scale
    nv, ne, nt = len(s.vertices), len(s.edges), len(s.triangles)
    assert nv and ne and nt  # these slices are solid
    c = {k: slice(col, col + size) for k, (col, size) in bf.COLUMNS.items()}
    np.testing.assert_allclose(rows[:nv, c["ball"]][:, :3], v, rtol=1e-6, atol=1e-6)
    assert np.all(rows[:nv, 3] == 1.0)
    np.testing.assert_allclose(rows[:ne, c["bar_a"]], v[s.edges[:, 0]], rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(rows[:ne, c["bar_b"]], v[s.edges[:, 1]], rtol=1e-6, atol=1e-6)
    for key, k in (("tri_a", 0), ("tri_b", 1), ("tri_c", 2)):
        np.testing.assert_allclose(rows[:nt, c[key]], v[s.triangles[:, k]], rtol=1e-6, atol=1e-6)
    rgb = bf.unpack_rgb(rows[:nt, 19])
    expected = np.rint(palette[s.triangle_cells].astype(np.float64) * 255).astype(np.uint8)
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
    s = fake_slice(n_vertices=3, n_edges=9, n_triangles=5)
    rows = bf.slice_rows(s, capacity=16)
    # balls: flag 0 past the vertex count
    assert np.all(rows[3:, 3] == 0.0) and np.all(rows[:3, 3] == 1.0)
    # bars: zero length past the edge count
    assert np.all(np.linalg.norm(rows[9:, 4:7] - rows[9:, 7:10], axis=1) == 0.0)
    # triangles: zero area past the triangle count
    a, b, c = rows[5:, 10:13], rows[5:, 13:16], rows[5:, 16:19]
    assert np.all(np.linalg.norm(np.cross(b - a, c - a), axis=1) == 0.0)
    # rows past all counts are all zero
    assert not rows[9:].any()


def test_hidden_rows_of_real_slices():
    name, p, s = SLICES[-1]  # 600-cell off-centre
    rows = bf.slice_rows(s, capacity=bf.capacity_for(bf.rows_needed(s)))
    nv, ne, nt = len(s.vertices), len(s.edges), len(s.triangles)
    assert not rows[nv:, 0:4].any() and not rows[ne:, 4:10].any() and not rows[nt:, 10:20].any()


def test_empty_slice_is_all_hidden():
    s = SimpleNamespace(
        vertices=np.zeros((0, 3)), edges=np.zeros((0, 2), np.intp),
        triangles=np.zeros((0, 3), np.intp), triangle_cells=np.zeros(0, np.intp),
    )
    assert bf.rows_needed(s) == 0
    rows = bf.slice_rows(s, capacity=16)
    assert rows.shape == (16, 20) and not rows.any()
    p = polytope("5-cell")
    far = slice_polytope(p, np.eye(4), 2.0 * p.circumradius)
    assert not bf.slice_rows(far, capacity=16).any()


def test_capacity_too_small_and_bad_shapes_raise():
    s = fake_slice(n_edges=9)
    with pytest.raises(ValueError, match=r"`capacity` >= 9"):
        bf.slice_rows(s, capacity=8)
    bad = fake_slice()
    bad.vertices = np.zeros((5, 4))
    with pytest.raises(ValueError, match=r"`vertices` to have shape \(n, 3\), got \(5, 4\)"):
        bf.slice_rows(bad)
    bad = fake_slice()
    bad.triangle_cells = bad.triangle_cells[:-1]
    with pytest.raises(ValueError, match="`triangle_cells`"):
        bf.slice_rows(bad)
    with pytest.raises(ValueError, match="colour for cell 2"):
        bf.slice_rows(fake_slice(n_cells=3, n_triangles=40), cell_rgb=bf.cell_palette(2))
    empty = slice_polytope(polytope("5-cell"), np.eye(4), 10.0)  # no triangles: the eye is still checked
    for eye in [(0.0, 5.0), (0.0, 0.0, float("nan")), "eye"]:
        for s_ in (fake_slice(), empty):
            with pytest.raises(ValueError, match="`eye` to be three finite numbers"):
                bf.slice_rows(s_, capacity=16, eye=eye)


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
        cap = bf.estimate_capacity(p)
        assert cap % 16 == 0
        most = max(bf.rows_needed(slice_polytope(p, random_rotation(rng), 0.0)) for _ in range(20))
        assert most <= cap <= 2 * most


# ------------------------------------------------------------------ sizes
def test_bytes_per_update_within_budget_for_every_polychoron():
    """Central slices are the largest; 64 KB is the issue's budget per update."""
    rng = np.random.default_rng(2)
    for name in POLYTOPE_NAMES:
        p = polytope(name)
        most = max(bf.rows_needed(slice_polytope(p, random_rotation(rng), 0.0)) for _ in range(30))
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
def test_cylinder_template_is_closed_and_wound_outwards():
    pos, nrm = bf.cylinder_template(12)
    assert pos.dtype == nrm.dtype == np.float32 and pos.shape == nrm.shape == (12 * 12, 3)
    assert pos.flags["C_CONTIGUOUS"] and nrm.flags["C_CONTIGUOUS"]
    np.testing.assert_allclose(np.linalg.norm(nrm, axis=1), 1.0, atol=1e-6)
    assert set(np.unique(pos[:, 2])) == {0.0, 1.0}
    tri = pos.reshape(-1, 3, 3).astype(np.float64)
    face_n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    centroid = tri.mean(axis=1) - [0.0, 0.0, 0.5]
    assert np.all((face_n * centroid).sum(axis=1) > 0)  # CCW seen from outside
    # every edge of the closed surface is shared by exactly two triangles
    key = lambda p: tuple(np.round(p, 5))  # noqa: E731
    edges = {}
    for t in tri:
        for i in range(3):
            e = tuple(sorted([key(t[i]), key(t[(i + 1) % 3])]))
            edges[e] = edges.get(e, 0) + 1
    assert set(edges.values()) == {2}
    with pytest.raises(ValueError, match="`segments` >= 3"):
        bf.cylinder_template(2)


def test_quad_and_triangle_templates():
    q = bf.quad_template()
    assert q.shape == (6, 3) and q.dtype == np.float32
    assert set(map(tuple, q[:, :2].tolist())) == {(-1, -1), (1, -1), (1, 1), (-1, 1)}
    t = bf.triangle_template()
    np.testing.assert_array_equal(t, np.eye(3))
    assert t.dtype == np.float32
