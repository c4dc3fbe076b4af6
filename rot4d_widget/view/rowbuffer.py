"""The update's wire format: the one synced buffer every picture travels in, and what goes with it.

The rows (balls, bars, faces) are one float32 array shared by the three instanced layers; the
traits here travel in the same comm message as the array (or alone, for a turn), so the page
applies a picture whole.  `rot4d_widget.view.scene.Scene` makes one and fills it.
"""

from __future__ import annotations

import pythreejs as p3
from traitlets import CFloat, CInt, Dict, List

__all__ = ["RowBuffer", "NO_TURN"]

#: The turn trait when the view is not turned: the identity, column-major.
NO_TURN = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0]


class RowBuffer(p3.InstancedInterleavedBuffer):
    """The shared buffer.  What travels in the same message as the array (or alone, for a turn):

    ``_rot4d_seq`` the update's id; ``_rot4d_counts`` the rows each layer draws
    (balls, bars, faces: the companion sets the geometries' drawn count as it
    applies the message); ``_rot4d_turn`` a 3-D turn of the whole view as a
    column-major 4x4 (the companion sets it on the meshes); ``_rot4d_surface``
    a smooth surface's quantised arrays (the companion uploads them); ``_rot4d_volume`` a
    field's cut(s) on grids for the ray-cast renderings (`rot4d_widget.view.volume_layer`);
    ``_rot4d_skeleton`` and ``_rot4d_project`` what the projection view draws (the companion
    projects the skeleton in the page, `rot4d_widget.view.projection`).
    """

    _rot4d_seq = CInt(0).tag(sync=True)
    _rot4d_counts = List(CInt(), default_value=[0, 0, 0]).tag(sync=True)
    _rot4d_turn = List(CFloat(), default_value=NO_TURN).tag(sync=True)
    #: A smooth surface (`buffers.surface_arrays`, arrays as bytes): the companion uploads it
    #: into the surface mesh as it applies the same message as the rows.  {} = none.
    _rot4d_surface = Dict().tag(sync=True)
    #: The cut(s) as an atlas, boxes and colour table (`volume_layer.volume_message`).  {} = none.
    _rot4d_volume = Dict().tag(sync=True)
    #: Texts pinned to points of the view, turned with it, and the data's extent the box labels keep
    #: clear of ([x, y, z] displayed units; `rot4d_widget.view.cuts.CutLabels.traits`).
    _rot4d_labels = List(Dict()).tag(sync=True)
    _rot4d_label_extent = List(List(CFloat())).tag(sync=True)
    #: The projection's skeleton, sent once per source (`projection.skeleton_message`).  {} = none.
    _rot4d_skeleton = Dict().tag(sync=True)
    #: The projection's state, with every update while it is shown (`projection.state_message`).
    _rot4d_project = Dict().tag(sync=True)
    version = CInt(0).tag(sync=True, echo_update=False)
