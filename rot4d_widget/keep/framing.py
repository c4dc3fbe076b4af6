"""Where a rendered picture looks and what it says: the fitted frame and the annotation.

`frame_extent` / `union_extent`: the projected bounding box of a slice (or of an animation's
frames) that ``frame="fit"`` fills `FIT_FILL` of the picture with; `annotation`: the corner text
and legend of a picture.  Part of `rot4d_widget.keep.figures`, which re-exports every public name.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ..core import look
from ..core.look import REFERENCE_RADIUS
from ..sources.protocol import w_frame
from .drawing import _Z_LABEL, CAMERA_DISTANCE, CAMERA_FOV, perspective

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


def _level_colors(levels, lo, hi, cmap: str = look.LEVEL_COLORMAP, by_value: bool = False) -> np.ndarray:
    """`look.level_colors` (read-only), kept for the levels, range, map and rule it was asked for:
    it copies the colormap and builds its table on every call, twice an animation's frame."""
    try:
        key = (tuple(float(v) for v in levels), lo, hi, cmap, bool(by_value))
        hash(key)
    except TypeError:  # nothing to key it by: as look computes it
        return look.level_colors(levels, lo, hi, cmap, by_value=by_value)
    return _level_colors_kept(*key)


@functools.lru_cache(maxsize=64)
def _level_colors_kept(levels: tuple, lo: float, hi: float, cmap: str, by_value: bool) -> np.ndarray:
    rgb = look.level_colors(levels, lo, hi, cmap, by_value=by_value)
    rgb.flags.writeable = False
    return rgb


def level_rgb(inner, cmap: str = look.LEVEL_COLORMAP, clim=None):
    """(n, 3) colours of ``inner``'s iso ``levels`` along ``cmap`` (None without levels): the live
    view's rule (`rot4d_widget.view.painter.level_colors`) -- ``clim`` None: spread by rank over the
    map (the data's range orders them), else each at its value over ``clim``."""
    levels = tuple(getattr(inner, "levels", ()) or ())
    if not levels:
        return None
    if clim is not None:
        return _level_colors(levels, float(clim[0]), float(clim[1]), cmap, True)
    lo, hi = getattr(inner, "data_range", (min(levels), max(levels)))
    return _level_colors(levels, lo, hi, cmap)


def annotation(source, data, c0: float, *, theta0: float | None = None, cmap: str = look.LEVEL_COLORMAP,
               clim=None):
    """``(lines, legend)`` describing slice ``data`` of ``source`` (a `StackSource`) at ``c0``:
    ``lines`` of text (θ0 when given and c0; the inner source's ``name`` and ``units``; its
    ``levels``; the w span of the slice from its ``readout`` row "w cut" (in ``w_units``); a
    polytope slice's census, its readout row "slice"; a stack's slices' w, from ``cuts_at``)
    and ``legend``, ``[(rgb, label), ...]``: the colours of a field's levels (along ``cmap``, by
    value over ``clim`` when given: `level_rgb`) or of a stack's slices.  Only attributes the
    sources have are read, never their class."""
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
    ws = np.asarray(source.cuts_at(c0)) if n > 1 and hasattr(source, "cuts_at") else np.zeros(0)
    if len(ws):
        spacing = getattr(source, "spacing", None)
        per = w_frame(source)[1]  # the protocol's reader: a stack answers for its inner source
        lines.append(f"{n} slices w = {ws[0]:+.4g} \u2026 {ws[-1]:+.4g}{wu}"
                     + (f", \u0394 = {spacing * per:.3g}{wu}" if spacing else ""))
    legend = []
    group_rgb = (getattr(data, "extra", None) or {}).get("group_rgb")
    if len(ws) and group_rgb is not None:
        picks = range(n) if n <= 8 else sorted({0, n // 4, n // 2, (3 * n) // 4, n - 1})
        legend = [(tuple(np.asarray(group_rgb[k], dtype=float)[:3]), f"w = {ws[k]:+.4g}{wu}") for k in picks]
    elif levels:
        rgb = level_rgb(inner, cmap, clim)
        legend = [(tuple(rgb[k]), f"{v:.4g}{u}") for k, v in enumerate(levels)]
    return lines, legend


def _draw_annotation(ax, lines, legend, height: float, canvas=None) -> None:
    """``lines`` in the upper left corner, ``legend`` swatches in the lower left (gid "annotation").
    With a `_FrameCanvas`, the previous frame's text is given the new lines and its legend is
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
    name = getattr(inner, "long_name", None) or getattr(inner, "name", None) or "value"
    units = getattr(inner, "units", None)
    return f"{name} [{units}]" if units else str(name)


def _draw_colorbar(fig, rect, cmap: str, clim, label: str, marks=(), fontsize: float = 8.0):
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


def _draw_box_labels(ax, labels, scale: float, centre, fontsize: float = 7.0, height: float = 5.0) -> list:
    """``labels`` (`rot4d_widget.sources.field_labels.box_labels`: the origin corner first, then the
    far ends of the three edges leaving it, in slice coordinates) drawn at the points placed at
    ``scale * p`` and projected: the three edges as thin dashed lines (what the texts label), each
    text small, one data coordinate a line, set off from the projected ``centre`` of the box on
    its outer side so that it reads beside the picture rather than across it, moved inward where
    it would leave the axes and to another side of its point (or a text's height above or below)
    where it would cover a text already placed (``height``: the axes' height in inches).  Returns
    the Text artists (gid "box-label")."""
    # matplotlib collections: imported when a field's box is labelled
    from matplotlib.collections import LineCollection

    if not labels:
        return []
    pts = np.asarray([p for p, _ in labels], dtype=np.float64).reshape(-1, 3) * float(scale)
    xy, _ = perspective(pts)
    (c,), _ = perspective(np.asarray(centre, dtype=np.float64).reshape(1, 3) * float(scale))
    edges = LineCollection([[xy[0], xy[k]] for k in range(1, len(xy))], colors="#777777", linewidths=0.6,
                           linestyles=(0, (3, 2)), zorder=_Z_LABEL - 2.0, gid="box-edge")
    ax.add_collection(edges, autolim=False)
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    point = (y1 - y0) / (float(height) * 72.0)  # data units per typographic point
    gap = 3.0 * point
    out, placed = [], []
    box = dict(facecolor="white", alpha=0.7, edgecolor="none", pad=1.0)
    for (x, y), (_, text) in zip(xy, labels):
        if not text:
            continue
        lines = text.split(", ")
        wd = (0.6 * fontsize * max(len(s) for s in lines) + 2.0) * point  # the text's size, roughly
        ht = (1.2 * fontsize * len(lines) + 2.0) * point
        sx, sy = (1.0 if x >= c[0] else -1.0), (1.0 if y >= c[1] else -1.0)  # outward from the centre
        choices = []
        for shift in (0.0, 1.0, -1.0, 2.0, -2.0):  # beside the point, else a text's height above or below
            for fx, fy in ((sx, sy), (-sx, sy), (sx, -sy), (-sx, -sy)):
                tx = x + gap if fx > 0 else x - gap - wd
                ty = (y + gap if fy > 0 else y - gap - ht) + shift * ht
                tx = min(max(tx, x0 + point), x1 - wd - point)  # inside the picture
                ty = min(max(ty, y0 + point), y1 - ht - point)
                choices.append((tx, ty))
        free = [(tx, ty) for tx, ty in choices
                if not any(tx < b[2] and b[0] < tx + wd and ty < b[3] and b[1] < ty + ht for b in placed)]
        tx, ty = (free or choices)[0]
        placed.append((tx, ty, tx + wd, ty + ht))
        out.append(ax.text(tx, ty, "\n".join(lines), ha="left", va="bottom", fontsize=fontsize, color="#333333",
                           zorder=_Z_LABEL - 1.0, gid="box-label", bbox=box, linespacing=1.1))
    return out
