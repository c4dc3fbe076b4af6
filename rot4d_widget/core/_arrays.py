"""Arrays the package hands out: read-only, so no caller can corrupt shared state."""

from __future__ import annotations

import numpy as np

__all__ = ["sealed"]


def sealed(a: np.ndarray) -> np.ndarray:
    """``a`` made read-only, behind a read-only view: nothing can write, resize or
    re-enable writing through what is handed out."""
    if a.base is not None:  # a view: its base could be unlocked and written
        a = a.copy()
    a.flags.writeable = False
    v = a.view()
    v.flags.writeable = False
    return v
