"""The 3-D view: a pythreejs scene built once, updated by assigning ONE new array.

Its pythreejs objects are a `rot4d_widget.view.stage.Stage` it holds; what goes into the
row buffer and when is decided here.  The widget talks to it through a
small interface: `Scene.canvas` (the element ipyevents watches), `view_count`
and `on_view_count`, `eye` and `on_eye_moved`, `show` (returns whether it
sent an update) and `set_display`.  The reasons for the choices below are in
docs/design.md ("Drawing on software WebGL"), the figures and their commands in
docs/performance.md.

Layers
------
Balls at a slice's points, bars along its segments and translucent faces
coloured by group, seen by a perspective camera at (0, 0, 5) looking down -z
(the paper's view; `rot4d_widget.core.camera`), turned with the mouse by
OrbitControls (keys disabled).  Every source is scaled by
``REFERENCE_RADIUS / source.size`` so it appears the size of the pentachoron.
Each layer is one instanced mesh with its own `ShaderMaterial` (GLSL in
``rot4d_widget/view/glsl/``): balls and bars are ray-cast impostors (exact
perspective silhouette, depth written), faces are instanced triangles lit at
their corners.  A new layer (an isosurface with normals, labels) is one more
mesh reading its own columns.

One update = one message, never drawn half-applied
--------------------------------------------------
All layers read ONE `InstancedInterleavedBuffer` holding the row table of
`rot4d_widget.view.buffers`.  ``show(data)`` assigns a new array to it and, in the
same ``hold_sync`` message, the update's sequence number (a synced trait the
companion reads).  Balls, bars and faces come from the same buffer, so a
frame can never show parts of two updates.

The ``maxInstancedCount`` trap: three r97 sets it from the buffer's row count
at the first render *only if undefined* and never again, and changing it from
Python is a separate message to another widget.  Drawing more instances than
the buffer has rows is a WebGL error (nothing drawn); fewer hides rows.  So
the drawn count and the row count never disagree:

* The scene has a row *capacity* R (a multiple of 16 with 12.5 % headroom,
  first estimated from a few central slices of the source) and sets
  ``maxInstancedCount = R`` on every geometry at construction.  Every normal
  update sends exactly R rows, the unused ones all zero = hidden.
* A slice needing more than R rows grows the capacity in three steps, each
  leaving the page consistent: (a) re-send the picture already shown, padded
  with hidden rows to the new capacity (same sequence number, so it is not
  acknowledged as a new update); (b) set ``maxInstancedCount`` on the
  geometries; (c) send the new slice.  Comm messages are applied in order.
  The capacity never shrinks.

Translucent faces in order: `buffers.slice_rows` orders the triangles for the
eye as the kernel knows it (exact for a convex slice: back-facing first;
otherwise by depth).  OrbitControls syncs the camera's position when a drag
ends (`on_eye_moved`); the widget then re-sends the rows (during a drag the
previous order stands).

No multisampling by default: MSAA smooths triangle edges only, and the
impostors' outlines come from a per-pixel discard; ``antialias=True`` turns
it on.  The buffer's ``version`` trait is synced back by pythreejs's front
end after every update; it is declared with ``echo_update=False`` so the
kernel does not echo it back again.
"""

from __future__ import annotations

import contextlib
import uuid

import numpy as np

from ..core import colours
from . import buffers as bf
from .cuts import NO_LABELS, CutLabels
from .stage import Stage, shader_source
from .traits import check_flag as _flag
from .traits import check_fraction as _unit
from .traits import check_positive as _positive

__all__ = ["Scene", "shader_source"]


# -- option validation -------------------------------------------------------


def _pixels(name, value):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"Expected `{name}` to be an int number of pixels in [16, 8192], got {value!r}")
    if not 16 <= int(value) <= 8192:
        raise ValueError(f"Expected `{name}` to be an int number of pixels in [16, 8192], got {value!r}")
    return int(value)


def _group_colors(value, n_groups):
    if value is None:
        return colours.group_palette(max(n_groups, 1))
    if isinstance(value, str):
        raise ValueError("Expected `group_colors` to be a sequence of colours, one per group, got a string")
    try:
        items = list(value)
    except TypeError:
        raise TypeError(f"Expected `group_colors` to be a sequence of colours, got {value!r}") from None
    if len(items) < n_groups:
        raise ValueError(f"Expected `group_colors` to have at least {n_groups} colours (one per group), "
                         f"got {len(items)}")
    rgb = [colours.as_rgb(c, f"group_colors[{i}]") for i, c in enumerate(items)]
    return np.asarray(rgb, dtype=np.float32)


#: Display options `set_display` accepts, with their validators.
DISPLAY_OPTIONS = ("ball_radius", "bar_radius", "face_opacity", "background", "show_balls", "show_bars", "show_faces")


# -- the scene ---------------------------------------------------------------


class Scene:
    """Balls, bars and group-coloured faces of a slice, in a pythreejs `Renderer`.

    Parameters
    ----------
    scale : float > 0
        Source units -> displayed units (``REFERENCE_RADIUS / source.size``).
    n_groups : int >= 1
        Colour groups (sets the palette's size).
    capacity : int >= 1
        Initial row capacity (`rot4d_widget.view.buffers.estimate_capacity`).
    width, height : int
        Canvas size in CSS pixels, 16 ... 8192.  Default 600 x 500.
    ball_radius, bar_radius : float > 0
        In displayed units (the pentachoron's circumradius is 1.26).
    face_opacity : float in [0, 1]
    background, ball_color, bar_color : '#rgb', '#rrggbb' or (r, g, b) in [0, 1]
    group_colors : sequence of such colours, at least one per group, optional
        Default `rot4d_widget.core.colours.group_palette`.
    show_balls, show_bars, show_faces : bool
    antialias : bool
        WebGL multisampling (default False).

    Attributes
    ----------
    canvas : the widget to display (the pythreejs Renderer), CSS classes
        ``rot4d-canvas`` and `canvas_class` (unique per scene)
    update_id : int -- sequence number of the last update sent (0 = none yet)
    buffer_model_id, scene_model_id : str -- for the companion
    buffer : the `RowBuffer` -- what the page holds (counts, turn, surface, volume, labels, ...)
    capacity : int -- rows per update
    """

    def __init__(
        self,
        *,
        scale,
        n_groups=1,
        capacity=16,
        width=600,
        height=500,
        ball_radius=0.07,
        bar_radius=0.028,
        face_opacity=colours.FACE_OPACITY,
        background=colours.BACKGROUND,
        ball_color=colours.BALL_COLOR,
        bar_color=colours.BAR_COLOR,
        group_colors=None,
        show_balls=True,
        show_bars=True,
        show_faces=True,
        antialias=False,
    ):
        self.scale = _positive("scale", scale)
        if isinstance(n_groups, bool) or not isinstance(n_groups, (int, np.integer)) or n_groups < 1:
            raise ValueError(f"Expected `n_groups` to be an int >= 1, got {n_groups!r}")
        self.width = _pixels("width", width)
        self.height = _pixels("height", height)
        self.ball_color = colours.as_rgb(ball_color, "ball_color")
        self.bar_color = colours.as_rgb(bar_color, "bar_color")
        if not isinstance(antialias, bool):
            raise TypeError(f"Expected `antialias` to be True or False, got {antialias!r}")
        self.group_rgb = _group_colors(group_colors, int(n_groups))
        self._user_rgb = None if group_colors is None else self.group_rgb
        if isinstance(capacity, bool) or not isinstance(capacity, (int, np.integer)) or capacity < 1:
            raise ValueError(f"Expected `capacity` to be an int >= 1, got {capacity!r}")
        self.capacity = int(capacity)
        self.update_id = 0
        self._unsent = False  # a send of the buffer failed and none succeeded since
        self.canvas_class = f"rot4d-canvas-{uuid.uuid4().hex[:12]}"
        self._closed = False
        display = self.check_display(
            dict(ball_radius=ball_radius, bar_radius=bar_radius, face_opacity=face_opacity, background=background,
                 show_balls=show_balls, show_bars=show_bars, show_faces=show_faces)
        )
        self._view_callbacks = []
        self._eye_callbacks = []
        # the pythreejs objects: one row buffer read by balls, bars and faces, the smooth surface,
        # camera, controls, renderer (built once; updates assign new arrays)
        self._rows = np.zeros((self.capacity, bf.ROW_FLOATS), dtype=np.float32)
        self._stage = Stage(rows=self._rows, width=self.width, height=self.height, antialias=antialias,
                            display=display, ball_color=self.ball_color, bar_color=self.bar_color,
                            canvas_class=self.canvas_class)
        self._buffer = self._stage.buffer
        self._display = display
        self._stage.canvas.watch_views(self._view_count_changed)
        self._stage.camera.observe(self._camera_moved, names="position")

    # -- what the widget needs ---------------------------------------------
    @property
    def canvas(self):
        """The displayable canvas widget (ipyevents watches it)."""
        return self._stage.canvas

    @property
    def buffer(self):
        """The shared `RowBuffer`: what the page holds of the view, as last sent (read it only)."""
        return self._buffer

    @property
    def buffer_model_id(self) -> str:
        """Model id of the shared buffer: its ``array`` change is the message of an update."""
        return self._buffer.model_id

    @property
    def geometry_model_ids(self) -> list:
        """Model ids of the ball, bar and face geometries (the companion sets their drawn counts)."""
        return [self._stage.geometries[k].model_id for k in ("ball", "bar", "face")]

    @property
    def mesh_model_ids(self) -> list:
        """Model ids of the ball, bar, face, surface, volume and field meshes (the companion turns them)."""
        return [self._stage.meshes[k].model_id for k in ("ball", "bar", "face", "surface", "volume", "field")]

    @property
    def texture_model_ids(self) -> list:
        """Model ids of the volume layer's atlas and colour-table textures (the companion fills them) and
        the field layer's placeholder 3-D texture (the page takes its class)."""
        return [*self._stage.volume.texture_model_ids, self._stage.field.texture_model_id]

    @property
    def scene_model_id(self) -> str:
        """Model id of the pythreejs Scene (it fires ``afterRender`` on the page)."""
        return self._stage.three_scene.model_id

    @property
    def rows(self) -> np.ndarray:
        """The row table last assigned (read-only view)."""
        v = self._rows.view()
        v.flags.writeable = False
        return v

    @property
    def eye(self) -> tuple:
        """The camera's position as the kernel knows it (OrbitControls syncs it after a drag)."""
        return tuple(float(x) for x in self._stage.camera.position)

    @property
    def view_count(self) -> int:
        """How many views of the canvas the front end reports (0 before any, or if it does not count)."""
        return self._stage.canvas.view_count

    def on_view_count(self, callback, remove=False) -> None:
        """Call ``callback(n)`` when the number of displayed views of the canvas changes."""
        _register(self._view_callbacks, callback, remove)

    def on_eye_moved(self, callback, remove=False) -> None:
        """Call ``callback(eye)`` when the camera's position changes (a mouse orbit ended)."""
        _register(self._eye_callbacks, callback, remove)

    def _view_count_changed(self, change):
        n = self.view_count
        for cb in list(self._view_callbacks):
            cb(n)

    def _camera_moved(self, change):
        eye = self.eye
        for cb in list(self._eye_callbacks):
            cb(eye)

    @property
    def display(self) -> dict:
        """The display options in force (a copy)."""
        return dict(self._display)

    @staticmethod
    def check_display(options) -> dict:
        """Validated display options (TypeError/ValueError naming what is allowed)."""
        out = {}
        for name, value in options.items():
            if name in ("ball_radius", "bar_radius"):
                out[name] = _positive(name, value, upper=10.0)
            elif name == "face_opacity":
                out[name] = _unit(name, value)
            elif name == "background":
                colours.as_rgb(value, "background")
                out[name] = value
            elif name in ("show_balls", "show_bars", "show_faces"):
                out[name] = _flag(name, value)
            else:
                raise ValueError(f"Unknown display option {name!r}; expected one of {', '.join(DISPLAY_OPTIONS)}")
        return out

    def set_display(self, **options) -> None:
        """Change display options live (each one synced trait: no new rows are sent)."""
        new = self.check_display(options)
        for name, value in new.items():
            self._stage.apply_display(name, value)
            self._display[name] = value

    def palette(self, n_groups: int) -> np.ndarray:
        """(n, 3) colours for ``n_groups`` groups: the ``group_colors`` given, followed where they
        run out by `rot4d_widget.core.colours.group_palette` (a source's group count may change at run
        time: a stack taken down to one slice shows its inner source's cells)."""
        n = max(int(n_groups), 1)
        if self._user_rgb is None:
            return colours.group_palette(n) if n != len(self.group_rgb) else self.group_rgb
        if len(self._user_rgb) >= n:
            return self._user_rgb
        more = np.asarray(colours.group_palette(n), dtype=np.float32)[len(self._user_rgb):]
        return np.concatenate([self._user_rgb, more])

    # -- the update --------------------------------------------------------
    def show(self, data, *, single_rgb=None, group_rgb=None, force=False, volume=None,
             labels: CutLabels = NO_LABELS, projection=None) -> bool:
        """Show a slice (`rot4d_widget.sources.protocol.SliceData`); True if an update was sent.

        Normally one message: a new (capacity, 20) float32 array for the shared
        buffer plus the new `update_id`.  Sends nothing and returns False if
        the rows equal those shown (unless ``force``); then `update_id` does
        not change and no "drawn" acknowledgement will come.  Never creates
        widgets.  A slice with ``normals`` is a smooth surface: its triangles
        travel quantised in the same message (``_rot4d_surface``, coloured by
        ``group_rgb`` if given), the rows carry its points' bars.  ``volume``: a ray-cast
        rendering of the cut (`volume_layer.volume_message`) sent in the same message, in place
        of any surface (None: no volume; one shown before is hidden).  ``labels``: a `CutLabels`
        (in the source's units) drawn over the canvas where its points project.
        ``projection``: what the projection view draws of this state (`ProjectionView.message`:
        ``{"state": ..., "skeleton": ...}``, the skeleton only when new), in the same message.
        """
        if self._closed:
            raise RuntimeError("this Scene is closed")
        bf.check_update_size(data, volume=volume)  # before anything is built
        smooth = data.normals is not None
        surface = None
        if smooth:  # the triangles go to the surface layer, quantised; the rows carry the rest
            arrays = bf.surface_arrays(data, scale=self.scale, eye=self.eye, single_rgb=single_rgb,
                                       group_rgb=self.group_rgb if group_rgb is None else group_rgb)
            n_levels = len(np.unique(np.asarray(data.groups))) if len(data.groups) else 0
            surface = bf.surface_message(arrays, 1.0 if n_levels <= 1 else colours.SURFACE_OPACITY)
            data = bf.without_triangles(data)
        elif self._buffer.surface or volume is not None:
            surface = {}
        if volume is None and self._buffer.volume:
            volume = {}
        pinned = labels.traits(self.scale)
        pinned = None if pinned == (self._buffer.labels, self._buffer.label_extent) else pinned
        need = bf.rows_needed(data)
        if need > self.capacity:
            self._grow(bf.capacity_for(need))
        rows = bf.slice_rows(
            data, scale=self.scale, group_rgb=self.group_rgb if group_rgb is None else group_rgb,
            capacity=self.capacity, eye=self.eye, single_rgb=single_rgb,
        )
        projection = self._buffer.projection_news(projection)
        if (not force and not self._unsent and surface is None and volume is None and pinned is None
                and projection is None and np.array_equal(rows, self._rows)
                and not self._buffer.turned):
            return False
        self.update_id += 1
        counts = [bf.ball_count(data), len(data.segments), len(data.triangles)]
        self._assign(rows, self.update_id, counts, surface=surface, volume=volume, labels=pinned,
                     projection=projection)
        return True

    def project(self, projection) -> bool:
        """`show`'s ``projection`` alone (the projection turned on, the slice unchanged: no `update_id`)."""
        if self._closed:
            raise RuntimeError("this Scene is closed")
        projection = self._buffer.projection_news(projection)
        if projection is not None:
            with self._sending():
                self._buffer.put_projection(projection)
        return projection is not None

    @property
    def surface(self) -> dict:
        """The smooth surface last sent: its quantised arrays and box (empty dict if none)."""
        return dict(self._buffer.surface)

    def turn(self, rotation, projection=None) -> bool:
        """Turn the whole view by the 3-D ``rotation`` (3, 3) relative to the rows shown; True if sent.

        One small message (no rows): the page turns the meshes as it applies
        it.  The next `show` resets the turn (its rows are in the new frame), in
        the same message.  The faces' back-to-front order stays that of the rows.
        ``projection`` as in `show`, in the same message.
        """
        if self._closed:
            raise RuntimeError("this Scene is closed")
        r = np.asarray(rotation, dtype=np.float64)
        if r.shape != (3, 3) or not np.all(np.isfinite(r)) or not np.allclose(r @ r.T, np.eye(3), atol=1e-9):
            raise ValueError(f"Expected `rotation` to be a (3, 3) rotation matrix, got shape {r.shape}")
        m4 = np.eye(4)
        m4[:3, :3] = r
        turn = [float(x) for x in m4.flatten(order="F")]
        projection = self._buffer.projection_news(projection)
        if turn == self._buffer.turn and not self._unsent and projection is None:
            return False
        self.update_id += 1
        with self._sending():
            if projection is not None:
                self._buffer.put_projection(projection)
            self._buffer.put_turn(turn, self.update_id)
        return True

    @contextlib.contextmanager
    def _sending(self):
        """The buffer's ``hold_sync``, remembering a failed send: until one succeeds, `show` and
        `turn` never take "unchanged" for an answer (the kernel's copy of the traits is ahead of
        the page's, and ipywidgets sends what it still owes with the next message)."""
        try:
            with self._buffer.hold_sync():
                yield
        except BaseException:
            self._unsent = True
            raise
        self._unsent = False

    unsent = property(lambda self: self._unsent, doc="A send failed and none succeeded since: the page is "
                      "behind, so the picture goes again even if unchanged.")

    @property
    def counts(self) -> list:
        """Rows each layer draws now: [balls, bars, faces] (the rest of the capacity is skipped)."""
        return list(self._buffer.counts)

    @property
    def turned(self) -> bool:
        """True while the view shows its rows turned by `turn` (the faces' order may be stale)."""
        return self._buffer.turned

    def _assign(self, rows, seq, counts=None, surface=None, volume=None, labels=None, projection=None):
        with self._sending():
            if projection is not None:
                self._buffer.put_projection(projection)
            self._buffer.put_picture(rows, seq, counts, surface=surface, volume=volume, labels=labels)
        self._rows = rows

    def _grow(self, capacity):
        """Grow the row capacity; every intermediate frame shows one whole picture."""
        capacity = max(int(capacity), len(self._rows))
        padded = np.zeros((capacity, bf.ROW_FLOATS), dtype=np.float32)
        padded[: len(self._rows)] = self._rows  # the rows assigned last (a failed send may have left them longer)
        self._assign(padded, self.update_id, self._buffer.counts)  # (a) same picture, more (hidden) rows
        self.capacity = capacity  # the rows are that long now, whatever (b) does
        self._stage.draw_rows(capacity)  # (b) draw them
        # (c) is the caller's normal update

    # -- teardown ----------------------------------------------------------
    def close(self) -> None:
        """Close every widget this scene created (idempotent)."""
        if self._closed:
            return
        self._closed = True
        self._view_callbacks.clear()
        self._eye_callbacks.clear()
        try:
            self._stage.canvas.watch_views(self._view_count_changed, remove=True)
            self._stage.camera.unobserve(self._camera_moved, names="position")
        except ValueError:
            pass
        self._stage.close()

    def __repr__(self) -> str:
        return f"Scene(capacity={self.capacity}, scale={self.scale:.4g}, update_id={self.update_id})"


def _register(callbacks, callback, remove):
    if remove:
        if callback in callbacks:
            callbacks.remove(callback)
    elif callback not in callbacks:
        callbacks.append(callback)
