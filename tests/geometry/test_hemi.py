"""Hemi and non-orientable polychora load and slice, with no volume (issue 22).

Two prisms built here over hemi-polyhedra, whose faces pass through their centre:

* over the **octahemioctahedron** (the cuboctahedron's 12 vertices, its 8 triangles and the 4
  hexagons through its centre): two-sided, a torus (Euler characteristic 0), but enclosing no
  volume (its faces' oriented areas cancel): ``why_no_volume == "hemi cells"``;
* over the **tetrahemihexahedron** (the octahedron's 6 vertices, 4 of its triangles and its 3
  squares through the centre): one-sided, a projective plane (Euler characteristic 1):
  ``"not orientable"``.

Checked independently of the slicer: cut straight (w = c0 between the caps) the slice is the
polyhedron itself -- its vertices, its edges as segments, its faces as polygons, their areas; cut
obliquely through a cap, the slice's points are the edges' crossings (interpolated here) and each
cell's drawn triangles cover exactly the points of its section that lie inside the 4-D cell by ray
parity against the cell's own faces (for a hemi cap: the even-odd region of the hemi-polyhedron's
plane section).  The volume is None in every slice, and everything that reads it (readouts, stacks,
exports, figures, state files) says "none" and why, never a number or "None".  A broken mesh (an
open cell, an edge in three faces of a cell) is still refused.
"""

from __future__ import annotations

import collections
import itertools

import numpy as np
import pytest
from mesh_shapes import prism_mesh
from reference_geometry import random_rotation
from test_star_cells import edge_crossings, parity_in_faces, plane_frame, same_points, shoelace

from rot4d_widget import Polytope, slice_polytope
from rot4d_widget.geometry.meshcheck import MeshError
from rot4d_widget.sources.protocol import PolytopeSource
from rot4d_widget.sources.tomography import StackSource


def cycle(v, idx):
    """The vertices ``idx`` of a planar convex polygon in cyclic order (by angle about their mean)."""
    idx = np.asarray(idx)
    c, ax = plane_frame(v[idx])
    xy = (v[idx] - c) @ ax.T
    return idx[np.argsort(np.arctan2(xy[:, 1], xy[:, 0]))].tolist()


def octahemioctahedron():
    v = np.array(sorted({p for a in (-1, 1) for b in (-1, 1) for p in itertools.permutations((a, b, 0))}), float)
    tris = [cycle(v, np.flatnonzero(v @ np.array(s) == 2)) for s in itertools.product((-1, 1), repeat=3)]
    hexagons = [cycle(v, np.flatnonzero(v @ np.array(s) == 0)) for s in ((1, 1, 1), (1, 1, -1), (1, -1, 1), (-1, 1, 1))]
    return v, tris + hexagons


def tetrahemihexahedron():
    v = np.concatenate([np.eye(3), -np.eye(3)])
    tris = [cycle(v, np.flatnonzero(v @ np.array(s) > 0)) for s in itertools.product((-1, 1), repeat=3)
            if np.prod(s) > 0]
    squares = [cycle(v, np.flatnonzero(v[:, k] == 0)) for k in range(3)]
    return v, tris + squares


HEMI = {"octahemioctahedron": (octahemioctahedron, "hemi cells", (12, 24, 12)),
        "tetrahemihexahedron": (tetrahemihexahedron, "not orientable", (6, 12, 7))}


def edges3(faces3):
    return {tuple(sorted((f[i], f[(i + 1) % len(f)]))) for f in faces3 for i in range(len(f))}


@pytest.fixture(scope="module", params=list(HEMI))
def hemi(request):
    build, why, counts = HEMI[request.param]
    v3, faces3 = build()
    return request.param, v3, faces3, why, counts, Polytope(*prism_mesh(v3, faces3), name=f"{request.param} prism")


def test_the_hemi_polyhedra_are_what_they_are(hemi):
    name, v3, faces3, _, counts, _ = hemi
    e = edges3(faces3)
    assert (len(v3), len(e), len(faces3)) == counts
    assert len(v3) - len(e) + len(faces3) == {"octahemioctahedron": 0, "tetrahemihexahedron": 1}[name]
    for f in faces3:  # every edge 1, the hexagons / squares through the centre
        c, ax = plane_frame(v3[f])
        assert np.allclose(np.linalg.norm(np.diff(v3[f + f[:1]], axis=0), axis=1), np.sqrt(2))
        assert (abs(c @ np.cross(*ax)) < 1e-12) == (len(f) > 3)
    assert all(n == 2 for n in collections.Counter(
        tuple(sorted((f[i], f[(i + 1) % len(f)]))) for f in faces3 for i in range(len(f))).values())


def test_hemi_prisms_load_with_no_volume_and_say_why(hemi):
    name, v3, faces3, why, _, p = hemi
    assert p.volume_defined is False and p.why_no_volume == why
    assert p.convex is False and p.self_intersecting is True
    assert p.star.hemi_cells.tolist() == [True, True] + [False] * len(faces3)  # the two caps
    assert p.star.orientable == (why != "not orientable")
    q = Polytope.from_off(p.to_off())  # the 4OFF round trip loads the same
    assert q.why_no_volume == why and q.counts == p.counts
    assert np.isfinite(p.cell_normals).all() and np.allclose(np.linalg.norm(p.cell_normals, axis=1), 1)


def test_a_convex_polychoron_has_a_volume():
    from rot4d_widget import polytope

    p = polytope("24-cell")
    assert p.volume_defined is True and p.why_no_volume is None
    assert slice_polytope(p, np.eye(4), 0.3).volume > 0


@pytest.mark.parametrize("c0", [0.2, 0.5, 0.8])
def test_a_straight_cut_is_the_hemi_polyhedron(hemi, c0):
    """Between the caps, w = c0 crosses each side prism over a face in that face: the slice's points
    are the polyhedron's vertices, its segments its edges, its polygons its faces."""
    _, v3, faces3, _, _, p = hemi
    s = slice_polytope(p, np.eye(4), c0)
    assert s.volume is None and s.dim == 3 and "volume=none" in repr(s)
    v = np.asarray(s.vertices)
    assert s.n_fill == 0 and same_points(v, v3)
    near = np.argmin(np.linalg.norm(v[:, None] - v3[None], axis=2), axis=1)  # slice point -> polyhedron vertex
    assert {tuple(sorted(near[e])) for e in s.edges} == edges3(faces3) and len(s.edges) == len(edges3(faces3))
    assert sorted(sorted(near[q]) for q in s.polygons) == sorted(sorted(f) for f in faces3)
    area = 0.5 * np.linalg.norm(np.cross(v[s.triangles[:, 1]] - v[s.triangles[:, 0]],
                                         v[s.triangles[:, 2]] - v[s.triangles[:, 0]]), axis=1).sum()
    faces_area = sum(abs(shoelace((v3[f] - plane_frame(v3[f])[0]) @ plane_frame(v3[f])[1].T)) for f in faces3)
    assert area == pytest.approx(faces_area, rel=1e-12)


def polygon_edges_even(s) -> bool:
    count = collections.Counter()
    for q in s.polygons:
        count.update(tuple(sorted(e)) for e in zip(q, np.roll(q, -1)))
    return all(n % 2 == 0 for n in count.values())


@pytest.mark.parametrize("seed", [3, 8])
def test_an_oblique_cut_through_a_cap_is_each_cells_parity_region(hemi, seed):
    """Turned, the hyperplane cuts the hemi caps too: the slice's points are the edges' crossings,
    its polygons close up (each edge in an even number), and every crossing cell's drawn triangles
    (not overlapping) cover exactly the points of its section inside the cell by ray parity
    against the cell's own faces, within its hyperplane."""
    _, _, _, _, _, p = hemi
    m = random_rotation(seed)
    x = np.asarray(p.vertices) @ m.T
    rng = np.random.default_rng(seed)
    caps_cut = 0
    for c0 in np.quantile(x[:, 3], [0.15, 0.35, 0.5, 0.7, 0.9]):
        s = slice_polytope(p, m, c0)
        assert s.volume is None
        v = np.asarray(s.vertices)
        assert same_points(v[: len(v) - s.n_fill], edge_crossings(p, m, c0))
        assert polygon_edges_even(s)
        caps_cut += int(np.isin(s.triangle_cells, [0, 1]).any())
        for cell in np.unique(s.triangle_cells):
            faces = [x[p.faces[f]] for f in p.cells[cell]]
            tri = v[s.triangles[s.triangle_cells == cell]]
            c, ax = plane_frame(tri.reshape(-1, 3))
            sample = rng.uniform(*(np.stack([((tri.reshape(-1, 3) - c) @ ax.T).min(axis=0) - 0.2,
                                             ((tri.reshape(-1, 3) - c) @ ax.T).max(axis=0) + 0.2])), size=(120, 2))
            T2 = (tri - c) @ ax.T
            drawn = np.zeros(len(sample), dtype=int)
            for A, B, C in T2:
                d = [(Q[0] - P[0]) * (sample[:, 1] - P[1]) - (Q[1] - P[1]) * (sample[:, 0] - P[0])
                     for P, Q in ((A, B), (B, C), (C, A))]
                drawn += ((d[0] > 0) & (d[1] > 0) & (d[2] > 0)) | ((d[0] < 0) & (d[1] < 0) & (d[2] < 0))
            assert drawn.max() <= 1  # the fill's triangles do not overlap
            allf = np.concatenate(faces)
            c4 = allf.mean(axis=0)
            ax4 = np.linalg.svd(allf - c4)[2][:3]  # the cell's hyperplane
            faces3 = [(f - c4) @ ax4.T for f in faces]
            direction = rng.normal(size=3)
            direction /= np.linalg.norm(direction)
            inside = [parity_in_faces((np.append(q, c0) - c4) @ ax4.T, faces3, direction) for q in c + sample @ ax]
            assert drawn.tolist() == inside, f"cell {cell} at c0 = {c0:.3g}"
    assert caps_cut >= 2  # the hemi caps' sections were among those checked


def test_no_volume_reads_none_everywhere(hemi, tmp_path):
    """A readout says "none" and why; a stack's volumes are None and its readout says why; a mesh
    export's metadata has volume None; a static figure draws."""
    _, _, _, why, _, p = hemi
    m = random_rotation(5)
    d = PolytopeSource(p).slice(m, 0.3)
    assert d.volume is None and ("volume", f"none ({why})") in d.readout
    assert not any("None" in str(v) for _, v in d.readout)
    for n in (1, 3, 20):
        data = StackSource(p, slices=n, spacing=0.2).slice(m, 0.3)
        assert data.volume is None and all(v is None for v in data.volumes)
        assert ("volume", f"none ({why})") in data.readout
        assert not any("None" in str(v) for _, v in data.readout)
    from rot4d_widget.keep.meshes import slice_mesh

    pytest.importorskip("trimesh")
    for data in (d, slice_polytope(p, m, 0.3), StackSource(p, slices=3, spacing=0.2).slice(m, 0.3)):
        mesh = slice_mesh(data)
        assert mesh.metadata["rot4d_widget"]["volume"] is None and len(mesh.faces) > 0
        mesh.export(tmp_path / "hemi.ply")


@pytest.mark.usefixtures("recording_comms")
def test_the_widget_says_none_and_keeps_the_polytope(hemi, make, clock, tmp_path):
    _, _, _, why, _, p = hemi
    w = make(p, c0=0.3)
    w.press("4")
    assert w.slice.volume is None
    html = w.readout.value
    assert f"none ({why})" in html and "None" not in html
    fig = w.render(size=(200, 200))
    assert fig is not None
    w.save_state(tmp_path / "hemi.json")
    w2 = type(w).from_state(tmp_path / "hemi.json", _clock=clock, _autotick=False)
    try:
        assert w2.source.polytope.why_no_volume == why and w2.slice.volume is None
    finally:
        w2.close()


def test_broken_hemi_meshes_are_still_refused():
    v3, faces3 = tetrahemihexahedron()
    v, f, c = prism_mesh(v3, faces3)
    k = len(faces3)
    # an open cell: the caps swap a triangle (every face still in two cells)
    c_open = [list(x) for x in c]
    c_open[0][0], c_open[1][0] = k, 0
    with pytest.raises(MeshError, match=r"cell 0 is not closed: its edge \(\d+, \d+\) is in 1 of its faces"):
        Polytope(v, f, c_open)
    # an edge in three faces of a cell: a triangle of the octahedron's other four added to both caps
    other = [cycle(v3, np.flatnonzero(v3 @ np.array(s) > 0)) for s in itertools.product((-1, 1), repeat=3)
             if np.prod(s) < 0][0]
    f3 = f + [other]
    c3 = [list(x) for x in c]
    c3[0].append(len(f))
    c3[1].append(len(f))
    with pytest.raises(MeshError, match=r"cell 0 is not closed: its edge \(\d+, \d+\) is in 3 of its faces"):
        Polytope(v, f3, c3)
    # a face in three cells
    c_three = [list(x) for x in c] + [[0, 1, 2, 3]]
    with pytest.raises(MeshError, match=r"face 0 is in 3 cell\(s\)"):
        Polytope(v, f, c_three)
