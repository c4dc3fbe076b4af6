"""The even-odd fill of the regular star polychora's sections (issue 22), checked against an
independent computation that never calls the slicer's steps.

For random cells of a slice at random rotations and levels: random points of the cell's section
plane are inside a drawn triangle of that cell exactly when they are inside the 4-D cell by ray
parity (a ray in the cell's hyperplane, its hits on the cell's faces counted even-odd in each
face's own plane), and no point is inside two of its triangles (the view draws the fill
translucent: an overlap would show as a darker patch).  Then, per cell, the triangles' area is
the sampled even-odd area (within the sampling error), and every triangle is wound the way the
cell's outward normal says (the fill's vector area is the section's, not its mirror).

The great icosahedral and great grand 120-cells have cells whose sections are several cycles
crossing each other (dozens of crossings a cell); the great 120-cell fewer; the small stellated
120-cell's are mostly star-shaped (fanned from a centroid).
"""

from __future__ import annotations

import numpy as np
import pytest
from reference_geometry import random_rotation
from scipy.spatial import cKDTree

from rot4d_widget import polytope, slice_polytope
from rot4d_widget.geometry.slicing.even_odd_fill import arrangement_fill

NAMES = ["great icosahedral 120-cell", "great grand 120-cell", "great 120-cell", "small stellated 120-cell",
         "great stellated 120-cell"]


def _frame(points):
    """(origin, (k, d) orthonormal rows spanning the affine hull's first k principal axes)."""
    c = points.mean(axis=0)
    return c, np.linalg.svd(points - c)[2]


def _inside_faces(q, faces, direction):
    """(n,) ray parity of points ``q`` (n, 3) against planar polygons ``faces`` (list of (k, 3)),
    the ray ``q + s direction`` (s > 0); each face hit counts when the hit is inside the face by
    the even-odd rule in the face's plane."""
    hits = np.zeros(len(q), dtype=int)
    for poly in faces:
        c, ax = _frame(poly)
        n = np.cross(ax[0], ax[1])
        den = direction @ n
        if abs(den) < 1e-12:
            continue
        s = ((c - q) @ n) / den
        h = q + s[:, None] * direction - c
        x, y = h @ ax[0], h @ ax[1]
        p2 = (poly - c) @ ax[:2].T
        odd = np.zeros(len(q), dtype=bool)
        for (x1, y1), (x2, y2) in zip(p2, np.roll(p2, -1, axis=0)):
            if y1 == y2:
                continue
            odd ^= ((y1 > y) != (y2 > y)) & (x < x1 + (y - y1) * (x2 - x1) / (y2 - y1))
        hits += odd & (s > 0)
    return hits % 2


def _drawn(sample, tri2):
    """(n,) how many of the triangles ``tri2`` (k, 3, 2) contain each point of ``sample`` (n, 2)."""
    A, B, C = tri2[:, None, 0], tri2[:, None, 1], tri2[:, None, 2]
    s = sample[None]

    def side(P, Q):
        return (Q[..., 0] - P[..., 0]) * (s[..., 1] - P[..., 1]) - (Q[..., 1] - P[..., 1]) * (s[..., 0] - P[..., 0])

    d1, d2, d3 = side(A, B), side(B, C), side(C, A)
    return (((d1 > 0) & (d2 > 0) & (d3 > 0)) | ((d1 < 0) & (d2 < 0) & (d3 < 0))).sum(axis=0)


def _check_cells(p, m, c0, rng, n_cells=12, n_pts=400):
    s = slice_polytope(p, m, c0)
    x = np.asarray(p.vertices) @ m.T
    v = np.asarray(s.vertices)
    tri_cells = np.asarray(s.triangle_cells)
    cells = np.unique(tri_cells)
    assert len(cells)
    checked = 0
    for cell in rng.permutation(cells)[:n_cells]:
        faces4 = [x[p.faces[f]] for f in p.cells[cell]]
        allv = np.concatenate(faces4)
        c4, ax4 = _frame(allv)
        ax4 = ax4[:3]  # the cell's hyperplane
        faces3 = [(f - c4) @ ax4.T for f in faces4]
        tri = v[np.asarray(s.triangles)[tri_cells == cell]]  # (k, 3, 3)
        flat = tri.reshape(-1, 3)
        c, ax = _frame(flat)
        assert np.abs((flat - c) @ ax[2]).max() < 1e-9  # the fill is flat
        T2 = (tri - c) @ ax[:2].T
        # the section's extent: the cell's vertices' hull cut by the level, bounded by the
        # triangles' box grown by a margin (points outside every triangle count too)
        lo, hi = T2.reshape(-1, 2).min(axis=0), T2.reshape(-1, 2).max(axis=0)
        pad = 0.25 * (hi - lo).max()
        sample = rng.uniform(lo - pad, hi + pad, size=(n_pts, 2))
        q4 = np.concatenate([c + sample @ ax[:2], np.full((n_pts, 1), c0)], axis=1)
        q3 = (q4 - c4) @ ax4.T
        assert np.abs((q4 - c4) - q3 @ ax4).max() < 1e-9  # the section plane lies in the cell's hyperplane
        direction = rng.normal(size=3)
        inside = _inside_faces(q3, faces3, direction / np.linalg.norm(direction))
        drawn = _drawn(sample, T2)
        assert drawn.max() <= 1, f"cell {cell}: overlapping fill triangles"
        assert (drawn == inside).all(), f"cell {cell}: {int((drawn != inside).sum())} of {n_pts} points differ"
        # area: the triangles' against the sampled even-odd area (binomial error, 5 sigma)
        e1, e2 = T2[:, 1] - T2[:, 0], T2[:, 2] - T2[:, 0]
        area = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]).sum()
        box = float(np.prod(hi - lo + 2 * pad))
        f = inside.mean()
        assert abs(area - f * box) <= 5 * box * np.sqrt(max(f * (1 - f), 1 / n_pts) / n_pts) + 1e-12
        # orientation: every triangle wound the same way about the plane normal as the cell's
        # outward normal restricted to the level (a triangle's normal . cell normal > 0)
        n3 = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        cn = (np.asarray(p.cell_normals)[cell] @ m.T)[:3]
        assert (n3 @ cn > -1e-12).all()  # (a sliver of no area may come out either way)
        checked += 1
    return checked


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("seed, level", [(1, 0.05), (7, -0.4), (23, 0.75)])
def test_fill_is_each_cells_even_odd_region_without_overlap(name, seed, level):
    """At ``level`` times the circumradius."""
    p = polytope(name)
    rng = np.random.default_rng(seed)
    assert _check_cells(p, random_rotation(seed), level * p.circumradius, rng) > 0


def test_a_level_through_vertices_fills_alike():
    """A level at a vertex's height (vertices on H: crossings merged into them)."""
    p = polytope("great icosahedral 120-cell")
    m = random_rotation(5)
    w = (np.asarray(p.vertices) @ m.T)[:, 3]
    c0 = float(np.sort(w)[len(w) // 3])
    assert _check_cells(p, m, c0, np.random.default_rng(5), n_cells=20) > 0


def _section_crossings(s):
    """(k, 3) the points where two edges of one cell's section polygons cross inside both, from
    the slice's polygons alone (per cell, every pair of its polygons' edges)."""
    v = np.asarray(s.vertices)
    out = []
    by_cell = {}
    for q, c in zip(s.polygons, np.asarray(s.cell_ids).tolist()):
        by_cell.setdefault(c, []).append(q)
    for qs in by_cell.values():
        a = np.concatenate(qs)
        b = np.concatenate([np.roll(q, -1) for q in qs])
        c0, ax = _frame(v[np.concatenate([a, b])])
        A, B = (v[a] - c0) @ ax[:2].T, (v[b] - c0) @ ax[:2].T
        i, j = np.triu_indices(len(a), 1)
        d1, d2, e = B[i] - A[i], B[j] - A[j], A[j] - A[i]
        den = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (e[:, 0] * d2[:, 1] - e[:, 1] * d2[:, 0]) / den
            u = (e[:, 0] * d1[:, 1] - e[:, 1] * d1[:, 0]) / den
        hit = (den != 0) & (t > 1e-9) & (t < 1 - 1e-9) & (u > 1e-9) & (u < 1 - 1e-9)
        out.append(v[a[i[hit]]] + t[hit, None] * (v[b[i[hit]]] - v[a[i[hit]]]))
    return np.concatenate(out)


@pytest.mark.parametrize("name", ["great icosahedral 120-cell", "great grand 120-cell", "great 120-cell"])
@pytest.mark.parametrize("seed", [2, 9])
def test_crossing_sections_fill_with_their_crossings_as_only_new_corners(name, seed):
    """Sections of several crossing cycles are filled from their arrangement: the fill's new corners
    are exactly the points where two of the cell's section edges cross (none where a slab line would
    cut an edge), and the triangles about (edges + crossings) per cell, not slabs x edges."""
    p = polytope(name)
    s = slice_polytope(p, random_rotation(seed), 0.1 * p.circumradius)
    v = np.asarray(s.vertices)
    fill = v[len(v) - s.n_fill:]
    want = _section_crossings(s)
    assert len(fill) == len(want)
    assert cKDTree(want).query(fill)[0].max() < 1e-9 and cKDTree(fill).query(want)[0].max() < 1e-9
    n_edges = sum(len(q) for q in s.polygons)
    assert len(s.triangles) <= n_edges + 2 * len(want)


def _one_cycle(xy):
    """arrangement_fill's inputs for one closed polygon ``xy`` (k, 2) in the plane z = 0, its one cell's
    normal +z: record r is the side from corner r to r + 1 (ends 2r, 2r + 1), each end's partner the
    touching end of the neighbouring side."""
    k = len(xy)
    pts = np.concatenate([xy, np.zeros((k, 1))], axis=1)
    end_pt = np.stack([np.arange(k), (np.arange(k) + 1) % k], axis=1).ravel()
    partner = np.empty(2 * k, dtype=np.intp)
    partner[2 * np.arange(k) + 1] = 2 * ((np.arange(k) + 1) % k)
    partner[2 * ((np.arange(k) + 1) % k)] = 2 * np.arange(k) + 1
    return (np.arange(k), np.zeros(k, dtype=np.intp), end_pt, partner, pts, np.arange(k),
            np.array([[0.0, 0.0, 1.0]]), np.zeros((1, 3)), k)


def test_arrangement_fill_of_a_pentagram_and_a_dented_bowtie():
    """A pentagram: its five points filled, a corner at each of its five crossings, each triangle
    counter-clockwise about +z; a bowtie with one lobe dented (an odd face with a reflex corner):
    left to the slab fill, not fanned."""
    a = np.pi / 2 + 4 * np.pi * np.arange(5) / 5
    star = np.stack([np.cos(a), np.sin(a)], axis=1)
    tri, cells, extra, rest, _ = arrangement_fill(*_one_cycle(star))
    assert not rest.any() and len(extra) == 5 and len(tri) == 5
    v = np.concatenate([star, extra[:, :2]])
    rng = np.random.default_rng(0)
    sample = rng.uniform(-1.1, 1.1, size=(4000, 2))
    inside = np.zeros(len(sample), dtype=int)
    for (x1, y1), (x2, y2) in zip(star, np.roll(star, -1, axis=0)):
        inside ^= ((y1 > sample[:, 1]) != (y2 > sample[:, 1])) & (
            sample[:, 0] < x1 + (sample[:, 1] - y1) * (x2 - x1) / (y2 - y1))
    assert (_drawn(sample, v[tri]) == inside).all()
    e1, e2 = v[tri[:, 1]] - v[tri[:, 0]], v[tri[:, 2]] - v[tri[:, 0]]
    assert (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0] > 0).all()
    bowtie = np.array([[0, 0], [2, 2], [2, 0], [0, 2], [0.5, 1.0]])
    tri, cells, extra, rest, _ = arrangement_fill(*_one_cycle(bowtie))
    assert rest.all() and len(tri) == 0 and len(extra) == 0
