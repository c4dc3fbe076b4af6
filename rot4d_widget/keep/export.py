"""Keep what you see: the slice as a mesh (trimesh) and the state as a JSON file.

The names live in three modules, each documented there, and are all importable from here:
`rot4d_widget.keep.meshes` (`slice_mesh`, `face_colors`, `load_mesh`: meshes in the source's
own units, colour groups and data coordinates kept), `rot4d_widget.keep.rebuild`
(`describe_source`, `rebuild_source`, `open_field`: what a state file says a source is, and the
source made again from it -- never by running code the file names unless asked) and
`rot4d_widget.keep.statefile` (`save_state`, `load_state`, `settings_of`: the JSON file).
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
