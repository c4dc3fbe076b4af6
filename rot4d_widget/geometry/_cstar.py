"""The compiled generic level of the general slicer (``_starcut.c``), through ctypes.

`rot4d_widget.geometry.starslice.slice_star` hands a level here when no vertex lies on H; the
C code cuts it by the numpy slicer's rules in one pass (the numpy slicer stays the reference, and
does every level the C code declines: a tie along a face's line, a failed check, a vertex on H).

The library is built when the package is installed (``hatch_build.py``, with the platform's C
compiler); where there is none, `available` is False and every level goes to numpy (the same
slices, slower).  A library built from another version of ``_starcut.c`` than the one beside it is
not used (a warning says to reinstall).  ``ROT4D_NO_C=1`` in the environment turns it off (for
comparing the two).
"""

from __future__ import annotations

import ctypes
import hashlib
import os
import pathlib
import warnings

import numpy as np

__all__: list = []

_LIB_NAMES = ("_starcut.so", "_starcut.dylib", "_starcut.dll")


def _load(here: pathlib.Path | None = None):
    """The library beside this module (or in ``here``), checked against its source; None without."""
    if os.environ.get("ROT4D_NO_C"):
        return None
    here = pathlib.Path(__file__).parent if here is None else pathlib.Path(here)
    for name in _LIB_NAMES:
        path = here / name
        if path.exists():
            try:
                lib = ctypes.CDLL(str(path))
            except OSError:  # pragma: no cover - built for another platform
                return None
            lib.starcut_source.restype = ctypes.c_char_p
            src = here / "_starcut.c"
            if src.exists() and lib.starcut_source().decode() != hashlib.sha256(src.read_bytes()).hexdigest():
                warnings.warn(f"{path} was built from another _starcut.c: not used (the numpy slicer does every "
                              "level); reinstall the package (pip install -e .) to build it again", stacklevel=2)
                return None
            P, N, D = ctypes.c_void_p, ctypes.c_int64, ctypes.c_double
            lib.starcut.restype = P
            lib.starcut.argtypes = [N, P, D, D, N, P, P, N, N, P, P, P, P, P, P, P, P, P, N, P, P, P, P, P]
            lib.starcut_take.restype = None
            lib.starcut_take.argtypes = [P] * 8
            return lib
    return None


_lib = _load()
#: True when the compiled level is there (the package was built with a C compiler).
available = _lib is not None


def _ptr(a: np.ndarray) -> int:
    return a.__array_interface__["data"][0]


class CTables:
    """The per-polytope arrays the C level reads, contiguous int64 / float64, and their addresses."""

    def __init__(self, p, t, st):
        i8 = np.int64
        self.keep = [
            np.ascontiguousarray(t.ea, dtype=i8), np.ascontiguousarray(t.eb, dtype=i8),
            np.ascontiguousarray(t.fe_face, dtype=i8), np.ascontiguousarray(t.fe_edge, dtype=i8),
            np.ascontiguousarray(t.fv_vert, dtype=i8), np.ascontiguousarray(st.fv_next, dtype=i8),
            np.ascontiguousarray(st.face_basis, dtype=np.float64).reshape(-1, 8),
            np.ascontiguousarray(p.face_cells, dtype=i8), np.ascontiguousarray(st.face_rho, dtype=np.float64),
            np.ascontiguousarray(st.slot_mate, dtype=i8),
            np.ascontiguousarray(st.cell_convex, dtype=np.uint8),
            np.ascontiguousarray(t.cell_normals, dtype=np.float64),
        ]
        if not np.all(np.diff(self.keep[2]) >= 0):  # pragma: no cover - the incidence keeps faces in order
            raise ValueError("face sides out of face order")
        self.E, self.F, self.S, self.C = len(t.ea), len(self.keep[6]), len(t.fe_face), len(self.keep[10])
        self.args = [_ptr(a) for a in self.keep]


def cut(ct: CTables, x: np.ndarray, m: np.ndarray, c0: float, tol: float):
    """The level ``c0`` of the unit vertices ``x`` (V, 4) turned by ``m``: (vertices (n, 3), edges,
    polygon corners, offsets, polygon cells, triangles, triangle cells, volume, n_fill), or None
    when the C code declines it (the numpy slicer then does it)."""
    x = np.ascontiguousarray(x, dtype=np.float64)
    m = np.ascontiguousarray(m, dtype=np.float64)
    counts = np.zeros(6, dtype=np.int64)
    vol = ctypes.c_double()
    status = ctypes.c_int()
    ea, eb, fe_face, fe_edge, fv_vert, fv_next, fb, fm, fc, fr, sm, cc, cn = (
        ct.args[0], ct.args[1], ct.args[2], ct.args[3], ct.args[4], ct.args[5], ct.args[6], _ptr(m),
        ct.args[7], ct.args[8], ct.args[9], ct.args[10], ct.args[11])
    res = _lib.starcut(len(x), _ptr(x), c0, tol, ct.E, ea, eb, ct.F, ct.S, fe_face, fe_edge, fv_vert, fv_next,
                       fb, fm, fc, fr, sm, ct.C, cc, cn, _ptr(counts), ctypes.addressof(vol),
                       ctypes.addressof(status))
    if not res:
        return None
    n_pts, n_extra, n_seg, n_flat, n_poly, n_tri = (int(c) for c in counts)
    verts = np.empty((n_pts + n_extra, 3))
    edges = np.empty((n_seg, 2), dtype=np.int64)
    flat = np.empty(n_flat, dtype=np.int64)
    offsets = np.empty(n_poly + 1, dtype=np.int64)
    cells = np.empty(n_poly, dtype=np.int64)
    tri = np.empty((n_tri, 3), dtype=np.int64)
    tcell = np.empty(n_tri, dtype=np.int64)
    _lib.starcut_take(res, _ptr(verts), _ptr(edges), _ptr(flat), _ptr(offsets), _ptr(cells), _ptr(tri), _ptr(tcell))
    return verts, edges, flat, offsets, cells, tri, tcell, vol.value, n_extra
