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
    polytope slice's census, its readout row "slice"; a stack's slices' w, from ``cuts_at``)
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
        lo, hi = getattr(inner, "data_range", (min(levels), max(levels)))
        rgb = _level_colors(levels, lo, hi)
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
