"""How values come into a `Field4D`: arrays checked, xarray DataArrays mapped to x, y, z, w,
files opened, and what a state file keeps of them.

`as_array` checks an array and the ``axes`` naming its dims; `xarray_arguments` maps a
DataArray's dims and coordinates to a field's arguments (`Field4D.from_xarray`); `open_dataarray`
opens a netCDF file or zarr store (`Field4D.open`).  A variable's data range is read from its
metadata (`metadata_range`); a reopenable origin from xarray's encoding: the Dataset's
``encoding["source"]``, which xarray sets for every engine (`_dataset_origin`), or a DataArray's own,
which only the netCDF4 and h5netcdf engines set (`_encoding_origin`); selections and chunks are
written as JSON (`_selection_json`, `_chunks_json`) and read back.
"""

from __future__ import annotations

import math
import numbers
import os
import warnings

import numpy as np

from ...core._arrays import sealed as _sealed
from .checks import AXES, UnitsWarning
from .chunks import array_kind


def _dataset_error(ds) -> TypeError:
    names = [str(k) for k in getattr(ds, "data_vars", {})]
    first = names[0] if names else "name"
    listed = ", ".join(repr(n) for n in names) if names else "none"
    return TypeError(f"Field4D(values) takes a plain array, got an xarray.Dataset with data variables {listed}; "
                     f"use Field4D.from_xarray(ds, {first!r}, w='time') (the Dataset and a variable's name: "
                     "a state file can then reopen the file it came from)")


def _dataset_variable(ds, variable):
    """``(variable name, DataArray)`` of the Dataset ``ds`` for `Field4D.from_xarray`: ``variable``, or
    its one data variable; ValueError naming the data variables otherwise."""
    names = [str(k) for k in ds.data_vars]
    listed = ", ".join(repr(n) for n in names) if names else "none"
    if variable is None:
        if len(names) != 1:
            first = names[0] if names else "name"
            raise ValueError(f"The xarray.Dataset has data variables {listed}; name one: "
                             f"Field4D.from_xarray(ds, {first!r}, w='time')")
        variable = names[0]
    if not isinstance(variable, str):
        raise TypeError(f"Expected `variable` to be a data variable's name (a string), got {type(variable).__name__}")
    if variable not in ds.data_vars:
        raise ValueError(f"The xarray.Dataset has no data variable {variable!r}; it has {listed}")
    return variable, ds[variable]


class LazyXarray:
    """A DataArray whose data are neither dask nor loaded (an xarray backend's lazily indexed
    array: netCDF or zarr opened without chunks), seen as a plain sliceable array.

    Slicing reads only that block (``variable[key].values``) and returns a numpy array, so the
    chunk reader and dask's ``from_array`` never see a DataArray (inside dask a DataArray chunk
    aligns by its labels -- two takes of neighbouring samples shrink to their common ones -- and
    pulls in dask.dataframe, which needs pyarrow).  ``chunks``: the store's own chunk shape when
    the encoding gives one (zarr), else None (the reader then reads 16-sample blocks).
    """

    def __init__(self, da):
        self._variable = da.variable
        self.shape = tuple(int(n) for n in da.shape)
        self.ndim = len(self.shape)
        self.dtype = np.dtype(da.dtype)
        enc = getattr(da, "encoding", None) or {}
        pref = enc.get("preferred_chunks")
        ch = None
        if isinstance(pref, dict) and all(d in pref for d in da.dims):
            ch = tuple(int(pref[d]) for d in da.dims)
        elif isinstance(enc.get("chunks"), (tuple, list)) and len(enc["chunks"]) == self.ndim:
            ch = tuple(int(c) for c in enc["chunks"])
        self.chunks = ch if ch is not None and all(c > 0 for c in ch) else None
        self.name = da.name

    def __getitem__(self, key):
        return np.asarray(self._variable[key].values)

    def __array__(self, dtype=None, copy=None):
        a = self[(slice(None),) * self.ndim]
        return a if dtype is None else a.astype(dtype, copy=False)


def _xarray_values(da):
    """The array behind a DataArray for `Field4D`: dask stays dask, loaded data become numpy,
    a lazily indexed backend array becomes `LazyXarray` (never the DataArray itself)."""
    if da.chunks is not None:
        return da.data
    if getattr(da.variable, "_in_memory", True):
        return np.asarray(da.values)
    return LazyXarray(da)


def _is_xarray(obj, what: str) -> bool:
    return type(obj).__name__ == what and (type(obj).__module__ or "").startswith("xarray")


def _attr_numbers(v, n: int):
    """``n`` finite floats from an attribute value (a number or an array), else None."""
    try:
        a = np.asarray(v, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        return None
    return tuple(float(x) for x in a) if a.size == n and np.all(np.isfinite(a)) else None


def zarr_attrs(values) -> dict:
    """A zarr array's attributes as a plain dict ({} when it has none or they cannot be read)."""
    try:
        return dict(values.attrs)
    except Exception:  # noqa: BLE001 - metadata is a bonus: without it the range comes from the data
        return {}


def metadata_range(attrs, encoding, dtype=None):
    """(lo, hi, where) of a variable from its attributes, read without touching its data, or None.

    ``actual_range`` (CF: the data's own min and max, in unpacked units) first, else
    ``valid_range`` or ``valid_min`` and ``valid_max`` (CF: the bounds of valid values, in packed
    units: unpacked here by the ``scale_factor`` / ``add_offset`` xarray moved into the encoding
    when it decoded the data).  A pair is a range the level keys can step through only when it is
    finite with lo < hi and a finite span: ``[1, 1]`` (o / i would have nowhere to go) and
    ``[-1e308, 1e308]`` (a step of 1/50 of the span overflows) are ignored, as is a pair beyond
    what the data's floating ``dtype`` holds (``valid_max = 1e307`` for float32 data): the range
    then comes from the data."""
    attrs = attrs or {}
    encoding = encoding or {}
    packed = "scale_factor" in attrs or "add_offset" in attrs  # not decoded: the data are still packed
    pair = None if packed else _attr_numbers(attrs.get("actual_range"), 2)
    if pair is not None and _steppable(pair, dtype):
        return pair[0], pair[1], "actual_range"
    pair, where = _attr_numbers(attrs.get("valid_range"), 2), "valid_range"
    if pair is None:
        lo, hi = _attr_numbers(attrs.get("valid_min"), 1), _attr_numbers(attrs.get("valid_max"), 1)
        pair, where = (None if lo is None or hi is None else lo + hi), "valid_min/valid_max"
    if pair is None:
        return None
    if not packed:
        scale = _attr_numbers(encoding.get("scale_factor", 1.0), 1)
        offset = _attr_numbers(encoding.get("add_offset", 0.0), 1)
        if scale is None or offset is None:
            return None
        pair = tuple(sorted((pair[0] * scale[0] + offset[0], pair[1] * scale[0] + offset[0])))
    return (pair[0], pair[1], where) if _steppable(pair, dtype) else None


def _steppable(pair, dtype=None) -> bool:
    """A metadata (lo, hi) the field can use as its data range: finite, lo < hi, a finite span, and
    within what a floating ``dtype`` holds."""
    lo, hi = (float(v) for v in pair)
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi and math.isfinite(hi - lo)):
        return False
    if dtype is not None and np.issubdtype(np.dtype(dtype), np.floating):
        return max(abs(lo), abs(hi)) <= float(np.finfo(dtype).max)
    return True


def _encoding_origin(da, chosen):
    """What a state file needs to reopen a DataArray read from a file, from what xarray kept:
    the path in ``da.encoding["source"]`` (the netCDF4 and h5netcdf engines put it there; scipy
    and zarr do not), when the array is the file's whole variable (its shape is the encoding's
    ``original_shape``; a selection made after opening cannot be seen).  None otherwise."""
    enc = getattr(da, "encoding", None) or {}
    src = enc.get("source")
    if not isinstance(src, str) or not os.path.exists(src) or da.name is None:
        return None
    shape = enc.get("original_shape")
    if shape is not None and tuple(int(n) for n in shape) != tuple(int(n) for n in da.shape):
        return None
    if da.chunks is not None:
        chunks = {str(d): int(c[0]) for d, c in zip(da.dims, da.chunks)}
    else:
        chunks = None
    return {"kind": "xarray", "path": os.path.abspath(src), "variable": str(da.name), "engine": None,
            "chunks": chunks, "isel": None, "sel": None, "kwargs": dict(chosen),
            "load": bool(da.chunks is None and getattr(da.variable, "_in_memory", False))}


def _dataset_origin(ds, variable, da, chosen):
    """``(origin, why)`` for `Field4D.from_xarray` given a Dataset: what a state file needs to reopen
    ``variable`` from the file or store xarray opened -- its path from ``ds.encoding["source"]``, set
    by ``xarray.open_dataset`` / ``open_zarr`` whatever the engine (scipy and zarr included) -- or
    (None, why not).  The file is opened again (metadata and coordinates only) to tell the whole
    variable from a selection made after opening (``ds.isel(...)``: its shape or coordinates differ),
    which a state file would reopen whole: refused, naming `Field4D.open`'s ``isel=`` / ``sel=``."""
    import xarray  # optional: from_xarray was given a Dataset, so it is installed

    src = (getattr(ds, "encoding", None) or {}).get("source")
    if not isinstance(src, str) or not os.path.exists(src):
        return None, ("xarray does not know the file this Dataset came from (no encoding['source']: made in "
                      "memory, or opened from a file object)")
    engine = "zarr" if os.path.isdir(src) or src.rstrip("/").endswith(".zarr") else None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", category=RuntimeWarning)  # zarr: no consolidated metadata
            with xarray.open_dataset(src, engine=engine) as whole:
                stored = whole[variable] if variable in whole.data_vars else None
                same = stored is not None and stored.dims == da.dims and stored.shape == da.shape and all(
                    np.array_equal(np.asarray(stored.coords[d].values), np.asarray(da.coords[d].values))
                    for d in da.dims if d in da.coords and d in stored.coords)
    except (OSError, ValueError, KeyError) as exc:
        return None, f"the file {src!r} cannot be opened again ({type(exc).__name__}: {exc})"
    if not same:
        return None, (f"the field is a selection of {variable!r} in {src!r} (made after opening), which a state "
                      f"file would reopen whole; use Field4D.open(path, {variable!r}, isel=..., sel=...)")
    if da.chunks is not None:
        chunks = {str(d): int(c[0]) for d, c in zip(da.dims, da.chunks)}
    else:
        chunks = None
    return ({"kind": "xarray", "path": os.path.abspath(src), "variable": str(variable), "engine": engine,
             "chunks": chunks, "isel": None, "sel": None, "kwargs": dict(chosen),
             "load": bool(da.chunks is None and getattr(da.variable, "_in_memory", False))}, None)


def _label_json(v, where):
    if isinstance(v, (np.datetime64, np.timedelta64)):
        return str(v)
    if hasattr(v, "isoformat") and not isinstance(v, (int, float)):  # datetime, pandas Timestamp
        return v.isoformat()
    if isinstance(v, (bool, np.bool_)):
        raise TypeError(f"{where} = {v!r}: expected an integer, a label (number or string) or a slice")
    if isinstance(v, (numbers.Integral, np.integer)):
        return int(v)
    if isinstance(v, (numbers.Real, np.floating)) and math.isfinite(float(v)):
        return float(v)
    if v is None or isinstance(v, str):
        return v
    raise TypeError(f"{where} = {v!r}: expected an integer, a label (number or string) or a slice")


def _selection_json(selection, name):
    """``{dim: value}`` as JSON: numbers and strings as they are, ``slice(a, b, c)`` as
    ``{"slice": [a, b, c]}``, lists as lists; TypeError naming anything else."""
    if not selection:
        return None
    if not isinstance(selection, dict):
        raise TypeError(f"Expected `{name}` to be a dict {{dim: index or label or slice}}, "
                        f"got {type(selection).__name__}")
    out = {}
    for dim, v in selection.items():
        where = f"{name}[{dim!r}]"
        if isinstance(v, slice):
            out[str(dim)] = {"slice": [_label_json(e, where) for e in (v.start, v.stop, v.step)]}
        elif isinstance(v, (list, tuple, np.ndarray)):
            out[str(dim)] = [_label_json(e, where) for e in v]
        else:
            out[str(dim)] = _label_json(v, where)
    return out


def selection_from_json(selection, name):
    """The inverse of `_selection_json` (a state file's selection for isel / sel)."""
    if selection is None:
        return None
    if not isinstance(selection, dict):
        raise ValueError(f"Expected `{name}` to be a dict, got {selection!r}")
    out = {}
    for dim, v in selection.items():
        if isinstance(v, dict):
            parts = v.get("slice")
            if set(v) != {"slice"} or not isinstance(parts, list) or len(parts) != 3:
                raise ValueError(f"Expected {name}[{dim!r}] to be {{'slice': [start, stop, step]}}, got {v!r}")
            v = slice(*parts)
            items = (v.start, v.stop, v.step)
        else:
            items = v if isinstance(v, list) else [v]
        for e in items:
            if e is not None and (isinstance(e, bool) or not isinstance(e, (int, float, str))):
                raise ValueError(f"Expected {name}[{dim!r}] to hold numbers, strings or slices, got {e!r}")
        out[str(dim)] = v
    return out


def _chunks_json(chunks):
    if chunks is None or isinstance(chunks, str):
        return chunks
    if isinstance(chunks, (numbers.Integral, np.integer)) and not isinstance(chunks, bool):
        return int(chunks)
    if isinstance(chunks, dict):
        out = {}
        for d, c in chunks.items():
            if isinstance(c, (numbers.Integral, np.integer)) and not isinstance(c, bool):
                out[str(d)] = int(c)
            elif isinstance(c, str) or c is None:
                out[str(d)] = c
            else:
                raise TypeError(f"Expected chunks[{d!r}] to be an int, 'auto' or None, got {c!r}")
        return out
    raise TypeError(f"Expected `chunks` to be None, 'auto', an int or a dict {{dim: size}}, got {chunks!r}")


def as_array(values, axes):
    """``(values, kind, axis_of, shape)`` of an array given to `Field4D`, checked: 4-D, real numbers,
    ``axes`` a permutation of "xyzw" (required), at least 2 samples along every axis.  An array in
    memory becomes numpy (float32 kept, other dtypes as float64; a memmap stays a memmap)."""
    if _is_xarray(values, "Dataset"):
        raise _dataset_error(values)
    if _is_xarray(values, "DataArray"):
        raise TypeError("Field4D(values) takes a plain array; for an xarray.DataArray use "
                        "Field4D.from_xarray(da, w='time') (dims by name, extents from the coordinates), "
                        "or pass da.data with axes=")
    for attr in ("shape", "ndim", "__getitem__"):
        if not hasattr(values, attr):
            raise TypeError(f"Expected `values` to be a 4-D array-like (numpy, dask, zarr ...) with shape, "
                            f"ndim and slicing; {type(values).__name__} has no {attr!r}")
    kind = array_kind(values)
    if kind == "lazy" and not hasattr(values, "dtype"):
        values = np.asarray(values)
        kind = "numpy"
    if values.ndim != 4:
        raise ValueError(f"Expected `values` to be 4-D, got {values.ndim}-D with shape {tuple(values.shape)}")
    dtype = np.dtype(values.dtype)
    if dtype.kind not in "fiub":
        raise TypeError(f"Expected `values` to hold real numbers (float, int, uint or bool), got dtype {dtype}")
    if kind == "numpy":
        values = np.asarray(values)  # a memmap stays a memmap underneath (no copy)
        if dtype not in (np.float32, np.float64):
            values = values.astype(np.float64)
    if axes is not None and (not isinstance(axes, str) or sorted(axes) != sorted(AXES)):
        raise ValueError(f"Expected `axes` to be a permutation of 'xyzw' naming each array axis "
                         f"(e.g. 'wzyx' for f[t, z, y, x]), got {axes!r}")
    if axes is None:  # a guess cannot tell time from x: the caller says which axis is which
        sh = tuple(int(n) for n in values.shape)
        raise TypeError(
            f"Field4D needs `axes`, which of x, y, z, w each array axis is (shape {sh}): "
            f"axes='wzyx' for f[t, z, y, x] (time first), axes='xyzw' for f[x, y, z, t]; "
            f"Field4D.from_xarray(da, w='time') takes them from the dims")
    axis_of = tuple(axes.index(c) for c in AXES)  # array axis of x, y, z, w
    shape = tuple(int(values.shape[a]) for a in axis_of)
    small = [f"{c}={n}" for c, n in zip(AXES, shape) if n < 2]
    if small:
        raise ValueError(f"Expected at least 2 samples along every axis, got {', '.join(small)}")
    return values, kind, axis_of, shape


def xarray_arguments(data, variable, x, y, z, w, w_per_unit, kwargs):
    """``(values, arguments, dims, meta_range, (origin, why not), long_name)`` for
    `Field4D.from_xarray`: the values of the DataArray ``data`` (or of ``variable`` of the Dataset
    ``data``: `_dataset_variable`) (`_xarray_values`), the field's keyword arguments (``kwargs``
    given for it are consumed: name, units, w_units, space_units), its dim names, its data range
    from metadata, the file it came from (`_dataset_origin`, `_encoding_origin`) and its
    ``long_name`` attribute (`_long_name`)."""
    ds = None
    if _is_xarray(data, "Dataset") or (hasattr(data, "data_vars") and hasattr(data, "dims")):
        ds = data
        variable, da = _dataset_variable(ds, variable)
    else:
        da = data
        if variable is not None:
            raise TypeError(f"`variable` ({variable!r}) names a data variable of an xarray.Dataset; "
                            "a DataArray is one already: Field4D.from_xarray(da, w=...)")
    if not (hasattr(da, "dims") and hasattr(da, "coords") and hasattr(da, "isel")):
        raise TypeError(f"Expected an xarray.DataArray or Dataset, got {type(da).__name__}")
    dims = tuple(str(d) for d in da.dims)
    if len(dims) != 4:
        raise ValueError(f"Expected a 4-D DataArray, got dims {dims}; select a 4-D part first "
                         "(da.isel(...) / da.sel(...))")
    given = {"x": x, "y": y, "z": z, "w": w}
    for k, v in given.items():
        if v is not None and v not in dims:
            raise ValueError(f"`{k}={v!r}` is not a dim of the DataArray; its dims are {dims}")
    chosen = {k: v for k, v in given.items() if v is not None}
    if len(set(chosen.values())) != len(chosen):
        raise ValueError(f"Expected distinct dims for x, y, z, w, got {chosen}")
    for k in "xyz":
        if k not in chosen:
            cands = [d for d in dims if d.lower() == k and d not in chosen.values()]
            if len(cands) == 1:
                chosen[k] = cands[0]
    left = [d for d in dims if d not in chosen.values()]
    missing = [k for k in AXES if k not in chosen]
    if len(missing) == 1 and len(left) == 1:
        chosen[missing[0]] = left[0]
    elif missing:
        raise ValueError(
            f"Cannot map the dims {dims} to x, y, z, w: found {chosen or 'none'}; name them, e.g. "
            f"Field4D.from_xarray(da, x='lon', y='lat', z='depth', w='time')"
        )
    axes = "".join(next(k for k, v in chosen.items() if v == d) for d in dims)
    few = [f"{chosen[k]}={int(da.sizes[chosen[k]])} ({k})" for k in AXES if int(da.sizes[chosen[k]]) < 2]
    if few:
        raise ValueError(
            f"Expected at least 2 samples along every dim (a surface needs a cell to cross), got "
            f"{', '.join(few)}; dims {dict((d, int(da.sizes[d])) for d in dims)}. A single time step is a "
            f"3-D field, not a 4-D one: select a range, e.g. da.isel({chosen['w']}=slice(0, 2))")
    meta_range = metadata_range(getattr(da, "attrs", None), getattr(da, "encoding", None), getattr(da, "dtype", None))
    if ds is not None:
        origin = _dataset_origin(ds, variable, da, chosen)
    else:
        found = _encoding_origin(da, chosen)
        origin = (found, None) if found is not None else (None, (
            "a DataArray does not say which file it came from (xarray's netCDF4 and h5netcdf engines write it "
            "into its encoding; scipy, which xarray uses when netCDF4 is not installed, and zarr do not)"))
    flips, coords, extent = {}, [None] * 4, []
    epoch = None
    for d_i, k in enumerate(AXES):
        dim = chosen[k]
        n = int(da.sizes[dim])
        if dim in da.coords:
            c = np.asarray(da.coords[dim].values)
            if k == "w" and np.issubdtype(c.dtype, np.datetime64):  # seconds from the first; shown as dates
                epoch = c.min()
            if np.issubdtype(c.dtype, np.datetime64) or np.issubdtype(c.dtype, np.timedelta64):
                c = (c - c.min()) / np.timedelta64(1, "s")
            try:
                c = np.asarray(c, dtype=np.float64)
            except (TypeError, ValueError):
                raise TypeError(f"Expected numeric or datetime coordinates for {dim!r}, got dtype {c.dtype}") from None
            if c.shape != (n,) or not np.all(np.isfinite(c)):
                raise ValueError(f"Expected finite 1-D coordinates for {dim!r}")
        else:
            c = np.arange(n, dtype=np.float64)
        dc = np.diff(c)
        if n >= 2 and np.all(dc < 0):
            flips[dim] = slice(None, None, -1)
            c, dc = c[::-1], -dc[::-1]
        if not np.all(dc > 0):
            raise ValueError(f"Expected the coordinates of {dim!r} to be strictly monotonic, got {c.tolist()[:8]}...")
        extent.append((float(c[0]), float(c[-1])))
        uniform = np.allclose(dc, (c[-1] - c[0]) / (n - 1), rtol=1e-6, atol=0)
        coords[d_i] = None if uniform else _sealed(c.copy())
    if flips:
        da = da.isel(flips)
    if w_per_unit is None:
        sp = np.mean([(b - a) / (int(da.sizes[chosen[k]]) - 1) for k, (a, b) in zip("xyz", extent)])
        w_per_unit = ((extent[3][1] - extent[3][0]) / (int(da.sizes[chosen["w"]]) - 1)) / sp
    values = _xarray_values(da)
    units = da.attrs.get("units")
    w_units = kwargs.pop("w_units", da.coords[chosen["w"]].attrs.get("units") if chosen["w"] in da.coords else None)
    if w_units is None and chosen["w"] in da.coords and np.issubdtype(da.coords[chosen["w"]].dtype, np.datetime64):
        w_units = "s"
    space = {da.coords[chosen[k]].attrs.get("units") if chosen[k] in da.coords else None for k in "xyz"}
    space_units = kwargs.pop("space_units", space.pop() if len(space) == 1 else None)
    args = dict(axes=axes, extent=extent, name=kwargs.pop("name", da.name), units=kwargs.pop("units", units),
                w_per_unit=w_per_unit, w_units=w_units, _coords=coords, space_units=space_units)
    if epoch is not None:
        args["_w_epoch"] = epoch
    _warn_missing_units(args, chosen, da)
    return values, args, dims, meta_range, origin, _long_name(getattr(da, "attrs", None))


def _warn_missing_units(args, chosen, da) -> None:
    """One `UnitsWarning` naming what has no units -- the values, x, y, z (or their disagreeing
    units), w -- and the xarray attribute (or keyword) that gives them: the readout, the labels and
    the exports would show bare numbers.  (A state file reopening the data says it no more:
    `rot4d_widget.keep.rebuild`.)"""
    name = repr(str(da.name)) if da.name is not None else "the DataArray"
    fixes = []
    if args["units"] is None:
        fixes.append("the values (set da.attrs['units'], e.g. 'K', or pass units=...)")
    if args["space_units"] is None:
        dims = [chosen[k] for k in "xyz"]
        found = {d: (da.coords[d].attrs.get("units") if d in da.coords else None) for d in dims}
        if len({u for u in found.values() if u is not None}) > 1:
            fixes.append(f"x, y and z together (their units disagree: {found}; pass space_units=...)")
        else:
            lacking = [d for d, u in found.items() if u is None]
            fixes.append(f"{', '.join(lacking)} (set " + ", ".join(f"da[{d!r}].attrs['units']" for d in lacking)
                         + " to one unit, e.g. 'm', or pass space_units=...)")
    if args["w_units"] is None:
        fixes.append(f"w, {chosen['w']} (set da[{chosen['w']!r}].attrs['units'], e.g. 's', or pass w_units=...)")
    if fixes:
        warnings.warn(f"Field4D.from_xarray: {name} has no units for " + "; for ".join(fixes)
                      + ". Until they are given, the readout, the box labels and the exports show bare numbers.",
                      UnitsWarning, stacklevel=4)


def _long_name(attrs):
    """A variable's descriptive name, CF's ``long_name`` attribute ("sea surface temperature"), as
    `Field4D.long_name` keeps it for the colour bar (its label; ``name`` is the short variable
    name): a string, or None when the attribute is absent or blank."""
    v = (attrs or {}).get("long_name")
    if v is None:
        return None
    v = v.decode() if isinstance(v, bytes) else str(v)
    return v if v.strip() else None


def open_dataarray(path, variable, engine, chunks, isel, sel, load):
    """``(da, record)`` for `Field4D.open`: ``variable`` of the file or store at ``path``, selected
    (isel, then sel) and loaded as asked, and where it came from (``record``: kind, path,
    variable, engine, chunks, isel, sel as JSON; `Field4D.open` adds the dims and ``load``)."""
    import xarray  # optional: only opening a file needs it

    p = os.path.abspath(os.fspath(path))
    if engine is None and (os.path.isdir(p) or p.rstrip("/").endswith(".zarr")):
        engine = "zarr"
    rec_isel = _selection_json(isel, "isel")
    rec_sel = _selection_json(sel, "sel")
    rec_chunks = _chunks_json(chunks)
    ds = xarray.open_dataset(p, engine=engine, chunks=chunks)
    if variable is None:
        names = list(ds.data_vars)
        if len(names) != 1:
            raise ValueError(f"{os.fspath(path)!r} has data variables {names}; name one: "
                             f"Field4D.open(path, variable)")
        variable = names[0]
    if variable not in ds.data_vars:
        raise ValueError(f"{os.fspath(path)!r} has no data variable {variable!r}; it has {list(ds.data_vars)}")
    da = ds[variable]
    if isel:
        da = da.isel(isel)
    if sel:
        da = da.sel(sel)
    if load:
        da = da.load()
    record = {"kind": "xarray", "path": p, "variable": str(variable), "engine": engine,
              "chunks": rec_chunks, "isel": rec_isel, "sel": rec_sel}
    return da, record
