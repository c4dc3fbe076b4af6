"""Keep what you see: the slice as a mesh (trimesh) and the state as a JSON file.

Meshes
    `slice_mesh(data)` turns what a source's ``slice(matrix, c0)`` returned -- a polytope's
    slice, a field's isosurfaces, a stack of parallel slices, or a list of any of them -- into
    one `trimesh.Trimesh`: the triangles of every face, concatenated, in the source's own units
    (see `slice_mesh` for what a unit is for each kind; a field's in the data's units, at the
    data's place, each vertex's 4-D data coordinates in ``mesh.vertex_attributes["data_xyzw"]``),
    each face keeping its colour group
    (``mesh.face_attributes["group"]``: a polytope's 4-D cell, a field's level index, a stack's
    slice index when coloured by w) and its colour (``mesh.visual.face_colors``, the live view's
    palette from `rot4d_widget.core.look`).  ``mesh.export(path)`` writes OBJ, PLY, STL or GLB by the
    extension (trimesh's own writers); what each keeps is listed in `MESH_FORMATS`.
    `load_mesh(path)` reads one back with the groups a PLY file carries.

State files
    `save_state(path, state, source, settings)` writes a JSON file with the `RotationState`
    (`RotationState.to_dict`), what the source is (`describe_source`: the source's
    ``describe()`` plus what rebuilding it needs), the widget's settings (levels, slices,
    display options: any JSON-able dict) and a format version; `load_state(path)` reads it
    back as ``(state, source or None, settings)``.  A polytope is rebuilt from its name (or its
    vertices); a stack from its inner source and its settings; a `Field4D` from a module-level
    function (``module.name``) or from the file it was opened from (``field.origin``:
    `Field4D.open` / `open_field`, or `Field4D.from_xarray` when xarray's encoding names the
    file), by its path relative to the state file when the data sit in its folder, else its
    absolute path, with the selection and dims it was opened with; its levels, ``inside``,
    ``caps``, ``w_per_unit`` and resolution restored.  An in-memory array is not written into
    the file: saving says so (`SourceNotRebuildable` warning) and loading then needs the source
    passed in (``load_state(path, source=field)``).  Files are written as version 1 unless a
    field needs what a version-1 reader would silently drop (a selection, ``inside="below"``,
    ``caps=False``: version 2); both versions load.

    A state file is data, never code: loading one imports no module and calls nothing the file
    names.  A field made from a function is described by the function's name
    (``"module:qualname"``); `load_state` refuses to import it (`CodeNotAllowed`, a ValueError
    saying how to allow it) unless asked: ``load_state(path, allow_code=True)`` for a file you
    trust, ``load_state(path, function=f)`` to give the function yourself, or
    ``load_state(path, source=field)``.

numpy, trimesh (and xarray to reopen a field's file); nothing here knows about widgets.
"""

from __future__ import annotations

import importlib
import json
import math
import os
import secrets
import stat
import warnings
from typing import Mapping, NamedTuple

import numpy as np

from ..core import look
from ..core.state import RotationState

__all__ = [
    "MESH_FORMATS",
    "STATE_FILE_FORMAT",
    "STATE_FILE_VERSION",
    "SourceNotRebuildable",
    "CodeNotAllowed",
    "LoadedState",
    "slice_mesh",
    "face_colors",
    "load_mesh",
    "describe_source",
    "rebuild_source",
    "open_field",
    "save_state",
    "load_state",
    "SETTING_NAMES",
    "settings_of",
]

#: The widget's settings a state file keeps, by their trait names (`settings_of` reads them;
#: `rot4d_widget.keep.figures.render_state` takes them as keywords).
SETTING_NAMES = ("levels", "inside", "caps", "slices", "spacing", "arrangement", "color_by", "face_opacity", "ball_radius",
                 "bar_radius", "background", "show_balls", "show_bars", "show_faces")

#: What trimesh's writers keep of a `slice_mesh`, by extension.  Vertices are written as
#: float32 by every format (float64 in none).
MESH_FORMATS = {
    ".ply": "vertices, faces, per-face RGBA colours and the face attribute 'group' (a face property "
            "'int group'; `load_mesh` puts it back in face_attributes); a field's vertex attribute "
            "'data_xyzw' (a vertex property 'list uchar double', float64 in binary PLY; `load_mesh` puts "
            "it back in vertex_attributes)",
    ".obj": "vertices, faces, per-vertex colours (a face colour averaged over the faces at a vertex: "
            "use separate_groups=True to keep every face's colour exact); no groups",
    ".glb": "vertices, faces, per-vertex colours (as OBJ); no groups; 'data_xyzw' as the float32 "
            "attribute '_data_xyzw'",
    ".stl": "faces only (a triangle soup: trimesh merges equal vertices on loading); no colours, no groups",
}

#: ``"format"`` and ``"version"`` of a state file.
STATE_FILE_FORMAT = "rot4d_widget state"
STATE_FILE_VERSION = 2


class SourceNotRebuildable(UserWarning):
    """A source that a state file describes but cannot rebuild (an in-memory array, a lambda,
    a user's own source): loading the file needs the source passed in."""


class CodeNotAllowed(ValueError):
    """A state file names code (a field's ``"module:qualname"`` function) and the caller did not
    allow importing it: pass ``allow_code=True`` (a file you trust), the function
    (``function=f``) or the source (``source=...``)."""


class _CannotRebuild(ValueError):
    """`rebuild_source`: the description is fine, the source just cannot be made from it."""


# ============================================================================ meshes
def _is_stack_data(data) -> bool:
    ex = getattr(data, "extra", None) or {}
    return "triangle_offsets" in ex and "centres" in ex


def _is_field_data(data) -> bool:
    ex = getattr(data, "extra", None) or {}
    return "levels" in ex and "box" in ex


def face_colors(data, *, color_by="group", group_colors=None) -> np.ndarray:
    """(k, 3) float64 in [0, 1]: the colour of each triangle of ``data`` as the live view draws it.

    ``color_by`` is the widget's: ``"group"`` or one colour for every face (``"#9fb6cd"``).
    Groups are coloured by ``group_colors`` (one colour per group) if given, else as the widget
    chooses: a stack coloured by w by its levels' colormap, a field by its levels' colormap
    (`look.level_colors`), anything else by `look.group_palette` (a polytope's cells).
    """
    data = _as_slice_data(data)
    groups = np.asarray(data.groups, dtype=np.intp)
    if color_by != "group":
        return np.tile(np.asarray(look.as_rgb(color_by, "color_by"), dtype=np.float64), (len(groups), 1))
    n = int(groups.max()) + 1 if len(groups) else 0
    if group_colors is not None:
        palette = np.array([look.as_rgb(c, f"group_colors[{i}]") for i, c in enumerate(group_colors)],
                           dtype=np.float64).reshape(-1, 3)
    elif _is_stack_data(data) and data.extra.get("group_rgb") is not None:
        palette = np.asarray(data.extra["group_rgb"], dtype=np.float64)
    elif _is_field_data(data) and len(data.extra["levels"]):
        levels = [s.level for s in data.extra["levels"]]
        palette = look.level_colors(levels, min(levels), max(levels))
    else:
        palette = look.group_palette(n).astype(np.float64)
    if n > len(palette):
        raise ValueError(f"Expected a colour for every group (0 ... {n - 1}), got {len(palette)} colours")
    return palette[groups].reshape(-1, 3)


def _as_slice_data(obj):
    """A bare `Slice` (slice_polytope) or `FieldSlice` (slice_field) as slice data; else as is."""
    from ..sources.fields import FieldSlice
    from ..geometry.slicing import Slice
    from ..sources.protocol import SliceData

    if isinstance(obj, Slice):
        return SliceData.build(obj.vertices, obj.edges, obj.triangles, obj.triangle_cells, volume=float(obj.volume),
                               extra={"slice": obj})
    if isinstance(obj, FieldSlice):
        return SliceData.build(obj.vertices, None, obj.triangles, None, volume=float(obj.volume))
    return obj


def _data_frame(data):
    """(matrix (4, 4), d, centre (4,), unit (4,)) of what a slice offers as ``extra["data_frame"]``
    (a `Field4D`'s: a point p of the cut, d slice units along the turned w axis from the box's
    centre, is at data ``centre + (matrix.T @ (p, d)) * unit``), or
    None when it offers none, or not a usable one."""
    ex = getattr(data, "extra", None)
    fr = ex.get("data_frame") if isinstance(ex, Mapping) else None
    if not isinstance(fr, Mapping):
        return None
    try:
        m = np.asarray(fr["matrix"], dtype=np.float64)
        c0 = float(fr["d"])
        centre = np.asarray(fr["centre"], dtype=np.float64)
        unit = np.asarray(fr["unit"], dtype=np.float64)
    except (KeyError, TypeError, ValueError):
        return None
    if m.shape != (4, 4) or centre.shape != (4,) or unit.shape != (4,):
        return None
    if not (np.all(np.isfinite(m)) and math.isfinite(c0) and np.all(np.isfinite(centre))
            and np.all(np.isfinite(unit)) and np.all(unit > 0)):
        return None
    return m, c0, centre, unit


def _to_data(points, frame) -> np.ndarray:
    """(n, 4) data coordinates of slice points (n, 3) in a `_data_frame`."""
    m, c0, centre, unit = frame
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    return centre + (np.column_stack([p, np.full(len(p), c0)]) @ m) * unit


def _data_coordinates(data, n_points):
    """(xyzw (n, 4) per point, or None; (scale (3,), shift (3,)) to the data's frame, or None).

    A slice with a data frame (a field's): its points' data coordinates.  A stack: each slice's
    points from its own slice's frame (``extra["slices"]``, row for row), when every slice has one.
    """
    if _is_stack_data(data):
        ex = data.extra
        pieces = ex.get("slices") or ()
        off = np.asarray(ex.get("point_offsets", ()), dtype=np.intp)
        frames = [_data_frame(pc) for pc in pieces]
        if not pieces or len(off) != len(pieces) + 1 or off[-1] != n_points or any(f is None for f in frames):
            return None, None
        out = np.empty((n_points, 4))
        for k, (pc, fr) in enumerate(zip(pieces, frames)):
            pts = np.asarray(pc.points, dtype=np.float64).reshape(-1, 3)
            if len(pts) != off[k + 1] - off[k]:
                return None, None
            out[off[k]:off[k + 1]] = _to_data(pts, fr)
        return out, (frames[0][3][:3], frames[0][2][:3])
    fr = _data_frame(data)
    if fr is None:
        return None, None
    return _to_data(data.points, fr), (fr[3][:3], fr[2][:3])


def _one_mesh_arrays(data, color_by, group_colors):
    """vertices (n, 3), faces (k, 3), rgb (k, 3), attributes {name: (k,)}, volume or None, kind,
    data coordinates (n, 4) or None, (scale, shift) to the data's frame or None."""
    data = _as_slice_data(data)
    try:
        points = np.asarray(data.points, dtype=np.float64).reshape(-1, 3)
        tris = np.asarray(data.triangles, dtype=np.intp).reshape(-1, 3)
        groups = np.asarray(data.groups, dtype=np.intp).reshape(-1)
    except AttributeError:
        raise TypeError(
            "Expected slice data (what a source's slice(matrix, c0) returns: points, triangles, groups), "
            f"got {type(data).__name__}"
        ) from None
    rgb = face_colors(data, color_by=color_by, group_colors=group_colors)
    attrs = {"group": groups}
    if _is_stack_data(data):
        ex = data.extra
        toff = np.asarray(ex["triangle_offsets"])
        attrs["slice"] = np.repeat(np.arange(len(toff) - 1), np.diff(toff))
        scales = np.asarray(ex["scales"], dtype=np.float64)
        vols = ex.get("volumes", ())  # each slice drawn scaled by scales[k] (1 for a single slice)
        volume = None if any(v is None for v in vols) else float(sum(s**3 * v for s, v in zip(scales, vols)))
        kind = "stack"
    elif _is_field_data(data):
        volume = float(sum(s.volume for s in data.extra["levels"]))
        kind = "field"
    else:
        v = getattr(data, "volume", None)
        volume = None if v is None else float(v)
        kind = "polytope" if hasattr(data, "extra") and "slice" in data.extra else "slice"
    xyzw, to_frame = _data_coordinates(data, len(points))
    return points, tris, rgb, attrs, volume, kind, xyzw, to_frame


def slice_mesh(data, *, color_by="group", group_colors=None, separate_groups: bool = False,
               opacity: float = 1.0, frame: str = "data"):
    """One `trimesh.Trimesh` of the faces of a slice (or of several), as the live view colours them.

    Parameters
    ----------
    data : slice data, or a sequence of them
        What a source's ``slice(matrix, c0)`` returns (or a bare `Slice` from `slice_polytope`,
        a `FieldSlice` from `slice_field`): a polytope's slice (its triangles, the
        polygons fanned, grouped by 4-D cell), a `Field4D`'s (the isosurface of every level,
        grouped by level index), a `StackSource`'s (the N parallel slices placed as the view
        places them, grouped by slice index when coloured by w, else by cell / level).  A
        sequence is concatenated in order.
    color_by, group_colors :
        As the widget's ``color_by`` (``"group"`` or one colour) and ``group_colors``
        (see `face_colors`).
    separate_groups : bool
        False: one vertex per slice vertex (each slice's surface closed and watertight).
        True: a vertex shared by faces of different groups is repeated for each group, so the
        formats that keep only vertex colours (OBJ, GLB) show every face in its own colour.
    opacity : float in [0, 1]
        The colours' alpha (default opaque; the live view draws polytope faces at
        `look.FACE_OPACITY`).
    frame : "data" (default) or "view"
        Where a slice that knows its data coordinates (a `Field4D`'s, a stack of them: any slice
        data whose ``extra["data_frame"]`` gives the cut's ``matrix``, offset ``d`` and the data's
        ``centre`` and ``unit``, see `rot4d_widget.sources.fields.Field4D.slice`) puts its vertices.
        ``"data"``: in the data's units at the data's place -- the view's 3-D picture scaled by
        the data's units of x, y, z (1 for a field) and moved by the data box's centre, so at
        rest (identity orientation) a vertex is at its data (x, y, z).  After a turn the 3
        coordinates stay the slice's own frame (the picture the view shows, not turned back;
        an axis the turn mixes w into counts w in units of ``w_per_unit``, as in the view),
        only moved to the data's centre: the mesh's shape and volume are the slice's.
        ``"view"``: the view's slice coordinates, as before (centred on the box, w scaled).
        Other slices (polytopes, user sources without a data frame) are the same in both.

    Returns
    -------
    trimesh.Trimesh (built with ``process=False``: nothing merged, reordered or dropped but the
    points no face uses -- balls and bars are not part of it, nor a field's box outline).

    * ``mesh.vertices`` (n, 3) float64 in the source's own units: a polytope's vertex
      coordinates (the six regular ones have edge 2); a field's data units, at the data's place
      (``frame="data"``, above), or with ``frame="view"`` its *slice units* -- x, y, z in the
      data's units about the centre of its box, the w axis counted in units of
      ``field.w_per_unit`` (a turn mixes them); a stack in its inner source's units, slice k
      moved to its place and shrunk by its scale (``data.extra["centres"]``,
      ``data.extra["scales"]``) as in the view -- with ``frame="data"`` a stack of field slices
      keeps that layout, moved as a whole by the data box's centre (so one slice is placed as
      a field's).
    * ``mesh.vertex_attributes["data_xyzw"]`` (n, 4) float64, when every slice knows its data
      coordinates (a field's, a stack of a field's; not a polytope's), in either ``frame``:
      each vertex's 4-D data coordinates (x, y, z, w in the data's own units), the slice point
      p of the cut w = c0 rotated back, ``centre + (matrix.T @ (p, d)) * (1, 1, 1, w_per_unit)`` with
      d = (c0 - centre_w) / w_per_unit the cut's offset in slice units
      (`Field4D.to_data`); a stack's vertices each from its own slice's level.  At rest,
      ``data_xyzw[:, :3] == mesh.vertices`` (``frame="data"``) and ``data_xyzw[:, 3]`` is the
      cut's time, c0.  Binary PLY keeps it exactly (a vertex
      property ``list uchar double data_xyzw``; `load_mesh` puts it back), ASCII PLY to about 8
      digits, GLB as float32 (``_data_xyzw``), OBJ and STL not at all.
    * ``mesh.faces`` (k, 3), counter-clockwise seen from outside (a field's: from where f < level).
    * ``mesh.face_attributes["group"]`` (k,) int32: each face's colour group; a stack adds
      ``"slice"`` (k,) int32, a sequence adds ``"item"`` (k,) int32 (its index in the sequence).
    * ``mesh.visual.face_colors`` (k, 4) uint8 RGBA (`face_colors`).
    * ``mesh.metadata["rot4d_widget"]``: ``{"kind", "volume"}``, the volume the slicer computed
      (a polytope's `Slice.volume`, the sum of a field's level volumes, a stack's
      ``sum scale_k^3 V_k``; None where it has no meaning), for checks against ``mesh.volume``.
    """
    import trimesh

    opacity = float(opacity)
    if not 0.0 <= opacity <= 1.0:
        raise ValueError(f"Expected `opacity` in [0, 1], got {opacity}")
    if frame not in ("data", "view"):
        raise ValueError(f"Expected `frame` to be 'data' (the data's units and place) or 'view' (the view's "
                         f"slice coordinates), got {frame!r}")
    items = list(data) if isinstance(data, (list, tuple)) else [data]
    if not items:
        raise ValueError("Expected slice data or a non-empty sequence of them, got an empty sequence")
    many = isinstance(data, (list, tuple))
    verts, faces, rgbs, attrs, kinds, xyzws = [], [], [], {}, [], []
    volume = 0.0
    off = 0
    for i, item in enumerate(items):
        p, t, rgb, a, vol, kind, xyzw, to_frame = _one_mesh_arrays(item, color_by, group_colors)
        if frame == "data" and to_frame is not None:
            p = p * to_frame[0] + to_frame[1]  # the view's picture in the data's units, at the data's place
        if separate_groups and len(t):
            key = a["group"][:, None] * len(p) + t  # (group, vertex) pairs
            uniq, inv = np.unique(key.ravel(), return_inverse=True)
            rows, t = uniq % len(p), inv.reshape(-1, 3)
        elif len(t):
            rows, inv = np.unique(t.ravel(), return_inverse=True)  # only the points faces use
            t = inv.reshape(-1, 3)
        else:
            rows = np.zeros(0, dtype=np.intp)
        p = p[rows]
        xyzws.append(None if xyzw is None else xyzw[rows])
        if many:
            a["item"] = np.full(len(t), i)
        verts.append(p)
        faces.append(t + off)
        rgbs.append(rgb)
        for name, values in a.items():
            attrs.setdefault(name, []).append(values)
        off += len(p)
        kinds.append(kind)
        volume = None if volume is None or vol is None else volume + vol
    names = [n for n in attrs if len(attrs[n]) == len(items)]  # attributes every item has
    rgb = np.concatenate(rgbs) if rgbs else np.zeros((0, 3))
    colors = np.column_stack([np.rint(rgb * 255), np.full(len(rgb), round(opacity * 255))]).astype(np.uint8)
    mesh = trimesh.Trimesh(vertices=np.concatenate(verts), faces=np.concatenate(faces).astype(np.int64),
                           face_colors=colors, process=False, validate=False)
    for name in names:
        mesh.face_attributes[name] = np.concatenate(attrs[name]).astype(np.int32)
    if all(x is not None for x in xyzws):  # every item knows its data coordinates
        mesh.vertex_attributes["data_xyzw"] = np.concatenate(xyzws).astype(np.float64)
    mesh.metadata["rot4d_widget"] = {"kind": kinds[0] if len(set(kinds)) == 1 else "mixed", "volume": volume}
    return mesh


def _ply_column(element, name):
    """A property of a PLY element as trimesh's reader left it (``metadata["_ply_raw"]``): a
    structured array (binary files; a list property as its count and its values) or a dict of
    columns (ASCII files); None when absent."""
    data = (element or {}).get("data")
    if isinstance(data, Mapping):
        col = data.get(name)
        return None if col is None else np.asarray(col)
    names = getattr(getattr(data, "dtype", None), "names", None) or ()
    if name not in names:
        return None
    col = data[name]
    if getattr(col.dtype, "names", None):  # a list property: (count, values)
        col = col[col.dtype.names[-1]]
    return np.asarray(col)


def load_mesh(path):
    """Read a mesh file with trimesh (nothing merged), restoring ``face_attributes["group"]``
    (and "slice", "item") from a PLY file's face properties and ``vertex_attributes["data_xyzw"]``
    (n, 4) float64 from its vertex property (a list of 4 doubles)."""
    import trimesh

    mesh = trimesh.load(os.fspath(path), force="mesh", process=False)
    raw = mesh.metadata.get("_ply_raw") if isinstance(mesh.metadata, dict) else None
    if raw is not None:
        for name in ("group", "slice", "item"):
            col = _ply_column(raw.get("face"), name)
            if col is not None and len(col) == len(mesh.faces):
                mesh.face_attributes[name] = col.reshape(-1)
        col = _ply_column(raw.get("vertex"), "data_xyzw")
        if col is not None and col.size == 4 * len(mesh.vertices):
            mesh.vertex_attributes["data_xyzw"] = col.reshape(-1, 4).astype(np.float64)
    return mesh


# ============================================================================ sources
def _function_path(f):
    module = getattr(f, "__module__", None)
    qual = getattr(f, "__qualname__", None)
    if not module or not qual:
        return None, f"{type(f).__name__} has no module-level name"
    if "<" in qual:
        return None, f"{module}.{qual} is a lambda or a local function"
    if module == "__main__":
        return None, f"{qual} is defined in a notebook or script (__main__)"
    return f"{module}:{qual}", None


def describe_source(source) -> dict:
    """``source.describe()`` plus what `rebuild_source` needs, and ``"rebuild"``: True, or the reason
    it cannot be rebuilt.

    A polytope that is not one of the six named ones as `polytope(name)` builds them (a scaled
    pentachoron, a uniform polychoron, one read from 4OFF, possibly non-convex) keeps its
    vertices, faces and cells; a field keeps its resolution, w units and how to reopen it (a module-level function
    ``"module:qualname"``, or the file `open_field` read); a stack describes its inner source the
    same way.
    """
    from ..sources.fields import Field4D
    from ..sources.protocol import PolytopeSource
    from ..sources.tomography import StackSource

    if isinstance(source, StackSource):
        d = dict(source.describe())
        d["source"] = describe_source(source.source)
        d["rebuild"] = d["source"]["rebuild"]
        return d
    d = dict(source.describe())
    if isinstance(source, PolytopeSource):
        from ..geometry.polytopes import POLYTOPE_NAMES, polytope

        p = source.polytope
        if "vertices" in d or p.name not in POLYTOPE_NAMES or not np.array_equal(
                np.asarray(p.vertices), np.asarray(polytope(p.name).vertices)):
            # not one of the named six as `polytope(name)` builds it: its vertices, faces and
            # cells (a non-convex polytope is not the hull of its vertices)
            d["vertices"] = np.asarray(p.vertices).tolist()
            d["faces"] = [np.asarray(f).tolist() for f in p.faces]
            d["cells"] = [np.asarray(c).tolist() for c in p.cells]
        d["rebuild"] = True
    elif isinstance(source, Field4D):
        d.update(resolution=source.resolution, coarse_resolution=source.coarse_resolution, w_units=source.w_units,
                 chunk_cache_bytes=source.chunk_cache_bytes)
        origin = getattr(source, "origin", None)
        if source._kind == "function":
            path, why = _function_path(source._function)
            d["function"] = path or d.get("function")
            d["rebuild"] = True if path else f"its function cannot be imported again: {why}"
        elif isinstance(origin, Mapping):
            d["origin"] = dict(origin)
            d["array"] = f"read from {origin.get('path')!r} (reopened from there)"
            d["rebuild"] = True
        else:
            d["rebuild"] = (f"its values are a {d.get('array', 'array').replace(' (not recordable)', '')} held in "
                            "memory, not written into a state file; open the file with Field4D.open(path, variable, "
                            "w=...) (or rot4d_widget.keep.export.open_field) to record where it comes from -- "
                            "the only way for a zarr store or a file xarray read with the scipy engine")
    else:
        d["rebuild"] = f"a source of kind {d.get('kind', type(source).__name__)!r} cannot be rebuilt from its description"
    return _jsonable(d, "source.describe()")


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
        from ..geometry.polytopes import Polytope, polytope
        from ..sources.protocol import PolytopeSource

        if "vertices" in description:
            faces, cells = description.get("faces"), description.get("cells")
            return PolytopeSource(Polytope(np.asarray(description["vertices"], dtype=np.float64),
                                           None if faces is None else [np.asarray(f, dtype=np.intp) for f in faces],
                                           None if cells is None else [tuple(c) for c in cells],
                                           name=str(description.get("name", "polytope"))))
        return PolytopeSource(polytope(description["name"]))
    if kind == "stack":
        from ..sources.tomography import StackSource

        inner = rebuild_source(description["source"], allow_code=allow_code, function=function, base=base)
        return StackSource(inner, slices=description["slices"], spacing=description.get("spacing"),
                           arrangement=description.get("arrangement", "oval"),
                           color_by=description.get("color_by", "w"))
    if why is not True:
        raise _CannotRebuild(f"The state file's source cannot be rebuilt: {why}. "
                         "Pass it in: load_state(path, source=...)")
    if kind == "field":
        return _rebuild_field(description, allow_code, function, base)
    raise _CannotRebuild(f"Unknown source kind {kind!r}; pass the source in: load_state(path, source=...)")


#: The `Field4D.from_xarray` keywords an origin's ``"kwargs"`` may carry (files written by
#: `open_field` before version 2 keep the dims and any of these there).
_ORIGIN_KWARGS = ("x", "y", "z", "w", "w_per_unit", "name", "units", "w_units", "space_units", "resolution", "coarse_resolution",
                  "levels", "inside", "caps", "chunk_cache_bytes")


def _origin_path(origin, base):
    """The data file an origin names: its ``"relative_path"`` beside the state file (``base``, the
    state file's folder) when that exists, else its absolute ``"path"``; `_CannotRebuild` naming
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
    raise _CannotRebuild(f"the field's data are not found at {' or '.join(map(repr, tried))}; put the file "
                         "back, or open it and pass it in: load_state(path, source=Field4D.open(...))")


def _open_origin(origin, base):
    from ..sources.fields import Field4D, _selection_from_json

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
            field = Field4D.open(path, variable, engine=engine, chunks=chunks,
                                 isel=_selection_from_json(origin.get("isel"), "isel"),
                                 sel=_selection_from_json(origin.get("sel"), "sel"),
                                 load=bool(origin.get("load", False)), **kwargs)
    except (OSError, KeyError, IndexError) as exc:
        raise _CannotRebuild(f"the field's data at {path!r} cannot be opened as saved ({type(exc).__name__}: "
                             f"{exc}); open it and pass it in: load_state(path, source=...)") from None
    return field


def _rebuild_field(d, allow_code=False, function=None, base=None):
    from ..sources.fields import Field4D

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
            obj = importlib.import_module(module)
            for part in qual.split("."):
                obj = getattr(obj, part)
        except (ImportError, AttributeError, ValueError) as exc:
            raise _CannotRebuild(f"The field's function {spec!r} cannot be imported ({exc}); "
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
    """`_CannotRebuild` when a reopened file no longer holds what was saved: another shape, axis
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
            raise _CannotRebuild(f"the file {field.origin.get('path')!r} no longer holds the saved field: its "
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
    from ..sources.fields import Field4D

    return Field4D.open(path, variable, engine=engine, **kwargs)


def _made_by_function(d) -> bool:
    """Whether a source description is (a stack of) a field made by a function."""
    while isinstance(d, Mapping) and d.get("kind") == "stack":
        d = d.get("source")
    return isinstance(d, Mapping) and d.get("kind") == "field" and "origin" not in d and bool(d.get("function"))


def _described_w_frame(desc):
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


def _inner_identity(d):
    while d.get("kind") == "stack":
        d = d.get("source", {})
    return d.get("kind"), d.get("name") if d.get("kind") == "polytope" else None


# ============================================================================ state files
def _jsonable(value, where: str):
    """``value`` with tuples as lists and numpy scalars/arrays as Python numbers/lists; TypeError
    naming ``where`` for anything JSON cannot hold (NaN and infinities included)."""
    if isinstance(value, Mapping):
        out = {}
        for k, v in value.items():
            if not isinstance(k, str):
                raise TypeError(f"Expected string keys in {where}, got {k!r}")
            out[k] = _jsonable(v, f"{where}[{k!r}]")
        return out
    if isinstance(value, (list, tuple)):
        return [_jsonable(v, f"{where}[{i}]") for i, v in enumerate(value)]
    if isinstance(value, np.ndarray):
        return _jsonable(value.tolist(), where)
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


def settings_of(widget) -> dict:
    """The `SETTING_NAMES` a widget (or any object) has, as JSON-able values: what `save_state`
    stores and `rot4d_widget.keep.figures.render_state` takes (``render_state(w.state, w.source,
    **settings_of(w))``).  A stack's ``spacing`` is None while it follows its default."""
    out = {}
    for name in SETTING_NAMES:
        if hasattr(widget, name):
            out[name] = getattr(widget, name)
    src = getattr(widget, "source", None)
    if out.get("spacing") is not None and getattr(src, "spacing_is_default", False):
        out["spacing"] = None
    return _jsonable(out, "settings")


class LoadedState(NamedTuple):
    """What `load_state` returns: ``state, source, settings = load_state(path)``."""

    state: RotationState
    source: object
    settings: dict


def save_state(path, state: RotationState, source=None, settings: Mapping | None = None) -> dict:
    """Write ``state``, what ``source`` is and the widget's ``settings`` to the JSON file ``path``.

    ``settings`` is any dict of JSON-able values (tuples and numpy numbers are converted), for
    the widget: its traits (``levels``, ``slices``, ``spacing``, ``arrangement``,
    ``face_opacity``, ``ball_radius``, ``bar_radius``, ``background``, ``show_balls``,
    ``show_bars``, ``show_faces``, ``color_by``) -- `rot4d_widget.keep.figures.render_state` takes the
    same names.  A source that cannot be rebuilt (an in-memory array, a lambda) is described
    anyway, with a `SourceNotRebuildable` warning saying so.  Returns the dict written.
    The file is replaced atomically (written beside it, then renamed).
    """
    if not isinstance(state, RotationState):
        raise TypeError(f"Expected `state` to be a rot4d_widget.RotationState, got {type(state).__name__}")
    src = None
    if source is not None:
        from ..sources.protocol import as_source

        src = describe_source(as_source(source))
        if src["rebuild"] is not True:
            warnings.warn(f"The source is described in {os.fspath(path)!r} but cannot be rebuilt from it: "
                          f"{src['rebuild']}. Loading the file will need it passed in: "
                          "load_state(path, source=...)", SourceNotRebuildable, stacklevel=2)
    if src is not None:
        _add_relative_paths(src, os.path.dirname(os.path.abspath(os.fspath(path))))
    doc = {
        "format": STATE_FILE_FORMAT,
        "version": _version_needed(src),
        "state": state.to_dict(),
        "source": src,
        "settings": _jsonable(dict(settings or {}), "settings"),
    }
    from .. import __version__

    doc["rot4d_widget"] = __version__
    text = json.dumps(doc, indent=1, allow_nan=False)
    _write_atomically(os.fspath(path), text + "\n")
    return doc


def _fields_in(d):
    while isinstance(d, Mapping) and d.get("kind") == "stack":
        d = d.get("source")
    return [d] if isinstance(d, Mapping) and d.get("kind") == "field" else []


def _add_relative_paths(desc, folder: str) -> None:
    """Give a file field's origin its path relative to the state file's ``folder`` when the data
    sit there or below it (so the folder can move, or be copied, with its data)."""
    for d in _fields_in(desc):
        origin = d.get("origin")
        if isinstance(origin, dict):
            origin.pop("relative_path", None)
        if isinstance(origin, dict) and isinstance(origin.get("path"), str):
            rel = os.path.relpath(origin["path"], folder)
            if rel != os.pardir and not rel.startswith(os.pardir + os.sep) and not os.path.isabs(rel):
                origin["relative_path"] = rel.replace(os.sep, "/")


def _version_needed(desc) -> int:
    """1 unless a field needs what version 1 readers would drop without a word: a selection of
    its file (``isel``, ``sel``: they would open the whole variable), ``inside="below"`` or
    ``caps=False`` (they would draw the other side, or close it)."""
    for d in _fields_in(desc):
        origin = d.get("origin") or {}
        if any(origin.get(k) for k in ("isel", "sel")) or d.get("inside", "above") != "above" \
                or d.get("caps", True) is not True:
            return 2
    return 1


def _write_atomically(path: str, text: str) -> None:
    """Write ``text`` to ``path`` through a temporary file beside it and `os.replace`.

    The file gets the mode ``open(path, "w")`` would leave: a replaced file keeps its own; a new
    one gets 0o666 less the umask (the temporary file is created with mode 0o666, so the
    kernel applies the umask, and default ACLs, itself -- never read or changed here)."""
    folder = os.path.dirname(os.path.abspath(path))
    try:
        keep = stat.S_IMODE(os.stat(path).st_mode)
    except FileNotFoundError:
        keep = None
    for _ in range(100):
        tmp = os.path.join(folder, f".rot4d-state-{secrets.token_hex(8)}.json")
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0), 0o666)
            break
        except FileExistsError:
            continue
    else:
        raise FileExistsError(f"Could not create a temporary file in {folder!r}")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            if keep is not None:
                os.chmod(tmp, keep)
            fh.write(text)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def load_state(path, source=None, *, allow_code: bool = False, function=None) -> LoadedState:
    """Read a `save_state` file: ``(state, source, settings)``.

    The state is validated (`RotationState.from_dict`: an orientation within 1e-6 of orthogonal
    is re-orthonormalised, further off refused) and is what its ``reset()`` returns to.  The
    source is ``source`` if given -- then it must be of the kind the file describes (a
    polytope of the same name), else ``ValueError`` -- or rebuilt from the file; when it cannot
    be (an in-memory array), the source is None and a `SourceNotRebuildable` warning says why.
    ``ValueError`` names what is wrong with a file that is not a state file, or a newer one.

    A state file is data: loading it imports no module and calls no code it names.  A field
    the file describes by a function's name (``"module:qualname"``) is rebuilt with
    ``function`` (a callable ``f(x, y, z, w)``) if given, or by importing that name only when
    ``allow_code=True`` (for a file you trust: importing runs the module's code); otherwise
    `CodeNotAllowed` (a ValueError) says so and how to allow it.
    """
    if source is not None and function is not None:
        raise TypeError("Expected `source` or `function`, not both (the source already has its function)")
    allow_code = bool(allow_code)
    path = os.fspath(path)
    try:
        with open(path, encoding="utf-8") as fh:
            doc = json.load(fh)
    except json.JSONDecodeError as exc:
        raise ValueError(f"{path!r} is not a rot4d_widget state file: not JSON ({exc})") from None
    except UnicodeDecodeError:
        raise ValueError(f"{path!r} is not a rot4d_widget state file: not UTF-8 text") from None
    if not isinstance(doc, dict) or doc.get("format") != STATE_FILE_FORMAT:
        raise ValueError(f"{path!r} is not a rot4d_widget state file (no \"format\": \"{STATE_FILE_FORMAT}\")")
    version = doc.get("version")
    if isinstance(version, bool) or not isinstance(version, int) or not 1 <= version <= STATE_FILE_VERSION:
        raise ValueError(f"{path!r} is a state file of version {version!r}; this rot4d_widget reads versions "
                         f"1 ... {STATE_FILE_VERSION}")
    missing = [k for k in ("state", "source", "settings") if k not in doc]
    if missing:
        raise ValueError(f"{path!r} lacks {', '.join(map(repr, missing))}")
    try:  # a state from before c0 followed the data's units: converted by the file's own source
        state = RotationState.from_dict(doc["state"], w_frame=_described_w_frame(doc.get("source")))
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{path!r}: bad state: {exc}") from None
    settings = doc["settings"]
    if not isinstance(settings, dict):
        raise ValueError(f"{path!r}: expected 'settings' to be a dict, got {type(settings).__name__}")
    desc = doc["source"]
    if source is not None:
        from ..sources.protocol import as_source

        source = as_source(source)
        if desc is not None:
            want, got = _inner_identity(desc), _inner_identity(describe_source(source))
            if want != got:
                raise ValueError(f"{path!r} was saved with a source of kind {want[0]!r}"
                                 f"{'' if want[1] is None else f' ({want[1]})'}, got {got[0]!r}"
                                 f"{'' if got[1] is None else f' ({got[1]})'}")
        return LoadedState(state, source, settings)
    if function is not None and not _made_by_function(desc):
        raise ValueError(f"{path!r}: `function` rebuilds a field the file describes by a function's name; "
                         f"its source is {_inner_identity(desc or {})[0]!r}")
    if desc is None:
        return LoadedState(state, None, settings)
    try:
        rebuilt = rebuild_source(desc, allow_code=allow_code, function=function,
                                 base=os.path.dirname(os.path.abspath(path)))
    except CodeNotAllowed as exc:
        raise CodeNotAllowed(f"{path!r}: {exc}") from None
    except _CannotRebuild as exc:
        warnings.warn(str(exc), SourceNotRebuildable, stacklevel=2)
        rebuilt = None
    except (TypeError, ValueError, KeyError) as exc:
        raise ValueError(f"{path!r}: bad source description: {exc}") from None
    return LoadedState(state, rebuilt, settings)
