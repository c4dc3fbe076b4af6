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

The names live in three modules and are all importable from here: `rot4d_widget.keep.meshes`
(`slice_mesh`, `face_colors`, `load_mesh`), `rot4d_widget.keep.rebuild` (`describe_source`,
`rebuild_source`, `open_field`) and `rot4d_widget.keep.statefile` (`save_state`, `load_state`,
`settings_of`).

numpy, trimesh (and xarray to reopen a field's file); nothing here knows about widgets.
"""

from __future__ import annotations

from .meshes import MESH_FORMATS, face_colors, load_mesh, slice_mesh
from .rebuild import CodeNotAllowed, SourceNotRebuildable, describe_source, open_field, rebuild_source
from .statefile import (
    SETTING_NAMES,
    STATE_FILE_FORMAT,
    STATE_FILE_VERSION,
    LoadedState,
    load_state,
    save_state,
    settings_of,
)

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
