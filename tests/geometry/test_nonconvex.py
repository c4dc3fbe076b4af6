"""Slices of non-convex polytopes: unions of unit tesseracts glued face to face.

The independent check: a union of convex pieces that share whole cells has, at every
orientation and level, a slice volume equal to the sum of its pieces' slice volumes
(each piece a tesseract, sliced through the convex-hull path), and a slice whose Euler
characteristic follows from the pieces by inclusion-exclusion (every intersection of
convex slices is convex: Euler characteristic 1).  The meshes keep coplanar neighbouring
cubes as separate cells (flat ridges, which `Polytope` allows).
"""

import functools
import itertools
from collections import Counter

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings, strategies as st
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from mesh_shapes import SHAPES, stellated_tesseract_mesh, tesseract_union, tesseract_union_mesh
from reference_geometry import random_rotation, rotation_with_w_row
from rot4d_widget import Polytope, slice_polytope
from rot4d_widget.geometry.meshcheck import MeshError

PROPS = settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
seeds = st.integers(0, 2**32 - 1)


#: a non-grid one: a tesseract with a tall pyramid on each cube (reflex ridges at its squares)
STELLA = "stellated tesseract"
ALL_SHAPES = sorted(SHAPES) + [STELLA]
shapes = st.sampled_from(ALL_SHAPES)


@functools.lru_cache(maxsize=None)
def union(shape):
    """(the union as a Polytope, its pieces as convex Polytopes, each piece's corners as a set of
    coordinate tuples).  Pieces meet in common faces: the intersection of any of them is the
    convex hull of their common corners."""
    if shape == STELLA:
        v, f, c, pieces = stellated_tesseract_mesh(2.0)
        p = Polytope(v, f, c, name=shape)
    elif isinstance(shape, tuple):  # integer positions of unit tesseracts
        v, f, c, pieces = tesseract_union_mesh(shape)
        p = Polytope(v, f, c, name=str(shape))
    else:
        p, pieces = tesseract_union(shape)
    corners = [frozenset(map(tuple, np.round(pc, 9).tolist())) for pc in pieces]
    return p, [Polytope(pc) for pc in pieces], corners


def boxes(shape):
    """The pieces of a union of tesseracts as (low, high) corners."""
    return [(q.vertices.min(axis=0), q.vertices.max(axis=0)) for q in union(shape)[1]]


def pieces_volume(shape, m, c0):
    return sum(slice_polytope(q, m, c0).volume for q in union(shape)[1])


def _meets(common, m, c0):
    """The convex hull of the corners ``common`` meets H strictly inside (general position)."""
    if not common:
        return False
    h = (np.array(sorted(common)) @ m.T)[:, 3]
    return h.min() < c0 < h.max()


def euler_by_inclusion_exclusion(shape, m, c0):
    """chi(S) of S = union of the pieces' slices: sum over sets of pieces whose common face
    meets H, with sign (-1)^(k+1) (each such intersection is convex: chi 1).  Levels must be
    away from vertex heights."""
    corners = union(shape)[2]
    chi = 0
    for k in range(1, len(corners) + 1):
        for group in itertools.combinations(corners, k):
            if _meets(frozenset.intersection(*group), m, c0):
                chi += (-1) ** (k + 1)
    return chi


def pieces_components(shape, m, c0):
    """Connected components of the union of the pieces' slices (pieces whose slices meet)."""
    corners = union(shape)[2]
    cut = [i for i, q in enumerate(union(shape)[1]) if slice_polytope(q, m, c0).dim == 3]
    if not cut:
        return 0
    pairs = [(a, b) for a, b in itertools.combinations(range(len(cut)), 2)
             if _meets(corners[cut[a]] & corners[cut[b]], m, c0)]
    a, b = zip(*pairs) if pairs else ((), ())
    return connected_components(coo_matrix((np.ones(len(a)), (a, b)), shape=(len(cut), len(cut))), directed=False)[0]


def check_closed(s, manifold=True, lying_in_h=None):
    """Every directed triangle edge once and its reverse once; every edge in exactly two polygons.

    ``manifold=False`` (two solids touching along an edge in H): every directed edge as often
    as its reverse, every edge in an even number of polygons (a closed surface, pinched).

    The slice's vertices are the polygons' corners and its edges their sides, but for the parts of
    P lying in H that bound no polygon (where P touches H away from the solid, issue 33):
    ``lying_in_h`` (k, 3), P's vertices on H (None: there are none), then also holds every vertex
    no polygon uses, and the ends of every edge that is no polygon's side."""
    directed = Counter()
    for a, b, c in s.triangles.tolist():
        for e in ((a, b), (b, c), (c, a)):
            directed[e] += 1
    assert all(directed[(b, a)] == n for (a, b), n in directed.items())
    sides = Counter()
    for poly in s.polygons:
        cyc = poly.tolist()
        for a, b in zip(cyc, cyc[1:] + cyc[:1]):
            sides[frozenset((a, b))] += 1
    if manifold:
        assert set(directed.values()) == {1} and set(sides.values()) == {2}
    else:
        assert all(n % 2 == 0 for n in sides.values())
    edges = {frozenset(e) for e in s.edges.tolist()}
    used = set(np.unique(s.polygon_indices).tolist())
    assert set(sides) <= edges and len(s.edges) == len(edges) and used <= set(range(len(s.vertices)))
    alone = {k for e in edges - set(sides) for k in e} | (set(range(len(s.vertices))) - used)
    if lying_in_h is None:
        assert not alone
    elif alone:
        k = sorted(alone)
        assert np.abs(s.vertices[k][:, None, :] - lying_in_h[None, :, :]).max(axis=2).min(axis=1).max() < 1e-9


def signed_volume(s):
    tri = s.vertices[s.triangles]
    return float(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum()) / 6.0


def check_outward(shape, m, c0, s, eps=1e-7):
    """Just outside each polygon (along its normal from the winding) is outside every piece,
    just inside is inside one (a closed box: S may lie in the boundary when cells lie in H):
    outward winding, checked locally, polygon by polygon."""
    pieces = union(shape)[1]

    def inside(q3):
        x = m.T @ np.append(q3, c0)  # back to the polytope's own frame
        return any(np.all(q.cell_normals @ x <= q.cell_offsets + 1e-12) for q in pieces)

    for poly in s.polygons:
        pts = s.vertices[poly]
        n = np.cross(pts - pts.mean(axis=0), np.roll(pts, -1, axis=0) - pts.mean(axis=0)).sum(axis=0)
        n /= np.linalg.norm(n)
        g = pts.mean(axis=0)
        assert not inside(g + eps * n) and inside(g - eps * n)


def components(s):
    """(V, E, F) of each connected piece of the slice's surface."""
    n = len(s.vertices)
    a, b = s.edges[:, 0], s.edges[:, 1]
    k, label = connected_components(coo_matrix((np.ones(len(a)), (a, b)), shape=(n, n)), directed=False)
    first = s.polygon_indices[s.polygon_offsets[:-1]]
    return [(int((label == i).sum()), int((label[a] == i).sum()), int((label[first] == i).sum())) for i in range(k)]


def level(shape, m, frac):
    h = (union(shape)[0].vertices @ m.T)[:, 3]
    return float(h.min() + frac * (h.max() - h.min())), h


# -- at random orientations and levels ---------------------------------------------------


@PROPS
@given(shape=shapes, seed=seeds, frac=st.floats(0.01, 0.99))
def test_random_slices_volume_closed_outward_and_euler(shape, seed, frac):
    check_slice_in_general_position(shape, random_rotation(seed), frac)


@PROPS
@given(cells=st.sets(st.tuples(st.integers(0, 3), st.integers(0, 2)), min_size=2, max_size=10), seed=seeds,
       frac=st.floats(0.01, 0.99))
def test_random_polyominoes_of_tesseracts(cells, seed, frac):
    """Any set of unit tesseracts on a 4x3 grid in the xy-plane (holes, several pieces, ...);
    sets with a diagonal-only contact make a face of four cells and are refused by `Polytope`."""
    shape = tuple(sorted((x, y, 0, 0) for x, y in cells))
    try:
        union(shape)
    except MeshError as exc:
        assert "is in 4 cell(s)" in str(exc)
        assume(False)
    check_slice_in_general_position(shape, random_rotation(seed), frac)


def check_slice_in_general_position(shape, m, frac):
    c0, h = level(shape, m, frac)
    p = union(shape)[0]
    assume(np.abs(h - c0).min() > 1e-3 * p.circumradius)  # general position
    s = slice_polytope(p, m, c0)
    ref = pieces_volume(shape, m, c0)
    assert s.volume == pytest.approx(ref, rel=1e-9, abs=1e-12)
    if ref == 0:
        assert s.dim == -1 and len(s.cell_ids) == 0
        return
    assert s.dim == 3
    check_closed(s)
    assert signed_volume(s) == pytest.approx(s.volume, rel=1e-9) and s.volume > 0  # wound outward
    check_outward(shape, m, c0, s)
    pieces = components(s)
    for v, e, f in pieces:  # each piece a closed orientable surface: 2 - 2g
        chi = v - e + f
        assert chi <= 2 and chi % 2 == 0
    assert sum(v - e + f for v, e, f in pieces) == 2 * euler_by_inclusion_exclusion(shape, m, c0)
    assert len(pieces) == pieces_components(shape, m, c0)  # no polygon joins two pieces


@PROPS
@given(shape=shapes, seed=seeds, which=st.integers(0, 10**6))
def test_slices_exactly_at_vertex_heights(shape, seed, which):
    """On-H cases: volume and closedness hold (the vertex on H may be a pinch point of S)."""
    m = random_rotation(seed)
    p = union(shape)[0]
    h = (p.vertices @ m.T)[:, 3]
    c0 = float(h[which % len(h)])
    s = slice_polytope(p, m, c0)
    assert s.volume == pytest.approx(pieces_volume(shape, m, c0), rel=1e-9, abs=1e-12)
    if s.dim == 3:
        check_closed(s, lying_in_h=(p.vertices @ m.T)[np.abs(h - c0) <= 1e-9 * p.circumradius, :3])
        assert signed_volume(s) == pytest.approx(s.volume, rel=1e-9)


@PROPS
@given(shape=shapes, seed=seeds, fracs=st.lists(st.floats(-0.1, 1.1), min_size=1, max_size=12))
def test_batched_levels_equal_single_slices(shape, seed, fracs):
    m = random_rotation(seed)
    p = union(shape)[0]
    levels = [level(shape, m, f)[0] for f in fracs]
    for c0, b in zip(levels, slice_polytope(p, m, np.array(levels))):
        a = slice_polytope(p, m, c0)
        assert a.dim == b.dim and abs(a.volume - b.volume) <= 1e-12 * max(1.0, abs(a.volume))
        np.testing.assert_array_equal(a.vertices, b.vertices)
        np.testing.assert_array_equal(a.polygon_indices, b.polygon_indices)
        np.testing.assert_array_equal(a.triangles, b.triangles)


def test_a_ring_slices_into_a_solid_torus():
    """3x3 tesseracts minus the centre, cut nearly along its zw-plane: genus 1 (V - E + F = 0)."""
    m = rotation_with_w_row((0.01, -0.02, 0.03, 1.0))
    s = slice_polytope(union("ring")[0], m, 0.0)
    assert s.volume == pytest.approx(pieces_volume("ring", m, 0.0), rel=1e-12)
    check_closed(s)
    assert components(s) and [v - e + f for v, e, f in components(s)] == [0]


def test_a_u_slices_into_two_pieces():
    """The U cut across its two prongs: two pieces, no polygon spans both."""
    p, _, _ = union("U")
    m = rotation_with_w_row((0.01, 1.0, 0.02, -0.03))
    c0 = float(np.median((p.vertices @ m.T)[:, 3])) + 0.31  # in the prongs (y in 1..2 before centring)
    s = slice_polytope(p, m, c0)
    assert len(components(s)) == 2 == pieces_components("U", m, c0)
    assert s.volume == pytest.approx(pieces_volume("U", m, c0), rel=1e-12)
    check_closed(s)
    check_outward("U", m, c0, s)


# -- on-H cases that only a non-convex polytope has ---------------------------------------


@pytest.mark.parametrize("shape", sorted(SHAPES))  # the grid ones
@pytest.mark.parametrize("c0", [-0.5, -0.25, 0.0, 0.5])
def test_cells_lying_in_h_side_by_side(shape, c0):
    """Identity orientation: at w = +-0.5 every piece has a cube in H, neighbours coplanar (flat
    ridges); the faces between them are inside S and give no polygon."""
    p = union(shape)[0]
    w = p.vertices[:, 3]
    c0 = c0 if shape not in ("tripod", "staircase") else c0 + (w.min() + 0.5)  # those span two w-units
    s = slice_polytope(p, np.eye(4), c0)
    assert s.volume == pytest.approx(pieces_volume_union_in_h(shape, c0))
    check_closed(s)
    assert signed_volume(s) == pytest.approx(s.volume)
    (v, e, f), = components(s)
    assert v - e + f == (0 if shape == "ring" else 2)  # the ring's cubes make a solid torus


def pieces_volume_union_in_h(shape, c0):
    """Volume of the union's slice at w = c0, identity orientation: the unit cubes of the pieces
    whose w-range holds c0 (a cube counted once where two pieces meet in H)."""
    cubes = {tuple(np.round(lo[:3], 9)) for lo, hi in boxes(shape) if lo[3] - 1e-12 <= c0 <= hi[3] + 1e-12}
    return float(len(cubes))


def test_a_face_inside_the_slice_at_a_reflex_ridge_gives_no_polygon():
    """2x2 minus one, cut by x + y = 2 through its reflex 2-face R (both cells of R rise above
    H, the polytope fills both sides of R in H): R is inside S, which is one box of volume 2√2."""
    p = union("2x2 minus one")[0]
    m = rotation_with_w_row((1.0, 1.0, 0.0, 0.0))
    shift = -boxes("2x2 minus one")[0][0]  # the mesh is centred; the first piece's low corner was 0
    c0 = float((np.array([1.0, 1.0, 0.0, 0.0]) - shift) @ m[3])
    s = slice_polytope(p, m, c0)
    assert s.volume == pytest.approx(2 * np.sqrt(2))
    check_closed(s)
    assert (len(s.vertices), len(s.edges), len(s.cell_ids)) == (12, 20, 10)  # the box, its long faces halved


def test_a_pinch_point_where_the_level_passes_through_a_reflex_vertex():
    """2x2 minus one (pieces A, B, C around the missing D), cut through the reflex vertex v at
    (1, 1, 0, 0) by a hyperplane that leaves A below except at v: S is B's and C's slices, two
    solids touching only at v.  The slicer keeps v as ONE vertex of the slice, shared by both:
    the surface is closed and wound outward and the volume is exact, but at v two fans of
    polygons meet (the link of v has two cycles) and V - E + F = 3 = 2 + 2 - 1."""
    p = union("2x2 minus one")[0]
    shift = -boxes("2x2 minus one")[0][0]
    iv = int(np.argmin(np.linalg.norm(p.vertices - (np.array([1.0, 1, 0, 0]) - shift), axis=1)))
    m = rotation_with_w_row((-1.0, -1.1, 1.2, 1.3))
    x = p.vertices @ m.T
    c0 = float(x[iv, 3])
    assert np.sort(np.abs(x[:, 3] - c0))[1] > 0.04  # no other vertex near H
    s = slice_polytope(p, m, c0)
    piece_volumes = [slice_polytope(q, m, c0).volume for q in union("2x2 minus one")[1]]
    assert piece_volumes[0] == 0 and min(piece_volumes[1:]) > 0.2
    assert s.volume == pytest.approx(sum(piece_volumes), rel=1e-12)
    check_closed(s)
    assert signed_volume(s) == pytest.approx(s.volume)
    k = np.flatnonzero(np.linalg.norm(s.vertices - x[iv, :3], axis=1) < 1e-12)
    assert len(k) == 1
    link = []  # the link of v: for each polygon at v, its two neighbours of v
    for poly in s.polygons:
        cyc = poly.tolist()
        if k[0] in cyc:
            i = cyc.index(k[0])
            link.append((cyc[i - 1], cyc[(i + 1) % len(cyc)]))
    nodes = sorted({a for e in link for a in e})
    ix = {a: i for i, a in enumerate(nodes)}
    a, b = zip(*[(ix[u], ix[w]) for u, w in link])
    n_fans = connected_components(coo_matrix((np.ones(len(a)), (a, b)), shape=(len(nodes),) * 2), directed=False)[0]
    assert n_fans == 2
    assert len(s.vertices) - len(s.edges) + len(s.cell_ids) == 3


def test_two_solids_touching_along_a_reflex_edge_in_h():
    """2x2 minus one cut by x + y + z = 3, which holds its reflex edge (1, 1, 1, 0)-(1, 1, 1, 1):
    S is two triangular prisms (in B and in C) touching along that edge.  The slicer keeps the
    edge once, in four polygons (two of each prism, each pair wound against the other), and its
    two ends once: closed and outward, exact volume, V - E + F = 3 = 2 + 2 - 1."""
    p = union("2x2 minus one")[0]
    shift = -boxes("2x2 minus one")[0][0]
    m = rotation_with_w_row((1.0, 1.0, 1.0, 0.0))
    c0 = float((np.array([1.0, 1, 1, 0]) - shift) @ m[3])
    s = slice_polytope(p, m, c0)
    assert s.volume == pytest.approx(2 * np.sqrt(3) / 2) == pytest.approx(pieces_volume("2x2 minus one", m, c0))
    check_closed(s, manifold=False)
    ends = [int(np.argmin(np.linalg.norm(s.vertices - (m @ (np.array([1.0, 1, 1, w]) - shift))[:3], axis=1)))
            for w in (0.0, 1.0)]
    on_edge = [k for k, poly in enumerate(s.polygons) if set(ends) <= set(poly.tolist())]
    assert len(on_edge) == 4
    assert signed_volume(s) == pytest.approx(s.volume)
    check_outward("2x2 minus one", m, c0, s)
    assert (len(s.vertices), len(s.edges), len(s.cell_ids)) == (10, 17, 10)


def test_pieces_apart_on_both_sides_of_h_give_an_empty_slice():
    """Two tesseracts, one above and one below H: vertices on both sides, no cell crosses."""
    v, f, c, _ = tesseract_union_mesh([(0, 0, 0, 0), (0, 0, 0, 3)], centre=False)  # w in 0..1 and 3..4
    p = Polytope(v, f, c)
    for s in (slice_polytope(p, np.eye(4), 2.0), *slice_polytope(p, np.eye(4), [1.5, 2.0, 2.7])):
        assert s.dim == -1 and s.volume == 0 and len(s.cell_ids) == 0
    s0, s1 = slice_polytope(p, np.eye(4), [0.2, 3.7])
    assert s0.volume == pytest.approx(1.0) and s1.volume == pytest.approx(1.0)


SPECIAL = [(1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (0, 0, 0, 1), (1, 1, 0, 0), (1, -1, 0, 0), (1, 0, 1, 0),
           (0, 1, 0, 1), (1, 1, 1, 0), (1, 1, 1, 1), (1, -1, 1, -1), (1, 2, 0, 0), (2, 1, 1, 0)]


@PROPS
@given(shape=st.sampled_from(sorted(SHAPES)), direction=st.sampled_from(SPECIAL), which=st.integers(0, 10**6),
       spin=seeds)
def test_levels_through_whole_faces_and_cells(shape, direction, which, spin):
    """Hyperplanes along the grid (axes, diagonals) at vertex heights: faces, cells and flat
    ridges lie in H.  S is the union of the pieces' slices: their sum, or along an axis the
    distinct unit cubes lying in H."""
    p = union(shape)[0]
    m = rotation_with_w_row(direction)
    q, r = np.linalg.qr(np.random.default_rng(spin).normal(size=(3, 3)))
    q = q * np.sign(np.diag(r)) * (1 if np.linalg.det(q * np.sign(np.diag(r))) > 0 else -1)
    m[:3] = q @ m[:3]  # any turn of H in itself
    h = (p.vertices @ m.T)[:, 3]
    c0 = float(h[which % len(h)])
    s = slice_polytope(p, m, c0)
    axis = [k for k in range(4) if direction[k]]
    if len(axis) == 1:
        k = axis[0]
        cubes = {tuple(np.round(np.delete(lo, k), 9)) for lo, hi in boxes(shape)
                 if lo[k] - 1e-9 <= c0 <= hi[k] + 1e-9}
        expected = float(len(cubes))
    else:
        expected = pieces_volume(shape, m, c0)
    assert s.volume == pytest.approx(expected, rel=1e-9, abs=1e-12)
    if expected > 0:
        assert s.dim == 3
        check_closed(s, manifold=False,  # H may hold a reflex edge: two solids touching along it
                     lying_in_h=(p.vertices @ m.T)[np.abs(h - c0) <= 1e-9 * p.circumradius, :3])
        assert signed_volume(s) == pytest.approx(s.volume, rel=1e-9)
        check_outward(shape, m, c0, s)
    else:
        assert s.dim < 3 and len(s.cell_ids) == 0


def test_the_24_cell_as_a_stellated_tesseract_with_flat_ridges():
    """Pyramids of height 1 on the tesseract's cubes make the 24-cell, each octahedron split in
    two square pyramids (flat ridges in every orientation): convex, and sliced as its hull."""
    v, f, c, pieces = stellated_tesseract_mesh(1.0)
    p, hull = Polytope(v, f, c), Polytope(v)
    assert p.convex and p.counts == (24, 96, 120, 48) and hull.counts == (24, 96, 96, 24)
    for seed in range(6):
        m = random_rotation(seed)
        for c0 in (0.0, 0.7, -1.3, float((v @ m.T)[seed, 3])):
            a, b = slice_polytope(p, m, c0), slice_polytope(hull, m, c0)
            assert a.volume == pytest.approx(b.volume, rel=1e-12, abs=1e-12)
            if a.dim == 3:
                check_closed(a)
                assert len(a.vertices) == len(b.vertices)
    tall = union(STELLA)[0]
    assert not tall.convex
