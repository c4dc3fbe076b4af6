"""The uniform polychora of rot4d_widget.geometry.uniform: counts, geometry, combinatorics, names.

Published (V, E, F, C) are from the English Wikipedia articles on the uniform 4-polytopes (the
"Uniform 4-polytope" list and the per-family articles, e.g. "Runcinated 120-cells", "Truncated
120-cells") and R. Klitzing's incidence matrices (bendwavy.org/klitzing, "Convex uniform
polychora"); see docs/user-guide.md, "Polytopes by name".
"""

import itertools

import numpy as np
import pytest
from scipy.spatial import ConvexHull, cKDTree

from rot4d_widget.geometry import uniform
from rot4d_widget.geometry.catalogue import polytope
from rot4d_widget.geometry.mesh import Polytope

PUBLISHED = {
    # A4
    "5-cell": (5, 10, 10, 5),
    "rectified 5-cell": (10, 30, 30, 10),
    "truncated 5-cell": (20, 40, 30, 10),
    "cantellated 5-cell": (30, 90, 80, 20),
    "runcinated 5-cell": (20, 60, 70, 30),
    "bitruncated 5-cell": (30, 60, 40, 10),
    "cantitruncated 5-cell": (60, 120, 80, 20),
    "runcitruncated 5-cell": (60, 150, 120, 30),
    "omnitruncated 5-cell": (120, 240, 150, 30),
    # B4
    "8-cell": (16, 32, 24, 8),
    "rectified tesseract": (32, 96, 88, 24),
    "16-cell": (8, 24, 32, 16),
    "truncated tesseract": (64, 128, 88, 24),
    "cantellated tesseract": (96, 288, 248, 56),
    "runcinated tesseract": (64, 192, 208, 80),
    "bitruncated tesseract": (96, 192, 120, 24),
    "truncated 16-cell": (48, 120, 96, 24),
    "cantitruncated tesseract": (192, 384, 248, 56),
    "runcitruncated tesseract": (192, 480, 368, 80),
    "runcitruncated 16-cell": (192, 480, 368, 80),
    "omnitruncated tesseract": (384, 768, 464, 80),
    # F4
    "24-cell": (24, 96, 96, 24),
    "rectified 24-cell": (96, 288, 240, 48),
    "truncated 24-cell": (192, 384, 240, 48),
    "cantellated 24-cell": (288, 864, 720, 144),
    "runcinated 24-cell": (144, 576, 672, 240),
    "bitruncated 24-cell": (288, 576, 336, 48),
    "cantitruncated 24-cell": (576, 1152, 720, 144),
    "runcitruncated 24-cell": (576, 1440, 1104, 240),
    "omnitruncated 24-cell": (1152, 2304, 1392, 240),
    # H4
    "120-cell": (600, 1200, 720, 120),
    "rectified 120-cell": (1200, 3600, 3120, 720),
    "rectified 600-cell": (720, 3600, 3600, 720),
    "600-cell": (120, 720, 1200, 600),
    "truncated 120-cell": (2400, 4800, 3120, 720),
    "cantellated 120-cell": (3600, 10800, 9120, 1920),
    "runcinated 120-cell": (2400, 7200, 7440, 2640),
    "bitruncated 120-cell": (3600, 7200, 4320, 720),
    "cantellated 600-cell": (3600, 10800, 8640, 1440),
    "truncated 600-cell": (1440, 4320, 3600, 720),
    "cantitruncated 120-cell": (7200, 14400, 9120, 1920),
    "runcitruncated 120-cell": (7200, 18000, 13440, 2640),
    "runcitruncated 600-cell": (7200, 18000, 13440, 2640),
    "cantitruncated 600-cell": (7200, 14400, 8640, 1440),
    "omnitruncated 120-cell": (14400, 28800, 17040, 2640),
    # non-Wythoffian
    "snub 24-cell": (96, 432, 480, 144),
    "grand antiprism": (100, 500, 720, 320),
}

#: published cell counts by type (Wikipedia / Klitzing), a sample
CELLS = {
    "runcinated 5-cell": {"tetrahedron": 10, "triangular prism": 20},
    "truncated tesseract": {"truncated cube": 8, "tetrahedron": 16},
    "cantellated 24-cell": {"rhombicuboctahedron": 24, "cuboctahedron": 24, "triangular prism": 96},
    "runcinated 120-cell": {"dodecahedron": 120, "pentagonal prism": 720, "triangular prism": 1200,
                            "tetrahedron": 600},
    "omnitruncated 120-cell": {"truncated icosidodecahedron": 120, "decagonal prism": 720,
                               "hexagonal prism": 1200, "truncated octahedron": 600},
    "snub 24-cell": {"icosahedron": 24, "tetrahedron": 120},
    "grand antiprism": {"pentagonal antiprism": 20, "tetrahedron": 300},
    "bitruncated 24-cell": {"truncated cube": 48},
}

NON_PRISMATIC = [n for fam, names in uniform.polytope_names().items()
                 if not fam.startswith(("prisms", "duoprisms", "antiprismatic")) for n in names]
BIG = {n for n in NON_PRISMATIC if PUBLISHED[n][0] > 3000}
PRISMATIC_SAMPLE = [
    "tetrahedral prism", "octahedral prism", "dodecahedral prism", "icosahedral prism",
    "truncated tetrahedral prism", "cuboctahedral prism", "truncated cubic prism", "truncated octahedral prism",
    "rhombicuboctahedral prism", "truncated cuboctahedral prism", "snub cubic prism", "icosidodecahedral prism",
    "truncated dodecahedral prism", "truncated icosahedral prism", "rhombicosidodecahedral prism",
    "truncated icosidodecahedral prism", "snub dodecahedral prism",
    "3-3 duoprism", "3-4 duoprism", "5-7 duoprism", "3-32 duoprism", "32-32 duoprism",
    "4-antiprismatic prism", "7-antiprismatic prism", "32-antiprismatic prism",
]


def test_forty_seven_non_prismatic():
    names = uniform.polytope_names()
    assert len(NON_PRISMATIC) == 47
    assert sorted(NON_PRISMATIC) == sorted(PUBLISHED)
    assert sum(len(v) for k, v in names.items() if k.startswith(("A4", "B4", "F4", "H4"))) == 45


@pytest.mark.parametrize("name", sorted(PUBLISHED))
def test_counts_match_published(name):
    assert uniform.combinatorics(name).counts == PUBLISHED[name]


@pytest.mark.parametrize("name", sorted(CELLS))
def test_cell_types_match_published(name):
    assert uniform.combinatorics(name).cell_census() == CELLS[name]


def _check_polytope(c, name):
    V, E, F, C = c.counts
    v = c.vertices
    assert V - E + F - C == 0, name
    # centred, every vertex on one sphere
    assert np.abs(v.mean(axis=0)).max() < 1e-9
    r = np.linalg.norm(v, axis=1)
    assert np.ptp(r) < 1e-9 * r.max()
    # every edge of length 2, no repeated edge or vertex
    el = np.linalg.norm(v[c.edges[:, 0]] - v[c.edges[:, 1]], axis=1)
    np.testing.assert_allclose(el, 2.0, atol=1e-9)
    assert len(np.unique(c.edges, axis=0)) == E
    assert len(np.unique(np.round(v, 6), axis=0)) == V
    # faces: regular polygons, their sides are the edges (each edge in some face)
    face_edges = np.concatenate([np.sort(np.stack([f, np.roll(f, -1)], axis=1), axis=1) for f in c.faces])
    assert {tuple(e) for e in face_edges.tolist()} == {tuple(e) for e in c.edges.tolist()}
    for size in {len(f) for f in c.faces}:
        fs = np.array([f for f in c.faces if len(f) == size])
        pts = v[fs]
        side = np.linalg.norm(pts - np.roll(pts, -1, axis=1), axis=2)
        np.testing.assert_allclose(side, 2.0, atol=1e-9)
        centre = pts.mean(axis=1, keepdims=True)
        rad = np.linalg.norm(pts - centre, axis=2)
        np.testing.assert_allclose(rad, 1.0 / np.sin(np.pi / size), atol=1e-9)  # regular size-gon
    # every face in exactly two cells, no face twice in a cell
    used = np.concatenate(c.cells)
    assert np.array_equal(np.bincount(used, minlength=F), np.full(F, 2))
    assert all(len(np.unique(cell)) == len(cell) for cell in c.cells)
    # vertex transitivity: same degree and same multiset of incident face sizes everywhere
    deg = np.bincount(c.edges.ravel(), minlength=V)
    assert (deg == deg[0]).all()
    sizes = np.concatenate([np.full(len(f), len(f)) for f in c.faces])
    verts = np.concatenate(c.faces)
    table = np.zeros((V, sizes.max() + 1), dtype=int)
    np.add.at(table, (verts, sizes), 1)
    assert (table == table[0]).all()


@pytest.mark.parametrize("name", NON_PRISMATIC)
def test_polychoron_invariants(name):
    _check_polytope(uniform.combinatorics(name), name)


@pytest.mark.parametrize("name", PRISMATIC_SAMPLE)
def test_prismatic_invariants(name):
    _check_polytope(uniform.combinatorics(name), name)


def _cell_is_convex_polyhedron(c, k):
    """Cell k lies in a hyperplane, is closed, and its faces are exactly its convex hull's facets."""
    faces = [c.faces[f] for f in c.cells[k]]
    idx = np.unique(np.concatenate(faces))
    pts = c.vertices[idx]
    centre = pts.mean(axis=0)
    _, s, vt = np.linalg.svd(pts - centre)
    assert s[3] < 1e-9 * s[0]  # flat: in a 3-D hyperplane
    xyz = (pts - centre) @ vt[:3].T
    hull = ConvexHull(xyz)
    assert len(hull.vertices) == len(idx)  # every vertex a corner
    # the hull's facets (coplanar simplices merged) are the cell's faces
    key = np.round(hull.equations, 7)
    _, inv = np.unique(key, axis=0, return_inverse=True)
    facets = {frozenset(idx[np.unique(hull.simplices[inv.ravel() == g])].tolist()) for g in range(inv.max() + 1)}
    assert facets == {frozenset(f.tolist()) for f in faces}
    # closed: each edge of the cell in exactly two of its faces
    e = np.concatenate([np.sort(np.stack([f, np.roll(f, -1)], axis=1), axis=1) for f in faces])
    _, counts = np.unique(e, axis=0, return_counts=True)
    assert (counts == 2).all()
    # and on the boundary of the polytope: every vertex on one side of the cell's hyperplane
    n = vt[3]
    h = (c.vertices - centre) @ n
    assert (h <= 1e-9).all() or (h >= -1e-9).all()


@pytest.mark.parametrize("name", NON_PRISMATIC + PRISMATIC_SAMPLE[:20])
def test_cells_are_convex_polyhedra(name):
    """One cell of every type, and a random sample of 12 more (all cells of the small ones)."""
    c = uniform.combinatorics(name)
    rng = np.random.default_rng(11)
    _, first = np.unique(c.cell_types, return_index=True)
    sample = set(first.tolist())
    if len(c.cells) <= 150:
        sample = set(range(len(c.cells)))
    else:
        sample |= set(rng.choice(len(c.cells), 12, replace=False).tolist())
    for k in sorted(sample):
        _cell_is_convex_polyhedron(c, k)


def _same_up_to_rotation(a, b):
    """A rotation (orthogonal map) R with a @ R.T == b as sets, found from a vertex and three
    neighbours, or None."""
    if a.shape != b.shape:
        return None
    da = np.linalg.norm(a - a[0], axis=1)
    near = np.argsort(da)[1:]
    # three neighbours of a[0] spanning, with a[0], the space
    frame = [0]
    for j in near:
        if np.linalg.matrix_rank(a[frame + [j]], tol=1e-6) == len(frame) + 1:
            frame.append(j)
        if len(frame) == 4:
            break
    A = a[frame]
    gram = A @ A.T
    tree = cKDTree(b)
    for i0 in range(len(b)):
        if abs(b[i0] @ b[i0] - gram[0, 0]) > 1e-6:
            continue
        cand = [np.flatnonzero(np.abs(b @ b[i0] - gram[0, k]) < 1e-6) for k in range(1, 4)]
        for j1, j2, j3 in itertools.product(*cand):
            B = b[[i0, j1, j2, j3]]
            if np.abs(B @ B.T - gram).max() > 1e-6:
                continue
            R = np.linalg.solve(A, B).T  # a @ R.T = b on the frame
            dist, _ = tree.query(a @ R.T)
            if dist.max() < 1e-6 and np.allclose(R @ R.T, np.eye(4), atol=1e-9):
                return R
        return None  # b is vertex-transitive: one starting vertex suffices
    return None


@pytest.mark.parametrize("name", ["5-cell", "8-cell", "16-cell", "24-cell", "600-cell", "120-cell"])
def test_regular_six_wythoff_equals_core_up_to_rotation(name):
    core = polytope(name)
    w = uniform.combinatorics(name)
    assert w.counts == core.counts
    R = _same_up_to_rotation(w.vertices, core.vertices)
    assert R is not None
    # the rotation carries the Wythoff faces onto the core's faces
    _, match = cKDTree(core.vertices).query(w.vertices @ R.T)
    assert {frozenset(match[f].tolist()) for f in w.faces} == {frozenset(f.tolist()) for f in core.faces}


def test_rotation_finder_can_fail():
    """The comparison above is not vacuous: a rectified 5-cell is not a 5-cell scaled, and a
    16-cell with one vertex moved is not the 16-cell."""
    a = polytope("16-cell").vertices.copy()
    b = a.copy()
    b[3] *= 1.01
    assert _same_up_to_rotation(a, b) is None
    assert _same_up_to_rotation(uniform.combinatorics("x3x3o3o").vertices,
                                uniform.combinatorics("o3x3x3o").vertices) is None


@pytest.mark.parametrize("name", ["x3o3o3o", "o3o3o3x", "x4o3o3o", "tesseract", "o4o3o3x", "x3o4o3o",
                                  "o4o3x3o", "x5o3o3o", "o5o3o3x", "4-4 duoprism", "cubic prism"])
def test_regular_names_give_the_core_objects(name):
    canon = uniform.canonical_name(name)
    assert uniform.build(name) is polytope(canon)


def test_sixty_ring_patterns_name_forty_five_polytopes():
    canon = set()
    for labels in ("333", "433", "343", "533"):
        for rings in itertools.product("xo", repeat=4):
            if "x" not in rings:
                continue
            sym = "".join(r + m for r, m in zip(rings, (*labels, "")))
            canon.add(uniform.canonical_name(sym))
    assert len(canon) == 45 and None not in canon


@pytest.mark.parametrize("b4, f4", [("o4o3x3o", "24-cell"), ("o4x3o3x", "rectified 24-cell"),
                                    ("o4x3x3x", "truncated 24-cell")])
def test_three_b4_patterns_are_f4_polytopes(b4, f4):
    """The B4 construction of these three gives the F4 one up to rotation."""
    assert uniform.canonical_name(b4) == f4
    sym = b4
    b = uniform.wythoff((4, 3, 3), tuple(c == "x" for c in sym[0::2]))
    f = uniform.combinatorics(f4)
    assert b.counts == f.counts
    assert _same_up_to_rotation(b.vertices, f.vertices) is not None


@pytest.mark.parametrize("name, canon", [
    ("o3x3o3o", "rectified 5-cell"), ("o3o3x3o", "rectified 5-cell"), ("x4x3o3o", "truncated tesseract"),
    ("x5x3x3x", "omnitruncated 120-cell"), ("X5X3X3X", "omnitruncated 120-cell"),
    ("Truncated Tesseract", "truncated tesseract"), ("cantellated_24-cell", "cantellated 24-cell"),
    ("runcinated 600-cell", "runcinated 120-cell"), ("omnitruncated 600-cell", "omnitruncated 120-cell"),
    ("s3s4o3o", "snub 24-cell"), ("grand antiprism", "grand antiprism"), ("7-5 duoprism", "5-7 duoprism"),
    ("x5o x7o", "5-7 duoprism"), ("pentagonal prism prism", "4-5 duoprism"), ("3-antiprismatic prism",
    "octahedral prism"), ("pentagonal antiprismatic prism", "5-antiprismatic prism"),
    ("truncated cube prism", "truncated cubic prism"), ("x4x3o x", "truncated cubic prism"),
    ("hypercube", "8-cell"), ("{3,3,5}", "600-cell"),
])
def test_canonical_names(name, canon):
    assert uniform.canonical_name(name) == canon


@pytest.mark.parametrize("name", ["x3o3o", "s3s3s3s", "2-5 duoprism", "3-33 duoprism", "33-antiprismatic prism",
                                  "truncated teseract", "", "x6o3o3o"])
def test_unknown_names(name):
    assert uniform.canonical_name(name) is None
    with pytest.raises(ValueError, match=r"polytope_names\(\)"):
        uniform.build(name)
    with pytest.raises(ValueError, match="Unknown polychoron"):
        uniform.dynkin_symbol(name)


@pytest.mark.parametrize("bad", [None, 5, 5.0, b"x3o3o3o", ["5-cell"]])
def test_non_str_names(bad):
    with pytest.raises(TypeError, match="Expected a polychoron name"):
        uniform.build(bad)
    with pytest.raises(TypeError, match="Expected a polychoron name"):
        uniform.canonical_name(bad)


def test_dynkin_symbols():
    assert uniform.dynkin_symbol("rectified 5-cell") == "o3x3o3o"
    assert uniform.dynkin_symbol("omnitruncated 120-cell") == "x5x3x3x"
    assert uniform.dynkin_symbol("5-cell") == "x3o3o3o"
    assert uniform.dynkin_symbol("600-cell") == "o5o3o3x"
    assert uniform.dynkin_symbol("snub 24-cell") == "s3s4o3o"
    assert uniform.dynkin_symbol("grand antiprism") is None
    assert uniform.dynkin_symbol("7-5 duoprism") == "x5o x7o"
    # every symbol names its polytope back
    for fam, names in uniform.polytope_names().items():
        for n in names[:40]:
            sym = uniform.dynkin_symbol(n)
            if sym is not None:
                assert uniform.canonical_name(sym) == n


def test_prismatic_counts():
    for p in (3, 5, 32):
        for q in (3, 8, 32):
            if p <= q:
                assert uniform.combinatorics(f"{p}-{q} duoprism").counts == (p * q, 2 * p * q, p * q + p + q, p + q)
    for p in (4, 9, 32):  # p-antiprismatic prism: 2 antiprisms, 2 p-gonal prisms, 2p triangular prisms
        c = uniform.combinatorics(f"{p}-antiprismatic prism")
        assert c.counts == (4 * p, 10 * p, 2 * (2 * p + 2) + 4 * p, 2 + 2 + 2 * p)
    # prism over a polyhedron (V, E, F): (2V, 2E + V, 2F + E, 2 + F)
    for base, (V, E, F) in {"snub dodecahedron": (60, 150, 92), "truncated icosidodecahedron": (120, 180, 62),
                            "snub cube": (24, 60, 38), "tetrahedron": (4, 6, 4)}.items():
        c = uniform.combinatorics(f"{base} prism")
        assert c.counts == (2 * V, 2 * E + V, 2 * F + E, 2 + F)
    assert sum(len(v) for k, v in uniform.polytope_names().items() if k.startswith("duoprisms")) == 30 * 31 // 2 - 1


def test_build_is_cached():
    c = uniform.combinatorics("x5x3x3x")  # its build time: benchmarks/uniform_build.py
    assert c.counts == (14400, 28800, 17040, 2640)
    assert uniform.combinatorics("omnitruncated 120-cell") is c


@pytest.mark.parametrize("name", ["rectified 5-cell", "truncated tesseract", "snub 24-cell", "grand antiprism",
                                  "5-7 duoprism", "truncated cubic prism", "7-antiprismatic prism",
                                  "runcinated 24-cell"])
def test_build_gives_a_polytope(name):
    p = uniform.build(name)
    assert isinstance(p, Polytope)
    assert p.counts == uniform.combinatorics(name).counts
    assert uniform.build(name) is p


# -- as core Polytopes: slices -------------------------------------------------------------------

from reference_geometry import merged_hull_faces, random_rotation, slice_volume_by_halfspaces  # noqa: E402

from rot4d_widget.geometry.slicing.polytope_slice import slice_polytope  # noqa: E402

SLICE_SAMPLE = ["rectified 5-cell", "runcinated 5-cell", "truncated tesseract", "truncated 16-cell",
                "cantellated 24-cell", "snub 24-cell", "grand antiprism", "5-7 duoprism", "3-32 duoprism",
                "truncated cubic prism", "snub cubic prism", "7-antiprismatic prism", "rectified 600-cell",
                "bitruncated 24-cell"]


def _check_slice(p, m, c0):
    s = slice_polytope(p, m, c0)
    r = p.circumradius
    ref_volume, _ = slice_volume_by_halfspaces(p.vertices @ m.T, c0)
    assert s.dim == 3
    assert abs(s.volume - ref_volume) / r**3 <= max(1e-9 * ref_volume / r**3, 1e-12)
    faces, edges, hull_vertices = merged_hull_faces(s.vertices)
    assert hull_vertices == set(range(len(s.vertices)))
    assert faces == {frozenset(poly.tolist()) for poly in s.polygons}
    assert edges == {frozenset(e) for e in s.edges.tolist()}
    assert len(s.vertices) - len(s.edges) + len(s.cell_ids) == 2
    return s


@pytest.mark.parametrize("name", SLICE_SAMPLE)
@pytest.mark.parametrize("seed", range(3))
def test_slices_against_halfspaces_and_hull(name, seed):
    p = uniform.build(name)
    m = random_rotation(100 + seed)
    h = p.vertices @ m[3]
    c0 = (0.0, 0.37, -0.81)[seed] * h.max()
    _check_slice(p, m, c0)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["omnitruncated 120-cell", "runcitruncated 600-cell", "cantellated 120-cell"])
def test_big_slices_against_halfspaces_and_hull(name):
    p = uniform.build(name)
    _check_slice(p, random_rotation(5), 0.0)


@pytest.mark.parametrize("name", ["rectified 5-cell", "truncated tesseract", "snub 24-cell", "grand antiprism",
                                  "5-7 duoprism", "truncated cubic prism", "7-antiprismatic prism"])
def test_cavalieri_integral_of_slice_volumes_is_the_4_volume(name):
    """Between two consecutive vertex heights the slice volume is a cubic in c0: two Gauss points
    per interval integrate it exactly, and the sum is the 4-volume of scipy's hull."""
    p = uniform.build(name)
    m = random_rotation(7)
    h = np.unique(np.round(p.vertices @ m[3], 12))
    nodes = np.array([-1.0, 1.0]) / np.sqrt(3.0)
    lo, hi = h[:-1], h[1:]
    mid, half = (lo + hi) / 2, (hi - lo) / 2
    levels = (mid[:, None] + half[:, None] * nodes[None, :]).ravel()
    vols = np.array([s.volume for s in slice_polytope(p, m, levels)]).reshape(-1, 2)
    total = float((half * vols.sum(axis=1)).sum())
    assert total == pytest.approx(ConvexHull(p.vertices).volume, rel=1e-9)


def test_widest_slice_census_of_the_omnitruncated_120_cell():
    """Cut through the centre at a random orientation: every polygon is a
    slice of a cell, their number is the number of cells crossed."""
    p = uniform.build("x5x3x3x")
    s = slice_polytope(p, random_rotation(3), 0.0)
    assert s.dim == 3 and s.volume > 0
    w = p.vertices @ random_rotation(3)[3]
    crossed = sum(1 for c in range(len(p.cells)) if w[p.cell_vertices(c)].min() < 0 < w[p.cell_vertices(c)].max())
    assert len(s.cell_ids) == crossed


def test_cached_combinatorics_are_read_only():
    c = uniform.combinatorics("rectified 5-cell")
    for a in (c.vertices, c.edges, c.faces[0], c.cells[0], c.cell_types):
        with pytest.raises(ValueError, match="read-only"):
            a[0] = a[0]


@pytest.mark.parametrize("name", ["truncated tesseract", "runcinated 24-cell", "grand antiprism", "5-7 duoprism",
                                  "snub cubic prism"])
def test_hyperplane_through_a_cell_gives_that_cell(name):
    """H turned onto a cell's hyperplane (an on-H case): the slice is that cell, its volume the
    cell's own (scipy hull in the cell's 3-space), one polygon per face of the cell."""
    from reference_geometry import rotation_with_w_row

    p = uniform.build(name)
    c = uniform.combinatorics(name)
    for k in np.unique(c.cell_types, return_index=True)[1]:
        m = rotation_with_w_row(p.cell_normals[k])
        s = slice_polytope(p, m, float(p.cell_offsets[k]))
        pts = p.vertices[p.cell_vertices(k)] @ m.T
        assert s.dim == 3
        assert s.volume == pytest.approx(ConvexHull(pts[:, :3]).volume, rel=1e-9)
        assert len(s.cell_ids) == len(p.cells[k])


def test_every_listed_name_is_canonical_and_listed_once():
    names = uniform.polytope_names()
    flat = [n for ns in names.values() for n in ns]
    assert len(flat) == len(set(flat)) == 47 + 17 + 464 + 29
    assert all(uniform.canonical_name(n) == n for n in flat)
    assert all(uniform.family(n) == fam for fam, ns in names.items() for n in ns)
    names["A4: 5-cell family [3,3,3]"].clear()  # a copy: the table is not changed
    assert len(uniform.polytope_names()["A4: 5-cell family [3,3,3]"]) == 9
