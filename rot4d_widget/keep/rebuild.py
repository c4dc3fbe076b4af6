"""Sources described for a state file and rebuilt from the description.

`describe_source` is a source's ``describe()`` (the source protocol's: everything rebuilding it
needs and ``"rebuild"``: True or why it cannot be rebuilt), a stack's inner source described the
same way; `rebuild_source` makes the source again from the kinds it knows (a polytope, a stack, a
field from a module-level function or the file it was opened from).  A description is data:
rebuilding imports nothing it names unless the caller allows it (`CodeNotAllowed`).
"""

from __future__ import annotations

import importlib
import math
import os
import warnings
from typing import Mapping

import numpy as np

from ..geometry.catalogue import polytope
from ..geometry.mesh import Polytope
from ..sources.field.checks import UnitsWarning
from ..sources.field.inputs import selection_from_json
from ..sources.protocol import PolytopeSource, as_source, class_name
from ..sources.tomography import StackSource


class SourceNotRebuildable(UserWarning):
    """A source that a state file describes but cannot rebuild (an in-memory array, a lambda,
    a user's own source): loading the file needs the source passed in."""


class CodeNotAllowed(ValueError):
    """A state file names code (a field's ``"module:qualname"`` function) and the caller did not
    allow importing it: pass ``allow_code=True`` (a file you trust), the function
    (``function=f``) or the source (``source=...``)."""


#: Module paths of the package from before the wings (issue 20) -> where that code is now.  A
#: state file names a field's function by ``"module:qualname"``; one written before the wings can
#: name package code by an old path, which the package no longer imports (issue 38: no import
#: hook before 1.0), so the loader translates it with this table -- data, nothing imported.
#: Every flat module path is here except ``rot4d_widget.recording`` and ``rot4d_widget.figures``,
#: whose code is now spread over several modules of keep (no one place to send them).
OLD_MODULES = {
    "rot4d_widget.rotation": "rot4d_widget.core.rotation",
    "rot4d_widget.keymap": "rot4d_widget.core.keymap",
    "rot4d_widget.state": "rot4d_widget.core.state",
    "rot4d_widget._arrays": "rot4d_widget.core._arrays",
    "rot4d_widget.progress": "rot4d_widget.core.progress",
    "rot4d_widget.polytopes": "rot4d_widget.geometry.catalogue",
    "rot4d_widget.uniform": "rot4d_widget.geometry.uniform",
    "rot4d_widget.slicing": "rot4d_widget.geometry.slicing.polytope_slice",
    "rot4d_widget.offfile": "rot4d_widget.geometry.offfile",
    "rot4d_widget.source": "rot4d_widget.sources.protocol",
    "rot4d_widget.fields": "rot4d_widget.sources.field.container",
    "rot4d_widget.tomography": "rot4d_widget.sources.tomography",
    "rot4d_widget.datasets": "rot4d_widget.sources.datasets",
    "rot4d_widget.export": "rot4d_widget.keep.statefile",
    "rot4d_widget.widget": "rot4d_widget.view.widget",
    "rot4d_widget.scene": "rot4d_widget.view.scene",
    "rot4d_widget.buffers": "rot4d_widget.view.buffers",
    "rot4d_widget.companion": "rot4d_widget.view.companion",
    "rot4d_widget.pump": "rot4d_widget.view.pump",
    "rot4d_widget.keyhold": "rot4d_widget.view.keyhold",
    "rot4d_widget.readout": "rot4d_widget.view.markup",
}


def module_now(module: str) -> str:
    """Where the module a state file names is now: `OLD_MODULES`'s entry for an old path of the
    package (or of a module under it), else ``module`` itself.

    >>> module_now("rot4d_widget.fields"), module_now("mylab.fields")
    ('rot4d_widget.sources.field.container', 'mylab.fields')
    """
    for old, new in OLD_MODULES.items():
        if module == old or module.startswith(old + "."):
            return new + module[len(old):]
    return module


class CannotRebuild(ValueError):
    """`rebuild_source`: the description is fine, the source just cannot be made from it."""

# ============================================================================ sources
def describe_source(source) -> dict:
    """``source.describe()`` -- everything `rebuild_source` needs (the source protocol's ``describe``)
    -- with ``"rebuild"``: True, or the reason it cannot be rebuilt.

    Nothing here depends on the source's class: a polytope's description keeps the vertices, faces
    and cells of one that is not a named polytope as `polytope(name)` builds it, a field's its
    resolutions, w units and how to reopen it -- each source says so itself.  A source that wraps
    another (a stack: the protocol's ``wraps``) has its inner source described the same way and
    is rebuildable exactly when that one is.  A description without ``"rebuild"`` can be rebuilt
    when `rebuild_source` knows its kind (a polytope, a stack, a field), else it carries the reason.
    """
    source = as_source(source)
    d = dict(source.describe())
    inner = source.wraps
    if inner is not None:
        d["source"] = describe_source(inner)
        d["rebuild"] = d["source"]["rebuild"]
        return d
    if "rebuild" not in d:
        kind = d.get("kind", class_name(source))
        d["rebuild"] = (True if kind in _KNOWN_KINDS
                        else f"a source of kind {kind!r} cannot be rebuilt from its description")
    return jsonable(d, "source.describe()")


#: The kinds of description `rebuild_source` can make a source from.
_KNOWN_KINDS = ("polytope", "stack", "field")


def rebuild_source(description: Mapping, *, allow_code: bool = False, function=None, base=None):
    """The source a `describe_source` dict describes.

    ``ValueError`` says why it cannot be rebuilt and what to do (pass the source to
    `load_state`), or what is wrong with the description (an unknown polytope name ...).
    A field described by a function's name (``"module:qualname"``) is rebuilt with ``function``
    if given (a callable ``f(x, y, z, w)``), else by importing the name only when
    ``allow_code`` is True; otherwise `CodeNotAllowed` (a ValueError) says how to allow it.
    Nothing else in a description is ever imported or called.  A field opened from a file
    (``"origin"``) is reopened by path, with xarray (data only): its ``"relative_path"`` under
    ``base`` (the state file's folder) when that exists, else its absolute ``"path"``.
    """
    if function is not None and not callable(function):
        raise TypeError(f"Expected `function` to be a callable f(x, y, z, w), got {type(function).__name__}")
    if not isinstance(description, Mapping) or "kind" not in description:
        raise ValueError(f"Expected a source description with a 'kind', got {description!r}")
    kind = description["kind"]
    why = description.get("rebuild", True)
    if kind == "polytope":
        if "vertices" in description:
            faces, cells = description.get("faces"), description.get("cells")
            return PolytopeSource(Polytope(np.asarray(description["vertices"], dtype=np.float64),
                                           None if faces is None else [np.asarray(f, dtype=np.intp) for f in faces],
                                           None if cells is None else [tuple(c) for c in cells],
                                           name=str(description.get("name", "polytope"))))
        return PolytopeSource(polytope(description["name"]))
    if kind == "stack":
        inner = rebuild_source(description["source"], allow_code=allow_code, function=function, base=base)
        return StackSource(inner, slices=description["slices"], spacing=description.get("spacing"),
                           arrangement=description.get("arrangement", "oval"),
                           color_by=description.get("color_by", "w"))
    if why is not True:
        raise CannotRebuild(f"The state file's source cannot be rebuilt: {why}. "
                         "Pass it in: load_state(path, source=...)")
    if kind == "field":
        return _rebuild_field(description, allow_code, function, base)
    raise CannotRebuild(f"Unknown source kind {kind!r}; pass the source in: load_state(path, source=...)")


#: The `Field4D.from_xarray` keywords an origin's ``"kwargs"`` may carry (files written by
#: `open_field` before version 2 keep the dims and any of these there).
_ORIGIN_KWARGS = ("x", "y", "z", "w", "w_per_unit", "name", "units", "w_units", "space_units", "resolution",
                  "coarse_resolution", "levels", "inside", "caps", "chunk_cache_bytes")


def _origin_path(origin, base):
    """The data file an origin names: its ``"relative_path"`` beside the state file (``base``, the
    state file's folder) when that exists, else its absolute ``"path"``; `CannotRebuild` naming
    both when neither exists."""
    path = origin.get("path")
    rel = origin.get("relative_path")
    for name, value in (("path", path), ("relative_path", rel)):
        if value is not None and not isinstance(value, str):
            raise ValueError(f"Expected the origin's {name!r} to be a string, got {value!r}")
    if not path and not rel:
        raise ValueError("Expected the field's origin to have a 'path'")
    tried = []
    if rel and base is not None:
        cand = os.path.normpath(os.path.join(base, rel))
        if os.path.exists(cand):
            return cand
        tried.append(cand)
    if path:
        if os.path.exists(path):
            return path
        tried.append(path)
    raise CannotRebuild(f"the field's data are not found at {' or '.join(map(repr, tried))}; put the file "
                        "back, or open it and pass it in: load_state(path, source=Field4D.open(...))")


def _open_origin(origin, base):
    # sources.field.container imports numba and scikit-image (~0.5 s): only a field's rebuild needs it
    from ..sources.field.container import Field4D

    origin = dict(origin)
    if origin.get("kind", "xarray") != "xarray":
        raise ValueError(f"Unknown field origin kind {origin.get('kind')!r}")
    path = _origin_path(origin, base)
    engine = origin.get("engine")
    if engine is not None and not (isinstance(engine, str) and engine.isidentifier()):
        raise ValueError(f"Expected the origin's 'engine' to be an xarray engine's name, got {engine!r}")
    chunks = origin.get("chunks")
    if not (chunks is None or isinstance(chunks, (str, int)) or (
            isinstance(chunks, dict) and all(c is None or isinstance(c, (int, str)) for c in chunks.values()))):
        raise ValueError(f"Expected the origin's 'chunks' to be None, a string, an int or a dict, got {chunks!r}")
    kwargs = origin.get("kwargs") or {}
    if not isinstance(kwargs, Mapping) or any(k not in _ORIGIN_KWARGS for k in kwargs):
        raise ValueError(f"Expected the origin's 'kwargs' to name only {', '.join(_ORIGIN_KWARGS)}, got {kwargs!r}")
    kwargs = dict(kwargs)
    variable = origin.get("variable")
    if variable is not None and not isinstance(variable, str):
        raise ValueError(f"Expected the origin's 'variable' to be a string, got {variable!r}")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", category=RuntimeWarning)  # zarr: no consolidated metadata
            warnings.simplefilter("ignore", category=UnitsWarning)  # said when the field was first made
            field = Field4D.open(path, variable, engine=engine, chunks=chunks,
                                 isel=selection_from_json(origin.get("isel"), "isel"),
                                 sel=selection_from_json(origin.get("sel"), "sel"),
                                 load=bool(origin.get("load", False)), **kwargs)
    except (OSError, KeyError, IndexError) as exc:
        raise CannotRebuild(f"the field's data at {path!r} cannot be opened as saved ({type(exc).__name__}: "
                            f"{exc}); open it and pass it in: load_state(path, source=...)") from None
    return field


def _rebuild_field(d, allow_code=False, function=None, base=None):
    # sources.field.container imports numba and scikit-image (~0.5 s): only a field's rebuild needs it
    from ..sources.field.container import Field4D

    common = dict(name=d.get("name"), units=d.get("units"), w_per_unit=d.get("w_per_unit"))
    if d.get("w_units") is not None:
        common["w_units"] = d["w_units"]
    if d.get("space_units") is not None:
        common["space_units"] = d["space_units"]
    if "origin" in d:
        field = _open_origin(d["origin"], base)
        _same_data(field, d)
        field.w_per_unit = d["w_per_unit"]
        for attr in ("name", "units", "w_units", "space_units"):
            if attr in d:
                setattr(field, attr, None if d[attr] is None else str(d[attr]))
    elif function is not None:
        field = Field4D.from_function(function, d["extent"], **common)
    else:
        spec = d.get("function")
        if not spec or not isinstance(spec, str):
            raise ValueError(f"Expected a field described by a file ('origin') or by a function's name "
                             f"('function': 'module:qualname'), got 'function': {spec!r}")
        if not allow_code:
            raise CodeNotAllowed(
                f"The state file's field is made by the Python function {spec!r}: loading it would import "
                "and run that code, which a state file does not do unless asked. If you trust the file, "
                "pass allow_code=True (load_state(path, allow_code=True)); or pass the function, "
                "load_state(path, function=f), or the source, load_state(path, source=...)")
        module, _, qual = spec.partition(":")
        try:
            obj = importlib.import_module(module_now(module))
            for part in qual.split("."):
                obj = getattr(obj, part)
        except (ImportError, AttributeError, ValueError) as exc:
            raise CannotRebuild(f"The field's function {spec!r} cannot be imported ({exc}); "
                             "pass the source in: load_state(path, source=...)") from None
        field = Field4D.from_function(obj, d["extent"], **common)
    for attr in ("resolution", "coarse_resolution", "chunk_cache_bytes"):
        if d.get(attr) is not None:
            setattr(field, attr, d[attr])
    for attr in ("inside", "caps"):  # files before version 2 have neither: the defaults
        if attr in d:
            setattr(field, attr, d[attr])
    if d.get("levels"):
        field.levels = d["levels"]
    return field


def _same_data(field, d) -> None:
    """`CannotRebuild` when a reopened file no longer holds what was saved: another shape, axis
    order or extent (the file was rewritten, or the saved field was a selection xarray's
    encoding did not show)."""
    got = {"shape": [int(n) for n in field.values.shape], "axes": field.axes,
           "extent": [[float(a), float(b)] for a, b in field.extent]}
    for key, value in got.items():
        want = d.get(key)
        if want is None:
            continue
        if key == "extent":
            same = np.allclose(np.asarray(want, dtype=np.float64), np.asarray(value), rtol=1e-12, atol=0)
        else:
            same = want == value
        if not same:
            raise CannotRebuild(f"the file {field.origin.get('path')!r} no longer holds the saved field: its "
                                f"{key} is {value}, the state file's {want}; open the data as they were and pass "
                                "them in: load_state(path, source=...)")


def open_field(path, variable=None, *, engine=None, **kwargs):
    """`Field4D.open`: ``variable`` of the netCDF file or zarr store at ``path`` as a field that
    remembers where it came from (``field.origin``), so a state file reopens it.

    ``variable`` may be omitted when the dataset has one data variable; ``engine`` goes to
    ``xarray.open_dataset`` (a directory or a path ending in ``.zarr`` opens with ``"zarr"``);
    ``chunks=``, ``isel=``, ``sel=`` and the keywords of `Field4D.from_xarray`
    (``x=, y=, z=, w=, w_per_unit=`` ...) as in `Field4D.open`.
    """
    # sources.field.container imports numba and scikit-image (~0.5 s): only opening a field needs it
    from ..sources.field.container import Field4D

    return Field4D.open(path, variable, engine=engine, **kwargs)


def made_by_function(d) -> bool:
    """Whether a source description is (a stack of) a field made by a function."""
    while isinstance(d, Mapping) and d.get("kind") == "stack":
        d = d.get("source")
    return isinstance(d, Mapping) and d.get("kind") == "field" and "origin" not in d and bool(d.get("function"))


def described_w_frame(desc):
    """``(origin, per_unit)`` of c0 for the source a state file describes (`describe_source`): a
    field's (w at its box's centre, ``w_per_unit``), also inside stacks; None for any other (a
    polytope's c0 is its own w) or a description without them."""
    d = desc
    while isinstance(d, Mapping) and d.get("kind") == "stack":
        d = d.get("source")
    if not isinstance(d, Mapping) or d.get("kind") != "field":
        return None
    try:
        lo, hi = (float(v) for v in d["extent"][3])
        per = float(d["w_per_unit"])
    except (KeyError, TypeError, ValueError, IndexError):
        return None
    if not (math.isfinite(lo) and math.isfinite(hi) and math.isfinite(per) and per > 0):
        return None
    return (lo + hi) / 2, per


def inner_identity(d):
    while d.get("kind") == "stack":
        d = d.get("source", {})
    return d.get("kind"), d.get("name") if d.get("kind") == "polytope" else None


# ============================================================================ state files
def jsonable(value, where: str):
    """``value`` with tuples as lists and numpy scalars/arrays as Python numbers/lists; TypeError
    naming ``where`` for anything JSON cannot hold (NaN and infinities included)."""
    if isinstance(value, Mapping):
        out = {}
        for k, v in value.items():
            if not isinstance(k, str):
                raise TypeError(f"Expected string keys in {where}, got {k!r}")
            out[k] = jsonable(v, f"{where}[{k!r}]")
        return out
    if isinstance(value, (list, tuple)):
        return [jsonable(v, f"{where}[{i}]") for i, v in enumerate(value)]
    if isinstance(value, np.ndarray):
        return jsonable(value.tolist(), where)
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        if not math.isfinite(value):
            raise TypeError(f"{where} = {value}: a state file holds finite numbers only")
        return float(value)
    if value is None or isinstance(value, str):
        return value
    raise TypeError(f"{where} is a {type(value).__name__}, which a JSON state file cannot hold")
