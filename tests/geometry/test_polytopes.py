"""The six regular polychora: counts, metric facts, and combinatorial closure."""

import itertools
import math
from collections import Counter

import numpy as np
import pytest

from rot4d_widget import Polytope, pentachoron, polytope, slice_polytope

COUNTS = {
    "5-cell": (5, 10, 10, 5),
    "8-cell": (16, 32, 24, 8),
    "16-cell": (8, 24, 32, 16),
    "24-cell": (24, 96, 96, 24),
    "120-cell": (600, 1200, 720, 120),
    "600-cell": (120, 720, 1200, 600),
}
DEGREE = {"5-cell": 4, "8-cell": 4, "16-cell": 6, "24-cell": 8, "120-cell": 4, "600-cell": 12}
FACE_SIDES = {"5-cell": 3, "8-cell": 4, "16-cell": 3, "24-cell": 3, "120-cell": 5, "600-cell": 3}
NAMES = list(COUNTS)


@pytest.mark.parametrize("name", NAMES)
def test_counts_and_euler(name):
    p = polytope(name)
    v, e, f, c = COUNTS[name]
    assert (len(p.vertices), len(p.edges), len(p.faces), len(p.cells)) == (v, e, f, c)
    assert v - e + f - c == 0


@pytest.mark.parametrize("name", NAMES)
def test_edges_have_length_2_and_vertices_regular_degree(name):
    p = polytope(name)
    d = np.linalg.norm(p.vertices[p.edges[:, 0]] - p.vertices[p.edges[:, 1]], axis=1)
    np.testing.assert_allclose(d, 2.0, rtol=1e-12)
    degree = np.bincount(p.edges.ravel(), minlength=len(p.vertices))
    assert np.all(degree == DEGREE[name])
    # no pair of vertices closer than an edge: the edges are all the shortest pairs
    all_d = np.linalg.norm(p.vertices[:, None] - p.vertices[None], axis=-1)
    assert np.sum(np.isclose(all_d, 2.0)) == 2 * len(p.edges)
    assert all_d[~np.eye(len(all_d), dtype=bool)].min() == pytest.approx(2.0)


@pytest.mark.parametrize("name", NAMES)
def test_vertices_on_one_3_sphere_centred_at_origin(name):
    p = polytope(name)
    r = np.linalg.norm(p.vertices, axis=1)
    np.testing.assert_allclose(r, p.circumradius, rtol=1e-12)
    np.testing.assert_allclose(p.vertices.mean(axis=0), 0.0, atol=1e-12)


@pytest.mark.parametrize("name", NAMES)
def test_faces_are_regular_polygons_in_two_cells(name):
    p = polytope(name)
    k = FACE_SIDES[name]
    vsets = [frozenset(p.cell_vertices(c).tolist()) for c in range(len(p.cells))]
    for f, cyc in enumerate(p.faces):
        assert len(cyc) == k
        # consecutive corners are joined by edges of length 2: a real cycle
        pts = p.vertices[cyc]
        np.testing.assert_allclose(np.linalg.norm(pts - np.roll(pts, -1, axis=0), axis=1), 2.0, rtol=1e-12)
        # planar: rank 2 after centring
        assert np.linalg.matrix_rank(pts - pts.mean(axis=0), tol=1e-9) == 2
        # in exactly two cells, counted by vertex containment (not by construction)
        assert sum(frozenset(cyc.tolist()) <= s for s in vsets) == 2


@pytest.mark.parametrize("name", NAMES)
def test_cells_are_closed_polyhedra(name):
    p = polytope(name)
    for c, faces in enumerate(p.cells):
        edge_use = Counter()
        for f in faces:
            cyc = p.faces[f].tolist()
            for a, b in zip(cyc, cyc[1:] + cyc[:1]):
                edge_use[frozenset((a, b))] += 1
        assert set(edge_use.values()) == {2}  # every edge of the cell shared by two of its faces
        nv = len({v for f in faces for v in p.faces[f].tolist()})
        assert nv - len(edge_use) + len(faces) == 2  # Euler for a polyhedron
        # the cell is flat (a 3-D facet) and its normal points outward
        pts = p.vertices[p.cell_vertices(c)]
        np.testing.assert_allclose(pts @ p.cell_normals[c], p.cell_offsets[c], atol=1e-9)
        assert np.all(p.vertices @ p.cell_normals[c] <= p.cell_offsets[c] + 1e-9)


def test_pentachoron_is_eqs_8_to_12():
    a = 2.0
    expected = np.array(
        [
            [-a / 2, -a / (2 * math.sqrt(3)), -a / (2 * math.sqrt(6)), -a / (2 * math.sqrt(10))],
            [a / 2, -a / (2 * math.sqrt(3)), -a / (2 * math.sqrt(6)), -a / (2 * math.sqrt(10))],
            [0, a / math.sqrt(3), -a / (2 * math.sqrt(6)), -a / (2 * math.sqrt(10))],
            [0, 0, a * math.sqrt(3) / (2 * math.sqrt(2)), -a / (2 * math.sqrt(10))],
            [0, 0, 0, 2 * a / math.sqrt(10)],
        ]
    )
    np.testing.assert_allclose(pentachoron(2.0).vertices, expected, atol=1e-15)
    np.testing.assert_allclose(polytope("5-cell").vertices, expected, atol=1e-15)
    assert polytope("5-cell").circumradius == pytest.approx(math.sqrt(2 / 5) * a)
    np.testing.assert_allclose(pentachoron(1.0).vertices, expected / 2, atol=1e-15)


def test_pentachoron_w0_slice_is_a_regular_tetrahedron_of_edge_1_6():
    s = slice_polytope("5-cell", np.eye(4), 0.0)
    assert len(s.vertices) == 4 and s.face_census() == {3: 4}
    d = [np.linalg.norm(s.vertices[i] - s.vertices[j]) for i, j in itertools.combinations(range(4), 2)]
    np.testing.assert_allclose(d, 1.6, rtol=1e-12)


def test_textbook_coordinates():
    phi = (1 + math.sqrt(5)) / 2
    assert {tuple(r) for r in polytope("8-cell").vertices} == set(itertools.product((-1.0, 1.0), repeat=4))
    np.testing.assert_allclose(np.sort(np.abs(polytope("16-cell").vertices), axis=1)[:, -1], math.sqrt(2))
    assert polytope("120-cell").circumradius == pytest.approx(math.sqrt(8) * phi**2)
    assert polytope("120-cell").circumradius == pytest.approx(7.4, abs=0.01)
    assert polytope("600-cell").circumradius == pytest.approx(2 * phi)


@pytest.mark.parametrize(
    "alias, canon",
    [("pentachoron", "5-cell"), ("{3,3,3}", "5-cell"), ("Tesseract", "8-cell"), ("{4,3,3}", "8-cell"),
     ("hexadecachoron", "16-cell"), ("{3,3,4}", "16-cell"), ("24 cell", "24-cell"), ("{3,4,3}", "24-cell"),
     ("dodecaplex", "120-cell"), ("{5,3,3}", "120-cell"), ("hexacosichoron", "600-cell"), ("{3, 3, 5}", "600-cell")],
)
def test_names_and_schlafli_symbols(alias, canon):
    assert polytope(alias) is polytope(canon)


def test_repr_is_readable():
    assert repr(polytope("24-cell")) == "Polytope('24-cell', V=24, E=96, F=96, C=24, circumradius=2)"


def test_loading_is_cached_and_fast():
    import time

    t = time.perf_counter()
    a = polytope("120-cell")
    b = polytope("600-cell")
    assert polytope("120-cell") is a and polytope("600-cell") is b
    assert time.perf_counter() - t < 10.0  # generous: a leak or a per-call rebuild would show


@pytest.mark.parametrize(
    "arg, exc, match",
    [
        ("7-cell", ValueError, "Unknown polytope '7-cell'; expected one of '5-cell'"),
        ("", ValueError, "'600-cell'"),
        (5, TypeError, "name"),
    ],
)
def test_bad_names(arg, exc, match):
    with pytest.raises(exc, match=match):
        polytope(arg)


@pytest.mark.parametrize(
    "verts, exc, match",
    [
        (np.zeros((5, 3)), ValueError, r"\(V, 4\)"),
        (np.zeros((6, 4)), ValueError, "4-D convex polytope"),
        ([["a"] * 4] * 5, TypeError, "real numbers"),
        (np.full((5, 4), np.inf), ValueError, "finite"),
    ],
)
def test_bad_polytopes(verts, exc, match):
    with pytest.raises(exc, match=match):
        Polytope(verts)


def test_bad_pentachoron_edge():
    with pytest.raises(ValueError, match="positive"):
        pentachoron(-1.0)
    with pytest.raises(TypeError, match="positive number"):
        pentachoron("2")


# -- arrays that cannot be corrupted (issue 7) ---------------------------------


def exposed_arrays(p):
    """Every array a Polytope hands out, by name."""
    arrays = {
        "vertices": p.vertices,
        "edges": p.edges,
        "cell_normals": p.cell_normals,
        "cell_offsets": p.cell_offsets,
        "face_cells": p.face_cells,
    }
    arrays.update({f"faces[{i}]": f for i, f in enumerate(p.faces)})
    arrays.update({f"cells[{i}]": np.asarray(c) for i, c in enumerate(p.cells) if isinstance(c, np.ndarray)})
    # every public ndarray attribute is in the list above
    public = {k for k, v in vars(p).items() if not k.startswith("_") and isinstance(v, np.ndarray)}
    assert public <= set(arrays), public - set(arrays)
    return arrays


@pytest.mark.parametrize("name", NAMES)
def test_every_array_of_a_cached_polytope_is_read_only(name):
    p = polytope(name)
    assert polytope(name) is p  # cached: an edit would reach every later user
    for attr, a in exposed_arrays(p).items():
        assert not a.flags.writeable, f"{name}: {attr} is writable"
        with pytest.raises(ValueError, match="read-only"):
            a[...] = 0


@pytest.mark.parametrize("name", NAMES)
def test_faces_and_cells_cannot_be_replaced_or_extended(name):
    p = polytope(name)
    for seq in (p.faces, p.cells):
        assert isinstance(seq, tuple)
        with pytest.raises(TypeError):
            seq[0] = seq[1]
    for cell in p.cells:
        assert isinstance(cell, tuple)


def test_editing_edges_cannot_corrupt_later_slices():
    p = polytope("5-cell")
    before = slice_polytope(p, np.eye(4), 0.0)
    with pytest.raises(ValueError):
        p.edges[0] = (3, 4)
    with pytest.raises(ValueError):
        p.faces[0][0] = 4
    for a in (p.edges, p.vertices, p.faces[0], p.face_cells, p.cell_normals):
        with pytest.raises(ValueError):
            a.flags.writeable = True
        with pytest.raises(ValueError):
            a.resize(a.size + 5, refcheck=False)
    after = slice_polytope(p, np.eye(4), 0.0)
    np.testing.assert_array_equal(after.edges, before.edges)
    assert p.counts == COUNTS["5-cell"]


def test_a_built_polytope_copies_its_input_and_is_read_only():
    v = polytope("8-cell").vertices.copy()
    p = Polytope(v, name="box")
    v[0] = 100.0
    assert np.abs(p.vertices).max() == 1.0
    for attr, a in exposed_arrays(p).items():
        assert not a.flags.writeable, attr
    assert p.cell_vertices(0).flags.writeable  # a fresh array, the caller's to keep
