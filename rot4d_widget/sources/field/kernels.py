"""The resampling kernels of a `Field4D` step: quadrilinear interpolation compiled by numba.

`resample_affine` fills f (the field) and g (the signed in-slice distance to the box's faces) on
an affine grid of index coordinates, `resample_points` interpolates at a list of index points.
Both run numba kernels (parallel from `PARALLEL_MIN_POINTS` points on) and fall back to scipy's
``map_coordinates`` (order 1, the same numbers) without numba.

numba is imported and the kernels compiled (or loaded from its cache) at the first step, not when
the package is imported (numba's import alone is ~0.2 s).  Each kernel is compiled with
``cache=True``: numba keeps the machine code in ``__pycache__`` beside this file, or, when that
folder cannot be written (a package installed read-only), in the user's cache folder
(``~/.cache/numba``, or ``$NUMBA_CACHE_DIR``), so a new kernel loads it in a fraction of a second.
The serial and the parallel kernel are separate Python functions: numba's cache keys an entry by
the function and its signature, not by ``parallel``, so one function jitted both ways loaded
whichever was cached first for both (measured: the parallel dispatcher hit the serial entry).
"""

from __future__ import annotations

import threading

import numpy as np

__all__ = ["PARALLEL_MIN_POINTS"]

_numba = None  # the numba module once the kernels are made (`_get_kernels`); False: not installed
_prange = range  # numba.prange once imported (read by the parallel kernels when they compile)

#: Grids with fewer points run the serial kernel: waking a second thread costs a
#: scheduler time slice (several ms) when the other core is busy, more than the work.
PARALLEL_MIN_POINTS = 150_000

_kernels = {}
_kernel_lock = threading.Lock()


def _import_numba():
    """numba, imported once (None when it is not installed: scipy stands in)."""
    global _numba, _prange, _lerp4_jit, _affine_rows_jit
    if _numba is None:
        with _kernel_lock:
            if _numba is None:
                try:  # numba's import (~0.2 s) waits for the first step, not the package's import
                    import numba
                except ImportError:  # pragma: no cover - numba is optional: scipy stands in without it
                    _numba = False
                    return None
                # the kernels call the inner functions compiled (inlined into each kernel)
                _lerp4_jit = numba.njit(cache=True, inline="always")(_lerp4)
                _affine_rows_jit = numba.njit(cache=True, inline="always")(_affine_rows)
                _prange = numba.prange
                _numba = numba
    return _numba or None


def _get_kernels(parallel: bool = True):
    """(affine, points) numba kernels, serial or parallel, compiled (or loaded from numba's cache)
    on first call; None without numba."""
    numba = _import_numba()
    if numba is None:
        return None  # pragma: no cover
    k = _kernels.get(parallel)
    if k is None:
        with _kernel_lock:
            k = _kernels.get(parallel)
            if k is None:
                jit = numba.njit(parallel=parallel, cache=True, nogil=True)
                k = _kernels[parallel] = ((jit(_affine_parallel), jit(_points_parallel)) if parallel
                                          else (jit(_affine_serial), jit(_points_serial)))
    return k


def _lerp4(a, x0, x1, x2, x3):  # pragma: no cover - compiled by numba
    """Quadrilinear interpolation of the 4-D array ``a`` at index (x0, x1, x2, x3), clamped into it."""
    n0, n1, n2, n3 = a.shape
    x0 = min(max(x0, 0.0), n0 - 1.0)
    x1 = min(max(x1, 0.0), n1 - 1.0)
    x2 = min(max(x2, 0.0), n2 - 1.0)
    x3 = min(max(x3, 0.0), n3 - 1.0)
    i0 = min(int(x0), n0 - 2)
    i1 = min(int(x1), n1 - 2)
    i2 = min(int(x2), n2 - 2)
    i3 = min(int(x3), n3 - 2)
    t0 = x0 - i0
    t1 = x1 - i1
    t2 = x2 - i2
    t3 = x3 - i3
    acc = 0.0
    for d0 in range(2):
        w0 = t0 if d0 else 1.0 - t0
        for d1 in range(2):
            w01 = w0 * (t1 if d1 else 1.0 - t1)
            for d2 in range(2):
                w012 = w01 * (t2 if d2 else 1.0 - t2)
                acc += w012 * (1.0 - t3) * a[i0 + d0, i1 + d1, i2 + d2, i3]
                acc += w012 * t3 * a[i0 + d0, i1 + d1, i2 + d2, i3 + 1]
    return acc


def _affine_serial(a, base, step, n, centre, halfn, inv_s, f_out, g_out):  # pragma: no cover - numba
    """f and the box distance g on the affine grid ``base + i step[0] + j step[1] + k step[2]``.

    a : 4-D array (a block of the data, native axis order); base (4,), step (3, 4):
    index coordinates in ``a``; centre, halfn (4,): the data box's centre and half
    size in the same index coordinates; inv_s (4,): in-slice distance per index step
    across each face.  g = min_d (halfn_d - |x_d - centre_d|) inv_s_d (slice units,
    > 0 inside; see `_in_slice_distance`).
    Points outside the box are not interpolated (f = 0 there).
    """
    for i in range(n[0]):
        _affine_rows_jit(a, base, step, n, centre, halfn, inv_s, f_out, g_out, i)


def _affine_parallel(a, base, step, n, centre, halfn, inv_s, f_out, g_out):  # pragma: no cover - numba
    """`_affine_serial` with the grid's first axis shared among threads."""
    for i in _prange(n[0]):
        _affine_rows_jit(a, base, step, n, centre, halfn, inv_s, f_out, g_out, i)


def _affine_rows(a, base, step, n, centre, halfn, inv_s, f_out, g_out, i):  # pragma: no cover - numba
    """Row ``i`` of `_affine_serial`'s grid."""
    n1, n2 = n[1], n[2]
    for j in range(n1):
        b0 = base[0] + i * step[0, 0] + j * step[1, 0]
        b1 = base[1] + i * step[0, 1] + j * step[1, 1]
        b2 = base[2] + i * step[0, 2] + j * step[1, 2]
        b3 = base[3] + i * step[0, 3] + j * step[1, 3]
        for k in range(n2):
            x0 = b0 + k * step[2, 0]
            x1 = b1 + k * step[2, 1]
            x2 = b2 + k * step[2, 2]
            x3 = b3 + k * step[2, 3]
            g = (halfn[0] - abs(x0 - centre[0])) * inv_s[0]
            g = min(g, (halfn[1] - abs(x1 - centre[1])) * inv_s[1])
            g = min(g, (halfn[2] - abs(x2 - centre[2])) * inv_s[2])
            g = min(g, (halfn[3] - abs(x3 - centre[3])) * inv_s[3])
            g_out[i, j, k] = g
            if g < 0.0:
                f_out[i, j, k] = 0.0
            else:
                f_out[i, j, k] = _lerp4_jit(a, x0, x1, x2, x3)


def _points_serial(a, idx, inside, out):  # pragma: no cover - numba
    """Quadrilinear values of ``a`` at the rows of ``idx`` (N, 4) where ``inside``; 0 elsewhere."""
    for p in range(idx.shape[0]):
        if inside[p]:
            out[p] = _lerp4_jit(a, idx[p, 0], idx[p, 1], idx[p, 2], idx[p, 3])
        else:
            out[p] = 0.0


def _points_parallel(a, idx, inside, out):  # pragma: no cover - numba
    """`_points_serial` with the points shared among threads."""
    for p in _prange(idx.shape[0]):
        if inside[p]:
            out[p] = _lerp4_jit(a, idx[p, 0], idx[p, 1], idx[p, 2], idx[p, 3])
        else:
            out[p] = 0.0


# the compiled inner functions once numba is imported (`_import_numba`)
_lerp4_jit = _lerp4
_affine_rows_jit = _affine_rows


def resample_affine(a, base, step, n, centre, halfn, inv_s):
    """(f, g) on an affine grid of shape ``n`` in ``a`` (see `_affine_kernel`); float64."""
    n = tuple(int(v) for v in n)
    f = np.empty(n, dtype=np.float64)
    g = np.empty(n, dtype=np.float64)
    k = _get_kernels(f.size >= PARALLEL_MIN_POINTS)
    args = [np.ascontiguousarray(v, dtype=np.float64) for v in (base, step, centre, halfn, inv_s)]
    if k is not None:
        k[0](a, args[0], args[1], np.array(n, dtype=np.int64), args[2], args[3], args[4], f, g)
        return f, g
    # pragma: no cover - without numba: the same numbers through scipy
    from scipy.ndimage import map_coordinates

    ijk = np.indices(n, dtype=np.float64).reshape(3, -1)
    x = args[0][:, None] + args[1].T @ ijk  # (4, N)
    g[...] = ((args[3][:, None] - np.abs(x - args[2][:, None])) * args[4][:, None]).min(axis=0).reshape(n)
    f[...] = map_coordinates(a, x, order=1, prefilter=False, mode="nearest").reshape(n)
    f[g < 0] = 0.0
    return f, g


def resample_points(a, idx, inside):
    """Quadrilinear values at (N, 4) index coordinates where ``inside``; float64 (N,)."""
    out = np.empty(len(idx), dtype=np.float64)
    k = _get_kernels(len(idx) >= PARALLEL_MIN_POINTS)
    if k is not None:
        k[1](a, np.ascontiguousarray(idx, dtype=np.float64), np.ascontiguousarray(inside), out)
        return out
    from scipy.ndimage import map_coordinates  # pragma: no cover

    out[...] = map_coordinates(a, idx.T, order=1, prefilter=False, mode="nearest")  # pragma: no cover
    out[~inside] = 0.0  # pragma: no cover
    return out  # pragma: no cover
