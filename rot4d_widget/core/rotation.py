"""Plane rotations and double rotations in 4-D (pure numpy).

Conventions (Kageyama, *Keyboard based control of four dimensional rotations*):

* Axes x, y, z, w are indices 0, 1, 2, 3 (the paper numbers them 1..4).
* ``simple_rotation(plane, angle)`` has ``cos, -sin`` / ``sin, cos`` in rows and
  columns (i, j) of ``plane`` -- eq. (5) of the paper for ``"xy"``.
* A double rotation is the (commuting) product of two simple rotations in
  absolutely perpendicular planes -- eq. (4) for ``"xy,zw"``.
* Composition is **extrinsic**: a step about the fixed frame is applied on the
  left, ``new = step @ old``.  Points are rows, rotated as ``points @ matrix.T``.

Every function returns a fresh (4, 4) float64 array.
"""

from __future__ import annotations

import numpy as np

from . import tolerances as tol_
from .validate import real

__all__ = [
    "random_rotation",
    "AXES",
    "PLANES",
    "DOUBLE_PLANES",
    "simple_rotation",
    "double_rotation",
    "as_rotation_matrix",
    "reorthonormalize",
    "quaternion_xyzw",
]

AXES = "xyzw"
PLANES = ("xy", "xz", "xw", "yz", "yw", "zw")
#: The three double rotations of the paper's Table 1, keyed by their planes.
DOUBLE_PLANES = ("xy,zw", "xz,yw", "xw,yz")

_PLANE_AXES = {p: (AXES.index(p[0]), AXES.index(p[1])) for p in PLANES}

#: How far from orthogonal a user-supplied matrix may be (max |M M^T - I|):
#: `rot4d_widget.core.tolerances.ORTHOGONALITY`.
ORTHOGONALITY_TOLERANCE = tol_.ORTHOGONALITY


def _check_angle(name: str, value) -> float:
    return real(value, name, what="a real number (radians)", finite_what="a finite number of radians")


def _plane_axes(plane) -> tuple[int, int]:
    try:
        return _PLANE_AXES[plane]
    except (KeyError, TypeError):
        raise ValueError(
            f"Unknown rotation plane {plane!r}; expected one of {', '.join(map(repr, PLANES))}"
        ) from None


def simple_rotation(plane: str, angle: float) -> np.ndarray:
    """Rotation by ``angle`` (radians) in ``plane``, one of ``"xy" "xz" "xw" "yz" "yw" "zw"``.

    Returns a (4, 4) float64 matrix R with ``R[i, i] = R[j, j] = cos(angle)``,
    ``R[i, j] = -sin(angle)``, ``R[j, i] = sin(angle)`` for the plane's axes i < j,
    and the identity elsewhere (the paper's eqs. (3), (5), (6)).

    >>> r = simple_rotation("xw", np.pi / 2)
    >>> np.round(r, 12) + 0.0
    array([[ 0.,  0.,  0., -1.],
           [ 0.,  1.,  0.,  0.],
           [ 0.,  0.,  1.,  0.],
           [ 1.,  0.,  0.,  0.]])
    >>> np.allclose(np.array([1.0, 0, 0, 0]) @ r.T, [0, 0, 0, 1])  # points are rows: x turns to w
    True
    """
    i, j = _plane_axes(plane)
    angle = _check_angle("angle", angle)
    c, s = np.cos(angle), np.sin(angle)
    m = np.eye(4)
    m[i, i] = c
    m[i, j] = -s
    m[j, i] = s
    m[j, j] = c
    return m


def double_rotation(planes: str, alpha: float, beta: float) -> np.ndarray:
    """Double rotation in two absolutely perpendicular planes, e.g. ``"xy,zw"``.

    ``planes`` is one of ``"xy,zw" "xz,yw" "xw,yz"``; ``alpha`` turns the first
    plane and ``beta`` the second.  The two factors commute, so the result is
    ``simple_rotation(p1, alpha) @ simple_rotation(p2, beta)`` in either order
    (eq. (4) of the paper for ``"xy,zw"``).

    >>> m = double_rotation("xy,zw", 0.3, 0.5)
    >>> np.allclose(m, simple_rotation("xy", 0.3) @ simple_rotation("zw", 0.5))
    True
    >>> np.allclose(m, simple_rotation("zw", 0.5) @ simple_rotation("xy", 0.3))  # they commute
    True
    """
    if planes not in DOUBLE_PLANES:
        raise ValueError(
            f"Unknown double-rotation planes {planes!r}; expected one of "
            f"{', '.join(map(repr, DOUBLE_PLANES))}"
        )
    p1, p2 = planes.split(",")
    alpha = _check_angle("alpha", alpha)
    beta = _check_angle("beta", beta)
    # The two blocks touch disjoint rows/columns: write both into one identity.
    m = simple_rotation(p1, alpha)
    i, j = _PLANE_AXES[p2]
    c, s = np.cos(beta), np.sin(beta)
    m[i, i] = c
    m[i, j] = -s
    m[j, i] = s
    m[j, j] = c
    return m


def as_rotation_matrix(matrix, name: str = "matrix") -> np.ndarray:
    """Validate a 4-D rotation: (4, 4), finite, orthogonal with det +1.

    Returns a **fresh** C-contiguous float64 array, never the caller's own
    (so neither side can later edit what the other holds).  Raises
    ``TypeError`` for non-numeric input and ``ValueError`` naming what is
    expected otherwise.

    >>> a = np.eye(4)
    >>> m = as_rotation_matrix(a); m is a, m.dtype, m.shape
    (False, dtype('float64'), (4, 4))
    >>> as_rotation_matrix(np.eye(3))
    Traceback (most recent call last):
    ...
    ValueError: Expected `matrix` to have shape (4, 4), got (3, 3)
    >>> as_rotation_matrix(np.diag([1.0, 1.0, 1.0, -1.0]))
    Traceback (most recent call last):
    ...
    ValueError: Expected `matrix` to be a rotation (det +1), got a reflection (det -1)
    """
    try:
        m = np.array(matrix, dtype=np.float64, order="C", copy=True)
    except (TypeError, ValueError):
        raise TypeError(f"Expected `{name}` to be a (4, 4) array of real numbers") from None
    if m.shape != (4, 4):
        raise ValueError(f"Expected `{name}` to have shape (4, 4), got {m.shape}")
    if not np.all(np.isfinite(m)):
        raise ValueError(f"Expected `{name}` to be finite, got non-finite entries")
    err = np.abs(m @ m.T - np.eye(4)).max()
    if err > ORTHOGONALITY_TOLERANCE:
        raise ValueError(
            f"Expected `{name}` to be orthogonal (|M M^T - I| <= {ORTHOGONALITY_TOLERANCE:g}), "
            f"got deviation {err:.3g}"
        )
    if np.linalg.det(m) < 0:
        raise ValueError(f"Expected `{name}` to be a rotation (det +1), got a reflection (det -1)")
    return m


def reorthonormalize(matrix: np.ndarray) -> np.ndarray:
    """One Newton-Schulz step towards the nearest orthogonal matrix.

    ``M <- M (3 I - M^T M) / 2`` squares the deviation from orthogonality, so
    applied after every composed step it keeps ``|M M^T - I|`` at rounding level
    however many steps are taken (without it the error grows like sqrt(steps)).
    """
    return 1.5 * matrix - 0.5 * (matrix @ (matrix.T @ matrix))


def quaternion_xyzw(r) -> tuple:
    """(x, y, z, w) floats: the unit quaternion of the 3-D rotation matrix ``r`` (3, 3), as
    three.js reads ``Object3D.quaternion`` (Shepperd's method: the largest square first).

    >>> quaternion_xyzw(np.eye(3))
    (0.0, 0.0, 0.0, 1.0)
    """
    r = np.asarray(r, dtype=np.float64).reshape(3, 3)
    t = float(np.trace(r))
    if t > 0:
        s = 2.0 * float(np.sqrt(t + 1.0))
        q = [(r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s, 0.25 * s]
    else:
        i = int(np.argmax(np.diag(r)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * float(np.sqrt(1.0 + r[i, i] - r[j, j] - r[k, k]))
        q = [0.0, 0.0, 0.0, (r[k, j] - r[j, k]) / s]
        q[i], q[j], q[k] = 0.25 * s, (r[j, i] + r[i, j]) / s, (r[k, i] + r[i, k]) / s
    return tuple(float(v) for v in q)


def random_rotation(rng=None) -> np.ndarray:
    """A uniformly random (4, 4) rotation (Haar measure, det +1) from ``rng``
    (a numpy Generator or a seed)."""
    rng = np.random.default_rng(rng)
    q, r = np.linalg.qr(rng.standard_normal((4, 4)))
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    return q
