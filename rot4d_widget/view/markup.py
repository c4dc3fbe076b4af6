"""Every piece of HTML the widget shows, built here and only here, from escaped text.

Text a user or a file supplies -- a field's name, long name and units, its coordinates' units and
dimension names, a source's name, description and readout rows, a polytope's name, a keymap's
labels, a note, an error that quotes its input -- is shown as text, never as markup.  The rule
is carried by types: every template here is a ``markupsafe.Markup`` literal, and values go into
it through ``Markup.format`` / ``Markup.join``, which escape anything that is not itself
``Markup``.  Only the functions of this module make ``Markup``, so a value that did not come
from one of them is escaped wherever it lands, whichever row or attribute it fills.

The widgets' HTML goes through `html_widget` and `show`, which refuse a plain ``str``.
``tests/view/test_markup.py`` reads the package's source and fails on HTML built or assigned
anywhere else (a tag in a string outside this module, an HTML widget made or its ``value`` set
outside it, an f-string or ``+`` building markup here, ``innerHTML`` in the page's code).

The readout is sent with updates, so it stays small: rows of (label, text), a c0 gauge (where
the hyperplane lies between the object's lowest and highest w) and an orientation gizmo (where
the object's own four axes point now).  Styles go once, with the help panel.
"""

from __future__ import annotations

import math

import ipywidgets as widgets
import numpy as np
from markupsafe import Markup

from ..core.text import number_text

__all__ = ["Markup", "html_widget", "show", "readout_html", "help_html", "gizmo_svg", "gauge_html",
           "colourbar_html", "legend_html", "projection_caption_html", "views_html", "keypad_label_html",
           "angle_text", "number_text", "STYLE"]

#: Compact tables (Jupyter's rendered-HTML CSS pads cells generously).  Sent
#: once, with the help panel (a <style> applies while its container is hidden).
STYLE = Markup(
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
    ".rot4d-cbar-ticks{display:flex;justify-content:space-between}"
    # the page is ahead of the kernel (keys it steps itself): the readout is of an older state
    ".rot4d-side.rot4d-behind .rot4d-readout table,.rot4d-side.rot4d-behind .rot4d-readout svg{opacity:0.45}"
    ".rot4d-side.rot4d-behind .rot4d-readout::before{content:'turning: the numbers follow at rest';"
    "display:block;font-size:85%;color:#666}"
    ".rot4d-side.rot4d-silent .rot4d-readout::before{content:'the kernel is not answering: keys wait for it';"
    "display:block;font-size:85%;color:#c8102e}</style>"
)

#: The colours of the object's axes x, y, z, w in the gizmo.
AXIS_COLORS = ("#d62728", "#2ca02c", "#1f77b4", "#9467bd")


# ----------------------------------------------------------------------------- the widgets
#: No markup: an HTML widget that shows nothing yet.
EMPTY = Markup()


def html_widget(markup: Markup = EMPTY, **kwargs) -> widgets.HTML:
    """An ``ipywidgets.HTML`` showing ``markup`` (made by this module; empty by default);
    ``kwargs`` as for HTML."""
    return widgets.HTML(_checked(markup), **kwargs)


def show(widget: widgets.HTML, markup: Markup) -> None:
    """Set an HTML widget's ``value`` to ``markup`` (made by this module)."""
    widget.value = _checked(markup)


def _checked(markup) -> Markup:
    if not isinstance(markup, Markup):
        raise TypeError(f"Expected HTML made by rot4d_widget.view.markup (a markupsafe.Markup), "
                        f"got {type(markup).__name__}: text is never shown as markup")
    return markup


# ----------------------------------------------------------------------------- text
def angle_text(rad: float) -> str:
    """``0.04909 rad (2.81°)``."""
    return f"{rad:.5f} rad ({math.degrees(rad):.2f}\u00b0)"


def _unit(unit) -> str:
    """`` K`` (a space before it), or "" for no unit."""
    return f" {unit}" if unit else ""


# ----------------------------------------------------------------------------- readout pieces
def gauge_html(c0: float, lo: float, hi: float, unit: str | None = None, text: str | None = None) -> Markup:
    """c0 with a small bar: where w = c0 lies between ``lo`` and ``hi`` (clamped, marked outside).
    ``unit``: c0's unit (a field's ``w_units``), written after the number; the number has four
    decimals between 1 and 1000 from zero (a polytope's w), else four significant digits (a time
    in s, or in ms of a run).  ``text``: what c0 is written as instead (a date and time), no unit.

    >>> print(gauge_html(0.5, 0.0, 1.0, "<b>"))
    0.5000 &lt;b&gt;<span class='rot4d-gauge' title='w from 0 to 1 &lt;b&gt;'><i style='left:50%'></i></span>
    """
    span = hi - lo
    frac = 0.5 if span <= 0 else (c0 - lo) / span
    where = "below" if frac < 0 else "above" if frac > 1 else ""
    pos = min(max(frac, 0.0), 1.0) * 100.0
    note = f" ({where} the object)" if where else ""
    big = max(abs(lo), abs(hi), abs(c0))
    u = _unit(unit)
    if text is not None:
        u = ""
    elif 1.0 <= big < 1000:
        text = f"{c0:.4f}"
    else:
        text = number_text(c0, big, 6 if big >= 1000 else 4)
    if text.lstrip("-").strip("0.") == "":  # no "-0.0000"
        text = text.lstrip("-")
    return Markup("{}{}<span class='rot4d-gauge' title='w from {:.4g} to {:.4g}{}'>"
                  "<i style='left:{:.0f}%'></i></span>{}").format(text, u, lo, hi, _unit(unit), pos, note)


def colourbar_html(stops, lo: float, hi: float, label: str, units: str | None = None, marks=(),
                   cmap: str = "") -> Markup:
    """A horizontal colour bar: the gradient through ``stops`` ('#rrggbb', low to high) over
    [``lo``, ``hi``] (finite, lo < hi), ticks at both ends in the data's ``units``, the variable's
    ``label`` and units above, and a mark per ``(value, '#rrggbb')`` of ``marks`` (an iso level and
    its surface's colour) at the value's place (clamped to the ends; its tooltip says so).

    >>> 'left:25.00%' in colourbar_html(("#000000", "#ffffff"), 0.0, 4.0, "T", "K", [(1.0, "#123456")])
    True
    """
    big = max(abs(lo), abs(hi))
    u = _unit(units)
    n = len(stops) - 1
    gradient = ",".join(f"{_colour(c)} {100.0 * i / n:.1f}%" for i, c in enumerate(stops))
    parts = []
    for value, colour in marks:
        frac = (value - lo) / (hi - lo)
        where = " (below the scale)" if frac < 0 else " (above the scale)" if frac > 1 else ""
        parts.append(Markup("<i class='rot4d-cbar-mark' style='left:{:.2f}%;border-color:{}' "
                            "title='level {}{}{}'></i>").format(100.0 * min(max(frac, 0.0), 1.0), _colour(colour),
                                                                number_text(value, big), u, where))
    heading = Markup("{} [{}]").format(label, units) if units else label
    return Markup(
        "<div class='rot4d-cbar' data-cmap='{}'><div class='rot4d-cbar-label'>{}</div>"
        "<div class='rot4d-cbar-bar' style='background:linear-gradient(to right,{})'>{}</div>"
        "<div class='rot4d-cbar-ticks'><span>{}</span><span>{}{}</span></div></div>"
    ).format(cmap, heading, gradient, Markup("").join(parts), number_text(lo, big), number_text(hi, big), u)


def legend_html(labels, colours) -> Markup:
    """What each colour is: a swatch per ``(label, rgb in 0..1)``, the label after it.

    >>> print(legend_html(["<i>"], [(1.0, 0.0, 0.0)]).split("background:")[1])
    #ff0000'></span>&nbsp;&lt;i&gt;
    """
    return Markup(" ").join(
        Markup("<span class='rot4d-swatch' style='display:inline-block;width:0.9em;height:0.9em;"
               "vertical-align:middle;background:{}'></span>&nbsp;{}").format(_rgb_hex(rgb), text)
        for text, rgb in zip(labels, colours))


def gizmo_svg(matrix) -> Markup:
    """An inline SVG: the object's own axes now (columns of ``matrix``).

    Left: the x, y part of each axis as an arrow from the centre as seen from
    the camera (dashed when its z part points away); right: its w part as a
    signed bar, labelled.  Colours `AXIS_COLORS`.  About 0.6 KB.
    """
    m = np.asarray(matrix, dtype=np.float64)
    parts = []
    for i, name in enumerate("xyzw"):
        x, y, z, w = (float(v) for v in m[:, i])
        col = AXIS_COLORS[i]
        dash = Markup(" stroke-dasharray=3") if z < 0 else ""
        by = 9 + 14 * i
        parts.append(Markup(
            "<line x1=30 y1=30 x2={:.0f} y2={:.0f} stroke={}{} /><text x=66 y={} fill={}>{}</text>"
            "<rect x={:.0f} y={} width={:.0f} height=6 fill={} />"
        ).format(30 + 26 * x, 30 - 26 * y, col, dash, by + 3, col, name, 100 + min(0.0, 28 * w), by - 3,
                 abs(28 * w), col))
    return Markup(
        "<svg width=130 height=62 style='font:9px sans-serif'><title>the object's own axes now: "
        "x, y parts as arrows, w parts as bars</title><g stroke-width=2>{}</g>"
        "<line x1=100 y1=0 x2=100 y2=60 stroke=#999 /></svg>"
    ).format(Markup("").join(parts))


def readout_html(title: str, rows, *, gizmo: Markup | str = "",
                 footer: str = "mouse over the view; ? for keys") -> Markup:
    """The readout: a bold ``title``, ``rows`` of (label, value) and a footer.  A value is text
    (escaped) or a piece made by this module (`gauge_html`, `colourbar_html`, `legend_html` ...).

    >>> print(readout_html("<b>", [("units", "<img src=x onerror=f()>")], footer="").split("<table>")[1])
    <tr><td>units</td><td>&lt;img src=x onerror=f()&gt;</td></tr></table><br><small></small></div>
    """
    body = Markup("").join(Markup("<tr><td>{}</td><td>{}</td></tr>").format(k, v) for k, v in rows)
    return Markup("<div class='rot4d-readout'><b>{}</b><table>{}</table>{}<br><small>{}</small></div>").format(
        title, body, gizmo, footer)


def help_html(groups, hold_delay: float, tick_rate: float) -> Markup:
    """The key table: ``groups`` are (keys text, label, description) rows, one per action."""
    rows = Markup("").join(
        Markup("<tr><td><kbd>{}</kbd></td><td>{}</td><td>{}</td></tr>").format(keys, label, text)
        for keys, label, text in groups
    )
    return STYLE + Markup(
        "<div class='rot4d-help'><table style='margin:0.5em 0'>{}</table>"
        "<small>Shift inverts a rotation. Hold a key: it repeats after {:.0f} ms, {:g} steps/s. "
        "Drag to turn the 3-D view (the slice itself does not change); the wheel zooms.</small></div>"
    ).format(rows, hold_delay * 1000, tick_rate)


# ----------------------------------------------------------------------------- other panels
def projection_caption_html(eye_distance: float, note: str | None = None) -> Markup:
    """The projection view's caption: what its colours mean; ``note`` (text) after it."""
    text = Markup(
        "<b>projection</b>: the whole object, perspective from w = {:g}&times;size; edges "
        "<span style='color:#3b4cc0'>blue below</span> / <span style='color:#b40426'>red above</span> "
        "w = c0, <span style='color:#e07b00'>balls</span>: where w = c0 cuts (the slice)"
    ).format(eye_distance)
    if note:
        text += Markup(" &mdash; {}").format(note)
    return Markup("<div style='font-size:0.85em;max-width:36em'>{}</div>").format(text)


def views_html() -> Markup:
    """The readout's row saying which view is which, with the projection shown."""
    return Markup("left: the slice w = c0 &middot; right: the whole object projected (balls: the slice)")


def keypad_label_html(title: str) -> Markup:
    """A key pad row's title, small."""
    return Markup("<small>{}</small>").format(title)


# ----------------------------------------------------------------------------- colours
def _rgb_hex(rgb) -> str:
    """``#rrggbb`` of an rgb triple in 0..1 (clipped)."""
    return "#" + "".join(f"{min(max(round(255 * float(c)), 0), 255):02x}" for c in rgb)


def _colour(text) -> str:
    """A '#rrggbb' colour as given, or a ValueError: colours go into style attributes."""
    s = str(text)
    if len(s) != 7 or s[0] != "#" or any(c not in "0123456789abcdefABCDEF" for c in s[1:]):
        raise ValueError(f"Expected a colour '#rrggbb', got {s!r}")
    return s
