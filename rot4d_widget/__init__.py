"""rot4d_widget: keyboard-driven 4-D rotations and w=c0 slices (Kageyama's method).

The numpy core (rotation, keymap, state, polytopes, slicing) imports no widget
library, and importing the package imports nothing at all: every public name is
resolved on first use (PEP 562), from the table ``_LAZY`` below.  The reason is
the server extension ``rot4d_widget._server``: a Jupyter server that loads it
imports this ``__init__`` first, and an eager numpy/scipy import here cost every
server in the environment 0.55-0.72 s at start.
"""

from __future__ import annotations

import importlib
import importlib.util
import sys as _sys

from .core.version import __version__ as __version__

#: public name -> the submodule that defines it.  A new public name is one line here.
#: An entry whose module does not exist (yet) does not break ``import rot4d_widget``:
#: the name is left out of ``__all__`` and looking it up raises AttributeError.
_LAZY = {
    "Action": "core.keymap",
    "DEFAULT_KEYMAP": "core.keymap",
    "Keymap": "core.keymap",
    "Polytope": "geometry.mesh",
    "MeshError": "geometry.meshcheck",
    "pentachoron": "geometry.regular",
    "polytope": "geometry.catalogue",
    "double_rotation": "core.rotation",
    "simple_rotation": "core.rotation",
    "Slice": "geometry.slicing.tables",
    "slice_polytope": "geometry.slicing.polytope_slice",
    "RotationState": "core.state",
    "Source": "sources.protocol",
    "SliceData": "sources.protocol",
    "SourceAction": "sources.protocol",
    "SourceBase": "sources.protocol",
    "UserSource": "sources.protocol",
    "PolytopeSource": "sources.protocol",
    "Rot4DWidget": "view.widget",
    "Field4D": "sources.field.container",
    "StackSource": "sources.tomography",
    "arrangement_layout": "sources.arrangements",
    "slice_field": "sources.field.container",
    "FieldSlice": "sources.field.surface",
    "FieldSliceData": "sources.field.surface",
    "polytope_names": "geometry.catalogue",
    "slice_mesh": "keep.meshes",
    "save_state": "keep.statefile",
    "load_state": "keep.statefile",
    "Recording": "keep.recorder",
    "Recorder": "keep.recorder",
    "render_state": "keep.pictures.state_picture",
}


def _exists(module: str) -> bool:
    return importlib.util.find_spec(f"{__name__}.{module}") is not None


__all__ = sorted(name for name, module in _LAZY.items() if _exists(module))


def __getattr__(name: str):
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    try:
        mod = importlib.import_module(f".{module}", __name__)
    except ModuleNotFoundError as exc:
        # only the submodule itself missing means "no such attribute"; a missing
        # dependency inside it (pythreejs for Rot4DWidget, say) must be seen as it is
        if exc.name != f"{__name__}.{module}":
            raise
        raise AttributeError(f"module {__name__!r} has no attribute {name!r} "
                             f"(there is no module {__name__}.{module})") from None
    value = getattr(mod, name)
    globals()[name] = value  # resolved once
    _kernel_bar()
    return value


def _kernel_bar() -> None:
    """In a kernel, the view's progress bar is registered with the core's `Progress` as soon as
    the package is used (a field's coarse copy shows it in a notebook that never made a widget);
    elsewhere nothing is imported."""
    if "ipykernel" in _sys.modules and f"{__name__}.view.progress" not in _sys.modules:
        try:
            importlib.import_module(".view.progress", __name__)
        except ImportError:  # no ipywidgets: no bar, the work goes on
            pass


def __dir__():
    return sorted(set(globals()) | set(__all__))
