"""Where a stack's N parallel slices sit in the view: the oval, the grid and the row.

`arrangement_layout` gives slice k a centre and a scale: a point p of it is drawn at
``centre_k + scale_k * p`` (`rot4d_widget.sources.tomography.StackSource`).  It is designed in
displayed units (the circumradius `sizes.REFERENCE_RADIUS`, the eye at (0, 0, 5), the default
600 x 500 canvas) and scaled to the source's.  ``"oval"``: centres on a parabola that perspective
draws as an oval, the central slice nearest the eye (Kageyama's follow-up, J. Visualization
2016); ``"grid"``: small multiples like a CT film; ``"stack"``: one row along x.  N = 1 is the
identity in every arrangement.  The constants and why: docs/design.md, "Parallel slices".
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
    picture is the same once the widget scales the source to its displayed size.  Each
    arrangement's constants: docs/design.md, "Parallel slices".  ``n = 1``: centre 0, scale 1.
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
