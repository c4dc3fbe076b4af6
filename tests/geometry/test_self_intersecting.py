"""A self-intersecting polytope is not convex (issue 22): the grand 600-cell {3, 3, 5/2}, built by
hand from the 600-cell's vertices (its edges are the chords of length phi on the unit 3-sphere,
its faces the triangles and its cells the tetrahedra of those chords), has convex faces and cells
and is locally convex at every ridge, yet winds round its centre 191 times.  It was reported
``convex=True``, so its slices were drawn and measured as convex solids.

Checked against independent computation: the published counts (120, 720, 1200, 600), and
Cavalieri -- the integral of the slices' volumes over c0 equals the winding-weighted 4-volume,
which the divergence theorem gives in closed form from its 600 regular tetrahedra.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from rot4d_widget import polytope
from rot4d_widget.geometry.mesh import Polytope
from rot4d_widget.geometry.slicing.polytope_slice import slice_polytope
from rot4d_widget.sources.protocol import PolytopeSource

PHI = (1 + math.sqrt(5)) / 2


def grand_600_cell():
    """(vertices, faces, cells) of {3, 3, 5/2} on the unit 3-sphere."""
    p = polytope("600-cell")
    v = np.asarray(p.vertices) / p.circumradius
    d = np.linalg.norm(v[:, None] - v[None], axis=2)
    A = np.isclose(d, PHI, atol=1e-9)
    tri = sorted({tuple(sorted((i, j, k))) for i in range(len(v))
                  for j, k in itertools.combinations(np.flatnonzero(A[i]), 2) if A[j, k]})
    index = {t: n for n, t in enumerate(tri)}
    tets = sorted({tuple(sorted(t + (int(c),))) for t in tri for c in np.flatnonzero(A[t[0]] & A[t[1]] & A[t[2]])})
    cells = [[index[f] for f in itertools.combinations(t, 3)] for t in tets]
    return v, [list(t) for t in tri], cells


@pytest.fixture(scope="module")
def grand():
    v, f, c = grand_600_cell()
    return Polytope(v, f, c, name="grand 600-cell")


def test_counts_and_not_convex(grand):
    assert (len(grand.vertices), len(grand.edges), len(grand.faces), len(grand.cells)) == (120, 720, 1200, 600)
    assert grand.convex is False and grand.self_intersecting is True
    p = polytope("600-cell")
    assert p.convex is True and p.self_intersecting is False
    q = Polytope(p.vertices, [list(f) for f in p.faces], [list(c) for c in p.cells])  # the same, as a mesh
    assert q.convex is True and q.self_intersecting is False


def test_slice_volumes_integrate_to_the_winding_weighted_4_volume(grand):
    e = PHI  # edge of each regular tetrahedron (unit circumradius)
    vol3 = e ** 3 / (6 * math.sqrt(2))
    height = math.sqrt(1 - 3 * e * e / 8)  # distance of a cell's hyperplane from the centre
    vol4 = 600 * vol3 * height / 4  # divergence theorem: (1/4) sum of h_c vol3(c)
    hull4 = 600 * (1 / PHI) ** 3 / (6 * math.sqrt(2)) * math.sqrt(1 - 3 / (8 * PHI * PHI)) / 4  # the 600-cell's
    assert vol4 > 2 * hull4  # not the hull's volume: the boundary winds round the centre many times
    m = np.linalg.qr(np.random.default_rng(5).normal(size=(4, 4)))[0]
    m[:, 0] *= np.sign(np.linalg.det(m))
    lo, hi = -1.0, 1.0
    c0 = np.linspace(lo, hi, 401)
    vols = np.array([slice_polytope(grand, m, c).volume for c in c0])
    integral = float(np.sum((vols[1:] + vols[:-1]) / 2 * np.diff(c0)))
    assert integral == pytest.approx(vol4, rel=0.01)


def test_the_readout_says_so_and_slices_are_not_drawn_as_convex(grand):
    src = PolytopeSource(grand)
    s = src.slice(np.eye(4), 0.1)
    assert s.convex is False
    rows = dict(s.readout)
    assert "winds round" in rows["self-intersecting"]
    assert "self-intersecting" not in dict(PolytopeSource(polytope("600-cell")).slice(np.eye(4), 0.1).readout)
