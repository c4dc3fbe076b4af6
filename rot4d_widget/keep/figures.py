"""Static matplotlib renderings of w = c0 slices: one panel, key sequences, the paper's figures,
the widget's picture.

The names live in the modules that do one job each, and are all importable from here:

* `rot4d_widget.keep.drawing` -- one slice drawn in the live view's perspective (`draw_slice`,
  `perspective`, the camera constants);
* `rot4d_widget.keep.paper` -- grids of panels: `render_slice`, `render_key_sequence`, the paper's
  Figs. 3 and 4 (`paper_figure_3`, `paper_figure_4`, `panel_style`);
* `rot4d_widget.keep.framing` -- the fitted frame (`frame_extent`, `union_extent`, `FIT_FILL`),
  the corner `annotation`, a field's colour bar strip (`colorbar_width`) and box labels;
* `rot4d_widget.keep.picture` -- `render_state` (what a widget shows: a `RotationState` and any
  source, polytope, field, stack or a user's own, with the widget's display settings, at a size in
  pixels), `render_tomography` (parallel slices) and `state_source`;
* `rot4d_widget.keep.volume` -- a field's cut ray-cast in numpy (`render_grid`: ``"mip"``,
  ``"volume"`` and ``"sections"``, what ``render_state(..., rendering=...)`` draws; `default_clim`);
* `rot4d_widget.keep.canvas` -- the one reused figure an animation's frames are drawn into, with
  its glyph cache.

Functions build :class:`matplotlib.figure.Figure` objects directly and never touch
``matplotlib.pyplot``, so they work under any backend and leave pyplot's state alone.
`rot4d_widget.keep.animation` calls `render_state` through this module (``figures.render_state``),
so replacing it here reaches every frame.
"""

from __future__ import annotations

from ..core.look import REFERENCE_RADIUS as REFERENCE_RADIUS
from .canvas import _FrameCanvas as _FrameCanvas
from .canvas import _glyph_caching_renderer as _glyph_caching_renderer
from .canvas import _text_caching_canvas as _text_caching_canvas
from .drawing import (
    CAMERA_DISTANCE,
    CAMERA_FOV,
    FIG3_THETA0,
    FIG4_ALPHA,
    FIG4_THETA0,
    SliceDrawing,
    draw_slice,
    perspective,
)
from .drawing import TITLE_HEIGHT as TITLE_HEIGHT
from .drawing import _slice_collection as _slice_collection
from .framing import FIT_FILL, annotation, colorbar_width, frame_extent, turn_text, union_extent
from .framing import _level_colors as _level_colors
from .paper import panel_style, paper_figure_3, paper_figure_4, render_key_sequence, render_slice
from .picture import _prepare as _prepare
from .picture import render_state, render_tomography, state_source
from .volume import RENDERINGS, default_clim, render_grid

__all__ = [
    "CAMERA_DISTANCE",
    "CAMERA_FOV",
    "REFERENCE_RADIUS",
    "FIG3_THETA0",
    "FIG4_THETA0",
    "FIG4_ALPHA",
    "SliceDrawing",
    "perspective",
    "draw_slice",
    "panel_style",
    "render_slice",
    "render_key_sequence",
    "paper_figure_3",
    "paper_figure_4",
    "render_tomography",
    "render_state",
    "state_source",
    "FIT_FILL",
    "frame_extent",
    "union_extent",
    "annotation",
    "turn_text",
    "colorbar_width",
    "RENDERINGS",
    "render_grid",
    "default_clim",
]
