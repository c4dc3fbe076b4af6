"""Colours: the frame's colours, the group palette, colour conversion and the colour scale (colour
maps and their limits), for the static pictures (matplotlib) and the live view (pythreejs) alike, so
that a 4-D cell, a ball or the frame look the same in both.

``BACKGROUND``, ``BALL_COLOR``, ``BAR_COLOR`` ('#rrggbb'); faces are ``FACE_OPACITY`` opaque and coloured
by group (the 4-D cell a face is cut from) with ``group_palette``, or all ``SINGLE_FACE_COLOR`` when one
colour is chosen for every face.  ``as_rgb`` reads any of these colour forms, ``hex_color`` writes one.
A field's values are coloured through a matplotlib colour map (``check_cmap``, ``level_colors``,
``cmap_stops``) over colour limits (``check_clim``, ``default_clim``).  numpy only at import:
matplotlib is imported inside the colour map functions, when called.
"""

from __future__ import annotations

import difflib
import math

import numpy as np

from .validate import int_in_range

__all__ = [
    "BACKGROUND", "BALL_COLOR", "BAR_COLOR", "FACE_OPACITY", "SINGLE_FACE_COLOR", "SURFACE_OPACITY",
    "as_rgb", "hex_color", "group_palette", "cell_palette", "LEVEL_COLORMAP", "check_cmap",
    "check_clim", "default_clim", "level_colors", "cmap_stops",
]

BACKGROUND = "#ffffff"
BALL_COLOR = "#c8102e"
BAR_COLOR = "#4a4a4a"
#: Opacity of the faces (0 transparent ... 1 opaque).
FACE_OPACITY = 0.35
#: Every face's colour when faces are not coloured by group: a light steel blue.
SINGLE_FACE_COLOR = "#9fb6cd"


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
