"""The compiled generic level of the general slicer (``_starcut.c``), through ctypes.

`rot4d_widget.geometry.starslice.slice_star` hands a level here when no vertex lies on H; the
C code cuts it by the numpy slicer's rules in one pass (the numpy slicer stays the reference, and
does every level the C code declines: a tie along a face's line, a failed check, a vertex on H).

The library is built when the package is installed (``hatch_build.py``, with the platform's C
compiler); where there is none, `available` is False and every level goes to numpy (the same
slices, slower).  A library built from another version of ``_starcut.c`` than the one beside it is
not used (a warning says to reinstall).  ``ROT4D_NO_C=1`` in the environment turns it off (for
comparing the two).  Where the machine has two or more cores, a level with many crossing sections
that follows the last level of the same polytope closely (`BATCH_GAP`: a stack, a batch) has some
of their fills done by a second thread (the same slice); ``ROT4D_C_THREADS=1`` keeps it to one.
"""

from __future__ import annotations

import ctypes
import hashlib
import itertools
import os
import pathlib
import threading
import warnings
import weakref

import numpy as np

__all__: list = []

#: what hatch_build.py compiles ``_starcut.c`` to, beside it (one name on every platform: ctypes loads any)
LIBRARY = "_starcut.so"


def _load(here: pathlib.Path | None = None):
    """The library beside this module (or in ``here``), checked against its source; None without."""
    if os.environ.get("ROT4D_NO_C"):
        return None
    here = pathlib.Path(__file__).parent if here is None else pathlib.Path(here)
    path = here / LIBRARY
    if not path.exists():
        return None
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
    #    V  x  c0 tol E  ea eb F  S  fe_face fe_edge fv_vert fv_next basis m  f_cells rho mate C  convex normals
    #    slabs_only threads batch_gap pool out...
    lib.starcut.argtypes = [N, P, D, D, N, P, P, N, N, P, P, P, P, P, P, P, P, P, N, P, P, ctypes.c_int, ctypes.c_int,
                            D, P, P, P, P]
    lib.starcut_pool_new.restype = P
    lib.starcut_pool_new.argtypes = []
    lib.starcut_pool_free.restype = None
    lib.starcut_pool_free.argtypes = [P]
    lib.starcut_take.restype = None
    lib.starcut_take.argtypes = [P] * 8
    return lib


_lib = _load()
#: True when the compiled level is there (the package was built with a C compiler).
available = _lib is not None
#: threads a level may use: 2 on a machine with two or more cores, unless ROT4D_C_THREADS=1
THREADS = 1 if os.environ.get("ROT4D_C_THREADS") == "1" or (os.cpu_count() or 1) < 2 else 2
#: a level takes two threads only if it follows the last of the same polytope within this many
#: seconds (levels in a batch); a key's steps, further apart, stay on one (see _starcut.c)
BATCH_GAP = 0.001


def _ptr(a: np.ndarray) -> int:
    return a.__array_interface__["data"][0]


class CTables:
    """The per-polytope arrays the C level reads (`slicetables._Tables` and `starslice._StarTables`
    as contiguous int64 / float64 / uint8, kept alive here) and their addresses, in the C
    function's order."""

    def __init__(self, p, t, st):
        def ints(a):
            return np.ascontiguousarray(a, dtype=np.int64)

        def floats(a):
            return np.ascontiguousarray(a, dtype=np.float64)

        self.edges_a, self.edges_b = ints(t.ea), ints(t.eb)
        self.fe_face, self.fe_edge = ints(t.fe_face), ints(t.fe_edge)  # face sides, face by face
        self.fv_vert, self.fv_next = ints(t.fv_vert), ints(st.fv_next)
        self.face_basis = floats(st.face_basis).reshape(len(p.face_cells), 8)  # (F, 2, 4) rows
        self.face_cells, self.face_rho = ints(p.face_cells), floats(st.face_rho)
        self.slot_mate = ints(st.slot_mate)
        self.cell_convex = np.ascontiguousarray(st.cell_convex, dtype=np.uint8)
        self.cell_normals = floats(t.cell_normals)
        if not np.all(np.diff(self.fe_face) >= 0):  # pragma: no cover - the incidence keeps faces in order
            raise ValueError("face sides out of face order")
        self.E, self.F = len(self.edges_a), len(self.face_basis)
        self.S, self.C = len(self.fe_face), len(self.cell_convex)
        self.edge_ptrs = [_ptr(a) for a in (self.edges_a, self.edges_b)]
        self.face_ptrs = [_ptr(a) for a in (self.fe_face, self.fe_edge, self.fv_vert, self.fv_next, self.face_basis)]
        self.cell_ptrs = [_ptr(a) for a in (self.face_cells, self.face_rho, self.slot_mate)]
        self.conv_ptrs = [_ptr(a) for a in (self.cell_convex, self.cell_normals)]
        # memory one level leaves for the next (freed with these tables); one level at a time holds it
        self.pool = _lib.starcut_pool_new()
        self.pool_lock = threading.Lock()
        self.threads_used = 0  # how many threads the last level's fills took (for tests and benchmarks)
        weakref.finalize(self, _lib.starcut_pool_free, self.pool)


def cut(ct: CTables, x: np.ndarray, m: np.ndarray, c0: float, tol: float, slabs_only: bool = False,
        threads: int | None = None, batch_gap: float | None = None):
    """The level ``c0`` of the unit vertices ``x`` (V, 4) turned by ``m``: (vertices (n, 3), edges,
    polygon corners, offsets, polygon cells, triangles, triangle cells, volume, n_fill), or None
    when the C code declines it (the numpy slicer then does it).  ``slabs_only``: the slab fill
    takes every section the arrangement fill would (so tests reach it with crossing segments);
    ``threads`` (1 or 2, default `THREADS`), ``batch_gap`` (s, default `BATCH_GAP`): the same
    slice either way."""
    x = np.ascontiguousarray(x, dtype=np.float64)
    m = np.ascontiguousarray(m, dtype=np.float64)
    counts = np.zeros(7, dtype=np.int64)
    vol = ctypes.c_double()
    status = ctypes.c_int()
    pooled = ct.pool_lock.acquire(blocking=False)  # another thread on the same tables: fresh memory
    try:
        return _level(ct, x, m, c0, tol, slabs_only, threads, batch_gap, counts, vol, status,
                      ct.pool if pooled else None)
    finally:
        if pooled:
            ct.pool_lock.release()


def _level(ct, x, m, c0, tol, slabs_only, threads, batch_gap, counts, vol, status, pool):
    threads = THREADS if threads is None else int(threads)
    batch_gap = BATCH_GAP if batch_gap is None else float(batch_gap)
    res = _lib.starcut(len(x), _ptr(x), c0, tol, ct.E, *ct.edge_ptrs, ct.F, ct.S, *ct.face_ptrs, _ptr(m),
                       *ct.cell_ptrs, ct.C, *ct.conv_ptrs, int(slabs_only), threads, batch_gap, pool, _ptr(counts),
                       ctypes.addressof(vol), ctypes.addressof(status))
    if not res:
        return None
    n_pts, n_extra, n_seg, n_flat, n_poly, n_tri, ct.threads_used = counts.tolist()
    verts = np.empty((n_pts + n_extra, 3))
    # the index arrays: one block, locked before its parts are cut from it (so they are handed out
    # read-only without a copy), in the order starcut_take fills them
    sizes = (2 * n_seg, n_flat, n_poly + 1, n_poly, 3 * n_tri, n_tri)
    block = np.empty(sum(sizes), dtype=np.int64)
    at, ptrs = _ptr(block), []
    for n in sizes:
        ptrs.append(at)
        at += 8 * n
    _lib.starcut_take(res, _ptr(verts), *ptrs)
    block.flags.writeable = False
    ends = list(itertools.accumulate(sizes))
    edges = block[:ends[0]].reshape(n_seg, 2)
    flat, offsets, cells = block[ends[0]:ends[1]], block[ends[1]:ends[2]], block[ends[2]:ends[3]]
    tri, tcell = block[ends[3]:ends[4]].reshape(n_tri, 3), block[ends[4]:ends[5]]
    return verts, edges, flat, offsets, cells, tri, tcell, vol.value, n_extra
