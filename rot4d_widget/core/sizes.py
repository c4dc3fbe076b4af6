"""Sizes in displayed units: the scale every object is shown at and the default radii of its balls
and bars, for the static pictures (`rot4d_widget.keep`) and the live view (`rot4d_widget.view`) alike.

Every polytope is shown scaled by ``REFERENCE_RADIUS / circumradius``: its displayed circumradius is
that of the paper's pentachoron (edge a = 2), ``a sqrt(2/5)``.  ``default_ball_radius(displayed_edge)``
and ``default_bar_radius(ball_radius)`` are in those displayed units.
"""

from __future__ import annotations

import math

__all__ = ["REFERENCE_RADIUS", "default_ball_radius", "default_bar_radius"]

#: Displayed circumradius of every object: the paper's pentachoron (edge a = 2), a sqrt(2/5).
REFERENCE_RADIUS = 2.0 * math.sqrt(2.0 / 5.0)


def default_ball_radius(displayed_edge: float) -> float:
    """Ball radius for an object whose edges are ``displayed_edge`` long (displayed units).

    ``min(0.07, 0.1 * displayed_edge)``: the pentachoron's 0.07 at most, smaller for dense
    polytopes so that neighbouring balls do not merge.
    """
    return min(0.07, 0.1 * float(displayed_edge))


def default_bar_radius(ball_radius: float) -> float:
    """Bar radius that goes with balls of ``ball_radius``: ``0.4 * ball_radius``."""
    return 0.4 * float(ball_radius)
