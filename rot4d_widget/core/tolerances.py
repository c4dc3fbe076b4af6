"""The package's tolerances, by name: one place to read (and to change) how close is close enough.

Use the module as the tolerance object (like trimesh's ``constants.tol``)::

    from ..core import tolerances as tol
    on = np.abs(h) <= tol.ON_HYPERPLANE * radius

Each constant says what it is relative to.  The older names stay where they were
(`rot4d_widget.geometry.slicing.polytope_slice.TOLERANCE`, `rot4d_widget.core.rotation.ORTHOGONALITY_TOLERANCE`,
`rot4d_widget.geometry.mesh.MESH_TOLERANCE`) and are these same numbers.

>>> ON_HYPERPLANE, ORTHOGONALITY, MESH
(1e-09, 1e-06, 1e-06)
"""

from __future__ import annotations

__all__ = [
    "ON_HYPERPLANE", "ORTHOGONALITY", "ORTHOGONAL_TO_ROUNDING", "MESH", "HULL", "HULL_DECIMALS",
    "HULL_INCIDENCE", "COINCIDENT", "NUDGE", "NOISE", "PARALLEL", "TINY",
]

#: A vertex is on the slicing hyperplane w = c0 when ``|w - c0| <= ON_HYPERPLANE * circumradius``:
#: the slicer's one tolerance (``polytope_slice.TOLERANCE``).
ON_HYPERPLANE = 1e-9

#: How far from orthogonal a user's rotation matrix may be (max ``|M M^T - I|``); within it a
#: stored orientation is re-orthonormalised (``rotation.ORTHOGONALITY_TOLERANCE``).
ORTHOGONALITY = 1e-6

#: A loaded orientation this close to orthogonal (max ``|M M^T - I|``) is taken as it is.
ORTHOGONAL_TO_ROUNDING = 1e-14

#: A mesh's geometric checks (planar faces, flat and convex cells, distinct vertices): this times
#: the largest extent of its vertices' bounding box.  Looser than `ON_HYPERPLANE` so that
#: coordinates written with 7 significant digits pass (``polytopes.MESH_TOLERANCE``).
MESH = 1e-6

#: A vertex lies in a hull facet's hyperplane within ``HULL * 10`` times the largest |coordinate|.
HULL = 1e-9

#: Hull facets (unit normal, offset) rounded to this many decimals are one hyperplane (qhull's
#: coplanar simplices merged into one cell or face).
HULL_DECIMALS = 7

#: A point of a small hull (a snub polyhedron, the 96- and 100-vertex polychora, edge 2) lies in a
#: facet within this distance (absolute).
HULL_INCIDENCE = 1e-8

#: In an exact construction of edge 2 (the 600-cell's vertices cut into the grand antiprism), points
#: closer than this (absolute) are one, and a distance below it is zero.
COINCIDENT = 1e-9

#: Where a face is almost parallel to the hyperplane and neither the tolerance nor the exact sign
#: classifies it consistently, the hyperplane is moved by this times the circumradius.
NUDGE = 1e-7

#: A number shown to people is 0 when below this times the scale it is read against.
NOISE = 1e-9

#: A ray whose direction has a component below this (unit vectors) is parallel to a hyperplane.
PARALLEL = 1e-12

#: Divisors are kept above this (a guard against division by zero, far below any length used).
TINY = 1e-300
