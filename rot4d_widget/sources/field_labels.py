"""Labels for the corners and edges of a field's cut: which data coordinates a picture's box spans.

After a turn, x of the picture may be time in the data.  `box_labels` names, at the grid's origin
corner, the data coordinates there, and at the far end of each of the three grid edges leaving it,
the data coordinates that change along that edge ("time 0 → 38 s, x 3 → 12 mm"), so a picture says
which way each data axis runs.  Pure numpy, no drawing: the static renders
(`rot4d_widget.keep.pictures.state_picture`) and the page place the same texts at the same points.
"""

from __future__ import annotations

import numpy as np

from ..core.text import number_text

__all__ = ["box_labels", "axis_names", "axis_units", "coordinate_text", "date_time_text"]

#: A data coordinate changing by less than this fraction of the box's span along it is unchanged.
_CHANGE = 1e-6
_LETTERS = "xyzw"


def axis_names(field) -> tuple:
    """(x, y, z, w): each data axis's name -- the field's dim names when it has them (``dims``
    in the array's order, ``axes`` saying which of x, y, z, w each is: "time" for w ...), else
    the letters x, y, z, w."""
    dims, axes = field.dims, field.axes
    if dims is not None and isinstance(axes, str) and len(dims) == len(axes) == 4 and set(axes) == set(_LETTERS):
        return tuple(str(dims[axes.index(c)]) for c in _LETTERS)
    return tuple(_LETTERS)


def axis_units(field) -> tuple:
    """(x, y, z, w) units: the field's ``space_units`` three times and its ``w_units`` (None where
    it names none)."""
    space, w = field.space_units, field.w_units
    return (space, space, space, w)


def date_time_text(epoch, seconds: float, step: float) -> str:
    """``epoch`` (a numpy datetime64) plus ``seconds``, as a date and time to the resolution of
    ``step`` (the data's time step, s: whole seconds for a step of a second or more, else ms or µs).

    >>> date_time_text(np.datetime64("2021-03-04T12:00:00"), 330.0, 60.0)
    '2021-03-04 12:05:30'
    """
    unit = "s" if step >= 1.0 else "ms" if step >= 1e-3 else "us"
    t = np.datetime64(epoch, "us") + np.timedelta64(int(round(float(seconds) * 1e6)), "us")
    return str(np.datetime_as_string(t, unit=unit)).replace("T", " ")


def coordinate_text(field, c: int, value: float, span: float, digits: int = 3) -> str:
    """Data coordinate ``c`` (0 ... 3: x, y, z, w) of ``field`` at ``value`` as a label writes it:
    a number for people (`number_text`, rounding noise next to ``span`` shown as 0) and its unit, or
    -- w of a field whose times were datetime64 (``w_epoch``: c0 counts seconds from it) -- the date
    and time."""
    epoch = field.w_epoch if c == 3 else None
    if epoch is not None:
        lo, hi = (float(v) for v in field.extent[3])
        return date_time_text(epoch, value, (hi - lo) / max(int(field.shape[3]) - 1, 1))
    unit = axis_units(field)[c]
    return number_text(value, span, digits) + (f" {unit}" if unit else "")


def box_labels(field, matrix, c0, grid) -> tuple:
    """``((point, text), ...)``: four labels of ``grid``'s box (a `FieldGrid` of the cut w = ``c0``
    of ``field`` after ``matrix``; only its ``origin`` and ``extent`` are read).

    First the origin corner (x0, y0, z0), its text every data coordinate there ("x 3 mm, y -2 mm,
    z 0 mm, time 12 s"); then the far ends of the grid's edges along x, y and z leaving it, each
    text the data coordinates that change along that edge, from the corner's value to the end's
    ("time 0 → 38 s, x 3 → 12 mm"; a coordinate changing by less than 1e-6 of the data box's span
    along it is left out; an edge along which nothing changes has the empty text).  ``point``: (3,)
    float64 in slice coordinates.  Names from `axis_names`, units from `axis_units`; data
    coordinates by ``field.to_data(p, matrix, c0)`` (``c0`` in the data's w units).  A grid with
    no nodes gives ()."""
    values = getattr(grid, "values", None)
    if values is not None and np.asarray(values).size == 0:
        return ()
    origin = np.asarray(grid.origin, dtype=np.float64).reshape(3)
    ext = np.asarray(grid.extent, dtype=np.float64).reshape(3, 2)
    ends = np.repeat(origin[None, :], 3, axis=0)
    ends[np.arange(3), np.arange(3)] = ext[:, 1]
    points = np.vstack([origin[None, :], ends])
    data = np.asarray(field.to_data(points, matrix, c0), dtype=np.float64).reshape(4, 4)
    names, units = axis_names(field), axis_units(field)
    extent = field.extent
    if extent is not None:
        span = np.abs(np.diff(np.asarray(extent, dtype=np.float64).reshape(4, 2), axis=1)).ravel()
    else:  # no data box: the change across the grid itself
        span = np.abs(data[1:] - data[0]).max(axis=0)
    span = np.where(span > 0, span, 1.0)

    def unit(c):
        return f" {units[c]}" if units[c] else ""

    def change(c, a, b):  # "0.01 → 0.05 m", or two date-times
        if c == 3 and field.w_epoch is not None:
            return f"{coordinate_text(field, c, a, span[c])} \u2192 {coordinate_text(field, c, b, span[c])}"
        return f"{number_text(a, span[c], 3)} \u2192 {number_text(b, span[c], 3)}{unit(c)}"

    corner = ", ".join(f"{names[c]} {coordinate_text(field, c, data[0, c], span[c])}" for c in range(4))
    out = [(points[0].copy(), corner)]
    for a in range(3):
        moved = [c for c in range(4) if abs(data[a + 1, c] - data[0, c]) > _CHANGE * span[c]]
        moved.sort(key=lambda c: -abs(data[a + 1, c] - data[0, c]) / span[c])  # the main change first
        text = ", ".join(f"{names[c]} {change(c, data[0, c], data[a + 1, c])}" for c in moved)
        out.append((points[a + 1].copy(), text))
    return tuple(out)
