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

__version__ = "0.1.0"

#: public name -> the submodule that defines it.  A new public name is one line here.
#: An entry whose module does not exist (yet) does not break ``import rot4d_widget``:
#: the name is left out of ``__all__`` and looking it up raises AttributeError.
_LAZY = {
    "Action": "keymap",
    "DEFAULT_KEYMAP": "keymap",
    "Keymap": "keymap",
    "Polytope": "polytopes",
    "MeshError": "polytopes",
    "pentachoron": "polytopes",
    "polytope": "polytopes",
    "double_rotation": "rotation",
    "simple_rotation": "rotation",
    "Slice": "slicing",
    "slice_polytope": "slicing",
    "RotationState": "state",
    "Source": "source",
    "SliceData": "source",
    "SourceAction": "source",
    "PolytopeSource": "source",
    "Rot4DWidget": "widget",
    "Field4D": "fields",
    "StackSource": "tomography",
    "arrangement_layout": "tomography",
    "slice_field": "fields",
    "FieldSlice": "fields",
    "FieldSliceData": "fields",
    "polytope_names": "uniform",
    "slice_mesh": "export",
    "save_state": "export",
    "load_state": "export",
    "Recording": "recording",
    "Recorder": "recording",
    "render_state": "figures",
}

#: submodules reachable as attributes (``rot4d_widget.slicing.TOLERANCE``) without an import
#: statement, as they were when this ``__init__`` imported the core eagerly.
_SUBMODULES = ("buffers", "companion", "figures", "keymap", "polytopes", "rotation",
               "scene", "slicing", "source", "state", "widget",
               "look", "readout", "keyhold", "pump", "fields", "tomography", "datasets",
               "uniform", "export", "recording")


def _exists(module: str) -> bool:
    return importlib.util.find_spec(f"{__name__}.{module}") is not None


__all__ = sorted(name for name, module in _LAZY.items() if _exists(module))


def __getattr__(name: str):
    module = _LAZY.get(name)
    if module is None and name not in _SUBMODULES:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    try:
        mod = importlib.import_module(f".{module or name}", __name__)
    except ModuleNotFoundError as exc:
        # only the submodule itself missing means "no such attribute"; a missing
        # dependency inside it (pythreejs for Rot4DWidget, say) must be seen as it is
        if exc.name != f"{__name__}.{module or name}":
            raise
        raise AttributeError(f"module {__name__!r} has no attribute {name!r} "
                             f"(there is no module {__name__}.{module or name})") from None
    value = mod if module is None else getattr(mod, name)
    globals()[name] = value  # resolved once
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))
