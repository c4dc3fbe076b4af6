"""The 3-D view: a pythreejs scene built once, updated by assigning ONE new array.

The only module that imports pythreejs.  The widget talks to it through a
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
import functools
import pathlib
import re
import uuid

import numpy as np
import pythreejs as p3

from ..core import camera, colours
from . import buffers as bf
from .cuts import NO_LABELS, CutLabels
from .field_layer import FieldLayer
from .keypad import close_quietly
from .rowbuffer import NO_TURN, RowBuffer
from .traits import check_flag as _flag
from .traits import check_fraction as _unit
from .traits import check_positive as _positive
from .volume_layer import VolumeLayer

__all__ = ["Scene", "shader_source"]

_GLSL = pathlib.Path(__file__).with_name("glsl")
_INCLUDE = re.compile(r"^// @include (\S+)$", re.M)


@functools.lru_cache(maxsize=None)
def shader_source(name: str) -> str:
    """The GLSL of ``rot4d_widget/view/glsl/<name>`` with its ``// @include FILE`` lines expanded."""
    text = (_GLSL / name).read_text()
    return _INCLUDE.sub(lambda m: shader_source(m.group(1)), text)


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
        self._display = {}
        display = self.check_display(
            dict(ball_radius=ball_radius, bar_radius=bar_radius, face_opacity=face_opacity, background=background,
                 show_balls=show_balls, show_bars=show_bars, show_faces=show_faces)
        )
        self._view_callbacks = []
        self._eye_callbacks = []
        self._build(antialias, display)

    # -- construction ------------------------------------------------------
    def _build(self, antialias, display):
        _build_three(self, antialias, display)

    def _ball_uniforms(self, radius):
        return dict(self._light, u_ball_radius={"value": radius}, u_ball_color={"value": list(self.ball_color)})

    def _bar_uniforms(self, radius):
        return dict(self._light, u_bar_radius={"value": radius}, u_bar_color={"value": list(self.bar_color)})

    def _face_uniforms(self, opacity):
        return dict(self._light, u_opacity={"value": opacity})

    def _surface_uniforms(self):
        # u_lo, u_span, u_opacity: set by the companion with each surface
        return dict(self._light, u_lo={"value": [0.0, 0.0, 0.0]}, u_span={"value": [1.0, 1.0, 1.0]},
                    u_opacity={"value": 1.0})

    # -- what the widget needs ---------------------------------------------
    @property
    def canvas(self):
        """The displayable canvas widget (ipyevents watches it)."""
        return self._renderer

    @property
    def buffer_model_id(self) -> str:
        """Model id of the shared buffer: its ``array`` change is the message of an update."""
        return self._buffer.model_id

    @property
    def geometry_model_ids(self) -> list:
        """Model ids of the ball, bar and face geometries (the companion sets their drawn counts)."""
        return [self._geometries[k].model_id for k in ("ball", "bar", "face")]

    @property
    def mesh_model_ids(self) -> list:
        """Model ids of the ball, bar, face, surface, volume and field meshes (the companion turns them)."""
        return [self._meshes[k].model_id for k in ("ball", "bar", "face", "surface", "volume", "field")]

    @property
    def texture_model_ids(self) -> list:
        """Model ids of the volume layer's atlas and colour-table textures (the companion fills them) and
        the field layer's placeholder 3-D texture (the page takes its class)."""
        return [*self._volume.texture_model_ids, self._field.texture_model_id]

    @property
    def scene_model_id(self) -> str:
        """Model id of the pythreejs Scene (it fires ``afterRender`` on the page)."""
        return self._three_scene.model_id

    @property
    def rows(self) -> np.ndarray:
        """The row table last assigned (read-only view)."""
        v = self._rows.view()
        v.flags.writeable = False
        return v

    @property
    def eye(self) -> tuple:
        """The camera's position as the kernel knows it (OrbitControls syncs it after a drag)."""
        return tuple(float(x) for x in self._camera.position)

    @property
    def view_count(self) -> int:
        """How many views of the canvas the front end reports (0 before any, or if it does not count)."""
        n = self._renderer._view_count
        return n if isinstance(n, int) else 0

    def on_view_count(self, callback, remove=False) -> None:
        """Call ``callback(n)`` when the number of displayed views of the canvas changes."""
        _register(self._view_callbacks, callback, remove)

    def on_eye_moved(self, callback, remove=False) -> None:
        """Call ``callback(eye)`` when the camera's position changes (a mouse orbit ended)."""
        _register(self._eye_callbacks, callback, remove)

    def _view_count_changed(self, change):
        n = change["new"]
        for cb in list(self._view_callbacks):
            cb(n if isinstance(n, int) else 0)

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
            if name == "ball_radius":
                self._materials["ball"].uniforms = self._ball_uniforms(value)
            elif name == "bar_radius":
                self._materials["bar"].uniforms = self._bar_uniforms(value)
            elif name == "face_opacity":
                self._materials["face"].uniforms = self._face_uniforms(value)
            elif name == "background":
                h = colours.hex_color(colours.as_rgb(value, "background"))
                with self._renderer.hold_sync():
                    self._renderer.background = h
                    self._renderer.clearColor = h
            else:
                self._meshes[{"show_balls": "ball", "show_bars": "bar", "show_faces": "face"}[name]].visible = value
                if name == "show_faces":
                    self._meshes["surface"].visible = value
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
        smooth = getattr(data, "normals", None) is not None
        surface = None
        if smooth:  # the triangles go to the surface layer, quantised; the rows carry the rest
            arrays = bf.surface_arrays(data, scale=self.scale, eye=self.eye, single_rgb=single_rgb,
                                       group_rgb=self.group_rgb if group_rgb is None else group_rgb)
            n_levels = len(np.unique(np.asarray(data.groups))) if len(data.groups) else 0
            surface = bf.surface_message(arrays, 1.0 if n_levels <= 1 else colours.SURFACE_OPACITY)
            data = bf.without_triangles(data)
        elif self._surface_shown or volume is not None:
            surface = {}
        if volume is None and self._volume_shown:
            volume = {}
        pinned = labels.traits(self.scale)
        pinned = None if pinned == (self._buffer._rot4d_labels, self._buffer._rot4d_label_extent) else pinned
        need = bf.rows_needed(data)
        if need > self.capacity:
            self._grow(bf.capacity_for(need))
        rows = bf.slice_rows(
            data, scale=self.scale, group_rgb=self.group_rgb if group_rgb is None else group_rgb,
            capacity=self.capacity, eye=self.eye, single_rgb=single_rgb,
        )
        projection = _projection_news(self._buffer, projection)
        if (not force and not self._unsent and surface is None and volume is None and pinned is None
                and projection is None and np.array_equal(rows, self._rows)
                and self._buffer._rot4d_turn == NO_TURN):
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
        projection = _projection_news(self._buffer, projection)
        if projection is not None:
            with self._sending():
                _put_projection(self._buffer, projection)
        return projection is not None

    @property
    def surface(self) -> dict:
        """The smooth surface last sent: its quantised arrays and box (empty dict if none)."""
        return dict(self._buffer._rot4d_surface)

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
        projection = _projection_news(self._buffer, projection)
        if turn == self._buffer._rot4d_turn and not self._unsent and projection is None:
            return False
        self.update_id += 1
        with self._sending():
            if projection is not None:
                _put_projection(self._buffer, projection)
            self._buffer._rot4d_turn = turn
            self._buffer._rot4d_seq = self.update_id
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
        return list(self._buffer._rot4d_counts)

    @property
    def turned(self) -> bool:
        """True while the view shows its rows turned by `turn` (the faces' order may be stale)."""
        return self._buffer._rot4d_turn != NO_TURN

    def _assign(self, rows, seq, counts=None, surface=None, volume=None, labels=None, projection=None):
        buf = self._buffer
        with self._sending():
            if projection is not None:
                _put_projection(self._buffer, projection)
            if labels is not None:
                buf._rot4d_label_extent, buf._rot4d_labels = labels[1], labels[0]
            if surface is not None:
                buf._rot4d_surface = surface
                self._surface_shown = bool(surface)
            if volume is not None:
                buf._rot4d_volume = volume
                self._volume_shown = bool(volume)
            buf.array = rows
            buf._rot4d_seq = seq
            if counts is not None:
                buf._rot4d_counts = [int(c) for c in counts]
            if buf._rot4d_turn != NO_TURN:
                buf._rot4d_turn = list(NO_TURN)
        self._rows = rows

    def _grow(self, capacity):
        """Grow the row capacity; every intermediate frame shows one whole picture."""
        capacity = max(int(capacity), len(self._rows))
        padded = np.zeros((capacity, bf.ROW_FLOATS), dtype=np.float32)
        padded[: len(self._rows)] = self._rows  # the rows assigned last (a failed send may have left them longer)
        self._assign(padded, self.update_id, self._buffer._rot4d_counts)  # (a) same picture, more (hidden) rows
        self.capacity = capacity  # the rows are that long now, whatever (b) does
        for g in self._geometries.values():  # (b) draw them
            g.maxInstancedCount = capacity
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
            self._renderer.unobserve(self._view_count_changed, names="_view_count")
            self._camera.unobserve(self._camera_moved, names="position")
        except ValueError:
            pass
        for w in self._widgets:  # with the Layout / Style / shadow map each one made for itself
            close_quietly(w)

    def __repr__(self) -> str:
        return f"Scene(capacity={self.capacity}, scale={self.scale:.4g}, update_id={self.update_id})"


def _build_three(scene, antialias, display):
    """The pythreejs objects of ``scene``: one row buffer read by balls, bars and faces, the smooth
    surface, camera, controls, renderer (built once; updates assign new arrays)."""
    scene._rows = np.zeros((scene.capacity, bf.ROW_FLOATS), dtype=np.float32)
    scene._buffer = RowBuffer(array=scene._rows, meshPerAttribute=1)
    attrs = {
        name: p3.InterleavedBufferAttribute(data=scene._buffer, itemSize=size, offset=col)
        for name, (col, size) in bf.COLUMNS.items()
    }
    templates = {
        "ball": {"position": p3.BufferAttribute(array=bf.quad_template())},
        "bar": {"position": p3.BufferAttribute(array=bf.quad_template())},
        "face": {"position": p3.BufferAttribute(array=bf.triangle_template())},
    }
    uses = {
        "ball": ("ball",),
        "bar": ("bar_a", "bar_b"),
        "face": ("tri_a", "tri_b", "tri_c", "tri_rgb"),
    }
    scene._geometries = {}
    for part, names in uses.items():
        a = dict(templates[part])
        a.update({n: attrs[n] for n in names})
        scene._geometries[part] = p3.InstancedBufferGeometry(attributes=a, maxInstancedCount=scene.capacity)

    scene._light = {
        "u_ambient": {"value": [0.28, 0.28, 0.28]},
        "u_sky": {"value": [0.30, 0.30, 0.32]},
        "u_ground": {"value": [0.08, 0.07, 0.06]},
        "u_light_color": {"value": [0.62, 0.62, 0.60]},
        "u_light_position": {"value": [-3.0, 4.0, 2.0]},
        "u_specular": {"value": 0.35},
    }
    scene._materials = {
        "ball": p3.ShaderMaterial(
            vertexShader=shader_source("ball.vert"),
            fragmentShader=shader_source("ball.frag"),
            uniforms=scene._ball_uniforms(display["ball_radius"]),
            extensions={"fragDepth": True},
            side="DoubleSide",
        ),
        "bar": p3.ShaderMaterial(
            vertexShader=shader_source("bar.vert"),
            fragmentShader=shader_source("bar.frag"),
            uniforms=scene._bar_uniforms(display["bar_radius"]),
            extensions={"fragDepth": True},
            side="DoubleSide",
        ),
        "face": p3.ShaderMaterial(
            vertexShader=shader_source("face.vert"),
            fragmentShader=shader_source("face.frag"),
            uniforms=scene._face_uniforms(display["face_opacity"]),
            side="DoubleSide",
            transparent=True,
            depthWrite=False,
        ),
    }
    # the smooth surface (a field's isosurfaces): indexed, quantised; the companion
    # replaces these placeholder arrays (their types stay) as it applies an update
    scene._surface_attrs = {
        "position": p3.BufferAttribute(array=np.zeros((3, 3), dtype=np.uint16), normalized=True),
        "normal": p3.BufferAttribute(array=np.zeros((3, 3), dtype=np.int8), normalized=True),
        "a_rgb": p3.BufferAttribute(array=np.zeros((3, 3), dtype=np.uint8), normalized=True),
    }
    scene._surface_index = p3.BufferAttribute(array=np.zeros(0, dtype=np.uint32))
    scene._surface_geometry = p3.BufferGeometry(attributes=scene._surface_attrs, index=scene._surface_index)
    scene._materials["surface"] = p3.ShaderMaterial(
        vertexShader=shader_source("surface.vert"),
        fragmentShader=shader_source("surface.frag"),
        uniforms=scene._surface_uniforms(),
        side="DoubleSide",
        transparent=True,
        depthWrite=True,
    )
    names = {"ball": "balls", "bar": "bars", "face": "faces"}
    scene._meshes = {
        part: p3.Mesh(
            geometry=scene._geometries[part], material=scene._materials[part], frustumCulled=False,
            name=names[part], visible=display[f"show_{names[part]}"],
        )
        for part in ("ball", "bar", "face")
    }
    scene._meshes["surface"] = p3.Mesh(
        geometry=scene._surface_geometry, material=scene._materials["surface"], frustumCulled=False,
        name="surface", visible=display["show_faces"],
    )
    scene._volume = VolumeLayer()  # a field's cut ray-cast: hidden until a volume arrives
    scene._meshes["volume"] = scene._volume.build(shader_source)
    scene._field = FieldLayer(scene._light)  # the page's own picture of a field (issue 36): hidden
    scene._meshes["field"] = scene._field.build(shader_source)
    scene._camera = p3.PerspectiveCamera(
        position=list(camera.CAMERA_POSITION), fov=camera.CAMERA_FOV, aspect=scene.width / scene.height,
        near=camera.CAMERA_NEAR, far=camera.CAMERA_FAR,
    )
    scene._three_scene = p3.Scene(children=[*scene._meshes.values(), scene._camera], background=None)
    scene._controls = p3.OrbitControls(controlling=scene._camera, enableKeys=False)
    background = colours.hex_color(colours.as_rgb(display["background"], "background"))
    scene._renderer = p3.Renderer(
        camera=scene._camera,
        scene=scene._three_scene,
        controls=[scene._controls],
        width=scene.width,
        height=scene.height,
        antialias=antialias,
        background=background,
        background_opacity=1.0,
        clearColor=background,
    )
    scene._renderer.add_class("rot4d-canvas")
    scene._renderer.add_class(scene.canvas_class)
    scene._display = display
    scene._widgets = [
        scene._renderer, scene._controls, scene._three_scene, scene._camera, *scene._meshes.values(),
        *scene._materials.values(), *scene._geometries.values(), *attrs.values(), scene._buffer,
        *(a for t in templates.values() for a in t.values()),
        scene._surface_geometry, *scene._surface_attrs.values(), scene._surface_index,
        *(w for w in scene._volume.widgets if w is not scene._meshes["volume"]),
        *(w for w in scene._field.widgets if w is not scene._meshes["field"]),
    ]  # fmt: skip
    scene._surface_shown = False
    scene._volume_shown = False
    # ipywidgets' view count, kept by the front end on request (None: not requested)
    if scene._renderer._view_count is None:
        scene._renderer._view_count = 0
    scene._renderer.observe(scene._view_count_changed, names="_view_count")
    scene._camera.observe(scene._camera_moved, names="position")


def _projection_news(buffer, projection):
    """``projection`` (`Scene.show`'s) if it changes what the page holds, else None."""
    if projection is None or "skeleton" in projection or projection["state"] != buffer._rot4d_project:
        return projection
    return None


def _put_projection(buffer, projection):
    if "skeleton" in projection:
        buffer._rot4d_skeleton = projection["skeleton"]
    buffer._rot4d_project = projection["state"]


def _register(callbacks, callback, remove):
    if remove:
        if callback in callbacks:
            callbacks.remove(callback)
    elif callback not in callbacks:
        callbacks.append(callback)
