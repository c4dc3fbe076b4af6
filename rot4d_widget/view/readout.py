"""The readout and help panel as HTML strings (pure functions, no widgets).

The readout is sent with updates, so it stays small: rows of (label, text),
a c0 gauge (where the hyperplane is between the object's lowest and highest
w) and an orientation gizmo (where the object's own four axes point now: the
x, y, z part of each as an arrow seen from the camera, the w part as a signed
bar -- so a user sees how far w has been mixed in).  Styles go once, with the
help panel.
"""

from __future__ import annotations

import html
import math

import numpy as np

from ..core.look import number_text

__all__ = ["readout_html", "help_html", "gizmo_svg", "gauge_html", "colourbar_html", "angle_text", "number_text",
           "STYLE"]

#: Compact tables (Jupyter's rendered-HTML CSS pads cells generously).  Sent
#: once, with the help panel (a <style> applies while its container is hidden).
STYLE = (
    "<style>.rot4d-side table{border-collapse:collapse;margin:0}"
    ".rot4d-side .rot4d-readout td,.rot4d-side .rot4d-help td"
    "{padding:1px 0.5em 1px 0;line-height:1.3;text-align:left;vertical-align:top}"
    ".rot4d-side .rot4d-readout table{font-family:monospace}"
    ".rot4d-side .rot4d-readout td:first-child{white-space:nowrap}"  # "▸ w 30 s" on one line
    ".rot4d-side .rot4d-help{font-size:90%}"
    ".rot4d-gauge{display:inline-block;position:relative;width:8em;height:0.6em;"
    "background:#ddd;vertical-align:middle;margin-left:0.4em}"
    ".rot4d-gauge i{position:absolute;top:-0.2em;width:2px;height:1em;background:#c8102e}"
    ".rot4d-cbar{font-family:sans-serif;font-size:90%;width:14em}"
    ".rot4d-cbar-bar{position:relative;height:0.9em;margin:0.15em 0;border:1px solid #888}"
    ".rot4d-cbar-bar i{position:absolute;top:-4px;bottom:-4px;width:0;margin-left:-2px;"
    "border-left:4px solid;box-shadow:0 0 0 1px #fff}"
    ".rot4d-cbar-ticks{display:flex;justify-content:space-between}</style>"
)

#: The colours of the object's axes x, y, z, w in the gizmo.
AXIS_COLORS = ("#d62728", "#2ca02c", "#1f77b4", "#9467bd")


def angle_text(rad: float) -> str:
    """``0.04909 rad (2.81°)``."""
    return f"{rad:.5f} rad ({math.degrees(rad):.2f}\u00b0)"


def gauge_html(c0: float, lo: float, hi: float, unit: str | None = None) -> str:
    """c0 with a small bar: where w = c0 lies between ``lo`` and ``hi`` (clamped, marked outside).
    ``unit``: c0's unit (a field's ``w_units``), written after the number; the number has four
    decimals within 1000 of zero (a polytope's w), else four significant digits (a time in s)."""
    span = hi - lo
    frac = 0.5 if span <= 0 else (c0 - lo) / span
    where = "below" if frac < 0 else "above" if frac > 1 else ""
    pos = min(max(frac, 0.0), 1.0) * 100.0
    note = f" ({where} the object)" if where else ""
    big = max(abs(lo), abs(hi), abs(c0))
    text = f"{c0:.4f}" if big < 1000 else number_text(c0, big, 6)
    if text.lstrip("-").strip("0.") == "":  # no "-0.0000"
        text = text.lstrip("-")
    u = f" {html.escape(unit)}" if unit else ""
    return (
        f"{text}{u}<span class='rot4d-gauge' title='w from {lo:.4g} to {hi:.4g}{u}'>"
        f"<i style='left:{pos:.0f}%'></i></span>{note}"
    )


def colourbar_html(stops, lo: float, hi: float, label: str, units: str | None = None, marks=(),
                   cmap: str = "") -> str:
    """A horizontal colour bar: the gradient through ``stops`` ('#rrggbb', low to high) over
    [``lo``, ``hi``] (finite, lo < hi), ticks at both ends in the data's ``units``, the variable's
    ``label`` and units above, and a mark per ``(value, '#rrggbb')`` of ``marks`` (an iso level and
    its surface's colour) at the value's place (clamped to the ends; its tooltip says so).

    >>> 'left:25.00%' in colourbar_html(("#000000", "#ffffff"), 0.0, 4.0, "T", "K", [(1.0, "#123456")])
    True
    """
    big = max(abs(lo), abs(hi))
    u = f" {html.escape(units)}" if units else ""
    n = len(stops) - 1
    gradient = ",".join(f"{c} {100.0 * i / n:.1f}%" for i, c in enumerate(stops))
    parts = []
    for value, colour in marks:
        frac = (value - lo) / (hi - lo)
        where = " (below the scale)" if frac < 0 else " (above the scale)" if frac > 1 else ""
        parts.append(f"<i class='rot4d-cbar-mark' style='left:{100.0 * min(max(frac, 0.0), 1.0):.2f}%;"
                     f"border-color:{colour}' title='level {number_text(value, big)}{u}{where}'></i>")
    return (
        f"<div class='rot4d-cbar' data-cmap='{html.escape(cmap)}'>"
        f"<div class='rot4d-cbar-label'>{html.escape(label)}{f' [{html.escape(units)}]' if units else ''}</div>"
        f"<div class='rot4d-cbar-bar' style='background:linear-gradient(to right,{gradient})'>{''.join(parts)}</div>"
        f"<div class='rot4d-cbar-ticks'><span>{number_text(lo, big)}</span><span>{number_text(hi, big)}{u}</span>"
        "</div></div>"
    )


def gizmo_svg(matrix) -> str:
    """An inline SVG: the object's own axes now (columns of ``matrix``).

    Left: the x, y part of each axis as an arrow from the centre as seen from
    the camera (dashed when its z part points away); right: its w part as a
    signed bar, labelled.  Colours `AXIS_COLORS`.  About 0.6 KB.
    """
    m = np.asarray(matrix, dtype=np.float64)
    parts = []
    for i, name in enumerate("xyzw"):
        x, y, z, w = m[:, i]
        col = AXIS_COLORS[i]
        dash = "" if z >= 0 else " stroke-dasharray=3"
        by = 9 + 14 * i
        parts.append(
            f"<line x2={30 + 26 * x:.0f} y2={30 - 26 * y:.0f} stroke={col}{dash} />"
            f"<text x=66 y={by + 3} fill={col}>{name}</text>"
            f"<rect x={100 + min(0.0, 28 * w):.0f} y={by - 3} width={abs(28 * w):.0f} height=6 fill={col} />"
        )
    return (
        "<svg width=130 height=62 style='font:9px sans-serif'><title>the object's own axes now: "
        "x, y parts as arrows, w parts as bars</title><g stroke-width=2>"
        + "".join(parts).replace("<line ", "<line x1=30 y1=30 ")
        + "</g><line x1=100 y1=0 x2=100 y2=60 stroke=#999 /></svg>"
    )


def readout_html(title: str, rows, *, gizmo: str = "", footer: str = "mouse over the view; ? for keys") -> str:
    """The readout: a bold title, rows of (label, html text) and a footer."""
    body = "".join(f"<tr><td>{html.escape(str(k))}</td><td>{v}</td></tr>" for k, v in rows)
    return (
        f"<div class='rot4d-readout'><b>{html.escape(title)}</b><table>{body}</table>"
        f"{gizmo}<br><small>{html.escape(footer)}</small></div>"
    )


def help_html(groups, hold_delay: float, tick_rate: float) -> str:
    """The key table: ``groups`` are (keys text, label, description) rows, one per action."""
    rows = "".join(
        f"<tr><td><kbd>{html.escape(keys)}</kbd></td><td>{html.escape(label)}</td><td>{html.escape(text)}</td></tr>"
        for keys, label, text in groups
    )
    return (
        STYLE + "<div class='rot4d-help'><table style='margin:0.5em 0'>" + rows + "</table>"
        f"<small>Shift inverts a rotation. Hold a key: it repeats after {hold_delay * 1000:.0f} ms, "
        f"{tick_rate:g} steps/s. Drag to turn the 3-D view (the slice itself does not change); "
        "the wheel zooms.</small></div>"
    )
