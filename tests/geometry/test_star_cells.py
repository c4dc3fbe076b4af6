"""Star faces and non-convex or star cells, cut by w = c0 (issue 22), checked against independent
computations that never call the slicer's steps:

* the {5/2}-{5} duoprism (pentagram faces, pentagram-prism cells): its slice points are the edges'
  crossings (each edge interpolated here), the slices' volumes integrate over c0 (scipy quad) to the
  winding-weighted 4-volume (pentagram's shoelace area x pentagon's area), and every cell's drawn
  triangles cover exactly the points of its section that lie inside the 4-D cell by ray parity;
* the prism over a dented octahedron (a non-convex, embedded cell): the slice volume is the
  polyhedron's closed-form volume at every level, the cap included at the prism's end levels;
* prisms over the small stellated dodecahedron {5/2,5}, the great dodecahedron {5,5/2} and the great
  icosahedron {3,5/2} (self-intersecting cells): the drawn triangles' even-odd region is the
  polyhedron's by ray parity against its own faces (random points), their area the faces' even-odd
  area (closed form: a pentagram's five points), the volume the winding-weighted closed form.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from scipy.integrate import quad

from mesh_shapes import duoprism_mesh, prism_mesh
from reference_geometry import random_rotation
from rot4d_widget import Polytope, slice_polytope

PHI = (1 + math.sqrt(5)) / 2


# -- independent geometry ----------------------------------------------------------------------


def shoelace(xy):
    """Signed area of a closed polygon (counts each region as often as the polygon winds round it)."""
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def in_polygon(pt, poly):
    """Even-odd point-in-polygon (2-D ray to +x), any density."""
    x, y = pt
    inside = False
    for (x1, y1), (x2, y2) in zip(poly, np.roll(poly, -1, axis=0)):
        if (y1 > y) != (y2 > y) and x < x1 + (y - y1) * (x2 - x1) / (y2 - y1):
            inside = not inside
    return inside


def plane_frame(points):
    """(origin, (2, d) orthonormal axes) of a planar point set."""
    c = points.mean(axis=0)
    return c, np.linalg.svd(points - c)[2][:2]


def parity_in_faces(pt, faces_xyz, direction):
    """Ray parity of ``pt`` against polygons in 3-D (each face hit where it is odd, even-odd)."""
    hits = 0
    for poly in faces_xyz:
        c, ax = plane_frame(poly)
        n = np.cross(ax[0], ax[1])
        den = direction @ n
        if abs(den) < 1e-12:
            continue
        s = ((c - pt) @ n) / den
        if s <= 0:
            continue
        q = pt + s * direction - c
        hits += in_polygon(q @ ax.T, (poly - c) @ ax.T)
    return hits % 2


def parity_in_triangles(pts, tri_xyz, direction):
    """(n,) ray parity of every point against triangles (Moller-Trumbore), vectorised over triangles."""
    A, B, C = tri_xyz[:, 0], tri_xyz[:, 1], tri_xyz[:, 2]
    e1, e2 = B - A, C - A
    pvec = np.cross(direction, e2)
    det = np.einsum("ij,ij->i", e1, pvec)
    ok = np.abs(det) > 1e-14
    out = np.empty(len(pts), dtype=int)
    for k, p in enumerate(pts):
        tv = p - A
        u = np.einsum("ij,ij->i", tv, pvec) / np.where(ok, det, 1)
        qv = np.cross(tv, e1)
        v = (qv @ direction) / np.where(ok, det, 1)
        t = np.einsum("ij,ij->i", e2, qv) / np.where(ok, det, 1)
        out[k] = int((ok & (u > 0) & (v > 0) & (u + v < 1) & (t > 0)).sum()) % 2
    return out


def triangle_area(s, cells=None):
    v = np.asarray(s.vertices)
    t = np.asarray(s.triangles)
    if cells is not None:
        t = t[np.isin(s.triangle_cells, cells)]
    T = v[t]
    return 0.5 * float(np.linalg.norm(np.cross(T[:, 1] - T[:, 0], T[:, 2] - T[:, 0]), axis=1).sum())


def edge_crossings(p, m, c0):
    """(k, 3) the points where the polytope's edges cross w = c0 (rotated), computed here."""
    x = np.asarray(p.vertices) @ m.T
    a, b = np.asarray(p.edges).T
    wa, wb = x[a, 3] - c0, x[b, 3] - c0
    cross = wa * wb < 0
    s = (wa[cross] / (wa[cross] - wb[cross]))[:, None]
    return x[a[cross], :3] + s * (x[b[cross], :3] - x[a[cross], :3])


def same_points(a, b, tol=1e-9):
    if len(a) != len(b):
        return False
    d = np.linalg.norm(a[:, None] - b[None], axis=2)
    return bool((d.min(axis=1) < tol).all() and (d.min(axis=0) < tol).all())


def pentagram_areas(R):
    """(winding area, even-odd area) of the regular {5/2} of circumradius R: the inner pentagon
    counts twice by winding, not at all by parity."""
    pent = lambda r: 2.5 * r * r * math.sin(2 * math.pi / 5)  # noqa: E731
    a = np.pi / 2 + 4 * np.pi * np.arange(5) / 5
    wind = shoelace(R * np.stack([np.cos(a), np.sin(a)], 1))
    inner = pent(R * math.cos(2 * math.pi / 5) / math.cos(math.pi / 5))
    return wind, wind - 2 * inner


# -- shapes built by hand -------------------------------------------------------------------------


def star_duoprism_mesh(edge=2.0):
    """The {5/2}-{5} duoprism: `duoprism_mesh(5, 5)` with the first factor's corners i placed at
    angle 4 pi i / 5, so its 'pentagons' are pentagrams and its p-gonal prisms pentagram prisms."""
    v, f, c = duoprism_mesh(5, 5, edge)
    rp = float(np.linalg.norm(v[0, :2]))
    ang = 4 * np.pi * (np.arange(25) // 5) / 5
    v = v.copy()
    v[:, 0], v[:, 1] = rp * np.cos(ang), rp * np.sin(ang)
    return v, f, c, rp


def icosahedron():
    v = np.array([p for a, b in itertools.product((-1, 1), repeat=2)
                  for p in ((0, a, b * PHI), (a, b * PHI, 0), (b * PHI, 0, a))], float)
    d = np.linalg.norm(v[:, None] - v[None], axis=2)
    return v, np.isclose(d, 2.0)


def ring(v, adj, k):
    """The 5 neighbours of vertex k in cyclic order around it."""
    nb = np.flatnonzero(adj[k])
    c, ax = plane_frame(v[nb])
    xy = (v[nb] - c) @ ax.T
    return nb[np.argsort(np.arctan2(xy[:, 1], xy[:, 0]))]


def great_dodecahedron():
    v, adj = icosahedron()
    return v, [ring(v, adj, k).tolist() for k in range(12)]


def small_stellated_dodecahedron():
    v, adj = icosahedron()
    return v, [ring(v, adj, k)[[0, 2, 4, 1, 3]].tolist() for k in range(12)]


def great_icosahedron():
    v, _ = icosahedron()
    d = np.linalg.norm(v[:, None] - v[None], axis=2)
    far = np.isclose(d, 2 * PHI)  # the second-neighbour chords
    return v, [list(t) for t in itertools.combinations(range(12), 3)
               if far[t[0], t[1]] and far[t[1], t[2]] and far[t[0], t[2]]]


def dented_octahedron():
    """A square bipyramid with one apex pushed inside: non-convex, embedded; volume 2/3."""
    v = np.array([[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0], [0, 0, 1.5], [0, 0, 0.5]], float)
    faces = [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4], [1, 0, 5], [2, 1, 5], [3, 2, 5], [0, 3, 5]]
    return v, faces


def winding_volume(v, faces):
    """(1/3) sum of each face plane's distance from the centre times its shoelace (winding) area,
    every face oriented away from the centre (a regular star polyhedron's faces all are)."""
    total = 0.0
    for f in faces:
        poly = v[f]
        c, ax = plane_frame(poly)
        n = np.cross(ax[0], ax[1])
        area = shoelace((poly - c) @ ax.T)
        if c @ n < 0:
            n, area = -n, -area
        total += (c @ n) * abs(area) / 3
    return total


# -- the {5/2}-{5} duoprism ----------------------------------------------------------------------


@pytest.fixture(scope="module")
def star_duoprism():
    v, f, c, rp = star_duoprism_mesh()
    return Polytope(v, f, c, name="{5/2}-{5} duoprism"), rp


def test_star_duoprism_loads_as_self_intersecting(star_duoprism):
    p, _ = star_duoprism
    assert p.counts == (25, 50, 35, 10)
    assert p.convex is False and p.self_intersecting is True
    assert p.star.face_star.sum() == 5 and p.star.cell_convex.tolist() == [True] * 5 + [False] * 5


def test_star_duoprism_slice_points_and_volume_at_the_identity(star_duoprism):
    p, rp = star_duoprism
    wind, odd = pentagram_areas(rp)
    q = np.asarray(p.vertices)[:5, 2:]  # the pentagon (z, w)
    edge = 2 * rp * math.sin(2 * math.pi / 5)  # a pentagram side
    for c0 in (0.1, 0.3, -0.7, 1.2):
        s = slice_polytope(p, np.eye(4), c0)
        pts = np.asarray(s.vertices)[: len(s.vertices) - s.n_fill]
        assert same_points(pts, edge_crossings(p, np.eye(4), c0))
        zs = [a[0] + (c0 - a[1]) / (b[1] - a[1]) * (b[0] - a[0])
              for a, b in zip(q, np.roll(q, -1, axis=0)) if (a[1] - c0) * (b[1] - c0) < 0]
        chord = abs(zs[0] - zs[1])
        assert s.volume == pytest.approx(wind * chord, rel=1e-9)  # winding-weighted
        # drawn: two pentagram caps (even-odd: the five points) and five rectangles
        assert triangle_area(s) == pytest.approx(2 * odd + 5 * edge * chord, rel=1e-9)
        assert sorted(s.face_census().items()) == [(4, 5), (5, 2)]


def test_star_duoprism_cavalieri_under_a_rotation(star_duoprism):
    p, rp = star_duoprism
    wind, _ = pentagram_areas(rp)
    q = np.asarray(p.vertices)[:5, 2:]
    vol4 = wind * abs(shoelace(q))
    m = random_rotation(7)
    w = np.asarray(p.vertices) @ m[3]
    val, err = quad(lambda c: slice_polytope(p, m, c).volume, w.min(), w.max(), limit=400,
                    points=np.sort(w)[1:-1])
    assert val == pytest.approx(vol4, rel=1e-6)


@pytest.mark.parametrize("seed, c0", [(3, 0.2), (11, -0.4), (19, 0.9)])
def test_star_duoprism_drawn_region_is_each_cells_parity_region(star_duoprism, seed, c0):
    """Random points of each crossing cell's section plane: inside a drawn triangle of that cell
    exactly when inside the 4-D cell by ray parity (even-odd) within its hyperplane."""
    p, _ = star_duoprism
    m = random_rotation(seed)
    s = slice_polytope(p, m, c0)
    x = np.asarray(p.vertices) @ m.T
    v = np.asarray(s.vertices)
    rng = np.random.default_rng(seed)
    assert same_points(v[: len(v) - s.n_fill], edge_crossings(p, m, c0))
    for cell in np.unique(s.triangle_cells):
        faces = [x[p.faces[f]] for f in p.cells[cell]]
        tri = v[s.triangles[s.triangle_cells == cell]]
        c, ax = plane_frame(tri.reshape(-1, 3))
        xy = (tri.reshape(-1, 3) - c) @ ax.T
        lo, hi = xy.min(axis=0) - 0.2, xy.max(axis=0) + 0.2
        sample = rng.uniform(lo, hi, size=(300, 2))
        pts3 = c + sample @ ax
        T2 = (tri - c) @ ax.T  # (k, 3, 2)
        drawn = np.zeros(len(sample), dtype=int)
        for A, B, C in T2:
            d1 = (B[0] - A[0]) * (sample[:, 1] - A[1]) - (B[1] - A[1]) * (sample[:, 0] - A[0])
            d2 = (C[0] - B[0]) * (sample[:, 1] - B[1]) - (C[1] - B[1]) * (sample[:, 0] - B[0])
            d3 = (A[0] - C[0]) * (sample[:, 1] - C[1]) - (A[1] - C[1]) * (sample[:, 0] - C[0])
            drawn += ((d1 > 0) & (d2 > 0) & (d3 > 0)) | ((d1 < 0) & (d2 < 0) & (d3 < 0))
        assert drawn.max() <= 1  # the fill's triangles do not overlap
        # independent: the point (x, y, z, c0) in the cell's hyperplane, ray parity against its faces
        c4, ax4 = np.mean(np.concatenate(faces), axis=0), np.linalg.svd(np.concatenate(faces) - np.mean(
            np.concatenate(faces), axis=0))[2][:3]
        faces3 = [(f - c4) @ ax4.T for f in faces]
        direction = rng.normal(size=3)
        direction /= np.linalg.norm(direction)
        inside = [parity_in_faces((np.append(q, c0) - c4) @ ax4.T, faces3, direction) for q in pts3]
        assert drawn.tolist() == inside


# -- a non-convex, embedded cell ----------------------------------------------------------------


def test_prism_over_a_dented_octahedron_has_the_polyhedrons_volume():
    p = Polytope(*prism_mesh(*dented_octahedron()))
    assert p.convex is False and p.self_intersecting is False
    assert p.star.cell_convex.tolist() == [False, False] + [True] * 8
    for c0 in (0.0, 0.25, 0.5, 0.999, 1.0):
        s = slice_polytope(p, np.eye(4), c0)
        assert s.volume == pytest.approx(2 / 3, rel=1e-12) and s.dim == 3
        assert s.face_census() == {3: 8}
    assert slice_polytope(p, np.eye(4), 1.01).dim == -1
    m = random_rotation(4)
    w = np.asarray(p.vertices) @ m[3]
    val = quad(lambda c: slice_polytope(p, m, c).volume, w.min(), w.max(), limit=400, points=np.sort(w)[1:-1])[0]
    assert val == pytest.approx(2 / 3, rel=1e-6)  # Cavalieri: 4-volume = 2/3 x height 1


# -- star cells: prisms over the regular star polyhedra ------------------------------------------------


STARS = {"small stellated dodecahedron": small_stellated_dodecahedron, "great dodecahedron": great_dodecahedron,
         "great icosahedron": great_icosahedron}


@pytest.fixture(scope="module", params=list(STARS))
def star_prism(request):
    v3, faces3 = STARS[request.param]()
    return request.param, v3, faces3, Polytope(*prism_mesh(v3, faces3), name=f"{request.param} prism")


def test_star_polyhedra_counts(star_prism):
    name, v3, faces3, p = star_prism
    edges = {tuple(sorted((f[i], f[(i + 1) % len(f)]))) for f in faces3 for i in range(len(f))}
    assert (len(v3), len(edges), len(faces3)) == {"small stellated dodecahedron": (12, 30, 12),
                                                  "great dodecahedron": (12, 30, 12),
                                                  "great icosahedron": (12, 30, 20)}[name]
    assert p.convex is False and p.self_intersecting is True
    # the two caps wind round their centres 3 or 7 times; a pentagram prism twice; other prisms once
    assert p.star.cell_star[:2].all()
    assert p.star.cell_star[2:].all() == (name == "small stellated dodecahedron") == p.star.cell_star[2:].any()


def test_star_prism_slice_is_the_polyhedron_by_parity_area_and_winding_volume(star_prism):
    name, v3, faces3, p = star_prism
    s = slice_polytope(p, np.eye(4), 0.5)
    v = np.asarray(s.vertices)
    assert same_points(v[: len(v) - s.n_fill], v3)
    # area: every face's even-odd region once
    areas = []
    for f in faces3:
        c, ax = plane_frame(v3[f])
        if len(f) == 5 and name == "small stellated dodecahedron":
            areas.append(pentagram_areas(np.linalg.norm(v3[f[0]] - c))[1])
        else:
            areas.append(abs(shoelace((v3[f] - c) @ ax.T)))
    assert triangle_area(s) == pytest.approx(sum(areas), rel=1e-9)
    assert s.volume == pytest.approx(winding_volume(v3, faces3), rel=1e-9)
    # the drawn surface's parity region is the polyhedron's, by ray parity against its own faces
    rng = np.random.default_rng(1)
    pts = rng.uniform(-1.9, 1.9, size=(400, 3))
    direction = rng.normal(size=3)
    direction /= np.linalg.norm(direction)
    ours = parity_in_triangles(pts, v[s.triangles], direction)
    theirs = np.array([parity_in_faces(q, [v3[f] for f in faces3], direction) for q in pts])
    assert ours.tolist() == theirs.tolist()
    assert 0 < theirs.sum() < len(pts)


def test_star_prism_cavalieri_under_a_rotation(star_prism):
    name, v3, faces3, p = star_prism
    m = random_rotation(2)
    w = np.asarray(p.vertices) @ m[3]
    val = quad(lambda c: slice_polytope(p, m, c).volume, w.min(), w.max(), limit=600, points=np.sort(w)[1:-1])[0]
    assert val == pytest.approx(winding_volume(v3, faces3) * 1.0, rel=1e-5)


def test_batched_levels_equal_single_slices(star_prism):
    _, _, _, p = star_prism
    m = random_rotation(9)
    levels = np.linspace(-1.0, 1.5, 7)
    for one, c in zip(slice_polytope(p, m, levels), levels):
        single = slice_polytope(p, m, c)
        assert one.volume == single.volume and np.array_equal(one.triangles, single.triangles)


# -- the even-odd rule on each face -------------------------------------------------------------


def face_chords(p, m, c0):
    """Per face crossing w = c0: (its sides' crossing points sorted along its line, and for each
    stretch between consecutive ones whether it is inside the face by even-odd point-in-polygon),
    computed here from the face's polygon."""
    x = np.asarray(p.vertices) @ m.T
    out = []
    for f in p.faces:
        poly = x[f]
        h = poly[:, 3] - c0
        nxt = np.roll(np.arange(len(f)), -1)
        cr = np.flatnonzero(h * h[nxt] < 0)
        if not len(cr):
            continue
        pts = poly[cr] + (h[cr] / (h[cr] - h[nxt[cr]]))[:, None] * (poly[nxt[cr]] - poly[cr])
        c, ax = plane_frame(poly)
        direction = pts[-1] - pts[0] if len(pts) > 1 else ax[0]
        pts = pts[np.argsort(pts @ direction)]
        inside = [in_polygon((0.5 * (a + b) - c) @ ax.T, (poly - c) @ ax.T) for a, b in zip(pts[:-1], pts[1:])]
        out.append((pts, inside))
    return out


@pytest.mark.parametrize("which, seed, c0", [("duoprism", 5, 0.35), ("duoprism", 8, -0.2),
                                            ("small stellated dodecahedron", 6, 0.4),
                                            ("small stellated dodecahedron", 12, -0.3)])
def test_segments_are_the_faces_even_odd_chords(star_duoprism, which, seed, c0):
    """The slice's edges are the stretches of each face's line inside the face by parity: their
    total length is the independent one, and every edge's midpoint is inside a face."""
    if which == "duoprism":
        p = star_duoprism[0]
    else:
        p = Polytope(*prism_mesh(*STARS[which]()))
    m = random_rotation(seed)
    chords = face_chords(p, m, c0)
    assert max(len(pts) for pts, _ in chords) >= 4  # some face is cut four times: the rule matters
    expected = sum(float(np.linalg.norm(b - a)) for pts, inside in chords
                   for a, b, i in zip(pts[:-1], pts[1:], inside) if i)
    s = slice_polytope(p, m, c0)
    v = np.asarray(s.vertices)
    e = np.asarray(s.edges)
    assert float(np.linalg.norm(v[e[:, 0]] - v[e[:, 1]], axis=1).sum()) == pytest.approx(expected, rel=1e-9)
    x = np.asarray(p.vertices) @ m.T
    frames = [(plane_frame(x[f]), x[f]) for f in p.faces]
    for a, b in e:
        mid = np.append(0.5 * (v[a] + v[b]), c0)
        assert any(np.linalg.norm((mid - c) - ((mid - c) @ ax.T) @ ax) < 1e-9
                   and in_polygon((mid - c) @ ax.T, (poly - c) @ ax.T) for (c, ax), poly in frames)


@pytest.mark.parametrize("seed, c0", [(13, 0.3), (14, -0.5), (22, 0.45)])
@pytest.mark.parametrize("name", ["great dodecahedron", "great icosahedron"])
def test_cycles_run_each_segment_both_ways(name, seed, c0):
    """Each segment bounds the sections of its face's two cells, wound against each other (the
    cycles follow the boundary's orientation) where the faces wind round at most once, however the
    cells pass through each other.  (Not so with star faces: a pentagram's even-odd points border
    both its outside and its doubly wound centre, and no one way round a cycle agrees with both.)"""
    m = random_rotation(seed)
    p = Polytope(*prism_mesh(*STARS[name]()))
    s = slice_polytope(p, m, c0)
    idx, off = np.asarray(s.polygon_indices), np.asarray(s.polygon_offsets)
    nxt = np.arange(1, len(idx) + 1)
    nxt[off[1:] - 1] = off[:-1]
    directed = sorted(zip(idx.tolist(), idx[nxt].tolist()))
    assert len(directed) > 0 and directed == sorted((b, a) for a, b in directed)


def test_touching_and_missing_levels(star_duoprism):
    """At the top vertex's level H only touches (dim 0, no polygons, volume 0); above, it misses."""
    p, _ = star_duoprism
    m = random_rotation(3)
    w = np.asarray(p.unit_vertices) @ m[3] * p.unit
    top = slice_polytope(p, m, float(w.max()))
    assert top.dim == 0 and len(top.polygon_offsets) == 1 and top.volume == 0 and len(top.triangles) == 0
    assert slice_polytope(p, m, float(w.max()) + 0.5).dim == -1
