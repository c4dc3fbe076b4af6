"""The pythreejs objects of one `rot4d_widget.view.scene.Scene`, built once: its `Stage`.

One `RowBuffer` read by the instanced ball, bar and face layers (``ShaderMaterial``s with the GLSL
of ``rot4d_widget/view/glsl/``), the smooth surface's indexed mesh, the volume and field layers,
camera, OrbitControls (keys disabled) and the renderer (a `Canvas`, which counts its views on the
page).  Updates assign new arrays and uniforms to these objects; none is ever rebuilt.  What goes
into the buffer and when is the `Scene`'s business; the stage says how each display option lands
on its objects (`Stage.apply_display`) and how many rows its layers draw (`Stage.draw_rows`).
"""

from __future__ import annotations

import functools
import pathlib
import re

import numpy as np
import pythreejs as p3

from ..core import camera, colours
from . import buffers as bf
from .field_layer import FieldLayer
from .keypad import close_quietly
from .rowbuffer import RowBuffer
from .volume_layer import VolumeLayer

__all__ = ["Stage", "Canvas", "shader_source", "LAYERS"]

_GLSL = pathlib.Path(__file__).with_name("glsl")
_INCLUDE = re.compile(r"^// @include (\S+)$", re.M)

#: The row buffer's instanced layers, their mesh names and the columns each reads.
LAYERS = {
    "ball": ("balls", ("ball",)),
    "bar": ("bars", ("bar_a", "bar_b")),
    "face": ("faces", ("tri_a", "tri_b", "tri_c", "tri_rgb")),
}


def light_uniforms() -> dict:
    """The lights every ShaderMaterial of a stage shades with (a new dict of uniforms)."""
    return {
        "u_ambient": {"value": [0.28, 0.28, 0.28]},
        "u_sky": {"value": [0.30, 0.30, 0.32]},
        "u_ground": {"value": [0.08, 0.07, 0.06]},
        "u_light_color": {"value": [0.62, 0.62, 0.60]},
        "u_light_position": {"value": [-3.0, 4.0, 2.0]},
        "u_specular": {"value": 0.35},
    }


@functools.lru_cache(maxsize=None)
def shader_source(name: str) -> str:
    """The GLSL of ``rot4d_widget/view/glsl/<name>`` with its ``// @include FILE`` lines expanded."""
    text = (_GLSL / name).read_text()
    return _INCLUDE.sub(lambda m: shader_source(m.group(1)), text)


class Canvas(p3.Renderer):
    """pythreejs's `Renderer` (the same model on the page) that counts its views there.

    The count is ipywidgets' ``_view_count``, kept by the front end only when asked for (not None).
    """

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        if self._view_count is None:
            self._view_count = 0

    @property
    def view_count(self) -> int:
        """How many views of the canvas the front end reports (0 before any, or if it does not count)."""
        n = self._view_count
        return n if isinstance(n, int) else 0

    def watch_views(self, handler, remove=False) -> None:
        """Call ``handler(change)`` (a traitlets change) when the number of views changes."""
        if remove:
            self.unobserve(handler, names="_view_count")
        else:
            self.observe(handler, names="_view_count")


class Stage:
    """The scene's pythreejs objects (public attributes; built once, never rebuilt).

    Parameters
    ----------
    rows : the (capacity, ROW_FLOATS) float32 row table the buffer starts with
    width, height : canvas size in CSS pixels
    antialias : bool
    display : validated display options (`Scene.check_display`), all of them
    ball_color, bar_color : (r, g, b)
    canvas_class : the canvas's own CSS class (besides ``rot4d-canvas``)
    """

    def __init__(self, *, rows, width, height, antialias, display, ball_color, bar_color, canvas_class):
        self.ball_color, self.bar_color = ball_color, bar_color
        self.light = light_uniforms()
        self.buffer = RowBuffer(array=rows, meshPerAttribute=1)
        self.attributes = {
            name: p3.InterleavedBufferAttribute(data=self.buffer, itemSize=size, offset=col)
            for name, (col, size) in bf.COLUMNS.items()
        }
        self.templates = {
            "ball": p3.BufferAttribute(array=bf.quad_template()),
            "bar": p3.BufferAttribute(array=bf.quad_template()),
            "face": p3.BufferAttribute(array=bf.triangle_template()),
        }
        capacity = len(rows)
        self.geometries = {
            part: p3.InstancedBufferGeometry(
                attributes={"position": self.templates[part], **{n: self.attributes[n] for n in columns}},
                maxInstancedCount=capacity,
            )
            for part, (_, columns) in LAYERS.items()
        }
        self.materials = {
            "ball": p3.ShaderMaterial(
                vertexShader=shader_source("ball.vert"), fragmentShader=shader_source("ball.frag"),
                uniforms=self._ball_uniforms(display["ball_radius"]), extensions={"fragDepth": True},
                side="DoubleSide",
            ),
            "bar": p3.ShaderMaterial(
                vertexShader=shader_source("bar.vert"), fragmentShader=shader_source("bar.frag"),
                uniforms=self._bar_uniforms(display["bar_radius"]), extensions={"fragDepth": True},
                side="DoubleSide",
            ),
            "face": p3.ShaderMaterial(
                vertexShader=shader_source("face.vert"), fragmentShader=shader_source("face.frag"),
                uniforms=self._face_uniforms(display["face_opacity"]), side="DoubleSide", transparent=True,
                depthWrite=False,
            ),
        }
        # the smooth surface (a field's isosurfaces): indexed, quantised; the companion
        # replaces these placeholder arrays (their types stay) as it applies an update
        self.surface_attributes = {
            "position": p3.BufferAttribute(array=np.zeros((3, 3), dtype=np.uint16), normalized=True),
            "normal": p3.BufferAttribute(array=np.zeros((3, 3), dtype=np.int8), normalized=True),
            "a_rgb": p3.BufferAttribute(array=np.zeros((3, 3), dtype=np.uint8), normalized=True),
        }
        self.surface_index = p3.BufferAttribute(array=np.zeros(0, dtype=np.uint32))
        self.surface_geometry = p3.BufferGeometry(attributes=self.surface_attributes, index=self.surface_index)
        self.materials["surface"] = p3.ShaderMaterial(
            vertexShader=shader_source("surface.vert"), fragmentShader=shader_source("surface.frag"),
            uniforms=self._surface_uniforms(), side="DoubleSide", transparent=True, depthWrite=True,
        )
        self.meshes = {
            part: p3.Mesh(geometry=self.geometries[part], material=self.materials[part], frustumCulled=False,
                          name=name, visible=display[f"show_{name}"])
            for part, (name, _) in LAYERS.items()
        }
        self.meshes["surface"] = p3.Mesh(
            geometry=self.surface_geometry, material=self.materials["surface"], frustumCulled=False,
            name="surface", visible=display["show_faces"],
        )
        self.volume = VolumeLayer()  # a field's cut ray-cast: hidden until a volume arrives
        self.meshes["volume"] = self.volume.build(shader_source)
        self.field = FieldLayer(self.light)  # the page's own picture of a field (issue 36): hidden
        self.meshes["field"] = self.field.build(shader_source)
        self.camera = p3.PerspectiveCamera(
            position=list(camera.CAMERA_POSITION), fov=camera.CAMERA_FOV, aspect=width / height,
            near=camera.CAMERA_NEAR, far=camera.CAMERA_FAR,
        )
        self.three_scene = p3.Scene(children=[*self.meshes.values(), self.camera], background=None)
        self.controls = p3.OrbitControls(controlling=self.camera, enableKeys=False)
        background = colours.hex_color(colours.as_rgb(display["background"], "background"))
        self.canvas = Canvas(
            camera=self.camera, scene=self.three_scene, controls=[self.controls], width=width, height=height,
            antialias=antialias, background=background, background_opacity=1.0, clearColor=background,
        )
        self.canvas.add_class("rot4d-canvas")
        self.canvas.add_class(canvas_class)

    @property
    def widgets(self) -> list:
        """Every widget the stage made (with the Layout / Style / shadow map each one made for itself)."""
        return [
            self.canvas, self.controls, self.three_scene, self.camera, *self.meshes.values(),
            *self.materials.values(), *self.geometries.values(), *self.attributes.values(), self.buffer,
            *self.templates.values(),
            self.surface_geometry, *self.surface_attributes.values(), self.surface_index,
            *(w for w in self.volume.widgets if w is not self.meshes["volume"]),
            *(w for w in self.field.widgets if w is not self.meshes["field"]),
        ]  # fmt: skip

    def _ball_uniforms(self, radius):
        return dict(self.light, u_ball_radius={"value": radius}, u_ball_color={"value": list(self.ball_color)})

    def _bar_uniforms(self, radius):
        return dict(self.light, u_bar_radius={"value": radius}, u_bar_color={"value": list(self.bar_color)})

    def _face_uniforms(self, opacity):
        return dict(self.light, u_opacity={"value": opacity})

    def _surface_uniforms(self):
        # u_lo, u_span, u_opacity: set by the companion with each surface
        return dict(self.light, u_lo={"value": [0.0, 0.0, 0.0]}, u_span={"value": [1.0, 1.0, 1.0]},
                    u_opacity={"value": 1.0})

    def apply_display(self, name, value) -> None:
        """Put one validated display option on the objects it changes (each one synced trait)."""
        if name == "ball_radius":
            self.materials["ball"].uniforms = self._ball_uniforms(value)
        elif name == "bar_radius":
            self.materials["bar"].uniforms = self._bar_uniforms(value)
        elif name == "face_opacity":
            self.materials["face"].uniforms = self._face_uniforms(value)
        elif name == "background":
            h = colours.hex_color(colours.as_rgb(value, "background"))
            with self.canvas.hold_sync():
                self.canvas.background = h
                self.canvas.clearColor = h
        else:
            self.meshes[{"show_balls": "ball", "show_bars": "bar", "show_faces": "face"}[name]].visible = value
            if name == "show_faces":
                self.meshes["surface"].visible = value

    def draw_rows(self, capacity) -> None:
        """Let the instanced layers draw ``capacity`` rows (the buffer must hold that many already)."""
        for g in self.geometries.values():
            g.maxInstancedCount = capacity

    def close(self) -> None:
        for w in self.widgets:
            close_quietly(w)
