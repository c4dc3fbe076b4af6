"""What the page needs to draw its own picture of a field it holds (issue 36), besides the data
(`rot4d_widget.view.pagefield`) and the state it predicts.

* `view_message`: the field's view settings that keys change -- the rendering, the section planes,
  the iso levels -- and the rules the page steps them by (`rot4d_widget.view.fieldkeys.view_rules`),
  carried in the kernel's state (`rot4d_widget.view.pagestate.state_message`) so the page adopts
  them with the state.
* `field_config`: everything else, the companion's synced ``field_config``: the field's box (half
  widths, slice units) and w frame, the view's scale, where each cut lies and is placed (a stack's
  offsets, centres and scales), the kernel's grid resolutions and ray steps (held and at rest),
  the colour table of ``cmap`` and the colour limits the kernel's pictures use (``clim``, else the
  limits of the last ray-cast picture, else the 1st-99th percentile of the page's copy), the
  density, which side is inside and the caps, the colours of the levels (or of a stack's cuts, or
  one colour) and the surfaces' opacity, the copy's texture side (a page whose WebGL cannot hold it
  does not ask).  Numbers as JSON; the colour table as 1024 integers.
"""

from __future__ import annotations

import numpy as np

from ..core import colours, renderings
from ..sources.protocol import inner_source, w_frame
from ..sources.tomography import StackSource
from .cuts import STACK_NODES, can_sample
from .fieldkeys import view_rules
from .volume_layer import HELD_STEP, MAX_STEPS, STEP, colour_table

__all__ = ["view_message", "field_config", "copy_clim", "MARCH", "HELD_MARCH"]

#: The page's surfaces are marched every this many kernel grid spacings at rest (and refined by
#: bisection), and while keys are held every this many spacings of the coarse grid.
MARCH = 0.5
HELD_MARCH = 1.0


def view_message(source, rendering: str, sections) -> dict | None:
    """``{"rendering", "sections", "levels"}`` of a field's view (None for a source without renderings)."""
    if not can_sample(source):
        return None
    inner = inner_source(source)
    return {"rendering": rendering, "sections": [float(s) for s in sections],
            "levels": [float(v) for v in inner.levels], **view_rules(source)}


def _rgb(colours) -> list:
    """Colours as the surface layer quantises them (uint8), back in [0, 1]."""
    c = np.rint(np.clip(np.asarray(colours, dtype=np.float64).reshape(-1, 3), 0.0, 1.0) * 255.0) / 255.0
    return [[float(x) for x in row] for row in c]


def copy_clim(values) -> list:
    """The 1st and 99th percentiles of a copy's values (every 7th: the same to a few codes, quickly):
    the page's colour limits when neither ``clim`` nor a ray-cast picture of the kernel's gives any."""
    v = np.asarray(values).reshape(-1)[::7]
    return [float(x) for x in colours.default_clim(v)]


def field_config(src, scale: float, field, *, cmap: str, clim, color_by, cast_clim, default_clim_: list,
                 texture_side: int, painted) -> dict:
    """The page's ``field_config`` for ``field`` (the `Field4D` the page holds) inside the shown source
    ``src``, drawn at ``scale``; ``cmap``, ``clim``, ``color_by`` the view's, ``cast_clim`` the
    limits of the kernel's last ray-cast picture (`Painter.cast_clim`); ``default_clim_`` the copy's
    `copy_clim`, ``texture_side`` the copy's longest texture side, ``painted`` the painter's
    ``(rgb, labels)`` (`Painter.colours`)."""
    origin, per = w_frame(src)
    if isinstance(src, StackSource) and src.slices > 1:
        dc = np.asarray(src.cuts_at(0.0), dtype=np.float64)
        centres, scales = src.layout()
        slices = [{"dc": float(dc[k]), "centre": [float(x) for x in centres[k]], "scale": float(scales[k])}
                  for k in range(len(dc))]
    else:
        slices = [{"dc": 0.0, "centre": [0.0, 0.0, 0.0], "scale": 1.0}]
    level_by_value = clim is not None
    clim = clim if clim is not None else cast_clim
    if clim is None:
        clim = default_clim_
    rgb, labels = painted
    single = None if color_by == "group" else colours.as_rgb(color_by, "color_by")
    by_slice = labels is not None and inner_source(src) is not src  # a stack coloured by w
    return {
        "hw": [float(h) for h in field.half_widths],
        "origin": float(origin), "per_unit": float(per), "scale": float(scale),
        "slices": slices,
        "resolution": int(field.resolution), "coarse_resolution": int(field.coarse_resolution),
        "stack_nodes": int(STACK_NODES),
        "step": float(STEP), "held_step": float(HELD_STEP), "max_steps": int(MAX_STEPS),
        "march": float(MARCH), "held_march": float(HELD_MARCH),
        "lut": [int(b) for b in colour_table(cmap).reshape(-1)],
        "clim": [float(clim[0]), float(clim[1])],
        "density": float(renderings.DEFAULT_DENSITY),
        "inside": field.inside, "caps": bool(field.caps),
        "level_rgb": _rgb(rgb) if not by_slice else [],
        "level_by_value": level_by_value and single is None and not by_slice,
        "box_rgb": _rgb(rgb) if by_slice and single is None else None,
        "single_rgb": None if single is None else _rgb([single])[0],
        "surface_opacity": float(colours.SURFACE_OPACITY),
        "texture_side": int(texture_side),
    }
