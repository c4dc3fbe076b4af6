"""What the page needs to cut a polytope itself: the slicer's own tables, as one flat message.

The page (``page/slicer.js``, ``page/starslicer.js``) slices the polytope of its latest state
without waiting for the kernel, and must get what
`rot4d_widget.geometry.slicing.polytope_slice.slice_polytope` gets, array for array.  So the
message is built from the slicer's own tables (`rot4d_widget.geometry.slicing.tables.tables`,
and `rot4d_widget.geometry.slicing.star.star_tables` for a star polytope) in their unit scale:
the page never recomputes a float the kernel has.  It is sent once per polytope (the sender splits
it into chunks); `polytope_message` lists its names.
"""

from __future__ import annotations

import numpy as np

from ..core import tolerances as tol_
from ..geometry.mesh import Polytope
from ..geometry.slicing.star import star_tables
from ..geometry.slicing.tables import tables

__all__ = ["polytope_message", "polytope_message_bytes"]

#: the largest index an int32 entry can hold
_INT32_MAX = 2**31 - 1


def _f64(a) -> memoryview:
    return memoryview(np.ascontiguousarray(a, dtype="<f8").reshape(-1).tobytes())


def _i32(a, name: str) -> memoryview:
    a = np.asarray(a).reshape(-1)
    if a.size and int(a.max()) > _INT32_MAX:
        raise ValueError(f"Expected `{name}` to fit int32 for the page, got an index {int(a.max())}")
    return memoryview(np.ascontiguousarray(a, dtype="<i4").tobytes())


def _offsets(owner: np.ndarray, n: int) -> np.ndarray:
    """A ragged table's owner of each entry (ascending) -> its (n + 1,) row offsets."""
    ptr = np.zeros(n + 1, dtype=np.intp)
    np.cumsum(np.bincount(owner, minlength=n), out=ptr[1:])
    return ptr


def polytope_message(polytope: Polytope) -> dict:
    """Everything ``page/slicer.js`` (``decodePolytope``, ``slicePolytope``) needs to cut
    ``polytope`` as `slice_polytope` does.

    A flat dict: scalars as JSON numbers and flags, arrays as little-endian bytes (memoryview; int32
    for indices, float64 for coordinates), each named below with its length:

    ========================  =======  ===========================================================
    name                      type     what
    ========================  =======  ===========================================================
    vertices                  f64 4V   the unit vertices, row by row
    edges                     i32 2E   each edge's two vertices
    face_ptr                  i32 F+1  where each face's corners start in ``face_vidx``
    face_vidx, face_eidx      i32 ΣF   each face's corners in cycle order; the edge from each corner
                                       to the next
    cell_vptr, cell_vidx      i32      each cell's vertices, ascending (offsets C+1, entries)
    cell_eptr, cell_eidx      i32      each cell's edges, ascending (offsets C+1, entries)
    face_cells                i32 2F   each face's two cells, ascending
    cell_normals              f64 4C   each cell's outward unit normal
    cell_centres              f64 4C   each cell's vertex mean, in the unit scale
    ========================  =======  ===========================================================

    A polytope with star faces or non-convex cells (``star``) adds what the star slicer's points
    and segments need (`rot4d_widget.geometry.slicing.star.star_tables`; ``page/starslicer.js``):

    ========================  =======  ===========================================================
    face_basis                f64 8F   each face's two orthonormal in-plane axes (4 numbers each)
    face_rho                  f64 2F   +-1 per (face, its cell in ``face_cells``): which way the
                                       face's chord runs in that cell's section (for the volume
                                       that picks the side of a cell lying in H)
    slot_mate                 i32 2ΣF  per (face side k, cell j of the face), slot 2k + j: the slot
                                       of the cell's other face at that side's edge, or -1
    ========================  =======  ===========================================================

    and the flag ``volume_defined`` (False: a hemi or non-orientable polytope, its slices' volume None).

    Scalars: ``n_vertices`` V, ``n_edges`` E, ``n_faces`` F, ``n_cells`` C; ``unit`` (the power of
    two), ``tol`` (on H when ``|w - c0| <= tol``, unit scale), ``radius`` (circumradius, unit
    scale), ``nudge`` (how far the slicer's fallbacks move H, unit scale); ``convex``, ``star``
    (star faces or non-convex cells: the page draws only their points and segments) and ``n_groups``
    (the source's colour groups, its cells); ``name``.
    """
    t = tables(polytope)
    msg = {
        "name": polytope.name,
        "n_vertices": int(t.V), "n_edges": int(len(t.ea)), "n_faces": int(t.F), "n_cells": int(t.C),
        "unit": float(t.unit), "tol": float(t.tol), "radius": float(t.radius),
        "nudge": float(tol_.NUDGE * t.radius),  # the very product slice_level adds to c0
        "convex": bool(polytope.convex), "star": polytope.star is not None,
        "n_groups": max(1, int(t.C)),
        "vertices": _f64(t.vertices),
        "edges": _i32(np.stack([t.ea, t.eb], axis=1), "edges"),
        "face_ptr": _i32(_offsets(t.fv_face, t.F), "face_ptr"),
        "face_vidx": _i32(t.fv_vert, "face_vidx"),
        "face_eidx": _i32(t.fe_edge, "face_eidx"),
        "cell_vptr": _i32(_offsets(t.cv_cell, t.C), "cell_vptr"),
        "cell_vidx": _i32(t.cv_vert, "cell_vidx"),
        "cell_eptr": _i32(_offsets(t.ce_cell, t.C), "cell_eptr"),
        "cell_eidx": _i32(t.ce_edge, "cell_eidx"),
        "face_cells": _i32(t.face_cells, "face_cells"),
        "cell_normals": _f64(t.cell_normals),
        "cell_centres": _f64(t.cell_centres),
    }
    if polytope.star is not None:  # what the star slicer adds, its own tables
        st = star_tables(polytope, t)
        msg.update({"face_basis": _f64(st.face_basis), "face_rho": _f64(st.face_rho),
                    "slot_mate": _i32(st.slot_mate, "slot_mate"),
                    "volume_defined": bool(polytope.volume_defined)})
    return msg


def polytope_message_bytes(msg: dict) -> int:
    """The bytes of a `polytope_message`'s arrays (its scalars aside)."""
    return sum(v.nbytes for v in msg.values() if isinstance(v, memoryview))
