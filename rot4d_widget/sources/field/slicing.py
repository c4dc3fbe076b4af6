"""The geometry of one `Field4D` step: the cut of the data's box and the samples on the slice.

`box_slice` cuts the data's 4-D box (an 8-cell scaled to its half widths) with the exact
polytope slicer; `slice_samples` lays a 3-D grid over that cut (``resolution`` samples along its
longest side, one sample of padding) and pulls it back into the data: f through the resampling
kernels (an array in memory), the chunk reader (a chunked or lazy array) or the function itself,
and g, the signed in-slice distance to the planes where the box's faces cut the slice.
`slice_offset` turns a step's samples into one surface per level.

Every function here takes a rotation matrix already validated (`as_rotation_matrix`): a
`Field4D.slice` or `slice_field` validates it once.
"""

from __future__ import annotations

import itertools

import numpy as np

from ...geometry.mesh import Polytope
from ...geometry.slicing.polytope_slice import slice_polytope
from .checks import AXES, checked_call
from .kernels import resample_affine
from .surface import empty_slice, level_surface

_BOX_CACHE: dict = {}


def box_polytope(hw):
    key = tuple(float(v) for v in hw)
    p = _BOX_CACHE.get(key)
    if p is None:
        corners = np.array(list(itertools.product((-1.0, 1.0), repeat=4))) * np.asarray(hw)
        p = Polytope(corners, name="field box")
        if len(_BOX_CACHE) > 64:
            _BOX_CACHE.clear()
        _BOX_CACHE[key] = p
    return p


def box_slice(field, m, c0):
    """The exact cut of ``field``'s box (half widths `Field4D.half_widths`) at the offset ``c0``
    (slice units) after ``m``: a `rot4d_widget.geometry.slicing.Slice`."""
    return slice_polytope(box_polytope(field.half_widths), m, c0)


class _Samples:
    """One step's samples: the grid (origin, spacing, shape) and f, g on it."""

    __slots__ = ("origin", "spacing", "f", "g", "k", "box")


class LastCut:
    """The last cut sampled from a chunked or lazy array (`slice_samples_raw`), so that the same cut asked
    twice -- the first cut that sets the default level and range, then the view's first picture,
    both at rest -- reads its chunks once (a big store's cut can hold more chunks than the chunk
    cache).  One entry, replaced whole (safe to read from another thread)."""

    def __init__(self):
        self._entry = (None, None)

    def get(self, key):
        k, s = self._entry
        return s if k == key else None

    def keep(self, key, samples) -> None:
        self._entry = (key, samples)


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
    c = field.coords[d]
    hw = field.half_widths
    if c is None:
        return np.linspace(-hw[d], hw[d], n)
    return (np.asarray(c) - field.centre[d]) / field.unit[d]


def slice_samples(field, m, c0, res, first_cut: bool = False, box=None) -> _Samples | None:
    """Resample ``field`` on the grid of one step, or None when w = c0 misses the box; with its
    cap scale K (`Field4D.cap_scale`: taken after the read, so a first cut needs nothing more).
    ``box``: the box's cut at (m, c0) when the caller has it already (`box_slice`)."""
    s = slice_samples_raw(field, m, c0, res, box)
    if s is not None:
        s.k = field.cap_scale(s, first_cut)
    return s


def slice_samples_raw(field, m, c0, res, box=None) -> _Samples | None:
    """`slice_samples` without K (``s.k`` None).  Of a chunked or lazy array, the last cut is kept
    (`LastCut`): asked again for the same one, nothing is read."""
    chunked = field.kind not in ("numpy", "function") and field.resident is None
    key = (m.tobytes(), float(c0), int(res), tuple(field.half_widths)) if chunked else None
    if chunked:
        s = field.last_cut.get(key)
        if s is not None:
            return s
    s = _sample_grid(field, m, c0, res, box)
    if chunked:
        field.last_cut.keep(key, s)
    return s


def _sample_grid(field, m, c0, res, box):
    if box is None:
        box = box_slice(field, m, c0)
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
    hw = np.asarray(field.half_widths)
    p0 = np.array([origin[0], origin[1], origin[2], c0])
    if field.kind == "function":
        axes = [origin[a] + d * np.arange(n[a]) for a in range(3)]
        P = np.meshgrid(*axes, indexing="ij")
        q = [m[0, j] * P[0] + m[1, j] * P[1] + m[2, j] * P[2] + m[3, j] * c0 for j in range(4)]
        g = _in_slice_distance(q, hw, m)
        unit, centre = field.unit, field.centre
        with np.errstate(all="ignore"):
            f = checked_call(field.function, *[q[j] * unit[j] + centre[j] for j in range(4)])
        s.f, s.g = f, g
        return s
    uniform = all(c is None for c in field.coords)
    axis_of = field.axis_of
    # data axis j <-> array axis axis_of[j]
    if uniform:
        sc = np.array([(field.shape[j] - 1) / (2 * hw[j]) for j in range(4)])  # index steps per slice unit
        base_d = (m.T @ p0 + hw) * sc
        step_d = d * m[:3, :] * sc  # (3, 4): grid axis r -> data axis j
        base = np.empty(4)
        step = np.empty((3, 4))
        centre = np.empty(4)
        inv_s = np.empty(4)
        for j in range(4):
            a = axis_of[j]
            base[a] = base_d[j]
            step[:, a] = step_d[:, j]
            centre[a] = (field.shape[j] - 1) / 2
            inv_s[a] = 1.0 / (sc[j] * _face_norms(m)[j])
        halfn = np.where(_face_norms(m)[list(AXES.index(c) for c in field.axes)] > _PARALLEL, centre, 1e300)
        resident = field.resident
        if resident is not None:  # in memory: given so, or read whole in the background
            s.f, s.g = resample_affine(resident, base, step, n, centre, halfn, inv_s)
            return s
        # chunked or lazy: the same numbers, each touched chunk read once (memory stays bounded)
        ijk = np.indices(tuple(int(v) for v in n), dtype=np.float64).reshape(3, -1).T
        x = base[None, :] + ijk @ step  # (N, 4) index coordinates, array axis order
        g = ((halfn[None, :] - np.abs(x - centre[None, :])) * inv_s[None, :]).min(axis=1)
        s.f = field.values_at(x, g >= 0.0).reshape(tuple(n))
        s.g = g.reshape(tuple(n))
        return s
    # uneven coordinates: points -> fractional indices by np.interp, then the points kernel
    axes = [origin[a] + d * np.arange(n[a]) for a in range(3)]
    P = np.meshgrid(*axes, indexing="ij")
    q = [(m[0, j] * P[0] + m[1, j] * P[1] + m[2, j] * P[2] + m[3, j] * c0).ravel() for j in range(4)]
    g = _in_slice_distance(q, hw, m)
    idx = np.empty((len(g), 4))
    for j in range(4):
        a = axis_of[j]
        idx[:, a] = np.interp(q[j], _geometric_nodes(field, j), np.arange(field.shape[j], dtype=np.float64))
    f = field.values_at(idx, g >= 0)
    s.f, s.g = f.reshape(tuple(n)), g.reshape(tuple(n))
    return s


def slice_offset(field, m, d, levels, res, *, coarse, box=None) -> tuple:
    """One `FieldSlice` per level of ``levels`` (a tuple of floats) at the offset ``d`` (slice units)
    after the validated rotation ``m``, sampled at ``res`` along the longest side; of
    ``field.coarse()`` with ``coarse``.  ``box``: the box's cut there, when known (the coarse copy
    has the field's box).  A full step of a chunked field reads only the chunks its samples touch:
    its cap scale comes from this cut's samples until the coarse copy is ready (`Field4D.cap_scale`),
    never from a coarse copy built for it."""
    src = field.coarse() if coarse else field
    s = slice_samples(src, m, d, res, first_cut=not coarse, box=box)
    if s is None:
        return tuple(empty_slice(lv, 0.0) for lv in levels)
    return tuple(level_surface(s, lv, field.inside, field.caps) for lv in levels)
