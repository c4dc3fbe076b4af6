"""Static pictures of a view, drawn with matplotlib (or numpy for a field's ray-cast cut), without a browser.

Each module is named for what it makes:

* `slice_drawing` -- one w = c0 slice drawn in the live view's perspective (`draw_slice`,
  `perspective`, the camera and paper constants) and the checks the others share;
* `panels` -- grids of slice panels: one panel (`render_slice`), a key held down
  (`render_key_sequence`), the paper's Figs. 3 and 4 (`paper_figure_3`, `paper_figure_4`);
* `state_picture` -- what a widget shows, as a picture: `render_state` (a `RotationState` and any
  source with the widget's display settings), `render_tomography`, `state_source`;
* `framing` -- where a picture looks and what it says: the fitted frame (`frame_extent`,
  `union_extent`), the corner annotation, a field's colour bar and box labels;
* `canvas` -- the figures pictures are drawn into: text as written, and the one reused figure of
  an animation's frames with its glyph cache;
* `ray_caster` -- a field's cut ray-cast in numpy (`render_grid`: ``"mip"``, ``"volume"``,
  ``"sections"``), and `ray_caster_kernels` the same rays compiled by numba when it is installed.

Before issue 38 these were `keep.drawing`, `keep.paper`, `keep.picture`, `keep.framing`,
`keep.canvas`, `keep.volume` and `keep.volume_kernels`. Import each name from the module that
defines it; this package re-exports nothing.
"""
