"""4-polytopes: the `Polytope` class, the six regular polychora and `polytope(name)`, in one place.

This module gathers names that live in smaller modules (it defines nothing itself):

==================================  ============================================================
`rot4d_widget.geometry.mesh`        `Polytope` (vertices and combinatorics, from a hull or a
                                    mesh given whole), `Incidence`, `COORDINATE_RANGE`,
                                    `check_scale`, `order_cycle`, `MESH_TOLERANCE`
`rot4d_widget.geometry.meshcheck`   `MeshError` and the checks of a mesh (planar convex faces,
                                    closed convex cells, orientation)
`rot4d_widget.geometry.regular`     the six regular polychora (`pentachoron`, `POLYTOPE_NAMES`,
                                    their aliases and Schläfli symbols, `PHI`)
`rot4d_widget.geometry.catalogue`   `polytope(name)`: the regular six, the ten regular star
                                    ones (`rot4d_widget.geometry.star_regular`) and every
                                    uniform polychoron (`rot4d_widget.geometry.uniform`) by name
==================================  ============================================================

`polytope(name)` gives the six regular polychora, all with edge length 2 and centred on the
origin (`rot4d_widget.geometry.regular` lists their coordinates), and the uniform ones.

>>> polytope("24-cell").counts
(24, 96, 96, 24)
"""

from __future__ import annotations

from ._ragged import _gather, _owner, _ptr
from .catalogue import polytope
from .mesh import COORDINATE_RANGE, MESH_TOLERANCE, Incidence, Polytope, _power_of_two_unit, check_scale, order_cycle
from .meshcheck import MeshError, _cavities, _check_cells, _check_closed, duplicate_in_rows, index_lists, mesh_geometry
from .regular import (
                   _BUILDERS,
                   _NAME_OF,
                   PHI,
                   POLYTOPE_NAMES,
                   _cell8,
                   _cell16,
                   _cell24,
                   _cell120,
                   _cell600,
                   _even_permutations,
                   _normalise_name,
                   _orbit,
                   _unique_rows,
                   pentachoron,
)
from .regular import ALIASES as _ALIASES
from .regular import named as _named

__all__ = ["Polytope", "MeshError", "polytope", "pentachoron", "POLYTOPE_NAMES", "MESH_TOLERANCE",
           "COORDINATE_RANGE"]

# the names this module had before it was split (importable from it as before)
_index_lists, _duplicate_in_rows, _mesh_geometry = index_lists, duplicate_in_rows, mesh_geometry
_MOVED = (_gather, _owner, _ptr, Incidence, _power_of_two_unit, check_scale, order_cycle, _cavities, _check_cells,
          _check_closed, _BUILDERS, _NAME_OF, PHI, _cell8, _cell16, _cell24, _cell120, _cell600, _even_permutations,
          _normalise_name, _orbit, _unique_rows, _ALIASES, _named)
