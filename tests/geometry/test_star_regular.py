"""The ten regular star polychora (Schläfli–Hess, issue 22), built by rot4d_widget.geometry.star_regular.

Checked against the published figures (Wikipedia "Schläfli–Hess polychoron" and the Polytope Wiki's
pages, after Coxeter, Regular Polytopes, table I(iv)): counts, Euler characteristic, density; and
against the definition of the Schläfli symbol {p,q,r}: every face a regular {p} of edge 2, every
cell a regular {p,q} (its vertex figures regular {q}, star or not, by their turning number), every
edge in r cells winding round it as {r} does.

The density is computed here, independently of the construction and of `Polytope`: the cells are
oriented outward (normal = the direction of the cell's centre) and their faces outward in each
cell; that this is a consistent orientation of the boundary is checked (every face gets opposite
orientations from its two cells, every cell edge is run once each way).  Then the winding number
of the boundary round the centre is the sum, over the cells a ray from the centre crosses, of the
cell's own 3-D winding number at the crossing (its faces fan-triangulated from their centres,
solid angles summed), for several random rays.

As `Polytope` objects (validated, with star faces and non-convex cells): one cached object per
name, not convex, self-intersecting, and a slice through the centre whose points are exactly the
edges' crossings, computed here from the vertices and edges.
"""

from __future__ import annotations

import math
from collections import defaultdict

import numpy as np
import pytest
from scipy.spatial import cKDTree

import rot4d_widget
from rot4d_widget import polytope
from rot4d_widget.core.rotation import random_rotation
from rot4d_widget.geometry import star_regular
from rot4d_widget.geometry.slicing.polytope_slice import slice_polytope
from rot4d_widget.geometry.star_regular import STAR_FAMILY, star_arrays

PHI = (1 + math.sqrt(5)) / 2

#: name: (Schläfli symbol, (V, E, F, C), Euler characteristic V - E + F - C, density), as published
PUBLISHED = {
    "icosahedral 120-cell": ("{3,5,5/2}", (120, 720, 1200, 120), 480, 4),
    "small stellated 120-cell": ("{5/2,5,3}", (120, 1200, 720, 120), -480, 4),
    "great 120-cell": ("{5,5/2,5}", (120, 720, 720, 120), 0, 6),
    "grand 120-cell": ("{5,3,5/2}", (120, 720, 720, 120), 0, 20),
    "great stellated 120-cell": ("{5/2,3,5}", (120, 720, 720, 120), 0, 20),
    "grand stellated 120-cell": ("{5/2,5,5/2}", (120, 720, 720, 120), 0, 66),
    "great grand 120-cell": ("{5,5/2,3}", (120, 1200, 720, 120), -480, 76),
    "great icosahedral 120-cell": ("{3,5/2,5}", (120, 720, 1200, 120), 480, 76),
    "grand 600-cell": ("{3,3,5/2}", (120, 720, 1200, 600), 0, 191),
    "great grand stellated 120-cell": ("{5/2,3,3}", (600, 1200, 720, 120), 0, 191),
}
NAMES = list(PUBLISHED)
#: density of each cell (a regular polyhedron) about its own centre: Kepler–Poinsot's 3 and 7
CELL_DENSITY = {"{3,3}": 1, "{3,5}": 1, "{5,3}": 1, "{5,5/2}": 3, "{5/2,5}": 3, "{3,5/2}": 7, "{5/2,3}": 7}


def _symbol(sym: str):
    """"{5/2,3,3}" -> [(5, 2), (3, 1), (3, 1)]: (numerator, density) of each entry."""
    out = []
    for s in sym.strip("{}").split(","):
        n, _, d = s.partition("/")
        out.append((int(n), int(d or 1)))
    return out


def _edges(faces):
    return {tuple(sorted((f[k], f[k - 1]))) for f in faces for k in range(len(f))}


def _plane(points):
    """Centroid, 2-D coordinates in the best plane, and the distance of the farthest point from it."""
    g = points.mean(axis=0)
    _, s, vt = np.linalg.svd(points - g)
    return g, (points - g) @ vt[:2].T, (s[2] if len(s) > 2 else 0.0)


def _turns(xy, about=None):
    """How many times the closed polygon ``xy`` (n, 2) winds round ``about`` (default its centroid)."""
    c = xy.mean(axis=0) if about is None else about
    a = np.arctan2(xy[:, 1] - c[1], xy[:, 0] - c[0])
    d = np.diff(np.append(a, a[0]))
    return round(float(np.sum((d + np.pi) % (2 * np.pi) - np.pi)) / (2 * np.pi))


@pytest.fixture(scope="module")
def built():
    return {n: star_arrays(n) for n in NAMES}


@pytest.mark.parametrize("name", NAMES)
def test_counts_and_euler_characteristic(built, name):
    v, faces, cells = built[name]
    sym, counts, chi, _ = PUBLISHED[name]
    got = (len(v), len(_edges(faces)), len(faces), len(cells))
    assert got == counts
    assert got[0] - got[1] + got[2] - got[3] == chi
    assert len({frozenset(f) for f in faces}) == len(faces)  # a face shared by two cells is one face
    per_face = np.bincount(np.concatenate([np.asarray(c) for c in cells]), minlength=len(faces))
    assert np.all(per_face == 2)  # closed
    assert np.allclose(np.linalg.norm(v, axis=1), np.linalg.norm(v[0]))  # one circumradius


@pytest.mark.parametrize("name", NAMES)
def test_every_face_is_a_regular_p_gon_of_edge_2(built, name):
    v, faces, _ = built[name]
    (p, q), _, _ = _symbol(PUBLISHED[name][0])
    # corners k and k + 2 of a regular {p/q}: 2 * the ratio of its chord over two steps to one step
    skip = 2 * math.sin(2 * math.pi * q * 2 / (2 * p)) / math.sin(math.pi * q / p) if p == 5 else None
    for f in faces:
        pts = v[f]
        assert len(f) == p
        assert np.allclose(np.linalg.norm(pts - np.roll(pts, -1, axis=0), axis=1), 2.0, atol=1e-9)
        g, xy, off = _plane(pts)
        assert off < 1e-9
        assert np.allclose(np.linalg.norm(xy, axis=1), np.linalg.norm(xy[0]), atol=1e-9)
        assert abs(_turns(xy)) == q  # a pentagram winds twice round its centre
        if skip is not None:
            assert np.allclose(np.linalg.norm(pts - np.roll(pts, -2, axis=0), axis=1), skip, atol=1e-9)
    assert skip is None or math.isclose(skip, 2 * PHI if q == 1 else 2 / PHI)


def _cell_frames(v, faces, cells):
    """Per cell: centre, outward unit normal, a (4, 3) basis of its hyperplane oriented with the
    normal first, and each face's orientation in the cell (+1: as stored, -1: reversed) that makes
    its fan triangles' normals point away from the cell's centre."""
    out = []
    for c in cells:
        verts = sorted({i for f in c for i in faces[f]})
        centre = v[verts].mean(axis=0)
        u = centre / np.linalg.norm(centre)
        basis = np.linalg.svd(np.eye(4) - np.outer(u, u))[0][:, :3]
        if np.linalg.det(np.column_stack([u, basis])) < 0:
            basis[:, 0] *= -1
        signs = []
        for f in c:
            pts = (v[faces[f]] - centre) @ basis
            g = pts.mean(axis=0)
            n = np.cross(pts[0] - g, pts[1] - g)
            signs.append(1 if n @ g > 0 else -1)
        out.append((centre, u, basis, signs))
    return out


def test_cells_and_edges_have_the_symbol(built):
    for name in NAMES:
        v, faces, cells = built[name]
        _, (q, qd), (r, rd) = _symbol(PUBLISHED[name][0])
        for c in cells:  # every vertex of a cell: q faces, their far corners a regular {q} or {q/qd}
            at = defaultdict(list)
            for f in c:
                cyc = faces[f]
                for k, x in enumerate(cyc):
                    at[x].append((cyc[k - 1], cyc[(k + 1) % len(cyc)]))
            for pairs in at.values():
                assert len(pairs) == q, name
                ring = list(pairs.pop())
                while pairs:
                    nxt = next(pr for pr in pairs if ring[-1] in pr)
                    pairs.remove(nxt)
                    ring.append(nxt[1] if nxt[0] == ring[-1] else nxt[0])
                assert ring[-1] == ring[0], name  # the faces round the vertex close up
                _, xy, off = _plane(v[ring[:-1]])
                assert off < 1e-9 and abs(_turns(xy)) == qd, name
        # every edge: r cells round it, their centres winding rd times round it
        face_cells = defaultdict(list)
        for ci, c in enumerate(cells):
            for f in c:
                face_cells[f].append(ci)
        edge_faces = defaultdict(list)
        for fi, f in enumerate(faces):
            for k in range(len(f)):
                edge_faces[tuple(sorted((f[k], f[k - 1])))].append(fi)
        centres = np.array([v[sorted({i for f in c for i in faces[f]})].mean(axis=0) for c in cells])
        for (i, j), fs in edge_faces.items():
            assert len(fs) == r, name
            ring, f = [face_cells[fs[0]][0]], fs[0]
            for _ in range(r):
                cell = next(x for x in face_cells[f] if x != ring[-1])  # across face f
                ring.append(cell)
                f = next(g for g in fs if g != f and g in cells[cell])  # the cell's other face at the edge
            assert ring[-1] == ring[0] and len(set(ring)) == r, name
            plane = np.linalg.svd(np.stack([v[i], v[j]]))[2][2:]  # the 2-plane orthogonal to the edge's
            assert abs(_turns(centres[ring[:-1]] @ plane.T, about=(0.0, 0.0))) == rd, name


def _solid_angles(p, tri):
    """Signed solid angles (Van Oosterom–Strackee) of triangles ``tri`` (T, 3, 3) seen from ``p`` (T, 3)."""
    a, b, c = (tri[:, k] - p for k in range(3))
    la, lb, lc = (np.linalg.norm(x, axis=1) for x in (a, b, c))
    num = np.einsum("ij,ij->i", a, np.cross(b, c))
    den = la * lb * lc + np.einsum("ij,ij->i", a, b) * lc + np.einsum("ij,ij->i", a, c) * lb \
        + np.einsum("ij,ij->i", b, c) * la
    return 2 * np.arctan2(num, den)


def _winding_tables(v, faces, cells):
    """Fan triangles of every cell in its own oriented 3-D coordinates: (cell of each, (T, 3, 3))."""
    frames = _cell_frames(v, faces, cells)
    owner, tris = [], []
    for ci, (c, (centre, _, basis, signs)) in enumerate(zip(cells, frames)):
        for f, s in zip(c, signs):
            pts = (v[faces[f]] - centre) @ basis
            pts = pts if s > 0 else pts[::-1]
            g = pts.mean(axis=0)
            for k in range(len(pts)):
                tris.append((g, pts[k], pts[(k + 1) % len(pts)]))
                owner.append(ci)
    return frames, np.array(owner), np.array(tris)


def _cell_winding(frames, owner, tris, points3):
    """Each cell's 3-D winding number round its point ``points3[c]`` (C, 3), not rounded."""
    om = _solid_angles(points3[owner], tris)
    return np.bincount(owner, weights=om, minlength=len(frames)) / (4 * np.pi)


def density(v, faces, cells, rays: int = 3, seed: int = 0) -> list:
    """The winding number of the boundary round the origin along ``rays`` random rays (floats)."""
    frames, owner, tris = _winding_tables(v, faces, cells)
    u = np.array([f[1] for f in frames])
    h = np.array([f[0] @ f[1] for f in frames])  # each cell's distance from the centre
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(rays):
        d = rng.normal(size=4)
        d /= np.linalg.norm(d)
        cos = u @ d
        hit = cos > 0  # the ray t d (t > 0) crosses cell c's hyperplane outward at t = h / cos
        p4 = np.where(hit[:, None], (h / np.where(hit, cos, 1))[:, None] * d, 0)
        p3 = np.array([(p4[c] - f[0]) @ f[2] for c, f in enumerate(frames)])
        w = _cell_winding(frames, owner, tris, p3)
        out.append(float(np.sum(w[hit])))
    return out


@pytest.mark.parametrize("name", NAMES)
def test_the_outward_orientation_is_consistent(built, name):
    v, faces, cells = built[name]
    frames = _cell_frames(v, faces, cells)
    seen = defaultdict(list)
    for c, (_, _, _, signs) in zip(cells, frames):
        for f, s in zip(c, signs):
            seen[f].append(s)
        # within the cell, its oriented faces run each of its edges once each way
        runs = defaultdict(int)
        for f, s in zip(c, signs):
            cyc = faces[f] if s > 0 else faces[f][::-1]
            for k in range(len(cyc)):
                runs[(cyc[k - 1], cyc[k])] += 1
        assert all(runs[(b, a)] == n == 1 for (a, b), n in runs.items())
    # a face's two cells give it opposite orientations: the cells' outward orientation is one
    # orientation of the whole boundary, so the winding number below is its degree
    assert all(sorted(s) == [-1, 1] for s in seen.values())


@pytest.mark.parametrize("name", NAMES)
def test_density_by_winding_number_is_the_published_one(built, name):
    v, faces, cells = built[name]
    frames, owner, tris = _winding_tables(v, faces, cells)
    cell_sym = "{" + ",".join(PUBLISHED[name][0].strip("{}").split(",")[:2]) + "}"
    at_centre = _cell_winding(frames, owner, tris, np.zeros((len(cells), 3)))
    assert np.allclose(at_centre, CELL_DENSITY[cell_sym], atol=1e-6)  # Kepler–Poinsot cells: 3 or 7
    got = density(v, faces, cells)
    assert np.allclose(got, np.round(got), atol=1e-6)
    assert [round(x) for x in got] == [PUBLISHED[name][3]] * len(got)


def test_names_symbols_and_aliases():
    for name, (sym, *_rest) in PUBLISHED.items():
        assert star_regular.star_name(sym) == name
        assert star_regular.star_name(name.upper().replace(" ", "_")) == name
        assert star_regular.star_name(sym.replace(",", ", ")) == name
    assert star_regular.star_name("grand hexacosichoron") == "grand 600-cell"
    assert star_regular.star_name("600-cell") is None and star_regular.star_name("{5,3,3}") is None
    assert star_arrays("{5/2,3,3}") is star_arrays("{5/2,3,3}")
    with pytest.raises(ValueError, match="great grand stellated 120-cell"):
        star_arrays("{5/2,5/2,5/2}")


def test_polytope_names_lists_the_family():
    names = rot4d_widget.polytope_names()
    assert names[STAR_FAMILY] == NAMES
    assert list(names)[-1] == STAR_FAMILY
    flat = [n for ns in names.values() for n in ns]
    assert len(flat) == len(set(flat))  # listed once, apart from the uniform ones


def test_a_bad_name_still_says_what_is_allowed():
    with pytest.raises(ValueError, match=r"'5-cell'.*'great grand stellated 120-cell' \(\{5/2,3,3\}\).*polytope_names"):
        polytope("{5/2,5/2,5/2}")
    with pytest.raises(ValueError, match="Unknown polytope '7-cell'; expected one of '5-cell'"):
        polytope("7-cell")


# -- as Polytope objects (star faces and non-convex cells accepted by the mesh checks) ---------------


@pytest.mark.parametrize("name", NAMES)
def test_a_validated_polytope_by_every_name(name):
    sym, counts, _, _ = PUBLISHED[name]
    p = polytope(name)
    assert p is polytope(sym) is polytope(name.title()) is polytope(sym.replace(",", ", "))  # one cached object
    assert p.name == name and p.counts == counts
    assert p.convex is False and p.self_intersecting is True  # density > 1: winds round its centre
    v = star_arrays(name)[0]
    assert np.array_equal(p.vertices, v)
    assert np.allclose(np.linalg.norm(v[p.edges[:, 0]] - v[p.edges[:, 1]], axis=1), 2.0)  # edge 2


@pytest.mark.parametrize("name", NAMES)
def test_the_slice_through_the_centre_is_at_the_edges_crossings(name):
    p = polytope(name)
    for seed in (1, 2):
        m = random_rotation(seed)
        s = slice_polytope(p, m, 0.0)
        x = p.vertices @ m.T  # computed here from the vertices and edges alone
        w = x[:, 3]
        assert np.abs(w).min() > 1e-6  # a generic cut: no vertex on it
        a, b = p.edges[(w[p.edges[:, 0]] < 0) != (w[p.edges[:, 1]] < 0)].T
        t = w[a] / (w[a] - w[b])
        want = x[a, :3] + t[:, None] * (x[b, :3] - x[a, :3])
        got = s.vertices[: len(s.vertices) - s.n_fill]  # the extra corners of fill triangles are not points
        assert s.dim == 3 and len(got) == len(want) > 0
        d1, _ = cKDTree(want).query(got)
        d2, _ = cKDTree(got).query(want)
        assert max(d1.max(), d2.max()) < 1e-9 * p.circumradius
