"""Where a stack's N parallel slices sit in the view: the oval, the grid and the row.

`arrangement_layout` is designed in displayed units -- the object's circumradius
`sizes.REFERENCE_RADIUS`, the eye at (0, 0, 5) looking down -z, vertical fov 40 degrees, the
default canvas aspect 600 / 500 -- and scaled to the source's units.  A point p of slice k is
drawn at ``centre_k + scale_k * p`` (`rot4d_widget.sources.tomography.StackSource`).

The arrangements:

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

N = 1 is the identity in every arrangement (centre 0, scale 1).

Pure numpy: geometry of the picture, nothing about slicing or widgets.
"""

from __future__ import annotations

import math
from numbers import Integral, Real

import numpy as np

from ..core import camera, sizes

__all__ = ["ARRANGEMENTS", "OVAL_PARABOLA", "arrangement_layout", "check_arrangement"]

#: The arrangements, in the order the docs list them.
ARRANGEMENTS = ("oval", "grid", "stack")
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

_D = float(camera.CAMERA_POSITION[2])
_HALF_H = _D * math.tan(math.radians(camera.CAMERA_FOV) / 2.0)  # frame half-height at z = 0


def check_arrangement(a) -> str:
    """``a`` if it names an arrangement, else a ValueError naming them."""
    if a not in ARRANGEMENTS:
        raise ValueError(f"Expected `arrangement` to be one of {', '.join(map(repr, ARRANGEMENTS))}, got {a!r}")
    return a


def _frame_fit(cx, cy, cz, r):
    """Largest factor for radii ``r`` (n,) so that the spheres' images lie in the camera frame."""
    f = _D / (_D - cz)
    lim_y = FRAME_MARGIN * _HALF_H
    lim_x = VIEW_ASPECT * lim_y
    return min(float(((lim_x - np.abs(cx * f)) / (r * f)).min()), float(((lim_y - np.abs(cy * f)) / (r * f)).min()))


def _oval(n: int):
    R = sizes.REFERENCE_RADIUS
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
    R = sizes.REFERENCE_RADIUS
    rows = -(-n // cols)
    lim_y = FRAME_MARGIN * _HALF_H
    lim_x = VIEW_ASPECT * lim_y
    s = min(1.0, lim_x / (R * ((cols - 1) * (1.0 + GAP) + 1.0)), lim_y / (R * ((rows - 1) * (1.0 + GAP) + 1.0)))
    pitch = 2.0 * R * s * (1.0 + GAP)
    k = np.arange(n)
    r, c = k // cols, k % cols
    centres = np.stack([(c - (cols - 1) / 2.0) * pitch, ((rows - 1) / 2.0 - r) * pitch, np.zeros(n)], axis=1)
    return centres, np.full(n, s)


def arrangement_layout(name: str, n: int, radius: float = sizes.REFERENCE_RADIUS):
    """Where each of ``n`` slices goes: ``(centres (n, 3) float64, scales (n,) float64)``.

    Slice k of an object of circumradius ``radius`` is drawn at ``centres[k] + scales[k] * p``.
    Designed for ``radius = sizes.REFERENCE_RADIUS`` (what the widget shows) and the camera of
    `rot4d_widget.core.camera`; other radii scale the centres (``radius / REFERENCE_RADIUS``), so the
    picture is the same once the widget scales the source to its displayed size.  See the
    module docstring for each arrangement's constants.  ``n = 1``: centre 0, scale 1.
    """
    check_arrangement(name)
    if isinstance(n, (bool, np.bool_)) or not isinstance(n, Integral) or n < 1:
        raise ValueError(f"Expected `slices` to be an int >= 1, got {n!r}")
    n = int(n)
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
    return centres * (float(radius) / sizes.REFERENCE_RADIUS), scales
