"""The iso levels of a `Field4D` and the side and caps of its surfaces: the settings a recording
keeps and a state file restores (the source protocol's ``settings`` / ``apply_setting``), and the
o / i keys that step the levels through the data range; the resolutions of full and coarse steps."""

from __future__ import annotations

import math

import numpy as np

from ..protocol import SourceAction
from .checks import as_levels, check_resolution


class FieldLevels:
    """What `Field4D` takes from here: ``levels``, ``inside``, ``caps``, the level keys, the
    settings and the resolutions of its steps.  The field provides ``_levels`` (None until first
    asked), ``data_range`` and ``_stat`` (`rot4d_widget.sources.field.stats.FieldStatistics`)."""

    @property
    def inside(self) -> str:
        """Which side of each level the surface encloses: "above" {f >= level} or "below" {f <= level}."""
        return self._inside

    @inside.setter
    def inside(self, value) -> None:
        if not isinstance(value, str) or value not in ("above", "below"):
            raise ValueError(f"Expected `inside` to be 'above' (the surface encloses f >= level) or 'below' "
                             f"(f <= level, e.g. a signed distance negative inside), got {value!r}")
        self._inside = value

    @property
    def caps(self) -> bool:
        """Whether the surface is closed on the box's faces (True) or left open there (False)."""
        return self._caps

    @caps.setter
    def caps(self, value) -> None:
        if not isinstance(value, (bool, np.bool_)):
            raise TypeError(f"Expected `caps` to be True (close the surface on the box's faces) or False "
                            f"(leave it open there), got {value!r}")
        self._caps = bool(value)

    @property
    def levels(self) -> tuple:
        """The iso levels (tuple of floats); settable with a number or a sequence."""
        if self._levels is None:
            lo, hi = self._stat.range_info(first_cut=True)[0]
            self._levels = ((lo + hi) / 2,) if math.isfinite(lo) and math.isfinite(hi) else (0.0,)
        return self._levels

    @levels.setter
    def levels(self, value) -> None:
        self._levels = as_levels(value)

    @property
    def level_step(self) -> float:
        """How far o / i move the levels: 1/50 of the data range (1/50 of |value| or 0.02 when constant)."""
        lo, hi = self.data_range
        if not (math.isfinite(lo) and math.isfinite(hi)):
            return 0.02
        span = hi / 50 - lo / 50  # not (hi - lo) / 50: data reaching +-1e308 would overflow to inf
        return span if span > 0 else max(abs(hi), 1.0) / 50

    def step_levels(self, sign: int):
        """Move every level by ``sign * level_step``; returns the levels, or False (no change) when
        a level would leave the data range widened by one step (refused, not clamped, so the
        opposite key undoes every step made)."""
        step = self.level_step
        lo, hi = self.data_range
        new = tuple(v + (1 if sign > 0 else -1) * step for v in self.levels)
        if not all(math.isfinite(v) for v in new):
            return False  # a level never becomes inf, however it was set
        if math.isfinite(lo) and math.isfinite(hi):
            def outside(v):  # how far beyond the widened range (0 inside)
                return max(lo - step - v, v - hi - step, 0.0)

            # a level set outside by hand may still step back towards the range
            if any(outside(v) > 0 and outside(v) >= outside(u) for u, v in zip(self.levels, new)):
                return False
        self._levels = new
        return self._levels

    @property
    def actions(self) -> dict:
        """``{"o": level up, "i": level down}`` (`SourceAction`), repeating while held."""
        return {
            "o": SourceAction("level up", "raise the iso level(s) by 1/50 of the data range",
                              lambda sign=1: self.step_levels(sign)),
            "i": SourceAction("level down", "lower the iso level(s) by 1/50 of the data range",
                              lambda sign=1: self.step_levels(-sign)),
        }

    #: the source protocol's ``coarse_steps``: held keys slice the coarse copy
    coarse_steps = True

    @property
    def settings(self) -> dict:
        """The source protocol's ``settings``: the iso levels, which side is inside, the caps."""
        return {"levels": tuple(self.levels), "inside": self.inside, "caps": self.caps}

    def apply_setting(self, name: str, value) -> None:
        """Set one of `settings` (ValueError for another name; the setters validate the values)."""
        if name not in ("levels", "inside", "caps"):
            raise ValueError(f"A field's settings are 'levels', 'inside' and 'caps', not {name!r}")
        setattr(self, name, tuple(value) if name == "levels" else value)

    @property
    def resolution(self) -> int:
        """Samples along the longest side of a full step's region (int >= 2)."""
        return self._resolution

    @resolution.setter
    def resolution(self, value) -> None:
        self._resolution = check_resolution(value)

    @property
    def coarse_resolution(self) -> int:
        """Samples along the longest side of a coarse step's region (int >= 2)."""
        return self._coarse_resolution

    @coarse_resolution.setter
    def coarse_resolution(self, value) -> None:
        self._coarse_resolution = check_resolution(value, "coarse_resolution")
