"""The coarse copy of a `Field4D`: in memory, at most `COARSE_SAMPLES` nodes per axis over the
same box, for held keys and for the data range of a chunked array.

`CoarseCopy` builds it once (linear resampling onto evenly spaced fractional indices): now, or on
a daemon thread (`prepare`), reading a chunked or lazy array chunk by chunk (memory: the copy
plus a few chunks), counting its +-inf samples on the way.
"""

from __future__ import annotations

import math
import threading

import numpy as np

from ..core._arrays import sealed as _sealed
from ..core.progress import progress
from .chunks import CHUNK_BATCH, _ChunkReader
from .field_checks import _AXES

__all__ = ["COARSE_SAMPLES", "CoarseCopy"]

#: Nodes per axis, at most, of the in-memory coarse copy (`Field4D.coarse`).
COARSE_SAMPLES = 48


class CoarseCopy:
    """The coarse copy of ``field`` (`copy` once built; `get` builds it or waits for the build).

    ``counted((n +inf, n -inf, None))`` receives the +-inf counts of a chunk-by-chunk build;
    ``progress``: (chunks done, chunks in all) of that build once it started; ``error``: what
    made the background build fail."""

    def __init__(self, field, counted):
        self._field = field
        self._counted = counted
        self.copy = None
        #: the whole array in memory once the background read made it (else None)
        self.loaded = None
        self._lock = threading.Lock()
        self._thread = None  # the background build (`prepare`)
        self.error = None
        self.progress = None

    @property
    def ready(self) -> bool:
        return self.copy is not None

    def get(self):
        """The copy, built now when nobody started it, else when the background build ends
        (RuntimeError from its error when it failed)."""
        if self.copy is None:
            with self._lock:
                t = self._thread
                if self.copy is None and t is None:
                    self.copy = self._make()
            if t is not None:
                t.join()
                if self.copy is None:
                    raise RuntimeError("Field4D: building the coarse copy failed") from self.error
        return self.copy

    def prepare(self, show_progress: bool = True) -> None:
        """Start the build on a daemon thread (nothing when built or being built)."""
        with self._lock:
            if self.copy is not None or self._thread is not None:
                return
            t = threading.Thread(target=self._build, args=(bool(show_progress),), daemon=True,
                                 name=f"rot4d coarse copy {self._field.name or ''}".strip())
            self._thread = t
        t.start()

    def _build(self, show: bool) -> None:
        try:
            c = self._make(progress_bar=show)
            self.copy = c
        except BaseException as e:  # noqa: BLE001 - kept for `get` to raise
            self.error = e

    def building(self) -> bool:
        """True while the background build runs."""
        t = self._thread
        return self.copy is None and t is not None and t.is_alive()

    def _copy(self, x, coords):
        f = self._field
        return type(f)(x, axes=f.axes, extent=f.extent, name=f.name, units=f.units,
                       w_per_unit=f.w_per_unit, w_units=f.w_units, _coords=coords, _copy_of=f)

    def _make(self, progress_bar: bool = False):
        f = self._field
        if f.kind == "function":
            return f
        nshape = f.values.shape
        target = [min(int(n), COARSE_SAMPLES) for n in nshape]
        if f.kind == "numpy" and list(nshape) == target:
            return f
        if f.kind != "numpy":
            return self._by_chunks(progress_bar)
        x = f.values
        coords = list(f.coords)
        for a in np.argsort([t / n for t, n in zip(target, nshape)]):  # biggest reduction first
            n, m = int(nshape[a]), target[a]
            if m == n:
                continue
            u = np.linspace(0.0, n - 1.0, m)
            i0 = np.minimum(np.floor(u).astype(np.int64), n - 2)
            t = (u - i0).reshape([-1 if k == a else 1 for k in range(4)])
            x = np.take(x, i0, axis=a) * (1 - t) + np.take(x, i0 + 1, axis=a) * t
            di = _AXES.index(f.axes[a])
            if coords[di] is not None:
                coords[di] = _sealed(np.interp(u, np.arange(n), coords[di]))
        x = np.asarray(x, dtype=np.float64 if np.dtype(f.values.dtype) != np.float32 else np.float32)
        x = np.ascontiguousarray(x)
        x.flags.writeable = False
        return self._copy(x, coords)

    def _by_chunks(self, progress_bar: bool = False):
        """The coarse copy of a chunked or lazy array, read chunk by chunk: each chunk's share of
        the linear resampling (the same nodes and weights as for an array in memory) is added into
        the copy and the chunk dropped; the +-inf counts ride along."""
        f = self._field
        vals = f.values
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
        self.progress = (0, total)
        bar = None
        if progress_bar:
            bar = progress(total, f"coarse copy of {f.name or 'the field'} (chunks)")
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
                    self.progress = (done, total)
                    if bar is not None:
                        bar.update(1)
                del got
        finally:
            if bar is not None:
                bar.close()
        self._counted((npos, nneg, None) if floating else (0, 0, None))
        x = out.astype(np.float32) if np.dtype(vals.dtype) == np.float32 else out
        x.flags.writeable = False
        coords = list(f.coords)
        for a, (n, m) in enumerate(zip(nshape, target)):
            di = _AXES.index(f.axes[a])
            if m != n and coords[di] is not None:
                coords[di] = _sealed(np.interp(np.linspace(0.0, n - 1.0, m), np.arange(n), coords[di]))
        return self._copy(x, coords)
