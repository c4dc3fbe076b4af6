"""Static matplotlib renderings of w = c0 slices: one panel, key sequences, the paper's figures.

No browser and no widget library: the slice is drawn with matplotlib 2-D artists in a perspective
view from the paper's viewpoint, the point (x, y, z) = (0, 0, ``distance``) looking down -z
(``distance`` = 5 in the paper).  A 3-D point is projected by hand,

    x' = x d / (d - z),    y' = y d / (d - z),

and every radius at that point is multiplied by the same factor ``d / (d - z)``.  The frame is the
live view's camera (:mod:`rot4d_widget.core.look`): a vertical field of view of ``fov`` = 40 degrees, so
the axes span ``|y'| <= d tan(fov / 2)`` and ``|x'| <=`` that times the panel's aspect, and a point
sits in the panel where a three.js ``PerspectiveCamera`` at (0, 0, 5) with that fov and aspect puts
it.  Palette, scale, default radii and colours come from :mod:`rot4d_widget.core.look` too, so a 4-D
cell has the same colour here and in the widget.  Artists are
painted back to front (painter's algorithm, by the depth of a ball's centre, a bar's midpoint, a
face's centroid), so nearer things cover farther ones.

* balls at slice vertices (circles, with a small highlight),
* bars along slice edges (trapezoids whose width follows the perspective of each end),
* translucent faces (slice polygons), coloured by the 4-D cell they are cut from
  (``look.group_palette``, the live view's palette).

``render_key_sequence(key, n_panels)`` shows what holding a key does: panel k is drawn after k
presses; :func:`paper_figure_3` and :func:`paper_figure_4` reproduce the paper's figures.
:func:`render_state` draws what a widget shows -- a `RotationState` and any source (polytope,
field, stack) with the widget's display settings -- at a chosen size in pixels.

Functions build :class:`matplotlib.figure.Figure` objects directly and never touch
``matplotlib.pyplot``, so they work under any backend and leave pyplot's state alone.
"""

from __future__ import annotations

import copy
import functools
import math
import os
import string
from dataclasses import dataclass, field
from numbers import Integral, Real

import numpy as np
from matplotlib.axes import Axes
from matplotlib.colors import Colormap, ListedColormap, to_rgba
from matplotlib.figure import Figure
from matplotlib.patches import Circle, Polygon

from ..core import look
from ..core.look import REFERENCE_RADIUS
from ..geometry.polytopes import Polytope, pentachoron
from ..geometry.polytopes import polytope as _named_polytope
from ..geometry.slicing import Slice, slice_polytope
from ..core.state import PAPER_ALPHA_RATIO, RotationState

__all__ = [
    "CAMERA_DISTANCE",
    "CAMERA_FOV",
    "REFERENCE_RADIUS",
    "FIG3_THETA0",
    "FIG4_THETA0",
    "FIG4_ALPHA",
    "SliceDrawing",
    "perspective",
    "draw_slice",
    "panel_style",
    "render_slice",
    "render_key_sequence",
    "paper_figure_3",
    "paper_figure_4",
    "render_tomography",
    "render_state",
    "state_source",
    "FIT_FILL",
    "frame_extent",
    "union_extent",
    "annotation",
]

#: The paper's viewpoint: the eye at (0, 0, 5) looking down -z (``look.CAMERA_POSITION``).
CAMERA_DISTANCE = float(look.CAMERA_POSITION[2])
#: Vertical field of view of the frame, degrees (``look.CAMERA_FOV``, the live camera's).
CAMERA_FOV = float(look.CAMERA_FOV)
# REFERENCE_RADIUS (from look): the paper's pentachoron's circumradius (edge a = 2), sqrt(2/5) * a.
# Other polytopes are scaled to it by default so that they appear the same size.
#: Edge of the pentachoron of circumradius REFERENCE_RADIUS: the default ball and bar radii of
#: :func:`draw_slice` are this edge's (``look.default_ball_radius(2.0)`` = 0.07).
_REFERENCE_EDGE = REFERENCE_RADIUS / math.sqrt(2.0 / 5.0)
#: Fig. 3: key "4" (R_xw) with theta0 = pi/16.
FIG3_THETA0 = math.pi / 16
#: Fig. 4: key "z" (R_xz,yw) with alpha = pi sqrt2 / (8 sqrt3) and "beta = 1 - alpha",
#: i.e. alpha + beta = theta0 = 1 rad.
FIG4_THETA0 = 1.0
FIG4_ALPHA = PAPER_ALPHA_RATIO * FIG4_THETA0

#: Extra figure height (inches) for a title above the panels.
TITLE_HEIGHT = 0.4
_SAVE_FORMATS = (".png", ".pdf", ".svg")

# Painter's order: zorder = _Z_BASE + depth + a tiny offset per kind, so at equal depth a ball is
# drawn over a bar, and a bar over a face.  Labels stay above everything.
_Z_BASE = 10.0
_Z_KIND = {"face": 0.0, "bar": 1e-4, "ball": 2e-4}
_Z_LABEL = 1e6


# --------------------------------------------------------------------------- validation helpers
def _real(name: str, value, *, minimum=None, inclusive=True, maximum=None) -> float:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, Real):
        raise TypeError(f"Expected `{name}` to be a real number, got {type(value).__name__}")
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"Expected `{name}` to be finite, got {value}")
    if minimum is not None:
        if (inclusive and value < minimum) or (not inclusive and value <= minimum):
            op = ">=" if inclusive else ">"
            raise ValueError(f"Expected `{name}` {op} {minimum:g}, got {value:g}")
    if maximum is not None and value > maximum:
        raise ValueError(f"Expected `{name}` <= {maximum:g}, got {value:g}")
    return value


def _count(name: str, value, *, minimum: int = 1) -> int:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, Integral):
        raise TypeError(f"Expected `{name}` to be an integer, got {type(value).__name__}")
    value = int(value)
    if value < minimum:
        raise ValueError(f"Expected `{name}` >= {minimum}, got {value}")
    return value


def _as_polytope(value) -> Polytope:
    if isinstance(value, str):
        return _named_polytope(value)
    if isinstance(value, Polytope):
        return value
    raise TypeError(
        f"Expected `polytope` to be a name such as '5-cell' or a rot4d_widget.Polytope, "
        f"got {type(value).__name__}"
    )


def _as_colormap(cmap) -> Colormap:
    if isinstance(cmap, Colormap):
        return cmap
    if isinstance(cmap, str):
        import matplotlib

        try:
            return matplotlib.colormaps[cmap]
        except KeyError:
            raise ValueError(f"Unknown matplotlib colormap {cmap!r} for `cmap`") from None
    raise TypeError(f"Expected `cmap` to be a colormap name or a matplotlib Colormap, got {type(cmap).__name__}")


def _cell_colors(cell_ids: np.ndarray, cmap: Colormap | None) -> np.ndarray:
    """(P, 4) RGBA per polygon: the same 4-D cell always gets the same colour.

    ``cmap`` None: ``look.group_palette`` (the live view's colour of each cell, unrounded).
    """
    ids = np.asarray(cell_ids, dtype=np.int64)
    if cmap is None:
        rgb = look.group_palette(int(ids.max()) + 1 if len(ids) else 0)[ids].astype(np.float64)
        return np.concatenate([rgb, np.ones((len(ids), 1))], axis=1)
    if isinstance(cmap, ListedColormap):  # qualitative maps: cycle through the list
        return np.asarray(cmap(ids % cmap.N))
    # continuous maps: spread consecutive ids with the golden ratio
    return np.asarray(cmap(np.mod(ids * 0.6180339887498949, 1.0)))


# --------------------------------------------------------------------------- projection
def perspective(points, distance: float = CAMERA_DISTANCE):
    """Project 3-D points seen from (0, 0, ``distance``) looking down -z onto the plane z = 0.

    ``points`` is (n, 3) float64 (x, y, z).  Returns ``(xy, factor)``: ``xy`` (n, 2) float64 with
    ``xy = (x, y) * factor`` and ``factor`` (n,) float64 ``= distance / (distance - z)``, the
    magnification of anything of size 1 at that point.  Raises ``ValueError`` if a point is at or
    behind the eye (z >= distance).
    """
    d = _real("distance", distance, minimum=0.0, inclusive=False)
    try:
        p = np.asarray(points, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError("Expected `points` to be an (n, 3) array of real numbers") from None
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"Expected `points` to have shape (n, 3), got {p.shape}")
    if not np.all(np.isfinite(p)):
        raise ValueError("Expected `points` to be finite")
    depth = d - p[:, 2]
    if p.shape[0] and depth.min() <= 0.0:
        z = p[np.argmin(depth), 2]
        raise ValueError(
            f"A point at z = {z:.6g} is at or behind the eye at z = {d:g}; scale the scene down "
            "or move the eye back (`distance`)"
        )
    factor = d / depth
    return p[:, :2] * factor[:, None], factor


def _view_limit(radius: float, distance: float, margin: float) -> float:
    """Half-width of the view that holds a sphere of ``radius`` at the origin, plus ``margin``."""
    if radius >= distance:
        raise ValueError(
            f"Expected `radius` < `distance` ({distance:g}) so the eye is outside the scene, got {radius:g}"
        )
    return distance * radius / math.sqrt(distance**2 - radius**2) + margin


def _axes_aspect(ax) -> float:
    """Width / height of ``ax``'s box on its figure (1 if it has no area)."""
    fig = ax.figure
    box = ax.get_position(original=True).transformed(getattr(fig, "transSubfigure", fig.transFigure))
    return box.width / box.height if box.width > 0 and box.height > 0 else 1.0


def _add_patch(ax, patch):
    """``ax.add_patch`` without updating the data limits (every frame here sets its limits itself;
    matplotlib's per-patch limit update was most of the time of a frame)."""
    return ax.add_artist(patch)


# --------------------------------------------------------------------------- one panel
@dataclass
class SliceDrawing:
    """What :func:`draw_slice` added to the axes, in drawing (painter's) order per kind.

    ``centers`` (n, 2) and ``factors`` (n,) are the projected slice vertices and their perspective
    factors; ``balls[i]`` is the circle of slice vertex ``i``; ``bars[j]`` the patch of edge ``j``;
    ``faces[k]`` the polygon of ``slice.polygons[k]``.  ``limit`` is the half-height of the view
    (the x limits are ``limit`` times the panel's aspect with a camera, ``limit`` without one).
    """

    centers: np.ndarray
    factors: np.ndarray
    balls: list = field(default_factory=list)
    bars: list = field(default_factory=list)
    faces: list = field(default_factory=list)
    highlights: list = field(default_factory=list)
    limit: float = 0.0


def draw_slice(
    ax,
    slice: Slice,
    *,
    scale: float = 1.0,
    distance: float = CAMERA_DISTANCE,
    fov: float | None = CAMERA_FOV,
    radius: float | None = None,
    ball_radius: float | None = None,
    bar_radius: float | None = None,
    face_alpha: float = look.FACE_OPACITY,
    ball_color=look.BALL_COLOR,
    bar_color=look.BAR_COLOR,
    cmap=None,
    label: str | None = None,
) -> SliceDrawing:
    """Draw one slice on a matplotlib ``ax`` in the paper's perspective view.

    ``slice`` is a :class:`rot4d_widget.Slice`; its vertices are multiplied by ``scale`` first.
    ``ball_radius`` and ``bar_radius`` are 3-D sizes (after scaling), shrunk with distance like
    everything else; by default ``look.default_ball_radius`` of the reference pentachoron's edge
    (0.07) and ``look.default_bar_radius(ball_radius)``, as in the live view.
    The frame is the camera's: vertical field of view ``fov`` degrees and the aspect of ``ax``,
    so every panel of a sequence shares it and a point sits where the live view puts it.  With
    ``fov=None`` the frame fits a sphere of ``radius`` (after scaling) if given, else this slice;
    with a camera, ``radius`` only checks that the eye is outside that sphere.
    Faces are coloured by ``slice.cell_ids`` with ``look.group_palette`` (the live view's colours),
    or through ``cmap`` (a matplotlib colormap name or Colormap) if given.

    Returns a :class:`SliceDrawing` listing the artists; they also carry the gids "ball", "bar",
    "face" and "highlight" (kept in SVG output).
    """
    if not isinstance(ax, Axes):
        raise TypeError(f"Expected `ax` to be a matplotlib Axes, got {type(ax).__name__}")
    if not isinstance(slice, Slice):
        raise TypeError(f"Expected `slice` to be a rot4d_widget.Slice, got {type(slice).__name__}")
    scale = _real("scale", scale, minimum=0.0, inclusive=False)
    d = _real("distance", distance, minimum=0.0, inclusive=False)
    if fov is not None:
        fov = _real("fov", fov, minimum=0.0, inclusive=False)
        if fov >= 180.0:
            raise ValueError(f"Expected `fov` < 180 degrees, got {fov:g}")
    if ball_radius is None:
        ball_radius = look.default_ball_radius(_REFERENCE_EDGE)
    ball_radius = _real("ball_radius", ball_radius, minimum=0.0)
    if bar_radius is None:
        bar_radius = look.default_bar_radius(ball_radius)
    bar_radius = _real("bar_radius", bar_radius, minimum=0.0)
    face_alpha = _real("face_alpha", face_alpha, minimum=0.0, maximum=1.0)
    if radius is not None:
        radius = _real("radius", radius, minimum=0.0, inclusive=False)
        if radius >= d:
            raise ValueError(
                f"Expected `radius` < `distance` ({d:g}) so the eye is outside the scene, got {radius:g}"
            )
    if label is not None and not isinstance(label, str):
        raise TypeError(f"Expected `label` to be a string or None, got {type(label).__name__}")
    colormap = None if cmap is None else _as_colormap(cmap)
    ball_rgba = to_rgba(ball_color)
    bar_rgba = to_rgba(bar_color)

    pts = np.asarray(slice.vertices, dtype=np.float64).reshape(-1, 3) * scale
    xy, fac = perspective(pts, d) if len(pts) else (np.zeros((0, 2)), np.zeros(0))
    z = pts[:, 2]
    drawing = SliceDrawing(centers=xy, factors=fac)

    # faces: convex polygons (a cell meets a hyperplane in a convex polygon); order the corners
    # around the projected centroid so the drawing does not depend on the slicer's corner order.
    polygons = list(slice.polygons)
    colors = _cell_colors(np.asarray(slice.cell_ids), colormap) if polygons else []
    for poly, rgba in zip(polygons, colors):
        idx = np.asarray(poly, dtype=np.int64)
        if len(idx) < 3:
            continue
        p2 = xy[idx]
        c2 = p2.mean(axis=0)
        order = np.argsort(np.arctan2(p2[:, 1] - c2[1], p2[:, 0] - c2[0]))
        depth = z[idx].mean()
        patch = Polygon(
            p2[order], closed=True, facecolor=(*rgba[:3], face_alpha), edgecolor="none",
            zorder=_Z_BASE + depth + _Z_KIND["face"], gid="face",
        )
        _add_patch(ax, patch)
        drawing.faces.append(patch)

    # bars: a trapezoid from end a to end b, half-width bar_radius * factor at each end
    edge_rgba = tuple(0.6 * np.asarray(bar_rgba[:3])) + (bar_rgba[3],)
    if bar_radius > 0:
        for a, b in np.asarray(slice.edges, dtype=np.int64).reshape(-1, 2):
            pa, pb = xy[a], xy[b]
            ra, rb = bar_radius * fac[a], bar_radius * fac[b]
            u = pb - pa
            length = math.hypot(*u)
            zo = _Z_BASE + 0.5 * (z[a] + z[b]) + _Z_KIND["bar"]
            if length <= 1e-12:  # edge along the line of sight: its end-on disc
                patch = Circle(pa, max(ra, rb), facecolor=bar_rgba, edgecolor="none", zorder=zo, gid="bar")
            else:
                n = np.array([-u[1], u[0]]) / length
                corners = [pa + n * ra, pb + n * rb, pb - n * rb, pa - n * ra]
                patch = Polygon(corners, closed=True, facecolor=bar_rgba, edgecolor=edge_rgba,
                                linewidth=0.3, zorder=zo, gid="bar")
            _add_patch(ax, patch)
            drawing.bars.append(patch)

    # balls: circles of radius ball_radius * factor, with a highlight towards the upper left
    if ball_radius > 0:
        dark = tuple(0.55 * np.asarray(ball_rgba[:3])) + (ball_rgba[3],)
        for i in range(len(pts)):
            r = ball_radius * fac[i]
            zo = _Z_BASE + z[i] + _Z_KIND["ball"]
            ball = Circle(xy[i], r, facecolor=ball_rgba, edgecolor=dark, linewidth=0.4, zorder=zo, gid="ball")
            shine = Circle(xy[i] + np.array([-0.35, 0.35]) * r, 0.3 * r, facecolor=(1, 1, 1, 0.55),
                           edgecolor="none", zorder=zo + 1e-5, gid="highlight")
            _add_patch(ax, ball)
            _add_patch(ax, shine)
            drawing.balls.append(ball)
            drawing.highlights.append(shine)

    # frame: the camera's (as the live view), else a fixed sphere if given, else this slice.
    # The picture plane is z = 0 (x' = x d / (d - z)); there the camera's frustum is
    # |y'| <= d tan(fov/2), |x'| <= aspect d tan(fov/2): axes fractions are three.js NDC.
    margin = max(ball_radius, bar_radius)
    aspect = 1.0
    if fov is not None:
        limit = d * math.tan(math.radians(fov) / 2.0)
        aspect = _axes_aspect(ax)
    elif radius is not None:
        limit = _view_limit(radius, d, margin * d / (d - radius))
    elif len(pts):
        limit = float(np.max(np.abs(xy) + (margin * fac)[:, None]))
        limit = max(limit * 1.05, 1e-3)
    else:
        limit = 1.0
    ax.set_xlim(-limit * aspect, limit * aspect)
    ax.set_ylim(-limit, limit)
    ax.set_aspect("equal")
    ax.set_axis_off()
    drawing.limit = limit
    if label:
        ax.text(0.03, 0.97, label, transform=ax.transAxes, ha="left", va="top", fontsize=10,
                zorder=_Z_LABEL)
    return drawing


# --------------------------------------------------------------------------- one panel, fast (animations)
_CIRCLE = None  # Path.unit_circle()'s vertices and codes, made on first use
_POLY_CODES: dict = {}  # closed polygon codes by corner count


def _closed_codes(n: int) -> np.ndarray:
    codes = _POLY_CODES.get(n)
    if codes is None:
        from matplotlib.path import Path

        codes = np.full(n + 1, Path.LINETO, dtype=Path.code_type)
        codes[0], codes[-1] = Path.MOVETO, Path.CLOSEPOLY
        _POLY_CODES[n] = codes
    return codes


def _slice_collection(slice: Slice, *, scale: float, ball_radius: float, bar_radius: float, face_alpha: float,
                      cmap=None, ball_color=look.BALL_COLOR, bar_color=look.BAR_COLOR, z_shift: float = 0.0,
                      distance: float = CAMERA_DISTANCE):
    """What `draw_slice` draws -- the same faces, bars, balls and highlights, with the same paths,
    colours, edges and painter's order (zorders plus ``z_shift``, ties in draw_slice's order) --
    as ONE `PathCollection` (gid "slice"), drawn by a single renderer call.  For animations:
    a frame of the 24-cell is ~100 patches, whose building and drawing was most of its time.
    ``cmap`` a Colormap or None; radii and sizes already checked.  None when nothing is drawn."""
    from matplotlib.collections import PathCollection
    from matplotlib.path import Path

    global _CIRCLE
    if _CIRCLE is None:
        c = Path.unit_circle()
        _CIRCLE = (np.asarray(c.vertices, dtype=np.float64), np.asarray(c.codes))
    circ_v, circ_c = _CIRCLE
    pts = np.asarray(slice.vertices, dtype=np.float64).reshape(-1, 3) * scale
    if not len(pts):
        return None
    xy, fac = perspective(pts, distance)
    z = pts[:, 2]
    paths, face, edge, width, zo = [], [], [], [], []
    none = (0.0, 0.0, 0.0, 0.0)

    # faces: corners ordered around the projected centroid (draw_slice's order), one loop-free pass
    off = np.asarray(slice.polygon_offsets, dtype=np.int64)
    lens = np.diff(off)
    if len(lens):
        rgba = _cell_colors(np.asarray(slice.cell_ids), cmap)
        flat = np.asarray(slice.polygon_indices, dtype=np.int64)
        seg = np.repeat(np.arange(len(lens)), lens)
        p2 = xy[flat]
        cnt = np.maximum(lens, 1)
        cx = np.bincount(seg, p2[:, 0], len(lens)) / cnt
        cy = np.bincount(seg, p2[:, 1], len(lens)) / cnt
        depth = np.bincount(seg, z[flat], len(lens)) / cnt
        ang = np.arctan2(p2[:, 1] - cy[seg], p2[:, 0] - cx[seg])
        ring = p2[np.lexsort((ang, seg))]
        for k in np.flatnonzero(lens >= 3):
            v = ring[off[k]:off[k + 1]]
            paths.append(Path(np.concatenate([v, v[:1]]), _closed_codes(len(v))))
            face.append((*rgba[k][:3], face_alpha))
            edge.append(none)
            width.append(0.0)
            zo.append(_Z_BASE + depth[k] + _Z_KIND["face"])

    # bars: trapezoids, half-width bar_radius * factor at each end; an end-on edge is a disc
    e = np.asarray(slice.edges, dtype=np.int64).reshape(-1, 2)
    if bar_radius > 0 and len(e):
        bar_rgba = to_rgba(bar_color)
        edge_rgba = tuple(0.6 * np.asarray(bar_rgba[:3])) + (bar_rgba[3],)
        pa, pb = xy[e[:, 0]], xy[e[:, 1]]
        ra, rb = bar_radius * fac[e[:, 0]], bar_radius * fac[e[:, 1]]
        u = pb - pa
        length = np.hypot(u[:, 0], u[:, 1])
        flat_end = length <= 1e-12
        n = np.stack([-u[:, 1], u[:, 0]], axis=1) / np.where(flat_end, 1.0, length)[:, None]
        quad = np.stack([pa + n * ra[:, None], pb + n * rb[:, None], pb - n * rb[:, None], pa - n * ra[:, None],
                         pa + n * ra[:, None]], axis=1)
        zb = _Z_BASE + 0.5 * (z[e[:, 0]] + z[e[:, 1]]) + _Z_KIND["bar"]
        codes = _closed_codes(4)
        for j in range(len(e)):
            if flat_end[j]:
                paths.append(Path(circ_v * max(ra[j], rb[j]) + pa[j], circ_c))
                edge.append(none)
                width.append(0.0)
            else:
                paths.append(Path(quad[j], codes))
                edge.append(edge_rgba)
                width.append(0.3)
            face.append(bar_rgba)
            zo.append(zb[j])

    # balls and their highlights (each highlight right after its ball)
    if ball_radius > 0:
        ball_rgba = to_rgba(ball_color)
        dark = tuple(0.55 * np.asarray(ball_rgba[:3])) + (ball_rgba[3],)
        r = ball_radius * fac
        zb = _Z_BASE + z + _Z_KIND["ball"]
        shine = xy + np.array([-0.35, 0.35]) * r[:, None]
        for i in range(len(pts)):
            paths.append(Path(circ_v * r[i] + xy[i], circ_c))
            paths.append(Path(circ_v * (0.3 * r[i]) + shine[i], circ_c))
            face += [ball_rgba, (1.0, 1.0, 1.0, 0.55)]
            edge += [dark, none]
            width += [0.4, 0.0]
            zo += [zb[i], zb[i] + 1e-5]
    if not paths:
        return None
    zo = np.asarray(zo) + z_shift
    order = np.argsort(zo, kind="stable")  # matplotlib sorts artists by zorder, stably
    coll = PathCollection([paths[i] for i in order], facecolors=np.asarray(face)[order],
                          edgecolors=np.asarray(edge)[order], linewidths=np.asarray(width)[order],
                          joinstyle="miter", capstyle="butt", zorder=float(zo.min()), gid="slice")
    coll._items_zorder = zo[order]
    return coll


# --------------------------------------------------------------------------- grids of panels
def _panel_label(k: int) -> str:
    return f"({string.ascii_lowercase[k]})" if k < 26 else f"({k + 1})"


def _grid_figure(n_panels: int, ncols: int, panel_size: float, dpi: float, title: str | None):
    ncols = min(ncols, n_panels)
    nrows = -(-n_panels // ncols)
    top = TITLE_HEIGHT if title else 0.0
    width, height = ncols * panel_size, nrows * panel_size + top
    fig = Figure(figsize=(width, height), dpi=dpi, facecolor=look.BACKGROUND)
    axes = []
    for k in range(nrows * ncols):
        r, c = divmod(k, ncols)
        # [left, bottom, width, height] in figure fractions: panels tile the figure exactly
        rect = [c * panel_size / width, (height - top - (r + 1) * panel_size) / height,
                panel_size / width, panel_size / height]
        ax = fig.add_axes(rect)
        ax.set_axis_off()
        axes.append(ax)
    if title:
        fig.text(0.5, 1.0 - 0.5 * TITLE_HEIGHT / height, title, ha="center", va="center", fontsize=11)
    return fig, axes


def _check_grid_args(ncols, panel_size, dpi, title):
    ncols = _count("ncols", ncols)
    panel_size = _real("panel_size", panel_size, minimum=0.0, inclusive=False)
    dpi = _real("dpi", dpi, minimum=0.0, inclusive=False)
    if title is not None and not isinstance(title, str):
        raise TypeError(f"Expected `title` to be a string or None, got {type(title).__name__}")
    return ncols, panel_size, dpi


def _default_scale(poly: Polytope, scale):
    if scale is None:
        return REFERENCE_RADIUS / float(poly.circumradius)
    return _real("scale", scale, minimum=0.0, inclusive=False)


def panel_style(polytope, scale: float | None = None) -> dict:
    """Keywords for :func:`draw_slice` that suit ``polytope``: ``scale``, ``radius``, ball and bar sizes.

    ``scale`` defaults to ``REFERENCE_RADIUS / circumradius`` (every polytope the size of the paper's
    pentachoron); the ``radius`` is the scaled circumradius; balls and bars follow the scaled
    edge length as in the live view (``look.default_ball_radius`` and ``look.default_bar_radius``:
    the pentachoron's 0.07 and 0.028 at most, so that the 600 vertices of the 120-cell do not
    merge).  Use as ``draw_slice(ax, s, **panel_style(p))``.
    """
    poly = _as_polytope(polytope)
    s = _default_scale(poly, scale)
    e = np.asarray(poly.edges, dtype=np.int64).reshape(-1, 2)
    edge = float(np.linalg.norm(poly.vertices[e[:, 0]] - poly.vertices[e[:, 1]], axis=1).mean()) if len(e) else 1.0
    ball = look.default_ball_radius(edge * s)
    return {"scale": s, "radius": s * float(poly.circumradius), "ball_radius": ball,
            "bar_radius": look.default_bar_radius(ball)}


def render_slice(
    polytope="5-cell",
    matrix=None,
    c0: float = 0.0,
    *,
    scale: float | None = None,
    panel_size: float = 3.0,
    dpi: float = 100,
    title: str | None = None,
    **draw_kwargs,
) -> Figure:
    """One panel: the slice w = ``c0`` of ``polytope`` turned by ``matrix`` (identity by default).

    ``polytope`` is a name ("5-cell" ... "600-cell") or a Polytope; ``scale`` defaults to
    ``REFERENCE_RADIUS / circumradius`` (every polytope appears the size of the paper's
    pentachoron), sizes to :func:`panel_style`.  Other keywords go to :func:`draw_slice`.
    """
    poly = _as_polytope(polytope)
    matrix = np.eye(4) if matrix is None else matrix
    c0 = _real("c0", c0)
    s = _default_scale(poly, scale)
    _, panel_size, dpi = _check_grid_args(1, panel_size, dpi, title)
    fig, (ax,) = _grid_figure(1, 1, panel_size, dpi, title)
    kwargs = {**panel_style(poly, s), **draw_kwargs}
    draw_slice(ax, slice_polytope(poly, matrix, c0), **kwargs)
    return fig


def render_key_sequence(
    key: str,
    n_panels: int = 16,
    *,
    state: RotationState | None = None,
    polytope="5-cell",
    shift: bool = False,
    ncols: int = 4,
    scale: float | None = None,
    panel_size: float = 2.0,
    dpi: float = 100,
    labels: bool = True,
    title: str | None = None,
    **draw_kwargs,
) -> Figure:
    """A grid of panels showing what pressing ``key`` repeatedly does.

    Panel k (k = 0 ... ``n_panels`` - 1, labelled (a), (b), ...) shows the slice w = c0 after k
    presses of ``key`` (with ``shift`` for the inverse) starting from ``state`` (default: a fresh
    :class:`RotationState`).  ``state`` is copied, never modified.  Any bound key works: "4" turns
    in the x-w plane, "z" is a double rotation, "l" raises c0.  ``ncols`` panels per row
    (fewer if there are fewer panels), each ``panel_size`` inches square at ``dpi``; all panels
    share one frame.  Sizes default to :func:`panel_style`; other keywords go to :func:`draw_slice`.
    """
    if not isinstance(key, str):
        raise TypeError(f"Expected `key` to be a string such as '4' or 'z', got {type(key).__name__}")
    n_panels = _count("n_panels", n_panels)
    ncols, panel_size, dpi = _check_grid_args(ncols, panel_size, dpi, title)
    if state is None:
        state = RotationState()
    elif not isinstance(state, RotationState):
        raise TypeError(f"Expected `state` to be a rot4d_widget.RotationState, got {type(state).__name__}")
    state = copy.deepcopy(state)
    if state.keymap.resolve(key, bool(shift)) is None:
        bound = " ".join(sorted(k for k in state.keymap if len(k) == 1))
        raise ValueError(f"Key {key!r} is not bound to an action; bound keys: {bound}")
    poly = _as_polytope(polytope)
    kwargs = {**panel_style(poly, scale), **draw_kwargs}

    fig, axes = _grid_figure(n_panels, ncols, panel_size, dpi, title)
    for k in range(n_panels):
        if k:
            state.press(key, shift=bool(shift))
        label = _panel_label(k) if labels else None
        draw_slice(axes[k], slice_polytope(poly, state.matrix, state.c0), label=label, **kwargs)
    return fig


def _save(fig: Figure, path) -> None:
    if path is None:
        return
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"Expected `path` to be a file path or None, got {type(path).__name__}")
    ext = os.path.splitext(os.fspath(path))[1].lower()
    if ext not in _SAVE_FORMATS:
        raise ValueError(f"Expected `path` to end in one of {', '.join(_SAVE_FORMATS)}, got {os.fspath(path)!r}")
    fig.savefig(path, dpi=fig.dpi, facecolor=fig.get_facecolor())


def paper_figure_3(path=None, *, panel_size: float = 2.0, dpi: float = 100, title: bool = True) -> Figure:
    """The paper's Fig. 3: 16 slices w = 0 of the a = 2 pentachoron under key "4" (R_xw, theta0 = pi/16).

    Panel k shows the slice after k presses; panel (a) is the regular tetrahedron of edge 1.6.
    (The paper's caption says R_yw; its key table, which wins, binds "4" to R_xw.)
    Saved to ``path`` (.png, .pdf or .svg) if given.
    """
    fig = render_key_sequence(
        "4", 16, state=RotationState(theta0=FIG3_THETA0), polytope=pentachoron(2.0), ncols=4,
        scale=1.0, panel_size=panel_size, dpi=dpi,
        title="Fig. 3: key \u201c4\u201d, R_xw(\u03c0/16) per panel; pentachoron a = 2, slice w = 0"
        if title else None,
    )
    _save(fig, path)
    return fig


def paper_figure_4(path=None, *, panel_size: float = 2.0, dpi: float = 100, title: bool = True) -> Figure:
    """The paper's Fig. 4: 16 slices w = 0 of the a = 2 pentachoron under key "z" (R_xz,yw).

    alpha = pi sqrt2 / (8 sqrt3) and beta = 1 - alpha (theta0 = 1 rad); alpha/beta is irrational, so
    the sequence never returns to panel (a).  Saved to ``path`` (.png, .pdf or .svg) if given.
    """
    fig = render_key_sequence(
        "z", 16, state=RotationState(theta0=FIG4_THETA0, alpha=FIG4_ALPHA), polytope=pentachoron(2.0),
        ncols=4, scale=1.0, panel_size=panel_size, dpi=dpi,
        title="Fig. 4: key \u201cz\u201d, R_xz,yw(\u03b1, \u03b2), \u03b1 = \u03c0\u221a2/(8\u221a3), "
        "\u03b2 = 1 \u2212 \u03b1; w = 0" if title else None,
    )
    _save(fig, path)
    return fig


# --------------------------------------------------------------------------- framing and annotation
#: With ``frame="fit"`` the bounding box of what is drawn spans this fraction of the picture's
#: width or height (whichever it reaches first).
FIT_FILL = 0.9


def frame_extent(data, source, *, ball_radius: float = 0.0):
    """``(x0, x1, y0, y1)``: the projected bounding box of slice ``data`` of ``source`` (a
    `StackSource`'s slice, as `render_tomography` draws it) in the picture plane of the live
    view's camera, every point widened by ``ball_radius`` (displayed units) times its
    perspective factor.  None when the slice is empty."""
    pts = np.asarray(data.points, dtype=np.float64).reshape(-1, 3) * (REFERENCE_RADIUS / source.size)
    if not len(pts):
        return None
    xy, fac = perspective(pts)
    m = float(ball_radius) * fac
    return (float((xy[:, 0] - m).min()), float((xy[:, 0] + m).max()),
            float((xy[:, 1] - m).min()), float((xy[:, 1] + m).max()))


def union_extent(boxes):
    """The box holding every ``(x0, x1, y0, y1)`` of ``boxes`` (None ones skipped); None if none."""
    boxes = [b for b in boxes if b is not None]
    if not boxes:
        return None
    b = np.asarray(boxes, dtype=np.float64)
    return (float(b[:, 0].min()), float(b[:, 1].max()), float(b[:, 2].min()), float(b[:, 3].max()))


def _as_box(frame):
    try:
        box = tuple(float(v) for v in frame)
    except (TypeError, ValueError):
        box = ()
    if len(box) != 4 or not all(math.isfinite(v) for v in box) or box[1] < box[0] or box[3] < box[2]:
        raise ValueError(f"Expected `frame` to be 'camera', 'fit' or a box (x0, x1, y0, y1) with x0 <= x1 and "
                         f"y0 <= y1, got {frame!r}")
    return box


def _frame_limits(box, aspect: float):
    """``((x0, x1), (y0, y1))`` axes limits: the camera's frustum for ``box`` None, else ``box``
    centred and grown to the picture's ``aspect`` so that it fills `FIT_FILL` of it."""
    if box is None:
        limit = CAMERA_DISTANCE * math.tan(math.radians(CAMERA_FOV) / 2.0)
        return (-limit * aspect, limit * aspect), (-limit, limit)
    cx, cy = 0.5 * (box[0] + box[1]), 0.5 * (box[2] + box[3])
    half = max(0.5 * (box[3] - box[2]), 0.5 * (box[1] - box[0]) / aspect, 1e-3) / FIT_FILL
    return (cx - half * aspect, cx + half * aspect), (cy - half, cy + half)


def _fmt_angle(theta: float) -> str:
    for k in (1, 2, 3, 4, 6, 8, 12, 16, 32, 64):
        if abs(theta * k / math.pi - round(theta * k / math.pi)) < 1e-9 and round(theta * k / math.pi):
            num = round(theta * k / math.pi)
            frac = ("\u03c0" if num == 1 else f"{num}\u03c0") + ("" if k == 1 else f"/{k}")
            return f"{frac} ({math.degrees(theta):.4g}\u00b0)"
    return f"{theta:.4g} rad ({math.degrees(theta):.4g}\u00b0)"


def _level_colors(levels, lo, hi) -> np.ndarray:
    """`look.level_colors` (read-only), kept for the levels and range it was asked for: it copies
    the colormap and builds its table on every call, twice an animation's frame."""
    try:
        key = (tuple(float(v) for v in levels), lo, hi)
        hash(key)
    except TypeError:  # nothing to key it by: as look computes it
        return look.level_colors(levels, lo, hi)
    return _level_colors_kept(*key)


@functools.lru_cache(maxsize=64)
def _level_colors_kept(levels: tuple, lo: float, hi: float) -> np.ndarray:
    rgb = look.level_colors(levels, lo, hi)
    rgb.flags.writeable = False
    return rgb


def annotation(source, data, c0: float, *, theta0: float | None = None):
    """``(lines, legend)`` describing slice ``data`` of ``source`` (a `StackSource`) at ``c0``:
    ``lines`` of text (θ0 when given and c0; the inner source's ``name`` and ``units``; its
    ``levels``; the w span of the slice from its ``readout`` row "w cut" (in ``w_units``); a
    polytope slice's census, its readout row "slice"; a stack's slices' w, from ``levels_at``)
    and ``legend``, ``[(rgb, label), ...]``: the colours of a field's levels or of a stack's
    slices.  Only attributes the sources have are read, never their class."""
    inner = getattr(source, "source", source)
    lines = []
    wu = getattr(inner, "w_units", None)
    wu = f" {wu}" if wu else ""  # c0 and the slices' w are in the source's w units (a field's time)
    state = f"c0 = {float(c0):+.4g}{wu}"
    lines.append(state if theta0 is None else f"\u03b80 = {_fmt_angle(float(theta0))}, {state}")
    name, units = getattr(inner, "name", None), getattr(inner, "units", None)
    u = f" {units}" if units else ""
    if name:
        lines.append(f"{name}" + (f" [{units}]" if units else ""))
    levels = tuple(getattr(inner, "levels", ()) or ())
    if levels:
        lines.append(("level " if len(levels) == 1 else "levels ") + ", ".join(f"{v:.4g}" for v in levels) + u)
    rows = dict(tuple(r) for r in (getattr(data, "readout", ()) or ()) if len(r) == 2)
    if "w cut" in rows:
        lines.append(f"w cut {rows['w cut']}")
    elif "slice" in rows:
        lines.append(str(rows["slice"]))
    n = int(getattr(source, "slices", 1) or 1)
    ws = np.asarray(source.levels_at(c0)) if n > 1 and hasattr(source, "levels_at") else np.zeros(0)
    if len(ws):
        spacing = getattr(source, "spacing", None)
        per = float(getattr(source, "w_frame", (0.0, 1.0))[1])
        lines.append(f"{n} slices w = {ws[0]:+.4g} \u2026 {ws[-1]:+.4g}{wu}"
                     + (f", \u0394 = {spacing * per:.3g}{wu}" if spacing else ""))
    legend = []
    group_rgb = (getattr(data, "extra", None) or {}).get("group_rgb")
    if len(ws) and group_rgb is not None:
        picks = range(n) if n <= 8 else sorted({0, n // 4, n // 2, (3 * n) // 4, n - 1})
        legend = [(tuple(np.asarray(group_rgb[k], dtype=float)[:3]), f"w = {ws[k]:+.4g}{wu}") for k in picks]
    elif levels:
        lo, hi = getattr(inner, "data_range", (min(levels), max(levels)))
        rgb = _level_colors(levels, lo, hi)
        legend = [(tuple(rgb[k]), f"{v:.4g}{u}") for k, v in enumerate(levels)]
    return lines, legend


def _draw_annotation(ax, lines, legend, height: float, canvas=None) -> None:
    """``lines`` in the upper left corner, ``legend`` swatches in the lower left (gid "annotation").
    With a `_FrameCanvas`, the previous frame's text is given the new lines and its legend is
    kept when the swatches are the same."""
    from matplotlib.patches import Patch

    fs = max(6.0, min(10.0, 1.7 * height))
    text = "\n".join(lines)
    if canvas is not None and canvas.note is not None and canvas.note.get_fontsize() == fs:
        canvas.note.set_text(text)
        canvas.keep.add(canvas.note)
    else:
        if canvas is not None and canvas.note is not None:
            canvas.note.remove()
        box = dict(facecolor="white", alpha=0.75, edgecolor="none", pad=2.0)
        note = ax.text(0.015, 0.985, text, transform=ax.transAxes, ha="left", va="top", fontsize=fs,
                       zorder=_Z_LABEL, gid="annotation", bbox=box)
        if canvas is not None:
            canvas.note = note
            canvas.keep.add(note)
    if canvas is not None:
        key = (tuple((tuple(float(c) for c in rgb), label) for rgb, label in legend), fs)
        if ax.get_legend() is not None and canvas.legend_key == key:
            return  # the same swatches as the frame before: keep its legend
        if ax.get_legend() is not None:
            ax.get_legend().remove()
        canvas.legend_key = key
    if legend:
        handles = [Patch(facecolor=rgb, edgecolor="none", label=label) for rgb, label in legend]
        leg = ax.legend(handles=handles, loc="lower left", fontsize=fs, framealpha=0.75, edgecolor="none",
                        handlelength=1.0, borderaxespad=0.3)
        leg.set_zorder(_Z_LABEL)
        leg.set_gid("legend")
        if canvas is not None:
            canvas.as_picture(leg)


# --------------------------------------------------------------------------- stacks of slices
def render_tomography(
    source="24-cell",
    matrix=None,
    c0: float = 0.0,
    slices: int = 5,
    spacing: float | None = None,
    arrangement: str = "oval",
    path=None,
    *,
    color_by: str = "w",
    width: float = 6.0,
    height: float = 5.0,
    dpi: float = 100,
    title: str | bool | None = True,
    labels: bool = True,
    face_alpha: float = look.FACE_OPACITY,
    ball_radius: float | None = None,
    bar_radius: float | None = None,
    show_balls: bool = True,
    show_bars: bool = True,
    show_faces: bool = True,
    face_color=None,
    group_colors=None,
    background=look.BACKGROUND,
    frame="camera",
    annotate=False,
    _data=None,
    _theta0=None,
    _canvas=None,
) -> Figure:
    """N parallel slices w_k = c0 + (k - (N-1)/2) Δ of ``source``, in one scene, as the live view lays them out.

    ``source`` is a polytope name, a Polytope or any source (a `Field4D` ...), ``matrix`` the
    (4, 4) orientation (identity by default); ``slices``, ``spacing`` (None: 2 size / N),
    ``arrangement`` ("oval", "grid", "stack") and ``color_by`` ("w" or "cell") as in
    :class:`rot4d_widget.sources.tomography.StackSource`, whose slice this draws: each slice is placed
    at its arrangement's centre and scale, the whole scene scaled to the live view's displayed
    size and seen through its camera (``width`` / ``height`` inches: the default 6 x 5 has the
    canvas's 600 x 500 aspect).  Slices are painted back to front by the depth of their centres
    (they never intersect), each slice's own faces, bars and balls by depth as in
    :func:`draw_slice`.  ``labels``: each slice's w under it; the slice at w = c0 (or the first
    above it, for even N) is ringed and its label bold.  Saved to ``path`` (.png, .svg or .pdf)
    if given.  Returns the Figure.

    The live view's display options: ``ball_radius`` / ``bar_radius`` in displayed units, the
    same for every slice (default: the widest slice's, shrunk with each slice's scale),
    ``show_balls`` / ``show_bars`` / ``show_faces``, ``face_color`` one colour for every face
    (the widget's ``color_by`` when it is a colour), ``group_colors`` one colour per group,
    ``background``.

    ``frame``: ``"camera"`` (default) the live camera's frustum; ``"fit"`` the same eye and
    perspective, zoomed so that the projected bounding box of what is drawn (every point of
    the slice, balls included) fills `FIT_FILL` of the picture, centred on it (`frame_extent`);
    or ``(x0, x1, y0, y1)``, a box in the picture plane to fit the same way (an animation passes
    the union of its frames' boxes so that the framing does not jump).  ``annotate``: False,
    True (a corner text naming the source, c0, a field's level(s) and w span with their units,
    a stack's slices' w, and a legend of the levels' or slices' colours: `annotation`), or a
    string written as the first line of that text.
    """
    from ..sources.protocol import as_source
    from ..sources.tomography import StackSource

    src = source if isinstance(source, StackSource) else None
    if src is None:
        inner = as_source(source)
        src = StackSource(inner, slices=slices, spacing=spacing, arrangement=arrangement, color_by=color_by)
    matrix = np.eye(4) if matrix is None else matrix
    c0 = _real("c0", c0)
    width = _real("width", width, minimum=0.0, inclusive=False)
    height = _real("height", height, minimum=0.0, inclusive=False)
    dpi = _real("dpi", dpi, minimum=0.0, inclusive=False)
    face_alpha = _real("face_alpha", face_alpha, minimum=0.0, maximum=1.0)
    if ball_radius is not None:
        ball_radius = _real("ball_radius", ball_radius, minimum=0.0)
    if bar_radius is not None:
        bar_radius = _real("bar_radius", bar_radius, minimum=0.0)
    palette = None  # an override of the group colours: one colour, or the caller's
    if face_color is not None:
        palette = np.asarray([look.as_rgb(face_color, "face_color")], dtype=np.float64)
    elif group_colors is not None:
        palette = np.asarray([look.as_rgb(c, f"group_colors[{i}]") for i, c in enumerate(group_colors)],
                             dtype=np.float64).reshape(-1, 3)
    background = to_rgba(background)
    data = src.slice(matrix, c0) if _data is None else _data
    ex = data.extra
    n = src.slices
    scale = REFERENCE_RADIUS / src.size  # source units -> displayed units (the live view's)
    centres = np.asarray(ex["centres"]) * scale
    scales = np.asarray(ex["scales"])
    levels = np.asarray(ex["levels"])
    hi = int(ex["highlighted"])
    group_rgb = ex.get("group_rgb")

    top = TITLE_HEIGHT if title else 0.0
    if _canvas is None:
        fig = Figure(figsize=(width, height + top), dpi=dpi, facecolor=background)
        ax = fig.add_axes([0, 0, 1, height / (height + top)])  # the camera's frame; the title above it
        ax.set_axis_off()
        ax.set_facecolor(background)
    else:  # an animation's next frame: the same figure, this frame's artists only
        fig, ax = _canvas.begin(width, height, top, dpi, background)
    aspect = width / height
    edge = getattr(src.source, "edge_length", None)
    base_ball = look.default_ball_radius(edge * scale) if edge else look.default_ball_radius(_REFERENCE_EDGE)
    if isinstance(frame, str) and frame == "fit":
        box = frame_extent(data, src, ball_radius=(ball_radius if ball_radius is not None else base_ball)
                           if show_balls else 0.0)
    elif isinstance(frame, str) and frame == "camera":
        box = None
    else:
        box = _as_box(frame)
    (x0, x1), (y0, y1) = _frame_limits(box, aspect)
    limit = 0.5 * (y1 - y0)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    if _canvas is None:
        ax.set_aspect("equal")

    poly = getattr(src.source, "polytope", None)
    offs = np.asarray(ex["point_offsets"])
    toff = np.asarray(ex["triangle_offsets"])
    soff = np.asarray(ex["segment_offsets"])
    # back to front by the depth of each slice's centre; zorders of slices never interleave
    jobs = []  # labels, placed after every slice is drawn
    for rank, k in enumerate(np.argsort(centres[:, 2], kind="stable")):
        z_shift = 1e3 * rank
        ball = base_ball * scales[k] if ball_radius is None else ball_radius
        bar = look.default_bar_radius(ball) if bar_radius is None else bar_radius
        if poly is not None:
            s = ex["slices"][k]
            placed = Slice(np.asarray(s.vertices) * scales[k] + centres[k] / scale if n > 1 else np.asarray(s.vertices),
                           s.edges, s.polygon_indices, s.polygon_offsets, s.cell_ids, s.triangles, s.triangle_cells,
                           s.volume, s.dim)
            if palette is not None:
                cmap = ListedColormap(palette)
            else:
                cmap = None if group_rgb is None else ListedColormap([group_rgb[k]])
            if not show_faces:
                placed = Slice(placed.vertices, placed.edges, placed.polygon_indices[:0], placed.polygon_offsets[:1],
                               placed.cell_ids[:0], placed.triangles[:0], placed.triangle_cells[:0], placed.volume,
                               placed.dim)
            if _canvas is not None:  # one collection per slice, in draw_slice's painter's order
                coll = _slice_collection(placed, scale=scale, ball_radius=ball if show_balls else 0.0,
                                         bar_radius=bar if show_bars else 0.0, face_alpha=face_alpha, cmap=cmap,
                                         z_shift=z_shift)
                if coll is not None:
                    ax.add_collection(coll, autolim=False)
            else:
                drawing = draw_slice(ax, placed, scale=scale, fov=CAMERA_FOV,
                                     ball_radius=ball if show_balls else 0.0,
                                     bar_radius=bar if show_bars else 0.0, face_alpha=face_alpha, cmap=cmap)
                for a in (*drawing.faces, *drawing.bars, *drawing.balls, *drawing.highlights):
                    a.set_zorder(a.get_zorder() + z_shift)
        else:
            bar_width = (0.35 * bar if bar_radius is None else bar) if show_bars else 0.0  # a field's box: thin
            _draw_surface(ax, data, k, offs, toff, soff, scale, group_rgb if palette is None else palette,
                          src.source, face_alpha, z_shift, bar_width, show_faces=show_faces)
        if labels:
            jobs.append((centres[k], scales[k] * REFERENCE_RADIUS, levels[k], k == hi, z_shift))
    # labels that would overlap one already placed are left out: the highlighted slice's first,
    # then the nearer (bigger) slices' (far, small slices of the oval crowd together)
    placed: list = []
    point = 2.0 * limit / (height * 72.0)  # data units per typographic point
    for job in sorted(jobs, key=lambda j: (not j[3], -j[1] * perspective(np.asarray(j[0])[None, :])[1][0])):
        _label_slice(ax, *job, point=point, placed=placed)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    if annotate:
        lines, legend = annotation(src, data, c0, theta0=_theta0)
        if isinstance(annotate, str):
            lines = [annotate, *lines]
        _draw_annotation(ax, lines, legend, height, _canvas)
    if title:
        name = getattr(src.source, "name", None) or type(src.source).__name__
        text = title if isinstance(title, str) else (
            f"{name}: {n} slice{'s' if n != 1 else ''} w = c0 + (k \u2212 {(n - 1) / 2:g})\u0394, "
            f"c0 = {c0:.3g}, \u0394 = {src.spacing:.3g}, {src.arrangement}")
        if _canvas is not None and _canvas.title is not None:
            _canvas.title.set_text(text)
        else:
            t = fig.text(0.5, 1.0 - 0.5 * top / (height + top), text, ha="center", va="center", fontsize=9)
            if _canvas is not None:
                _canvas.title = t
        if _canvas is not None:
            _canvas.keep.add(_canvas.title)
    if _canvas is not None:
        _canvas.end()
    _save(fig, path)
    return fig


_TEXT_CACHE_SIZE = 512  # rendered lines of text an animation's canvas keeps


_GLYPH_CACHE_SIZE = 4096  # glyph bitmaps (each at one sub-pixel offset) an animation's canvas keeps


def _glyph_caching_renderer():
    """`RendererAgg` that keeps the bitmap of every glyph it renders, by font, size, glyph and
    sub-pixel offset (1/64 pixel, FreeType's unit), and draws a glyph it rendered before from
    that bitmap: the same ``draw_text_image`` call with the same bitmap as matplotlib's own,
    so the same pixels, without FreeType (~40 µs a glyph).  A new line of text (an animation's
    "t = ..., frame k/n", "w cut ...") then costs its layout and one small blit per glyph.
    Only for matplotlib's glyph-by-glyph text (3.11+: ``_draw_text_glyphs_and_boxes``,
    ``FT2Font._render_glyph``) and unrotated text; anything else is drawn as usual."""
    global _GLYPH_RENDERER
    if _GLYPH_RENDERER is not None:
        return _GLYPH_RENDERER
    from matplotlib import ft2font
    from matplotlib.backends import backend_agg
    from matplotlib.backends.backend_agg import RendererAgg

    usable = (hasattr(RendererAgg, "_draw_text_glyphs_and_boxes") and hasattr(backend_agg, "get_hinting_flag")
              and hasattr(ft2font, "RenderMode")
              and all(hasattr(ft2font.FT2Font, a) for a in ("_render_glyph", "_set_transform", "_layout")))

    class GlyphCachingRenderer(RendererAgg):
        glyphs_cached = usable

        def __init__(self, *args, glyphs=None):
            super().__init__(*args)
            self._glyphs: dict = {} if glyphs is None else glyphs

        def _draw_text_glyphs_and_boxes(self, gc, x, y, angle, glyphs, boxes):
            if angle or boxes or not usable:
                return super()._draw_text_glyphs_and_boxes(gc, x, y, angle, glyphs, boxes)
            RenderMode = ft2font.RenderMode
            flags = backend_agg.get_hinting_flag()
            aa = bool(gc.get_antialiased())
            up = self.height - y  # FreeType's y is upwards
            height = int(self.height)
            cache = self._glyphs
            for font, size, index, slant, extend, dx, dy in glyphs:
                # the pen in 26.6 fixed point, as matplotlib places it (angle 0)
                tx, ty = round(0x40 * (x + dx)), round(0x40 * (up + dy))
                key = (font, size, self.dpi, index, slant, extend, tx & 63, ty & 63, flags, aa)
                hit = cache.get(key)
                if hit is None:  # rendered at the same sub-pixel offset, whole pixels apart
                    font.set_size(size, self.dpi)
                    font._set_transform(np.round(0x10000 * np.array([[extend, extend * slant], [0.0, 1.0]]))
                                        .astype(int), [tx & 63, ty & 63])
                    bitmap = font._render_glyph(index, flags, RenderMode.NORMAL if aa else RenderMode.MONO)
                    buffer = np.array(bitmap.buffer)
                    if not aa:
                        buffer *= 0xff
                    hit = (buffer, bitmap.left, bitmap.top)
                    if len(cache) >= _GLYPH_CACHE_SIZE:
                        cache.clear()
                    cache[key] = hit
                buffer, left, top = hit
                # draw_text_image's y is downwards and the bitmap's bottom side
                self._renderer.draw_text_image(buffer, left + (tx >> 6), height - (top + (ty >> 6)) + buffer.shape[0],
                                               0, gc)

    _GLYPH_RENDERER = GlyphCachingRenderer
    return GlyphCachingRenderer


_GLYPH_RENDERER = None


def _text_caching_canvas(fig):
    """A `FigureCanvasAgg` for ``fig`` whose renderer draws a line of text it drew before from a
    picture of it: matplotlib renders text glyph by glyph (FreeType, a few tens of µs each), and
    an animation's annotation, legend and title repeat from frame to frame but for a line or two.
    A line is rendered once into a transparent buffer at the same sub-pixel offset (so the same
    glyph bitmaps), cropped, and blended where it goes (Agg's draw_image, the same blending as
    drawing the glyphs there: the pixels agree up to rounding).  Glyphs are rendered once too
    (`_glyph_caching_renderer`): a new line is its layout and a blit per glyph.  Rotated text and
    mathtext are drawn as usual."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    GlyphCachingRenderer = _glyph_caching_renderer()

    class TextCachingRenderer(GlyphCachingRenderer):
        def __init__(self, *args):
            super().__init__(*args)
            self._lines: dict = {}

        def draw_text(self, gc, x, y, s, prop, angle, ismath=False, mtext=None):
            if ismath or angle or not s or gc.get_url() is not None:
                return super().draw_text(gc, x, y, s, prop, angle, ismath=ismath, mtext=mtext)
            up = self.height - y  # FreeType's y is upwards
            ix, iy = math.floor(x), math.floor(up)
            feats = (tuple(mtext.get_fontfeatures() or ()), mtext.get_language()) if mtext is not None else None
            font = (tuple(prop.get_family()), prop.get_style(), prop.get_variant(), prop.get_weight(),
                    prop.get_stretch(), prop.get_size(), prop.get_file(), prop.get_math_fontfamily())
            key = (s, font, tuple(gc.get_rgb()), gc.get_alpha(), gc.get_forced_alpha(), gc.get_antialiased(),
                   x - ix, up - iy, feats)
            hit = self._lines.get(key)
            if hit is None:
                hit = self._render_line(gc, x - ix, up - iy, s, prop, mtext)
                if len(self._lines) >= _TEXT_CACHE_SIZE:
                    self._lines.clear()
                self._lines[key] = hit
            img, dx, dy = hit
            if img is None:
                return
            gc1 = self.new_gc()
            gc1.copy_properties(gc)
            gc1.set_alpha(1.0)  # the picture carries the text's alpha already
            self.draw_image(gc1, ix + dx, iy + dy, img)
            gc1.restore()

        def _render_line(self, gc, fx, fy, s, prop, mtext):
            """``(rgba, dx, dy)``: line ``s`` drawn at (fx, fy) in a transparent buffer, cropped to
            its ink; (dx, dy) the crop's lower left corner relative to the pen's whole pixel."""
            em = self.points_to_pixels(prop.get_size_in_points())
            m = int(math.ceil(3.0 * em)) + 4  # room enough around the pen for any glyph (cropped below)
            wd, ht = int(math.ceil(1.5 * em * len(s))) + 2 * m, 2 * m
            off = GlyphCachingRenderer(wd, ht, self.dpi, glyphs=self._glyphs)
            gc1 = off.new_gc()
            gc1.copy_properties(gc)
            gc1.set_clip_rectangle(None)
            gc1.set_clip_path(None)
            oy = ht // 2
            GlyphCachingRenderer.draw_text(off, gc1, m + fx, ht - (oy + fy), s, prop, 0.0, ismath=False, mtext=mtext)
            gc1.restore()
            rgba = np.asarray(off.buffer_rgba())
            rows = np.flatnonzero(rgba[..., 3].any(axis=1))
            cols = np.flatnonzero(rgba[..., 3].any(axis=0))
            if not len(rows):
                return None, 0, 0
            r0, r1, c0, c1 = rows[0], rows[-1] + 1, cols[0], cols[-1] + 1
            # draw_image takes the rows bottom up (as matplotlib's images hand them over)
            return np.ascontiguousarray(rgba[r0:r1, c0:c1][::-1]), int(c0 - m), int(ht - r1 - oy)

    class TextCachingCanvas(FigureCanvasAgg):
        def get_renderer(self):
            w, h = self.get_width_height(physical=True)
            key = w, h, self.figure.dpi
            if self._lastKey != key:
                self.renderer = TextCachingRenderer(w, h, self.figure.dpi)
                self._lastKey = key
            return self.renderer

    return TextCachingCanvas(fig)


class _FrameCanvas:
    """One figure, axes and Agg canvas that an animation's frames are drawn into in turn
    (`render_state(..., _canvas=)`): building a figure and its axes was a third of a frame's time.
    `begin` takes the figure (a new one when the size, dpi, title strip or background change)
    and removes what the frame before added; the annotation, its legend and the title are kept
    and given the new frame's text (`_draw_annotation`), and removed when a frame has none.
    A polytope's slice is drawn as one collection (`_slice_collection`) instead of a patch per
    ball, highlight, bar and face.  `rgb()` draws the frame and returns its pixels."""

    def __init__(self):
        self.fig = self.ax = self.canvas = None
        self.key = None
        self.note = self.title = None
        self.legend_key = None
        self.keep: set = set()

    def begin(self, width, height, top, dpi, background):
        key = (width, height, top, dpi, tuple(background))
        if self.fig is None or key != self.key:
            self.fig = Figure(figsize=(width, height + top), dpi=dpi, facecolor=background)
            self.ax = self.fig.add_axes([0, 0, 1, height / (height + top)])
            self.ax.set_axis_off()
            self.ax.set_facecolor(background)
            self.ax.set_aspect("equal")
            self.canvas = _text_caching_canvas(self.fig)
            self.key = key
            self.note = self.title = self.legend_key = None
        else:  # the frame before's artists go, but for the annotation and the title (kept if used)
            ax = self.ax
            for a in (*ax.collections, *ax.patches, *ax.texts, *ax.lines, *ax.images, *self.fig.texts):
                if a is not self.note and a is not self.title:
                    a.remove()
        self.keep = set()
        return self.fig, self.ax

    def end(self):
        """After a frame is built: what it did not use of the kept artists goes."""
        if self.note is not None and self.note not in self.keep:
            self.note.remove()
            self.note = None
            if self.ax.get_legend() is not None:
                self.ax.get_legend().remove()
            self.legend_key = None
        if self.title is not None and self.title not in self.keep:
            self.title.remove()
            self.title = None

    @staticmethod
    def as_picture(artist) -> None:
        """Draw ``artist`` (one that stays the same from frame to frame: the legend) from a picture
        of it taken the first time: rendered alone into a transparent buffer of the canvas's size,
        cropped, then blended in place each frame (Agg's draw_image: the same pixels up to rounding)."""
        draw = artist.draw
        kept = {}

        def drawn_from_picture(renderer):
            if not artist.get_visible():
                return
            key = (renderer.width, renderer.height, renderer.dpi, type(renderer))
            if key not in kept:
                from matplotlib.backends.backend_agg import RendererAgg

                if not isinstance(renderer, RendererAgg):
                    return draw(renderer)
                off = RendererAgg(int(renderer.width), int(renderer.height), renderer.dpi)
                draw(off)
                rgba = np.asarray(off.buffer_rgba())
                rows = np.flatnonzero(rgba[..., 3].any(axis=1))
                cols = np.flatnonzero(rgba[..., 3].any(axis=0))
                if not len(rows):
                    kept[key] = None
                else:
                    r0, r1, c0, c1 = rows[0], rows[-1] + 1, cols[0], cols[-1] + 1
                    kept[key] = (np.ascontiguousarray(rgba[r0:r1, c0:c1][::-1]), int(c0),
                                 int(renderer.height) - int(r1))
            if kept[key] is not None:
                img, x, y = kept[key]
                gc = renderer.new_gc()
                renderer.draw_image(gc, x, y, img)
                gc.restore()
            artist.stale = False

        artist.draw = drawn_from_picture

    def rgba(self) -> np.ndarray:
        """Draw the frame; its (H, W, 4) uint8 pixels, a view valid until the next frame is drawn."""
        self.canvas.draw()
        return np.asarray(self.canvas.buffer_rgba())

    def rgb(self) -> np.ndarray:
        """The frame's (H, W, 3) uint8 pixels (a copy), drawn by Agg at the figure's size."""
        self.canvas.draw()
        return np.asarray(self.canvas.buffer_rgba())[..., :3].copy()


def _label_slice(ax, centre, radius, w, highlighted, z_shift, *, point=None, placed=None):
    """'w = ...' at the upper left of a slice's projected bounding circle (inside its square, like a
    CT film's corner text), painted with its slice (nearer slices cover it); the highlighted slice
    ringed, its label bold.  With ``point`` (data units per point) and ``placed`` (boxes of the
    labels drawn so far), a label overlapping one of them is left out (not the highlighted one)."""
    (xy,), (f,) = perspective(np.asarray(centre, dtype=np.float64)[None, :])
    r = radius * f
    fs = max(5.0, min(9.0, 30.0 * r))
    z = _Z_BASE + float(centre[2]) + z_shift + 0.5e3
    text = f"w = {w:.3g}"
    x0, y1 = xy[0] - 0.98 * r, xy[1] + 0.98 * r
    if point is not None and placed is not None:
        # the upper left corner of the slice's square, else its upper right, else just above it
        wd, ht = 0.62 * fs * point * len(text), 1.7 * fs * point  # a line and a gap
        for cx, cy in ((x0, y1), (xy[0] + 0.98 * r - wd, y1), (xy[0] - wd / 2, y1 + ht)):
            box = (cx, cy - ht, cx + wd, cy)
            if not any(box[0] < b[2] and b[0] < box[2] and box[1] < b[3] and b[1] < box[3] for b in placed):
                break
        else:
            if not highlighted:
                return  # nowhere free: left out
            cx, cy, box = x0, y1, (x0, y1 - ht, x0 + wd, y1)
        placed.append(box)
        x0, y1 = cx, cy
    ax.text(x0, y1, text, ha="left", va="top", fontsize=fs,
            fontweight="bold" if highlighted else "normal", zorder=z, gid="label")
    if highlighted:
        _add_patch(ax, Circle(xy, r, facecolor="none", edgecolor="#333333", linewidth=0.8, linestyle="--",
                            zorder=z, gid="highlight-ring"))


def _triangles_class():
    """`_Triangles`, made on first use (matplotlib's collections imported lazily)."""
    from matplotlib.collections import PolyCollection

    class Triangles(PolyCollection):
        """Flat-coloured triangles drawn in the order given with one renderer call
        (``draw_gouraud_triangles``, each corner the triangle's colour) instead of one path per
        triangle: a field's surface of thousands of triangles draws several times faster.  It is
        a `PolyCollection` for everything but drawing (``ax.collections``, its gid, colours)."""

        def __init__(self, verts, rgba, **kwargs):
            self._tri_verts = np.asarray(verts, dtype=np.float64).reshape(-1, 3, 2)
            self._tri_rgba = np.asarray(rgba, dtype=np.float64).reshape(-1, 4)
            super().__init__([], facecolors=self._tri_rgba, edgecolors="none", **kwargs)

        def get_paths(self):  # lazily, for anything that asks (hit tests, extents)
            if not self._paths and len(self._tri_verts):
                self.set_verts(self._tri_verts)
            return self._paths

        def draw(self, renderer):
            if not self.get_visible() or not len(self._tri_verts):
                return
            renderer.open_group("surface", gid=self.get_gid())
            gc = renderer.new_gc()
            self._set_gc_clip(gc)
            gc.set_linewidth(0.0)
            colors = np.repeat(self._tri_rgba[:, None, :], 3, axis=1)
            renderer.draw_gouraud_triangles(gc, self._tri_verts, colors, self.get_transform().frozen())
            gc.restore()
            renderer.close_group("surface")
            self.stale = False

    return Triangles


def _Triangles(verts, rgba, **kwargs):
    global _TRIANGLES
    if _TRIANGLES is None:
        _TRIANGLES = _triangles_class()
    return _TRIANGLES(verts, rgba, **kwargs)


_TRIANGLES = None


def _draw_surface(ax, data, k, offs, toff, soff, scale, group_rgb, inner, face_alpha, z_shift, bar_width,
                  show_faces=True):
    """Slice k of a stack of smooth surfaces: shaded triangles back to front, its bars as lines."""
    from matplotlib.collections import LineCollection, PolyCollection

    p0, p1 = offs[k], offs[k + 1]
    pts = np.asarray(data.points[p0:p1]) * scale
    tri = np.asarray(data.triangles[toff[k]:toff[k + 1]]) - p0
    seg = np.asarray(data.segments[soff[k]:soff[k + 1]]) - p0
    if not len(pts):
        return
    xy, _ = perspective(pts)
    z_base = _Z_BASE + float(pts[:, 2].mean()) + z_shift
    if len(tri) and show_faces:
        groups = np.asarray(data.groups[toff[k]:toff[k + 1]])
        if group_rgb is not None:
            pal = np.asarray(group_rgb, dtype=np.float64)
            rgb = pal[np.minimum(groups, len(pal) - 1)] if len(pal) == 1 else pal[groups]
        else:
            levels = getattr(inner, "levels", None)
            if levels:
                lo, hi = getattr(inner, "data_range", (min(levels), max(levels)))
                rgb = _level_colors(levels, lo, hi)[groups]
            else:
                rgb = look.group_palette(int(groups.max()) + 1)[groups].astype(np.float64)
        # a triangle's mean normal and depth as (c0 + c1 + c2) / 3: the sums and the division of
        # ``[tri].mean(axis=1)``, bit for bit, from three gathers instead of one (T, 3, 3) reduction
        t0, t1, t2 = tri[:, 0], tri[:, 1], tri[:, 2]
        nrm = data.normals
        if nrm is not None:
            nv = np.asarray(nrm[p0:p1])
            n = (nv[t0] + nv[t1] + nv[t2]) / 3.0
            n /= np.maximum(np.sqrt(np.add.reduce(n * n, axis=1, keepdims=True)), 1e-12)  # norm's arithmetic
            light = np.array([-0.35, 0.45, 0.82])
            shade = 0.45 + 0.55 * np.abs(n @ (light / np.linalg.norm(light)))
            rgb = np.clip(rgb * shade[:, None], 0.0, 1.0)
        z = pts[:, 2]
        depth = (z[t0] + z[t1] + z[t2]) / 3.0
        order = np.argsort(depth, kind="stable")
        alpha = 1.0 if len(getattr(inner, "levels", ()) or ()) <= 1 else max(face_alpha, look.SURFACE_OPACITY)
        coll = _Triangles(xy[tri[order]], np.column_stack([rgb[order], np.full(len(order), alpha)]),
                          zorder=z_base, gid="surface")
        ax.add_collection(coll, autolim=False)
    if len(seg) and bar_width > 0:
        lines = LineCollection(xy[seg], colors=look.BAR_COLOR, linewidths=max(0.3, 72 * bar_width),
                               zorder=z_base + 1e-3, gid="bar")
        ax.add_collection(lines, autolim=False)


# --------------------------------------------------------------------------- the live view's picture
def state_source(source, *, levels=None, slices=None, spacing=None, arrangement=None, inside=None, caps=None):
    """``source`` (a name, a Polytope or any source) with a widget's source settings applied, as a
    `StackSource` (N = 1 is today's single slice, point for point).  The source given is not
    changed: a field whose ``levels`` differ is copied (shallowly, sharing its array), a stack is
    rebuilt around its inner source."""
    from ..sources.protocol import as_source
    from ..sources.tomography import StackSource

    src = as_source(source)
    inner, color_by, n, spc, arr = src, "w", 1, None, "oval"
    if isinstance(src, StackSource):
        inner, color_by, n, arr = src.source, src.color_by, src.slices, src.arrangement
        spc = None if src.spacing_is_default else src.spacing
    if slices is not None:
        n = slices
    if spacing is not None:
        spc = spacing
    if arrangement is not None:
        arr = arrangement
    if levels is not None:
        if not hasattr(inner, "levels"):
            raise TypeError(f"`levels` applies to sources with iso levels (a Field4D), not {type(inner).__name__}")
        if tuple(np.atleast_1d(np.asarray(levels, dtype=np.float64)).tolist()) != tuple(inner.levels):
            inner = copy.copy(inner)
            inner.levels = levels
    for name, value in (("inside", inside), ("caps", caps)):  # a field's other settings, likewise
        if value is not None and getattr(inner, name, value) != value:
            inner = copy.copy(inner)
            setattr(inner, name, value)
    return StackSource(inner, slices=n, spacing=spc, arrangement=arr, color_by=color_by)


def render_state(
    state: RotationState,
    source="5-cell",
    path=None,
    *,
    levels=None,
    slices: int | None = None,
    spacing: float | None = None,
    arrangement: str | None = None,
    inside: str | None = None,
    caps: bool | None = None,
    color_by="group",
    group_colors=None,
    face_opacity: float = look.FACE_OPACITY,
    ball_radius: float | None = None,
    bar_radius: float | None = None,
    background=look.BACKGROUND,
    show_balls: bool = True,
    show_bars: bool = True,
    show_faces: bool = True,
    size=(600, 500),
    dpi: float = 100,
    labels: bool = False,
    title: str | None = None,
    frame="fit",
    annotate=False,
    _prepared=None,
    _canvas=None,
) -> Figure:
    """The picture the widget shows for ``state`` and ``source``, without a browser.

    ``state`` is a `RotationState` (its matrix and c0 are used); ``source`` a polytope name, a
    Polytope, a `Field4D`, a `StackSource` or any source.  The keywords are the widget's
    settings, by the names of its traits (`rot4d_widget.keep.export.save_state` stores them so):
    ``levels`` (a field's iso levels), ``slices``, ``spacing``, ``arrangement`` (parallel
    slices: `state_source`), ``color_by`` (``"group"`` or one colour), ``group_colors``,
    ``face_opacity``, ``ball_radius`` / ``bar_radius`` (displayed units; default as the widget
    chooses them: from the polytope's edge, the same for every slice), ``background``,
    ``show_balls`` / ``show_bars`` / ``show_faces``.

    The scene is the live view's: every source scaled to the displayed circumradius
    `look.REFERENCE_RADIUS`, the eye at `look.CAMERA_POSITION` looking down -z with the vertical
    field of view `look.CAMERA_FOV` and the aspect of ``size`` (pixels, width x height; the
    widget's canvas is 600 x 500), the cell palette `look.group_palette` (a field's levels:
    `look.level_colors`; a stack coloured by w: its levels' colormap).  It does not follow a
    camera the user dragged.  ``labels`` writes each parallel slice's w; ``title`` goes above.

    ``frame="fit"`` (the default) keeps that eye and perspective but zooms so that the projected
    bounding box of what is drawn fills `FIT_FILL` (90 %) of the picture's width or height;
    ``frame="camera"`` is the live view's frame exactly (an object there fills about a third of
    the picture); a box ``(x0, x1, y0, y1)`` in the picture plane is fitted like "fit" (see
    `render_tomography`).  ``annotate``: True writes θ0, c0 and what the source tells of itself
    (`annotation`: name, units, levels, w span, a stack's w) in the upper left corner and a
    legend of the levels' or slices' colours in the lower left; a string is written first.
    Saved to ``path`` (.png, .svg or .pdf) if given, at ``dpi``: a PNG is ``size`` pixels (plus the title's strip when ``title`` is given).
    Returns the Figure.
    """
    if not isinstance(state, RotationState):
        raise TypeError(f"Expected `state` to be a rot4d_widget.RotationState, got {type(state).__name__}")
    try:
        w_px, h_px = (float(v) for v in size)
    except (TypeError, ValueError):
        raise TypeError(f"Expected `size` to be (width, height) in pixels, got {size!r}") from None
    w_px = _real("size[0]", w_px, minimum=1.0)
    h_px = _real("size[1]", h_px, minimum=1.0)
    dpi = _real("dpi", dpi, minimum=0.0, inclusive=False)
    if title is not None and not isinstance(title, str):
        raise TypeError(f"Expected `title` to be a string or None, got {type(title).__name__}")
    face_color = None
    if color_by != "group":
        face_color = look.as_rgb(color_by, "color_by")
    if _prepared is None:
        _prepared = _prepare(state, source, levels=levels, slices=slices, spacing=spacing, arrangement=arrangement,
                             ball_radius=ball_radius, show_balls=show_balls, inside=inside, caps=caps)
    stack, data, ball_radius, box = _prepared
    if isinstance(frame, str) and frame == "fit":
        frame = "camera" if box is None else box
    return render_tomography(
        stack, state.matrix, state.c0, path=path, width=w_px / dpi, height=h_px / dpi, dpi=dpi,
        title=title if title else None, labels=labels, face_alpha=face_opacity, ball_radius=ball_radius,
        bar_radius=bar_radius, show_balls=show_balls, show_bars=show_bars, show_faces=show_faces,
        face_color=face_color, group_colors=group_colors, background=background, frame=frame,
        annotate=annotate, _data=data, _theta0=state.theta0, _canvas=_canvas,
    )


def _prepare(state, source, *, levels=None, slices=None, spacing=None, arrangement=None, ball_radius=None,
             show_balls=True, data=None, inside=None, caps=None, **_ignored):
    """What `render_state` draws before drawing it: ``(stack, data, ball_radius, box)`` -- the
    source with the settings applied (`state_source`), its slice at ``state``, the ball radius
    in displayed units (None: the stack's default) and the projected bounding box of the
    drawing (`frame_extent`; None when empty).  ``data``: the slice, computed before.  An animation takes the boxes of all its frames
    first to frame them alike, and draws each frame from the slice computed then."""
    stack = state_source(source, levels=levels, slices=slices, spacing=spacing, arrangement=arrangement,
                         inside=inside, caps=caps)
    if ball_radius is None:
        edge = getattr(stack, "edge_length", None)
        if edge:
            ball_radius = look.default_ball_radius(edge * REFERENCE_RADIUS / stack.size)
    if data is None:
        data = stack.slice(state.matrix, state.c0)
    if show_balls:
        ball = ball_radius if ball_radius is not None else look.default_ball_radius(_REFERENCE_EDGE)
    else:
        ball = 0.0
    return stack, data, ball_radius, frame_extent(data, stack, ball_radius=ball)
