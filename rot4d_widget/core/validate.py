"""Scalar validators: one set for the package, each error naming what is allowed.

``name`` is the argument's name, written in back quotes in the message (``"theta0"`` ->
"Expected `theta0` ..."); a phrase that already holds its back quotes is used as it is
(``"edge length `a`"``).  A bool is never a number here.

>>> real(0.5, "angle"), positive(2, "c0_step"), int_in_range(3, "total", 0)
(0.5, 2.0, 3)
>>> real("1", "angle")
Traceback (most recent call last):
...
TypeError: Expected `angle` to be a real number, got str
>>> positive(-1.0, "c0_step")
Traceback (most recent call last):
...
ValueError: Expected `c0_step` > 0, got -1.0
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["REAL_TYPES", "is_real", "real", "positive", "int_in_range"]

#: What counts as a real number (bools excluded by `is_real`).
REAL_TYPES = (int, float, np.integer, np.floating)


def _label(name: str) -> str:
    return name if "`" in name else f"`{name}`"


def is_real(value) -> bool:
    """True for an int or float (Python or numpy), False for a bool and everything else."""
    return isinstance(value, REAL_TYPES) and not isinstance(value, (bool, np.bool_))


def real(value, name: str, *, what: str = "a real number", finite: bool = True,
         finite_what: str = "finite") -> float:
    """``value`` as a float.

    TypeError "Expected `name` to be {what}, got <type>" unless it is a real number; with
    ``finite`` (the default) ValueError "Expected `name` to be {finite_what}, got <value>" for
    nan or inf.
    """
    if not is_real(value):
        raise TypeError(f"Expected {_label(name)} to be {what}, got {type(value).__name__}")
    value = float(value)
    if finite and not math.isfinite(value):
        raise ValueError(f"Expected {_label(name)} to be {finite_what}, got {value}")
    return value


def positive(value, name: str, *, what: str = "a real number", finite: bool = True,
             finite_what: str = "finite", must: str = "> 0") -> float:
    """A real number > 0 as a float (`real`'s errors first; ``finite=False`` lets +inf through).

    ValueError "Expected `name` {must}, got <value>" for a value that is not > 0 (nan included).
    """
    value = real(value, name, what=what, finite=finite, finite_what=finite_what)
    if not value > 0:
        raise ValueError(f"Expected {_label(name)} {must}, got {value}")
    return value


def int_in_range(value, name: str, lo: int | None = None, hi: int | None = None) -> int:
    """An int (Python or numpy, not a bool) with ``lo <= value <= hi`` (None: no bound).

    TypeError for another type, ValueError outside the range; both say
    "Expected `name` to be an int >= lo" (or "in [lo, hi]", "<= hi"), then what was given.
    """
    if lo is not None and hi is not None:
        allowed = f"an int in [{lo}, {hi}]"
    elif lo is not None:
        allowed = f"an int >= {lo}"
    elif hi is not None:
        allowed = f"an int <= {hi}"
    else:
        allowed = "an int"
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"Expected {_label(name)} to be {allowed}, got {value!r}")
    value = int(value)
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        raise ValueError(f"Expected {_label(name)} to be {allowed}, got {value!r}")
    return value
