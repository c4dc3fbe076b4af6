"""4-D scalar fields as sources: resample on the rotated hyperplane, then isosurfaces.

A `Field4D` holds samples f[x, y, z, w] on the nodes of a regular (or, from
xarray, unevenly spaced) 4-D grid -- a numpy array or memmap, a dask array, a
zarr array -- or a vectorised function f(x, y, z, w).  Each step
(`slice_field`):

1. the data's 4-D box is cut by w = c0 after the rotation (the exact polytope
   slicer on the box, an 8-cell scaled to the extent); c0 is in the data's w
   units (`Field4D.w_frame`): the hyperplane lies d = (c0 - w_centre) / w_per_unit
   slice units from the box's centre along the turned w axis, so that at rest
   c0 = 30 cuts the data at w = 30;
2. a 3-D grid of ``resolution`` samples along the longest side of that cut's
   bounding box (same spacing on all three axes, one sample of padding) is
   pulled back into the data, ``q = matrix.T @ (x, y, z, d) + centre``, and
   the array is interpolated there, multilinearly (order 1, no prefilter),
   by a numba kernel that walks the affine grid (base + i a + j b + k c in
   index space) -- a function is evaluated exactly at those points instead;
3. ``v = min(f - level, K * g)`` with g the signed distance, within the
   slice, to the planes where the box's faces cut it (positive inside; linear
   along a grid line near a face, so the zero of its linear interpolation lies
   ON the face) and K a typical |grad f|; outside the box v is K g alone; NaN
   counts as below every level;
4. scikit-image's marching cubes (Lewiner) at v = 0 for each level, vertices
   mapped from index space to slice coordinates, wound counter-clockwise seen
   from where f < level.

Coordinates.  *Data coordinates* are the field's own (``extent`` or xarray
coordinates).  *Slice coordinates* (what the widget draws) are data
coordinates about the box's centre, with w divided by ``w_per_unit`` (how
much data-w one unit of space is): a data point q is drawn at
``matrix @ (q - centre)`` with its w so scaled.

Chunked data (dask, zarr, anything with ``chunks``): a full-resolution step
reads only the chunks the hyperplane comes within one sample of (the whole
4-D bounding block is never read), into a zero-filled buffer whose untouched
pages are never committed; recently read chunks are kept up to
``chunk_cache_bytes``.  ``field.coarse()`` is an in-memory copy with at most
`COARSE_SAMPLES` nodes per axis over the same box (built once, the only time
every chunk is read) for the held-key steps and for the data range.

Shapes: vertices (n, 3) float64, triangles (k, 3) intp, normals (n, 3)
float64; everything returned is read-only.

Scale: the box's half widths (slice units) and the ends of ``extent`` must lie
in `rot4d_widget.geometry.polytopes.COORDINATE_RANGE` (1e-150 to 1e150; else a
ValueError naming it).  Within it a field scaled by ``s`` (extent times s, the
same samples) slices as the unscaled one at ``c0 / s`` (extent's w scaled too), its surfaces scaled by
s: the box cut is the exact slicer's (normalised), the resampling works in
index units, and marching cubes runs with unit spacing, its vertices, volume
and area scaled afterwards in float64.  Only a volume or area beyond float64
itself becomes inf (or 0); `Field4D.slice` then gives the widget no volume.
"""

from __future__ import annotations

import collections
import itertools
import math
import numbers
import os
import sys
import threading
import warnings
from dataclasses import dataclass

import numpy as np

from ..core._arrays import sealed as _sealed
from ..geometry.polytopes import COORDINATE_RANGE, _power_of_two_unit, check_scale
from ..core.rotation import as_rotation_matrix
from .protocol import SliceData

__all__ = ["Field4D", "FieldSlice", "FieldSliceData", "slice_field", "AxesWarning", "NonFiniteWarning",
           "COARSE_SAMPLES", "MAX_SAMPLE_BYTES"]

#: Nodes per axis, at most, of the in-memory coarse copy (`Field4D.coarse`).
COARSE_SAMPLES = 48
#: A step may hold at most this many bytes of samples (about `BYTES_PER_SAMPLE` per grid point).
MAX_SAMPLE_BYTES = 2 * 1024**3
#: Working bytes per grid point: f and g (float64), v (float32), marching cubes' own.
BYTES_PER_SAMPLE = 24
#: Nodes per axis of the grid a function field is sampled on for its range.
_FUNCTION_PROBE = 21
_AXES = "xyzw"


class AxesWarning(UserWarning):
    """Kept for code that filters it; `Field4D(array)` without ``axes=`` is now a TypeError."""


class NonFiniteWarning(RuntimeWarning):
    """The data hold +inf or -inf samples (reported once per field; NaN is allowed and silent)."""


def _axes_text(axes: str) -> str:
    """'wzyx' -> 'f[w, z, y, x]': which of x, y, z, w each array axis is."""
    return "f[" + ", ".join(axes) + "]"


def _dataset_error(ds) -> TypeError:
    names = [str(k) for k in getattr(ds, "data_vars", {})]
    first = names[0] if names else "name"
    listed = ", ".join(repr(n) for n in names) if names else "none"
    return TypeError(f"Expected an xarray.DataArray (one variable), got an xarray.Dataset with data variables "
                     f"{listed}; pick one: ds[{first!r}]")


# ----------------------------------------------------------------------------- kernels
try:
    import numba as _numba
    from numba import prange as _prange
except ImportError:  # pragma: no cover - numba is a dependency; scipy stands in without it
    _numba = None
    _prange = range

#: Grids with fewer points run the serial kernel: waking a second thread costs a
#: scheduler time slice (several ms) when the other core is busy, more than the work.
PARALLEL_MIN_POINTS = 150_000

_kernels = {}
_kernel_lock = threading.Lock()


def _get_kernels(parallel: bool = True):
    """(affine, points) numba kernels, compiled (or loaded from numba's cache) on first call;
    None without numba."""
    if _numba is None:
        return None  # pragma: no cover
    k = _kernels.get(parallel)
    if k is None:
        with _kernel_lock:
            k = _kernels.get(parallel)
            if k is None:
                jit = _numba.njit(parallel=parallel, cache=True, nogil=True)
                k = _kernels[parallel] = (jit(_affine_kernel), jit(_points_kernel))
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


def _affine_kernel(a, base, step, n, centre, halfn, inv_s, f_out, g_out):  # pragma: no cover - numba
    """f and the box distance g on the affine grid ``base + i step[0] + j step[1] + k step[2]``.

    a : 4-D array (a block of the data, native axis order); base (4,), step (3, 4):
    index coordinates in ``a``; centre, halfn (4,): the data box's centre and half
    size in the same index coordinates; inv_s (4,): in-slice distance per index step
    across each face.  g = min_d (halfn_d - |x_d - centre_d|) inv_s_d (slice units,
    > 0 inside; see `_in_slice_distance`).
    Points outside the box are not interpolated (f = 0 there).
    """
    n0, n1, n2 = n[0], n[1], n[2]
    for i in _prange(n0):
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


def _points_kernel(a, idx, inside, out):  # pragma: no cover - numba
    """Quadrilinear values of ``a`` at the rows of ``idx`` (N, 4) where ``inside``; 0 elsewhere."""
    for p in _prange(idx.shape[0]):
        if inside[p]:
            out[p] = _lerp4_jit(a, idx[p, 0], idx[p, 1], idx[p, 2], idx[p, 3])
        else:
            out[p] = 0.0


# the kernels call the inner function compiled (inlined into each kernel)
_lerp4_jit = _lerp4 if _numba is None else _numba.njit(cache=True, inline="always")(_lerp4)


def _resample_affine(a, base, step, n, centre, halfn, inv_s):
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


def _resample_points(a, idx, inside):
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


# ----------------------------------------------------------------------------- validation
def _real(value, name: str) -> float:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Real, np.integer, np.floating)):
        raise TypeError(f"Expected `{name}` to be a real number, got {type(value).__name__}")
    v = float(value)
    if not math.isfinite(v):
        raise ValueError(f"Expected `{name}` to be finite, got {v}")
    return v


def _as_levels(level) -> tuple:
    """A number or a non-empty sequence of numbers -> tuple of finite floats."""
    if isinstance(level, (numbers.Real, np.integer, np.floating)) and not isinstance(level, (bool, np.bool_)):
        return (_real(level, "level"),)
    try:
        items = list(np.asarray(level, dtype=object).ravel()) if not isinstance(level, (str, bytes)) else None
    except Exception:
        items = None
    if not items:
        raise TypeError(f"Expected `level` to be a real number or a non-empty sequence of them, got {level!r}")
    return tuple(_real(v, f"level[{i}]") for i, v in enumerate(items))


def _check_resolution(resolution, name: str = "resolution") -> int:
    if isinstance(resolution, (bool, np.bool_)) or not isinstance(resolution, (numbers.Integral, np.integer)):
        raise TypeError(f"Expected `{name}` to be an int >= 2, got {type(resolution).__name__}")
    r = int(resolution)
    if r < 2:
        raise ValueError(f"Expected `{name}` >= 2 (samples along the longest side), got {r}")
    need = r**3 * BYTES_PER_SAMPLE
    if need > MAX_SAMPLE_BYTES:
        r_max = int((MAX_SAMPLE_BYTES / BYTES_PER_SAMPLE) ** (1 / 3))
        raise ValueError(
            f"`{name}`={r} would need up to {_bytes_text(need)} of samples ({r}^3 points x "
            f"{BYTES_PER_SAMPLE} bytes); the limit is {_bytes_text(MAX_SAMPLE_BYTES)} "
            f"(rot4d_widget.sources.fields.MAX_SAMPLE_BYTES), i.e. resolution <= {r_max}"
        )
    return r


def _bytes_text(n: float) -> str:
    for unit in ("B", "KiB", "MiB", "GiB", "TiB"):
        if n < 1024 or unit == "TiB":
            return f"{n:.3g} {unit}"
        n /= 1024
    return f"{n:.3g} TiB"  # pragma: no cover


def _check_extent(extent) -> tuple:
    try:
        e = np.array(extent, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError("Expected `extent` to be ((xmin, xmax), (ymin, ymax), (zmin, zmax), (wmin, wmax)) of "
                        "real numbers") from None
    if e.shape != (4, 2):
        raise ValueError(f"Expected `extent` to have shape (4, 2): ((xmin, xmax), ..., (wmin, wmax)), got {e.shape}")
    if not np.all(np.isfinite(e)):
        raise ValueError(f"Expected `extent` to be finite, got {e.tolist()}")
    bad = [_AXES[d] for d in range(4) if not e[d, 0] < e[d, 1]]
    if bad:
        raise ValueError(f"Expected min < max in `extent` for every axis; not so for {', '.join(bad)}: {e.tolist()}")
    lo, hi = COORDINATE_RANGE
    for d in range(4):
        end = float(np.abs(e[d]).max())
        if end > hi:
            raise ValueError(f"`extent` of {_AXES[d]} reaches {end:.3g}; expected |ends| <= {hi:g} and half widths "
                             f"{lo:g} to {hi:g} (rot4d_widget.geometry.polytopes.COORDINATE_RANGE; rescale the coordinates, "
                             f"e.g. to other units)")
        check_scale(float(e[d, 1] - e[d, 0]) / 2, f"The half width of `extent` along {_AXES[d]}")
    return tuple((float(a), float(b)) for a, b in e)


def _check_positive(value, name: str) -> float:
    v = _real(value, name)
    if v <= 0:
        raise ValueError(f"Expected `{name}` > 0, got {v}")
    return v


# ----------------------------------------------------------------------------- the result
@dataclass(frozen=True, eq=False)
class FieldSlice:
    """The isosurface {f = level} closing {f >= level} (or {f <= level} for a field with
    ``inside="below"``) in one slice (all arrays read-only).

    vertices : (n, 3) float64 -- in slice coordinates
    triangles : (k, 3) intp -- counter-clockwise seen from outside the enclosed side
        (outward from {f >= level}); the surface is closed, capped on the box's faces
        (open there, and ``volume`` NaN, for a field with ``caps=False``)
    normals : (n, 3) float64 -- unit, outward
    volume : float -- 3-volume of {f >= level} in the slice (inf, or 0, when beyond float64's
        range: slice coordinates above about 5e102 or below about 2e-103)
    area : float -- area of the surface (likewise beyond about 1e154 and 1e-154)
    level : float
    spacing : float -- the sample spacing of the step (slice units); 0 when nothing was sampled
    """

    vertices: np.ndarray
    triangles: np.ndarray
    normals: np.ndarray
    volume: float
    area: float
    level: float
    spacing: float

    @property
    def empty(self) -> bool:
        return len(self.triangles) == 0

    def __repr__(self) -> str:
        return (f"FieldSlice(level={self.level:.6g}, V={len(self.vertices)}, T={len(self.triangles)}, "
                f"volume={self.volume:.6g}, area={self.area:.6g})")


_EMPTY3 = _sealed(np.zeros((0, 3)))
_EMPTY_T = _sealed(np.zeros((0, 3), dtype=np.intp))


def _empty_slice(level: float, spacing: float) -> FieldSlice:
    return FieldSlice(_EMPTY3, _EMPTY_T, _EMPTY3, 0.0, 0.0, level, spacing)


# ----------------------------------------------------------------------------- chunked reads
class _ChunkReader:
    """Reads chunks of a lazy 4-D array (dask, zarr, anything sliceable) and keeps recent ones."""

    def __init__(self, values, cache_bytes: int):
        self.values = values
        self.kind = _array_kind(values)
        shape = tuple(int(s) for s in values.shape)
        chunks = getattr(values, "chunks", None)
        bounds = None
        if self.kind == "dask":
            bounds = [np.concatenate([[0], np.cumsum(c)]).astype(np.int64) for c in chunks]
        elif isinstance(chunks, tuple) and len(chunks) == 4 and all(isinstance(c, (int, np.integer)) for c in chunks):
            bounds = [np.unique(np.r_[np.arange(0, n, int(c)), n]).astype(np.int64) for n, c in zip(shape, chunks)]
        elif isinstance(chunks, tuple) and len(chunks) == 4 and all(isinstance(c, tuple) for c in chunks):
            bounds = [np.concatenate([[0], np.cumsum(c)]).astype(np.int64) for c in chunks]
        if bounds is None:  # no chunk grid known: one chunk per 16 samples along each axis (reads are sub-blocks)
            bounds = [np.unique(np.r_[np.arange(0, n, 16), n]).astype(np.int64) for n in shape]
        self.bounds = bounds
        self.shape = shape
        self.dtype = np.dtype(np.float32) if np.dtype(values.dtype) == np.float32 else np.dtype(np.float64)
        self.cache_bytes = int(cache_bytes)
        self._cache: "collections.OrderedDict[tuple, np.ndarray]" = collections.OrderedDict()
        self._cached = 0
        self._delayed = None
        self._lock = threading.Lock()
        #: chunks read from the array (not from the cache) so far
        self.reads = 0
        #: [min, max] of the finite values of every chunk read so far (the "first cut" range)
        self.seen = [math.inf, -math.inf]

    def _slices(self, idx):
        return tuple(slice(int(b[i]), int(b[i + 1])) for b, i in zip(self.bounds, idx))

    def read(self, wanted):
        """{chunk index: ndarray} for the chunk indices ``wanted`` (list of 4-tuples)."""
        with self._lock:
            got, missing = {}, []
            for idx in wanted:
                a = self._cache.get(idx)
                if a is None:
                    missing.append(idx)
                else:
                    self._cache.move_to_end(idx)
                    got[idx] = a
        if missing:
            if self.kind == "dask":
                import dask

                if self._delayed is None:
                    self._delayed = self.values.to_delayed()
                parts = dask.compute(*[self._delayed[idx] for idx in missing])
            else:
                parts = [self.values[self._slices(idx)] for idx in missing]
            with self._lock:
                self.reads += len(missing)
                for idx, a in zip(missing, parts):
                    a = np.asarray(a, dtype=self.dtype)
                    got[idx] = a
                    fin = a[np.isfinite(a)] if a.dtype.kind == "f" else a
                    if fin.size:
                        self.seen[0] = min(self.seen[0], float(fin.min()))
                        self.seen[1] = max(self.seen[1], float(fin.max()))
                    if a.nbytes <= self.cache_bytes:
                        self._cache[idx] = a
                        self._cached += a.nbytes
                while self._cached > self.cache_bytes and self._cache:
                    _, old = self._cache.popitem(last=False)
                    self._cached -= old.nbytes
        return got

    def clear_cache(self) -> None:
        with self._lock:
            self._cache.clear()
            self._cached = 0


class _LazyXarray:
    """A DataArray whose data are neither dask nor loaded (an xarray backend's lazily indexed
    array: netCDF or zarr opened without chunks), seen as a plain sliceable array.

    Slicing reads only that block (``variable[key].values``) and returns a numpy array, so the
    chunk reader and dask's ``from_array`` never see a DataArray (inside dask a DataArray chunk
    aligns by its labels -- two takes of neighbouring samples shrink to their common ones -- and
    pulls in dask.dataframe, which needs pyarrow).  ``chunks``: the store's own chunk shape when
    the encoding gives one (zarr), else None (the reader then reads 16-sample blocks).
    """

    def __init__(self, da):
        self._variable = da.variable
        self.shape = tuple(int(n) for n in da.shape)
        self.ndim = len(self.shape)
        self.dtype = np.dtype(da.dtype)
        enc = getattr(da, "encoding", None) or {}
        pref = enc.get("preferred_chunks")
        ch = None
        if isinstance(pref, dict) and all(d in pref for d in da.dims):
            ch = tuple(int(pref[d]) for d in da.dims)
        elif isinstance(enc.get("chunks"), (tuple, list)) and len(enc["chunks"]) == self.ndim:
            ch = tuple(int(c) for c in enc["chunks"])
        self.chunks = ch if ch is not None and all(c > 0 for c in ch) else None
        self.name = da.name

    def __getitem__(self, key):
        return np.asarray(self._variable[key].values)

    def __array__(self, dtype=None, copy=None):
        a = self[(slice(None),) * self.ndim]
        return a if dtype is None else a.astype(dtype, copy=False)


def _xarray_values(da):
    """The array behind a DataArray for `Field4D`: dask stays dask, loaded data become numpy,
    a lazily indexed backend array becomes `_LazyXarray` (never the DataArray itself)."""
    if da.chunks is not None:
        return da.data
    if getattr(da.variable, "_in_memory", True):
        return np.asarray(da.values)
    return _LazyXarray(da)


def _is_xarray(obj, what: str) -> bool:
    return type(obj).__name__ == what and (type(obj).__module__ or "").startswith("xarray")


def _array_kind(values) -> str:
    if isinstance(values, np.ndarray):
        return "numpy"
    mod = type(values).__module__ or ""
    if mod.startswith("dask.") and hasattr(values, "to_delayed"):
        return "dask"
    if mod.startswith("zarr"):
        return "zarr"
    return "lazy"


def _count_infinite(a, block_bytes: int = 64 * 1024**2):
    """(n +inf, n -inf, first index as a tuple or None) of an array in memory, read in blocks
    along its first axis (at most ``block_bytes`` of booleans at a time)."""
    npos = nneg = 0
    first = None
    per = max(1, int(block_bytes // max(1, math.prod(int(n) for n in a.shape[1:]))))
    for i in range(0, int(a.shape[0]), per):
        b = np.asarray(a[i:i + per])
        inf = np.isinf(b)
        if not inf.any():
            continue
        pos = int(np.count_nonzero(inf & (b > 0)))
        npos += pos
        nneg += int(np.count_nonzero(inf)) - pos
        if first is None:
            j = np.unravel_index(int(np.flatnonzero(inf.ravel())[0]), inf.shape)
            first = (i + int(j[0]),) + tuple(int(v) for v in j[1:])
    return npos, nneg, first


def _finite_range(a, block_bytes: int = 64 * 1024**2) -> tuple:
    """(min, max) of the finite values of an array in memory, read in blocks along its first axis;
    (nan, nan) when none is finite."""
    lo, hi = math.inf, -math.inf
    per = max(1, int(block_bytes // max(1, 8 * math.prod(int(n) for n in a.shape[1:]))))
    for i in range(0, int(a.shape[0]), per):
        b = np.asarray(a[i:i + per])
        if b.dtype.kind == "f":
            b = b[np.isfinite(b)]
        if b.size:
            lo, hi = min(lo, float(b.min())), max(hi, float(b.max()))
    return (lo, hi) if lo <= hi else (math.nan, math.nan)


def _attr_numbers(v, n: int):
    """``n`` finite floats from an attribute value (a number or an array), else None."""
    try:
        a = np.asarray(v, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        return None
    return tuple(float(x) for x in a) if a.size == n and np.all(np.isfinite(a)) else None


def _zarr_attrs(values) -> dict:
    """A zarr array's attributes as a plain dict ({} when it has none or they cannot be read)."""
    try:
        return dict(values.attrs)
    except Exception:  # noqa: BLE001 - metadata is a bonus: without it the range comes from the data
        return {}


def _metadata_range(attrs, encoding):
    """(lo, hi, where) of a variable from its attributes, read without touching its data, or None.

    ``actual_range`` (CF: the data's own min and max, in unpacked units) first, else
    ``valid_range`` or ``valid_min`` and ``valid_max`` (CF: the bounds of valid values, in packed
    units: unpacked here by the ``scale_factor`` / ``add_offset`` xarray moved into the encoding
    when it decoded the data).  A pair that is not finite and ordered is ignored."""
    attrs = attrs or {}
    encoding = encoding or {}
    packed = "scale_factor" in attrs or "add_offset" in attrs  # not decoded: the data are still packed
    pair = None if packed else _attr_numbers(attrs.get("actual_range"), 2)
    if pair is not None and pair[0] <= pair[1]:
        return pair[0], pair[1], "actual_range"
    pair, where = _attr_numbers(attrs.get("valid_range"), 2), "valid_range"
    if pair is None:
        lo, hi = _attr_numbers(attrs.get("valid_min"), 1), _attr_numbers(attrs.get("valid_max"), 1)
        pair, where = (None if lo is None or hi is None else lo + hi), "valid_min/valid_max"
    if pair is None:
        return None
    if not packed:
        scale = _attr_numbers(encoding.get("scale_factor", 1.0), 1)
        offset = _attr_numbers(encoding.get("add_offset", 0.0), 1)
        if scale is None or offset is None:
            return None
        pair = tuple(sorted((pair[0] * scale[0] + offset[0], pair[1] * scale[0] + offset[0])))
    return (pair[0], pair[1], where) if pair[0] <= pair[1] else None


def _encoding_origin(da, chosen):
    """What a state file needs to reopen a DataArray read from a file, from what xarray kept:
    the path in ``da.encoding["source"]`` (the netCDF4 and h5netcdf engines put it there; scipy
    and zarr do not), when the array is the file's whole variable (its shape is the encoding's
    ``original_shape``; a selection made after opening cannot be seen).  None otherwise."""
    enc = getattr(da, "encoding", None) or {}
    src = enc.get("source")
    if not isinstance(src, str) or not os.path.exists(src) or da.name is None:
        return None
    shape = enc.get("original_shape")
    if shape is not None and tuple(int(n) for n in shape) != tuple(int(n) for n in da.shape):
        return None
    if da.chunks is not None:
        chunks = {str(d): int(c[0]) for d, c in zip(da.dims, da.chunks)}
    else:
        chunks = None
    return {"kind": "xarray", "path": os.path.abspath(src), "variable": str(da.name), "engine": None,
            "chunks": chunks, "isel": None, "sel": None, "kwargs": dict(chosen),
            "load": bool(da.chunks is None and getattr(da.variable, "_in_memory", False))}


def _label_json(v, where):
    if isinstance(v, (np.datetime64, np.timedelta64)):
        return str(v)
    if hasattr(v, "isoformat") and not isinstance(v, (int, float)):  # datetime, pandas Timestamp
        return v.isoformat()
    if isinstance(v, (bool, np.bool_)):
        raise TypeError(f"{where} = {v!r}: expected an integer, a label (number or string) or a slice")
    if isinstance(v, (numbers.Integral, np.integer)):
        return int(v)
    if isinstance(v, (numbers.Real, np.floating)) and math.isfinite(float(v)):
        return float(v)
    if v is None or isinstance(v, str):
        return v
    raise TypeError(f"{where} = {v!r}: expected an integer, a label (number or string) or a slice")


def _selection_json(selection, name):
    """``{dim: value}`` as JSON: numbers and strings as they are, ``slice(a, b, c)`` as
    ``{"slice": [a, b, c]}``, lists as lists; TypeError naming anything else."""
    if not selection:
        return None
    if not isinstance(selection, dict):
        raise TypeError(f"Expected `{name}` to be a dict {{dim: index or label or slice}}, got {type(selection).__name__}")
    out = {}
    for dim, v in selection.items():
        where = f"{name}[{dim!r}]"
        if isinstance(v, slice):
            out[str(dim)] = {"slice": [_label_json(e, where) for e in (v.start, v.stop, v.step)]}
        elif isinstance(v, (list, tuple, np.ndarray)):
            out[str(dim)] = [_label_json(e, where) for e in v]
        else:
            out[str(dim)] = _label_json(v, where)
    return out


def _selection_from_json(selection, name):
    """The inverse of `_selection_json` (a state file's selection for isel / sel)."""
    if selection is None:
        return None
    if not isinstance(selection, dict):
        raise ValueError(f"Expected `{name}` to be a dict, got {selection!r}")
    out = {}
    for dim, v in selection.items():
        if isinstance(v, dict):
            parts = v.get("slice")
            if set(v) != {"slice"} or not isinstance(parts, list) or len(parts) != 3:
                raise ValueError(f"Expected {name}[{dim!r}] to be {{'slice': [start, stop, step]}}, got {v!r}")
            v = slice(*parts)
            items = (v.start, v.stop, v.step)
        else:
            items = v if isinstance(v, list) else [v]
        for e in items:
            if e is not None and (isinstance(e, bool) or not isinstance(e, (int, float, str))):
                raise ValueError(f"Expected {name}[{dim!r}] to hold numbers, strings or slices, got {e!r}")
        out[str(dim)] = v
    return out


def _chunks_json(chunks):
    if chunks is None or isinstance(chunks, str):
        return chunks
    if isinstance(chunks, (numbers.Integral, np.integer)) and not isinstance(chunks, bool):
        return int(chunks)
    if isinstance(chunks, dict):
        out = {}
        for d, c in chunks.items():
            if isinstance(c, (numbers.Integral, np.integer)) and not isinstance(c, bool):
                out[str(d)] = int(c)
            elif isinstance(c, str) or c is None:
                out[str(d)] = c
            else:
                raise TypeError(f"Expected chunks[{d!r}] to be an int, 'auto' or None, got {c!r}")
        return out
    raise TypeError(f"Expected `chunks` to be None, 'auto', an int or a dict {{dim: size}}, got {chunks!r}")


# ----------------------------------------------------------------------------- the field
class Field4D:
    """A scalar field on a 4-D box: a source for `Rot4DWidget` and the input of `slice_field`.

    Parameters
    ----------
    values : 4-D array-like
        numpy array or memmap, dask array, zarr array or anything with ``shape``,
        ``ndim``, ``dtype`` and slicing; real numbers (NaN allowed: below every level).
        Chunked/lazy arrays are never read whole except once for `coarse`.  An xarray
        DataArray goes through `from_xarray` (a Dataset: pick a variable, ``ds["T"]``).
        +inf / -inf samples are allowed but reported once, by a `NonFiniteWarning` naming
        how many (and, in memory, where) when the data range is first needed: they sit
        above / below every level, and an interpolated point whose cell holds one is +-inf,
        or NaN (below every level) where its weight is 0 -- mask them (``np.where(np.isfinite(a), a, np.nan)``) or clip.
    axes : str
        Which of x, y, z, w each array axis is, a permutation of ``"xyzw"``:
        ``"wzyx"`` for ``f[t, z, y, x]`` (the usual time-first layout), ``"xyzw"``
        for ``f[x, y, z, t]``.  Required for an array (TypeError without it: a guess
        cannot tell time from x); `repr` and the readout name the order
        (``f[w, z, y, x]``).  `from_xarray` takes it from the dims.
    extent : ((xmin, xmax), (ymin, ymax), (zmin, zmax), (wmin, wmax)), optional
        Data coordinates of the first and last node along each axis (samples sit
        on the nodes).  Default: x, y, z span ``[-(n-1)/2, (n-1)/2] * h`` with one
        spacing ``h = 2 / (longest spatial n - 1)`` (the longest spatial side is
        2, voxels are cubes), and w is the sample index ``0 .. nw-1``.
    name, units : str, optional
        Shown in the readout.
    w_per_unit : float, optional
        How much data-w one unit of slice space is.  Default: 1 when ``extent``
        is given (taken literally), else ``1 / h`` (one w sample is as long as
        one spatial sample: voxels are cubes in 4-D).  Larger values squash time.
    w_units : str, optional
        Unit of w for the readout (default ``"sample"`` with the default extent).
    space_units : str, optional
        Unit of x, y and z (e.g. ``"m"``): the readout gives a slice's volume in it, cubed.
        `from_xarray` takes it from the coordinates' ``units`` when x, y and z agree.
    resolution, coarse_resolution : int
        Samples along the longest side of a full step (default 64) and of a
        coarse step (default ``max(24, resolution // 2)``).
    levels : float or sequence of floats, optional
        Iso levels (default: one, midway between the min and max of `data_range`: for a chunked
        array, of the first slice's chunks until `coarse` is ready -- the first picture never
        reads the whole array; `prepare_coarse` builds the copy in the background).
    inside : "above" or "below"
        Which side of each level the surface encloses: ``"above"`` {f >= level} (a density,
        a phase field), ``"below"`` {f <= level} (a signed distance, negative inside: the ball,
        not the box around it).  NaN is never enclosed.
    caps : bool
        True (default): the surface is closed on the box's faces (the enclosed part of each face
        is drawn; ``volume`` is the enclosed 3-volume).  False: only {f = level} itself, open where
        it meets a face (its edge within one sample of it) -- for fields that fill the box, e.g.
        periodic ones, whose caps would hide the inside; ``volume`` is then NaN (not closed).
    chunk_cache_bytes : int
        Recently read chunks of a chunked array kept in memory (default 128 MiB: with the
        rest of a full step, a 4 GB store stays under 1 GB resident; docs/fields.md).
    """

    def __init__(self, values, *, axes=None, extent=None, name=None, units=None,
                 w_per_unit=None, w_units=None, space_units=None, resolution: int = 64, coarse_resolution=None,
                 levels=None, chunk_cache_bytes: int = 128 * 1024**2, inside: str = "above", caps: bool = True,
                 _coords=None, _function=None):
        self._function = _function
        self._dims = None  # the array's dim names (from_xarray), for the readout
        self.axes_given = axes is not None
        if _function is None:
            if _is_xarray(values, "Dataset"):
                raise _dataset_error(values)
            if _is_xarray(values, "DataArray"):
                raise TypeError("Field4D(values) takes a plain array; for an xarray.DataArray use "
                                "Field4D.from_xarray(da, w='time') (dims by name, extents from the coordinates), "
                                "or pass da.data with axes=")
            for attr in ("shape", "ndim", "__getitem__"):
                if not hasattr(values, attr):
                    raise TypeError(f"Expected `values` to be a 4-D array-like (numpy, dask, zarr ...) with shape, "
                                    f"ndim and slicing; {type(values).__name__} has no {attr!r}")
            kind = _array_kind(values)
            if kind == "lazy" and not hasattr(values, "dtype"):
                values = np.asarray(values)
                kind = "numpy"
            if values.ndim != 4:
                raise ValueError(f"Expected `values` to be 4-D, got {values.ndim}-D with shape {tuple(values.shape)}")
            dtype = np.dtype(values.dtype)
            if dtype.kind not in "fiub":
                raise TypeError(f"Expected `values` to hold real numbers (float, int, uint or bool), got dtype {dtype}")
            if kind == "numpy":
                values = np.asarray(values)  # a memmap stays a memmap underneath (no copy)
                if dtype not in (np.float32, np.float64):
                    values = values.astype(np.float64)
            self._values = values
            self._kind = kind
            if axes is not None and (not isinstance(axes, str) or sorted(axes) != sorted(_AXES)):
                raise ValueError(f"Expected `axes` to be a permutation of 'xyzw' naming each array axis "
                                 f"(e.g. 'wzyx' for f[t, z, y, x]), got {axes!r}")
            if axes is None:  # a guess cannot tell time from x: the caller says which axis is which
                sh = tuple(int(n) for n in values.shape)
                raise TypeError(
                    f"Field4D needs `axes`, which of x, y, z, w each array axis is (shape {sh}): "
                    f"axes='wzyx' for f[t, z, y, x] (time first), axes='xyzw' for f[x, y, z, t]; "
                    f"Field4D.from_xarray(da, w='time') takes them from the dims")
            self.axes = axes
            self._axis_of = tuple(axes.index(c) for c in _AXES)  # array axis of x, y, z, w
            self.shape = tuple(int(values.shape[a]) for a in self._axis_of)
            small = [f"{c}={n}" for c, n in zip(_AXES, self.shape) if n < 2]
            if small:
                raise ValueError(f"Expected at least 2 samples along every axis, got {', '.join(small)}")
        else:
            self._values = None
            self._kind = "function"
            self.axes = _AXES
            self._axis_of = (0, 1, 2, 3)
            self.shape = None

        if extent is None:
            if _function is not None:
                raise ValueError("A function field needs an `extent`")
            h = 2.0 / (max(self.shape[:3]) - 1)
            ext = [(-(n - 1) / 2 * h, (n - 1) / 2 * h) for n in self.shape[:3]] + [(0.0, float(self.shape[3] - 1))]
            self.extent = tuple((float(a), float(b)) for a, b in ext)
            wpu = 1.0 / h if w_per_unit is None else w_per_unit
            self.w_units = "sample" if w_units is None else str(w_units)
            self.default_extent = True
        else:
            self.extent = _check_extent(extent)
            wpu = 1.0 if w_per_unit is None else w_per_unit
            self.w_units = None if w_units is None else str(w_units)
            self.default_extent = False
        self._coords = (None,) * 4 if _coords is None else tuple(_coords)
        self.name = None if name is None else str(name)
        self.units = None if units is None else str(units)
        self.space_units = None if space_units is None else str(space_units)
        e = np.array(self.extent)
        self._centre = (e[:, 0] + e[:, 1]) / 2
        self._coarse = None
        self._coarse_lock = threading.Lock()
        self._coarse_thread = None  # the background build (`prepare_coarse`)
        self._coarse_error = None
        #: (chunks done, chunks in all) of the coarse copy's build, once it started
        self.coarse_progress = None
        self._k_first = None  # K from the first cut's samples, until the coarse copy is ready
        self.w_per_unit = wpu
        self.resolution = resolution
        self.coarse_resolution = max(24, self.resolution // 2) if coarse_resolution is None else coarse_resolution
        self.chunk_cache_bytes = int(chunk_cache_bytes)
        self._reader = None
        self._box = None
        self._levels = None if levels is None else _as_levels(levels)
        self.inside = inside
        self.caps = caps
        #: (n +inf, n -inf, first index or None) once known; reported once (`NonFiniteWarning`)
        self._infinite = None
        self._infinite_reported = False
        #: (lo, hi, where) from the data's metadata (`from_xarray`: actual_range, valid_min/valid_max;
        #: a zarr array's own attributes likewise)
        self._meta_range = _metadata_range(_zarr_attrs(self._values), None) if self._kind == "zarr" else None
        self._range = None  # ((lo, hi), where the range comes from), once known
        #: Where the values come from, for a state file to reopen them (`Field4D.open`; `from_xarray`
        #: when xarray's encoding names the file): a JSON-able dict, or None (not reopenable)
        self.origin = None

    # -- constructors ---------------------------------------------------------
    @classmethod
    def from_function(cls, f, extent, *, name=None, units=None, w_per_unit=None, w_units=None, **kwargs) -> "Field4D":
        """A field given by ``f(x, y, z, w)``, vectorised over arrays of one shape and
        returning real values of that shape, evaluated exactly at each sample point
        (no grid, no interpolation).  ``extent`` is required (its box is the field's)."""
        if not callable(f):
            raise TypeError(f"Expected `f` to be callable as f(x, y, z, w), got {type(f).__name__}")
        if name is None:
            name = getattr(f, "__name__", None)
        return cls(None, extent=extent, name=name, units=units, w_per_unit=w_per_unit, w_units=w_units,
                   _function=f, **kwargs)

    @classmethod
    def from_xarray(cls, da, *, x=None, y=None, z=None, w=None, w_per_unit=None, **kwargs) -> "Field4D":
        """A field from a 4-D ``xarray.DataArray`` (dims by name; extents from coordinates).

        Dims named ``x``, ``y``, ``z`` (any case) are found by themselves and the one
        left over is w (``("time", "z", "y", "x")``); otherwise name them with
        ``x=, y=, z=, w=``.  Coordinates may be unevenly spaced (each maps to a
        fractional index) and decreasing (read reversed, lazily); not monotonic
        -> ValueError.  datetime64 coordinates become seconds since their first
        value.  A dask-backed array stays lazy.  ``w_per_unit`` defaults to the
        mean w spacing over the mean spatial spacing (voxels are cubes).
        """
        if _is_xarray(da, "Dataset") or (hasattr(da, "data_vars") and hasattr(da, "dims")):
            raise _dataset_error(da)
        if not (hasattr(da, "dims") and hasattr(da, "coords") and hasattr(da, "isel")):
            raise TypeError(f"Expected an xarray.DataArray, got {type(da).__name__}")
        dims = tuple(str(d) for d in da.dims)
        if len(dims) != 4:
            raise ValueError(f"Expected a 4-D DataArray, got dims {dims}; select a 4-D part first "
                             "(da.isel(...) / da.sel(...))")
        given = {"x": x, "y": y, "z": z, "w": w}
        for k, v in given.items():
            if v is not None and v not in dims:
                raise ValueError(f"`{k}={v!r}` is not a dim of the DataArray; its dims are {dims}")
        chosen = {k: v for k, v in given.items() if v is not None}
        if len(set(chosen.values())) != len(chosen):
            raise ValueError(f"Expected distinct dims for x, y, z, w, got {chosen}")
        for k in "xyz":
            if k not in chosen:
                cands = [d for d in dims if d.lower() == k and d not in chosen.values()]
                if len(cands) == 1:
                    chosen[k] = cands[0]
        left = [d for d in dims if d not in chosen.values()]
        missing = [k for k in _AXES if k not in chosen]
        if len(missing) == 1 and len(left) == 1:
            chosen[missing[0]] = left[0]
        elif missing:
            raise ValueError(
                f"Cannot map the dims {dims} to x, y, z, w: found {chosen or 'none'}; name them, e.g. "
                f"Field4D.from_xarray(da, x='lon', y='lat', z='depth', w='time')"
            )
        axes = "".join(next(k for k, v in chosen.items() if v == d) for d in dims)
        few = [f"{chosen[k]}={int(da.sizes[chosen[k]])} ({k})" for k in _AXES if int(da.sizes[chosen[k]]) < 2]
        if few:
            raise ValueError(
                f"Expected at least 2 samples along every dim (a surface needs a cell to cross), got "
                f"{', '.join(few)}; dims {dict((d, int(da.sizes[d])) for d in dims)}. A single time step is a "
                f"3-D field, not a 4-D one: select a range, e.g. da.isel({chosen['w']}=slice(0, 2))")
        meta_range = _metadata_range(getattr(da, "attrs", None), getattr(da, "encoding", None))
        origin = _encoding_origin(da, chosen)
        flips, coords, extent = {}, [None] * 4, []
        for d_i, k in enumerate(_AXES):
            dim = chosen[k]
            n = int(da.sizes[dim])
            if dim in da.coords:
                c = np.asarray(da.coords[dim].values)
                if np.issubdtype(c.dtype, np.datetime64) or np.issubdtype(c.dtype, np.timedelta64):
                    c = (c - c[0]) / np.timedelta64(1, "s")
                try:
                    c = np.asarray(c, dtype=np.float64)
                except (TypeError, ValueError):
                    raise TypeError(f"Expected numeric or datetime coordinates for {dim!r}, got dtype {c.dtype}") from None
                if c.shape != (n,) or not np.all(np.isfinite(c)):
                    raise ValueError(f"Expected finite 1-D coordinates for {dim!r}")
            else:
                c = np.arange(n, dtype=np.float64)
            dc = np.diff(c)
            if n >= 2 and np.all(dc < 0):
                flips[dim] = slice(None, None, -1)
                c, dc = c[::-1], -dc[::-1]
            if not np.all(dc > 0):
                raise ValueError(f"Expected the coordinates of {dim!r} to be strictly monotonic, got {c.tolist()[:8]}...")
            extent.append((float(c[0]), float(c[-1])))
            uniform = np.allclose(dc, (c[-1] - c[0]) / (n - 1), rtol=1e-6, atol=0)
            coords[d_i] = None if uniform else _sealed(c.copy())
        if flips:
            da = da.isel(flips)
        if w_per_unit is None:
            sp = np.mean([(b - a) / (int(da.sizes[chosen[k]]) - 1) for k, (a, b) in zip("xyz", extent)])
            w_per_unit = ((extent[3][1] - extent[3][0]) / (int(da.sizes[chosen["w"]]) - 1)) / sp
        values = _xarray_values(da)
        units = da.attrs.get("units")
        w_units = kwargs.pop("w_units", da.coords[chosen["w"]].attrs.get("units") if chosen["w"] in da.coords else None)
        if w_units is None and chosen["w"] in da.coords and np.issubdtype(da.coords[chosen["w"]].dtype, np.datetime64):
            w_units = "s"
        space = {da.coords[chosen[k]].attrs.get("units") if chosen[k] in da.coords else None for k in "xyz"}
        space_units = kwargs.pop("space_units", space.pop() if len(space) == 1 else None)
        field = cls(values, axes=axes, extent=extent, name=kwargs.pop("name", da.name),
                    units=kwargs.pop("units", units), w_per_unit=w_per_unit, w_units=w_units, _coords=coords,
                    space_units=space_units, **kwargs)
        field._dims = dims
        field._meta_range = meta_range
        field.origin = origin
        return field

    @classmethod
    def open(cls, path, variable=None, *, x=None, y=None, z=None, w=None, engine=None, chunks=None,
             isel=None, sel=None, load: bool = False, **kwargs) -> "Field4D":
        """`from_xarray` of ``variable`` in the netCDF file or zarr store at ``path``, remembering
        where it came from (``field.origin``), so that a state file reopens it
        (`rot4d_widget.keep.export.save_state`, `Rot4DWidget.save_state` / ``from_state``).

        ``variable`` may be omitted when the file has one data variable.  ``engine`` goes to
        ``xarray.open_dataset`` (None: xarray's guess; a directory opens with ``"zarr"``).
        ``chunks``: None reads lazily, block by block, as needed; ``{}`` (the store's own chunks),
        ``"auto"`` or ``{"time": 10}`` make it a dask array.  ``isel`` / ``sel`` select a 4-D part
        before `from_xarray` (``isel={"member": 0}``, ``sel={"time": slice("2020-01", "2020-06")}``;
        isel first): integers, labels (numbers, strings) and slices of them, kept in the origin.
        ``load=True`` reads the selected part into memory now (a numpy array).
        ``x=, y=, z=, w=`` name the dims as in `from_xarray`; other keywords go to it
        (``w_per_unit=``, ``levels=``, ``inside=``, ``caps=``, ``resolution=`` ...).

        Opening reads the file's metadata and coordinates, not its data.
        """
        import xarray

        p = os.path.abspath(os.fspath(path))
        if engine is None and (os.path.isdir(p) or p.rstrip("/").endswith(".zarr")):
            engine = "zarr"
        rec_isel = _selection_json(isel, "isel")
        rec_sel = _selection_json(sel, "sel")
        rec_chunks = _chunks_json(chunks)
        ds = xarray.open_dataset(p, engine=engine, chunks=chunks)
        if variable is None:
            names = list(ds.data_vars)
            if len(names) != 1:
                raise ValueError(f"{os.fspath(path)!r} has data variables {names}; name one: "
                                 f"Field4D.open(path, variable)")
            variable = names[0]
        if variable not in ds.data_vars:
            raise ValueError(f"{os.fspath(path)!r} has no data variable {variable!r}; it has {list(ds.data_vars)}")
        da = ds[variable]
        if isel:
            da = da.isel(isel)
        if sel:
            da = da.sel(sel)
        if load:
            da = da.load()
        field = cls.from_xarray(da, x=x, y=y, z=z, w=w, **kwargs)
        field.origin = {"kind": "xarray", "path": p, "variable": str(variable), "engine": engine,
                        "chunks": rec_chunks, "isel": rec_isel, "sel": rec_sel,
                        "kwargs": dict(zip(field.axes, field._dims)), "load": bool(load)}
        return field

    # -- geometry and resolution ------------------------------------------------
    @property
    def w_per_unit(self) -> float:
        """How much data-w one unit of slice space is (settable: larger squashes w, smaller stretches it)."""
        return self._w_per_unit

    @w_per_unit.setter
    def w_per_unit(self, value) -> None:
        wpu = _check_positive(value, "w_per_unit")
        e = np.array(self.extent)
        unit = np.array([1.0, 1.0, 1.0, wpu])  # data units per slice unit
        with np.errstate(over="ignore", under="ignore"):
            hw = (e[:, 1] - e[:, 0]) / 2 / unit
        check_scale(float(hw[3]), f"With `w_per_unit` = {wpu:.3g}, the box's half width along w in slice units")
        self._w_per_unit, self._unit, self._hw = wpu, unit, hw
        self.half_widths = tuple(float(v) for v in self._hw)
        self._stats = None  # K is per slice unit
        self._k_first = None
        if self._coarse is not None and self._coarse is not self:
            self._coarse.w_per_unit = value

    @property
    def inside(self) -> str:
        """Which side of each level the surface encloses: "above" {f >= level} or "below" {f <= level}."""
        return self._inside

    @inside.setter
    def inside(self, value) -> None:
        if not isinstance(value, str) or value not in ("above", "below"):
            raise ValueError(f"Expected `inside` to be 'above' (the surface encloses f >= level) or 'below' "
                             f"(f <= level, e.g. a signed distance negative inside), got {value!r}")
        self._inside = value

    @property
    def caps(self) -> bool:
        """Whether the surface is closed on the box's faces (True) or left open there (False)."""
        return self._caps

    @caps.setter
    def caps(self, value) -> None:
        if not isinstance(value, (bool, np.bool_)):
            raise TypeError(f"Expected `caps` to be True (close the surface on the box's faces) or False "
                            f"(leave it open there), got {value!r}")
        self._caps = bool(value)

    @property
    def resolution(self) -> int:
        """Samples along the longest side of a full step's region (int >= 2)."""
        return self._resolution

    @resolution.setter
    def resolution(self, value) -> None:
        self._resolution = _check_resolution(value)

    @property
    def coarse_resolution(self) -> int:
        """Samples along the longest side of a coarse step's region (int >= 2)."""
        return self._coarse_resolution

    @coarse_resolution.setter
    def coarse_resolution(self, value) -> None:
        self._coarse_resolution = _check_resolution(value, "coarse_resolution")

    # -- source protocol --------------------------------------------------------
    @property
    def size(self) -> float:
        """Circumradius of the 4-D box about its centre, in slice units."""
        return float(np.linalg.norm(self._hw))

    @property
    def n_groups(self) -> int:
        return len(self.levels)

    @property
    def levels(self) -> tuple:
        """The iso levels (tuple of floats); settable with a number or a sequence."""
        if self._levels is None:
            lo, hi = self._range_info(first_cut=True)[0]
            self._levels = ((lo + hi) / 2,) if math.isfinite(lo) and math.isfinite(hi) else (0.0,)
        return self._levels

    @levels.setter
    def levels(self, value) -> None:
        self._levels = _as_levels(value)

    @property
    def values(self):
        """The array as given (None for a function field)."""
        return self._values

    @property
    def data_range(self) -> tuple:
        """(min, max) of the finite values; (nan, nan) if there are none.  Where it comes from
        (`data_range_source`): the metadata of a variable from xarray (``actual_range``, else
        ``valid_range`` or ``valid_min``/``valid_max``), read without touching the data; else an
        array in memory, whole; a chunked or lazy array's `coarse` copy (which may miss a peak
        between its nodes), or, until the coarse copy is ready, the chunks a slice has read so far
        (``"first cut"``: a fresh field's first slice reads only the chunks its hyperplane touches
        and takes the default level from them); a function's probe grid.  Asked before any slice
        and before the coarse copy is ready, it builds (or waits for) the coarse copy."""
        return self._range_info()[0]

    @property
    def data_range_source(self) -> str:
        """Where `data_range` comes from: ``"data"``, ``"coarse copy"``, ``"first cut"`` (the
        chunks read so far, until the coarse copy is ready), ``"probe grid"``,
        ``"actual_range"``, ``"valid_range"`` or ``"valid_min/valid_max"``."""
        return self._range_info()[1]

    def _first_cut_range(self, first_cut: bool):
        """((lo, hi), "first cut") from the chunks read so far while the coarse copy is not ready
        (with ``first_cut``, reading the cut at rest when nothing was read yet), else None."""
        if self._range is not None or self._meta_range is not None or self._kind in ("function", "numpy"):
            return None
        if self._coarse is not None:
            return None
        rd = self._reader
        if (rd is None or rd.reads == 0) and first_cut:
            _sample_raw(self, np.eye(4), 0.0, self.resolution)  # the picture at rest: its chunks only
            rd = self._reader
        if rd is None or rd.reads == 0:
            return None
        lo, hi = rd.seen
        return ((lo, hi) if lo <= hi else (math.nan, math.nan)), "first cut"

    def _range_info(self, first_cut: bool = False):
        prov = self._first_cut_range(first_cut)
        if prov is not None:
            return prov
        if self._range is None:
            if self._meta_range is not None:
                lo, hi, where = self._meta_range
                self._range = ((lo, hi), where)
            elif self._kind == "function":
                a = self._probe_values()
                finite = np.isfinite(a)
                rng = (float(a[finite].min()), float(a[finite].max())) if finite.any() else (math.nan, math.nan)
                self._range = (rng, "probe grid")
            elif self._kind == "numpy":
                self._report_infinite()
                self._range = (_finite_range(self._values), "data")
            else:
                c = self.coarse()
                self._report_infinite()
                self._range = (c.data_range, "coarse copy")
        return self._range

    def _probe_values(self):
        """A function field's values on a `_FUNCTION_PROBE`^4 grid over its box, float64 (x, y, z, w)."""
        if getattr(self, "_probe", None) is None:
            m = _FUNCTION_PROBE
            grids = np.meshgrid(*[np.linspace(a, b, m) for a, b in self.extent], indexing="ij")
            self._probe = _call(self._function, *grids)
        return self._probe

    @property
    def level_step(self) -> float:
        """How far o / i move the levels: 1/50 of the data range (1/50 of |value| or 0.02 when constant)."""
        lo, hi = self.data_range
        if not (math.isfinite(lo) and math.isfinite(hi)):
            return 0.02
        span = hi - lo
        return span / 50 if span > 0 else max(abs(hi), 1.0) / 50

    def step_levels(self, sign: int):
        """Move every level by ``sign * level_step``; returns the levels, or False (no change) when
        a level would leave the data range widened by one step (refused, not clamped, so the
        opposite key undoes every step made)."""
        step = self.level_step
        lo, hi = self.data_range
        new = tuple(v + (1 if sign > 0 else -1) * step for v in self.levels)
        if math.isfinite(lo) and math.isfinite(hi):
            def outside(v):  # how far beyond the widened range (0 inside)
                return max(lo - step - v, v - hi - step, 0.0)

            # a level set outside by hand may still step back towards the range
            if any(outside(v) > 0 and outside(v) >= outside(u) for u, v in zip(self.levels, new)):
                return False
        elif not all(math.isfinite(v) for v in new):
            return False
        self._levels = new
        return self._levels

    @property
    def actions(self) -> dict:
        """``{"o": level up, "i": level down}`` (`SourceAction`), repeating while held."""
        from .protocol import SourceAction

        return {
            "o": SourceAction("level up", "raise the iso level(s) by 1/50 of the data range",
                              lambda sign=1: self.step_levels(sign)),
            "i": SourceAction("level down", "lower the iso level(s) by 1/50 of the data range",
                              lambda sign=1: self.step_levels(-sign)),
        }

    #: the source protocol's ``coarse_steps``: held keys slice the coarse copy
    coarse_steps = True

    @property
    def settings(self) -> dict:
        """The source protocol's ``settings``: the iso levels, which side is inside, the caps."""
        return {"levels": tuple(self.levels), "inside": self.inside, "caps": self.caps}

    def apply_setting(self, name: str, value) -> None:
        """Set one of `settings` (ValueError for another name; the setters validate the values)."""
        if name not in ("levels", "inside", "caps"):
            raise ValueError(f"A field's settings are 'levels', 'inside' and 'caps', not {name!r}")
        setattr(self, name, tuple(value) if name == "levels" else value)

    @property
    def w_frame(self) -> tuple:
        """``(origin, per_unit)`` = (the data's w at the box's centre, `w_per_unit`): c0 =
        origin + per_unit * d, d the hyperplane's offset from the box's centre along the turned
        w axis in slice units (the source protocol's ``w_frame``)."""
        return float(self._centre[3]), float(self._w_per_unit)

    def offset(self, c0) -> float:
        """d, the offset in slice units of the hyperplane w = ``c0`` (data w units): ``(c0 -
        origin) / w_per_unit`` (`w_frame`)."""
        return (_real(c0, "c0") - float(self._centre[3])) / float(self._w_per_unit)

    def w_range(self, matrix) -> tuple:
        """(lowest, highest) c0, in the data's w units, at which w = c0 touches the rotated box."""
        m = as_rotation_matrix(matrix)
        s = float(np.abs(m[3]) @ self._hw) * float(self._w_per_unit)
        origin = float(self._centre[3])
        return origin - s, origin + s

    def to_data(self, points, matrix, c0) -> np.ndarray:
        """(n, 4) float64: the data coordinates (x, y, z, w in the field's own units) of the
        slice points ``points`` (n, 3) of the cut w = ``c0`` (data w units) after ``matrix``:
        ``centre + (matrix.T @ (p, d)) * (1, 1, 1, w_per_unit)``, d = `offset` (c0)."""
        m = as_rotation_matrix(matrix)
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        q = np.column_stack([p, np.full(len(p), self.offset(c0))]) @ m  # rows of (m.T @ (p, d))
        return self._centre + q * self._unit

    def slice(self, matrix, c0, coarse: bool = False):
        """The slice as the widget draws it (`SliceData`): the isosurface of every level
        (group = level index) and the cut of the data's box as bars.  ``coarse``:
        the in-memory coarse copy at `coarse_resolution` (for held keys).  ``c0`` in the data's w
        units (`w_frame`).  ``extra["data_frame"]`` records the cut and the field's frame then
        (``matrix``, ``d`` the offset in slice units, ``centre``, ``unit``: a point p is at data
        ``centre + (matrix.T @ (p, d)) * unit``, as `to_data`)."""
        m = as_rotation_matrix(matrix)
        c0 = self.offset(c0)  # slice units from here on
        meanwhile = bool(coarse) and self._coarse_building()
        # held keys while the coarse copy is built: the full data sampled at the coarse resolution
        # (the chunks the cut touches, kept by the reader's cache; the build goes on)
        res = self.coarse_resolution if coarse else self.resolution
        if coarse and not meanwhile:
            slices = _slice_offset(self, m, c0, self.levels, res, coarse=True)
        else:  # read first: a fresh chunked field takes its range and level from this cut's chunks
            s = _sample(self, m, c0, _check_resolution(res), first_cut=True)
            levels = self.levels
            slices = (tuple(_empty_slice(lv, 0.0) for lv in levels) if s is None
                      else tuple(_surface(s, lv, self.inside, self.caps) for lv in levels))
        box = _box_slice(self, m, c0)
        pts, tris, nrm, groups = [], [], [], []
        off = 0
        for g, s in enumerate(slices):
            pts.append(s.vertices)
            nrm.append(s.normals)
            tris.append(s.triangles + off)
            groups.append(np.full(len(s.triangles), g, dtype=np.intp))
            off += len(s.vertices)
        bv = np.asarray(box.vertices)
        r = np.linalg.norm(bv, axis=1, keepdims=True)
        bn = np.where(r > 0, bv / np.where(r > 0, r, 1.0), np.array([0.0, 0.0, 1.0]))
        pts.append(bv)
        nrm.append(bn)
        segments = np.asarray(box.edges) + off
        readout = self._readout(m, c0, slices, box, coarse and not meanwhile)
        if meanwhile:
            done, total = self.coarse_progress or (0, 0)
            readout = readout + (("resolution", f"{res} (from the full data: the coarse copy is being built, "
                                                f"{done}/{total} chunks)"),)
        return FieldSliceData.build(
            points=np.concatenate(pts), segments=segments, triangles=np.concatenate(tris),
            groups=np.concatenate(groups), normals=np.concatenate(nrm),
            volume=_representable(slices[0]) if len(slices) == 1 else None,
            readout=readout, convex=False, show_points=False,
            extra={"levels": slices, "box": box, "data_frame": {
                "matrix": _sealed(m.copy()), "d": c0, "centre": _sealed(self._centre.copy()),
                "unit": _sealed(self._unit.copy())}},
        )

    def describe(self) -> dict:
        """A JSON-able description; rebuilds nothing for in-memory arrays (not recordable)."""
        d = {"kind": "field", "axes": self.axes, "extent": [list(e) for e in self.extent],
             "w_per_unit": self.w_per_unit, "levels": list(self.levels), "name": self.name, "units": self.units,
             "space_units": self.space_units, "inside": self.inside, "caps": self.caps}
        if self._kind == "function":
            f = self._function
            d["function"] = f"{getattr(f, '__module__', '?')}.{getattr(f, '__qualname__', type(f).__name__)}"
        else:
            what = {"numpy": "in-memory numpy", "dask": "dask array", "zarr": "zarr array"}.get(
                self._kind, "lazily read xarray array" if isinstance(self._values, _LazyXarray)
                else type(self._values).__name__)
            d["array"] = f"{what} (not recordable)"
            d["shape"] = list(self._values.shape)
            d["dtype"] = str(np.dtype(self._values.dtype))
            store = getattr(self._values, "store", None)
            if self._kind == "zarr" and store is not None:
                d["store"] = str(store)
        return d

    # -- coarse copy -------------------------------------------------------------
    def coarse(self) -> "Field4D":
        """An in-memory copy with at most `COARSE_SAMPLES` nodes per axis over the same box
        (linear resampling onto evenly spaced fractional indices), built once.

        The field itself when it already is that small and in memory, or a function.  A chunked or
        lazy array is read chunk by chunk (each downsampled into the copy and dropped: memory is the
        copy plus a few chunks).  Blocks until the copy is built: when `prepare_coarse` started it
        in the background, waits for that build."""
        if self._coarse is None:
            with self._coarse_lock:
                t = self._coarse_thread
                if self._coarse is None and t is None:
                    self._coarse = self._make_coarse()
            if t is not None:
                t.join()
                if self._coarse is None:
                    raise RuntimeError("Field4D: building the coarse copy failed") from self._coarse_error
        return self._coarse

    @property
    def coarse_ready(self) -> bool:
        """True once the coarse copy is built (`coarse`, or the background build of `prepare_coarse`)."""
        return self._coarse is not None

    def prepare_coarse(self, progress: bool = True) -> None:
        """Start building the coarse copy (`coarse`) on a daemon thread and return at once.

        The build reads the array chunk by chunk (memory: the copy plus a few chunks), counting
        chunks on a progress bar (`rot4d_widget.view.progress`, shown after a second: a widget in a
        kernel, a line on a terminal) when ``progress`` is true; `coarse_progress` holds
        (chunks done, chunks in all).  Until `coarse_ready`, held keys meanwhile slice at full
        resolution (``slice(..., coarse=True)`` returns the full-resolution slice and says so), the
        data range and default level come from the chunks read so far ("first cut"); `coarse`
        waits for the build.  Does nothing when the copy is built or being built."""
        with self._coarse_lock:
            if self._coarse is not None or self._coarse_thread is not None:
                return
            t = threading.Thread(target=self._build_coarse, args=(bool(progress),), daemon=True,
                                 name=f"rot4d coarse copy {self.name or ''}".strip())
            self._coarse_thread = t
        t.start()

    def _build_coarse(self, show: bool) -> None:
        try:
            c = self._make_coarse(progress_bar=show)
            self._coarse = c
        except BaseException as e:  # noqa: BLE001 - kept for `coarse` to raise
            self._coarse_error = e

    def _coarse_building(self) -> bool:
        t = self._coarse_thread
        return self._coarse is None and t is not None and t.is_alive()

    def _make_coarse(self, progress_bar: bool = False) -> "Field4D":
        if self._kind == "function":
            return self
        nshape = self._values.shape
        target = [min(int(n), COARSE_SAMPLES) for n in nshape]
        if self._kind == "numpy" and list(nshape) == target:
            return self
        x = self._values
        floating = np.dtype(self._values.dtype).kind == "f"
        if self._kind != "numpy":
            return self._coarse_by_chunks(progress_bar)
        xp = np  # chunked and lazy arrays took `_coarse_by_chunks` above
        whole = x
        coords = list(self._coords)
        for a in np.argsort([t / n for t, n in zip(target, nshape)]):  # biggest reduction first
            n, m = int(nshape[a]), target[a]
            if m == n:
                continue
            u = np.linspace(0.0, n - 1.0, m)
            i0 = np.minimum(np.floor(u).astype(np.int64), n - 2)
            t = (u - i0).reshape([-1 if k == a else 1 for k in range(4)])
            x = xp.take(x, i0, axis=a) * (1 - t) + xp.take(x, i0 + 1, axis=a) * t
            d = self.axes[a]
            di = _AXES.index(d)
            if coords[di] is not None:
                coords[di] = _sealed(np.interp(u, np.arange(n), coords[di]))
        if xp is not np:
            import dask

            # the only pass over every chunk: the +-inf counts ride along (the reads are shared)
            if floating:
                x, npos, nneg = dask.compute(x, xp.isposinf(whole).sum(), xp.isneginf(whole).sum())
                self._infinite = (int(npos), int(nneg), None)
            else:
                (x,) = dask.compute(x)
                self._infinite = (0, 0, None)
        x = np.asarray(x, dtype=np.float64 if np.dtype(self._values.dtype) != np.float32 else np.float32)
        x = np.ascontiguousarray(x)
        x.flags.writeable = False
        c = Field4D(x, axes=self.axes, extent=self.extent, name=self.name, units=self.units,
                    w_per_unit=self.w_per_unit, w_units=self.w_units, _coords=coords)
        c._coarse = c
        c._infinite_reported = True  # its infinities are the field's: reported by the field
        return c

    def _coarse_by_chunks(self, progress_bar: bool = False) -> "Field4D":
        """The coarse copy of a chunked or lazy array, read chunk by chunk: each chunk's share of
        the linear resampling (the same nodes and weights as for an array in memory) is added into
        the copy and the chunk dropped; the +-inf counts ride along."""
        vals = self._values
        nshape = tuple(int(n) for n in vals.shape)
        target = [min(n, COARSE_SAMPLES) for n in nshape]
        rd = _ChunkReader(vals, 0)  # no cache: every chunk once, then dropped
        nch = tuple(len(b) - 1 for b in rd.bounds)
        plans = []  # per axis, per chunk: (rows, local i0, has i0, local i0+1, has i0+1, 1-t, t), or rows only
        for a, (n, m) in enumerate(zip(nshape, target)):
            b = rd.bounds[a]
            per = []
            if m == n:
                for c in range(nch[a]):
                    per.append((np.arange(b[c], b[c + 1]),))
            else:
                u = np.linspace(0.0, n - 1.0, m)
                i0 = np.minimum(np.floor(u).astype(np.int64), n - 2)
                t = u - i0
                for c in range(nch[a]):
                    lo, hi = int(b[c]), int(b[c + 1])
                    in0 = (i0 >= lo) & (i0 < hi)
                    in1 = (i0 + 1 >= lo) & (i0 + 1 < hi)
                    rows = np.flatnonzero(in0 | in1)
                    per.append((rows, np.clip(i0[rows] - lo, 0, hi - lo - 1), in0[rows],
                                np.clip(i0[rows] + 1 - lo, 0, hi - lo - 1), in1[rows], 1.0 - t[rows], t[rows]))
            plans.append(per)
        order = [int(a) for a in np.argsort([t / n for t, n in zip(target, nshape)])]  # biggest reduction first
        out = np.zeros(target, dtype=np.float64)
        floating = np.dtype(vals.dtype).kind == "f"
        npos = nneg = 0
        total = math.prod(nch)
        chunk_bytes = math.prod(int(np.diff(b).max()) for b in rd.bounds) * rd.dtype.itemsize
        batch = max(1, min(CHUNK_BATCH, (64 * 1024**2) // max(1, chunk_bytes)))
        self.coarse_progress = (0, total)
        bar = None
        if progress_bar:
            from ..core.progress import progress

            bar = progress(total, f"coarse copy of {self.name or 'the field'} (chunks)")
        done = 0
        try:
            ids = list(np.ndindex(*nch))
            for b0 in range(0, total, batch):
                part = ids[b0:b0 + batch]
                got = rd.read(part)
                for idx in part:
                    x = got.pop(idx)
                    if floating:
                        inf = np.isinf(x)
                        if inf.any():
                            p = int(np.count_nonzero(inf & (x > 0)))
                            npos += p
                            nneg += int(np.count_nonzero(inf)) - p
                    rows = [None] * 4
                    for a in order:
                        plan = plans[a][idx[a]]
                        rows[a] = plan[0]
                        if len(plan) == 1 or not len(plan[0]):
                            continue
                        _, l0, m0, l1, m1, w0, w1 = plan
                        shp = [-1 if k == a else 1 for k in range(4)]
                        with np.errstate(invalid="ignore"):
                            A = np.take(x, l0, axis=a) * w0.reshape(shp)
                            B = np.take(x, l1, axis=a) * w1.reshape(shp)
                            x = np.where(m0.reshape(shp), A, 0.0) + np.where(m1.reshape(shp), B, 0.0)
                    if all(len(r) for r in rows):
                        out[np.ix_(*rows)] += x
                    del x
                    done += 1
                    self.coarse_progress = (done, total)
                    if bar is not None:
                        bar.update(1)
                del got
        finally:
            if bar is not None:
                bar.close()
        self._infinite = (npos, nneg, None) if floating else (0, 0, None)
        x = out.astype(np.float32) if np.dtype(vals.dtype) == np.float32 else out
        x.flags.writeable = False
        coords = list(self._coords)
        for a, (n, m) in enumerate(zip(nshape, target)):
            di = _AXES.index(self.axes[a])
            if m != n and coords[di] is not None:
                coords[di] = _sealed(np.interp(np.linspace(0.0, n - 1.0, m), np.arange(n), coords[di]))
        c = Field4D(x, axes=self.axes, extent=self.extent, name=self.name, units=self.units,
                    w_per_unit=self.w_per_unit, w_units=self.w_units, _coords=coords)
        c._coarse = c
        c._infinite_reported = True  # its infinities are the field's: reported by the field
        return c

    def _cap_scale(self, s, first_cut: bool = False) -> float:
        """K for one step's samples: the field's (`_statistics`), or, for a chunked or lazy array
        whose coarse copy is not ready, the 95th percentile of |grad f| within the first cut's
        samples (kept until the coarse copy is ready, so the pictures agree) -- with ``first_cut``
        (`Field4D.slice`; `slice_field` builds the coarse copy) or once K was taken so."""
        if (first_cut or self._k_first is not None) and self._stats is None and self._kind not in ("numpy", "function") and self._coarse is None:
            if self._k_first is None:
                u = _power_of_two_unit(self.size)
                inner = s.g > s.spacing  # both neighbours inside the box: no step to the zeros outside
                with np.errstate(invalid="ignore", over="ignore"):
                    grads = np.gradient(np.asarray(s.f, dtype=np.float32), s.spacing / u)
                    gm = np.sqrt(sum(g * g for g in grads))
                ok = np.isfinite(gm) & (gm > 0) & inner
                if ok.any():
                    self._k_first = float(np.percentile(gm[ok], 95)) / u
                else:
                    lo, hi = self._range_info()[0] if self._reader is not None and self._reader.reads else (0.0, 0.0)
                    span = hi - lo if math.isfinite(lo) and math.isfinite(hi) else 0.0
                    self._k_first = max(span, abs(hi) if math.isfinite(hi) else 0.0, 1.0) / (2 * self.size)
            return self._k_first
        return self._statistics()[1]

    def _statistics(self):
        """((min, max), K): `data_range` and a typical |grad f| (level units per slice unit)."""
        if self._stats is None:
            self._stats = (self.data_range, self._gradient_scale())
        return self._stats

    def _gradient_scale(self) -> float:
        """K, the 95th percentile of |grad f| in level units per slice unit, from `coarse` (a
        function's probe grid); from the data range when f is flat."""
        if self._kind == "function":
            m = _FUNCTION_PROBE
            a = self._probe_values()
            spacing = [(b - a_) / (m - 1) / u for (a_, b), u in zip(self.extent, self._unit)]
        else:
            c = self.coarse()
            self._report_infinite()
            if c is not self:  # the same numbers: computed on the coarse copy
                return c._statistics()[1]
            a = np.asarray(c._values, dtype=np.float32).transpose(c._axis_of)  # x, y, z, w order
            spacing = []
            for d in range(4):
                cd = c._coords[d]
                if cd is None:
                    lo, hi = c.extent[d]
                    spacing.append((hi - lo) / (a.shape[d] - 1) / c._unit[d])
                else:
                    spacing.append(np.asarray(cd) / c._unit[d])
        with np.errstate(invalid="ignore"):
            # spacings in units of the box's size (a power of two: exact), so a float32 gradient
            # neither overflows nor underflows at any scale; K is scaled back below
            u = _power_of_two_unit(self.size)
            grads = np.gradient(a, *[sp / u for sp in spacing])
            gm = np.sqrt(sum(g * g for g in grads))
        ok = np.isfinite(gm) & (gm > 0)
        if ok.any():
            return float(np.percentile(gm[ok], 95)) / u  # steep places: a phase field's plateaus must not set it
        rng = self.data_range
        span = rng[1] - rng[0] if math.isfinite(rng[0]) else 0.0
        return max(span, abs(rng[1]) if math.isfinite(rng[1]) else 0.0, 1.0) / (2 * self.size)

    def _report_infinite(self) -> None:
        """Warn once (`NonFiniteWarning`) when the data hold +inf or -inf: how many, and where
        (the first, for an array in memory).  Counted over the whole array: in blocks for numpy,
        alongside the coarse copy's pass for chunked and lazy arrays."""
        if self._infinite_reported:
            return
        self._infinite_reported = True
        if self._infinite is None:
            a = self._values
            self._infinite = _count_infinite(a) if np.dtype(a.dtype).kind == "f" else (0, 0, None)
        npos, nneg, first = self._infinite
        if npos == 0 and nneg == 0:
            return
        what = " and ".join(t for t in (f"{npos} +inf" if npos else "", f"{nneg} -inf" if nneg else "") if t)
        where = f" (the first at index {first} of {_axes_text(self.axes)})" if first is not None else ""
        warnings.warn(
            f"Field4D{' ' + repr(self.name) if self.name else ''}: the data hold {what} of "
            f"{math.prod(int(n) for n in self._values.shape)} samples{where}. They are kept: +inf lies above "
            f"and -inf below every level, the data range ignores them, and a point interpolated in a cell "
            f"that holds one is +-inf, or NaN (below every level) where two meet or its weight is 0. To draw them otherwise, mask or clip first, "
            f"e.g. np.where(np.isfinite(a), a, np.nan) or np.clip(a, lo, hi)",
            NonFiniteWarning, stacklevel=4)

    # -- readout -------------------------------------------------------------------
    def _readout(self, m, c0, slices, box, coarse) -> tuple:
        rows = []
        label = self.name or "field"
        rows.append(("field", f"{label}" + (f" [{self.units}]" if self.units else "")))
        if self._kind != "function":
            rows.append(("axes", f"{self._order_text()}, shape {tuple(int(n) for n in self._values.shape)}"))
        lo, hi = self.data_range
        parts = []
        for s in slices:
            t = f"{s.level:.4g}"
            above = self.inside == "above"
            if math.isfinite(hi) and (s.level > hi if above else s.level >= hi):
                t += " (above the max: empty)" if above else " (at or above the max: the whole box)"
            elif math.isfinite(lo) and (s.level <= lo if above else s.level < lo):
                t += " (at or below the min: the whole box)" if above else " (below the min: empty)"
            elif s.empty:
                t += " (empty here)"
            parts.append(t)
        where = self.data_range_source
        rng = (f" of {lo:.4g} \u2026 {hi:.4g}" + ("" if where == "data" else f" ({where})") if math.isfinite(lo)
               else " (all NaN)")
        rows.append(("level" if len(slices) == 1 else "levels", ", ".join(parts) + rng))
        if self.inside != "above" or not self.caps:
            rows.append(("surface", ("encloses f <= level" if self.inside == "below" else "encloses f >= level")
                         + ("" if self.caps else ", open on the box's faces (no volume)")))
        if len(slices) > 1:
            rows.append(("volumes", ", ".join(f"{s.volume:.4g}" for s in slices)))
        wu = f" {self.w_units}" if self.w_units else ""
        if len(box.vertices):
            p = np.column_stack([np.asarray(box.vertices), np.full(len(box.vertices), c0)])
            w = (p @ m)[:, 3] * self.w_per_unit + self._centre[3]
            rows.append(("w cut", f"{w.min():.4g} \u2026 {w.max():.4g}{wu} (data {self.extent[3][0]:.4g} \u2026 "
                                  f"{self.extent[3][1]:.4g})"))
        else:
            rows.append(("w cut", "none (w = c0 misses the data)"))
        per = self.space_units if self.space_units else "unit of space"
        rows.append(("w per unit", f"{self.w_per_unit:.4g}{wu} per {per}"))
        if coarse:
            rows.append(("resolution", f"{self.coarse_resolution} (coarse copy)"))
        return tuple(rows)

    def _order_text(self) -> str:
        """Which of x, y, z, w each array axis is: 'f[w, z, y, x]', with the dim names from xarray
        ('T[time, z, y, x] as [w, z, y, x]')."""
        if self._kind == "function":
            return "f(x, y, z, w)"
        if self._dims is not None:
            label = self.name or "f"
            return f"{label}[{', '.join(self._dims)}] as [{', '.join(self.axes)}]"
        return _axes_text(self.axes)

    def __repr__(self) -> str:
        if self._kind == "function":
            what = "function f(x, y, z, w)"
        else:
            kind = "array" if self._kind == "numpy" else f"{self._kind} array"
            what = f"{kind} {tuple(int(n) for n in self._values.shape)} {self._order_text()}"
        return f"Field4D({self.name or ''!s}{' ' if self.name else ''}{what}, axes={self.axes!r}, extent={self.extent})"


def _representable(s: FieldSlice):
    """The slice's volume, or None when it left float64's range (inf, or a non-empty surface whose
    volume underflowed: coordinates beyond about 1e102 or below about 1e-102)."""
    v = float(s.volume)
    if not math.isfinite(v) or (not s.empty and abs(v) < sys.float_info.min):
        return None
    return v


def _turned_slice(s: FieldSlice, t: np.ndarray) -> FieldSlice:
    if s.empty:
        return s
    return FieldSlice(_sealed(s.vertices @ t.T), s.triangles, _sealed(s.normals @ t.T), s.volume, s.area,
                      s.level, s.spacing)


class FieldSliceData(SliceData):
    """`SliceData` of a `Field4D`: ``extra["levels"]`` holds one `FieldSlice` per level and
    ``extra["box"]`` the exact cut of the data's box (a `rot4d_widget.geometry.slicing.Slice`);
    ``extra["data_frame"]`` the cut's matrix and c0 and the field's centre and units (`Field4D.slice`)."""

    def turned(self, t) -> "FieldSliceData":
        """The same slice turned by the 3-D rotation ``t`` (3, 3): the slice at ``T @ matrix``
        when T turns x, y, z only (points and normals ``@ t.T``; nothing is resampled).
        ``extra["box"]`` stays the unturned cut; ``extra["data_frame"]`` gets the turned matrix."""
        t = np.asarray(t, dtype=np.float64)
        if t.shape != (3, 3) or not np.allclose(t @ t.T, np.eye(3), atol=1e-9):
            raise ValueError(f"Expected `t` to be a (3, 3) rotation, got shape {t.shape}")
        extra = dict(self.extra)
        extra["levels"] = tuple(_turned_slice(s, t) for s in self.extra.get("levels", ()))
        if "data_frame" in extra:  # the slice at T @ matrix (T turning x, y, z only)
            t4 = np.eye(4)
            t4[:3, :3] = t
            extra["data_frame"] = {**extra["data_frame"], "matrix": _sealed(t4 @ extra["data_frame"]["matrix"])}
        return type(self).build(
            points=self.points @ t.T, segments=self.segments, triangles=self.triangles, groups=self.groups,
            normals=None if self.normals is None else self.normals @ t.T, volume=self.volume,
            readout=self.readout, convex=self.convex, show_points=self.show_points, extra=extra)


def _call(f, *arrays) -> np.ndarray:
    """``f(*arrays)`` validated: same shape as the inputs, real numbers -> float64."""
    out = f(*arrays)
    try:
        out = np.asarray(out)
    except Exception:
        raise TypeError(f"Expected the field function to return an array, got {type(out).__name__}") from None
    if out.dtype.kind not in "fiub":
        raise TypeError(f"Expected the field function to return real numbers (float, int or bool), got dtype {out.dtype}")
    if out.shape != arrays[0].shape:
        raise ValueError(
            f"Expected the field function to return one value per point, shape {arrays[0].shape}, got {out.shape} "
            "(write it with numpy operations on its arguments; for a constant use c + 0 * x)"
        )
    return out.astype(np.float64, copy=False)


# ----------------------------------------------------------------------------- one step
_BOX_CACHE: dict = {}


def _box_polytope(hw):
    from ..geometry.polytopes import Polytope

    key = tuple(float(v) for v in hw)
    p = _BOX_CACHE.get(key)
    if p is None:
        corners = np.array(list(itertools.product((-1.0, 1.0), repeat=4))) * np.asarray(hw)
        p = Polytope(corners, name="field box")
        if len(_BOX_CACHE) > 64:
            _BOX_CACHE.clear()
        _BOX_CACHE[key] = p
    return p


def _box_slice(field, m, c0):
    from ..geometry.slicing import slice_polytope

    return slice_polytope(_box_polytope(field._hw), m, c0)


class _Samples:
    """One step's samples: the grid (origin, spacing, shape) and f, g on it."""

    __slots__ = ("origin", "spacing", "f", "g", "k", "box")


#: A box face whose normal has less than this in-slice part is parallel to the slice: left out of g.
_PARALLEL = 1e-9


def _face_norms(m):
    """(4,) length of the in-slice part of each box face's normal, |m[:3, j]| (floored at _PARALLEL)."""
    return np.maximum(np.linalg.norm(m[:3, :], axis=0), _PARALLEL)


def _in_slice_distance(q, hw, m):
    """g = min_j (hw_j - |q_j|) / |m[:3, j]|: the signed distance, within the slice, to the planes
    where the box's faces cut it (positive inside).  Each term is the exact 3-D distance to its
    face's plane, so g is linear along grid lines near a face (the cap lands on it); faces parallel
    to the slice are left out (when the slice meets the box it lies between them)."""
    nrm = _face_norms(m)
    return np.minimum.reduce([(hw[j] - np.abs(q[j])) / nrm[j] for j in range(4) if nrm[j] > _PARALLEL])


def _geometric_nodes(field, d):
    """Slice-space coordinate (about the centre) of every node along data axis d."""
    n = field.shape[d]
    c = field._coords[d]
    if c is None:
        return np.linspace(-field._hw[d], field._hw[d], n)
    return (np.asarray(c) - field._centre[d]) / field._unit[d]


def _sample(field, m, c0, res, first_cut: bool = False) -> _Samples | None:
    """Resample ``field`` on the grid of one step, or None when w = c0 misses the box; with its
    cap scale K (`Field4D._cap_scale`: taken after the read, so a first cut needs nothing more)."""
    s = _sample_raw(field, m, c0, res)
    if s is not None:
        s.k = field._cap_scale(s, first_cut)
    return s


def _sample_raw(field, m, c0, res) -> _Samples | None:
    """`_sample` without K (``s.k`` None)."""
    box = _box_slice(field, m, c0)
    if box.dim < 3:
        return None
    bv = np.asarray(box.vertices)
    lo, hi = bv.min(axis=0), bv.max(axis=0)
    side = hi - lo
    L = float(side.max())
    if not L > 0:
        return None
    d = L / (res - 1)
    n = np.maximum(np.ceil(side / d - 1e-9).astype(np.int64) + 1, 2)
    origin = (lo + hi) / 2 - (n - 1) * d / 2 - d  # one sample of padding on each side
    n = n + 2
    s = _Samples()
    s.origin, s.spacing, s.box = origin, d, box
    s.k = None
    hw = field._hw
    p0 = np.array([origin[0], origin[1], origin[2], c0])
    if field._kind == "function":
        axes = [origin[a] + d * np.arange(n[a]) for a in range(3)]
        P = np.meshgrid(*axes, indexing="ij")
        q = [m[0, j] * P[0] + m[1, j] * P[1] + m[2, j] * P[2] + m[3, j] * c0 for j in range(4)]
        g = _in_slice_distance(q, hw, m)
        with np.errstate(all="ignore"):
            f = _call(field._function, *[q[j] * field._unit[j] + field._centre[j] for j in range(4)])
        s.f, s.g = f, g
        return s
    uniform = all(c is None for c in field._coords)
    # data axis j <-> array axis field._axis_of[j]
    if uniform:
        sc = np.array([(field.shape[j] - 1) / (2 * hw[j]) for j in range(4)])  # index steps per slice unit
        base_d = (m.T @ p0 + hw) * sc
        step_d = d * m[:3, :] * sc  # (3, 4): grid axis r -> data axis j
        base = np.empty(4)
        step = np.empty((3, 4))
        centre = np.empty(4)
        inv_s = np.empty(4)
        for j in range(4):
            a = field._axis_of[j]
            base[a] = base_d[j]
            step[:, a] = step_d[:, j]
            centre[a] = (field.shape[j] - 1) / 2
            inv_s[a] = 1.0 / (sc[j] * _face_norms(m)[j])
        halfn = np.where(_face_norms(m)[list(_AXES.index(c) for c in field.axes)] > _PARALLEL, centre, 1e300)
        if field._kind == "numpy":
            s.f, s.g = _resample_affine(field._values, base, step, n, centre, halfn, inv_s)
            return s
        # chunked or lazy: the same numbers, each touched chunk read once (memory stays bounded)
        ijk = np.indices(tuple(int(v) for v in n), dtype=np.float64).reshape(3, -1).T
        x = base[None, :] + ijk @ step  # (N, 4) index coordinates, array axis order
        g = ((halfn[None, :] - np.abs(x - centre[None, :])) * inv_s[None, :]).min(axis=1)
        s.f = _chunked_values(field, x, g >= 0.0).reshape(tuple(n))
        s.g = g.reshape(tuple(n))
        return s
    # uneven coordinates: points -> fractional indices by np.interp, then the points kernel
    axes = [origin[a] + d * np.arange(n[a]) for a in range(3)]
    P = np.meshgrid(*axes, indexing="ij")
    q = [(m[0, j] * P[0] + m[1, j] * P[1] + m[2, j] * P[2] + m[3, j] * c0).ravel() for j in range(4)]
    g = _in_slice_distance(q, hw, m)
    idx = np.empty((len(g), 4))
    for j in range(4):
        a = field._axis_of[j]
        idx[:, a] = np.interp(q[j], _geometric_nodes(field, j), np.arange(field.shape[j], dtype=np.float64))
    if field._kind == "numpy":
        f = _resample_points(field._values, idx, g >= 0)
    else:
        f = _chunked_values(field, idx, g >= 0)
    s.f, s.g = f.reshape(tuple(n)), g.reshape(tuple(n))
    return s


#: Points interpolated per pass of `_chunked_values` (its tables take ~2 KB per point).
CHUNKED_POINTS = 16384
#: Chunks read per call of the reader (one dask.compute: a distributed Client reads them in parallel).
CHUNK_BATCH = 32
#: Order a step's points by the chunk their cell starts in before cutting them into passes
#: (benchmarks/chunk_fetches.py compares both orders: fewer chunk fetches when the cache is small)
_SORT_PASSES = True
_CORNERS = np.array([(a, b, c, d) for a in (0, 1) for b in (0, 1) for c in (0, 1) for d in (0, 1)], dtype=np.int64)


def _chunked_values(field, x, inside):
    """Quadrilinear values of a chunked or lazy array at index points ``x`` (N, 4), where ``inside``.

    The same numbers as the kernels (clamped into the array, the last cell closed), but the
    array is never assembled: the 16 corners of every point's cell are grouped by the chunk
    they lie in and each chunk is read once per pass (through the field's chunk reader and its
    cache), ``CHUNK_BATCH`` at a time.  Memory: one pass's corner tables (``CHUNKED_POINTS``
    points) plus a batch of chunks, whatever the array's size.  0 outside.
    """
    if field._reader is None:
        field._reader = _ChunkReader(field._values, field.chunk_cache_bytes)
    rd = field._reader
    shape = np.array(rd.shape, dtype=np.int64)
    nch = tuple(len(b) - 1 for b in rd.bounds)
    out = np.zeros(len(x), dtype=np.float64)
    todo = np.flatnonzero(inside)
    if _SORT_PASSES and len(todo) > CHUNKED_POINTS:  # passes in the order of the chunk each point's cell starts in:
        # a chunk's points fall in one or two consecutive passes, so it is read once, not once per
        # pass that touches it after the cache let it go (the same values: each point on its own)
        i0 = np.minimum(np.clip(x[todo], 0.0, (shape - 1).astype(np.float64)).astype(np.int64), shape - 2)
        cid = [np.searchsorted(rd.bounds[a], i0[:, a], side="right") - 1 for a in range(4)]
        todo = todo[np.argsort(np.ravel_multi_index(tuple(cid), nch), kind="stable")]
    for p0 in range(0, len(todo), CHUNKED_POINTS):
        rows = todo[p0:p0 + CHUNKED_POINTS]
        xc = np.clip(x[rows], 0.0, (shape - 1).astype(np.float64))
        i0 = np.minimum(xc.astype(np.int64), shape - 2)
        t = xc - i0
        corner = (i0[:, None, :] + _CORNERS[None]).reshape(-1, 4)  # (16 M, 4)
        weight = np.prod(np.where(_CORNERS[None] == 1, t[:, None, :], 1.0 - t[:, None, :]), axis=2).ravel()
        cid = np.stack([np.searchsorted(rd.bounds[a], corner[:, a], side="right") - 1 for a in range(4)], axis=1)
        key = np.ravel_multi_index(tuple(cid.T), nch)
        order = np.argsort(key, kind="stable")
        keys, first = np.unique(key[order], return_index=True)
        last = np.r_[first[1:], len(order)]
        vals = np.empty(len(key), dtype=np.float64)
        for b0 in range(0, len(keys), CHUNK_BATCH):
            ids = [tuple(int(v) for v in np.unravel_index(k, nch)) for k in keys[b0:b0 + CHUNK_BATCH]]
            got = rd.read(ids)
            for idx, lo, hi in zip(ids, first[b0:b0 + CHUNK_BATCH], last[b0:b0 + CHUNK_BATCH]):
                sel = order[lo:hi]
                local = corner[sel] - np.array([rd.bounds[a][idx[a]] for a in range(4)], dtype=np.int64)
                vals[sel] = got[idx][local[:, 0], local[:, 1], local[:, 2], local[:, 3]]
        out[rows] = (vals * weight).reshape(-1, 16).sum(axis=1)
    return out


def _surface(s: _Samples, level: float, inside: str = "above", caps: bool = True) -> FieldSlice:
    """Marching cubes of min(±(f - level), K g) = 0 on one step's samples (+ for inside="above",
    - for "below"); without caps, of ±(f - level) alone within the box (an open surface)."""
    from skimage.measure import marching_cubes

    d = s.spacing
    sign = 1.0 if inside == "above" else -1.0
    with np.errstate(invalid="ignore"):
        v = sign * (s.f - level)
        v[v == 0] = 1e-9 * s.k * d  # f == level belongs to the enclosed side
        v[np.isnan(v)] = -s.k * d  # NaN: never enclosed (below every level for inside="above")
        out = s.g < 0
        if caps:
            v[out] = np.inf  # outside the box f means nothing: v is K g alone, so caps sit on the faces
            v = np.minimum(v, s.k * s.g).astype(np.float32)
        else:
            v = v.astype(np.float32)
    mask = None
    if not caps:
        if out.all():
            return _empty_slice(level, d)
        if out.any():
            # outside the box: the nearest inside sample's value (so cells across a face see the data
            # carried on, not zeros); cells wholly outside are skipped; triangles beyond the faces dropped
            from scipy.ndimage import binary_dilation, distance_transform_edt

            idx = distance_transform_edt(out, return_distances=False, return_indices=True)
            v = v[tuple(idx)]
            mask = binary_dilation(~out, structure=np.ones((3, 3, 3), dtype=bool))
        if not (v.max() > 0 and v.min() < 0):
            return _empty_slice(level, d)
    elif not v.max() > 0:
        return _empty_slice(level, d)
    # in index space (spacing 1): skimage scales in float32, which overflows beyond ~3e38; the
    # vertices, volume and area are scaled here in float64, so any field scale works alike
    try:
        verts, faces, normals, _ = marching_cubes(v, 0.0, method="lewiner", mask=mask)
    except (ValueError, RuntimeError):
        if caps:
            raise
        return _empty_slice(level, d)  # no crossing within the box
    if not caps and len(faces):
        from scipy.ndimage import map_coordinates

        gc = map_coordinates(s.g, verts[faces].mean(axis=1).T, order=1, mode="nearest")
        faces = faces[gc >= 0]  # keep triangles centred in the box: the open edge lies within a cell of a face
        used = np.unique(faces)
        remap = np.full(len(verts), -1, dtype=np.int64)
        remap[used] = np.arange(len(used))
        verts, normals, faces = verts[used], normals[used], remap[faces]
    if len(faces) == 0:
        return _empty_slice(level, d)
    iv = verts.astype(np.float64)  # index coordinates
    vertices = iv * d + s.origin
    tri = faces.astype(np.intp)
    # skimage (gradient 'descent') winds faces clockwise seen from the low side: flip to CCW
    tri = tri[:, ::-1].copy()
    nrm = normals.astype(np.float64)  # skimage's normals (gradient 'descent') point out of {f >= level}
    ln = np.linalg.norm(nrm, axis=1)
    bad = ~(ln > 1e-12)
    if bad.any():
        fn = np.cross(iv[tri[:, 1]] - iv[tri[:, 0]], iv[tri[:, 2]] - iv[tri[:, 0]])
        acc = np.zeros_like(iv)
        for c in range(3):
            for axis in range(3):
                acc[:, axis] += np.bincount(tri[:, c], weights=fn[:, axis], minlength=len(vertices))
        nrm[bad] = acc[bad]
        ln = np.linalg.norm(nrm, axis=1)
        still = ~(ln > 1e-300)
        nrm[still] = (0.0, 0.0, 1.0)
        ln[still] = 1.0
    nrm /= ln[:, None]
    # volume and area in index units (of order resolution**3 and **2), then times d**3 and d**2:
    # only a result beyond float64's range over- or underflows (inf, 0), never the products
    c = iv.mean(axis=0)
    A, B, C = (iv - c)[tri[:, 0]], (iv - c)[tri[:, 1]], (iv - c)[tri[:, 2]]
    cr = np.cross(B - A, C - A)
    volume = float(np.einsum("ij,ij->", A, np.cross(B, C))) / 6.0 * d * d * d if caps else math.nan
    area = float(np.linalg.norm(cr, axis=1).sum()) / 2.0 * d * d
    return FieldSlice(_sealed(vertices), _sealed(tri), _sealed(nrm), volume, area, level, d)


def slice_field(field, matrix, c0, level, resolution: int = 64, *, coarse: bool = False):
    """Isosurfaces of ``field`` (a `Field4D`) in the slice w = ``c0`` after the rotation ``matrix``.

    Parameters
    ----------
    field : Field4D
    matrix : (4, 4) rotation (validated: orthogonal, det +1); a data point q is at
        ``matrix @ (q - centre)`` (w scaled by ``1 / field.w_per_unit``)
    c0 : float -- the hyperplane w = c0, in the data's w units (`Field4D.w_frame`: at rest
        c0 = 30 cuts the data at w = 30)
    level : float or sequence of floats -- the surface closes {f >= level} (``field.inside``
        "above", the default) or {f <= level} ("below"); capped on the box's faces unless
        ``field.caps`` is False
    resolution : int -- samples along the longest side of the bounding box of the
        box's cut (padding not counted), same spacing on all three axes
    coarse : bool -- resample ``field.coarse()`` instead (for held keys)

    Returns
    -------
    `FieldSlice`, or a tuple of them (one per level, sharing one resampling) when
    ``level`` is a sequence.
    """
    if not isinstance(field, Field4D):
        raise TypeError(f"Expected `field` to be a Field4D, got {type(field).__name__}")
    return _slice_offset(field, matrix, field.offset(c0), level, resolution, coarse=coarse)


def _slice_offset(field, matrix, d, level, resolution, *, coarse):
    """`slice_field` at the offset ``d`` (slice units) instead of c0."""
    m = as_rotation_matrix(matrix)
    many = not isinstance(level, (numbers.Real, np.integer, np.floating)) or isinstance(level, (bool, np.bool_))
    levels = _as_levels(level)
    res = _check_resolution(resolution)
    src = field.coarse() if coarse else field
    s = _sample(src, m, d, res)
    if s is None:
        out = tuple(_empty_slice(lv, 0.0) for lv in levels)
    else:
        out = tuple(_surface(s, lv, field.inside, field.caps) for lv in levels)
    return out if many else out[0]
