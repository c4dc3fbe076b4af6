"""What a `Field4D` knows of its values: the data range and where it comes from, K (a typical
|grad f|, the scale of the caps on the box's faces) and the report of +-inf samples.

`FieldStatistics` keeps them for one field, computed once when first needed: from the metadata,
the array in memory, the coarse copy (a chunked or lazy array), the chunks read so far (the
"first cut", until the coarse copy is ready) or a function's probe grid.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from ...geometry.mesh import power_of_two_unit
from ..protocol import w_span_text, w_value_text
from .checks import NonFiniteWarning, axes_text, checked_call
from .slicing import slice_samples_raw

#: Nodes per axis of the grid a function field is sampled on for its range.
_FUNCTION_PROBE = 21


#: A step of w (a time step) whose samples are NaN beyond this fraction, more than in the step with
#: fewest, is reported (`FieldStatistics.report_nonfinite`): a block of missing data (a failed write,
#: a gap), not a mask that every step shares nor a stray NaN.
NAN_BLOCK_FRACTION = 0.01


def _count_nonfinite(a, w_axis: int, block_bytes: int = 64 * 1024**2):
    """(n +inf, n -inf, first +-inf index as a tuple or None, NaN per w step (nw,) int64) of an
    array in memory, read in blocks along its first axis (at most ``block_bytes`` of booleans at a
    time); ``w_axis``: the array axis that is w."""
    npos = nneg = 0
    first = None
    nan_w = np.zeros(int(a.shape[w_axis]), dtype=np.int64)
    per = max(1, int(block_bytes // max(1, math.prod(int(n) for n in a.shape[1:]))))
    for i in range(0, int(a.shape[0]), per):
        b = np.asarray(a[i:i + per])
        nan = np.isnan(b)
        if nan.any():
            counts = nan.sum(axis=tuple(ax for ax in range(nan.ndim) if ax != w_axis))
            if w_axis == 0:
                nan_w[i:i + len(counts)] += counts
            else:
                nan_w += counts
        inf = np.isinf(b)
        if not inf.any():
            continue
        pos = int(np.count_nonzero(inf & (b > 0)))
        npos += pos
        nneg += int(np.count_nonzero(inf)) - pos
        if first is None:
            j = np.unravel_index(int(np.flatnonzero(inf.ravel())[0]), inf.shape)
            first = (i + int(j[0]),) + tuple(int(v) for v in j[1:])
    return npos, nneg, first, nan_w


def _runs(idx) -> list:
    """Runs of consecutive integers in the sorted ``idx``: [(first, last), ...]."""
    out = []
    for i in (int(v) for v in idx):
        if out and i == out[-1][1] + 1:
            out[-1] = (out[-1][0], i)
        else:
            out.append((i, i))
    return out


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


class FieldStatistics:
    """The data range, K and the +-inf report of one `Field4D` (``field``), each found once.

    ``meta_range``: (lo, hi, where) from the data's metadata, or None; ``infinite``: (n +inf,
    n -inf, first index or None, NaN per w step) once counted (the coarse copy's pass counts them
    for a chunked array: `counted`); ``infinite_reported``: the warning was given (or is the
    original field's, for a coarse copy)."""

    def __init__(self, field, meta_range=None):
        self._field = field
        self.meta_range = meta_range
        self._range = None  # ((lo, hi), where the range comes from), once known
        self._stats = None  # ((lo, hi), K), once known (K is per slice unit)
        self._k_first = None  # K from the first cut's samples, until the coarse copy is ready
        self._probe = None
        self.infinite = None
        self.infinite_reported = False

    def counted(self, infinite) -> None:
        """The coarse copy's pass (the background read of a chunked or lazy array) counted the
        non-finite samples: ``(n +inf, n -inf, None, NaN per w step)``; reported at once
        (`report_nonfinite`: a warning and the readout's "missing" row) when there are any."""
        self.infinite = infinite
        self.report_nonfinite()

    def forget_k(self) -> None:
        """K is per slice unit: forgotten when `Field4D.w_per_unit` changes."""
        self._stats = None
        self._k_first = None

    def set_statistics(self, stats) -> None:
        """Use ``((lo, hi), K)`` as this field's (a test comparing two fields with the same caps)."""
        self._stats = stats

    def _first_cut_range(self, first_cut: bool):
        """((lo, hi), "first cut") from the chunks read so far while the coarse copy is not ready
        (with ``first_cut``, reading the cut at rest when nothing was read yet), else None."""
        f = self._field
        if self._range is not None or self.meta_range is not None or f.kind in ("function", "numpy"):
            return None
        if f.coarse_ready:
            return None
        rd = f.reader
        if (rd is None or rd.reads == 0) and first_cut:
            slice_samples_raw(f, np.eye(4), 0.0, f.resolution)  # the picture at rest: its chunks only
            rd = f.reader
        if rd is None or rd.reads == 0:
            return None
        lo, hi = rd.seen
        return ((lo, hi) if lo <= hi else (math.nan, math.nan)), "first cut"

    def range_info(self, first_cut: bool = False):
        """((lo, hi), where): `Field4D.data_range` and `Field4D.data_range_source`."""
        prov = self._first_cut_range(first_cut)
        if prov is not None:
            return prov
        f = self._field
        if self._range is None:
            if self.meta_range is not None:
                lo, hi, where = self.meta_range
                self._range = ((lo, hi), where)
            elif f.kind == "function":
                a = self.probe_values()
                finite = np.isfinite(a)
                rng = (float(a[finite].min()), float(a[finite].max())) if finite.any() else (math.nan, math.nan)
                self._range = (rng, "probe grid")
            elif f.resident is not None:  # in memory: given so, or read whole (`Field4D.prepare`)
                self.report_nonfinite()
                self._range = (_finite_range(f.resident), "data")
            else:  # chunked or lazy: one pass over the data (read whole when it fits the budget)
                c = f.coarse()
                self.report_nonfinite()
                self._range = ((_finite_range(f.resident), "data") if f.resident is not None
                               else (c.data_range, "coarse copy"))
        return self._range

    def probe_values(self):
        """A function field's values on a `_FUNCTION_PROBE`^4 grid over its box, float64 (x, y, z, w)."""
        if self._probe is None:
            m = _FUNCTION_PROBE
            grids = np.meshgrid(*[np.linspace(a, b, m) for a, b in self._field.extent], indexing="ij")
            self._probe = checked_call(self._field.function, *grids)
        return self._probe

    def cap_scale(self, s=None, first_cut: bool = False) -> float:
        """K for one step's samples ``s``: the field's (`statistics`), or, for a chunked or lazy array
        whose coarse copy is not ready, the 95th percentile of |grad f| within the first cut's
        samples (kept until the coarse copy is ready, so the pictures agree) -- with ``first_cut``
        (every full step: `Field4D.slice`, `slice_field`) or once K was taken so.  A full step
        therefore never builds the coarse copy (which reads every chunk)."""
        f = self._field
        if ((first_cut or self._k_first is not None) and self._stats is None
                and f.kind not in ("numpy", "function") and not f.coarse_ready):
            if self._k_first is None:
                u = power_of_two_unit(f.size)
                inner = s.g > s.spacing  # both neighbours inside the box: no step to the zeros outside
                with np.errstate(invalid="ignore", over="ignore"):
                    grads = np.gradient(np.asarray(s.f, dtype=np.float32), s.spacing / u)
                    gm = np.sqrt(sum(g * g for g in grads))
                ok = np.isfinite(gm) & (gm > 0) & inner
                if ok.any():
                    self._k_first = float(np.percentile(gm[ok], 95)) / u
                else:
                    lo, hi = self.range_info()[0] if f.reader is not None and f.reader.reads else (0.0, 0.0)
                    span = hi - lo if math.isfinite(lo) and math.isfinite(hi) else 0.0
                    self._k_first = max(span, abs(hi) if math.isfinite(hi) else 0.0, 1.0) / (2 * f.size)
            return self._k_first
        return self.statistics()[1]

    def statistics(self):
        """((min, max), K): `Field4D.data_range` and a typical |grad f| (level units per slice unit)."""
        if self._stats is None:
            self._stats = (self._field.data_range, self._gradient_scale())
        return self._stats

    def _gradient_scale(self) -> float:
        """K, the 95th percentile of |grad f| in level units per slice unit, from `Field4D.coarse` (a
        function's probe grid); from the data range when f is flat."""
        f = self._field
        if f.kind == "function":
            m = _FUNCTION_PROBE
            a = self.probe_values()
            spacing = [(b - a_) / (m - 1) / u for (a_, b), u in zip(f.extent, f.unit)]
        else:
            c = f.coarse()
            self.report_infinite()
            if c is not f:  # the same numbers: computed on the coarse copy
                return c.cap_scale()
            a = np.asarray(c.values, dtype=np.float32).transpose(c.axis_of)  # x, y, z, w order
            spacing = []
            for d in range(4):
                cd = c.coords[d]
                if cd is None:
                    lo, hi = c.extent[d]
                    spacing.append((hi - lo) / (a.shape[d] - 1) / c.unit[d])
                else:
                    spacing.append(np.asarray(cd) / c.unit[d])
        with np.errstate(invalid="ignore"):
            # spacings in units of the box's size (a power of two: exact), so a float32 gradient
            # neither overflows nor underflows at any scale; K is scaled back below
            u = power_of_two_unit(f.size)
            grads = np.gradient(a, *[sp / u for sp in spacing])
            gm = np.sqrt(sum(g * g for g in grads))
        ok = np.isfinite(gm) & (gm > 0)
        if ok.any():
            return float(np.percentile(gm[ok], 95)) / u  # steep places: a phase field's plateaus must not set it
        rng = f.data_range
        span = rng[1] - rng[0] if math.isfinite(rng[0]) else 0.0
        return max(span, abs(rng[1]) if math.isfinite(rng[1]) else 0.0, 1.0) / (2 * f.size)

    def report_infinite(self) -> None:
        """The old name of `report_nonfinite`."""
        self.report_nonfinite()

    def count_nonfinite(self) -> tuple | None:
        """(n +inf, n -inf, first index or None, NaN per w step): counted once over the whole array
        in memory (in blocks), or by the background read of a chunked or lazy one (None until then);
        a function's: None."""
        f = self._field
        if self.infinite is None and f.kind != "function" and (f.resident is not None or f.kind == "numpy"):
            a = f.resident if f.resident is not None else f.values
            w_axis = f.axis_of[3]
            self.infinite = (_count_nonfinite(a, w_axis) if np.dtype(a.dtype).kind == "f"
                             else (0, 0, None, np.zeros(int(a.shape[w_axis]), dtype=np.int64)))
        return self.infinite

    def nan_blocks(self) -> tuple:
        """``(steps, fraction)``: the w steps that hold NaN beyond `NAN_BLOCK_FRACTION` of their
        samples more than the step with fewest (indices, sorted), and the fraction of all samples
        that are NaN -- ``((), 0.0)`` when none (or not counted yet)."""
        census = self.infinite
        if census is None or len(census) < 4:
            return (), 0.0
        nan_w = np.asarray(census[3], dtype=np.int64)
        shape = self._field.values.shape
        per_step = math.prod(int(n) for n in shape) / max(len(nan_w), 1)
        if not len(nan_w) or not nan_w.any():
            return (), 0.0
        steps = np.flatnonzero(nan_w - nan_w.min() > NAN_BLOCK_FRACTION * per_step)
        return tuple(int(i) for i in steps), float(nan_w.sum()) / (per_step * len(nan_w))

    def nan_text(self) -> str | None:
        """The readout's "missing" text ("NaN in time 0.0021 … 0.0026 s (8 of 60 steps), 12.5 % of the
        samples"), or None when no block of NaN was found (`nan_blocks`)."""
        steps, fraction = self.nan_blocks()
        if not steps:
            return None
        f = self._field
        n_w = int(f.values.shape[f.axis_of[3]])
        lo, hi = f.extent[3]
        at = (np.asarray(f.coords[3]) if f.coords[3] is not None else np.linspace(lo, hi, n_w))
        blocks = _runs(steps)
        runs = ", ".join(w_value_text(f, at[a]) if a == b else w_span_text(f, at[a], at[b])
                         for a, b in blocks[:3]) + (" \u2026" if len(blocks) > 3 else "")
        name = f.dims[f.axes.index("w")] if f.dims is not None else "w"
        return (f"NaN in {name} {runs} ({len(steps)} of {n_w} steps), {100 * fraction:.3g} % of the samples")

    def report_nonfinite(self) -> None:
        """Warn once (`NonFiniteWarning`) when the data hold +inf or -inf -- how many, and where (the
        first, for an array in memory) -- or blocks of NaN in w (`nan_blocks`: a failed write, a gap;
        which steps and what fraction).  Counted over the whole array: in blocks for numpy, alongside
        the coarse copy's pass for chunked and lazy arrays (reported when that pass ends)."""
        if self.infinite_reported:
            return
        census = self.count_nonfinite()
        if census is None:
            return
        self.infinite_reported = True
        f = self._field
        npos, nneg, first = census[:3]
        parts = []
        if npos or nneg:
            what = " and ".join(t for t in (f"{npos} +inf" if npos else "", f"{nneg} -inf" if nneg else "") if t)
            where = f" (the first at index {first} of {axes_text(f.axes)})" if first is not None else ""
            parts.append(
                f"the data hold {what} of {math.prod(int(n) for n in f.values.shape)} samples{where}. They are kept: "
                f"+inf lies above and -inf below every level, the data range ignores them, and a point "
                f"interpolated in a cell that holds one is +-inf, or NaN (below every level) where two meet or its "
                f"weight is 0. To draw them otherwise, mask or clip first, "
                f"e.g. np.where(np.isfinite(a), a, np.nan) or np.clip(a, lo, hi)")
        nan = self.nan_text()
        if nan is not None:
            parts.append(f"{nan} -- a block of missing data (a failed write, a gap?). NaN lies below every "
                         f"level and is no value in the ray-cast renderings: those steps show nothing. Fill them, "
                         f"or select the steps around them (da.isel(...)); the readout's row \"missing\" says it too")
        if parts:
            warnings.warn(f"Field4D{' ' + repr(f.name) if f.name else ''}: " + "; ".join(parts),
                          NonFiniteWarning, stacklevel=4)
