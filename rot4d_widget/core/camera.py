"""The camera: where the eye is and how it sees, for the static pictures and the live view alike.

The paper's viewpoint: the eye at ``CAMERA_POSITION`` = (0, 0, 5) looking down -z, a perspective camera
with vertical field of view ``CAMERA_FOV`` degrees (a three.js ``PerspectiveCamera``; a figure uses the
same fov and its own aspect).  A point (x, y, z) in displayed units (`rot4d_widget.core.sizes`) lands at
``(x, y) / ((d - z) tan(fov / 2))`` in normalised device coordinates (y; x is further divided by the
aspect width / height), d = 5.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "CAMERA_POSITION", "SECTIONS_CAMERA_POSITION", "CAMERA_FOV", "CAMERA_NEAR", "CAMERA_FAR",
    "default_eye", "view_rotation",
]

#: Where the eye is (displayed units); it looks down -z at the origin.
CAMERA_POSITION = (0.0, 0.0, 5.0)
#: Where the eye is by default in the "sections" rendering (displayed units, 5 from the origin as
#: `CAMERA_POSITION`, looking at it, up +y): above, right of and in front of the cut, so that all
#: three section planes are seen at a slant, none edge-on (issue 37).
SECTIONS_CAMERA_POSITION = tuple(5.0 * v / math.sqrt(2.1**2 + 1.7**2 + 4.2**2) for v in (2.1, 1.7, 4.2))
#: Vertical field of view in degrees (three.js ``PerspectiveCamera.fov``).
CAMERA_FOV = 40.0
#: Near and far clipping distances of the live camera.
CAMERA_NEAR = 0.1
CAMERA_FAR = 100.0



def default_eye(rendering: str) -> tuple:
    """Where the camera is by default for ``rendering``: `SECTIONS_CAMERA_POSITION` for
    "sections" (three planes, none edge-on), else `CAMERA_POSITION` (the paper's viewpoint)."""
    return SECTIONS_CAMERA_POSITION if rendering == "sections" else CAMERA_POSITION


def view_rotation(eye) -> np.ndarray:
    """(3, 3) float64: the rotation taking scene coordinates to those of a camera at ``eye`` (3,)
    looking at the origin with +y up (three.js ``lookAt``): its rows are the camera's x, y and z
    axes, so that the camera sits on its own +z axis at ``|eye|``, as the static pictures' camera
    does.  The identity for `CAMERA_POSITION`.

    >>> view_rotation((0.0, 0.0, 5.0)).tolist()
    [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    """
    e = np.asarray(eye, dtype=np.float64).reshape(3)
    n = float(np.linalg.norm(e))
    if not (np.all(np.isfinite(e)) and n > 0):
        raise ValueError(f"Expected `eye` to be a finite point other than the origin, got {tuple(e)}")
    z = e / n
    x = np.cross((0.0, 1.0, 0.0), z)
    if np.linalg.norm(x) < 1e-12:
        raise ValueError(f"Expected `eye` off the vertical axis (the camera looks at the origin with +y up), "
                         f"got {tuple(e)}")
    x /= np.linalg.norm(x)
    return np.vstack([x, np.cross(z, x), z])
