"""The widget's trait types, typed in the declaration (the bqplot / ipywidgets manner).

Each type checks its value itself and raises a TypeError or ValueError that names what is
allowed (``Expected `face_opacity` to be a number in [0, 1], got 3``); traitlets passes those
on unchanged.  The checks are plain functions too (`check_positive`, `check_fraction`,
`check_flag`, `check_color_by`): the scene validates its options with the same ones.

    theta0 = Angle(DEFAULT_THETA0)                    # (0, pi]
    ball_radius = Positive(0.07, upper=10.0)          # (0, 10]
    face_opacity = Fraction(0.4)                      # [0, 1]
    background = Colour("#ffffff")                    # '#rrggbb', '#rgb', three floats in [0, 1]
    arrangement = Choice(None, ("oval", "grid", "stack"), allow_none=True)
    cmap = Cmap("viridis")                            # a matplotlib colour map name
    clim = Clim(None, allow_none=True)                # (lo, hi) finite, lo < hi; None: the data's range
    rendering = Rendering("surface")                  # "surface", "volume", "mip", "sections"
    sections = Sections((0.5, 0.5, 0.5))              # three fractions in [0, 1]
"""

from __future__ import annotations

import math
from numbers import Integral, Real

import numpy as np
import traitlets

from ..core import colours, renderings
from ..core.state import check_theta0
from ..core.validate import real

__all__ = [
    "Checked", "Angle", "Finite", "Positive", "Fraction", "Colour", "Flag", "ColorBy", "Count", "Spacing",
    "Choice", "Levels", "Cmap", "Clim", "Rendering", "Sections", "check_positive", "check_fraction", "check_flag",
    "check_color_by",
]


# -- checks (TypeError / ValueError naming what is allowed) ---------------------------------------
def check_positive(name, value, *, upper=None) -> float:
    """A finite number > 0 (and <= ``upper`` if given), as a float."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"Expected `{name}` to be a positive number, got {value!r}")
    v = float(value)
    if not (math.isfinite(v) and v > 0.0) or (upper is not None and v > upper):
        allowed = f"in (0, {upper}]" if upper is not None else "> 0 and finite"
        raise ValueError(f"Expected `{name}` {allowed}, got {value!r}")
    return v


def check_fraction(name, value) -> float:
    """A number in [0, 1], as a float."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"Expected `{name}` to be a number in [0, 1], got {value!r}")
    v = float(value)
    if not 0.0 <= v <= 1.0:
        raise ValueError(f"Expected `{name}` to be a number in [0, 1], got {value!r}")
    return v


def check_flag(name, value) -> bool:
    """True or False (a numpy bool too), as a bool."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"Expected `{name}` to be True or False, got {value!r}")
    return bool(value)


def check_color_by(value):
    """``"group"`` or one colour ('#rrggbb', '#rgb', three floats in [0, 1]; a sequence as a tuple)."""
    if value == "group":
        return value
    try:
        colours.as_rgb(value, "color_by")
    except ValueError:
        raise ValueError(
            "Expected `color_by` to be 'group' or one colour ('#rrggbb', '#rgb', three floats in [0, 1]), "
            f"got {value!r}"
        ) from None
    return value if isinstance(value, str) else tuple(float(x) for x in value)


# -- trait types ----------------------------------------------------------------------------------
class Checked(traitlets.TraitType):
    """A trait whose values pass ``check(name, value)`` (None too when ``allow_none``)."""

    info_text = "a checked value"

    def check(self, name, value):  # pragma: no cover - every subclass says
        return value

    def validate(self, obj, value):
        if value is None and self.allow_none:
            return None
        return self.check(self.name, value)


class Angle(Checked):
    """An angle in radians in (0, pi] (a step angle)."""

    info_text = "an angle in (0, pi] radians"

    def check(self, name, value):
        return check_theta0(value)


class Finite(Checked):
    """A finite real number, as a float."""

    info_text = "a finite number"

    def check(self, name, value):
        return real(value, name)


class Positive(Checked):
    """A finite number > 0, at most ``upper`` when given."""

    def __init__(self, default_value=traitlets.Undefined, *, upper=None, **kwargs):
        self.upper = upper
        self.info_text = f"a number in (0, {upper}]" if upper is not None else "a finite number > 0"
        super().__init__(default_value, **kwargs)

    def check(self, name, value):
        return check_positive(name, value, upper=self.upper)


class Fraction(Checked):
    """A number in [0, 1]."""

    info_text = "a number in [0, 1]"

    def check(self, name, value):
        return check_fraction(name, value)


class Colour(Checked):
    """A colour: '#rrggbb', '#rgb' or three floats in [0, 1] (kept as given)."""

    info_text = "a colour ('#rrggbb', '#rgb' or three floats in [0, 1])"

    def check(self, name, value):
        colours.as_rgb(value, name)
        return value


class Flag(Checked):
    """True or False (a numpy bool becomes a bool)."""

    info_text = "True or False"

    def check(self, name, value):
        return check_flag(name, value)


class ColorBy(Checked):
    """``"group"`` or one colour for every face."""

    info_text = "'group' or one colour"

    def check(self, name, value):
        return check_color_by(value)


class Count(Checked):
    """An int in ``[low, high]`` (never a bool: True == 1 would pass unseen)."""

    def __init__(self, default_value=traitlets.Undefined, *, low=1, high=None, **kwargs):
        self.low, self.high = low, high
        self.info_text = f"an int in {low} \u2026 {high}" if high is not None else f"an int >= {low}"
        super().__init__(default_value, **kwargs)

    def check(self, name, value):
        allowed = self.info_text + (" or None" if self.allow_none else "")
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, Integral):
            raise TypeError(f"Expected `{name}` to be {allowed}, got {value!r}")
        if value < self.low or (self.high is not None and value > self.high):
            raise ValueError(f"Expected `{name}` to be {allowed}, got {value!r}")
        return int(value)


class Spacing(Checked):
    """A finite number > 0 (bounds that depend on the source are the source's to check)."""

    info_text = "a finite number > 0"

    def check(self, name, value):
        allowed = self.info_text + (" or None" if self.allow_none else "")
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, Real):
            raise TypeError(f"Expected `{name}` to be {allowed}, got {value!r}")
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"Expected `{name}` to be {allowed}, got {value!r}")
        return float(value)


class Choice(Checked):
    """One of ``values`` (strings): an enum whose message names them all."""

    def __init__(self, default_value=traitlets.Undefined, values=(), **kwargs):
        self.values = tuple(values)
        self.info_text = " or ".join(map(repr, self.values))
        super().__init__(default_value, **kwargs)

    def check(self, name, value):
        allowed = ", ".join(map(repr, self.values)) + (" or None" if self.allow_none else "")
        if not isinstance(value, str):
            raise TypeError(f"Expected `{name}` to be one of {allowed}, got {value!r}")
        if value not in self.values:
            raise ValueError(f"Expected `{name}` to be one of {allowed}, got {value!r}")
        return value


class Levels(Checked):
    """Iso levels: a number or a non-empty sequence of numbers (a tuple of floats); the source
    checks their range."""

    info_text = "a number or a sequence of numbers"

    def check(self, name, value):
        if isinstance(value, (Real, np.number)) and not isinstance(value, (bool, np.bool_)):
            return (float(value),)
        if isinstance(value, (list, tuple, np.ndarray)):
            items = list(np.asarray(value).ravel()) if isinstance(value, np.ndarray) else list(value)
            if items and all(isinstance(v, (Real, np.number)) and not isinstance(v, (bool, np.bool_)) for v in items):
                return tuple(float(v) for v in items)
        raise TypeError(f"Expected `{name}` to be {self.info_text} (iso levels), got {value!r}")


class Cmap(Checked):
    """A matplotlib colour map name (`rot4d_widget.core.colours.check_cmap`: the message says how to
    list them)."""

    info_text = "a matplotlib colour map name"

    def check(self, name, value):
        return colours.check_cmap(value, name)


class Clim(Checked):
    """Colour limits (lo, hi): two finite numbers, lo < hi, kept as a tuple of floats; None (when
    ``allow_none``) for the data's range (`rot4d_widget.core.colours.check_clim`)."""

    info_text = "(lo, hi), two finite numbers with lo < hi"

    def check(self, name, value):
        if value is None:  # None is refused here only when the trait does not allow it
            raise TypeError(f"Expected `{name}` to be {self.info_text}, got None")
        return colours.check_clim(value, name)


class Rendering(Checked):
    """How a field's cut is drawn: one of `rot4d_widget.core.renderings.RENDERINGS`."""

    info_text = " or ".join(map(repr, renderings.RENDERINGS))

    def check(self, name, value):
        return renderings.check_rendering(value, name)


class Sections(Checked):
    """The section planes' positions (fx, fy, fz), each in [0, 1] of the cut's extent, as a tuple of
    floats (`rot4d_widget.core.renderings.check_sections`)."""

    info_text = "(fx, fy, fz), three numbers in [0, 1]"

    def check(self, name, value):
        return renderings.check_sections(value, name)
