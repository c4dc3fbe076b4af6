"""Many parallel slices at once (issue 10): a source that wraps another and shows a stack.

`StackSource(source, slices=N, spacing=Δ, arrangement=...)` cuts ``source`` (a polytope, a
`Field4D`, any source) with the N hyperplanes

    w_k = c0 + (k - (N - 1) / 2) Δ,        k = 0 ... N - 1,

all under one orientation, and returns ONE `SliceData` in which slice k is moved and shrunk to
its place in the arrangement: a point p of it is drawn at ``centre_k + scale_k * p`` (its
normals unchanged), so every slice keeps the same x, y, z orientation.  The widget shows it
like any source and stays unaware of stacks; ``slices=1`` is the single slice, point for point.

Arrangements (`arrangement_layout`, designed in displayed units -- the object's circumradius
`look.REFERENCE_RADIUS`, the eye at (0, 0, 5) looking down -z, vertical fov 40 degrees, the
default canvas aspect 600 / 500 -- and scaled to the source's units):

``"oval"``
    Kageyama's follow-up (J. Visualization 2016): the slice centres lie on the parabola
    ``P(u) = (A u, Y0 + C u^2, -B u^2)`` with A = 2.6, B = 3.0, C = 1.2, |u| <= 2.0 and Y0
    chosen for each N so that the picture is centred in the frame (the slices' bounding spheres
    reach as far above the frame's middle as below it: -0.05 for N = 5, -0.49 for N = 12, -0.95
    for N = 64): it opens away from the eye and rises with depth, so its perspective image is
    an oval (the points at infinity would close it at the horizon y' = 5 C / B = 2).  The
    central slice (w = c0) sits at the vertex P(0) = (0, Y0, 0), nearest the eye and
    lowest; slices of higher w go right, lower w left.  World scales are
    ``s0 (1 - 0.4 tau^2) / max``, tau = (k - (N-1)/2) / ((N-1)/2), on top of perspective.
    Slices are laid along the parabola from the vertex at arc-length steps proportional to
    their sizes (touching spheres at scale 0.6 plus a 5 % gap) until the arc |u| <= 2 is
    used up; then the steps shrink.  ``s0`` is the largest scale, at most 0.6, for which
    every pair of bounding spheres (radius ``radius * scale``) is disjoint with a 5 % gap
    and every sphere's image lies in the 600 x 500 camera frame with a 3 % margin.  Why these
    numbers: A, B, C make the oval's image span |x'| <= 1.68 and -0.65 ... 1.22 in y' (the
    frame is |x'| <= 2.18, |y'| <= 1.82 at z = 0, with Y0 = -0.65); u = 2 is past the widest point
    u* = sqrt(5 / B) = 1.29, so the ends curl back towards each other (an oval, not a U)
    while the farthest slice, 12 units deep, is still drawn at 29 % of its size.  With
    N = 16 every slice gets scale 0.56, with 64 about 0.2.
``"grid"``
    Small multiples like a CT film: ``ceil(sqrt(N))`` columns, rows from top to bottom,
    slice 0 (lowest w) top left, all at z = 0 and one scale, the largest (at most 1) for
    which the grid of bounding spheres, 5 % apart, fits the frame with a 3 % margin.
``"stack"``
    One row along x at z = 0, lowest w on the left, one scale chosen the same way.

N = 1 is the identity in every arrangement (centre 0, scale 1).  The *highlighted* slice is
the one at w = c0 (k = (N - 1) / 2 for odd N; for even N no slice is at c0 and k = N / 2,
the first above it, is highlighted).

Colour: ``color_by="w"`` gives triangles group k (slice k) and `StackSource.group_colors`
spreads ``look.LEVEL_COLORMAP`` over the N levels (lowest w darkest); ``color_by="cell"``
keeps the inner source's groups, so a 4-D cell has one colour in every slice (today's
colours).  With one slice, colour by w keeps the inner groups too (today's view).

Cost: a polytope's N slices come from one batched `slice_polytope(polytope, matrix, levels)`;
any other source is sliced level by level (a field samples each level's region).

Pure numpy; nothing here knows about widgets.
"""

from __future__ import annotations

import copy
import math
from numbers import Integral, Real

import numpy as np

from ..core import look
from ..core.rotation import as_rotation_matrix
from ..geometry.slicing import slice_polytope
from .protocol import (
    PolytopeSource,
    SliceData,
    SourceAction,
    _fill_flags,
    _winding_row,
    apply_setting,
    as_source,
    census_text,
    data_w_text,
    no_volume_row,
    settings_of,
    takes_coarse,
    w_frame,
)

__all__ = [
    "ARRANGEMENTS",
    "MAX_SLICES",
    "OVAL_PARABOLA",
    "StackSource",
    "StackSliceData",
    "arrangement_layout",
    "stack_levels",
    "stack_offsets",
    "default_spacing",
    "highlighted_index",
]

#: The arrangements, in the order the docs list them.
ARRANGEMENTS = ("oval", "grid", "stack")
#: Most slices in a stack.
MAX_SLICES = 64
COLOR_BY = ("w", "cell")

#: The oval's parabola P(u) = (A u, Y0 + C u^2, -B u^2), |u| <= U_MAX, in displayed units; Y0 is
#: where the layout starts: it is then shifted so that the picture is centred in the frame.
OVAL_PARABOLA = {"A": 2.6, "B": 3.0, "C": 1.2, "Y0": -0.65, "U_MAX": 2.0}
#: Largest world scale of an oval slice; relative shrink of the end slices (1 - 0.4 tau^2).
OVAL_MAX_SCALE = 0.6
OVAL_SHRINK = 0.4
#: Gap between neighbouring bounding spheres, relative to the sum of their radii.
GAP = 0.05
#: Fraction of the camera frame the layout may fill.
FRAME_MARGIN = 0.97
#: The widget's default canvas, width / height (600 x 500).
VIEW_ASPECT = 600.0 / 500.0
#: g / f multiply / divide the spacing by this (Shift inverts).
SPACING_FACTOR = 2.0 ** 0.25
#: Δ stays within [SPACING_MIN, SPACING_MAX] times the source's size: g / f refuse a step
#: beyond (so the opposite key always undoes one), and setting Δ outside is a ValueError.
#: 2^-12 size: slices closer than that look the same; 4 size: every slice but one misses.
SPACING_MIN = 2.0 ** -12
SPACING_MAX = 4.0

_D = float(look.CAMERA_POSITION[2])
_HALF_H = _D * math.tan(math.radians(look.CAMERA_FOV) / 2.0)  # frame half-height at z = 0


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


def _check_arrangement(a) -> str:
    if a not in ARRANGEMENTS:
        raise ValueError(f"Expected `arrangement` to be one of {', '.join(map(repr, ARRANGEMENTS))}, got {a!r}")
    return a


def _check_color_by(c) -> str:
    if c not in COLOR_BY:
        raise ValueError(f"Expected `color_by` to be one of {', '.join(map(repr, COLOR_BY))}, got {c!r}")
    return c


# ------------------------------------------------------------------ levels and layouts
def default_spacing(size: float, n: int) -> float:
    """The default Δ = 2 size / N: N slices spread over the object's extent."""
    return 2.0 * float(size) / _check_slices(n)


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


def _frame_fit(cx, cy, cz, r):
    """Largest factor for radii ``r`` (n,) so that the spheres' images lie in the camera frame."""
    f = _D / (_D - cz)
    lim_y = FRAME_MARGIN * _HALF_H
    lim_x = VIEW_ASPECT * lim_y
    return min(float(((lim_x - np.abs(cx * f)) / (r * f)).min()), float(((lim_y - np.abs(cy * f)) / (r * f)).min()))


def _oval(n: int):
    R = look.REFERENCE_RADIUS
    A, B, C, Y0, UM = (OVAL_PARABOLA[k] for k in ("A", "B", "C", "Y0", "U_MAX"))
    tau = (np.arange(n) - (n - 1) / 2.0) / ((n - 1) / 2.0)
    g = 1.0 - OVAL_SHRINK * tau * tau
    g /= g.max()
    uu = np.linspace(0.0, UM, 2001)
    arc = np.concatenate([[0.0], np.cumsum(np.hypot(A, np.hypot(2 * C * (uu[1:] + uu[:-1]) / 2,
                                                                  2 * B * (uu[1:] + uu[:-1]) / 2)) * np.diff(uu))])
    cum = np.concatenate([[0.0], np.cumsum((g[:-1] + g[1:]) / 2.0)])
    cum -= cum[-1] / 2.0  # symmetric about the vertex, in units of one step
    step = min(2.0 * R * OVAL_MAX_SCALE * (1.0 + GAP), arc[-1] / np.abs(cum).max())
    a = cum * step
    u = np.sign(a) * np.interp(np.abs(a), arc, uu)
    centres = np.stack([A * u, Y0 + C * u * u, -B * u * u], axis=1)
    diff = np.linalg.norm(centres[:, None, :] - centres[None, :, :], axis=2)
    iu = np.triu_indices(n, 1)
    s_sep = float((diff[iu] / (R * (g[:, None] + g[None, :])[iu] * (1.0 + GAP))).min())
    # centred in the frame (few slices use only the bottom of the oval), then fitted to it
    centres[:, 1] += _vertical_centring(centres, R * min(OVAL_MAX_SCALE, s_sep) * g)
    s_fit = _frame_fit(centres[:, 0], centres[:, 1], centres[:, 2], R * g)
    scales = min(OVAL_MAX_SCALE, s_sep, s_fit) * g
    centres[:, 1] += _vertical_centring(centres, R * scales)
    s_fit = _frame_fit(centres[:, 0], centres[:, 1], centres[:, 2], R * g)
    return centres, np.minimum(scales, s_fit * g)


def _vertical_centring(centres, radii) -> float:
    """The world-y shift after which the spheres' images reach as far above the frame's middle
    as below it (their top and bottom, ``(y +- r) D / (D - z)``, balance)."""
    f = _D / (_D - centres[:, 2])
    y, r = centres[:, 1], radii

    def imbalance(dy):
        return float(((y + dy + r) * f).max() + ((y + dy - r) * f).min())

    lo, hi = -20.0, 20.0  # imbalance rises with dy
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if imbalance(mid) < 0 else (lo, mid)
    return 0.5 * (lo + hi)


def _rows(n: int, cols: int):
    R = look.REFERENCE_RADIUS
    rows = -(-n // cols)
    lim_y = FRAME_MARGIN * _HALF_H
    lim_x = VIEW_ASPECT * lim_y
    s = min(1.0, lim_x / (R * ((cols - 1) * (1.0 + GAP) + 1.0)), lim_y / (R * ((rows - 1) * (1.0 + GAP) + 1.0)))
    pitch = 2.0 * R * s * (1.0 + GAP)
    k = np.arange(n)
    r, c = k // cols, k % cols
    centres = np.stack([(c - (cols - 1) / 2.0) * pitch, ((rows - 1) / 2.0 - r) * pitch, np.zeros(n)], axis=1)
    return centres, np.full(n, s)


def arrangement_layout(name: str, n: int, radius: float = look.REFERENCE_RADIUS):
    """Where each of ``n`` slices goes: ``(centres (n, 3) float64, scales (n,) float64)``.

    Slice k of an object of circumradius ``radius`` is drawn at ``centres[k] + scales[k] * p``.
    Designed for ``radius = look.REFERENCE_RADIUS`` (what the widget shows) and the camera of
    `rot4d_widget.core.look`; other radii scale the centres (``radius / REFERENCE_RADIUS``), so the
    picture is the same once the widget scales the source to its displayed size.  See the
    module docstring for each arrangement's constants.  ``n = 1``: centre 0, scale 1.
    """
    _check_arrangement(name)
    n = _check_slices(n)
    if (isinstance(radius, (bool, np.bool_)) or not isinstance(radius, Real)
            or not (math.isfinite(radius) and radius > 0)):
        raise ValueError(f"Expected `radius` to be a finite number > 0, got {radius!r}")
    if n == 1:
        return np.zeros((1, 3)), np.ones(1)
    if name == "oval":
        centres, scales = _oval(n)
    elif name == "grid":
        centres, scales = _rows(n, math.ceil(math.sqrt(n)))
    else:
        centres, scales = _rows(n, n)
    return centres * (float(radius) / look.REFERENCE_RADIUS), scales


# ------------------------------------------------------------------ the slice data
class StackSliceData(SliceData):
    """`SliceData` of a `StackSource`: N slices placed side by side in one scene.

    ``extra`` holds: ``cuts`` (N,) the w of each slice (also under ``levels``, its old name);
    ``centres`` (N, 3) and ``scales`` (N,) the placement (source units); ``highlighted`` the
    index of the slice at w = c0; ``arrangement``; ``spacing``; ``volumes`` (N,) each slice's
    3-volume (None where it has none); ``point_offsets``, ``segment_offsets``,
    ``triangle_offsets`` (N + 1,) where slice k's rows start; ``slices`` the inner source's N
    slice objects (unplaced, unturned);
    ``group_rgb`` (n_groups, 3) the colours of the groups when coloured by w, else None.
    """

    def turned(self, rotation) -> "StackSliceData":
        """The stack at ``R3 @ matrix``: each slice turned by ``rotation`` (3, 3) about its own centre.

        The layout stays; normals are turned; ``extra["slices"]`` stays unturned.
        """
        r = np.asarray(rotation, dtype=np.float64)
        if r.shape != (3, 3) or not np.allclose(r @ r.T, np.eye(3), atol=1e-9):
            raise ValueError(f"Expected `rotation` to be a (3, 3) rotation matrix, got shape {r.shape}")
        off = self.extra["point_offsets"]
        centre = np.repeat(np.asarray(self.extra["centres"]), np.diff(off), axis=0)
        points = (self.points - centre) @ r.T + centre
        normals = None if self.normals is None else self.normals @ r.T
        return type(self).build(points, self.segments, self.triangles, self.groups, normals=normals,
                                volume=self.volume, readout=self.readout, convex=self.convex,
                                show_points=self.show_points, extra=self.extra, corner_only=self.corner_only)


_SHORT = {3: "tri", 4: "quad", 5: "pent", 6: "hex", 7: "hept", 8: "oct", 9: "non", 10: "dec"}


def _short_census(s) -> str:
    if s.dim < 0:
        return "empty"
    census = s.face_census()
    if not census:
        return "touches"
    return " ".join(f"{c} {_SHORT.get(n, f'{n}-gon')}" for n, c in sorted(census.items()))


class StackSource:
    """N parallel slices of ``source`` under one orientation, placed by an arrangement, as ONE source.

    Parameters
    ----------
    source : a polytope name, a `Polytope` or any source (`rot4d_widget.Source`)
    slices : int in 1 ... 64 -- N
    spacing : float > 0 or None -- Δ, in the source's units; None: ``2 size / N`` (follows N)
    arrangement : "oval", "grid" or "stack" (see the module docstring)
    color_by : "w" (a colormap over the N levels) or "cell" (the inner source's groups)

    ``slices``, ``spacing``, ``arrangement`` and ``color_by`` are validated properties; keys
    n / b add / remove a slice and g / f widen / narrow Δ (``actions``).  ``slice(matrix,
    c0)`` takes ``coarse=`` exactly when the inner source's slice does.
    """

    def __init__(self, source, slices: int = 5, spacing=None, arrangement: str = "oval", color_by: str = "w"):
        self.source = as_source(source)
        self.slices = slices
        self.spacing = spacing
        self.arrangement = arrangement
        self.color_by = color_by
        self._polytope = getattr(self.source, "polytope", None) if _is_polytope_source(self.source) else None
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

    @property
    def spacing(self) -> float:
        """Δ in the source's units (the default ``2 size / N`` unless set; setting None restores it)."""
        return self._spacing if self._spacing is not None else default_spacing(self.size, self._slices)

    @spacing.setter
    def spacing(self, value) -> None:
        d = _check_spacing(value)
        if d is not None:
            lo, hi = self.spacing_range
            if not lo <= d <= hi:
                raise ValueError(f"Expected `spacing` in [{lo:.4g}, {hi:.4g}] ({SPACING_MIN:g} \u2026 {SPACING_MAX:g} "
                                 f"times the source's size {self.size:.4g}) or None, got {d!r}")
        self._spacing = d

    @property
    def spacing_range(self) -> tuple:
        """(lowest, highest) Δ allowed: `SPACING_MIN` and `SPACING_MAX` times the source's size."""
        return SPACING_MIN * self.size, SPACING_MAX * self.size

    @property
    def spacing_is_default(self) -> bool:
        return self._spacing is None

    @property
    def arrangement(self) -> str:
        return self._arrangement

    @arrangement.setter
    def arrangement(self, value) -> None:
        self._arrangement = _check_arrangement(value)

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
        inner = getattr(self.source, "name", None) or type(self.source).__name__
        return f"{inner}, {self._slices} slice{'s' if self._slices != 1 else ''}"

    @property
    def edge_length(self):
        """The inner source's edge length times the largest scale (the widget sizes balls by it)."""
        e = getattr(self.source, "edge_length", None)
        if e is None:
            return None
        return float(e) * float(self.layout()[1].max())

    def w_range(self, matrix) -> tuple:
        f = getattr(self.source, "w_range", None)
        return tuple(f(matrix)) if f is not None else (-self.size, self.size)

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
        """A stack around a copy of the inner source (replaying its actions changes the copy only)."""
        return StackSource(copy.copy(self.source), slices=self._slices, spacing=self._spacing,
                           arrangement=self._arrangement, color_by=self._color_by)

    @property
    def w_frame(self) -> tuple:
        """The inner source's ``(origin, per_unit)`` (`rot4d_widget.sources.protocol.w_frame`): c0 and the
        cuts are in its w units, Δ in the drawn units (a cut is Δ * per_unit from the next)."""
        return w_frame(self.source)

    def cut_offsets(self) -> np.ndarray:
        """(N,) float64: each cut's offset from c0, in c0's units, ``(k - (N - 1)/2) Δ per_unit``
        (`stack_offsets`)."""
        return stack_offsets(self._slices, self.spacing * w_frame(self.source)[1])

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
        return look.level_colors(np.arange(self._slices, dtype=float), 0.0, self._slices - 1.0)

    def describe(self) -> dict:
        return {"kind": "stack", "source": self.source.describe(), "slices": self._slices,
                "spacing": self._spacing, "arrangement": self._arrangement, "color_by": self._color_by}

    @property
    def actions(self) -> dict:
        """n / b: one slice more / fewer; g / f: Δ times / divided by 2^(1/4) (Shift inverts each);
        and the inner source's own keys (a field's o / i), which act on every slice."""
        inner = getattr(self.source, "actions", None) or {}
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
        self._slices = n
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
            return [self.source.slice(matrix, float(w), coarse=True) for w in cuts]
        return [self.source.slice(matrix, float(w)) for w in cuts]

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
        has_normals = all(getattr(p, "normals", None) is not None for p in pieces)
        for k, piece in enumerate(pieces):
            p = np.asarray(piece.points, dtype=np.float64).reshape(-1, 3)
            pts.append(p * scales[k] + centres[k] if n > 1 else p)
            flags = getattr(piece, "corner_only", None)  # fill corners: no ball
            corners.append(np.zeros(len(p), dtype=bool) if flags is None else np.asarray(flags, dtype=bool))
            segs.append(np.asarray(piece.segments, dtype=np.intp).reshape(-1, 2) + p_off[-1])
            t = np.asarray(piece.triangles, dtype=np.intp).reshape(-1, 3)
            tris.append(t + p_off[-1])
            groups.append(np.full(len(t), k, dtype=np.intp) if by_w else np.asarray(piece.groups, dtype=np.intp))
            if has_normals:
                nrms.append(np.asarray(piece.normals, dtype=np.float64).reshape(-1, 3))
            v = getattr(piece, "volume", None)
            volumes.append(None if v is None else float(v))
            p_off.append(p_off[-1] + len(p))
            s_off.append(s_off[-1] + len(segs[-1]))
            t_off.append(t_off[-1] + len(t))
        hi = highlighted_index(n)
        extra = {
            "cuts": cuts, "levels": cuts, "centres": centres, "scales": scales, "highlighted": hi,
            "arrangement": self._arrangement, "spacing": self.spacing, "volumes": tuple(volumes),
            "point_offsets": np.array(p_off), "segment_offsets": np.array(s_off),
            "triangle_offsets": np.array(t_off), "slices": tuple(getattr(p, "data", p) for p in pieces),
            "group_rgb": self.group_colors(),
        }
        if n == 1:  # today's view: the inner slice's volume and readout as they are
            return StackSliceData.build(
                pts[0], segs[0], tris[0], groups[0], normals=nrms[0] if has_normals else None,
                volume=volumes[0], readout=tuple(getattr(pieces[0], "readout", ())),
                convex=bool(getattr(pieces[0], "convex", False)),
                show_points=bool(getattr(pieces[0], "show_points", True)), extra=extra, corner_only=corners[0])
        return StackSliceData.build(
            np.concatenate(pts), np.concatenate(segs), np.concatenate(tris), np.concatenate(groups),
            normals=np.concatenate(nrms) if has_normals else None, volume=None,
            readout=self._readout(cuts, pieces, volumes, hi, m), convex=False,
            show_points=any(bool(getattr(p, "show_points", True)) for p in pieces), extra=extra,
            corner_only=np.concatenate(corners) if corners else None)

    def _readout(self, cuts, pieces, volumes, hi, m) -> tuple:
        """Rows for the readout: each slice labelled by its w in the data's own units (a field's
        time, `data_w_text`), its census (polytopes) and volume (the source's own units)."""
        n = len(cuts)
        how = "colour by w (viridis, low w dark)" if self._color_by == "w" else "colour by cell"
        wpu = getattr(self.source, "w_per_unit", None)
        unit = getattr(self.source, "w_units", None)
        delta = look.number_text(self.spacing * (wpu if wpu is not None else 1.0))
        delta += f" {unit}" if wpu is not None and unit else ""
        rows = [("stack", f"{n} slices, \u0394 = {delta}, {self._arrangement}, {how}")]
        polytope = self._polytope is not None
        if n <= 12:
            for k, (w, piece, v) in enumerate(zip(cuts, pieces, volumes)):
                label = ("\u25b8 " if k == hi else "") + data_w_text(self.source, w, m)
                parts = []
                if polytope:
                    parts.append(_short_census(piece.slice))
                if v is not None:
                    space = getattr(self.source, "space_units", None)
                    parts.append(f"vol {look.number_text(v)}" + (f" {space}\u00b3" if space else ""))
                rows.append((label, ", ".join(parts) or "\u2014"))
        else:
            rows.append(("w", f"{data_w_text(self.source, cuts[0], m)[2:]} \u2026 "
                              f"{data_w_text(self.source, cuts[-1], m)[2:]} "
                              f"(\u25b8 {data_w_text(self.source, cuts[hi], m)[2:]})"))
            if any(v is not None for v in volumes):
                rows.append(("volumes", " ".join("\u2014" if v is None else f"{v:.3g}" for v in volumes)))
        if polytope:  # a hemi or non-orientable polytope: its slices have no volume, and why
            rows += no_volume_row(self._polytope)
        return tuple(rows)

    def __repr__(self) -> str:
        return (f"StackSource({self.source!r}, slices={self._slices}, spacing={self.spacing:.4g}, "
                f"arrangement={self._arrangement!r}, color_by={self._color_by!r})")


class _PolytopePiece:
    """A polytope `Slice` seen as slice data (what `PolytopeSource.slice` would give)."""

    __slots__ = ("slice", "convex", "rows")

    def __init__(self, s, polytope):
        self.slice = s
        self.convex = bool(polytope.convex)  # a convex polytope's slice is convex; a non-convex one's may not be
        self.rows = _winding_row(polytope)  # self-intersecting; no volume, and why (hemi, not orientable)

    points = property(lambda self: self.slice.vertices)
    segments = property(lambda self: self.slice.edges)
    triangles = property(lambda self: self.slice.triangles)
    groups = property(lambda self: self.slice.triangle_cells)
    normals = None
    volume = property(lambda self: None if self.slice.volume is None else float(self.slice.volume))
    readout = property(lambda self: (("slice", census_text(self.slice)),) + self.rows)
    show_points = True
    corner_only = property(lambda self: _fill_flags(self.slice))  # as `PolytopeSource.slice` flags them
    data = property(lambda self: self.slice)


def _is_polytope_source(src) -> bool:
    """One of the package's three class tests, kept for speed, not for meaning: the N slices of
    our own polytope source come from one batched `slice_polytope` call instead of N ``slice``
    calls (the same slices); any other source, a user's polytope-like one too, is sliced through
    the protocol."""
    return isinstance(src, PolytopeSource)

