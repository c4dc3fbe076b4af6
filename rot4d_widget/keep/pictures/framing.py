"""Where a rendered picture looks and what it says: the fitted frame and the annotation.

`frame_extent` / `union_extent`: the projected bounding box of a slice (or of an animation's
frames) that ``frame="fit"`` fills `FIT_FILL` of the picture with; `annotation`: the corner text
and legend of a picture.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ...core import colours
from ...core.sizes import REFERENCE_RADIUS
from ...sources.field_labels import axis_names
from ...sources.protocol import c0_text, inner_source
from ...sources.tomography import StackSliceData
from .slice_drawing import CAMERA_DISTANCE, CAMERA_FOV, Z_LABEL, perspective

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


def as_box(frame):
    try:
        box = tuple(float(v) for v in frame)
    except (TypeError, ValueError):
        box = ()
    if len(box) != 4 or not all(math.isfinite(v) for v in box) or box[1] < box[0] or box[3] < box[2]:
        raise ValueError(f"Expected `frame` to be 'camera', 'fit' or a box (x0, x1, y0, y1) with x0 <= x1 and "
                         f"y0 <= y1, got {frame!r}")
    return box


def frame_limits(box, aspect: float):
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


def _level_colors(levels, lo, hi, cmap: str = colours.LEVEL_COLORMAP, by_value: bool = False) -> np.ndarray:
    """`colours.level_colors` (read-only), kept for the levels, range, map and rule it was asked for:
    it copies the colormap and builds its table on every call, twice an animation's frame."""
    try:
        key = (tuple(float(v) for v in levels), lo, hi, cmap, bool(by_value))
        hash(key)
    except TypeError:  # nothing to key it by: as colours computes it
        return colours.level_colors(levels, lo, hi, cmap, by_value=by_value)
    return _level_colors_kept(*key)


@functools.lru_cache(maxsize=64)
def _level_colors_kept(levels: tuple, lo: float, hi: float, cmap: str, by_value: bool) -> np.ndarray:
    rgb = colours.level_colors(levels, lo, hi, cmap, by_value=by_value)
    rgb.flags.writeable = False
    return rgb


def level_rgb(inner, cmap: str = colours.LEVEL_COLORMAP, clim=None):
    """(n, 3) colours of ``inner``'s iso ``levels`` along ``cmap`` (None without levels): the live
    view's rule (`rot4d_widget.view.painter.level_colors`) -- ``clim`` None: spread by rank over the
    map (the data's range orders them), else each at its value over ``clim``."""
    levels = tuple(inner.levels or ())
    if not levels:
        return None
    if clim is not None:
        return _level_colors(levels, float(clim[0]), float(clim[1]), cmap, True)
    lo, hi = inner.data_range if inner.data_range is not None else (min(levels), max(levels))
    return _level_colors(levels, lo, hi, cmap)


def annotation(source, data, c0: float, *, theta0: float | None = None, cmap: str = colours.LEVEL_COLORMAP,
               clim=None, matrix=None):
    """``(lines, legend)`` describing slice ``data`` of ``source`` (a `StackSource`) at ``c0``:
    ``lines`` of text (θ0 when given and c0; the inner source's ``name`` and ``units``; its
    ``levels``; the w span of the slice from its ``readout`` row "w cut" (in ``w_units``); a
    polytope slice's census, its readout row "slice"; a stack's slices' w, from ``cuts_at``)
    -- with ``matrix``, how far the cut is turned from the data's own w, `turn_text` --
    and ``legend``, ``[(rgb, label), ...]``: the colours of a field's levels (along ``cmap``, by
    value over ``clim`` when given: `level_rgb`) or of a stack's slices.  Only attributes the
    sources have are read, never their class."""
    inner = inner_source(source)
    lines = []
    wu = inner.w_units
    wu = f" {wu}" if wu else ""  # c0 and the slices' w are in the source's w units (a field's time)
    state = c0_text(inner, c0) or f"c0 = {float(c0):+.4g}{wu}"
    lines.append(state if theta0 is None else f"\u03b80 = {_fmt_angle(float(theta0))}, {state}")
    if matrix is not None:
        lines.append(turn_text(matrix, axis_names(inner)))
    name, units = inner.name, inner.units
    u = f" {units}" if units else ""
    if name:
        lines.append(f"{name}" + (f" [{units}]" if units else ""))
    levels = tuple(inner.levels or ())
    if levels:
        lines.append(("level " if len(levels) == 1 else "levels ") + ", ".join(f"{v:.4g}" for v in levels) + u)
    rows = dict(tuple(r) for r in (data.readout or ()) if len(r) == 2)
    if "w cut" in rows:
        lines.append(f"w cut {rows['w cut']}")
    elif "slice" in rows:
        lines.append(str(rows["slice"]))
    n = int(source.slices or 1)
    ws = np.asarray(source.cuts_at(c0)) if n > 1 and source.cuts_at is not None else np.zeros(0)
    if len(ws):
        spacing = source.spacing  # in the source's w units, as c0 (issue 37)
        lines.append(f"{n} slices w = {ws[0]:+.4g} \u2026 {ws[-1]:+.4g}{wu}"
                     + (f", \u0394 = {spacing:.3g}{wu}" if spacing else ""))
    legend = []
    group_rgb = data.group_rgb if isinstance(data, StackSliceData) else None
    if len(ws) and group_rgb is not None:
        picks = range(n) if n <= 8 else sorted({0, n // 4, n // 2, (3 * n) // 4, n - 1})
        legend = [(tuple(np.asarray(group_rgb[k], dtype=float)[:3]), f"w = {ws[k]:+.4g}{wu}") for k in picks]
    elif levels:
        rgb = level_rgb(inner, cmap, clim)
        legend = [(tuple(rgb[k]), f"{v:.4g}{u}") for k, v in enumerate(levels)]
    return lines, legend


def turn_text(matrix, names=("x", "y", "z", "w")) -> str:
    """How far the cut w = c0 is turned from the data's own w ("time") after ``matrix`` (4, 4), and
    towards which axes: the angle between its normal, row 3 of ``matrix`` in the data's axes, and
    the w axis -- "turn 22.5° in the x–time plane", "turn 30° from constant time towards 0.8 x +
    0.6 y", or "turn none (the cut is at constant time)".  ``names``: the data's x, y, z, w names.

    >>> turn_text(np.eye(4), ("x", "y", "z", "time"))
    'turn none (the cut is at constant time)'
    """
    n = np.asarray(matrix, dtype=np.float64).reshape(4, 4)[3]
    tilt = math.degrees(math.acos(min(1.0, abs(float(n[3])))))
    w = names[3]
    if tilt < 1e-3:
        return f"turn none (the cut is at constant {w})"
    space = n[:3] * (1.0 if n[3] >= 0 else -1.0)
    size = float(np.linalg.norm(space))
    parts = [(abs(v) / size, names[a], v < 0) for a, v in enumerate(space) if abs(v) > 1e-6 * size]
    if len(parts) == 1:
        return f"turn {tilt:.3g}\u00b0 in the {parts[0][1]}\u2013{w} plane"
    towards = " + ".join(("\u2212" if neg else "") + f"{c:.2g} {name}" for c, name, neg in parts)
    return f"turn {tilt:.3g}\u00b0 from constant {w} towards {towards}"


def annotation_boxes(lines, legend, height: float, dpi: float, size_px) -> list:
    """Where `draw_annotation` puts its text and legend in a picture of ``size_px`` (width,
    height) pixels ``height`` inches high: ``[(left, top, w, h), ...]`` in pixels, y down (what the
    box labels keep clear of), from the text's measured size; generous by a few pixels."""
    fs = max(6.0, min(10.0, 1.7 * height))
    px = dpi / 72.0
    out = []
    if lines:
        w, h = text_size("\n".join(lines), fs)
        out.append((0.015 * size_px[0] - 2 * px, 0.015 * size_px[1] - 2 * px, (w + 6) * px, (h + 6) * px))
    if legend:
        w = max(text_size(label, fs)[0] for _, label in legend) + 2.6 * fs
        h = len(legend) * 1.5 * fs + 1.2 * fs
        out.append((0.0, size_px[1] - (h + 0.6 * fs) * px, (w + 0.9 * fs) * px, (h + 0.6 * fs) * px))
    return out


def draw_annotation(ax, lines, legend, height: float, canvas=None) -> None:
    """``lines`` in the upper left corner, ``legend`` swatches in the lower left (gid "annotation").
    With a `FrameCanvas`, the previous frame's text is given the new lines and its legend is
    kept when the swatches are the same."""
    # matplotlib patches: imported when a legend is drawn
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
                       zorder=Z_LABEL, gid="annotation", bbox=box)
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
        leg.set_zorder(Z_LABEL)
        leg.set_gid("legend")
        if canvas is not None:
            canvas.as_picture(leg)


# --------------------------------------------------------------------------- stacks of slices


# --------------------------------------------------------------------------- a field's colour bar and box labels
def small_font(height: float) -> float:
    """Font size (points) of a field's colour bar and box labels in a picture ``height`` inches high."""
    return max(5.5, min(8.0, 1.4 * float(height)))


def colorbar_width(height: float) -> float:
    """Inches of the strip right of a field's picture (``height`` inches high) that holds its colour
    bar: the bar, its tick labels and the variable's name, at `small_font`."""
    return 0.25 + 6.0 * small_font(height) / 72.0


def value_label(inner) -> str:
    """The colour bar's title: the variable's ``long_name`` (xarray's attribute, when the source
    keeps it), else its ``name``, else "value", with its ``units`` in brackets."""
    name = inner.long_name or inner.name or "value"
    units = inner.units
    return f"{name} [{units}]" if units else str(name)


def draw_colorbar(fig, rect, cmap: str, clim, label: str, marks=(), fontsize: float = 8.0):
    """A colour bar in a new axes at ``rect`` (figure fraction): ``cmap``'s gradient from
    ``clim[0]`` (bottom) to ``clim[1]`` (top), ticks on its right in the data's values, ``label``
    beside them, and each of ``marks`` -- ``(value, rgb)``, an iso level in its surface's colour --
    a line across the bar at its value with a triangle on its left (levels outside ``clim`` are
    not marked).  Returns the axes (gid "colorbar")."""
    lo, hi = (float(v) for v in clim)
    cax = fig.add_axes(rect)
    cax.set_gid("colorbar")
    cax.imshow(np.linspace(0.0, 1.0, 256)[:, None], cmap=cmap, vmin=0.0, vmax=1.0, aspect="auto",
               extent=(0.0, 1.0, lo, hi), origin="lower", interpolation="bilinear")
    cax.set_xlim(0.0, 1.0)
    cax.set_ylim(lo, hi)
    cax.set_xticks([])
    cax.yaxis.tick_right()
    cax.yaxis.set_label_position("right")
    cax.tick_params(axis="y", labelsize=fontsize, length=2.0, pad=1.5)
    cax.set_ylabel(label, fontsize=fontsize, labelpad=2.0)
    for spine in cax.spines.values():
        spine.set_linewidth(0.5)
    for value, rgb in marks:
        if lo <= float(value) <= hi:
            cax.axhline(float(value), color="#222222", linewidth=0.8, gid="level-mark")
            cax.plot([-0.12], [float(value)], marker=">", markersize=0.9 * fontsize, color=tuple(rgb),
                     markeredgecolor="#222222", markeredgewidth=0.5, clip_on=False, gid="level-mark")
    return cax


#: Labels are placed this many pixels from the extent they keep clear of (the page's LABEL_GAP).
LABEL_GAP = 4.0
_STEPS = (0, 1, -1, 2, -2, 3, -3, 4, -4)
_OUTWARD = (0, 1, 2, 3, 4, 5, 6, 7, 8)


def _overlaps(a, b) -> bool:
    return a[0] < b[0] + b[2] and b[0] < a[0] + a[2] and a[1] < b[1] + b[3] and b[1] < a[1] + a[3]


def _label_candidates(x, y, w, h, kind, keep, width, height, gap):
    def clamp(v, lo, hi):
        return max(lo, min(hi, v))

    out = []
    if kind == "slice" or keep is None:
        return [(clamp(x - w / 2, 0, width - w), y + gap + k * (h + 1)) for k in _OUTWARD]
    x0, y0, x1, y1 = keep
    dist = {"left": x - x0, "right": x1 - x, "top": y - y0, "bottom": y1 - y}
    for side in sorted(("left", "right", "top", "bottom"), key=lambda s: dist[s]):  # stable: ties in this order
        if side in ("left", "right"):
            left = min(x0, x) - gap - w if side == "left" else max(x1, x) + gap
            out += [(left, clamp(y - h / 2 + k * (h + 1), 0, height - h)) for k in _STEPS]
        else:
            left = clamp(x - w / 2, 0, width - w)
            out += [(left, min(y0, y) - gap - h - k * (h + 1) if side == "top" else max(y1, y) + gap + k * (h + 1))
                    for k in _OUTWARD]
    return out


def place_labels(items, keep, width: float, height: float, gap: float = LABEL_GAP, placed=()) -> list:
    """Where each label goes, in pixels of a picture ``width`` x ``height`` (y down): ``items``
    ``[(x, y, w, h, kind), ...]`` -- a label's point and its box's size, placed in that order --
    ``keep`` the rectangle ``(x0, y0, x1, y1)`` the data's extent projects into (or None);
    ``placed``: boxes ``(left, top, w, h)`` already taken (an annotation).  Returns ``[(left, top,
    free), ...]``, free False where no place was free (the first place tried, clamped).

    The page's rule (``page/labels.js`` ``placeLabels``, the same places in the same order): a box
    label ("corner", "edge") goes outside ``keep`` on the side nearest its point, level with the
    point on the left or right (moved a line at a time, down and up alternately) or above or
    below it (moved outward a row at a time) until it overlaps no box placed before it, inside the
    picture; the next side when none of 9 places is free.  A "slice" label is centred under its
    point, moved down past the boxes placed before it."""
    taken = [tuple(float(v) for v in b) for b in placed]
    keep_box = None if keep is None else (keep[0], keep[1], keep[2] - keep[0], keep[3] - keep[1])
    out = []
    for x, y, w, h, kind in items:
        tries = _label_candidates(float(x), float(y), float(w), float(h), kind, keep, width, height, gap)
        found = None
        for left, top in tries:
            box = (left, top, w, h)
            if left < 0 or top < 0 or left + w > width or top + h > height:
                continue
            if keep_box is not None and kind != "slice" and _overlaps(box, keep_box):
                continue
            if any(_overlaps(box, b) for b in taken):
                continue
            found = (left, top, True)
            break
        if found is None:
            left, top = tries[0]
            found = (max(0.0, min(width - w, left)), max(0.0, min(height - h, top)), False)
        taken.append((found[0], found[1], w, h))
        out.append(found)
    return out


def text_size(text: str, fontsize: float, linespacing: float = 1.2) -> tuple:
    """(width, height) in points of ``text`` (lines split at newlines) at ``fontsize``, drawn
    literally (no mathtext): the widest line's advance, and the lines at ``linespacing``."""
    # matplotlib's text layout: imported when a label is placed
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import text_to_path

    prop = FontProperties(size=fontsize)
    lines = text.split("\n")
    width = max(text_to_path.get_text_width_height_descent(s, prop, ismath=False)[0] for s in lines)
    return width, fontsize * (1.0 + linespacing * (len(lines) - 1)) * 1.25


def box_label_layout(xlim, ylim, labels, scale: float, extent, fontsize: float, height: float, dpi: float,
                     placed=(), view=None):
    """Where `draw_box_labels` puts ``labels`` in axes with limits ``xlim``, ``ylim`` (a picture
    ``height`` inches high at ``dpi``): ``(xy, shown, items, boxes)`` -- the projected label points,
    the ``((u, v) pixel point, text)`` of each label drawn, their `place_labels` items and places
    (``free`` False where none was free).  Nothing is drawn: `render_tomography` zooms a fitted
    frame out until every label is free."""
    view = np.eye(3) if view is None else np.asarray(view, dtype=np.float64).reshape(3, 3)
    pts = np.asarray([p for p, _ in labels], dtype=np.float64).reshape(-1, 3) @ view.T * float(scale)
    xy, _ = perspective(pts)
    (x0, x1), (y0, y1) = xlim, ylim
    hpx = float(height) * float(dpi)
    wpx = hpx * (x1 - x0) / (y1 - y0)
    px = float(dpi) / 72.0  # pixels per point

    def to_px(p):
        p = np.asarray(p, dtype=np.float64).reshape(-1, 2)
        return np.column_stack([(p[:, 0] - x0) / (x1 - x0) * wpx, (y1 - p[:, 1]) / (y1 - y0) * hpx])

    ext = np.asarray(extent, dtype=np.float64).reshape(-1, 3) @ view.T * float(scale)
    keep = None
    if len(ext):
        e = to_px(perspective(ext)[0])
        keep = (float(e[:, 0].min()), float(e[:, 1].min()), float(e[:, 0].max()), float(e[:, 1].max()))
    shown = [(p, "\n".join(text.split(", "))) for p, (_, text) in zip(to_px(xy), labels) if text]
    items = []
    for _p, text in shown:
        w, h = text_size(text, fontsize, 1.1)
        items.append((_p[0], _p[1], (w + 2 * _LABEL_PAD) * px + 1, (h + 2 * _LABEL_PAD) * px + 1, "edge"))
    return xy, shown, items, place_labels(items, keep, wpx, hpx, LABEL_GAP, placed)


_LABEL_PAD = 1.0  # a box label's text box, points


def draw_box_labels(ax, labels, scale: float, extent, fontsize: float = 7.0, height: float = 5.0,
                    placed=(), view=None) -> list:
    """``labels`` (`rot4d_widget.sources.field_labels.box_labels`: the origin corner first, then the
    far ends of the three edges leaving it, in slice coordinates) drawn at the points placed at
    ``scale * p`` and projected: the three edges as thin dashed lines (what the texts label), each
    text small, one data coordinate a line, outside the rectangle the data's ``extent`` (its
    corners, slice coordinates) projects into, so that no label covers the picture
    (`place_labels`, the page's rule; `box_label_layout`), with a dotted line from its point when
    moved away from it (``height``: the axes' height in inches; ``placed``: boxes in axes pixels
    already taken, y down; ``view``: the camera's rotation, None the identity).  Returns the Text
    artists (gid "box-label")."""
    # matplotlib collections: imported when a field's box is labelled
    from matplotlib.collections import LineCollection

    if not labels:
        return []
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    dpi = float(ax.figure.dpi)
    xy, shown, items, boxes = box_label_layout((x0, x1), (y0, y1), labels, scale, extent, fontsize, height, dpi,
                                               placed, view)
    edges = LineCollection([[xy[0], xy[k]] for k in range(1, len(xy))], colors="#777777", linewidths=0.6,
                           linestyles=(0, (3, 2)), zorder=Z_LABEL - 2.0, gid="box-edge")
    ax.add_collection(edges, autolim=False)
    hpx = float(height) * dpi
    wpx = hpx * (x1 - x0) / (y1 - y0)
    px = dpi / 72.0

    def to_data(u, v):
        return x0 + u / wpx * (x1 - x0), y1 - v / hpx * (y1 - y0)

    out, leaders = [], []
    box = dict(facecolor="white", alpha=0.7, edgecolor="none", pad=_LABEL_PAD)
    for ((u, v), text), (left, top, _free), item in zip(shown, boxes, items):
        tx, ty = to_data(left + _LABEL_PAD * px, top + _LABEL_PAD * px)
        out.append(ax.text(tx, ty, text, ha="left", va="top", fontsize=fontsize, color="#333333",
                           zorder=Z_LABEL - 1.0, gid="box-label", bbox=box, linespacing=1.1))
        nu, nv = min(max(u, left), left + item[2]), min(max(v, top), top + item[3])
        if math.hypot(nu - u, nv - v) > 3.0:
            leaders.append([to_data(u, v), to_data(nu, nv)])
    if leaders:
        ax.add_collection(LineCollection(leaders, colors="#777777", linewidths=0.5, linestyles=(0, (1.5, 1.5)),
                                         zorder=Z_LABEL - 2.0, gid="label-leader"), autolim=False)
    return out


# --------------------------------------------------------------------------- where the camera looks from
def seen_from(data, view):
    """``data`` (a stack's slice) as the camera whose rotation is ``view`` (3, 3) sees it: every
    point, normal and slice centre turned by it about the origin (the whole scene, as an orbit of
    the live view's camera turns it); ``data`` itself for the identity."""
    view = np.asarray(view, dtype=np.float64).reshape(3, 3)
    if np.array_equal(view, np.eye(3)):
        return data
    normals = None if data.normals is None else np.asarray(data.normals) @ view.T
    return data.replaced(points=np.asarray(data.points) @ view.T, normals=normals,
                         centres=np.asarray(data.centres, dtype=np.float64) @ view.T)


#: A fitted frame with box labels grows by this factor at a time until every label has room.
_LABEL_ZOOM = 1.08


def room_for_labels(xlim, ylim, box_text, scale, fontsize, height, dpi, placed, view):
    """The limits of a fitted frame grown about their middle (`_LABEL_ZOOM` at a time, at most 12
    times) until every box label has a free place outside the data (`box_label_layout`): a small
    picture shows its data smaller rather than labels over it."""
    labels, extent = box_text
    (x0, x1), (y0, y1) = xlim, ylim
    for _ in range(12):
        boxes = box_label_layout((x0, x1), (y0, y1), labels, scale, extent, fontsize, height, dpi, placed, view)[3]
        if all(free for _l, _t, free in boxes):
            break
        cx, cy, hx, hy = 0.5 * (x0 + x1), 0.5 * (y0 + y1), 0.5 * (x1 - x0) * _LABEL_ZOOM, 0.5 * (y1 - y0) * _LABEL_ZOOM
        (x0, x1), (y0, y1) = (cx - hx, cx + hx), (cy - hy, cy + hy)
    return (x0, x1), (y0, y1)


def below_notes(box, xlim, ylim, note, height_px):
    """The limits ``xlim``, ``ylim`` of a fitted frame grown (about the box's bottom, keeping the
    aspect) until the top of ``box`` (x0, x1, y0, y1: what is drawn) lies below the annotation's
    text box ``note`` (left, top, w, h in pixels of a picture ``height_px`` high, y down), so the
    text covers none of the picture."""
    (x0, x1), (y0, y1) = xlim, ylim
    need = (note[1] + note[3]) / height_px  # of the picture's height, from its top
    top_room = (y1 - box[3]) / (y1 - y0)
    if top_room >= need:
        return xlim, ylim
    # keep the box's bottom margin; grow the height h so that (y1 - box top) = need * h
    below = box[2] - y0
    h = (box[3] - box[2] + below) / (1.0 - need)
    cx, aspect = 0.5 * (x0 + x1), (x1 - x0) / (y1 - y0)
    return (cx - 0.5 * h * aspect, cx + 0.5 * h * aspect), (box[2] - below, box[2] - below + h)
