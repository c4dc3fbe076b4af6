"""A field's cut for the ray-cast renderings: the grids the page casts rays through and the bars
around them, read through the source protocol (``sample``, a stack's ``cuts``), never a class.

`grid_cut` is the volume renderings' ``source.slice``: where a surface rendering asks the source
for its isosurfaces, these ask for the values on a grid (`rot4d_widget.sources.field.grid`) --
no isosurface is computed for a single field, so a held key costs a coarse sampling only.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..core.renderings import RENDERING_TEXT
from ..core.text import number_text
from ..sources.field_labels import axis_names, axis_units, box_labels
from ..sources.protocol import SliceData, data_w_text, inner_source, outline_of, settings_of

__all__ = ["GridCut", "grid_cut", "can_sample", "cut_labels", "CutLabels", "NO_LABELS", "data_extent", "rendering_rows",
           "STACK_NODES"]

#: A stack's slices share this many grid nodes in all (each sampled more coarsely as they multiply).
STACK_NODES = 4 * 64 ** 3


@dataclass(frozen=True)
class GridCut:
    """What a ray-cast picture shows: ``data`` (`SliceData`: the box's cut as bars, no faces, and the
    readout rows) and ``parts``, one ``(values (nx, ny, nz), lo (3,), span (3,))`` per cut, the
    grid's nodes spanning ``lo`` ... ``lo + span`` in scene units (``scale`` applied), and
    ``grids`` the `FieldGrid` s themselves (their values' range for the colour limits)."""

    data: SliceData
    parts: tuple
    grids: tuple

    @property
    def finite_values(self) -> np.ndarray:
        """Every finite value of every cut, flattened (for default colour limits)."""
        vals = [np.asarray(g.values)[np.isfinite(g.values)] for g in self.grids if not g.empty]
        return np.concatenate(vals) if vals else np.zeros(0, dtype=np.float32)


def can_sample(source) -> bool:
    """True when the (inner) source gives its cut on a grid (the protocol's optional ``sample``)."""
    return callable(inner_source(source).sample)


def _part(grid, lo_shift, scale):
    values = np.asarray(grid.values)
    lo = np.asarray(lo_shift, dtype=np.float64) + scale * np.asarray(grid.origin, dtype=np.float64)
    span = scale * float(grid.spacing) * (np.asarray(values.shape, dtype=np.float64) - 1.0)
    return values, lo, span


def grid_cut(source, matrix, c0, coarse: bool, lock, scale: float) -> GridCut:
    """The cut w = ``c0`` after ``matrix`` on grids, placed as the view places the slice: a single
    field's grid scaled by ``scale`` (source units -> displayed units); a stack's slices each at
    its centre and scale (``cuts``, ``centres``, ``scales`` of the stack's slice, as
    the static renders place them).  ``lock`` guards the source while it is read."""
    inner = inner_source(source)
    with lock:
        if inner is source:
            grid = _sample(inner, matrix, c0, None, coarse)
            pts, segs = grid.outline
            rows = tuple(outline_of(inner, matrix, c0).readout)
            n = sum(1 for k, _ in rows if k in ("field", "axes"))  # the level where the surfaces' readout has it
            rows = rows[:n] + _level_row(inner, grid) + rows[n:] + _readout(grid)
            data = SliceData.build(pts, segs, show_points=False, readout=rows)
            return GridCut(data, (_part(grid, np.zeros(3), scale),), (grid,))
        sliced = source.slice(matrix, c0, coarse=True) if coarse else source.slice(matrix, c0)
        cuts = np.asarray(sliced.cuts, dtype=np.float64)
        centres = np.asarray(sliced.centres, dtype=np.float64).reshape(-1, 3)
        scales = np.asarray(sliced.scales, dtype=np.float64).ravel()
        res = getattr(inner, "coarse_resolution" if coarse else "resolution", 64)
        res = max(8, min(int(res), int(round((STACK_NODES / max(len(cuts), 1)) ** (1.0 / 3.0)))))
        grids = tuple(_sample(inner, matrix, float(w), res, coarse) for w in cuts)
    parts = tuple(_part(g, scale * centres[k], scale * scales[k]) for k, g in enumerate(grids))
    # the stack's placement kept (its labels); no faces, no balls: the picture is the grids'
    data = sliced.replaced(triangles=None, groups=None, normals=None, volume=None, convex=False, show_points=False,
                           corner_only=None)
    return GridCut(data, parts, grids)


@dataclass(frozen=True)
class CutLabels:
    """What the page needs to label a picture of a cut, whichever picture it is (the kernel's or the
    page's own): ``labels``, ``(point (3,), text, kind)`` in slice coordinates (the source's units)
    -- kind ``"corner"`` (the box's origin corner, every data coordinate there), ``"edge"`` (the far
    end of an edge leaving it, what changes along it) or ``"slice"`` (a stack's slice, its w) --
    and ``extent`` (n, 3) float64, the corners of the data's extent (the box's cut) that the box
    labels keep clear of where they project.  False when there is no label."""

    labels: tuple = ()
    extent: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))

    def __bool__(self) -> bool:
        return bool(self.labels)

    def traits(self, scale: float) -> tuple:
        """``(labels, extent)`` as the scene's buffer holds them (``_rot4d_labels``: ``{"p": [x, y,
        z], "text", "kind"}``; ``_rot4d_label_extent``: ``[x, y, z]`` rows), in displayed units
        (``scale`` times the source's); no extent without a label."""
        pinned = [{"p": [float(v) * scale for v in np.asarray(p, dtype=np.float64).reshape(3)], "text": str(t),
                   "kind": str(kind)} for p, t, kind in self.labels]
        extent = np.asarray(self.extent, dtype=np.float64).reshape(-1, 3) * scale
        return pinned, [[float(v) for v in row] for row in extent] if pinned else []


#: A picture without labels.
NO_LABELS = CutLabels()


class _Box:
    """The bounding box of points in the shape `box_labels` reads (``origin``, ``extent``)."""

    def __init__(self, points):
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        self.origin = p.min(axis=0)
        self.extent = tuple(zip(self.origin, p.max(axis=0)))
        self.values = None


def data_extent(data) -> np.ndarray:
    """(n, 3) float64: the corners of a single cut's data extent -- the points its bars (the box's
    cut, ``data.segments``) join; the padded sampling grid of a ray-cast picture is never counted."""
    seg = np.asarray(data.segments, dtype=np.intp).reshape(-1, 2)
    if not len(seg):
        return np.zeros((0, 3))
    return np.asarray(data.points, dtype=np.float64).reshape(-1, 3)[np.unique(seg)]


def cut_labels(source, matrix, c0, data) -> CutLabels:
    """The labels of a single field's cut (`rot4d_widget.sources.field_labels.box_labels` of the
    data's extent: the bounding box of the box's cut, ``data``'s bars, in every rendering): its
    origin corner with every data coordinate there, the far ends of the three edges leaving it
    with what changes along each, and the extent's corners.  A stack's: each slice's w under it
    (`_slice_labels`).  An empty `CutLabels` for a source that maps no slice point to its data (no
    ``to_data``) or a cut that misses the data."""
    if inner_source(source) is not source:
        return _slice_labels(source, matrix, c0, data)
    if not callable(source.to_data):
        return CutLabels()
    extent = data_extent(data)
    if not len(extent):
        return CutLabels()
    pairs = box_labels(source, matrix, c0, _Box(extent))
    kinds = ("corner",) + ("edge",) * (len(pairs) - 1)
    return CutLabels(tuple((p, t, k) for (p, t), k in zip(pairs, kinds)), extent)


def _slice_labels(stack, matrix, c0, data) -> CutLabels:
    """A stack's labels: under each slice (its centre and scale, ``data.centres``, ``data.scales``), the w it cuts at in
    the data's own units (`data_w_text`: "time 0.0025 s", "(outside the data)" for a slice that
    misses it), kind "slice" -- every slice carries its w, an empty one too."""
    cuts = np.asarray(data.cuts, dtype=np.float64)
    centres = np.asarray(data.centres, dtype=np.float64).reshape(-1, 3)
    scales = np.asarray(data.scales, dtype=np.float64).ravel()
    if len(cuts) < 2:
        return CutLabels()
    radius = float(inner_source(stack).size)
    labels = tuple((centres[k] + np.array([0.0, -1.02 * scales[k] * radius, 0.0]),
                    data_w_text(stack, float(w), matrix), "slice") for k, w in enumerate(cuts))
    return CutLabels(labels)


def _sample(inner, matrix, c0, resolution, coarse):
    """``inner.sample``; a coarse one from the full data while the source's coarse copy is still
    being built (``coarse_ready`` False: the copy is not waited for, as `Field4D.slice` does)."""
    if coarse and not inner.coarse_ready:
        res = resolution if resolution is not None else inner.coarse_resolution
        return inner.sample(matrix, c0, res)
    return inner.sample(matrix, c0, resolution, coarse=coarse)


def _level_row(source, grid) -> tuple:
    """The iso level(s) in a ray-cast picture: named, and said not to be drawn (the surface
    rendering draws them), so that no row reads as if the picture showed them."""
    levels = settings_of(source).get("levels") or ()
    if not levels:
        return ()
    units = f" {grid.units}" if grid.units else ""
    return (("level" if len(levels) == 1 else "levels",
             f"{', '.join(f'{v:.4g}' for v in levels)}{units}: the surface rendering's (v), not drawn here"),)


def rendering_rows(source, matrix, c0, rendering: str, sections, grid) -> tuple:
    """Readout rows saying what a ray-cast picture of a single field's cut shows: the rendering,
    and for "sections" where its planes are, in the data's own coordinates -- for each plane (keys
    a, s, d: the picture's x, y, z), the data coordinates that change across it, at the point where
    it crosses the middle of the cut ("time 0.0025 s" after a turn into time; "(outside the data)"
    for a plane in the grid's padding, past the data's box)."""
    name = grid.name or "the value"
    rows = [("rendering", RENDERING_TEXT[rendering].format(name=name))]
    if rendering != "sections" or grid.empty or inner_source(source) is not source:
        return tuple(rows)
    ext = np.asarray(grid.extent, dtype=np.float64).reshape(3, 2)
    mid = ext.mean(axis=1)
    span = np.abs(np.diff(np.asarray(source.extent, dtype=np.float64).reshape(4, 2), axis=1)).ravel()
    names, units = axis_names(source), axis_units(source)
    planes = []
    for a in range(3):
        p = mid.copy()
        p[a] = ext[a, 0] + float(sections[a]) * (ext[a, 1] - ext[a, 0])
        q = p.copy()
        q[a] += ext[a, 1] - ext[a, 0]
        data = np.asarray(source.to_data(np.vstack([p, q]), matrix, c0), dtype=np.float64).reshape(2, 4)
        moved = [c for c in range(4) if abs(data[1, c] - data[0, c]) > 1e-6 * max(span[c], 1e-300)]
        moved.sort(key=lambda c: -abs(data[1, c] - data[0, c]) / max(span[c], 1e-300))
        text = ", ".join(f"{names[c]} {number_text(data[0, c], span[c], 3)}" + (f" {units[c]}" if units[c] else "")
                         for c in moved)
        lo, hi = np.asarray(source.extent, dtype=np.float64).reshape(4, 2).T
        outside = np.any((data[0] < lo - 1e-9 * span) | (data[0] > hi + 1e-9 * span))
        planes.append(text + (" (outside the data)" if outside else ""))
    rows.append(("planes a / s / d", "; ".join(planes)))
    return tuple(rows)


def _readout(grid) -> tuple:
    """Readout rows of one grid: its nodes and the range of the values it holds."""
    rows = [("grid", " \u00d7 ".join(str(n) for n in grid.values.shape) + f" nodes, spacing {grid.spacing:.4g}")]
    v = np.asarray(grid.values)
    finite = v[np.isfinite(v)]
    if len(finite):
        units = f" {grid.units}" if grid.units else ""
        rows.append(("cut range", f"{float(finite.min()):.4g} \u2026 {float(finite.max()):.4g}{units}"))
    return tuple(rows)
