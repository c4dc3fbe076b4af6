"""What a `Field4D` says about itself: the readout rows of a slice, the order of its axes, and
`describe`, the JSON-able description a state file keeps (and rebuilds it from when it can)."""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from ..protocol import w_span_text
from .checks import axes_text
from .inputs import LazyXarray


def field_readout(field, m, c0, slices, box, coarse) -> tuple:
    """The readout rows of a field's slice (`Field4D.slice`): what, its axes, the levels and
    the data range, the volumes, the w the box's cut spans, the resolution of a coarse step."""
    rows = list(_what_rows(field))
    lo, hi = field.data_range
    parts = []
    for s in slices:
        t = f"{s.level:.4g}"
        above = field.inside == "above"
        if math.isfinite(hi) and (s.level > hi if above else s.level >= hi):
            t += " (above the max: empty)" if above else " (at or above the max: the whole box)"
        elif math.isfinite(lo) and (s.level <= lo if above else s.level < lo):
            t += " (at or below the min: the whole box)" if above else " (below the min: empty)"
        elif s.empty:
            t += " (empty here)"
        parts.append(t)
    where = field.data_range_source
    rng = (f" of {lo:.4g} \u2026 {hi:.4g}" + ("" if where == "data" else f" ({where})") if math.isfinite(lo)
           else " (all NaN)")
    rows.append(("level" if len(slices) == 1 else "levels", ", ".join(parts) + rng))
    if field.inside != "above" or not field.caps:
        rows.append(("surface", ("encloses f <= level" if field.inside == "below" else "encloses f >= level")
                     + ("" if field.caps else ", open on the box's faces (no volume)")))
    if len(slices) > 1:
        rows.append(("volumes", ", ".join(f"{s.volume:.4g}" for s in slices)))
    rows += _cut_rows(field, m, c0, box)
    if coarse:
        rows.append(("resolution", f"{field.coarse_resolution} (coarse copy)"))
    return tuple(rows)


def _what_rows(field) -> tuple:
    """The rows naming the field: its name and units, the order of its axes and its shape."""
    rows = [("field", f"{field.name or 'field'}" + (f" [{field.units}]" if field.units else ""))]
    if field.kind != "function":
        rows.append(("axes", f"{order_text(field)}, shape {tuple(int(n) for n in field.values.shape)}"))
        missing = field.missing
        if missing is not None:
            rows.append(("missing", missing))
    return tuple(rows)


def _cut_rows(field, m, c0, box) -> tuple:
    """The rows of the cut itself, whatever draws it: the w its box spans and how much w one unit
    of space is."""
    rows = []
    wu = f" {field.w_units}" if field.w_units else ""
    if len(box.vertices):
        p = np.column_stack([np.asarray(box.vertices), np.full(len(box.vertices), c0)])
        w = (p @ m)[:, 3] * field.w_per_unit + field.centre[3]
        if field.w_epoch is not None:  # dates and times
            rows.append(("w cut", f"{w_span_text(field, w.min(), w.max())} "
                                  f"(data {w_span_text(field, *field.extent[3])})"))
        else:
            rows.append(("w cut", f"{w.min():.4g} \u2026 {w.max():.4g}{wu} (data {field.extent[3][0]:.4g} \u2026 "
                                  f"{field.extent[3][1]:.4g})"))
    else:
        rows.append(("w cut", "none (w = c0 misses the data)"))
    per = field.space_units if field.space_units else "unit of space"
    rows.append(("w per unit", f"{field.w_per_unit:.4g}{wu} per {per}"))
    return tuple(rows)


def outline_readout(field, m, d, box) -> tuple:
    """The readout rows of a field's cut without its surfaces (`Field4D.outline`): what it is and
    the cut (``d`` the offset in slice units, as `field_readout` takes it)."""
    return _what_rows(field) + _cut_rows(field, m, d, box)


def order_text(field) -> str:
    """Which of x, y, z, w each array axis is: 'f[w, z, y, x]', with the dim names from xarray
    ('T[time, z, y, x] as [w, z, y, x]')."""
    if field.kind == "function":
        return "f(x, y, z, w)"
    if field.dims is not None:
        label = field.name or "f"
        return f"{label}[{', '.join(field.dims)}] as [{', '.join(field.axes)}]"
    return axes_text(field.axes)


def _function_path(f):
    """(``"module:qualname"``, None) for a function a state file can import again, else (None, why)."""
    module = getattr(f, "__module__", None)
    qual = getattr(f, "__qualname__", None)
    if not module or not qual:
        return None, f"{type(f).__name__} has no module-level name"
    if "<" in qual:
        return None, f"{module}.{qual} is a lambda or a local function"
    if module == "__main__":
        return None, f"{qual} is defined in a notebook or script (__main__)"
    return f"{module}:{qual}", None


def describe_field(field) -> dict:
    """`Field4D.describe`: the field's frame, levels, surface and resolutions, where its values come
    from (a module-level function ``"module:qualname"``, the file `Field4D.open` read, or what
    array it holds) and ``"rebuild"``: True, or why a state file cannot rebuild it."""
    d = {"kind": "field", "axes": field.axes, "extent": [list(e) for e in field.extent],
         "w_per_unit": field.w_per_unit, "levels": list(field.levels), "name": field.name, "units": field.units,
         "space_units": field.space_units, "inside": field.inside, "caps": field.caps}
    values = field.values
    if field.kind == "function":
        f = field.function
        d["function"] = f"{getattr(f, '__module__', '?')}.{getattr(f, '__qualname__', type(f).__name__)}"
    else:
        what = {"numpy": "in-memory numpy", "dask": "dask array", "zarr": "zarr array"}.get(
            field.kind, "lazily read xarray array" if isinstance(values, LazyXarray) else type(values).__name__)
        d["array"] = f"{what} (not recordable)"
        d["shape"] = list(values.shape)
        d["dtype"] = str(np.dtype(values.dtype))
        store = getattr(values, "store", None)
        if field.kind == "zarr" and store is not None:
            d["store"] = str(store)
    d.update(resolution=field.resolution, coarse_resolution=field.coarse_resolution, w_units=field.w_units,
             chunk_cache_bytes=field.chunk_cache_bytes)
    origin = field.origin
    if field.kind == "function":
        path, why = _function_path(field.function)
        d["function"] = path or d.get("function")
        d["rebuild"] = True if path else f"its function cannot be imported again: {why}"
    elif isinstance(origin, Mapping):
        d["origin"] = dict(origin)
        d["array"] = f"read from {origin.get('path')!r} (reopened from there)"
        d["rebuild"] = True
    else:
        what = d.get("array", "array").replace(" (not recordable)", "")
        why = (f"its values are a {what}: {field.origin_missing}" if field.origin_missing
               else f"its values are a {what} held in memory, not written into a state file")
        d["rebuild"] = (f"{why}; give from_xarray the Dataset and the variable's name, "
                        "Field4D.from_xarray(ds, 'T', w=...), or open the file with Field4D.open(path, variable, "
                        "w=...), to record where the data come from")
    return d
