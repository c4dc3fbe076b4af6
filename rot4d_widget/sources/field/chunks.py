"""Chunked and lazy 4-D arrays (dask, zarr, an xarray backend's lazy array): read chunk by chunk.

`ChunkReader` reads the chunks a step needs, keeping recent ones up to a byte budget;
`chunked_values` interpolates at index points from those chunks alone (the array is never
assembled), the same numbers as the resampling kernels.
"""

from __future__ import annotations

import collections
import math
import threading

import numpy as np

__all__ = ["CHUNKED_POINTS", "CHUNK_BATCH"]


def array_kind(values) -> str:
    if isinstance(values, np.ndarray):
        return "numpy"
    mod = type(values).__module__ or ""
    if mod.startswith("dask.") and hasattr(values, "to_delayed"):
        return "dask"
    if mod.startswith("zarr"):
        return "zarr"
    return "lazy"


class ChunkReader:
    """Reads chunks of a lazy 4-D array (dask, zarr, anything sliceable) and keeps recent ones.

    The chunks are the array's own (dask's chunks, a zarr array's chunk shape; ``chunked`` True),
    else blocks of ``block`` samples (default 16 a side).  ``chunk_slices(idx)`` is where chunk
    ``idx`` lies in the array."""

    def __init__(self, values, cache_bytes: int, block=None):
        self.values = values
        self.kind = array_kind(values)
        shape = tuple(int(s) for s in values.shape)
        chunks = getattr(values, "chunks", None)
        bounds = None
        if block is not None and self.kind == "dask":
            raise ValueError("A dask array is read by its own chunks, not by blocks")
        if block is not None:
            bounds = [np.unique(np.r_[np.arange(0, n, int(c)), n]).astype(np.int64) for n, c in zip(shape, block)]
        elif self.kind == "dask":
            bounds = [np.concatenate([[0], np.cumsum(c)]).astype(np.int64) for c in chunks]
        elif isinstance(chunks, tuple) and len(chunks) == 4 and all(isinstance(c, (int, np.integer)) for c in chunks):
            bounds = [np.unique(np.r_[np.arange(0, n, int(c)), n]).astype(np.int64) for n, c in zip(shape, chunks)]
        elif isinstance(chunks, tuple) and len(chunks) == 4 and all(isinstance(c, tuple) for c in chunks):
            bounds = [np.concatenate([[0], np.cumsum(c)]).astype(np.int64) for c in chunks]
        #: the array's own chunk grid is used (not blocks chosen here)
        self.chunked = bounds is not None and block is None
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

    def chunk_slices(self, idx):
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
                import dask  # optional: only a dask array comes here

                if self._delayed is None:
                    self._delayed = self.values.to_delayed()
                parts = dask.compute(*[self._delayed[idx] for idx in missing])
            else:
                parts = [self.values[self.chunk_slices(idx)] for idx in missing]
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


#: Points interpolated per pass of `chunked_values` (its tables take ~2 KB per point).
CHUNKED_POINTS = 16384
#: Chunks read per call of the reader (one dask.compute: a distributed Client reads them in parallel).
CHUNK_BATCH = 32
_CORNERS = np.array([(a, b, c, d) for a in (0, 1) for b in (0, 1) for c in (0, 1) for d in (0, 1)], dtype=np.int64)


def chunked_values(rd: ChunkReader, x, inside, sort_passes: bool = True):
    """Quadrilinear values of a chunked or lazy array at index points ``x`` (N, 4), where ``inside``.

    The same numbers as the kernels (clamped into the array, the last cell closed), but the
    array is never assembled: the 16 corners of every point's cell are grouped by the chunk
    they lie in and each chunk is read once per pass (through the field's chunk reader and its
    cache), ``CHUNK_BATCH`` at a time.  Memory: one pass's corner tables (``CHUNKED_POINTS``
    points) plus a batch of chunks, whatever the array's size.  0 outside.  ``rd``: the field's
    chunk reader; ``sort_passes``: order the points by the chunk their cell starts in first.
    """
    shape = np.array(rd.shape, dtype=np.int64)
    nch = tuple(len(b) - 1 for b in rd.bounds)
    out = np.zeros(len(x), dtype=np.float64)
    todo = np.flatnonzero(inside)
    if sort_passes and len(todo) > CHUNKED_POINTS:  # passes in the order of the chunk each point's cell starts in:
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
