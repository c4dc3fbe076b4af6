"""The update's wire format: the one synced buffer every picture travels in, and what goes with it.

The rows (balls, bars, faces) are one float32 array shared by the three instanced layers; the
traits here travel in the same comm message as the array (or alone, for a turn), so the page
applies a picture whole.  `rot4d_widget.view.scene.Scene` makes one and fills it through the
methods below (inside its ``hold_sync``); the traits' names are the wire protocol the page's
``companion.js`` reads, so only this class touches them.
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

    # -- what the page holds, as the kernel last set it --------------------
    @property
    def seq(self) -> int:
        """The id of the update last sent."""
        return self._rot4d_seq

    @property
    def counts(self) -> list:
        """The rows each layer draws: [balls, bars, faces]."""
        return self._rot4d_counts

    @property
    def turn(self) -> list:
        """The view's 3-D turn, a column-major 4x4 (`NO_TURN` when not turned)."""
        return self._rot4d_turn

    @property
    def turned(self) -> bool:
        return self._rot4d_turn != NO_TURN

    @property
    def surface(self) -> dict:
        """The smooth surface last sent ({} = none)."""
        return self._rot4d_surface

    @property
    def volume(self) -> dict:
        """The cut(s) last sent for the ray-cast renderings ({} = none)."""
        return self._rot4d_volume

    @property
    def labels(self) -> list:
        """The texts pinned to points of the view (`CutLabels.traits`' first part)."""
        return self._rot4d_labels

    @property
    def label_extent(self) -> list:
        """The data's extent the box labels keep clear of (`CutLabels.traits`' second part)."""
        return self._rot4d_label_extent

    @property
    def skeleton(self) -> dict:
        """The projection's skeleton last sent ({} = none)."""
        return self._rot4d_skeleton

    @property
    def projection(self) -> dict:
        """The projection's state last sent ({} = none)."""
        return self._rot4d_project

    # -- setting it (the caller holds the sync: one message) ---------------
    def projection_news(self, projection):
        """``projection`` (`Scene.show`'s ``{"state": ..., "skeleton": ...}``) if it changes what the
        page holds, else None."""
        if projection is None or "skeleton" in projection or projection["state"] != self._rot4d_project:
            return projection
        return None

    def put_projection(self, projection) -> None:
        if "skeleton" in projection:
            self._rot4d_skeleton = projection["skeleton"]
        self._rot4d_project = projection["state"]

    def put_turn(self, turn, seq) -> None:
        """A turn of the whole view (no rows) as update ``seq``."""
        self._rot4d_turn = turn
        self._rot4d_seq = seq

    def put_picture(self, rows, seq, counts=None, surface=None, volume=None, labels=None) -> None:
        """New rows as update ``seq``, with what travels with them (None: unchanged); resets the turn."""
        if labels is not None:
            self._rot4d_label_extent, self._rot4d_labels = labels[1], labels[0]
        if surface is not None:
            self._rot4d_surface = surface
        if volume is not None:
            self._rot4d_volume = volume
        self.array = rows
        self._rot4d_seq = seq
        if counts is not None:
            self._rot4d_counts = [int(c) for c in counts]
        if self._rot4d_turn != NO_TURN:
            self._rot4d_turn = list(NO_TURN)
