"""Drawing one w = c0 slice with matplotlib 2-D artists, in the live view's perspective.

No browser and no widget library: the slice is drawn in a perspective view from the paper's
viewpoint, the point (x, y, z) = (0, 0, ``distance``) looking down -z (``distance`` = 5 in the
paper).  A 3-D point is projected by hand,

    x' = x d / (d - z),    y' = y d / (d - z),

and every radius at that point is multiplied by the same factor ``d / (d - z)``.  The frame is the
live view's camera (:mod:`rot4d_widget.core.camera`): a vertical field of view of ``fov`` = 40 degrees, so
the axes span ``|y'| <= d tan(fov / 2)`` and ``|x'| <=`` that times the panel's aspect, and a point
sits in the panel where a three.js ``PerspectiveCamera`` at (0, 0, 5) with that fov and aspect puts
it.  Palette and colours come from :mod:`rot4d_widget.core.colours`, scale and default radii from
:mod:`rot4d_widget.core.sizes`, so a 4-D
cell has the same colour here and in the widget.  Artists are
painted back to front (painter's algorithm, by the depth of a ball's centre, a bar's midpoint, a
face's centroid), so nearer things cover farther ones.

* balls at slice vertices (circles, with a small highlight),
* bars along slice edges (trapezoids whose width follows the perspective of each end),
* translucent faces (slice polygons), coloured by the 4-D cell they are cut from
  (``colours.group_palette``, the live view's palette).

Also the validators and the saving helper the other picture modules share.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from numbers import Integral, Real

import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import PathCollection
from matplotlib.colors import Colormap, ListedColormap, to_rgba
from matplotlib.figure import Figure
from matplotlib.patches import Circle, Polygon

from ...core import camera, colours, sizes
from ...core.sizes import REFERENCE_RADIUS
from ...core.state import PAPER_ALPHA_RATIO
from ...geometry.catalogue import polytope as _named_polytope
from ...geometry.mesh import Polytope
from ...geometry.slicing.tables import Slice

#: The paper's viewpoint: the eye at (0, 0, 5) looking down -z (``camera.CAMERA_POSITION``).
CAMERA_DISTANCE = float(camera.CAMERA_POSITION[2])
#: Vertical field of view of the frame, degrees (``camera.CAMERA_FOV``, the live camera's).
CAMERA_FOV = float(camera.CAMERA_FOV)
# REFERENCE_RADIUS (from core.sizes): the paper's pentachoron's circumradius (edge a = 2), sqrt(2/5) * a.
# Other polytopes are scaled to it by default so that they appear the same size.
#: Edge of the pentachoron of circumradius REFERENCE_RADIUS: the default ball and bar radii of
#: :func:`draw_slice` are this edge's (``sizes.default_ball_radius(2.0)`` = 0.07).
REFERENCE_EDGE = REFERENCE_RADIUS / math.sqrt(2.0 / 5.0)
#: Fig. 3: key "4" (R_xw) with theta0 = pi/16.
FIG3_THETA0 = math.pi / 16
#: Fig. 4: key "z" (R_xz,yw) with alpha = pi sqrt2 / (8 sqrt3) and "beta = 1 - alpha",
#: i.e. alpha + beta = theta0 = 1 rad.
FIG4_THETA0 = 1.0
FIG4_ALPHA = PAPER_ALPHA_RATIO * FIG4_THETA0

#: Extra figure height (inches) for a title above the panels.
TITLE_HEIGHT = 0.4
_SAVE_FORMATS = (".png", ".pdf", ".svg")

# Painter's order: zorder = Z_BASE + depth + a tiny offset per kind, so at equal depth a ball is
# drawn over a bar, and a bar over a face.  Labels stay above everything.
Z_BASE = 10.0
_Z_KIND = {"face": 0.0, "bar": 1e-4, "ball": 2e-4}
Z_LABEL = 1e6


# --------------------------------------------------------------------------- validation helpers
def checked_real(name: str, value, *, minimum=None, inclusive=True, maximum=None) -> float:
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


def checked_count(name: str, value, *, minimum: int = 1) -> int:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, Integral):
        raise TypeError(f"Expected `{name}` to be an integer, got {type(value).__name__}")
    value = int(value)
    if value < minimum:
        raise ValueError(f"Expected `{name}` >= {minimum}, got {value}")
    return value


def as_polytope(value) -> Polytope:
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
        # matplotlib's colormap registry: looked up only for a colormap named by a string
        import matplotlib

        try:
            return matplotlib.colormaps[cmap]
        except KeyError:
            raise ValueError(f"Unknown matplotlib colormap {cmap!r} for `cmap`") from None
    raise TypeError(f"Expected `cmap` to be a colormap name or a matplotlib Colormap, got {type(cmap).__name__}")


def _cell_colors(cell_ids: np.ndarray, cmap: Colormap | None) -> np.ndarray:
    """(P, 4) RGBA per polygon: the same 4-D cell always gets the same colour.

    ``cmap`` None: ``colours.group_palette`` (the live view's colour of each cell, unrounded).
    """
    ids = np.asarray(cell_ids, dtype=np.int64)
    if cmap is None:
        rgb = colours.group_palette(int(ids.max()) + 1 if len(ids) else 0)[ids].astype(np.float64)
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
    d = checked_real("distance", distance, minimum=0.0, inclusive=False)
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


def add_patch(ax, patch):
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
    face_alpha: float = colours.FACE_OPACITY,
    ball_color=colours.BALL_COLOR,
    bar_color=colours.BAR_COLOR,
    cmap=None,
    label: str | None = None,
) -> SliceDrawing:
    """Draw one slice on a matplotlib ``ax`` in the paper's perspective view.

    ``slice`` is a :class:`rot4d_widget.Slice`; its vertices are multiplied by ``scale`` first.
    ``ball_radius`` and ``bar_radius`` are 3-D sizes (after scaling), shrunk with distance like
    everything else; by default ``sizes.default_ball_radius`` of the reference pentachoron's edge
    (0.07) and ``sizes.default_bar_radius(ball_radius)``, as in the live view.
    The frame is the camera's: vertical field of view ``fov`` degrees and the aspect of ``ax``,
    so every panel of a sequence shares it and a point sits where the live view puts it.  With
    ``fov=None`` the frame fits a sphere of ``radius`` (after scaling) if given, else this slice;
    with a camera, ``radius`` only checks that the eye is outside that sphere.
    Faces are coloured by ``slice.cell_ids`` with ``colours.group_palette`` (the live view's colours),
    or through ``cmap`` (a matplotlib colormap name or Colormap) if given.

    Returns a :class:`SliceDrawing` listing the artists; they also carry the gids "ball", "bar",
    "face" and "highlight" (kept in SVG output).
    """
    if not isinstance(ax, Axes):
        raise TypeError(f"Expected `ax` to be a matplotlib Axes, got {type(ax).__name__}")
    if not isinstance(slice, Slice):
        raise TypeError(f"Expected `slice` to be a rot4d_widget.Slice, got {type(slice).__name__}")
    scale = checked_real("scale", scale, minimum=0.0, inclusive=False)
    d = checked_real("distance", distance, minimum=0.0, inclusive=False)
    if fov is not None:
        fov = checked_real("fov", fov, minimum=0.0, inclusive=False)
        if fov >= 180.0:
            raise ValueError(f"Expected `fov` < 180 degrees, got {fov:g}")
    if ball_radius is None:
        ball_radius = sizes.default_ball_radius(REFERENCE_EDGE)
    ball_radius = checked_real("ball_radius", ball_radius, minimum=0.0)
    if bar_radius is None:
        bar_radius = sizes.default_bar_radius(ball_radius)
    bar_radius = checked_real("bar_radius", bar_radius, minimum=0.0)
    face_alpha = checked_real("face_alpha", face_alpha, minimum=0.0, maximum=1.0)
    if radius is not None:
        radius = checked_real("radius", radius, minimum=0.0, inclusive=False)
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

    # faces: a convex cell's section is a convex polygon: order its corners around the projected
    # centroid so the drawing does not depend on the slicer's corner order.  A slice with fill
    # corners (non-convex sections, `Slice.n_fill`) draws its triangles instead (the even-odd fill).
    for corners, rgba, depth in _face_patches(slice, xy, z, colormap):
        patch = Polygon(
            corners, closed=True, facecolor=(*rgba[:3], face_alpha), edgecolor="none",
            zorder=Z_BASE + depth + _Z_KIND["face"], gid="face",
        )
        add_patch(ax, patch)
        drawing.faces.append(patch)

    # bars: a trapezoid from end a to end b, half-width bar_radius * factor at each end
    edge_rgba = tuple(0.6 * np.asarray(bar_rgba[:3])) + (bar_rgba[3],)
    if bar_radius > 0:
        for a, b in np.asarray(slice.edges, dtype=np.int64).reshape(-1, 2):
            pa, pb = xy[a], xy[b]
            ra, rb = bar_radius * fac[a], bar_radius * fac[b]
            u = pb - pa
            length = math.hypot(*u)
            zo = Z_BASE + 0.5 * (z[a] + z[b]) + _Z_KIND["bar"]
            if length <= 1e-12:  # edge along the line of sight: its end-on disc
                patch = Circle(pa, max(ra, rb), facecolor=bar_rgba, edgecolor="none", zorder=zo, gid="bar")
            else:
                n = np.array([-u[1], u[0]]) / length
                corners = [pa + n * ra, pb + n * rb, pb - n * rb, pa - n * ra]
                patch = Polygon(corners, closed=True, facecolor=bar_rgba, edgecolor=edge_rgba,
                                linewidth=0.3, zorder=zo, gid="bar")
            add_patch(ax, patch)
            drawing.bars.append(patch)

    # balls: circles of radius ball_radius * factor, with a highlight towards the upper left
    if ball_radius > 0:
        dark = tuple(0.55 * np.asarray(ball_rgba[:3])) + (ball_rgba[3],)
        for i in range(_n_balls(slice, len(pts))):
            r = ball_radius * fac[i]
            zo = Z_BASE + z[i] + _Z_KIND["ball"]
            ball = Circle(xy[i], r, facecolor=ball_rgba, edgecolor=dark, linewidth=0.4, zorder=zo, gid="ball")
            shine = Circle(xy[i] + np.array([-0.35, 0.35]) * r, 0.3 * r, facecolor=(1, 1, 1, 0.55),
                           edgecolor="none", zorder=zo + 1e-5, gid="highlight")
            add_patch(ax, ball)
            add_patch(ax, shine)
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
                zorder=Z_LABEL)
    return drawing



def _n_balls(slice, n_points: int) -> int:
    """Balls drawn: every vertex but the last ``n_fill`` (fill corners of non-convex sections)."""
    return n_points - int(slice.n_fill)


def _face_patches(slice, xy, z, colormap):
    """``(corners (k, 2), rgba, depth)`` per face patch: a convex slice's polygons with corners
    ordered by angle about their projected centroid; a slice with fill corners (``n_fill`` > 0:
    its non-convex sections are even-odd filled) its triangles, coloured by ``triangle_cells``."""
    if int(slice.n_fill):
        tri = np.asarray(slice.triangles, dtype=np.int64).reshape(-1, 3)
        if not len(tri):
            return []
        colors = _cell_colors(np.asarray(slice.triangle_cells), colormap)
        depth = z[tri].mean(axis=1)
        return [(xy[t], rgba, float(d)) for t, rgba, d in zip(tri, colors, depth)]
    out = []
    polygons = list(slice.polygons)
    colors = _cell_colors(np.asarray(slice.cell_ids), colormap) if polygons else []
    for poly, rgba in zip(polygons, colors):
        idx = np.asarray(poly, dtype=np.int64)
        if len(idx) < 3:
            continue
        p2 = xy[idx]
        c2 = p2.mean(axis=0)
        order = np.argsort(np.arctan2(p2[:, 1] - c2[1], p2[:, 0] - c2[0]))
        out.append((p2[order], rgba, float(z[idx].mean())))
    return out


# --------------------------------------------------------------------------- one panel, fast (animations)
_CIRCLE = None  # Path.unit_circle()'s vertices and codes, made on first use
_POLY_CODES: dict = {}  # closed polygon codes by corner count


def _closed_codes(n: int) -> np.ndarray:
    codes = _POLY_CODES.get(n)
    if codes is None:
        # matplotlib.path: imported when a polygon is drawn
        from matplotlib.path import Path

        codes = np.full(n + 1, Path.LINETO, dtype=Path.code_type)
        codes[0], codes[-1] = Path.MOVETO, Path.CLOSEPOLY
        _POLY_CODES[n] = codes
    return codes


def slice_collection(slice: Slice, *, scale: float, ball_radius: float, bar_radius: float, face_alpha: float,
                     cmap=None, ball_color=colours.BALL_COLOR, bar_color=colours.BAR_COLOR, z_shift: float = 0.0,
                     distance: float = CAMERA_DISTANCE):
    """What `draw_slice` draws -- the same faces, bars, balls and highlights, with the same paths,
    colours, edges and painter's order (zorders plus ``z_shift``, ties in draw_slice's order) --
    as ONE `PathCollection` (gid "slice"), drawn by a single renderer call.  For animations:
    a frame of the 24-cell is ~100 patches, whose building and drawing was most of its time.
    ``cmap`` a Colormap or None; radii and sizes already checked.  None when nothing is drawn."""
    # matplotlib paths: imported when a slice is drawn as one collection
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

    # faces: corners ordered around the projected centroid (draw_slice's order), one loop-free pass;
    # a slice with fill corners: its triangles (as draw_slice)
    off = np.asarray(slice.polygon_offsets, dtype=np.int64)
    lens = np.diff(off)
    if int(slice.n_fill):
        for corners, rgba, depth in _face_patches(slice, xy, z, cmap):
            paths.append(Path(np.concatenate([corners, corners[:1]]), _closed_codes(len(corners))))
            face.append((*rgba[:3], face_alpha))
            edge.append(none)
            width.append(0.0)
            zo.append(Z_BASE + depth + _Z_KIND["face"])
        lens = lens[:0]
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
            zo.append(Z_BASE + depth[k] + _Z_KIND["face"])

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
        zb = Z_BASE + 0.5 * (z[e[:, 0]] + z[e[:, 1]]) + _Z_KIND["bar"]
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
        zb = Z_BASE + z + _Z_KIND["ball"]
        shine = xy + np.array([-0.35, 0.35]) * r[:, None]
        for i in range(_n_balls(slice, len(pts))):
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
    return SliceCollection([paths[i] for i in order], zo[order], facecolors=np.asarray(face)[order],
                           edgecolors=np.asarray(edge)[order], linewidths=np.asarray(width)[order],
                           joinstyle="miter", capstyle="butt", zorder=float(zo.min()), gid="slice")


class SliceCollection(PathCollection):
    """`slice_collection`'s one collection of paths, painted in order; ``items_zorder``: the
    zorder each path would have as draw_slice's patch (ascending), which the collection's own
    zorder (their least) stands for."""

    def __init__(self, paths, items_zorder, **kwargs):
        super().__init__(paths, **kwargs)
        self.items_zorder = items_zorder


# --------------------------------------------------------------------------- grids of panels
def save_figure(fig: Figure, path) -> None:
    if path is None:
        return
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"Expected `path` to be a file path or None, got {type(path).__name__}")
    ext = os.path.splitext(os.fspath(path))[1].lower()
    if ext not in _SAVE_FORMATS:
        raise ValueError(f"Expected `path` to end in one of {', '.join(_SAVE_FORMATS)}, got {os.fspath(path)!r}")
    fig.savefig(path, dpi=fig.dpi, facecolor=fig.get_facecolor())
