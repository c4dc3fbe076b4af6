"""What the page needs to step its own copy of the state: the key table, the bounds, the timing,
and the state itself, as plain JSON-able data (the companion's synced ``config`` and ``state``).

The page (``page/state.js``, ``page/keymap.js``) applies the same rules as
`rot4d_widget.core.state.RotationState` and `rot4d_widget.core.keymap.Keymap`; the tables and
numbers come from here, never written twice.  Floats travel as JSON numbers (Python writes the
shortest repr that reads back exactly); an infinite c0 limit travels as null.
"""

from __future__ import annotations

import math

from ..core import state as st
from ..core.keymap import REPEATING_KINDS, SHIFT_KINDS, Keymap

__all__ = ["page_config", "state_message", "action_message"]


def action_message(action) -> dict:
    """An `Action` as the page reads it: ``{kind, planes, sign, name}``."""
    return {"kind": action.kind, "planes": action.planes, "sign": int(action.sign), "name": action.name}


def page_config(keymap: Keymap, *, hold_delay: float, tick_rate: float, max_lag: float, predicted=(),
                predicted_actions=None) -> dict:
    """The page's key table and rules: ``keymap`` (key name -> action), which kinds Shift inverts
    and which repeat while held, the state's bounds, the hold delay and tick rate (s, Hz) that give
    a held key's steps (`rot4d_widget.view.keyhold.steps_for`), the kernel's catch-up window
    ``max_lag``, and the action kinds the page steps itself (``predicted``: the state's kinds, a
    field's view kinds; a source's own actions run Python code and are the kernel's alone, but for
    those ``predicted_actions`` names -- a field's levels, ``{name: {"rule": "levels", "sign",
    "repeat"}}``: `rot4d_widget.view.fieldkeys`)."""
    return {
        "keymap": {k: action_message(a) for k, a in keymap.items()},
        "shift_kinds": sorted(SHIFT_KINDS),
        "repeating_kinds": sorted(REPEATING_KINDS),
        "predicted_kinds": sorted(predicted),
        "predicted_actions": dict(predicted_actions or {}),
        "bounds": {
            "theta0_min": st.THETA0_MIN,
            "theta0_max": st.THETA0_MAX,
            "alpha_max": st.ALPHA_MAX,
            "theta0_factor": st.THETA0_FACTOR,
            "alpha_step_fraction": st.ALPHA_STEP_FRACTION,
        },
        "hold_delay": float(hold_delay),
        "tick_rate": float(tick_rate),
        "max_lag": float(max_lag),
    }


def _matrix(m) -> list:
    return [float(x) for x in m.reshape(16)]


def state_message(state: st.RotationState, view: dict | None = None) -> dict:
    """``state`` as the page adopts it: the matrix (16 numbers, row by row), theta0, alpha, c0 and
    its step, the c0 range and the reset point; with ``view``, a field's view settings
    (`rot4d_widget.view.fieldview.view_message`)."""
    t, a, c, m = state.reset_point
    limit = state.c0_limit
    msg = {
        "matrix": _matrix(state.matrix),
        "theta0": state.theta0,
        "alpha": state.alpha,
        "c0": state.c0,
        "c0_step": state.c0_step,
        "c0_limit": None if math.isinf(limit) else limit,
        "c0_origin": state.c0_origin,
        "initial": {"matrix": _matrix(m), "theta0": t, "alpha": a, "c0": c},
    }
    if view is not None:
        msg["view"] = view
    return msg
