"""What the widget shows, without a browser: `render_state`, `render_tomography`, `state_source`.

:func:`render_state` draws a `RotationState` and any source (polytope, field, stack, a user's
own) with the widget's display settings at a chosen size in pixels; :func:`render_tomography`
draws N parallel slices as the live view lays them out.
"""

from __future__ import annotations

import copy
from types import SimpleNamespace

import numpy as np
from matplotlib.colors import ListedColormap, to_rgba
from matplotlib.figure import Figure
from matplotlib.patches import Circle

from ...core import camera, colours, renderings, sizes
from ...core.camera import view_rotation
from ...core.renderings import DEFAULT_SECTIONS, check_rendering
from ...core.sizes import REFERENCE_RADIUS
from ...core.state import RotationState
from ...geometry.slicing.tables import Slice
from ...sources.field_labels import box_labels
from ...sources.protocol import (
    apply_setting,
    as_source,
    class_name,
    data_w_text,
    inner_source,
    note_matrix,
    settings_of,
    source_title,
)
from ...sources.tomography import StackSource
from .canvas import LiteralTextFigure
from .framing import (
    annotation,
    annotation_boxes,
    as_box,
    below_notes,
    colorbar_width,
    draw_annotation,
    draw_box_labels,
    draw_colorbar,
    frame_extent,
    frame_limits,
    level_rgb,
    room_for_labels,
    seen_from,
    small_font,
    value_label,
)
from .ray_caster import cut_grids, draw_volume
from .slice_drawing import (
    CAMERA_FOV,
    REFERENCE_EDGE,
    TITLE_HEIGHT,
    Z_BASE,
    add_patch,
    checked_real,
    draw_slice,
    perspective,
    save_figure,
    slice_collection,
)


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
    face_alpha: float = colours.FACE_OPACITY,
    ball_radius: float | None = None,
    bar_radius: float | None = None,
    show_balls: bool = True,
    show_bars: bool = True,
    show_faces: bool = True,
    face_color=None,
    group_colors=None,
    background=colours.BACKGROUND,
    frame="camera",
    annotate=False,
    rendering: str = "surface",
    cmap: str = colours.LEVEL_COLORMAP,
    clim=None,
    sections=DEFAULT_SECTIONS,
    colorbar: bool = True,
    axis_labels: bool = True,
    progress=True,
    eye=None,
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

    A field (a source with a ``data_range``) is drawn as ``rendering``: ``"surface"`` its
    isosurfaces, coloured along ``cmap`` (by rank while ``clim`` is None, else by value over
    ``clim``, as the live view colours them); ``"volume"``, ``"mip"`` or ``"sections"`` its cut
    sampled on a grid and ray-cast (`rot4d_widget.keep.pictures.ray_caster.render_grid`; ``clim`` None: the
    1st-99th percentile of the cuts' values; ``sections`` the planes' places; ``progress``: a bar
    when the casting takes more than a second, see `render_grid`), the box's edges drawn over it.
    ``colorbar``: a colour bar in a strip right of the picture (`colorbar_width` inches: the
    figure is that much wider, the picture itself unchanged): ``cmap`` over the limits the colours
    stand for (``clim``, else the surfaces' data range or the rendering's percentiles), titled
    with the variable's ``long_name`` (else ``name``) and ``units``, the iso levels marked in their
    surfaces' colours (surface rendering).  ``axis_labels``: a single cut's box labelled with its
    data coordinates (`rot4d_widget.sources.field_labels.box_labels`: the origin corner's, and
    what changes along each edge leaving it), so the picture says which way time runs.
    ``eye``: where the camera is (displayed units; it looks at the origin, +y up, as the live view's
    OrbitControls do; only its direction counts, the distance is the live view's 5); None: the
    live view's default for ``rendering`` (`camera.default_eye`: for "sections" above, right of and in
    front of the cut, so that no plane is edge-on).
    """
    # a source that wraps another is parallel slices already (the protocol's ``wraps``)
    inner = as_source(source)
    src = inner if inner.wraps is not None else None
    if src is None:
        src = StackSource(inner, slices=slices, spacing=spacing, arrangement=arrangement, color_by=color_by)
    matrix = np.eye(4) if matrix is None else matrix
    c0 = checked_real("c0", c0)
    width = checked_real("width", width, minimum=0.0, inclusive=False)
    height = checked_real("height", height, minimum=0.0, inclusive=False)
    dpi = checked_real("dpi", dpi, minimum=0.0, inclusive=False)
    face_alpha = checked_real("face_alpha", face_alpha, minimum=0.0, maximum=1.0)
    if ball_radius is not None:
        ball_radius = checked_real("ball_radius", ball_radius, minimum=0.0)
    if bar_radius is not None:
        bar_radius = checked_real("bar_radius", bar_radius, minimum=0.0)
    palette = None  # an override of the group colours: one colour, or the caller's
    if face_color is not None:
        palette = np.asarray([colours.as_rgb(face_color, "face_color")], dtype=np.float64)
    elif group_colors is not None:
        palette = np.asarray([colours.as_rgb(c, f"group_colors[{i}]") for i, c in enumerate(group_colors)],
                             dtype=np.float64).reshape(-1, 3)
    background = to_rgba(background)
    rendering = check_rendering(rendering)
    cmap, clim = colours.check_cmap(cmap), colours.check_clim(clim)
    inner = inner_source(src)
    field = inner.data_range is not None  # a field: values to colour
    volume = rendering != "surface"
    data = src.slice(matrix, c0) if _data is None else _data
    # a volume rendering's cuts, sampled once (drawn, and the box labelled); no `sample`: a TypeError here
    grids = cut_grids(src, data, matrix) if volume else None
    view = view_rotation(camera.default_eye(rendering) if eye is None else eye)
    cut = data  # the slice in the scene's coordinates (labels, grids); `data` as the camera sees it
    data = seen_from(data, view)
    n = src.slices
    scale = REFERENCE_RADIUS / src.size  # source units -> displayed units (the live view's)
    centres = np.asarray(data.centres) * scale
    scales = np.asarray(data.scales)
    cuts = np.asarray(data.cuts)
    hi = int(data.highlighted)
    group_rgb = data.group_rgb

    top = TITLE_HEIGHT if title else 0.0
    right = colorbar_width(height) if colorbar and (field or volume) else 0.0
    if _canvas is None:
        fig = LiteralTextFigure(figsize=(width + right, height + top), dpi=dpi, facecolor=background)
        # the camera's frame; the title above it, the colour bar right of it
        ax = fig.add_axes([0, 0, width / (width + right), height / (height + top)])
        ax.set_axis_off()
        ax.set_facecolor(background)
    else:  # an animation's next frame: the same figure, this frame's artists only
        fig, ax = _canvas.begin(width, height, top, dpi, background, right)
    aspect = width / height
    edge = src.source.edge_length
    base_ball = sizes.default_ball_radius(edge * scale) if edge else sizes.default_ball_radius(REFERENCE_EDGE)
    if isinstance(frame, str) and frame == "fit":
        box = frame_extent(data, src, ball_radius=(ball_radius if ball_radius is not None else base_ball)
                           if show_balls else 0.0)
    elif isinstance(frame, str) and frame == "camera":
        box = None
    else:
        box = as_box(frame)
    (x0, x1), (y0, y1) = frame_limits(box, aspect)
    notes = None  # the annotation's lines and legend, and where they go (pixels, y down)
    if annotate:
        lines, legend = annotation(src, cut, c0, theta0=_theta0, cmap=cmap, clim=clim, matrix=matrix)
        if volume:
            legend = []  # no surfaces and no slice colours: the colour bar says what a colour is
            name = inner.name or "the value"  # no level drawn: say what is
            cast_text = renderings.RENDERING_TEXT[rendering].format(name=name)
            lines = [cast_text if ln.startswith(("level ", "levels ")) else ln for ln in lines]
        if isinstance(annotate, str):
            lines = [annotate, *lines]
        notes = (lines, legend, annotation_boxes(lines, legend, height, dpi, (width * dpi, height * dpi)))
        if box is not None:  # a fitted frame: the picture moves down, out from under the text
            (x0, x1), (y0, y1) = below_notes(box, (x0, x1), (y0, y1), notes[2][0], height * dpi)
    box_text = None  # a single field's box labels: ``(labels, extent)`` of the data's extent
    if axis_labels and (field or volume) and n == 1 and callable(inner.to_data):
        extent = _slice_box(cut, data.point_offsets, data.segment_offsets)
        if extent is not None:  # the data's extent, never the padded sampling grid
            box_text = (box_labels(inner, matrix, c0, extent), extent.corners)
    if box_text is not None and box is not None:  # a fitted frame: out until every label has room
        (x0, x1), (y0, y1) = room_for_labels((x0, x1), (y0, y1), box_text, scale, small_font(height) - 0.5,
                                              height, dpi, notes[2] if notes else (), view)
    limit = 0.5 * (y1 - y0)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    if _canvas is None:
        ax.set_aspect("equal")

    poly = src.source.polytope
    offs = np.asarray(data.point_offsets)
    toff = np.asarray(data.triangle_offsets)
    soff = np.asarray(data.segment_offsets)
    # back to front by the depth of each slice's centre; zorders of slices never interleave
    jobs = []  # labels, placed after every slice is drawn
    for rank, k in enumerate(np.argsort(centres[:, 2], kind="stable")):
        z_shift = 1e3 * rank
        ball = base_ball * scales[k] if ball_radius is None else ball_radius
        bar = sizes.default_bar_radius(ball) if bar_radius is None else bar_radius
        if poly is not None:
            s = data.slices[k]
            vertices = np.asarray(s.vertices) * scales[k] + np.asarray(cut.centres[k]) if n > 1 else s.vertices
            placed = Slice(np.asarray(vertices, dtype=np.float64) @ view.T if data is not cut else vertices,
                           s.edges, s.polygon_indices, s.polygon_offsets, s.cell_ids, s.triangles, s.triangle_cells,
                           s.volume, s.dim, n_fill=s.n_fill)
            if palette is not None:
                cmap = ListedColormap(palette)
            else:
                cmap = None if group_rgb is None else ListedColormap([group_rgb[k]])
            if not show_faces:
                placed = Slice(placed.vertices, placed.edges, placed.polygon_indices[:0], placed.polygon_offsets[:1],
                               placed.cell_ids[:0], placed.triangles[:0], placed.triangle_cells[:0], placed.volume,
                               placed.dim, n_fill=placed.n_fill)
            if _canvas is not None:  # one collection per slice, in draw_slice's painter's order
                coll = slice_collection(placed, scale=scale, ball_radius=ball if show_balls else 0.0,
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
                          src.source, face_alpha, z_shift, bar_width, show_faces=show_faces and not volume,
                          cmap=cmap, clim=clim)
        if labels:
            jobs.append((centres[k], scales[k] * REFERENCE_RADIUS, data_w_text(src, float(cuts[k]), matrix), k == hi,
                         z_shift))
    # labels that would overlap one already placed are left out: the highlighted slice's first,
    # then the nearer (bigger) slices' (far, small slices of the oval crowd together)
    placed: list = []
    point = 2.0 * limit / (height * 72.0)  # data units per typographic point
    for job in sorted(jobs, key=lambda j: (not j[3], -j[1] * perspective(np.asarray(j[0])[None, :])[1][0])):
        _label_slice(ax, *job, point=point, placed=placed)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    used = None
    if volume:
        image = draw_volume(ax, src, cut, matrix, rendering, size=(round(width * dpi), round(height * dpi)),
                            cmap=cmap, clim=clim, sections=sections, grids=grids, progress=progress, view=view)
        used = image.get_clim() if image is not None else None
    if right:
        _field_colorbar(fig, inner, rendering, cmap, clim, used, width, height, top, right)
    taken = []  # what the box labels keep clear of besides the data: the annotation
    if notes is not None:
        draw_annotation(ax, notes[0], notes[1], height, _canvas)
        taken = notes[2]
    if box_text is not None:
        draw_box_labels(ax, box_text[0], scale, box_text[1], small_font(height) - 0.5, height, placed=taken,
                        view=view)
    if title:
        name = source_title(src.source)
        text = title if isinstance(title, str) else (
            f"{name}: {n} slice{'s' if n != 1 else ''} w = c0 + (k \u2212 {(n - 1) / 2:g})\u0394, "
            f"c0 = {c0:.3g}, \u0394 = {src.spacing:.3g}, {src.arrangement}")
        if _canvas is not None and _canvas.title is not None:
            _canvas.title.set_text(text)
        else:
            t = fig.text(0.5 * width / (width + right), 1.0 - 0.5 * top / (height + top), text, ha="center",
                         va="center", fontsize=9)
            if _canvas is not None:
                _canvas.title = t
        if _canvas is not None:
            _canvas.keep.add(_canvas.title)
    if _canvas is not None:
        _canvas.end()
    save_figure(fig, path)
    return fig


def _field_colorbar(fig, inner, rendering, cmap, given, used, width, height, top, right):
    """A field's colour bar in the strip right of its picture: ``cmap`` over ``used`` (the limits a
    volume rendering coloured by; None: ``given``, the caller's clim, else the field's data range),
    its levels marked in their surfaces' colours (along ``cmap``, by value over ``given`` when set,
    else by rank: `level_rgb`) for the surface rendering."""
    clim = used if used is not None else given
    if clim is None:
        lo, hi = (float(v) for v in (inner.data_range if inner.data_range is not None else (0.0, 1.0)))
        if not (np.isfinite(lo) and np.isfinite(hi)):
            lo, hi = 0.0, 1.0
        if not hi > lo:
            lo, hi = lo - 0.5, lo + 0.5
        clim = (lo, hi)
    marks = ()
    if rendering == "surface":
        rgb = level_rgb(inner, cmap, given)
        if rgb is not None:
            marks = tuple(zip(tuple(inner.levels), rgb))
    total_w, total_h = width + right, height + top
    rect = ((width + 0.12) / total_w, 0.15 * height / total_h, 0.14 / total_w, 0.7 * height / total_h)
    draw_colorbar(fig, rect, cmap, clim, value_label(inner), marks, small_font(height))


def _slice_box(data, offs, soff):
    """The bounding box of a single cut's box edges (the slice's segments) as what `box_labels`
    reads of a grid (``origin``, ``extent``), with the points they join (``corners``: the data's
    extent in slice coordinates); None when the cut is empty."""
    seg = np.asarray(data.segments[soff[0]:soff[1]])
    if not len(seg):
        return None
    pts = np.asarray(data.points[offs[0]:offs[1]], dtype=np.float64)[np.unique(seg) - offs[0]]
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    return SimpleNamespace(origin=lo, extent=tuple((float(a), float(b)) for a, b in zip(lo, hi)), corners=pts)


def _label_slice(ax, centre, radius, text, highlighted, z_shift, *, point=None, placed=None):
    """``text`` (the slice's w in the data's units, `data_w_text`: "time 0.0025 s", "(outside the
    data)" for a slice that misses it) at the upper left of a slice's projected bounding circle
    (inside its square, like a CT film's corner text), painted with its slice (nearer slices
    cover it); the highlighted slice ringed, its label bold.  With ``point`` (data units per point)
    and ``placed`` (boxes of the labels drawn so far), a label overlapping one of them is left out
    (not the highlighted one)."""
    (xy,), (f,) = perspective(np.asarray(centre, dtype=np.float64)[None, :])
    r = radius * f
    fs = max(5.0, min(9.0, 30.0 * r))
    z = Z_BASE + float(centre[2]) + z_shift + 0.5e3
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
        add_patch(ax, Circle(xy, r, facecolor="none", edgecolor="#333333", linewidth=0.8, linestyle="--",
                            zorder=z, gid="highlight-ring"))


def _triangles_class():
    """`_Triangles`, made on first use (matplotlib's collections imported lazily)."""
    # matplotlib collections: imported when a surface is first drawn
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
                  show_faces=True, cmap=colours.LEVEL_COLORMAP, clim=None):
    """Slice k of a stack of smooth surfaces: shaded triangles back to front, its bars as lines; a
    field's levels coloured along ``cmap`` (by value over ``clim`` when given: `level_rgb`)."""
    # matplotlib collections: imported when a surface is drawn
    from matplotlib.collections import LineCollection

    p0, p1 = offs[k], offs[k + 1]
    pts = np.asarray(data.points[p0:p1]) * scale
    tri = np.asarray(data.triangles[toff[k]:toff[k + 1]]) - p0
    seg = np.asarray(data.segments[soff[k]:soff[k + 1]]) - p0
    if not len(pts):
        return
    xy, _ = perspective(pts)
    z_base = Z_BASE + float(pts[:, 2].mean()) + z_shift
    if len(tri) and show_faces:
        groups = np.asarray(data.groups[toff[k]:toff[k + 1]])
        if group_rgb is not None:
            pal = np.asarray(group_rgb, dtype=np.float64)
            rgb = pal[np.minimum(groups, len(pal) - 1)] if len(pal) == 1 else pal[groups]
        else:
            level_colours = level_rgb(inner, cmap, clim)
            if level_colours is not None:
                rgb = level_colours[groups]
            else:
                rgb = colours.group_palette(int(groups.max()) + 1)[groups].astype(np.float64)
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
        alpha = 1.0 if len(inner.levels or ()) <= 1 else max(face_alpha, colours.SURFACE_OPACITY)
        coll = _Triangles(xy[tri[order]], np.column_stack([rgb[order], np.full(len(order), alpha)]),
                          zorder=z_base, gid="surface")
        ax.add_collection(coll, autolim=False)
    if len(seg) and bar_width > 0:
        lines = LineCollection(xy[seg], colors=colours.BAR_COLOR, linewidths=max(0.3, 72 * bar_width),
                               zorder=z_base + 1e-3, gid="bar")
        ax.add_collection(lines, autolim=False)


# --------------------------------------------------------------------------- the live view's picture
def state_source(source, *, levels=None, slices=None, spacing=None, arrangement=None, inside=None, caps=None):
    """``source`` (a name, a Polytope or any source) with a widget's source settings applied, as a
    `StackSource` (N = 1 is today's single slice, point for point).  The source given is not
    changed: a field whose ``levels`` differ is copied (shallowly, sharing its array), a stack is
    rebuilt around its inner source.  What a source is and has is read through the source
    protocol (``wraps``, ``settings``, ``apply_setting``), never from its class."""
    src = as_source(source)
    inner, color_by, n, spc, arr = src, "w", 1, None, "oval"
    if src.wraps is not None:
        own = settings_of(src)
        inner, color_by = src.wraps, src.color_by
        n, spc, arr = own.get("slices", n), own.get("spacing", spc), own.get("arrangement", arr)
    if slices is not None:
        n = slices
    if spacing is not None:
        spc = spacing
    if arrangement is not None:
        arr = arrangement
    have = settings_of(inner)
    if levels is not None:
        if "levels" not in have:
            raise TypeError(f"`levels` applies to sources with iso levels (a Field4D), not {class_name(inner)}")
        wanted = tuple(np.atleast_1d(np.asarray(levels, dtype=np.float64)).tolist())
        if wanted != tuple(have["levels"]):
            inner = copy.copy(inner)
            apply_setting(inner, "levels", wanted)
    for name, value in (("inside", inside), ("caps", caps)):  # a field's other settings, likewise
        if value is not None and have.get(name, value) != value:
            inner = copy.copy(inner)
            apply_setting(inner, name, value)
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
    face_opacity: float = colours.FACE_OPACITY,
    ball_radius: float | None = None,
    bar_radius: float | None = None,
    background=colours.BACKGROUND,
    show_balls: bool = True,
    show_bars: bool = True,
    show_faces: bool = True,
    size=(600, 500),
    dpi: float = 100,
    labels=None,
    title: str | None = None,
    frame="fit",
    annotate=False,
    rendering: str = "surface",
    cmap="viridis",
    clim=None,
    sections=DEFAULT_SECTIONS,
    projection: bool = False,
    colorbar: bool = True,
    axis_labels: bool = True,
    progress=True,
    eye=None,
    _prepared=None,
    _canvas=None,
) -> Figure:
    """The picture the widget shows for ``state`` and ``source``, without a browser.

    ``state`` is a `RotationState` (its matrix and c0 are used); ``source`` a polytope name, a
    Polytope, a `Field4D`, a `StackSource` or any source.  The keywords are the widget's
    settings, by the names of its traits (`rot4d_widget.keep.statefile.save_state` stores them so):
    ``levels`` (a field's iso levels), ``slices``, ``spacing``, ``arrangement`` (parallel
    slices: `state_source`), ``color_by`` (``"group"`` or one colour), ``group_colors``,
    ``face_opacity``, ``ball_radius`` / ``bar_radius`` (displayed units; default as the widget
    chooses them: from the polytope's edge, the same for every slice), ``background``,
    ``show_balls`` / ``show_bars`` / ``show_faces``.

    The scene is the live view's: every source scaled to the displayed circumradius
    `sizes.REFERENCE_RADIUS`, the eye at `camera.CAMERA_POSITION` looking down -z (``eye``: elsewhere,
    looking at the origin; None: `camera.default_eye` of ``rendering``, the live view's default camera
    -- for "sections" an oblique one) with the vertical
    field of view `camera.CAMERA_FOV` and the aspect of ``size`` (pixels, width x height; the
    widget's canvas is 600 x 500), the cell palette `colours.group_palette` (a field's levels:
    `colours.level_colors`; a stack coloured by w: a colormap over its cuts).  It does not follow a
    camera the user dragged.  ``labels`` writes each parallel slice's w in the data's units (None, the
    default: when there are several, so every slice of the view carries its time); ``title`` goes above.

    ``frame="fit"`` (the default) keeps that eye and perspective but zooms so that the projected
    bounding box of what is drawn fills `FIT_FILL` (90 %) of the picture's width or height;
    ``frame="camera"`` is the live view's frame exactly (an object there fills about a third of
    the picture); a box ``(x0, x1, y0, y1)`` in the picture plane is fitted like "fit" (see
    `render_tomography`).  ``annotate``: True writes θ0, c0 and what the source tells of itself
    (`annotation`: name, units, levels, w span, a stack's w) in the upper left corner and a
    legend of the levels' or slices' colours in the lower left; a string is written first.
    ``rendering`` (a field's): ``"surface"`` (the default: the isosurfaces, coloured along ``cmap``,
    by value over ``clim`` when given), ``"mip"`` (maximum intensity projection), ``"volume"``
    (emission-absorption with a transfer function: colour ``cmap``, opacity rising linearly over
    ``clim``) or ``"sections"`` (three orthogonal colour-mapped planes at ``sections`` = (fx, fy,
    fz), fractions of the cut's extent), ray-cast in numpy through the cut sampled on a grid
    (`rot4d_widget.keep.pictures.ray_caster`; the box's edges drawn over it; ``progress``: a bar when that
    takes more than a second).  ``cmap``: a matplotlib colour map name; ``clim``: (lo, hi),
    default the 1st-99th percentile of the finite values of the cut (of all the cuts of a stack):
    robust to a few outliers.  ``colorbar``: a field's colour bar right of the picture (the
    variable's name and units, the levels marked); ``axis_labels``: a single cut's box labelled
    with its data coordinates (`render_tomography`).  ``projection`` (the widget's trait, kept in
    state files) is taken and ignored: the figure draws the slice view.
    Saved to ``path`` (.png, .svg or .pdf) if given, at ``dpi``: a PNG is ``size`` pixels, plus the
    title's strip above when ``title`` is given and, for a field, the colour bar's strip right of
    it (`colorbar_width`; the picture's own pixels are where they would be without it).
    Returns the Figure.
    """
    rendering = check_rendering(rendering)
    cmap, clim, sections = colours.check_cmap(cmap), colours.check_clim(clim), renderings.check_sections(sections)
    if not isinstance(state, RotationState):
        raise TypeError(f"Expected `state` to be a rot4d_widget.RotationState, got {type(state).__name__}")
    try:
        w_px, h_px = (float(v) for v in size)
    except (TypeError, ValueError):
        raise TypeError(f"Expected `size` to be (width, height) in pixels, got {size!r}") from None
    w_px = checked_real("size[0]", w_px, minimum=1.0)
    h_px = checked_real("size[1]", h_px, minimum=1.0)
    dpi = checked_real("dpi", dpi, minimum=0.0, inclusive=False)
    if title is not None and not isinstance(title, str):
        raise TypeError(f"Expected `title` to be a string or None, got {type(title).__name__}")
    face_color = None
    if color_by != "group":
        face_color = colours.as_rgb(color_by, "color_by")
    if _prepared is None:
        _prepared = prepare_render(state, source, levels=levels, slices=slices, spacing=spacing,
                                   arrangement=arrangement, ball_radius=ball_radius, show_balls=show_balls,
                                   inside=inside, caps=caps, rendering=rendering, eye=eye)
    stack, data, ball_radius, box = _prepared
    if isinstance(frame, str) and frame == "fit":
        frame = "camera" if box is None else box
    return render_tomography(
        stack, state.matrix, state.c0, path=path, width=w_px / dpi, height=h_px / dpi,
        dpi=dpi, title=title if title else None, labels=stack.slices > 1 if labels is None else labels,
        face_alpha=face_opacity, ball_radius=ball_radius,
        bar_radius=bar_radius, show_balls=show_balls, show_bars=show_bars, show_faces=show_faces,
        face_color=face_color, group_colors=group_colors, background=background, frame=frame,
        annotate=annotate, rendering=rendering, cmap=cmap, clim=clim, sections=sections, colorbar=colorbar,
        axis_labels=axis_labels, progress=progress, eye=eye, _data=data, _theta0=state.theta0, _canvas=_canvas,
    )


def prepare_render(state, source, *, levels=None, slices=None, spacing=None, arrangement=None, ball_radius=None,
                   show_balls=True, data=None, inside=None, caps=None, rendering="surface", eye=None, **_ignored):
    """What `render_state` draws before drawing it: ``(stack, data, ball_radius, box)`` -- the
    source with the settings applied (`state_source`), its slice at ``state``, the ball radius
    in displayed units (None: the stack's default) and the projected bounding box of the
    drawing (`frame_extent`; None when empty).  ``data``: the slice, computed before.  An
    animation takes the boxes of all its frames first to frame them alike, and draws each frame
    from the slice computed then.  ``rendering`` and ``eye``: where the camera is (`render_state`'s:
    the box as it sees the slice)."""
    stack = state_source(source, levels=levels, slices=slices, spacing=spacing, arrangement=arrangement,
                         inside=inside, caps=caps)
    note_matrix(stack, state.matrix)  # a default spacing not spread yet: along this picture's w
    if ball_radius is None:
        edge = stack.edge_length
        if edge:
            ball_radius = sizes.default_ball_radius(edge * REFERENCE_RADIUS / stack.size)
    if data is None:
        data = stack.slice(state.matrix, state.c0)
    if show_balls:
        ball = ball_radius if ball_radius is not None else sizes.default_ball_radius(REFERENCE_EDGE)
    else:
        ball = 0.0
    seen = seen_from(data, view_rotation(camera.default_eye(rendering) if eye is None else eye))
    return stack, data, ball_radius, frame_extent(seen, stack, ball_radius=ball)
