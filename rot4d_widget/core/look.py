"""How things look: the one place for the palette, reference scale, camera, default radii and colours.

The static pictures (`rot4d_widget.keep`, matplotlib) and the live view (`rot4d_widget.view.scene` and
`rot4d_widget.view.buffers`, pythreejs) both read these names, so a 4-D cell, a ball or the frame look the
same in both.  numpy only at import: no widget library; matplotlib only inside the colour map
functions (`level_colors`, `check_cmap`, `cmap_stops`: for its colormaps), imported when called.

Scale
    Every polytope is shown scaled by ``REFERENCE_RADIUS / circumradius``: its displayed
    circumradius is that of the paper's pentachoron (edge a = 2), ``a sqrt(2/5)``.
Camera
    The paper's viewpoint: the eye at ``CAMERA_POSITION`` = (0, 0, 5) looking down -z, a perspective
    camera with vertical field of view ``CAMERA_FOV`` degrees (a three.js ``PerspectiveCamera``; a
    figure uses the same fov and its own aspect).  A point (x, y, z) in displayed units lands at
    ``(x, y) / ((d - z) tan(fov / 2))`` in normalised device coordinates (y; x is further divided by
    the aspect width / height), d = 5.
Radii
    ``default_ball_radius(displayed_edge)`` and ``default_bar_radius(ball_radius)``, in displayed
    units.
Colours
    ``BACKGROUND``, ``BALL_COLOR``, ``BAR_COLOR`` ('#rrggbb'); faces are ``FACE_OPACITY`` opaque and
    coloured by group (the 4-D cell a face is cut from) with ``group_palette``, or all
    ``SINGLE_FACE_COLOR`` when one colour is chosen for every face.  ``as_rgb`` reads any of
    these colour forms.
"""

from __future__ import annotations

import difflib
import math

import numpy as np

from . import tolerances as tol_
from .validate import int_in_range

__all__ = [
    "REFERENCE_RADIUS",
    "CAMERA_POSITION",
    "SECTIONS_CAMERA_POSITION",
    "RENDERING_TEXT",
    "default_eye",
    "view_rotation",
    "CAMERA_FOV",
    "CAMERA_NEAR",
    "CAMERA_FAR",
    "BACKGROUND",
    "BALL_COLOR",
    "BAR_COLOR",
    "FACE_OPACITY",
    "SINGLE_FACE_COLOR",
    "default_ball_radius",
    "default_bar_radius",
    "as_rgb",
    "group_palette",
    "cell_palette",
    "LEVEL_COLORMAP",
    "check_cmap",
    "check_clim",
    "RENDERINGS",
    "DEFAULT_SECTIONS",
    "DEFAULT_DENSITY",
    "default_clim",
    "check_rendering",
    "check_sections",
    "level_colors",
    "cmap_stops",
    "hex_color",
]

# -- scale and camera ----------------------------------------------------------

#: Displayed circumradius of every object: the paper's pentachoron (edge a = 2), a sqrt(2/5).
REFERENCE_RADIUS = 2.0 * math.sqrt(2.0 / 5.0)

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
    does.  The identity for `look.CAMERA_POSITION`.

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



# -- colours -------------------------------------------------------------------

BACKGROUND = "#ffffff"
BALL_COLOR = "#c8102e"
BAR_COLOR = "#4a4a4a"
#: Opacity of the faces (0 transparent ... 1 opaque).
FACE_OPACITY = 0.35
#: Every face's colour when faces are not coloured by group: a light steel blue.
SINGLE_FACE_COLOR = "#9fb6cd"


# -- radii -----------------------------------------------------------------------


def default_ball_radius(displayed_edge: float) -> float:
    """Ball radius for an object whose edges are ``displayed_edge`` long (displayed units).

    ``min(0.07, 0.1 * displayed_edge)``: the pentachoron's 0.07 at most, smaller for dense
    polytopes so that neighbouring balls do not merge.
    """
    return min(0.07, 0.1 * float(displayed_edge))


def default_bar_radius(ball_radius: float) -> float:
    """Bar radius that goes with balls of ``ball_radius``: ``0.4 * ball_radius``."""
    return 0.4 * float(ball_radius)


# -- colour conversion and the group palette -----------------------------------

_HEX = "0123456789abcdefABCDEF"


def as_rgb(color, name: str = "color") -> tuple:
    """``'#rgb'``, ``'#rrggbb'`` or (r, g, b) floats in [0, 1] -> (r, g, b) floats."""
    if isinstance(color, str):
        s = color.strip()
        if s.startswith("#") and len(s) in (4, 7) and all(ch in _HEX for ch in s[1:]):
            h = s[1:] if len(s) == 7 else "".join(ch * 2 for ch in s[1:])
            return tuple(int(h[i : i + 2], 16) / 255.0 for i in (0, 2, 4))
    else:
        try:
            rgb = tuple(float(x) for x in color)
        except (TypeError, ValueError):
            rgb = None
        if rgb is not None and len(rgb) == 3 and all(0.0 <= x <= 1.0 for x in rgb):
            return rgb
    raise ValueError(
        f"Expected `{name}` to be '#rgb', '#rrggbb' or three floats in [0, 1], got {color!r}"
    )


def group_palette(n_cells: int) -> np.ndarray:
    """Deterministic, distinct colours for ``n_cells`` cells: (n_cells, 3) float32 in [0, 1].

    Hue and lightness follow the R2 low-discrepancy sequence (golden-ratio
    generalisation), so any few consecutive cells differ clearly and up to
    several thousand cells get distinct 8-bit colours.  Prefix-stable: row k
    depends on k only, so group k has one colour whatever ``n_cells`` is.
    """
    n = int_in_range(int(n_cells), "n_cells", 0)
    g = 1.32471795724474602596  # plastic number: R2 sequence
    k = np.arange(n, dtype=np.float64)
    hue = np.mod(0.5 + k / g, 1.0)
    light = 0.42 + 0.30 * np.mod(0.5 + k / (g * g), 1.0)
    sat = 0.72
    # HSL -> RGB, vectorised
    c = (1.0 - np.abs(2.0 * light - 1.0)) * sat
    h6 = hue * 6.0
    x = c * (1.0 - np.abs(np.mod(h6, 2.0) - 1.0))
    sector = np.floor(h6).astype(np.intp) % 6
    zeros = np.zeros(n)
    table = np.stack(
        [
            np.stack([c, x, zeros], 1),
            np.stack([x, c, zeros], 1),
            np.stack([zeros, c, x], 1),
            np.stack([zeros, x, c], 1),
            np.stack([x, zeros, c], 1),
            np.stack([c, zeros, x], 1),
        ]
    )  # (6, n, 3)
    rgb = table[sector, np.arange(n)] + (light - c / 2.0)[:, None]
    return np.clip(rgb, 0.0, 1.0).astype(np.float32)


#: The name the live view has used (``rot4d_widget.view.buffers.cell_palette``).
cell_palette = group_palette


#: Opacity of nested iso-surfaces (several levels); one level alone is opaque.
SURFACE_OPACITY = 0.45

#: The colormap of iso levels (matplotlib's name): the widget's default `cmap`.
LEVEL_COLORMAP = "viridis"


def check_cmap(cmap, name: str = "cmap") -> str:
    """A matplotlib colour map name (``"viridis"``, ``"magma_r"`` ...), as given.

    A TypeError for a non-string, a ValueError naming near matches and how to list them all
    (``sorted(matplotlib.colormaps)``) for an unknown name.
    """
    from matplotlib import colormaps  # here, not at the top: the core imports numpy only

    if not isinstance(cmap, str):
        raise TypeError(f"Expected `{name}` to be a matplotlib colour map name (a str; list them with "
                        f"sorted(matplotlib.colormaps)), got {cmap!r}")
    if cmap not in colormaps:
        near = difflib.get_close_matches(cmap, list(colormaps), n=3)
        hint = f" (did you mean {', '.join(map(repr, near))}?)" if near else ""
        raise ValueError(f"Expected `{name}` to be a matplotlib colour map name such as 'viridis'{hint}; "
                         f"list them with sorted(matplotlib.colormaps); got {cmap!r}")
    return cmap


def check_clim(clim, name: str = "clim"):
    """Colour limits: None (the data's range) or (lo, hi), two finite numbers with lo < hi, as a
    tuple of floats.

    >>> check_clim([0, 2.5]), check_clim(None)
    ((0.0, 2.5), None)
    """
    if clim is None:
        return None
    allowed = "None (the data's range) or (lo, hi), two finite numbers with lo < hi"
    try:
        pair = tuple(clim)
    except TypeError:
        raise TypeError(f"Expected `{name}` to be {allowed}, got {clim!r}") from None
    if (isinstance(clim, str) or len(pair) != 2
            or not all(isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, (bool, np.bool_))
                       for v in pair)):
        raise TypeError(f"Expected `{name}` to be {allowed}, got {clim!r}")
    lo, hi = float(pair[0]), float(pair[1])
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise ValueError(f"Expected `{name}` to be {allowed}, got {clim!r}")
    return lo, hi


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


def default_clim(values) -> tuple:
    """(lo, hi): the 1st and 99th percentiles of the finite ``values`` (robust to a few outliers),
    the colour range of a ray-cast rendering whose ``clim`` is not set (live view and picture).
    A constant gives (v - 1/2 |v|, v + 1/2 |v|) (1/2 around 0), so it takes the middle of the
    colour map; no finite value gives (0, 1).

    >>> default_clim(np.r_[np.arange(101.0), np.nan, 1e9])
    (1.01, 99.99)
    """
    v = np.asarray(values, dtype=np.float64).ravel()
    v = v[np.isfinite(v)]
    if not len(v):
        return 0.0, 1.0
    lo, hi = (float(x) for x in np.percentile(v, [1.0, 99.0]))
    if not hi > lo:
        half = 0.5 * abs(lo) if lo != 0 else 0.5
        lo, hi = lo - half, lo + half
    return lo, hi


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


def level_colors(levels, lo: float, hi: float, cmap: str = LEVEL_COLORMAP, *, by_value: bool = False) -> np.ndarray:
    """Colours of iso ``levels`` along the colour map ``cmap``: (n, 3) float64 in [0, 1].

    By rank (the default): one level alone takes a point of the colormap's brighter half (a
    readable surface); several are spread over the colormap in the order of their values
    (lowest darkest), so nested surfaces differ clearly whatever their spacing.  ``by_value``:
    each level takes the colour at its place in [lo, hi] (clamped), as on a colour bar over
    those limits.  Non-finite levels are refused; ``by_value`` needs finite lo < hi.

    >>> level_colors([0.0, 1.0], 0.0, 1.0, "gray", by_value=True).round(3).tolist()
    [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]
    """
    from matplotlib import colormaps  # here, not at the top: the core imports numpy only

    v = np.asarray(levels, dtype=np.float64).ravel()
    if not np.all(np.isfinite(v)):
        raise ValueError(f"Expected finite levels, got {levels!r}")
    if by_value:
        lo, hi = check_clim((lo, hi), "(lo, hi)")
        x = np.clip((v - lo) / (hi - lo), 0.0, 1.0)
    elif len(v) == 1:
        x = np.array([0.75])
    else:
        rank = np.argsort(np.argsort(v, kind="stable"), kind="stable")
        x = 0.12 + 0.8 * rank / (len(v) - 1)
    return np.asarray(colormaps[cmap](x))[:, :3].astype(np.float64)


def hex_color(rgb) -> str:
    """(r, g, b) floats in [0, 1] -> ``'#rrggbb'``.

    >>> hex_color((1.0, 0.5, 0.0))
    '#ff8000'
    """
    return "#" + "".join(f"{min(255, max(0, round(255 * float(c)))):02x}" for c in rgb)


def cmap_stops(cmap: str = LEVEL_COLORMAP, n: int = 11) -> tuple:
    """``n`` evenly spaced colours of ``cmap`` from its low end to its high end, ``'#rrggbb'``
    each: the stops of a colour bar's gradient.

    >>> cmap_stops("gray", 3)
    ('#000000', '#808080', '#ffffff')
    """
    from matplotlib import colormaps  # here, not at the top: the core imports numpy only

    check_cmap(cmap)
    n = int_in_range(int(n), "n", 2)
    rgb = np.asarray(colormaps[cmap](np.linspace(0.0, 1.0, n)))[:, :3]
    return tuple(hex_color(c) for c in rgb)


# -- numbers for people --------------------------------------------------------
def number_text(value: float, scale: float = 0.0, digits: int = 4) -> str:
    """A number for people: ``digits`` significant digits, and 0 for a value that is rounding noise
    next to ``scale`` (below 1e-9 of it: no "-2.132e-14" for a cut through t = 0).

    >>> number_text(-2.132e-14, 73.3), number_text(2.1362, 0), number_text(1234567.0)
    ('0', '2.136', '1.235e+06')
    """
    value = float(value)
    if not math.isfinite(value):
        return str(value)
    if abs(value) <= tol_.NOISE * abs(float(scale)):
        return "0"
    return f"{value:.{digits}g}"
