"""Slices checked against independent computation (scipy), swept across the polytope.

Property tests draw random rotations and slice levels: across and past the
polytope's extent, exactly at vertex heights, and the identity orientation.
"""

from collections import Counter

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings, strategies as st
from scipy.spatial import ConvexHull

from reference_geometry import merged_hull_faces, random_rotation, rotation_with_w_row, slice_volume_by_halfspaces
from rot4d_widget import polytope, slice_polytope
from rot4d_widget.geometry.slicing.polytope_slice import TOLERANCE
from rot4d_widget.geometry.slicing.tables import Slice

NAMES = ["5-cell", "8-cell", "16-cell", "24-cell", "120-cell", "600-cell"]
SMALL = ["5-cell", "8-cell", "16-cell", "24-cell"]
GENERIC_DEGREE = {"5-cell": 3, "8-cell": 3, "16-cell": 4, "24-cell": 3, "120-cell": 3, "600-cell": 5}

seeds = st.integers(0, 2**32 - 1)
fractions = st.floats(-1.2, 1.2, allow_nan=False)
PROPS = settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def heights(name, m):
    return (polytope(name).vertices @ m.T)[:, 3]


def check_closed_ccw_surface(s):
    """Every directed triangle edge appears once and its reverse once; normals point outward."""
    directed = Counter()
    for a, b, c in s.triangles.tolist():
        for e in ((a, b), (b, c), (c, a)):
            directed[e] += 1
    assert set(directed.values()) == {1}
    assert all(directed[(b, a)] == 1 for a, b in directed)
    g = s.vertices.mean(axis=0)
    p = s.vertices[s.triangles]
    outward = np.einsum("ij,ij->i", p[:, 0] - g, np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]))
    assert np.all(outward > 0)
    assert set(np.unique(s.triangles).tolist()) == set(range(len(s.vertices)))


def check_against_halfspaces(name, m, c0, s):
    p = polytope(name)
    r = p.circumradius
    ref_volume, _ = slice_volume_by_halfspaces(p.vertices @ m.T, c0)
    # 1e-9 relative or 1e-12 absolute at circumradius 1
    assert abs(s.volume - ref_volume) / r**3 <= max(1e-9 * ref_volume / r**3, 1e-12)


def check_against_hull(name, s):
    """The slice's combinatorics as scipy's ConvexHull of its own points sees them."""
    faces, edges, hull_vertices = merged_hull_faces(s.vertices)
    assert hull_vertices == set(range(len(s.vertices)))
    assert faces == {frozenset(poly.tolist()) for poly in s.polygons}
    assert edges == {frozenset(e) for e in s.edges.tolist()}
    assert Counter(len(f) for f in faces) == Counter(s.face_census())
    assert len(s.vertices) - len(s.edges) + len(s.cell_ids) == 2


def well_separated(name, m, c0, margin=1e-3):
    h = heights(name, m)
    return np.abs(h - c0).min() > margin * polytope(name).circumradius


@PROPS
@given(name=st.sampled_from(NAMES), seed=seeds, frac=fractions)
def test_random_slices_volume_and_surface(name, seed, frac):
    m = random_rotation(seed)
    c0 = frac * polytope(name).circumradius
    s = slice_polytope(name, m, c0)
    ref_volume, _ = slice_volume_by_halfspaces(polytope(name).vertices @ m.T, c0)
    if s.dim == 3:
        check_closed_ccw_surface(s)
        assert s.volume > 0
        assert len(s.vertices) - len(s.edges) + len(s.cell_ids) == 2
    else:
        assert s.volume == 0 and len(s.triangles) == 0 and s.face_census() == {}
    check_against_halfspaces(name, m, c0, s)


@PROPS
@given(name=st.sampled_from(NAMES), seed=seeds, frac=st.floats(0.02, 0.98))
def test_generic_slices_match_scipy_hull_and_are_simple(name, seed, frac):
    m = random_rotation(seed)
    h = heights(name, m)
    c0 = h.min() + frac * (h.max() - h.min())
    assume(well_separated(name, m, c0))
    s = slice_polytope(name, m, c0)
    assert s.dim == 3
    check_against_hull(name, s)
    degree = np.bincount(s.edges.ravel(), minlength=len(s.vertices))
    assert np.all(degree == GENERIC_DEGREE[name])
    # each polygon comes from a distinct cell
    assert len(np.unique(s.cell_ids)) == len(s.cell_ids)


@PROPS
@given(name=st.sampled_from(NAMES), seed=seeds, which=st.integers(0, 10**6))
def test_slices_exactly_at_vertex_heights(name, seed, which):
    m = random_rotation(seed)
    h = heights(name, m)
    c0 = float(h[which % len(h)])
    s = slice_polytope(name, m, c0)
    if s.dim == 3:
        check_closed_ccw_surface(s)
        # the vertex on H is a slice vertex, once
        x = (polytope(name).vertices @ m.T)[which % len(h), :3]
        assert np.sum(np.linalg.norm(s.vertices - x, axis=1) < 1e-9) == 1
    check_against_halfspaces(name, m, c0, s)


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("frac", [-1.01, -0.999, -0.5, -0.2, 0.0, 0.3, 0.7, 0.999, 1.01])
def test_identity_orientation_sweep(name, frac):
    m = np.eye(4)
    c0 = frac * heights(name, m).max()
    s = slice_polytope(name, m, c0)
    if s.dim == 3:
        check_closed_ccw_surface(s)
        check_against_hull(name, s)
    check_against_halfspaces(name, m, c0, s)


@pytest.mark.parametrize(
    "name, c0, vef, census",
    [
        ("16-cell", 0.0, (6, 12, 8), {3: 8}),
        ("24-cell", 0.0, (12, 24, 14), {3: 8, 4: 6}),
        ("8-cell", 1.0, (8, 12, 6), {4: 6}),
        ("8-cell", -1.0, (8, 12, 6), {4: 6}),
        ("5-cell", 0.0, (4, 6, 4), {3: 4}),
    ],
)
def test_degenerate_identity_cuts(name, c0, vef, census):
    s = slice_polytope(name, np.eye(4), c0)
    assert (len(s.vertices), len(s.edges), len(s.cell_ids)) == vef
    assert s.face_census() == census
    check_closed_ccw_surface(s)
    check_against_hull(name, s)
    check_against_halfspaces(name, np.eye(4), c0, s)


def test_24_cell_squares_come_from_cells_with_all_corners_on_h():
    p = polytope("24-cell")
    s = slice_polytope(p, np.eye(4), 0.0)
    for poly, cell in zip(s.polygons, s.cell_ids):
        if len(poly) == 4:
            on = np.abs(p.vertices[p.cell_vertices(cell), 3]) < 1e-12
            assert on.sum() == 4  # an octahedron's equator


def test_whole_cell_in_h_names_that_cell():
    p = polytope("8-cell")
    s = slice_polytope(p, np.eye(4), 1.0)
    cell = int(np.flatnonzero(np.isclose(p.cell_normals[:, 3], 1.0))[0])
    assert set(s.cell_ids.tolist()) == {cell}
    assert s.volume == pytest.approx(8.0)


@pytest.mark.parametrize(
    "direction, nv, ne, dim",
    [((1, 1, 1, 1), 1, 0, 0), ((1, 1, 1, 0), 2, 1, 1), ((1, 1, 0, 0), 4, 4, 2)],
)
def test_touching_a_vertex_an_edge_a_face_from_outside(direction, nv, ne, dim):
    m = rotation_with_w_row(direction)
    h = heights("8-cell", m)
    s = slice_polytope("8-cell", m, float(h.max()))
    assert (len(s.vertices), len(s.edges), s.dim) == (nv, ne, dim)
    assert len(s.cell_ids) == 0 and len(s.triangles) == 0 and s.volume == 0 and s.face_census() == {}
    top = (polytope("8-cell").vertices @ m.T)[np.isclose(h, h.max()), :3]
    assert {tuple(np.round(v, 9)) for v in s.vertices} == {tuple(np.round(v, 9)) for v in top}
    # the same from below
    s = slice_polytope("8-cell", m, float(h.min()))
    assert (len(s.vertices), len(s.edges), s.dim) == (nv, ne, dim)


@pytest.mark.parametrize("name", NAMES)
def test_missing_the_polytope_gives_empty_arrays_of_the_right_shapes(name):
    s = slice_polytope(name, np.eye(4), 2 * polytope(name).circumradius)
    assert s.vertices.shape == (0, 3) and s.edges.shape == (0, 2) and s.triangles.shape == (0, 3)
    assert s.polygon_offsets.tolist() == [0] and s.cell_ids.shape == (0,) and s.polygons == []
    assert s.volume == 0.0 and s.face_census() == {} and s.dim == -1


@pytest.mark.parametrize("name", NAMES)
def test_cavalieri_integral_of_slice_volumes_is_the_4_volume(name):
    m = random_rotation(7)
    p = polytope(name)
    h = np.unique(np.round(heights(name, m), 12))
    nodes = np.array([-1.0, 1.0]) / np.sqrt(3.0)  # 2-point Gauss-Legendre: exact for cubics
    total = 0.0
    for lo, hi in zip(h[:-1], h[1:]):
        mid, half = (lo + hi) / 2, (hi - lo) / 2
        total += half * sum(slice_polytope(p, m, mid + half * x).volume for x in nodes)
    assert total == pytest.approx(ConvexHull(p.vertices).volume, rel=1e-9)


@pytest.mark.parametrize("name, census", [("16-cell", {3: 8, 4: 6}), ("24-cell", {4: 6, 6: 12})])
@pytest.mark.parametrize("seed", range(5))
def test_generic_central_slice_census(name, census, seed):
    assert slice_polytope(name, random_rotation(seed), 0.0).face_census() == census


def test_tolerance_is_one_relative_number():
    assert TOLERANCE == 1e-9
    # a vertex a hair inside the tolerance counts as on H; one outside does not
    p = polytope("5-cell")
    top = p.vertices[4, 3]
    assert slice_polytope(p, np.eye(4), top - 0.5 * TOLERANCE * p.circumradius).dim == 0
    assert slice_polytope(p, np.eye(4), top - 2 * TOLERANCE * p.circumradius).dim == 3


def test_triangle_cells_follow_polygons():
    s = slice_polytope("600-cell", random_rotation(3), 0.5)
    sizes = s.polygon_sizes
    assert len(s.triangles) == int((sizes - 2).sum())
    assert np.array_equal(np.repeat(s.cell_ids, sizes - 2), s.triangle_cells)


@pytest.mark.parametrize(
    "args, exc, match",
    [
        (("5-cell", np.eye(3), 0.0), ValueError, r"shape \(4, 4\)"),
        (("5-cell", np.ones((4, 4)), 0.0), ValueError, "orthogonal"),
        (("5-cell", np.eye(4), float("nan")), ValueError, "c0.*finite"),
        (("5-cell", np.eye(4), "0"), TypeError, "c0"),
        (("9-cell", np.eye(4), 0.0), ValueError, "Unknown polytope"),
    ],
)
def test_bad_slice_input(args, exc, match):
    with pytest.raises(exc, match=match):
        slice_polytope(*args)


# -- arrays that cannot be corrupted (issue 7) ---------------------------------

SLICE_ARRAYS = ("vertices", "edges", "polygon_indices", "polygon_offsets", "cell_ids", "triangles", "triangle_cells")


def exposed_arrays(s):
    """Every array a Slice hands out: its fields, its properties, and the polygons."""
    arrays = {name: getattr(s, name) for name in SLICE_ARRAYS}
    arrays["polygon_sizes"] = s.polygon_sizes
    for i, poly in enumerate(s.polygons):
        arrays[f"polygons[{i}]"] = poly
    # no array field left unchecked
    fields = {f for f in Slice.__dataclass_fields__ if isinstance(getattr(s, f), np.ndarray)}
    assert fields == set(SLICE_ARRAYS)
    return arrays


def slices_of_every_kind(name):
    """A solid slice, a missed one, the touching cases and an on-H cell (8-cell)."""
    p = polytope(name)
    h = heights(name, np.eye(4))
    out = {
        "solid": slice_polytope(p, random_rotation(5), 0.1 * p.circumradius),
        "missed above": slice_polytope(p, np.eye(4), 2 * p.circumradius),
        "missed below": slice_polytope(p, np.eye(4), -2 * p.circumradius),
        "touching top": slice_polytope(p, np.eye(4), float(h.max())),
        "touching bottom": slice_polytope(p, np.eye(4), float(h.min())),
    }
    if name == "8-cell":
        out["whole cell"] = slice_polytope(p, np.eye(4), 1.0)
        out["vertex"] = slice_polytope(p, rotation_with_w_row((1, 1, 1, 1)), 2.0)
    return out


@pytest.mark.parametrize("name", NAMES)
def test_every_array_of_every_slice_is_read_only(name):
    for kind, s in slices_of_every_kind(name).items():
        for attr, a in exposed_arrays(s).items():
            assert not a.flags.writeable, f"{name} {kind}: {attr} is writable"
            with pytest.raises(ValueError, match="read-only"):
                a[...] = 0


@pytest.mark.parametrize("name", ["5-cell", "8-cell", "600-cell"])
def test_editing_one_missed_slice_cannot_corrupt_the_next(name):
    p = polytope(name)
    s = slice_polytope(p, np.eye(4), 3 * p.circumradius)
    for attr in SLICE_ARRAYS:
        a = getattr(s, attr)
        with pytest.raises(ValueError):
            a[...] = 5
        # a shared array can be neither unlocked nor resized in place; this slice's
        # own arrays may be (deliberately), which touches no other slice
        for edit in (lambda: setattr(a.flags, "writeable", True), lambda: a.resize(7, refcheck=False)):
            try:
                edit()
            except ValueError:
                pass
        if a.flags.writeable:
            a[...] = 5
    later = slice_polytope(p, random_rotation(2), -3 * p.circumradius)
    assert later.polygon_offsets.tolist() == [0] and later.polygons == [] and later.face_census() == {}
    assert later.edges.shape == (0, 2) and later.triangles.shape == (0, 3) and later.vertices.shape == (0, 3)


def test_slicing_does_not_touch_the_callers_matrix():
    m = random_rotation(4)
    before = m.copy()
    s = slice_polytope("24-cell", m, 0.2)
    m[:] = np.eye(4)
    np.testing.assert_array_equal(slice_polytope("24-cell", before, 0.2).vertices, s.vertices)
