"""Polytope(vertices, faces, cells): explicit combinatorics, their validation, and 4OFF files."""

import time

import numpy as np
import pytest

from mesh_shapes import duoprism, duoprism_mesh, prism_mesh, tesseract_union, tesseract_union_mesh
from reference_geometry import random_rotation
from rot4d_widget import Polytope, polytope, slice_polytope
from rot4d_widget.geometry.offfile import read_off
from rot4d_widget.geometry.meshcheck import MeshError

NAMES = ["5-cell", "8-cell", "16-cell", "24-cell", "120-cell", "600-cell"]


def as_lists(p):
    return [f.tolist() for f in p.faces], [list(c) for c in p.cells]


# -- explicit combinatorics agree with the convex hull ------------------------------------


@pytest.mark.parametrize("name", NAMES)
def test_the_regular_six_from_their_own_faces_and_cells(name):
    p = polytope(name)
    faces, cells = as_lists(p)
    q = Polytope(p.vertices, faces, cells, name=name)
    assert q.counts == p.counts
    np.testing.assert_array_equal(q.edges, p.edges)
    np.testing.assert_array_equal(q.face_cells, p.face_cells)
    assert q.cells == p.cells and all(np.array_equal(a, b) for a, b in zip(q.faces, p.faces))
    np.testing.assert_allclose(q.cell_normals, p.cell_normals, atol=1e-12)  # outward, from the orientation
    np.testing.assert_allclose(q.cell_offsets, p.cell_offsets, atol=1e-12)
    np.testing.assert_array_equal(q._cell_vertex_mask, p._cell_vertex_mask)
    m = random_rotation(3)
    for c0 in (0.0, 0.37 * p.circumradius):
        a, b = slice_polytope(p, m, c0), slice_polytope(q, m, c0)
        np.testing.assert_array_equal(a.polygon_indices, b.polygon_indices)
        assert a.volume == pytest.approx(b.volume, rel=1e-12)


@pytest.mark.parametrize("pq", [(3, 3), (5, 7), (4, 12)])
def test_duoprisms_match_the_hull_of_their_vertices(pq):
    p = duoprism(*pq)
    a, b = pq
    assert p.counts == (a * b, 2 * a * b, a * b + a + b, a + b)
    hull = Polytope(p.vertices)
    assert hull.counts == p.counts
    np.testing.assert_array_equal(hull.edges, p.edges)
    d = np.linalg.norm(p.vertices[p.edges[:, 0]] - p.vertices[p.edges[:, 1]], axis=1)
    np.testing.assert_allclose(d, 2.0)
    for seed in range(3):
        m = random_rotation(seed)
        for c0 in (-0.4, 0.0, 0.9):
            assert slice_polytope(p, m, c0).volume == pytest.approx(slice_polytope(hull, m, c0).volume, rel=1e-9)


def test_validate_false_gives_the_same_polytope():
    v, f, c = duoprism_mesh(6, 9)
    a, b = Polytope(v, f, c), Polytope(v, f, c, validate=False)
    np.testing.assert_array_equal(a.cell_normals, b.cell_normals)
    np.testing.assert_array_equal(a.edges, b.edges)


def test_a_big_duoprism_builds_and_slices_in_seconds():
    """14400 vertices, 14640 faces: the size of the largest uniform polychora."""
    v, f, c = duoprism_mesh(120, 120)
    t = time.perf_counter()
    p = Polytope(v, f, c, name="120-120 duoprism")
    s = slice_polytope(p, random_rotation(0), 0.0)  # includes the slicing tables
    assert time.perf_counter() - t < 10.0  # about 0.6 s on the project's machine
    assert p.counts == (14400, 28800, 14640, 240)
    assert s.dim == 3 and s.volume > 0


def test_outward_normals_of_a_non_convex_union():
    p, pieces = tesseract_union("plus")
    boxes = [(pc.min(axis=0), pc.max(axis=0)) for pc in pieces]

    def inside(x):
        return any(np.all((x > lo) & (x < hi)) for lo, hi in boxes)

    assert not all(np.all(p.vertices @ n <= o + 1e-9) for n, o in zip(p.cell_normals, p.cell_offsets))  # not convex
    for c in range(len(p.cells)):
        g = p.vertices[p.cell_vertices(c)].mean(axis=0)
        np.testing.assert_allclose(p.vertices[p.cell_vertices(c)] @ p.cell_normals[c], p.cell_offsets[c], atol=1e-12)
        assert not inside(g + 0.1 * p.cell_normals[c]) and inside(g - 0.1 * p.cell_normals[c])


def test_a_cavity_is_oriented_towards_its_hole_and_separate_pieces_outward():
    t = polytope("8-cell")
    faces, cells = as_lists(t)
    F, V = len(faces), len(t.vertices)
    faces2 = faces + [[i + V for i in f] for f in faces]
    cells2 = cells + [[i + F for i in c] for c in cells]
    shell = Polytope(np.concatenate([3 * t.vertices, t.vertices]), faces2, cells2)
    np.testing.assert_allclose(shell.cell_normals[:8], t.cell_normals, atol=1e-12)
    np.testing.assert_allclose(shell.cell_normals[8:], -t.cell_normals, atol=1e-12)  # into the hole
    s = slice_polytope(shell, np.eye(4), 0.0)
    assert s.volume == pytest.approx(6**3 - 2**3)
    apart = Polytope(np.concatenate([t.vertices - 3, t.vertices + 3]), faces2, cells2)
    np.testing.assert_allclose(apart.cell_normals, np.concatenate([t.cell_normals] * 2), atol=1e-12)


def test_flat_ridges_between_coplanar_cells_are_allowed():
    p, _ = tesseract_union("L")
    n = p.cell_normals
    flat = [f for f, (a, b) in enumerate(p.face_cells) if np.allclose(n[a], n[b])]
    assert flat  # cubes side by side in one hyperplane, sharing a face
    assert slice_polytope(p, np.eye(4), 0.1).volume == pytest.approx(4.0)


def test_arrays_of_an_explicit_polytope_are_read_only():
    p, _ = tesseract_union("L")
    for a in (p.vertices, p.edges, p.face_cells, p.cell_normals, p.cell_offsets, p.faces[0], p._cell_vertex_mask):
        with pytest.raises(ValueError, match="read-only"):
            a[...] = 0
        with pytest.raises(ValueError):
            a.flags.writeable = True
    assert isinstance(p.cells, tuple) and all(isinstance(c, tuple) for c in p.cells)


# -- validation: every check can fail, with a message naming the offence ------------------


def tesseract_lists():
    return polytope("8-cell").vertices.copy(), *as_lists(polytope("8-cell"))


def dented_octahedron():
    """A square bipyramid with one apex pushed inside: non-convex, all faces triangles."""
    v = np.array([[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0], [0, 0, 1.5], [0, 0, 0.5]], float)
    faces = [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4], [1, 0, 5], [2, 1, 5], [3, 2, 5], [0, 3, 5]]
    return v, faces


def bad(change):
    v, faces, cells = tesseract_lists()
    change(v, faces, cells)
    return v, faces, cells


def _swap(v, faces, cells):
    faces[3] = [faces[3][0], faces[3][2], faces[3][1], faces[3][3]]


def _bend(v, faces, cells):
    v[15] = [1.0, 1.0, 1.0, 1.3]


def _drop_cell(v, faces, cells):
    del cells[-1]


def _extra_cell(v, faces, cells):
    cells.append(list(cells[0]))


def _face_twice(v, faces, cells):
    cells[0] = cells[0] + [cells[0][0]]


def _vertex_twice(v, faces, cells):
    faces[0] = faces[0] + [faces[0][0]]


def _short_face(v, faces, cells):
    faces[0] = faces[0][:2]


def _bad_index(v, faces, cells):
    faces[2] = [0, 1, 99, 2]


def _cell_index(v, faces, cells):
    cells[1] = list(cells[1][:-1]) + [24]


@pytest.mark.parametrize(
    "change, exc, match",
    [
        (_swap, MeshError, r"face 3 .* is not a convex polygon in the order given"),
        (_bend, MeshError, r"face \d+ is not planar"),
        (_drop_cell, MeshError, r"face \d+ is in 1 cell\(s\) .*exactly two cells"),
        (_extra_cell, MeshError, r"face \d+ is in 3 cell\(s\)"),
        (_face_twice, MeshError, r"`cells\[0\]` has face \d+ twice"),
        (_vertex_twice, MeshError, r"`faces\[0\]` has vertex \d+ twice"),
        (_short_face, MeshError, r"`faces\[0\]` has 2 vertices; a face needs at least 3"),
        (_bad_index, MeshError, r"`faces\[2\]` has vertex index 99; expected integers 0 to 15"),
        (_cell_index, MeshError, r"`cells\[1\]` has face index 24; expected integers 0 to 23"),
    ],
)
def test_bad_meshes_are_refused_naming_the_offence(change, exc, match):
    with pytest.raises(exc, match=match):
        Polytope(*bad(change))


def test_type_errors_name_what_is_allowed():
    v, faces, cells = tesseract_lists()
    with pytest.raises(TypeError, match=r"`faces\[1\]` to be a sequence of integer vertex indices"):
        Polytope(v, [faces[0], [0, 1.5, 2, 3]] + faces[2:], cells)
    with pytest.raises(TypeError, match=r"`cells\[0\]` to be a sequence of face indices"):
        Polytope(v, faces, [7] + cells[1:])
    with pytest.raises(TypeError, match="both `faces` and `cells`, or neither"):
        Polytope(v, faces)
    with pytest.raises(TypeError, match="pass the name as name="):
        Polytope(v, "box")
    with pytest.raises(TypeError,
                       match=r"`faces` to be a sequence of sequences of vertex indices \(integers 0 to 15\)"):
        Polytope(v, 5, cells)


def test_a_vertex_in_no_face_and_coinciding_vertices():
    v, faces, cells = tesseract_lists()
    with pytest.raises(MeshError, match="vertex 16 is in no face"):
        Polytope(np.concatenate([v, [[5.0, 5, 5, 5]]]), faces, cells)
    v[15] = v[0]
    with pytest.raises(MeshError, match="vertices 0 and 15 coincide"):
        Polytope(v, faces, cells)


def test_a_star_pentagon_face_is_accepted_and_sliced():
    """The {5/2}-{5} duoprism (issue 22: star faces load): its slice at w = c0 is a prism over a
    pentagram, checked against an independent computation (the edges' crossings interpolated
    here, the volume winding-weighted: the pentagram's shoelace area times the chord of the
    pentagon; the drawn area even-odd: the pentagram's five points, twice, and five rectangles)."""
    v, f, c = duoprism_mesh(5, 5)
    rp = float(np.linalg.norm(v[0, :2]))
    ang = 4 * np.pi * (np.arange(25) // 5) / 5  # corner i of the first factor at 4 pi i / 5: a pentagram
    v[:, 0], v[:, 1] = rp * np.cos(ang), rp * np.sin(ang)
    p = Polytope(v, f, c)
    assert p.counts == (25, 50, 35, 10) and not p.convex and p.self_intersecting
    c0 = 0.3
    s = slice_polytope(p, np.eye(4), c0)
    a, b = p.edges.T
    cross = (v[a, 3] - c0) * (v[b, 3] - c0) < 0
    a, b = a[cross], b[cross]
    t = ((c0 - v[a, 3]) / (v[b, 3] - v[a, 3]))[:, None]
    expected = v[a, :3] + t * (v[b, :3] - v[a, :3])
    got = np.asarray(s.vertices)[: len(s.vertices) - s.n_fill]
    assert len(got) == len(expected) == 10
    assert np.abs(np.sort(got, axis=0) - np.sort(expected, axis=0)).max() < 1e-12
    star = v[f[0], :2]
    wind = 0.5 * np.sum(star[:, 0] * np.roll(star[:, 1], -1) - np.roll(star[:, 0], -1) * star[:, 1])
    q = v[:5, 2:]  # the pentagon (z, w) of corner i = 0
    zs = [qa[0] + (c0 - qa[1]) / (qb[1] - qa[1]) * (qb[0] - qa[0])
          for qa, qb in zip(q, np.roll(q, -1, axis=0)) if (qa[1] - c0) * (qb[1] - c0) < 0]
    chord = abs(zs[0] - zs[1])
    assert s.volume == pytest.approx(abs(wind) * chord, rel=1e-12)
    inner = 2.5 * np.sin(2 * np.pi / 5) * (rp * np.cos(2 * np.pi / 5) / np.cos(np.pi / 5)) ** 2
    tri = np.asarray(s.vertices)[s.triangles]
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1).sum()
    side = 2 * rp * np.sin(2 * np.pi / 5)
    assert area == pytest.approx(2 * (abs(wind) - 2 * inner) + 5 * side * chord, rel=1e-12)


def test_a_non_convex_cell_is_accepted_and_sliced_and_its_convex_prism_too():
    v, f, c = prism_mesh(*dented_octahedron())
    p = Polytope(v, f, c)  # issue 22: non-convex cells load
    assert p.counts == (12, 30, 28, 10) and not p.convex and not p.self_intersecting
    for c0 in (0.0, 0.5, 1.0):  # the dented octahedron: a pyramid of height 1.5 less one of 0.5, base 2
        s = slice_polytope(p, np.eye(4), c0)
        assert s.volume == pytest.approx(2 * 1.5 / 3 - 2 * 0.5 / 3, rel=1e-12)
        assert s.n_fill == 0 and np.abs(np.sort(np.asarray(s.vertices), axis=0)
                                        - np.sort(dented_octahedron()[0], axis=0)).max() < 1e-12
    ov = np.array([[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0], [0, 0, 1.0], [0, 0, -1.0]])
    octa = [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4], [1, 0, 5], [2, 1, 5], [3, 2, 5], [0, 3, 5]]
    p = Polytope(*prism_mesh(ov, octa))
    assert p.counts == (12, 6 + 12 + 12, 16 + 12, 2 + 8)


def test_coplanar_faces_in_one_cell_are_refused():
    """A cube whose top is split in two coplanar rectangles, times an interval."""
    v = np.array([[0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0], [0, 0, 2], [2, 0, 2], [2, 2, 2], [0, 2, 2],
                  [1, 0, 2], [1, 2, 2], [1, 0, 0], [1, 2, 0]], float)
    faces = [[0, 10, 11, 3], [10, 1, 2, 11], [4, 8, 9, 7], [8, 5, 6, 9], [0, 10, 8, 4], [10, 1, 5, 8],
             [3, 7, 9, 11], [11, 9, 6, 2], [0, 4, 7, 3], [1, 2, 6, 5]]
    with pytest.raises(MeshError, match=r"cell [01] is not strictly convex: .* \(two coplanar faces\?\)"):
        Polytope(*prism_mesh(v, faces))


def test_a_cell_that_is_not_closed_is_refused():
    v, faces, cells = tesseract_lists()
    # two cubes exchange a face each: every face still in two cells, each cell open
    j = next(j for j in range(1, 8) if not set(cells[0]) & set(cells[j]))  # the opposite cube
    a, b = cells[0], cells[j]
    cells[0] = [*a[:-1], b[-1]]
    cells[j] = [*b[:-1], a[-1]]
    with pytest.raises(MeshError, match=r"cell 0 is not closed: its edge \(\d+, \d+\) is in 1 of its faces"):
        Polytope(v, faces, cells)


def test_a_prism_of_no_height_is_refused():
    v = np.array(list(np.ndindex(2, 2, 2)), float)
    cube = [[0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6], [0, 2, 6, 4], [1, 3, 7, 5]]
    assert Polytope(*prism_mesh(v, cube)).counts == (16, 32, 24, 8)
    with pytest.raises(MeshError, match="vertices 0 and 8 coincide"):
        Polytope(*prism_mesh(v, cube, height=1e-9))


# -- 4OFF ---------------------------------------------------------------------------------

#: A tesseract written out by hand from Stella4D's description of 4OFF: vertex index
#: x + 2y + 4z + 8w (bit 0 -> -1, bit 1 -> +1), the 24 squares by the two axes they span
#: and the fixed other two, the 8 cubes by their fixed axis; colours in both notations.
TESSERACT_4OFF = """\
4OFF
# the tesseract, written out by hand
16 24 32 8

-1 -1 -1 -1
1 -1 -1 -1
-1 1 -1 -1
1 1 -1 -1
-1 -1 1 -1
1 -1 1 -1
-1 1 1 -1
1 1 1 -1
-1 -1 -1 1
1 -1 -1 1
-1 1 -1 1
1 1 -1 1
-1 -1 1 1
1 -1 1 1
-1 1 1 1
1 1 1 1

# faces
4 0 1 3 2      # xy z=- w=-
4 8 9 11 10    # xy z=- w=+
4 4 5 7 6      # xy z=+ w=-
4 12 13 15 14  # xy z=+ w=+
4 0 1 5 4      # xz y=- w=-
4 8 9 13 12    # xz y=- w=+
4 2 3 7 6      # xz y=+ w=-
4 10 11 15 14  # xz y=+ w=+
4 0 1 9 8      # xw y=- z=-
4 4 5 13 12    # xw y=- z=+
4 2 3 11 10    # xw y=+ z=-
4 6 7 15 14    # xw y=+ z=+
4 0 2 6 4      # yz x=- w=-
4 8 10 14 12   # yz x=- w=+
4 1 3 7 5      # yz x=+ w=-
4 9 11 15 13   # yz x=+ w=+
4 0 2 10 8     # yw x=- z=-
4 4 6 14 12    # yw x=- z=+
4 1 3 11 9     # yw x=+ z=-
4 5 7 15 13    # yw x=+ z=+
4 0 4 12 8     # zw x=- y=-
4 2 6 14 10    # zw x=- y=+
4 1 5 13 9     # zw x=+ y=-
4 3 7 15 11    # zw x=+ y=+

# cells
6 12 13 16 17 20 21   255 0 0       # x=-
6 14 15 18 19 22 23   0 255 0 128   # x=+
6 4 5 8 9 20 22       0.0 0.5 1.0   # y=-
6 6 7 10 11 21 23     0.2 0.2 0.2 0.5
6 0 1 8 10 16 18      # z=-
6 2 3 9 11 17 19      # z=+
6 0 2 4 6 12 14       # w=-
6 1 3 5 7 13 15       # w=+
"""


def test_reader_on_a_hand_written_tesseract():
    p = Polytope.from_off(TESSERACT_4OFF)
    t = polytope("8-cell")
    assert p.counts == t.counts == (16, 32, 24, 8)
    assert p.name == "4OFF"
    np.testing.assert_array_equal(p.vertices[5], [1, -1, 1, -1])  # index x + 2y + 4z + 8w
    assert {tuple(r) for r in p.vertices} == {tuple(r) for r in t.vertices}
    # cell k is the cube on axis k // 2, side - then +: its outward normal says so
    expected = np.repeat(np.eye(4), 2, axis=0) * np.tile([-1.0, 1.0], 4)[:, None]
    np.testing.assert_allclose(p.cell_normals, expected, atol=1e-12)
    np.testing.assert_allclose(p.cell_offsets, 1.0)
    assert p.faces[3].tolist() == [12, 13, 15, 14] and p.cells[2] == (4, 5, 8, 9, 20, 22)
    for seed in range(4):
        m = random_rotation(seed)
        assert slice_polytope(p, m, 0.3).volume == pytest.approx(slice_polytope(t, m, 0.3).volume, rel=1e-12)
    d = read_off(TESSERACT_4OFF)
    assert d.face_colours is None
    np.testing.assert_allclose(d.cell_colours[0], [1, 0, 0, 1])
    np.testing.assert_allclose(d.cell_colours[1], [0, 1, 0, 128 / 255])
    np.testing.assert_allclose(d.cell_colours[2], [0, 0.5, 1, 1])
    np.testing.assert_allclose(d.cell_colours[3], [0.2, 0.2, 0.2, 0.5])
    assert np.isnan(d.cell_colours[4]).all()
    assert d.vertex_lines[0] == 5 and d.face_lines[0] == 23 and d.cell_lines[-1] == 56


@pytest.mark.parametrize("name", NAMES)
def test_round_trip_of_the_regular_six(name, tmp_path):
    p = polytope(name)
    path = tmp_path / f"{name}.off"
    text = p.to_off(path)
    assert path.read_text() == text and text.startswith("4OFF\n")
    q = Polytope.from_off(path)
    assert q.name == name
    np.testing.assert_array_equal(q.vertices, p.vertices)  # exact
    assert q.cells == p.cells and all(np.array_equal(a, b) for a, b in zip(q.faces, p.faces))
    np.testing.assert_allclose(q.cell_normals, p.cell_normals, atol=1e-12)
    assert Polytope.from_off(str(path)).counts == p.counts


@pytest.mark.parametrize("shape", ["L", "plus"])
def test_round_trip_of_a_non_convex_mesh(shape):
    p, _ = tesseract_union(shape)
    q = Polytope.from_off(p.to_off(), name=shape)
    np.testing.assert_array_equal(q.vertices, p.vertices)
    np.testing.assert_array_equal(q.cell_normals, p.cell_normals)
    assert q.cells == p.cells and q.name == shape


def test_comments_blank_lines_and_counts_on_the_header_line():
    body = TESSERACT_4OFF.split("16 24 32 8\n", 1)[1].replace("\n\n", "\n\n# more\n\n")
    text = "# a comment first\n4OFF 16 24 0 8\n" + body
    assert Polytope.from_off(text).counts == (16, 32, 24, 8)


GEOMVIEW_CUBE = """\
4OFF
8 6 12
-1 -1 -1 1
1 -1 -1 1
1 1 -1 1
-1 1 -1 1
-1 -1 1 1
1 -1 1 1
1 1 1 1
-1 1 1 1
4 0 1 2 3
4 4 5 6 7
4 0 1 5 4
4 1 2 6 5
4 2 3 7 6
4 3 0 4 7
"""


def test_geomview_4off_is_recognised_and_refused():
    with pytest.raises(ValueError, match=r"line 2: three counts .*Geomview's 4OFF \(homogeneous 3-D"):
        Polytope.from_off(GEOMVIEW_CUBE)
    with pytest.raises(ValueError, match=r"line 2: no cells \(C = 0\)"):
        Polytope.from_off(GEOMVIEW_CUBE.replace("8 6 12", "8 6 12 0"))
    with pytest.raises(ValueError, match=r"line 1: header 'C4OFF' is Geomview's"):
        Polytope.from_off("C4OFF\n8 6 12\n")
    with pytest.raises(ValueError, match=r"line 1: header '4nOFF' is Geomview's"):
        Polytope.from_off("4nOFF\n4\n")


def edit(lineno, new):
    lines = TESSERACT_4OFF.split("\n")
    lines[lineno - 1] = new
    return "\n".join(lines)


@pytest.mark.parametrize(
    "text, match",
    [
        ("\n\n", r"line 1: empty file"),
        ("OFF\n8 6 12\n", r"line 1: expected the header 4OFF \(Stella4D\), got 'OFF'"),
        (edit(3, "16 24 32"), r"line 3: three counts"),
        (edit(3, "16 24 32 8 1"), r"line 3: expected four counts V F E C"),
        (edit(3, "16 24 x 8"), r"line 3: expected four integer counts"),
        # a wrong E is read with a warning (issue 22: other tools' files): tests/geometry/test_off_tools.py
        (edit(8, "1 1 -1"), r"line 8: vertex 3 has 3 numbers; expected 4 coordinates x y z w"),
        (edit(8, "1 1 -1 one"), r"line 8: vertex 3 has a coordinate that is not a number"),
        (edit(8, "1 1 -1 nan"), r"line 8: vertex 3 is not finite"),
        (edit(24, "4 8 9 11"), r"line 24: face 1 says 4 vertexs? but gives 3 numbers"),
        (edit(24, "4 8 9 11 16"), r"line 24: face 1 refers to vertex 16; expected 0 to 15"),
        (edit(24, "4 8 9 11 1.5"), r"line 24: face 1 has a vertex index that is not an integer"),
        (edit(24, "four 8 9 11 10"), r"line 24: face 1 should start with its number of vertexs?"),
        (edit(24, "4 8 9 11 10 1 2"), r"line 24: face 1 ends with 2 extra numbers '1 2'"),
        (edit(24, "4 8 9 11 10 1 2 300"), r"line 24: colour '1 2 300' out of range; expected integers 0...255"),
        (edit(24, "4 8 9 11 10 0.5 2.0 0"), r"line 24: colour '0.5 2.0 0' out of range; expected numbers in 0...1"),
        (edit(49, "6 12 13 16 17 20 24"), r"line 49: cell 0 refers to face 24; expected 0 to 23"),
        (TESSERACT_4OFF + "7\n", r"line 57: unexpected content after the 8 cells: '7'"),
        (TESSERACT_4OFF.rsplit("6 1 3 5", 1)[0], r"line 56: file ends after 7 of 8 cell lines"),
        # the Polytope's own checks, mapped to the line of the face, cell or vertex
        (edit(26, "4 12 13 14 15"), r"line 26 \(face 3\): face 3 .* is not a convex polygon"),
        (edit(8, "1 1 -1 -1.5"), r"line \d+ \(face \d+\): face \d+ is not planar"),
        (edit(49, "6 12 13 16 17 20 22"),
         r"line \d+ \((face \d+\): face \d+ is in [13] cell|cell \d+\): cell \d+ is not closed)"),
    ],
)
def test_bad_4off_files_name_the_line(text, match):
    with pytest.raises(ValueError, match=match):
        Polytope.from_off(text)


def test_from_off_reads_a_path_and_refuses_other_types(tmp_path):
    path = tmp_path / "my tesseract.off"
    path.write_text(TESSERACT_4OFF)
    assert Polytope.from_off(path).name == "my tesseract"
    with pytest.raises(TypeError, match="path or the text of a 4OFF file"):
        Polytope.from_off(3.5)
    with pytest.raises(FileNotFoundError):
        Polytope.from_off(str(tmp_path / "missing.off"))


def test_convex_says_whether_the_polytope_is_convex():
    assert all(polytope(n).convex for n in NAMES)
    assert all(Polytope(polytope(n).vertices, *as_lists(polytope(n))).convex for n in NAMES)
    assert duoprism(5, 7).convex and duoprism(3, 12).convex
    assert not any(tesseract_union(shape)[0].convex for shape in ("L", "plus", "ring", "tripod"))
    v, f, c, _ = tesseract_union_mesh([(0, 0, 0, 0), (1, 0, 0, 0)])  # a 2x1x1x1 box: flat ridges only
    assert Polytope(v, f, c).convex
    v, f, c, _ = tesseract_union_mesh([(0, 0, 0, 0), (0, 0, 0, 3)])  # two pieces apart
    assert not Polytope(v, f, c).convex
