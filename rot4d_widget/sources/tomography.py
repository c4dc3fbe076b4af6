"""Many parallel slices at once (issue 10): a source that wraps another and shows a stack.

`StackSource(source, slices=N, spacing=Δ, arrangement=...)` cuts ``source`` (a polytope, a
`Field4D`, any source) with the N hyperplanes

    w_k = c0 + (k - (N - 1) / 2) Δ,        k = 0 ... N - 1,

(c0 and Δ in the source's w units: a field's time) all under one orientation, and returns ONE
`SliceData` in which slice k is moved and shrunk to its place in the arrangement: a point p of
it is drawn at ``centre_k + scale_k * p`` (its normals unchanged), so every slice keeps the
same x, y, z orientation.  The widget shows it
like any source and stays unaware of stacks; ``slices=1`` is the single slice, point for point.

Where the N slices sit in the view: `rot4d_widget.sources.arrangements` (oval, grid, stack).

N = 1 is the identity in every arrangement (centre 0, scale 1).  The *highlighted* slice is
the one at w = c0 (k = (N - 1) / 2 for odd N; for even N no slice is at c0 and k = N / 2,
the first above it, is highlighted).

Colour: ``color_by="w"`` gives triangles group k (slice k) and `StackSource.group_colors`
spreads ``colours.LEVEL_COLORMAP`` over the N levels (lowest w darkest); ``color_by="cell"``
keeps the inner source's groups, so a 4-D cell has one colour in every slice (today's
colours).  With one slice, colour by w keeps the inner groups too (today's view).

Cost: a polytope's N slices come from one batched `slice_polytope(polytope, matrix, levels)`;
any other source is sliced level by level (a field samples each level's region).

Pure numpy; nothing here knows about widgets.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from numbers import Integral, Real

import numpy as np

from ..core import colours, text
from ..core._arrays import sealed as _sealed
from ..core.rotation import as_rotation_matrix
from ..geometry.slicing.polytope_slice import slice_polytope
from .arrangements import arrangement_layout, check_arrangement
from .protocol import (
    PolytopeSource,
    SliceData,
    SourceAction,
    SourceBase,
    apply_setting,
    as_slice,
    as_source,
    census_text,
    data_w_text,
    fill_flags,
    no_volume_row,
    rotation_3d,
    settings_of,
    source_title,
    takes_coarse,
    w_frame,
    w_value_text,
    winding_row,
)

__all__ = [
    "MAX_SLICES",
    "StackSource",
    "StackSliceData",
    "stack_levels",
    "stack_offsets",
    "default_spacing",
    "highlighted_index",
]

#: Most slices in a stack.
MAX_SLICES = 64
COLOR_BY = ("w", "cell")

#: g / f multiply / divide the spacing by this (Shift inverts).
SPACING_FACTOR = 2.0 ** 0.25
#: Δ stays within [SPACING_MIN, SPACING_MAX] times the source's size: g / f refuse a step
#: beyond (so the opposite key always undoes one), and setting Δ outside is a ValueError.
#: 2^-12 size: slices closer than that look the same; 4 size: every slice but one misses.
SPACING_MIN = 2.0 ** -12
SPACING_MAX = 4.0



# ------------------------------------------------------------------ validation
def _check_slices(n) -> int:
    if isinstance(n, (bool, np.bool_)) or not isinstance(n, Integral) or not 1 <= int(n) <= MAX_SLICES:
        raise ValueError(f"Expected `slices` to be an int in 1 \u2026 {MAX_SLICES}, got {n!r}")
    return int(n)


def _check_spacing(d):
    if d is None:
        return None
    if isinstance(d, (bool, np.bool_)) or not isinstance(d, Real) or not (math.isfinite(d) and d > 0):
        raise ValueError(f"Expected `spacing` to be a finite number > 0 or None (2 size / slices), got {d!r}")
    return float(d)


def _check_color_by(c) -> str:
    if c not in COLOR_BY:
        raise ValueError(f"Expected `color_by` to be one of {', '.join(map(repr, COLOR_BY))}, got {c!r}")
    return c


# ------------------------------------------------------------------ levels and layouts
def default_spacing(source, n: int, matrix=None) -> float:
    """The default Δ, in ``source``'s w units.  A record (a source with an ``extent``: a field): its
    extent along the current w -- the c0 at which the hyperplane w = c0 after ``matrix`` (default
    the identity) first and last touches the data, its ``w_range`` -- over N, so that N slices
    about the middle of it each take one N-th of it.  Any other source (a polytope): 2 size / N, as
    before there were records (times its w per unit of space)."""
    n = _check_slices(n)
    if source.extent is not None:
        lo, hi = _w_range(source, np.eye(4) if matrix is None else as_rotation_matrix(matrix))
        if math.isfinite(lo) and math.isfinite(hi) and hi > lo:
            return (hi - lo) / n
    return 2.0 * float(source.size) * w_frame(source)[1] / n


def _w_range(source, matrix) -> tuple:
    """``source.w_range(matrix)``, or (-size, size) for a source without one (a polytope's own w)."""
    return tuple(float(v) for v in source.w_range(matrix))


def _w_units(source):
    """The unit of ``source``'s w (a field's ``w_units``), or None."""
    return source.w_units


def stack_offsets(n: int, spacing: float) -> np.ndarray:
    """(n,) float64: each cut's offset from c0, ``(k - (n - 1) / 2) spacing`` (`stack_levels` adds c0;
    a page that cuts the stack itself adds its own c0 to these very numbers).

    Any n >= 1 (a `StackSource` holds at most `MAX_SLICES`; tests integrate with more)."""
    if isinstance(n, (bool, np.bool_)) or not isinstance(n, Integral) or n < 1:
        raise ValueError(f"Expected `n` to be an int >= 1, got {n!r}")
    return (np.arange(int(n)) - (int(n) - 1) / 2.0) * float(spacing)


def stack_levels(c0: float, n: int, spacing: float) -> np.ndarray:
    """(n,) float64: w_k = c0 + (k - (n - 1) / 2) spacing (`stack_offsets` plus c0); the middle one
    is c0 exactly for odd n."""
    return float(c0) + stack_offsets(n, spacing)


def highlighted_index(n: int) -> int:
    """The slice at w = c0 (odd n), else the first above c0: ``n // 2``."""
    return _check_slices(n) // 2


# ------------------------------------------------------------------ the slice data
@dataclass(frozen=True, eq=False)
class StackSliceData(SliceData):
    """`SliceData` of a `StackSource`: N slices placed side by side in one scene.

    cuts : (N,) float64 -- the w of each slice
    centres : (N, 3) float64, scales : (N,) float64 -- the placement (source units): a point p of
        slice k is drawn at ``centres[k] + scales[k] * p``
    highlighted : int -- the index of the slice at w = c0
    arrangement : str; spacing : float
    volumes : tuple of N floats or None -- each slice's 3-volume (None where it has none)
    point_offsets, segment_offsets, triangle_offsets : (N + 1,) intp -- where slice k's rows start
    slices : tuple -- the inner source's N slices (unplaced, unturned): a polytope's bare `Slice`
        s, any other source's `SliceData`
    group_rgb : (n_groups, 3) float64 or None -- the colours of the groups when coloured by w
    """

    cuts: np.ndarray | None = None
    centres: np.ndarray | None = None
    scales: np.ndarray | None = None
    highlighted: int = 0
    arrangement: str = ""
    spacing: float = 0.0
    volumes: tuple = ()
    point_offsets: np.ndarray | None = None
    segment_offsets: np.ndarray | None = None
    triangle_offsets: np.ndarray | None = None
    slices: tuple = ()
    group_rgb: np.ndarray | None = None

    def __post_init__(self):
        for name in ("cuts", "centres", "scales", "point_offsets", "segment_offsets", "triangle_offsets",
                     "group_rgb"):
            a = getattr(self, name)
            if a is not None:
                object.__setattr__(self, name, _sealed(np.array(a)))  # a copy: never lock the caller's

    def turned(self, rotation) -> "StackSliceData":
        """The stack at ``R3 @ matrix``: each slice turned by ``rotation`` (3, 3) about its own centre.

        The layout stays; normals are turned; ``slices`` stays unturned.
        """
        r = rotation_3d(rotation)
        centre = np.repeat(np.asarray(self.centres), np.diff(self.point_offsets), axis=0)
        points = (self.points - centre) @ r.T + centre
        return self.replaced(points=points, normals=None if self.normals is None else self.normals @ r.T)


_SHORT = {3: "tri", 4: "quad", 5: "pent", 6: "hex", 7: "hept", 8: "oct", 9: "non", 10: "dec"}


def _short_census(s) -> str:
    if s.dim < 0:
        return "empty"
    census = s.face_census()
    if not census:
        return "touches"
    return " ".join(f"{c} {_SHORT.get(n, f'{n}-gon')}" for n, c in sorted(census.items()))


class StackSource(SourceBase):
    """N parallel slices of ``source`` under one orientation, placed by an arrangement, as ONE source.

    Parameters
    ----------
    source : a polytope name, a `Polytope` or any source (`rot4d_widget.Source`)
    slices : int in 1 ... 64 -- N
    spacing : float > 0 or None -- Δ, in the source's w units (c0's: a field's time); None: the
        default, the record's extent along the current w over N (`default_spacing`), spread when the
        stack is made and whenever N changes, for the orientation noted last (`note_matrix`)
    matrix : (4, 4) rotation or None -- the orientation the default is spread for at first
    arrangement : "oval", "grid" or "stack" (`rot4d_widget.sources.arrangements`; docs/design.md, "Parallel slices")
    color_by : "w" (a colormap over the N levels) or "cell" (the inner source's groups)

    ``slices``, ``spacing``, ``arrangement`` and ``color_by`` are validated properties; keys
    n / b add / remove a slice and g / f widen / narrow Δ (``actions``).  ``slice(matrix,
    c0)`` takes ``coarse=`` exactly when the inner source's slice does.
    """

    def __init__(self, source, slices: int = 5, spacing=None, arrangement: str = "oval", color_by: str = "w",
                 matrix=None):
        self.source = as_source(source)
        self._matrix = np.eye(4) if matrix is None else as_rotation_matrix(matrix)
        self._default = None  # the default Δ once spread (`_spread`)
        self.slices = slices
        self.spacing = spacing
        self.arrangement = arrangement
        self.color_by = color_by
        self._polytope = self.source.polytope if _is_polytope_source(self.source) else None
        if not takes_coarse(self.source):
            self.slice = self._slice_exact  # same signature as the inner source: (matrix, c0)

    # -- validated settings -------------------------------------------------------
    @property
    def slices(self) -> int:
        """N, an int in 1 ... 64."""
        return self._slices

    @slices.setter
    def slices(self, value) -> None:
        self._slices = _check_slices(value)
        self._default = None  # a new N: the default is spread again, now (`_spread`)
        self._spread()

    @property
    def spacing(self) -> float:
        """Δ in the source's w units, c0's (a field's time): the one set, else the default spread over
        the record (`default_spacing`; setting None restores it)."""
        return self._spacing if self._spacing is not None else self._spread()

    @spacing.setter
    def spacing(self, value) -> None:
        d = _check_spacing(value)
        if d is not None:
            lo, hi = self.spacing_range
            if not lo <= d <= hi:
                unit = f" {_w_units(self.source)}" if _w_units(self.source) else ""
                raise ValueError(f"Expected `spacing` in [{lo:.4g}, {hi:.4g}]{unit} ({SPACING_MIN:g} \u2026 "
                                 f"{SPACING_MAX:g} times the source's size {self.size:.4g}, in its w units) or "
                                 f"None, got {d!r}")
        else:
            self._default = None
            self._spread()
        self._spacing = d

    @property
    def spacing_range(self) -> tuple:
        """(lowest, highest) Δ allowed, in the source's w units: `SPACING_MIN` and `SPACING_MAX`
        times the source's size (times its w per unit of space, `w_frame`)."""
        per = w_frame(self.source)[1]
        return SPACING_MIN * self.size * per, SPACING_MAX * self.size * per

    def note_matrix(self, matrix) -> None:
        """The orientation the view shows now (the source protocol's ``note_matrix``, told before an
        action or a setting changes N): a default spacing spread from now on is spread along its w.
        A turn alone never moves the slices: the default is spread only when the stack is made, when N
        changes and when the spacing is set back to None."""
        self._matrix = as_rotation_matrix(matrix)

    def _spread(self) -> float:
        """The default Δ, spread along the w of the orientation noted last -- at the moments the
        class docs name, never later: spread at its first use instead, it would take whatever
        orientation was noted by then (a replay, which reads it later than the live view, ended on
        another spacing)."""
        if self._default is None:
            self._default = default_spacing(self.source, self._slices, self._matrix)
        return self._default

    @property
    def spacing_is_default(self) -> bool:
        return self._spacing is None

    @property
    def arrangement(self) -> str:
        return self._arrangement

    @arrangement.setter
    def arrangement(self, value) -> None:
        self._arrangement = check_arrangement(value)

    @property
    def color_by(self) -> str:
        return self._color_by

    @color_by.setter
    def color_by(self, value) -> None:
        self._color_by = _check_color_by(value)

    # -- source protocol -------------------------------------------------------------
    @property
    def size(self) -> float:
        return float(self.source.size)

    @property
    def groups_by_w(self) -> bool:
        """Triangles are grouped by slice (group k: slice k), not by the inner source's groups:
        coloured by w with more than one slice."""
        return self._color_by == "w" and self._slices > 1

    @property
    def n_groups(self) -> int:
        if self.groups_by_w:
            return self._slices
        return int(self.source.n_groups)

    @property
    def name(self) -> str:
        inner = source_title(self.source)
        return f"{inner}, {self._slices} slice{'s' if self._slices != 1 else ''}"

    @property
    def edge_length(self):
        """The inner source's edge length times the largest scale (the widget sizes balls by it)."""
        e = self.source.edge_length
        if e is None:
            return None
        return float(e) * float(self.layout()[1].max())

    def w_range(self, matrix) -> tuple:
        return _w_range(self.source, matrix)

    @property
    def wraps(self):
        """The inner source (the source protocol's ``wraps``)."""
        return self.source

    @property
    def coarse_steps(self) -> bool:
        """Held keys get a coarse slice exactly when the inner source has one."""
        return takes_coarse(self.source)

    @property
    def settings(self) -> dict:
        """The protocol's ``settings``: N, Δ (None while it follows N) and the arrangement, then
        the inner source's (a field's levels, inside, caps)."""
        own = {"slices": self._slices, "spacing": self._spacing, "arrangement": self._arrangement}
        return {**own, **settings_of(self.source)}

    def apply_setting(self, name: str, value) -> None:
        """Set one of `settings`: the stack's own, or the inner source's (`apply_setting`)."""
        if name in ("slices", "spacing", "arrangement"):
            setattr(self, name, value)
        else:
            apply_setting(self.source, name, value)

    def __copy__(self) -> "StackSource":
        """A stack around a copy of the inner source (replaying its actions changes the copy only),
        its default spacing as spread here."""
        new = StackSource(copy.copy(self.source), slices=self._slices, spacing=self._spacing,
                          arrangement=self._arrangement, color_by=self._color_by, matrix=self._matrix)
        new._default = self._default
        return new

    @property
    def w_frame(self) -> tuple:
        """The inner source's ``(origin, per_unit)`` (`rot4d_widget.sources.protocol.w_frame`): c0, Δ
        and the cuts are in its w units."""
        return w_frame(self.source)

    def cut_offsets(self) -> np.ndarray:
        """(N,) float64: each cut's offset from c0, in c0's units (Δ's), ``(k - (N - 1)/2) Δ``
        (`stack_offsets`)."""
        return stack_offsets(self._slices, self.spacing)

    def cuts_at(self, c0: float) -> np.ndarray:
        """The stack's cuts for the plane w = ``c0``: the w of each of the N slices, in c0's units,
        ``c0 + cut_offsets()`` (N,) float64."""
        return float(c0) + self.cut_offsets()

    def levels_at(self, c0: float) -> np.ndarray:
        """The old name of `cuts_at` (kept for code written before it; "levels" are a field's iso values)."""
        return self.cuts_at(c0)

    def layout(self):
        """``(centres (N, 3), scales (N,))`` in the source's units (`arrangement_layout`)."""
        return arrangement_layout(self._arrangement, self._slices, self.size)

    def group_colors(self) -> np.ndarray:
        """(n_groups, 3) float64 colours when coloured by w (a colormap over the levels), else None."""
        if not self.groups_by_w:
            return None
        return colours.level_colors(np.arange(self._slices, dtype=float), 0.0, self._slices - 1.0)

    def describe(self) -> dict:
        return {"kind": "stack", "source": self.source.describe(), "slices": self._slices,
                "spacing": self._spacing, "arrangement": self._arrangement, "color_by": self._color_by}

    @property
    def actions(self) -> dict:
        """n / b: one slice more / fewer; g / f: Δ times / divided by 2^(1/4) (Shift inverts each);
        and the inner source's own keys (a field's o / i), which act on every slice."""
        inner = self.source.actions or {}
        return {
            **inner,
            "n": SourceAction("slice +", "add a parallel slice", lambda sign=1: self.step_slices(sign), repeat=False),
            "b": SourceAction("slice \u2212", "remove a parallel slice", lambda sign=1: self.step_slices(-sign),
                              repeat=False),
            "g": SourceAction("spacing +", "widen the slice spacing \u0394 by 2^(1/4)",
                              lambda sign=1: self.step_spacing(sign)),
            "f": SourceAction("spacing \u2212", "narrow the slice spacing \u0394 by 2^(1/4)",
                              lambda sign=1: self.step_spacing(-sign)),
        }

    def step_slices(self, sign: int):
        """One slice more (sign > 0) or fewer; returns N, or False (no change) beyond 1 ... 64."""
        n = self._slices + (1 if sign > 0 else -1)
        if not 1 <= n <= MAX_SLICES:
            return False
        self.slices = n  # a default spacing is spread again for N (never one the user set)
        return n

    def step_spacing(self, sign: int):
        """Δ times (sign > 0) or divided by `SPACING_FACTOR`; returns Δ (now explicit), or False
        (no change) when that would leave `spacing_range`."""
        d = self.spacing * (SPACING_FACTOR if sign > 0 else 1.0 / SPACING_FACTOR)
        lo, hi = self.spacing_range
        if not lo <= d <= hi:
            return False
        self._spacing = d
        return d

    def slice(self, matrix, c0, coarse: bool = False) -> StackSliceData:
        """The N slices at `cuts_at` (``c0``), placed by the arrangement, as one `StackSliceData`."""
        return self._slice(matrix, c0, bool(coarse))

    def _slice_exact(self, matrix, c0) -> StackSliceData:
        return self._slice(matrix, c0, False)

    # -- work -------------------------------------------------------------------------
    def _inner_slices(self, matrix, cuts, coarse):
        if self._polytope is not None:
            if len(cuts) == 1:  # today's single slice, bit for bit
                return [_PolytopePiece(slice_polytope(self._polytope, matrix, float(cuts[0])), self._polytope)]
            return [_PolytopePiece(s, self._polytope) for s in slice_polytope(self._polytope, matrix, cuts)]
        if coarse:
            return [as_slice(self.source.slice(matrix, float(w), coarse=True)) for w in cuts]
        return [as_slice(self.source.slice(matrix, float(w))) for w in cuts]

    def _slice(self, matrix, c0, coarse) -> StackSliceData:
        m = as_rotation_matrix(matrix)
        if isinstance(c0, (bool, np.bool_)) or not isinstance(c0, Real) or not math.isfinite(c0):
            raise ValueError(f"Expected `c0` to be a finite real number, got {c0!r}")
        n = self._slices
        cuts = self.cuts_at(float(c0))
        pieces = self._inner_slices(m, cuts, coarse)
        centres, scales = self.layout()
        by_w = self.groups_by_w
        pts, segs, tris, groups, nrms, corners = [], [], [], [], [], []
        p_off, s_off, t_off = [0], [0], [0]
        volumes = []
        has_normals = all(p.normals is not None for p in pieces)
        for k, piece in enumerate(pieces):
            p = np.asarray(piece.points, dtype=np.float64).reshape(-1, 3)
            pts.append(p * scales[k] + centres[k] if n > 1 else p)
            flags = piece.corner_only  # fill corners: no ball
            corners.append(np.zeros(len(p), dtype=bool) if flags is None else np.asarray(flags, dtype=bool))
            segs.append(np.asarray(piece.segments, dtype=np.intp).reshape(-1, 2) + p_off[-1])
            t = np.asarray(piece.triangles, dtype=np.intp).reshape(-1, 3)
            tris.append(t + p_off[-1])
            groups.append(np.full(len(t), k, dtype=np.intp) if by_w else np.asarray(piece.groups, dtype=np.intp))
            if has_normals:
                nrms.append(np.asarray(piece.normals, dtype=np.float64).reshape(-1, 3))
            v = piece.volume
            volumes.append(None if v is None else float(v))
            p_off.append(p_off[-1] + len(p))
            s_off.append(s_off[-1] + len(segs[-1]))
            t_off.append(t_off[-1] + len(t))
        hi = highlighted_index(n)
        placed = dict(
            cuts=cuts, centres=centres, scales=scales, highlighted=hi, arrangement=self._arrangement,
            spacing=self.spacing, volumes=tuple(volumes), point_offsets=np.array(p_off),
            segment_offsets=np.array(s_off), triangle_offsets=np.array(t_off),
            slices=tuple(p.slice if isinstance(p, _PolytopePiece) else p for p in pieces),
            group_rgb=self.group_colors(),
        )
        if n == 1:  # today's view: the inner slice's volume and readout as they are
            return StackSliceData.build(
                pts[0], segs[0], tris[0], groups[0], normals=nrms[0] if has_normals else None,
                volume=volumes[0], readout=tuple(pieces[0].readout), convex=bool(pieces[0].convex),
                show_points=bool(pieces[0].show_points), corner_only=corners[0], **placed)
        return StackSliceData.build(
            np.concatenate(pts), np.concatenate(segs), np.concatenate(tris), np.concatenate(groups),
            normals=np.concatenate(nrms) if has_normals else None, volume=None,
            readout=self._readout(cuts, pieces, volumes, hi, m), convex=False,
            show_points=any(bool(p.show_points) for p in pieces), **placed,
            corner_only=np.concatenate(corners) if corners else None)

    def _readout(self, cuts, pieces, volumes, hi, m) -> tuple:
        """Rows for the readout: each slice labelled by its w in the data's own units (a field's
        time, `data_w_text`), its census (polytopes) and volume (the source's own units)."""
        n = len(cuts)
        how = "colour by w (viridis, low w dark)" if self._color_by == "w" else "colour by cell"
        unit = _w_units(self.source)
        delta = text.number_text(self.spacing) + (f" {unit}" if unit else "")
        delta += "" if self._spacing is not None else " (spread over the record)"
        rows = [("stack", f"{n} slices, \u0394 = {delta}, {self._arrangement}, {how}")]
        polytope = self._polytope is not None
        if n <= 12:
            for k, (w, piece, v) in enumerate(zip(cuts, pieces, volumes)):
                label = ("\u25b8 " if k == hi else "") + data_w_text(self.source, w, m)
                parts = []
                if polytope:
                    parts.append(_short_census(piece.slice))
                if v is not None and not label.endswith("(outside the data)"):
                    space = self.source.space_units
                    parts.append(f"vol {text.number_text(v)}" + (f" {space}\u00b3" if space else ""))
                rows.append((label, ", ".join(parts) or "\u2014"))
        else:
            if self.source.extent is None:  # a polytope's own w
                ends = [data_w_text(self.source, cuts[i])[2:] for i in (0, -1, hi)]
            else:
                ends = [w_value_text(self.source, cuts[i]) for i in (0, -1, hi)]
            rows.append(("w", f"{ends[0]} \u2026 {ends[1]} (\u25b8 {ends[2]})"))
            if any(v is not None for v in volumes):
                rows.append(("volumes", " ".join("\u2014" if v is None else f"{v:.3g}" for v in volumes)))
        if polytope:  # a hemi or non-orientable polytope: its slices have no volume, and why
            rows += no_volume_row(self._polytope)
        return tuple(rows)

    def __repr__(self) -> str:
        return (f"StackSource({self.source!r}, slices={self._slices}, spacing={self.spacing:.4g}, "
                f"arrangement={self._arrangement!r}, color_by={self._color_by!r})")


class _PolytopePiece:
    """A polytope `Slice` seen as slice data (what `PolytopeSource.slice` would give: every member
    of a `SliceData`, made when read)."""

    __slots__ = ("slice", "convex", "rows")

    def __init__(self, s, polytope):
        self.slice = s
        self.convex = bool(polytope.convex)  # a convex polytope's slice is convex; a non-convex one's may not be
        self.rows = winding_row(polytope)  # self-intersecting; no volume, and why (hemi, not orientable)

    points = property(lambda self: self.slice.vertices)
    segments = property(lambda self: self.slice.edges)
    triangles = property(lambda self: self.slice.triangles)
    groups = property(lambda self: self.slice.triangle_cells)
    normals = None
    volume = property(lambda self: None if self.slice.volume is None else float(self.slice.volume))
    readout = property(lambda self: (("slice", census_text(self.slice)),) + self.rows)
    show_points = True
    corner_only = property(lambda self: fill_flags(self.slice))  # as `PolytopeSource.slice` flags them


def _is_polytope_source(src) -> bool:
    """One of the package's three class tests, kept for speed, not for meaning: the N slices of
    our own polytope source come from one batched `slice_polytope` call instead of N ``slice``
    calls (the same slices); any other source, a user's polytope-like one too, is sliced through
    the protocol."""
    return isinstance(src, PolytopeSource)

