"""How a field's cut is drawn: the renderings, where the sections cross the cut, the volume's density,
and the checks of these view settings (the widget's traits, a state file and a recording alike).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "RENDERINGS", "RENDERING_TEXT", "DEFAULT_SECTIONS", "DEFAULT_DENSITY", "check_rendering",
    "check_sections", "check_projection",
]

#: How a field's cut is drawn (the widget's `rendering`, napari's name): ``"surface"`` its
#: isosurfaces (the default), ``"volume"`` emission-absorption ray casting of the cut's values,
#: ``"mip"`` their maximum along each ray, ``"sections"`` three orthogonal colour-mapped planes
#: through the cut.  The rendering key cycles them in this order (Shift: backwards).
RENDERINGS = ("surface", "volume", "mip", "sections")
#: Where the three planes of ``"sections"`` cross the cut's grid: a fraction of its extent along
#: each of x, y, z (0 the first node, 1 the last).
DEFAULT_SECTIONS = (0.5, 0.5, 0.5)
#: ``"volume"``: the optical depth across the cut grid's longest side of a medium at the top of
#: the opacity ramp (the live view's shader and a static picture's ray caster alike).
DEFAULT_DENSITY = 4.0
#: What each ray-cast rendering shows, for readouts and annotations ({name}: the field's name).
RENDERING_TEXT = {
    "mip": "maximum intensity: the highest {name} along each line of sight",
    "volume": "volume: {name} glows and absorbs, the more the higher it is (colour bar)",
    "sections": "sections: {name} on three planes of the cut",
}


def check_projection(value, name: str = "projection") -> bool:
    """``value`` as a bool when it is True or False (a numpy bool too), else a TypeError naming
    what is allowed: the ``projection`` view setting (the widget's trait and recordings alike)."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"Expected `{name}` to be True or False, got {value!r}")
    return bool(value)


def check_rendering(rendering, name: str = "rendering") -> str:
    """``rendering`` when it is one of `RENDERINGS`, else a ValueError (TypeError for a
    non-string) naming them.

    >>> check_rendering("mip")
    'mip'
    """
    allowed = ", ".join(repr(r) for r in RENDERINGS)
    if not isinstance(rendering, str):
        raise TypeError(f"Expected `{name}` to be one of {allowed}, got {rendering!r}")
    if rendering not in RENDERINGS:
        raise ValueError(f"Expected `{name}` to be one of {allowed}, got {rendering!r}")
    return rendering


def check_sections(sections, name: str = "sections") -> tuple:
    """The positions of the three section planes: (fx, fy, fz), each a finite number in [0, 1]
    (a fraction of the cut grid's extent along x, y, z), as a tuple of floats.

    >>> check_sections([0, 0.25, 1])
    (0.0, 0.25, 1.0)
    """
    allowed = "(fx, fy, fz): three numbers in [0, 1], fractions of the cut's extent along x, y, z"
    try:
        triple = tuple(sections)
    except TypeError:
        raise TypeError(f"Expected `{name}` to be {allowed}, got {sections!r}") from None
    if (isinstance(sections, str) or len(triple) != 3
            or not all(isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, (bool, np.bool_))
                       for v in triple)):
        raise TypeError(f"Expected `{name}` to be {allowed}, got {sections!r}")
    out = tuple(float(v) for v in triple)
    if not all(math.isfinite(v) and 0.0 <= v <= 1.0 for v in out):
        raise ValueError(f"Expected `{name}` to be {allowed}, got {sections!r}")
    return out
