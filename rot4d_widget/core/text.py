"""Text for people: how the package writes numbers in readouts, labels and annotations."""

from __future__ import annotations

import math

from . import tolerances as tol_

__all__ = ["number_text"]


def number_text(value: float, scale: float = 0.0, digits: int = 4) -> str:
    """A number for people: ``digits`` significant digits, and 0 for a value that is rounding noise
    next to ``scale`` (below 1e-9 of it: no "-2.132e-14" for a cut through t = 0).

    >>> number_text(-2.132e-14, 73.3), number_text(2.1362, 0), number_text(1234567.0)
    ('0', '2.136', '1.235e+06')
    """
    value = float(value)
    if not math.isfinite(value):
        return str(value)
    if abs(value) <= tol_.NOISE * abs(float(scale)):
        return "0"
    return f"{value:.{digits}g}"
