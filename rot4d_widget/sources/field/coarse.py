"""What a `Field4D` keeps in memory: the coarse copy -- at most `COARSE_SAMPLES` nodes per axis
over the same box, for held keys and for the data range of a chunked array -- and, for a chunked
or lazy array that fits the field's memory budget (`MEMORY_BUDGET`), the whole array.

`CoarseCopy` builds them once, in one pass over the data: now (`get`), or on a daemon thread
(`prepare`, counted by a `rot4d_widget.core.progress.Progress`).  The pass reads the array chunk by
chunk (an array in memory in blocks of 16 samples a side); each chunk's share of the linear
resampling onto evenly spaced fractional indices is added into the copy (memory: the copy plus a
few chunks) and, when the array fits the budget, the chunk is copied into the array being loaded;
+-inf samples of a chunked array are counted on the way.  Once loaded, a field's steps run on the
array in memory (`Field4D.resident`): as fast as data given in memory.
"""

from __future__ import annotations

import math
import threading

import numpy as np

from ...core._arrays import sealed as _sealed
from ...core.progress import progress
from .checks import AXES
from .chunks import CHUNK_BATCH, ChunkReader

__all__ = ["COARSE_SAMPLES", "MEMORY_BUDGET", "CoarseCopy"]

#: Nodes per axis, at most, of the in-memory coarse copy (`Field4D.coarse`).
COARSE_SAMPLES = 48

#: Bytes a chunked or lazy array may take in memory (float32 kept, other types as float64) to be read
#: whole by the background read (`Field4D.memory_budget`, settable per field): 1 GiB.  Bigger data keep
#: the coarse copy and read, for a full step, only the chunks its samples touch.
MEMORY_BUDGET = 1024**3

#: Samples a side of the blocks an array in memory is resampled in (its coarse copy: the same numbers
#: as a chunked array's, a third of the time of whole-array resampling at 64^4, and little memory).
_BLOCK = 16


class CoarseCopy:
    """The coarse copy of ``field`` (`copy` once built; `get` builds it or waits for the build) and,
    when the field is chunked or lazy and fits its memory budget, the whole array (`loaded`).

    ``counted((n +inf, n -inf, None, NaN per w step))`` receives the non-finite counts of a chunk-by-chunk build of a
    chunked array not loaded (a loaded one, or one in memory, is counted by the field itself);
    ``progress``: (chunks done, chunks in all) of that build once it started; ``counter``: the
    `Progress` of the background read (`prepare`); ``error``: what made it fail."""

    def __init__(self, field, counted):
        self._field = field
        self._counted = counted
        self.copy = None
        #: the whole array in memory once the read made it (float32 or float64, read-only), else None
        self.loaded = None
        self._lock = threading.Lock()
        self._thread = None  # the background build (`prepare`)
        self.counter = None
        self.error = None
        self.progress = None

    @property
    def ready(self) -> bool:
        return self.copy is not None

    def get(self):
        """The copy, built now when nobody started it (the array loaded in the same pass when it fits
        the budget), else when the background build ends (RuntimeError from its error when it
        failed)."""
        if self.copy is None:
            with self._lock:
                t = self._thread
                if self.copy is None and t is None:
                    self._run(self._load_wanted(), None)
            if t is not None:
                t.join()
                if self.copy is None:
                    raise RuntimeError("Field4D: building the coarse copy failed") from self.error
        return self.copy

    def _load_wanted(self) -> bool:
        f = self._field
        return f.kind not in ("numpy", "function") and self.loaded is None and f.fits_in_memory

    def prepare(self, show_progress: bool = True):
        """Start the background read on a daemon thread: the coarse copy and, when the field fits its
        budget, the whole array, in one pass.  Returns its `Progress` (the running one when it was
        started before; created here, in the caller's thread, so that the kernel's bar goes to the
        caller's cell: ``show_progress``), or None when there is nothing to read."""
        with self._lock:
            t = self._thread
            if t is not None:
                return self.counter if t.is_alive() else None
            load = self._load_wanted()
            if self.copy is not None and not load:
                return None
            f = self._field
            if f.kind == "function" or (f.kind == "numpy" and max(f.values.shape) <= COARSE_SAMPLES):
                self.copy = f  # its own coarse copy: nothing to read
                return None
            total = _count(_reader(f.values, load))
            if load and self.copy is None:  # then the copy, from memory, in blocks
                total += math.prod(-(-int(n) // _BLOCK) for n in f.values.shape)
            what = (f"reading {f.name or 'the field'} into memory" if load
                    else f"coarse copy of {f.name or 'the field'}")
            self.counter = progress(total, what, mode=None if show_progress else "none",
                                    reserve=bool(show_progress))
            t = threading.Thread(target=self._build, args=(load, self.counter), daemon=True,
                                 name=f"rot4d background read {f.name or ''}".strip())
            self._thread = t
        t.start()
        return self.counter

    def _build(self, load: bool, counter) -> None:
        try:
            self._run(load, counter)
        except BaseException as e:  # noqa: BLE001 - kept for `get` to raise
            self.error = e
        finally:
            counter.close()

    def _run(self, load: bool, counter) -> None:
        """One pass over the data: the coarse copy (unless built) and, with ``load``, the whole array
        -- read first (large reads), the copy then made from it in memory, block by block (the
        same numbers; resampling large slabs at once is slower than the read)."""
        f = self._field
        if not load:
            self.copy = self._make(counter)
            return
        vals = f.values
        rd = _reader(vals, True)
        whole = np.empty(tuple(int(n) for n in vals.shape), dtype=rd.dtype)
        self._by_chunks(counter, rd, into=whole, coarse=False)
        whole.flags.writeable = False
        copy = None if self.copy is not None else self._by_chunks(counter, _reader(whole, False))
        f.drop_chunk_cache()  # steps read the array in memory from now on
        self.loaded = whole  # before the copy: once `ready`, steps find the data in memory
        if copy is not None:
            self.copy = copy

    def building(self) -> bool:
        """True while the background build runs."""
        t = self._thread
        return self.copy is None and t is not None and t.is_alive()

    def _copy(self, x, coords):
        f = self._field
        return type(f)(x, axes=f.axes, extent=f.extent, name=f.name, units=f.units,
                       w_per_unit=f.w_per_unit, w_units=f.w_units, _coords=coords, _copy_of=f)

    def _make(self, counter=None):
        f = self._field
        if f.kind == "function":
            return f
        nshape = f.values.shape
        target = [min(int(n), COARSE_SAMPLES) for n in nshape]
        if f.kind == "numpy" and list(nshape) == target:
            return f
        return self._by_chunks(counter, _reader(f.values, False), report=f.kind != "numpy")

    def _by_chunks(self, counter, rd, into=None, coarse: bool = True, report: bool = False):
        """The coarse copy of the field's array read chunk by chunk through ``rd`` (a `ChunkReader`
        without cache): each chunk's share of the linear resampling (evenly spaced fractional
        indices, axis by axis, the biggest reduction first) is added into the copy and the chunk
        dropped -- or first copied into ``into`` (the whole array, being loaded).  The +-inf counts
        ride along, reported with ``report`` (a chunked array not loaded: the only pass over its
        data; one in memory is counted by the field, where the first one is too).  ``coarse``
        False: only copy into ``into``; returns None then."""
        f = self._field
        vals = f.values
        nshape = tuple(int(n) for n in vals.shape)
        target = [min(n, COARSE_SAMPLES) for n in nshape]
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
        w_axis = f.axis_of[3]
        nan_w = np.zeros(nshape[w_axis], dtype=np.int64)  # NaN per w step: blocks of missing data
        total = math.prod(nch)
        chunk_bytes = math.prod(int(np.diff(b).max()) for b in rd.bounds) * rd.dtype.itemsize
        batch = max(1, min(CHUNK_BATCH, (64 * 1024**2) // max(1, chunk_bytes)))
        self.progress = (0, total)
        done = 0
        ids = list(np.ndindex(*nch))
        for b0 in range(0, total, batch):
            part = ids[b0:b0 + batch]
            got = rd.read(part)
            for idx in part:
                x = got.pop(idx)
                if into is not None:
                    into[rd.chunk_slices(idx)] = x
                if coarse:
                    if floating:
                        nan = np.isnan(x)
                        if nan.any():
                            nan_w[rd.chunk_slices(idx)[w_axis]] += nan.sum(
                                axis=tuple(ax for ax in range(nan.ndim) if ax != w_axis))
                        inf = np.isinf(x)
                        if inf.any():
                            p = int(np.count_nonzero(inf & (x > 0)))
                            npos += p
                            nneg += int(np.count_nonzero(inf)) - p
                    _add_share(out, x, idx, plans, order)
                del x
                done += 1
                self.progress = (done, total)
            del got
            if counter is not None:  # once a batch: the count a bar shows is never a batch behind
                counter.update(len(part))
        if not coarse:
            return None
        if report:
            self._counted((npos, nneg, None, nan_w))
        x = out.astype(np.float32) if np.dtype(vals.dtype) == np.float32 else out
        x.flags.writeable = False
        coords = list(f.coords)
        for a, (n, m) in enumerate(zip(nshape, target)):
            di = AXES.index(f.axes[a])
            if m != n and coords[di] is not None:
                coords[di] = _sealed(np.interp(np.linspace(0.0, n - 1.0, m), np.arange(n), coords[di]))
        return self._copy(x, coords)


def _add_share(out, x, idx, plans, order) -> None:
    """Add chunk ``idx``'s values ``x`` to the coarse copy ``out``: its share of the linear
    resampling along each axis (``plans``: per axis, per chunk, the copy's rows it reaches and their
    local nodes and weights), the axes in ``order``."""
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


def _count(rd: ChunkReader) -> int:
    return math.prod(len(b) - 1 for b in rd.bounds)


def _reader(values, load: bool) -> ChunkReader:
    """A reader without cache for one pass over ``values``: the array's own chunks; for an array in
    memory blocks of `_BLOCK` samples a side; for a lazy array without a chunk grid that is being
    loaded, slabs along its first axis of about 16 MB (fewer, larger reads of the file)."""
    if isinstance(values, np.ndarray):
        return ChunkReader(values, 0, block=(_BLOCK,) * 4)
    rd = ChunkReader(values, 0)
    if load and not rd.chunked:
        shape = tuple(int(n) for n in values.shape)
        per = max(1, (16 * 1024**2) // max(1, math.prod(shape[1:]) * rd.dtype.itemsize))
        rd = ChunkReader(values, 0, block=(min(per, shape[0]),) + shape[1:])
    return rd
