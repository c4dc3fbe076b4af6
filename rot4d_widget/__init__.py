"""rot4d_widget: keyboard-driven 4-D rotations and w=c0 slices (Kageyama's method).

The numpy core (rotation, keymap, state, polytopes, slicing) imports no widget
library; the widget layer is imported lazily on first use of ``Rot4DWidget``.
"""

from .keymap import DEFAULT_KEYMAP, Action, Keymap
from .polytopes import Polytope, pentachoron, polytope
from .rotation import double_rotation, simple_rotation
from .slicing import Slice, slice_polytope
from .state import RotationState

__all__ = [
    "Action",
    "DEFAULT_KEYMAP",
    "Keymap",
    "Polytope",
    "Rot4DWidget",
    "RotationState",
    "Slice",
    "double_rotation",
    "pentachoron",
    "polytope",
    "simple_rotation",
    "slice_polytope",
]

__version__ = "0.1.0"


def __getattr__(name):  # lazy: importing the core must not import ipywidgets
    if name == "Rot4DWidget":
        from .widget import Rot4DWidget

        return Rot4DWidget
    raise AttributeError(f"module 'rot4d_widget' has no attribute {name!r}")
