"""Arrays the package hands out: read-only, so no caller can corrupt shared state (the one helper: `sealed`)."""

from __future__ import annotations

import numpy as np

__all__ = ["sealed"]


def sealed(a: np.ndarray) -> np.ndarray:
    """``a`` made read-only, behind a read-only view: nothing can write, resize or
    re-enable writing through what is handed out.

    An array that owns its data is locked in place (no copy); a view of a writable array is
    copied first; an array sealed already (read-only down to the array owning its data) is
    returned as it is, so shared read-only arrays stay shared.

    >>> a = sealed(np.zeros(3)); a.flags.writeable, sealed(a) is a, sealed(a[1:]).flags.writeable
    (False, True, False)
    """
    if _locked(a):
        return a
    if a.base is not None:  # a view: its base could be unlocked and written
        a = a.copy()
    a.flags.writeable = False
    v = a.view()
    v.flags.writeable = False
    return v


def _locked(a) -> bool:
    """A read-only view whose every base is read-only, down to the array owning the data."""
    if a.base is None or a.flags.writeable:
        return False
    while isinstance(a, np.ndarray):
        if a.flags.writeable:
            return False
        a = a.base
    return True
