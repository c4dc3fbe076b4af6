"""The ray caster of `rot4d_widget.keep.pictures.ray_caster` compiled by numba: one loop per ray instead of numpy
passes over every ray at once (issue 37: an animation's ray-cast frames, one ray per pixel).

`cast` computes what `ray_caster._cast` computes -- the same rays through the same pixel centres, the
same box entry, the same samples at the middle of each piece of a ray, the same trilinear values and
cell rule, the same colour lookup (matplotlib's: entry ``int(x N)``, the top end in the last entry) --
ray by ray: a volume ray stops compositing as soon as its transparency is at most ``opaque`` (numpy's
version checks that once per batch of samples, so the two differ by less than that in a colour), and
sums and products are rounded in another order (within 1e-12 of each other otherwise).  The rows of
the picture are shared out over the cores (``prange``).

numba is imported and the kernel compiled (or loaded from its cache: ``cache=True``, in
``__pycache__`` beside this file or the user's cache folder) at the first ray-cast picture, not when
the package is imported; without numba `cast` returns None and `volume` casts in numpy.
`benchmarks/animation.py --cases flame` measures it.
"""

from __future__ import annotations

import math
import threading

import numpy as np

__all__ = ["cast", "MODES"]

#: The renderings the kernel casts, by the number it takes.
MODES = {"mip": 0, "volume": 1, "sections": 2}

_kernel = None  # the compiled kernel once made; False: numba is not installed
_lock = threading.Lock()
_prange = range


def _get_kernel():
    global _kernel, _prange
    if _kernel is None:
        with _lock:
            if _kernel is None:
                try:  # numba's import (~0.2 s) waits for the first ray-cast picture
                    import numba
                except ImportError:  # pragma: no cover - numba is optional: numpy casts without it
                    _kernel = False
                    return None
                _prange = numba.prange
                jit = numba.njit(cache=True, nogil=True, inline="always")
                global _trilinear_jit, _lookup_jit
                _trilinear_jit = jit(_trilinear)
                _lookup_jit = jit(_lookup)
                _kernel = numba.njit(parallel=True, cache=True, nogil=True)(_cast_rows)
    return _kernel or None


def _trilinear(vals, nx, ny, nz, x, y, z):  # pragma: no cover - compiled by numba
    """(value, cell) as `ray_caster._trilinear`: the trilinear interpolant of the flat C-ordered ``vals``
    at index (x, y, z), each within [0, n - 1], and the flat index of its cell's lowest corner."""
    ix = min(int(x), nx - 2)
    iy = min(int(y), ny - 2)
    iz = min(int(z), nz - 2)
    fx, fy, fz = x - ix, y - iy, z - iz
    cell = (ix * ny + iy) * nz + iz
    sx, sy = ny * nz, nz
    lo = vals[cell]
    c0 = lo + (vals[cell + 1] - lo) * fz
    lo = vals[cell + sy]
    c0 += (lo + (vals[cell + sy + 1] - lo) * fz - c0) * fy
    lo = vals[cell + sx]
    c1 = lo + (vals[cell + sx + 1] - lo) * fz
    lo = vals[cell + sx + sy]
    c1 += (lo + (vals[cell + sx + sy + 1] - lo) * fz - c1) * fy
    c0 += (c1 - c0) * fx
    return c0, cell


def _lookup(lut, x):  # pragma: no cover - compiled by numba
    """The colour-table entry of x in [0, 1], as matplotlib's colour maps read a float."""
    n = lut.shape[0]
    k = x * n
    if k == n:
        k = n - 1.0
    return min(max(int(k), 0), n - 1)


def _cast_rows(vals, cells, shape, view, rot, box, grid, mode, lut, clim, optics, planes, row0, row1,
               out):  # pragma: no cover - compiled by numba
    """Rows ``row0`` ... ``row1 - 1`` of the picture ``out`` (H, W, 4), straight RGBA.

    ``view`` = (x0, x1, y0, y1, distance): the picture plane's limits and the eye's distance;
    ``rot`` (3, 3) the camera's rotation (a ray's direction in the scene is ``rot.T @ d``);
    ``box`` (6,) the grid's box in scene units (lo, hi); ``grid`` (6,) the eye in grid indices
    (a0) and scene units per spacing, then step (scene units per sample) and the slack at the
    box's faces; ``optics`` = (extinction per scene unit at ramp 1, opaque); ``planes`` (3,) the
    sections' planes in grid indices."""
    h_px, w_px = out.shape[0], out.shape[1]
    nx, ny, nz = shape[0], shape[1], shape[2]
    x0, x1, y0, y1, dist = view[0], view[1], view[2], view[3], view[4]
    unit, dt, slack = grid[3], grid[4], grid[5]
    lo_c, hi_c = clim[0], clim[1]
    extinction, opaque = optics[0], optics[1]
    for r in _prange(row0, row1):
        Y = y1 - (r + 0.5) * ((y1 - y0) / h_px)
        for c in range(w_px):
            X = x0 + (c + 0.5) * ((x1 - x0) / w_px)
            norm = math.sqrt(X * X + Y * Y + dist * dist)
            v0, v1, v2 = X / norm, Y / norm, -dist / norm
            d0 = rot[0, 0] * v0 + rot[1, 0] * v1 + rot[2, 0] * v2
            d1 = rot[0, 1] * v0 + rot[1, 1] * v1 + rot[2, 1] * v2
            d2 = rot[0, 2] * v0 + rot[1, 2] * v1 + rot[2, 2] * v2
            dirs = (d0, d1, d2)
            eye = (rot[2, 0] * dist, rot[2, 1] * dist, rot[2, 2] * dist)
            t_in, t_out = -np.inf, np.inf
            for a in range(3):
                if dirs[a] == 0.0:
                    if not (box[a] <= eye[a] <= box[3 + a]):
                        t_in, t_out = np.inf, -np.inf
                    continue
                inv = 1.0 / dirs[a]
                t1, t2 = (box[a] - eye[a]) * inv, (box[3 + a] - eye[a]) * inv
                t_in = max(t_in, min(t1, t2))
                t_out = min(t_out, max(t1, t2))
            t_in = max(t_in, 0.0)
            if not t_out > t_in:
                continue
            b0, b1, b2 = d0 / unit, d1 / unit, d2 / unit
            a0, a1, a2 = grid[0], grid[1], grid[2]
            if mode == 2:  # sections: the nearest plane crossing in a cell of eight finite nodes
                best_t, best_v = np.inf, np.nan
                bs = (b0, b1, b2)
                aa = (a0, a1, a2)
                for a in range(3):
                    if bs[a] == 0.0:
                        continue
                    t = (planes[a] - aa[a]) / bs[a]
                    if not (t >= t_in - slack and t <= t_out + slack and t < best_t):
                        continue
                    px = planes[0] if a == 0 else min(max(a0 + t * b0, 0.0), nx - 1.0)
                    py = planes[1] if a == 1 else min(max(a1 + t * b1, 0.0), ny - 1.0)
                    pz = planes[2] if a == 2 else min(max(a2 + t * b2, 0.0), nz - 1.0)
                    v, cell = _trilinear_jit(vals, nx, ny, nz, px, py, pz)
                    if cells[cell]:
                        best_t, best_v = t, v
                if best_t < np.inf:
                    k = _lookup_jit(lut, min(max((best_v - lo_c) / (hi_c - lo_c), 0.0), 1.0))
                    out[r, c, 0], out[r, c, 1], out[r, c, 2] = lut[k, 0], lut[k, 1], lut[k, 2]
                    out[r, c, 3] = 1.0
                continue
            best = -np.inf
            cr, cg, cb, trans = 0.0, 0.0, 0.0, 1.0
            k = 0
            while True:
                start = t_in + k * dt
                piece = min(max(t_out - start, 0.0), dt)
                if piece <= 0.0:
                    break
                k += 1
                t_mid = start + 0.5 * piece
                v, cell = _trilinear_jit(vals, nx, ny, nz, min(max(a0 + t_mid * b0, 0.0), nx - 1.0),
                                         min(max(a1 + t_mid * b1, 0.0), ny - 1.0),
                                         min(max(a2 + t_mid * b2, 0.0), nz - 1.0))
                if not cells[cell]:
                    continue
                if mode == 0:
                    best = max(best, v)
                    continue
                x = min(max((v - lo_c) / (hi_c - lo_c), 0.0), 1.0)
                alpha = -math.expm1(-extinction * x * piece)
                e = _lookup_jit(lut, x)
                w = trans * alpha
                cr += w * lut[e, 0]
                cg += w * lut[e, 1]
                cb += w * lut[e, 2]
                trans *= 1.0 - alpha
                if trans <= opaque:
                    break
            if mode == 0:
                if best > -np.inf:
                    e = _lookup_jit(lut, min(max((best - lo_c) / (hi_c - lo_c), 0.0), 1.0))
                    out[r, c, 0], out[r, c, 1], out[r, c, 2] = lut[e, 0], lut[e, 1], lut[e, 2]
                    out[r, c, 3] = 1.0
            else:
                a = 1.0 - trans
                if a > 0.0:
                    out[r, c, 0] = min(max(cr / a, 0.0), 1.0)
                    out[r, c, 1] = min(max(cg / a, 0.0), 1.0)
                    out[r, c, 2] = min(max(cb / a, 0.0), 1.0)
                out[r, c, 3] = min(max(a, 0.0), 1.0)


#: Rows cast per call of the kernel (the progress callback is called between calls).
_BAND = 64


def cast(grid, rendering, colormap, clim, size, limits, scale, shift, distance, density, step, fractions,
         tick=lambda f: None, view=None, *, cells, opaque):
    """`ray_caster._cast`'s picture (H, W, 4) straight RGBA float64 from the compiled kernel, or None
    without numba (the caller casts in numpy); ``view`` the camera's rotation (None: identity);
    ``cells`` (nx, ny, nz) bool the cells of eight finite nodes and ``opaque`` the transparency at
    which a volume ray stops -- `volume`'s rule, handed in."""
    kernel = _get_kernel()
    if kernel is None:  # pragma: no cover - numba is optional
        return None
    vals = np.asarray(grid.values)
    shape = np.asarray(vals.shape, dtype=np.int64)
    spacing = float(grid.spacing)
    w_px, h_px = (int(v) for v in size)
    out = np.zeros((h_px, w_px, 4))
    flat = np.ascontiguousarray(np.where(np.isfinite(vals), vals, 0.0), dtype=np.float64).ravel()
    cells = np.ascontiguousarray(cells, dtype=bool).ravel()
    lo_box = shift + scale * np.asarray(grid.origin, dtype=np.float64)
    hi_box = lo_box + scale * spacing * (shape - 1)
    rot = np.eye(3) if view is None else np.ascontiguousarray(view, dtype=np.float64).reshape(3, 3)
    eye = rot.T @ np.array([0.0, 0.0, float(distance)])
    a0 = ((eye - shift) / scale - np.asarray(grid.origin, dtype=np.float64)) / spacing
    unit = scale * spacing
    (x0, x1), (y0, y1) = limits
    view = np.array([x0, x1, y0, y1, float(distance)], dtype=np.float64)
    box = np.concatenate([lo_box, hi_box]).astype(np.float64)
    gridv = np.array([a0[0], a0[1], a0[2], unit, step * spacing * scale, 1e-6 * unit], dtype=np.float64)
    lut = np.asarray(colormap(np.arange(colormap.N)), dtype=np.float64)
    lo, hi = (float(v) for v in clim)
    optics = np.array([float(density) / (unit * (max(vals.shape) - 1)), float(opaque)], dtype=np.float64)
    planes = (shape - 1).astype(np.float64) * np.asarray(fractions, dtype=np.float64)
    mode = MODES[rendering]
    for r0 in range(0, h_px, _BAND):
        kernel(flat, cells, shape, view, rot, box, gridv, mode, lut, np.array([lo, hi]), optics, planes, r0,
               min(h_px, r0 + _BAND), out)
        tick(min(h_px, r0 + _BAND) / h_px)
    return out
