"""The 3-D view: a pythreejs scene built once, updated by assigning ONE new array.

The only module that imports pythreejs.

What is drawn
-------------
Balls at the slice's vertices, bars along its edges and semi-transparent
faces coloured by the 4-D cell each comes from, seen by a perspective camera
at (0, 0, 5) looking down -z (the paper's view), turned with the mouse by
OrbitControls (keys disabled).  Every polytope is scaled by ``R_5cell / R``
so it appears the size of the pentachoron (the 120-cell's circumradius is
7.4 at edge 2: unscaled, the camera would sit inside it).

How it is drawn (pythreejs 2.4.2 bundles three.js r97: no InstancedMesh)
-------------------------------------------------------------------------
All three meshes read ONE `InstancedInterleavedBuffer` holding the row table
of `rot4d_widget.buffers` (R rows x 20 float32: ball centre + flag, bar end
points, triangle corners + packed colour).  Each mesh is an
`InstancedBufferGeometry` whose own ``position`` attribute is a fixed
template built once -- a billboard square (balls and bars), a barycentric
triangle (faces) -- and whose per-instance attributes are
`InterleavedBufferAttribute`s into the shared buffer.  `ShaderMaterial`s
(GLSL ES 1.0 style; three r97 runs them on a WebGL2 context when it gets
one, prefixing ``#version 300 es`` and compatibility defines) place each
instance: the ball shader ray-casts a sphere impostor (exact perspective
silhouette; the depth of the sphere's surface is written with
``gl_FragDepthEXT``, which is ``gl_FragDepth`` under WebGL2 and the
EXT_frag_depth extension under WebGL1), the bar shader ray-casts a closed
cylinder impostor the same way (the square is stretched over a rectangle,
aligned with the projected axis, that bounds the projection of the bar's
box; the fragment shader intersects the pixel's ray with the cylinder's side,
then with the end disc, discards misses, lights the hit like the balls and
writes its depth), the face shader places the triangle's three corners,
unpacks the colour and lights each corner.  No sphere or cylinder mesh is
ever sent.

Why impostors for the bars too: on the software renderer (SwiftShader) the
page's draw time is the update latency.  A 12-segment cylinder mesh is 144
vertices per bar, drawn for every capacity row; measured per draw call
(readPixels after each call, 600 x 500 canvas, median of 16 frames) the
600-cell's bars took 48 ms as meshes and 25 ms as impostors (balls 12 ms,
faces 17 ms), the 24-cell's 10.8 ms and 5.3 ms.  Needs a perspective camera
(the rays start at the eye).

Lighting is computed in those shaders, with one GLSL function for balls,
bars and faces: ambient + a hemisphere light (sky above, ground below, fixed in the
world) + one point light riding with the camera (a head lamp, up and to the
left).  There are no three.js light objects, in particular no
DirectionalLight (pythreejs issues #388, #406).  Balls and bars are lit per
pixel (their normal varies across the pixel's hits); faces are flat, so they
are lit at their corners and the colour is interpolated (Gouraud): the face
pass was the largest (translucent, both sides drawn) and this halved it,
4.9 -> 2.6 ms per 24-cell frame (with multisampling), with the picture
unchanged to within 2/255 per channel (``python benchmarks/browser_draw.py
--cases 24-cell --variants msaa --screenshots DIR``, on the two versions).

Translucent faces in the right order: a slice of a convex polytope is
convex, so along any ray from an eye outside it there is at most one face
seen from behind and one seen from the front.  `buffers.slice_rows` puts the
triangles that face away from the eye (the camera's position as the kernel
knows it) before those that face it, and WebGL blends the triangles of one
draw call in their order, so each pixel's two layers are composited back to
front exactly, in one pass.  OrbitControls syncs the camera's position to the
kernel when a drag ends; `Rot4DWidget` then re-sends the rows in the new
order (during the drag the previous order stands).  Blending in cell order
instead was off by up to 26/255 and 30/255 per channel over 5.2 % and 4.1 %
of a 24- and a 600-cell picture; drawing back faces and front faces as two
culled passes gives the same pixels as this order (0/255 difference) but
costs the software renderer a second pass over every instance.  Checked
with ``python benchmarks/browser_draw.py --cases 5-cell,24-cell,600-cell
--variants default --screenshots DIR --compare OTHER`` against pictures made
with ``--rev`` of each other version.

Why no multisampling by default: MSAA smooths triangle edges only.  The
balls' and bars' outlines are where their fragment shader discards, once per
pixel, so they are not smoothed either way; the faces' edges lie under the
bars.  With 4x MSAA and without, a 24-cell picture differs in 0.39 % of its
pixels (single pixels along outlines), while every pass costs more: on the
software renderer a 24-cell frame takes 8.5 ms with it, 5.4 ms without
(``python benchmarks/browser_draw.py --cases 24-cell --rounds 3
--screenshots DIR``).  ``antialias=True`` turns it on.

One update = one message, never drawn half-applied
--------------------------------------------------
``show(slice)`` assigns a new array to the shared buffer (and, in the same
``hold_sync`` message, the update's sequence number, an extra synced trait
the companion reads).  On the page pythreejs applies it with
``InterleavedBuffer.setArray`` inside the model's change event; the next
animation frame uploads it (``bufferData``, so the size may change) and
draws.  Balls, bars and faces come from the same buffer, so a frame can
never show parts of two updates.

The trap is ``InstancedBufferGeometry.maxInstancedCount``: three r97 sets it
from the buffer's row count at the first render *only if undefined* and
never again, and changing it from Python is a separate message to another
widget.  Drawing more instances than the buffer has rows is a WebGL error
(nothing drawn); fewer hides rows.  So this module never lets the drawn count
and the row count disagree:

* Each scene has a row *capacity* R (a multiple of 16 with 12.5 % headroom,
  first estimated from a few central slices of the polytope) and sets
  ``maxInstancedCount = R`` on all three geometries at construction.  Every
  normal update sends exactly R rows, the unused ones all zero = hidden.
  One message.
* A slice needing more than R rows (rare: central slices are the largest)
  grows the capacity in three steps, each leaving the page consistent:
  (a) re-send the picture already shown, padded with hidden rows to the new
  capacity (buffer message; same sequence number, so it is not acknowledged
  as the new update); (b) set ``maxInstancedCount`` to the new capacity on
  the three geometries (the new instances are hidden rows); (c) send the new
  slice (one buffer message).  Comm messages are applied in order, so every
  frame drawn in between shows the old picture or the new one, whole.
  The capacity never shrinks (bytes per update stay at the high-water mark).

Sizes: 80 bytes per row.  Central slices are the largest (rows = max of
vertices, edges, triangles, over random orientations): 5-cell 9, 8-cell 20,
16-cell 24, 24-cell 60, 120-cell 232, 600-cell 360.  The estimated
capacities are 16, 32, 32, 80, 256, 416 rows, so one update is a comm
payload of 1.5, 2.8, 2.8, 6.6, 20.7, 33.5 KB -- all under the 64 KB budget.
On the page (SwiftShader, 2 cores) a 120-cell update reached the pixels
~50 ms after its arrival.

The ``version`` trait of the buffer is synced back by pythreejs's front end
after every update; it is declared here with ``echo_update=False`` so the
kernel does not echo it back again.
"""

from __future__ import annotations

import json
import math
import uuid

import numpy as np
import pythreejs as p3
from traitlets import CInt

from . import buffers as bf

__all__ = ["Scene", "PENTACHORON_CIRCUMRADIUS"]

#: circumradius of the regular 5-cell with edge 2: every polytope is shown this size
PENTACHORON_CIRCUMRADIUS = 2.0 * math.sqrt(2.0 / 5.0)

CAMERA_POSITION = (0.0, 0.0, 5.0)

# -- widgets that count the bytes they send ----------------------------------


class _Counting:
    """Mixin: tally the comm payload (JSON of the comm data + binary buffers) sent."""

    _rot4d_bytes = 0
    _rot4d_messages = 0

    def _send(self, msg, buffers=None):
        if self.comm is not None:
            n = len(json.dumps(msg, default=str))
            n += sum(memoryview(b).nbytes for b in (buffers or ()))
            self._rot4d_bytes += n
            self._rot4d_messages += 1
        super()._send(msg, buffers=buffers)


class _RowBuffer(_Counting, p3.InstancedInterleavedBuffer):
    """The shared buffer; ``_rot4d_seq`` travels in the same message as the array."""

    _rot4d_seq = CInt(0).tag(sync=True)
    version = CInt(0).tag(sync=True, echo_update=False)


class _Geometry(_Counting, p3.InstancedBufferGeometry):
    pass


# -- shaders (GLSL ES 1.0; three r97 prepends the built-in uniforms/attributes) ---

_LIGHTING = """
uniform vec3 u_ambient;
uniform vec3 u_sky;
uniform vec3 u_ground;
uniform vec3 u_light_color;
uniform vec3 u_light_position;
uniform float u_specular;
uniform float u_shininess;

vec3 shade(vec3 base, vec3 n, vec3 p) {
    vec3 up = normalize((viewMatrix * vec4(0.0, 1.0, 0.0, 0.0)).xyz);
    vec3 hemi = mix(u_ground, u_sky, 0.5 + 0.5 * dot(n, up));
    vec3 l = normalize(u_light_position - p);
    float diffuse = max(dot(n, l), 0.0);
    vec3 h = normalize(l - normalize(p));
    float spec = diffuse > 0.0 ? pow(max(dot(n, h), 0.0), u_shininess) : 0.0;
    return base * (u_ambient + hemi + u_light_color * diffuse) + u_specular * spec * u_light_color;
}
"""

#: Shared by the ray-cast impostors (balls, bars): write the depth of the surface point
#: actually hit, so impostors occlude each other and the faces exactly.
_IMPOSTOR_DEPTH = """
uniform mat4 projectionMatrix;
void write_depth(vec3 hit) {
#if defined(GL_EXT_frag_depth) || __VERSION__ >= 300
    vec4 clip = projectionMatrix * vec4(hit, 1.0);
    gl_FragDepthEXT = 0.5 + 0.5 * clip.z / clip.w;
#endif
}
"""

_BALL_VERTEX = """
attribute vec4 ball;
uniform float u_ball_radius;
varying vec3 v_centre;
varying vec3 v_point;
void main() {
    if (ball.w < 0.5) {
        v_centre = vec3(0.0);
        v_point = vec3(0.0);
        gl_Position = vec4(0.0, 0.0, 2.0, 1.0);
        return;
    }
    vec3 c = (modelViewMatrix * vec4(ball.xyz, 1.0)).xyz;
    float r = u_ball_radius;
    float d = max(length(c), 1.0e-6);
    vec3 w = c / d;
    vec3 helper = abs(w.y) < 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
    vec3 u = normalize(cross(helper, w));
    vec3 v = cross(w, u);
    float s = 1.05 * r * d / sqrt(max(d * d - r * r, 1.0e-4 * r * r));
    vec3 p = c + s * (position.x * u + position.y * v);
    v_centre = c;
    v_point = p;
    gl_Position = projectionMatrix * vec4(p, 1.0);
}
"""

_BALL_FRAGMENT = (
    """
uniform vec3 u_ball_color;
uniform float u_ball_radius;
varying vec3 v_centre;
varying vec3 v_point;
"""
    + _LIGHTING
    + _IMPOSTOR_DEPTH
    + """
void main() {
    vec3 ray = normalize(v_point);
    float b = dot(ray, v_centre);
    float q = dot(v_centre, v_centre) - u_ball_radius * u_ball_radius;
    float disc = b * b - q;
    if (disc < 0.0) discard;
    vec3 hit = (b - sqrt(disc)) * ray;
    vec3 n = (hit - v_centre) / u_ball_radius;
    write_depth(hit);
    gl_FragColor = vec4(shade(u_ball_color, n, hit), 1.0);
}
"""
)

_BAR_VERTEX = """
attribute vec3 bar_a;
attribute vec3 bar_b;
uniform float u_bar_radius;
varying vec3 v_point;
varying vec3 v_a;
varying vec3 v_w;
varying float v_len;
void widen(vec3 c, vec2 e, vec2 f, inout vec4 box, inout float near) {
    float z = max(-c.z, 1.0e-4);
    vec2 q = c.xy / z;
    float pe = dot(q, e);
    float pf = dot(q, f);
    box = vec4(min(box.x, pe), max(box.y, pe), min(box.z, pf), max(box.w, pf));
    near = min(near, z);
}
void main() {
    vec3 a = (modelViewMatrix * vec4(bar_a, 1.0)).xyz;
    vec3 b = (modelViewMatrix * vec4(bar_b, 1.0)).xyz;
    vec3 axis = b - a;
    float len = length(axis);
    if (len < 1.0e-12) {
        v_point = vec3(0.0);
        v_a = vec3(0.0);
        v_w = vec3(0.0, 0.0, 1.0);
        v_len = 0.0;
        gl_Position = vec4(0.0, 0.0, 2.0, 1.0);
        return;
    }
    vec3 w = axis / len;
    // The box around the bar has sides u and v (both perpendicular to the axis).
    // Any such pair bounds the cylinder; taking u across the line of sight (and
    // v nearly along it) makes the box's projection hug the cylinder's, so the
    // quad is about 2r wide instead of up to 2.8r for a fixed helper axis.
    vec3 mid = 0.5 * (a + b);
    vec3 across = cross(w, mid);
    vec3 helper = abs(w.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
    if (dot(across, across) < 1.0e-8 * dot(mid, mid)) across = cross(w, helper);  // bar seen end-on
    float r = u_bar_radius;
    vec3 u = r * normalize(across);
    vec3 v = r * normalize(cross(w, u));
    // the bar's box (end discs included), projected on the plane z = -1 and
    // bounded by a rectangle aligned with the projected axis
    vec2 d = b.xy / max(-b.z, 1.0e-4) - a.xy / max(-a.z, 1.0e-4);
    vec2 e = dot(d, d) > 1.0e-12 ? normalize(d) : vec2(1.0, 0.0);
    vec2 f = vec2(-e.y, e.x);
    vec4 box = vec4(1.0e9, -1.0e9, 1.0e9, -1.0e9);
    float near = 1.0e9;
    widen(a + u + v, e, f, box, near);
    widen(a + u - v, e, f, box, near);
    widen(a - u + v, e, f, box, near);
    widen(a - u - v, e, f, box, near);
    widen(b + u + v, e, f, box, near);
    widen(b + u - v, e, f, box, near);
    widen(b - u + v, e, f, box, near);
    widen(b - u - v, e, f, box, near);
    vec2 pad = 0.01 * vec2(box.y - box.x, box.w - box.z);
    float pe = position.x < 0.0 ? box.x - pad.x : box.y + pad.x;
    float pf = position.y < 0.0 ? box.z - pad.y : box.w + pad.y;
    vec3 p = near * vec3(pe * e + pf * f, -1.0);
    v_point = p;
    v_a = a;
    v_w = w;
    v_len = len;
    gl_Position = projectionMatrix * vec4(p, 1.0);
}
"""

_BAR_FRAGMENT = (
    """
uniform vec3 u_bar_color;
uniform float u_bar_radius;
varying vec3 v_point;
varying vec3 v_a;
varying vec3 v_w;
varying float v_len;
"""
    + _LIGHTING
    + _IMPOSTOR_DEPTH
    + """
void main() {
    // ray from the eye (the origin) through this pixel against the closed cylinder
    vec3 ray = normalize(v_point);
    vec3 w = normalize(v_w);
    float r2 = u_bar_radius * u_bar_radius;
    float rw = dot(ray, w);
    float aw = dot(v_a, w);
    vec3 rp = ray - rw * w;
    vec3 ap = v_a - aw * w;
    float qa = dot(rp, rp);
    float qb = dot(rp, ap);
    float disc = qb * qb - qa * (dot(ap, ap) - r2);
    if (disc < 0.0 || qa < 1.0e-12) discard;
    float t = (qb - sqrt(disc)) / qa;
    vec3 hit = t * ray;
    float s = dot(hit - v_a, w);
    vec3 n;
    if (s < 0.0 || s > v_len) {
        // the front of the side lies past an end: the ray can only enter through that end's disc
        float cap = s < 0.0 ? 0.0 : v_len;
        vec3 c = v_a + cap * w;
        if (abs(rw) < 1.0e-6) discard;
        hit = (dot(c, w) / rw) * ray;
        vec3 off = hit - c;
        if (dot(off, off) > r2) discard;
        n = s < 0.0 ? -w : w;
    } else {
        n = (hit - v_a - s * w) / u_bar_radius;
    }
    write_depth(hit);
    gl_FragColor = vec4(shade(u_bar_color, n, hit), 1.0);
}
"""
)

_FACE_VERTEX = (
    """
attribute vec3 tri_a;
attribute vec3 tri_b;
attribute vec3 tri_c;
attribute float tri_rgb;
varying vec3 v_color;
"""
    + _LIGHTING
    + """
void main() {
    vec3 p = position.x * tri_a + position.y * tri_b + position.z * tri_c;
    float r = floor(tri_rgb / 65536.0);
    float g = floor((tri_rgb - r * 65536.0) / 256.0);
    float b = tri_rgb - r * 65536.0 - g * 256.0;
    vec4 mv = modelViewMatrix * vec4(p, 1.0);
    vec3 n = normalize(normalMatrix * cross(tri_b - tri_a, tri_c - tri_a));
    // a flat face: dot(n, point) has one sign over it, so each corner picks the same side
    if (dot(n, mv.xyz) > 0.0) n = -n;  // light the side facing the viewer
    v_color = shade(vec3(r, g, b) / 255.0, n, mv.xyz);
    gl_Position = projectionMatrix * mv;
}
"""
)

_FACE_FRAGMENT = """
uniform float u_opacity;
varying vec3 v_color;
void main() {
    gl_FragColor = vec4(v_color, u_opacity);
}
"""


# -- option validation -------------------------------------------------------


def _positive(name, value, *, upper=None):
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"Expected `{name}` to be a positive number, got {value!r}")
    v = float(value)
    if not (math.isfinite(v) and v > 0.0) or (upper is not None and v > upper):
        allowed = f"in (0, {upper}]" if upper is not None else "> 0 and finite"
        raise ValueError(f"Expected `{name}` {allowed}, got {value!r}")
    return v


def _pixels(name, value):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"Expected `{name}` to be an int number of pixels in [16, 8192], got {value!r}")
    if not 16 <= int(value) <= 8192:
        raise ValueError(f"Expected `{name}` to be an int number of pixels in [16, 8192], got {value!r}")
    return int(value)


def _unit(name, value):
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"Expected `{name}` to be a number in [0, 1], got {value!r}")
    v = float(value)
    if not 0.0 <= v <= 1.0:
        raise ValueError(f"Expected `{name}` to be a number in [0, 1], got {value!r}")
    return v


def _cell_colors(value, n_cells):
    if value is None:
        return bf.cell_palette(max(n_cells, 1))
    if isinstance(value, str):
        raise ValueError("Expected `cell_colors` to be a sequence of colours, one per cell, got a string")
    try:
        items = list(value)
    except TypeError:
        raise TypeError(f"Expected `cell_colors` to be a sequence of colours, got {value!r}") from None
    if len(items) < n_cells:
        raise ValueError(f"Expected `cell_colors` to have at least {n_cells} colours (one per cell), got {len(items)}")
    rgb = [bf.as_rgb(c, f"cell_colors[{i}]") for i, c in enumerate(items)]
    return np.asarray(rgb, dtype=np.float32)


def _hex(rgb):
    return "#" + "".join(f"{int(round(255 * c)):02x}" for c in rgb)


# -- the scene ---------------------------------------------------------------


class Scene:
    """Balls, bars and cell-coloured faces of a slice, in a pythreejs `Renderer`.

    Parameters
    ----------
    polytope : Polytope
        Needs ``circumradius``, ``cells`` and ``edges`` (sets the scale, the
        palette size and the default radii).
    width, height : int
        Canvas size in CSS pixels, 16 ... 8192.  Default 600 x 500.
    ball_radius, bar_radius : float > 0, optional
        In displayed units (the pentachoron's circumradius is 1.26).  Default:
        ``min(0.07, 0.1 x displayed edge length)`` for balls, 0.4 x that for bars.
    face_opacity : float in [0, 1]
        Default 0.35.
    background, ball_color, bar_color : '#rgb', '#rrggbb' or (r, g, b) in [0, 1]
    cell_colors : sequence of such colours, at least one per cell, optional
        Default `rot4d_widget.buffers.cell_palette`.
    capacity : int >= 1, optional
        Initial row capacity (default: estimated from the polytope).
    antialias : bool
        WebGL multisampling (default False: see the module notes).

    Attributes
    ----------
    renderer : pythreejs.Renderer -- display this; it has CSS classes
        ``rot4d-canvas`` and `canvas_class` (unique per scene).
    scale : float -- ``PENTACHORON_CIRCUMRADIUS / polytope.circumradius``
    update_id : int -- sequence number of the last update sent (0 = none yet)
    buffer_model_id, scene_model_id : str -- for the companion
    capacity : int -- rows per update
    """

    def __init__(
        self,
        polytope,
        *,
        width=600,
        height=500,
        ball_radius=None,
        bar_radius=None,
        face_opacity=0.35,
        background="#ffffff",
        ball_color="#c8102e",
        bar_color="#4a4a4a",
        cell_colors=None,
        capacity=None,
        antialias=False,
    ):
        try:
            radius = float(polytope.circumradius)
            n_cells = len(polytope.cells)
        except (AttributeError, TypeError):
            raise TypeError(f"Expected `polytope` to be a rot4d_widget.Polytope, got {type(polytope).__name__}") from None
        if not (math.isfinite(radius) and radius > 0):
            raise ValueError(f"Expected a polytope with a positive circumradius, got {radius}")
        self.polytope = polytope
        self.width = _pixels("width", width)
        self.height = _pixels("height", height)
        self.scale = PENTACHORON_CIRCUMRADIUS / radius
        if ball_radius is None:
            edges = np.asarray(polytope.edges)
            verts = np.asarray(polytope.vertices, dtype=np.float64)
            edge = float(np.linalg.norm(verts[edges[0, 0]] - verts[edges[0, 1]])) * self.scale
            ball_radius = min(0.07, 0.1 * edge)
        self.ball_radius = _positive("ball_radius", ball_radius, upper=10.0)
        self.bar_radius = _positive("bar_radius", 0.4 * self.ball_radius if bar_radius is None else bar_radius, upper=10.0)
        self.face_opacity = _unit("face_opacity", face_opacity)
        self.background = _hex(bf.as_rgb(background, "background"))
        self.ball_color = bf.as_rgb(ball_color, "ball_color")
        self.bar_color = bf.as_rgb(bar_color, "bar_color")
        if not isinstance(antialias, bool):
            raise TypeError(f"Expected `antialias` to be True or False, got {antialias!r}")
        self._cell_rgb = _cell_colors(cell_colors, n_cells)
        if capacity is None:
            capacity = bf.estimate_capacity(polytope)
        elif isinstance(capacity, bool) or not isinstance(capacity, (int, np.integer)) or capacity < 1:
            raise ValueError(f"Expected `capacity` to be an int >= 1 or None, got {capacity!r}")
        self.capacity = int(capacity)
        self.update_id = 0
        self.canvas_class = f"rot4d-canvas-{uuid.uuid4().hex[:12]}"
        self._closed = False
        self._build(antialias)

    # -- construction ------------------------------------------------------
    def _build(self, antialias):
        self._rows = np.zeros((self.capacity, bf.ROW_FLOATS), dtype=np.float32)
        self._buffer = _RowBuffer(array=self._rows, meshPerAttribute=1)
        attrs = {
            name: p3.InterleavedBufferAttribute(data=self._buffer, itemSize=size, offset=col)
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
        self._geometries = {}
        for part, names in uses.items():
            a = dict(templates[part])
            a.update({n: attrs[n] for n in names})
            self._geometries[part] = _Geometry(attributes=a, maxInstancedCount=self.capacity)

        light = {
            "u_ambient": {"value": [0.28, 0.28, 0.28]},
            "u_sky": {"value": [0.30, 0.30, 0.32]},
            "u_ground": {"value": [0.08, 0.07, 0.06]},
            "u_light_color": {"value": [0.62, 0.62, 0.60]},
            "u_light_position": {"value": [-3.0, 4.0, 2.0]},
            "u_specular": {"value": 0.35},
            "u_shininess": {"value": 40.0},
        }
        ball_mat = p3.ShaderMaterial(
            vertexShader=_BALL_VERTEX,
            fragmentShader=_BALL_FRAGMENT,
            uniforms=dict(light, u_ball_radius={"value": self.ball_radius}, u_ball_color={"value": list(self.ball_color)}),
            extensions={"fragDepth": True},
            side="DoubleSide",
        )
        bar_mat = p3.ShaderMaterial(
            vertexShader=_BAR_VERTEX,
            fragmentShader=_BAR_FRAGMENT,
            uniforms=dict(light, u_bar_radius={"value": self.bar_radius}, u_bar_color={"value": list(self.bar_color)}),
            extensions={"fragDepth": True},
            side="DoubleSide",
        )
        face_mat = p3.ShaderMaterial(
            vertexShader=_FACE_VERTEX,
            fragmentShader=_FACE_FRAGMENT,
            uniforms=dict(light, u_opacity={"value": self.face_opacity}),
            side="DoubleSide",
            transparent=True,
            depthWrite=False,
        )
        self._materials = [ball_mat, bar_mat, face_mat]
        self._meshes = [
            p3.Mesh(geometry=self._geometries["ball"], material=ball_mat, frustumCulled=False, name="balls"),
            p3.Mesh(geometry=self._geometries["bar"], material=bar_mat, frustumCulled=False, name="bars"),
            p3.Mesh(geometry=self._geometries["face"], material=face_mat, frustumCulled=False, name="faces"),
        ]
        self.camera = p3.PerspectiveCamera(
            position=list(CAMERA_POSITION), fov=40, aspect=self.width / self.height, near=0.1, far=100.0
        )
        self.three_scene = p3.Scene(children=[*self._meshes, self.camera], background=None)
        self.controls = p3.OrbitControls(controlling=self.camera, enableKeys=False)
        self.renderer = p3.Renderer(
            camera=self.camera,
            scene=self.three_scene,
            controls=[self.controls],
            width=self.width,
            height=self.height,
            antialias=antialias,
            background=self.background,
            background_opacity=1.0,
            clearColor=self.background,
        )
        self.renderer.add_class("rot4d-canvas")
        self.renderer.add_class(self.canvas_class)
        self._widgets = [
            self.renderer, self.controls, self.three_scene, self.camera, *self._meshes, *self._materials,
            *self._geometries.values(), *attrs.values(), self._buffer,
            *(a for t in templates.values() for a in t.values()),
        ]  # fmt: skip
        self._counted = [self._buffer, *self._geometries.values()]

    # -- the update --------------------------------------------------------
    @property
    def buffer_model_id(self) -> str:
        """Model id of the shared buffer: its ``array`` change is the message of an update."""
        return self._buffer.model_id

    @property
    def scene_model_id(self) -> str:
        """Model id of the pythreejs Scene (it fires ``afterRender`` on the page)."""
        return self.three_scene.model_id

    @property
    def rows(self) -> np.ndarray:
        """The row table last assigned (read-only view)."""
        v = self._rows.view()
        v.flags.writeable = False
        return v

    @property
    def eye(self) -> tuple:
        """The camera's position as the kernel knows it (OrbitControls syncs it after a drag)."""
        return tuple(float(x) for x in self.camera.position)

    @property
    def messages_sent(self) -> int:
        return sum(w._rot4d_messages for w in self._counted)

    @property
    def bytes_sent(self) -> int:
        return sum(w._rot4d_bytes for w in self._counted)

    def show(self, slice_, *, force=False) -> int:
        """Show ``slice_`` (a `Slice`); returns the comm payload bytes sent.

        Normally one message: a new (capacity, 20) float32 array for the shared
        buffer plus the new `update_id`.  Returns 0 and sends nothing if the
        rows equal those shown (unless ``force``); then `update_id` does not
        change and no "drawn" acknowledgement will come.  Never creates
        widgets.
        """
        if self._closed:
            raise RuntimeError("this Scene is closed")
        before = self.bytes_sent
        need = bf.rows_needed(slice_)
        if need > self.capacity:
            self._grow(bf.capacity_for(need))
        rows = bf.slice_rows(
            slice_, scale=self.scale, cell_rgb=self._cell_rgb, capacity=self.capacity, eye=self.eye
        )
        if force or not np.array_equal(rows, self._rows):
            self.update_id += 1
            self._assign(rows, self.update_id)
        return self.bytes_sent - before

    def _assign(self, rows, seq):
        buf = self._buffer
        with buf.hold_sync():
            buf.array = rows
            buf._rot4d_seq = seq
        self._rows = rows

    def _grow(self, capacity):
        """Grow the row capacity; every intermediate frame shows one whole picture."""
        padded = np.zeros((capacity, bf.ROW_FLOATS), dtype=np.float32)
        padded[: self.capacity] = self._rows
        self._assign(padded, self.update_id)  # (a) same picture, more (hidden) rows
        for g in self._geometries.values():  # (b) draw them
            g.maxInstancedCount = capacity
        self.capacity = capacity  # (c) is the caller's normal update

    # -- teardown ----------------------------------------------------------
    def close(self) -> None:
        """Close every widget this scene created (idempotent)."""
        if self._closed:
            return
        self._closed = True
        for w in self._widgets:
            w.close()

    def __repr__(self) -> str:
        name = getattr(self.polytope, "name", "polytope")
        return f"Scene({name!r}, capacity={self.capacity}, scale={self.scale:.4g}, update_id={self.update_id})"
