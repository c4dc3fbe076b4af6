"""The whole object beside its slice: a second 3-D view of the 4-D source projected to 3-D.

``Rot4DWidget(..., projection=True)`` (also a trait) puts a second canvas beside the slice view.
It shows the source's skeleton -- a polytope's edges, a field's data box (a tesseract: 16
corners, 32 edges) -- rotated by the same matrix as the slice and projected to 3-D, its edges
coloured by w on a diverging map (blue below the hyperplane w = c0, grey on it, red above),
and the points where the hyperplane cuts the edges (the slice's points) as orange points.  A
stack (parallel slices) marks every slice's crossings.

**Which projection, and why.**  A perspective projection from the point (0, 0, 0, d) on the
w axis, d = `EYE_DISTANCE` x the source's size (its circumradius)::

    (x, y, z, w)  ->  (x, y, z) * d / (d - w)

of the rotated vertices.  Not a Schlegel diagram: a Schlegel diagram looks through one cell,
which then changes as the object turns (and a field's box or a non-convex / star polytope has
no cell that shows the rest inside it), while the eye on the w axis is fixed in the same frame
as the slicing hyperplane: the hyperplane w = c0 is mapped to itself scaled by d / (d - c0),
so the slice's points lie in the projection exactly where the slice is (scaled), and points
above the hyperplane (nearer the eye) are drawn larger -- the depth cue is w itself.  With
d = 3 x size every vertex has d - w >= 2 x size > 0: nothing crosses the eye.

**The page projects; the kernel sends the state.**  Once per source the kernel sends the
skeleton (`skeleton_message`: vertices (V, 4) float64, edges (E, 2) uint32, d, size, scale,
colours); per update only the state (`state_message`: the 4x4 matrix, the hyperplanes' offsets and
the middle one) -- as fields of the slice view's own update message (the scene's row buffer,
`rot4d_widget.view.scene.Scene.show` / ``turn`` with ``projection=``), so a held key costs no
second widget message, and both canvases are updated from the same message, in the same task
of the page: neither gets a state the other does not.  The companion (``companion.js``:
``decodeSkeleton``, ``projectSkeleton``) rotates, projects, colours and finds the crossings in
the page, as `projection_arrays` does here, and writes them into the projection's own three.js
geometries.  The geometry functions
(`skeleton`, `hyperplane_offsets`, `perspective`, `crossings`, `w_colours`, `projection_arrays`)
need no browser: they serve static pictures and exports, and are the reference the page's
arrays are tested against (tests/view/test_projection.py under Node, the browser suite in the page).
`ProjectionView` builds the pythreejs objects only when the projection is first shown:
``projection=False`` (the default) makes no widget and changes nothing of the picture.

What the view knows of the source comes from the source protocol's members, never from its
class: a source that has ``polytope`` (vertices, edges) shows its edges; one that has
``half_widths`` (a field's box, in slice units about the rotation centre) shows its box; a
stack (``wraps``) shows its inner source with ``cuts_at(c0)`` marked; any other source shows
nothing in the projection (the caption says so).
"""

from __future__ import annotations

import uuid

import numpy as np

from ..core import camera, colours, renderings
from ..sources.protocol import inner_source, w_frame
from . import markup
from .keypad import close_quietly
from .traits import Checked

__all__ = ["EYE_DISTANCE", "BELOW_RGB", "ON_RGB", "ABOVE_RGB", "skeleton", "tesseract", "hyperplane_offsets",
           "middle_offset", "perspective", "crossings", "w_colours", "projection_arrays", "skeleton_message",
           "state_message", "ProjectionView", "ProjectionFlag"]

#: The eye sits at w = EYE_DISTANCE x the source's size on the w axis.
EYE_DISTANCE = 3.0
#: The diverging map's ends and middle (matplotlib's "coolwarm" ends): below c0, on it, above it.
BELOW_RGB = np.array([0.230, 0.299, 0.754])
ON_RGB = np.array([0.865, 0.865, 0.865])
ABOVE_RGB = np.array([0.706, 0.016, 0.150])
#: The projection's camera is this much farther than the slice view's: a vertex at w = size is
#: drawn up to d / (d - size) = 1.5 times farther out (such vertices are rare: a little is cut at worst).
CAMERA_FARTHER = 1.2
#: What the projection's canvas listens to: the slice canvas's events, handled alike.
KEY_EVENTS = ("keydown", "keyup", "mouseleave")
#: The crossing balls' colour.
CROSSING_RGB = "#e07b00"


class ProjectionFlag(Checked):
    """The ``projection`` trait: True or False (`rot4d_widget.core.renderings.check_projection`)."""

    info_text = "True or False"

    def check(self, name, value):
        return renderings.check_projection(value)


def tesseract(half_widths) -> tuple:
    """``(corners (16, 4) float64, edges (32, 2) intp)`` of the box ``[-h, h]`` (``half_widths``
    (4,)): corner k has coordinate i at ``+h[i]`` when bit i of k is set; an edge joins corners
    that differ in one bit."""
    h = np.asarray(half_widths, dtype=np.float64).reshape(4)
    k = np.arange(16)
    bits = (k[:, None] >> np.arange(4)) & 1  # (16, 4)
    corners = np.where(bits == 1, h, -h)
    a = np.repeat(k, 4)
    b = a ^ np.tile(1 << np.arange(4), 16)
    keep = a < b
    edges = np.column_stack([a[keep], b[keep]]).astype(np.intp)
    return corners, edges


def skeleton(source):
    """``(vertices (V, 4) float64, edges (E, 2) intp)`` of what the projection draws, in the
    source's slice units about its rotation centre, or None for a source without one.  Read
    from the protocol's members (a stack's inner source): ``polytope`` (its vertices and edges)
    or ``half_widths`` (a field's box: `tesseract`)."""
    inner = inner_source(source)
    poly = inner.polytope
    if poly is not None:
        return (np.asarray(poly.vertices, dtype=np.float64).reshape(-1, 4),
                np.asarray(poly.edges, dtype=np.intp).reshape(-1, 2))
    hw = inner.half_widths
    if hw is not None:
        return tesseract(hw)
    return None


def hyperplane_offsets(source, c0) -> np.ndarray:
    """(K,) float64: the offsets d of the hyperplanes shown (slice units along the turned w axis,
    c0 = origin + per_unit * d, `w_frame`): one, or a stack's every slice (``cuts_at(c0)``)."""
    origin, per = w_frame(source)
    cuts_at = source.cuts_at if inner_source(source) is not source else None
    cuts = np.atleast_1d(np.asarray(cuts_at(c0) if cuts_at is not None else c0, dtype=np.float64))
    return (cuts - origin) / per


def perspective(points4, distance) -> np.ndarray:
    """(n, 3) float64: rotated 4-D points (n, 4) seen from (0, 0, 0, ``distance``) on the w axis,
    ``xyz * d / (d - w)``."""
    p = np.asarray(points4, dtype=np.float64).reshape(-1, 4)
    return p[:, :3] * (distance / (distance - p[:, 3]))[:, None]


def crossings(rotated, edges, offsets) -> np.ndarray:
    """(m, 4) float64: where the edges (E, 2) of the rotated vertices (V, 4) cross the hyperplanes
    w = offset, every offset (K,) in one pass: an edge whose ends straddle it (or touch it) gives
    ``a + t (b - a)``, t = (o - w_a) / (w_b - w_a); an edge lying in it gives its two ends.
    Duplicates (a vertex on the plane, met by several edges) are kept."""
    v = np.asarray(rotated, dtype=np.float64)
    e = np.asarray(edges, dtype=np.intp).reshape(-1, 2)
    o = np.asarray(offsets, dtype=np.float64).reshape(-1, 1)  # (K, 1)
    w = v[:, 3]
    wa, wb = w.take(e[:, 0]), w.take(e[:, 1])  # (E,): only w first, whole rows where cut
    lo, hi = np.minimum(wa, wb), np.maximum(wa, wb)
    tol = 1e-12 * max(1.0, float(np.abs(w).max(initial=0.0)))
    flat = (hi - lo) <= tol
    any_flat = bool(flat.any())
    cut = (lo <= o + tol) & (hi >= o - tol)  # (K, E)
    if any_flat:
        cut &= ~flat
    k, j = np.nonzero(cut)
    a, b = v[e[j, 0]], v[e[j, 1]]
    t = np.clip((o[k, 0] - wa[j]) / (wb[j] - wa[j]), 0.0, 1.0)
    pts = a + t[:, None] * (b - a)
    pts[:, 3] = o[k, 0]
    if not any_flat:
        return pts
    k2, j2 = np.nonzero(flat & (np.abs(lo - o) <= tol))  # edges in the plane: both ends
    return np.concatenate([pts, v[e[j2, 0]], v[e[j2, 1]]])


def w_colours(w, offset, size) -> np.ndarray:
    """(n, 3) float64 in [0, 1]: a diverging map of ``w`` about the hyperplane ``offset`` -- `BELOW_RGB`
    at offset - size or lower, `ON_RGB` on it, `ABOVE_RGB` at offset + size or higher, linear between."""
    t = np.clip((np.asarray(w, dtype=np.float64).reshape(-1) - float(offset)) / float(size), -1.0, 1.0)[:, None]
    return ON_RGB + np.maximum(t, 0.0) * (ABOVE_RGB - ON_RGB) + np.minimum(t, 0.0) * (ON_RGB - BELOW_RGB)


def middle_offset(offsets) -> float:
    """The hyperplane the colours are centred on: the middle one of ``offsets`` (K,) (K odd), else their mean."""
    o = np.asarray(offsets, dtype=np.float64).reshape(-1)
    return float(o[len(o) // 2]) if len(o) % 2 else float(o.mean())


def projection_arrays(source, matrix, c0, scale: float = 1.0) -> dict | None:
    """What the projection draws, in displayed units (``scale`` x slice units), float32, or None for
    a source without a skeleton: ``positions`` (V, 3) the vertices projected, ``rgb`` (V, 3) their
    colours by w (`w_colours` about `middle_offset`; an edge blends its ends' colours),
    ``index`` (2E,) uint32 the edges as pairs of rows, ``points`` (m, 3) the hyperplanes'
    crossings (`crossings`) projected, ``distance`` d and ``offsets`` (K,).  The reference for
    what the page computes from `skeleton_message` and `state_message` (``companion.js``)."""
    sk = skeleton(source)
    if sk is None:
        return None
    vertices, edges = sk
    m = np.asarray(matrix, dtype=np.float64).reshape(4, 4)
    size = float(inner_source(source).size)
    d = EYE_DISTANCE * size
    rotated = vertices @ m.T
    offsets = hyperplane_offsets(source, c0)
    cross = crossings(rotated, edges, offsets)
    return {
        "positions": (perspective(rotated, d) * scale).astype(np.float32),
        "rgb": w_colours(rotated[:, 3], middle_offset(offsets), size).astype(np.float32),
        "index": edges.reshape(-1).astype(np.uint32),
        "points": (perspective(cross, d) * scale).astype(np.float32),
        "distance": d,
        "offsets": offsets,
    }


def _le_bytes(a, dtype) -> memoryview:
    """``a`` as little-endian ``dtype`` bytes: a binary buffer of the widget message."""
    return memoryview(np.ascontiguousarray(a, dtype=np.dtype(dtype).newbyteorder("<")).tobytes())


def skeleton_message(source, scale: float = 1.0) -> dict:
    """What the page needs once per source to project it (the scene's ``_rot4d_skeleton``):
    ``n_vertices`` V, ``n_edges`` E, ``vertices`` (V, 4) float64 and ``edges`` (E, 2) uint32 as
    little-endian bytes (`skeleton`), ``distance`` d, ``size``, ``scale`` (displayed units per
    slice unit) and the colour map's ``below`` / ``on`` / ``above`` ends.  ``{"n_vertices": 0,
    "n_edges": 0}`` for a source without a skeleton (the page draws nothing)."""
    sk = skeleton(source)
    if sk is None:
        return {"n_vertices": 0, "n_edges": 0}
    vertices, edges = sk
    size = float(inner_source(source).size)
    return {
        "n_vertices": int(len(vertices)), "n_edges": int(len(edges)),
        "vertices": _le_bytes(vertices, np.float64), "edges": _le_bytes(edges, np.uint32),
        "distance": EYE_DISTANCE * size, "size": size, "scale": float(scale),
        "below": BELOW_RGB.tolist(), "on": ON_RGB.tolist(), "above": ABOVE_RGB.tolist(),
    }


def state_message(source, matrix, c0) -> dict:
    """What the page needs per update to project the skeleton (the scene's ``_rot4d_project``):
    ``matrix`` the 16 entries of the 4x4 rotation, row by row (rotated = vertices @ matrix.T),
    ``offsets`` the hyperplanes (`hyperplane_offsets`) and ``middle`` (`middle_offset`).  Python
    floats: the page gets the very doubles (JSON round-trips them)."""
    offsets = hyperplane_offsets(source, c0)
    return {"matrix": np.asarray(matrix, dtype=np.float64).reshape(16).tolist(), "offsets": offsets.tolist(),
            "middle": middle_offset(offsets)}


class ProjectionView:
    """The projection's canvas, caption and pythreejs objects for one widget (``widget``): built
    the first time it is shown; `message` gives what each update of the slice view carries for
    it; closed with the widget.

    The pythreejs meshes hold placeholder geometries only: the companion draws them with
    geometries of its own, filled in the page from the skeleton and the state (the kernel never
    sends an array to them)."""

    def __init__(self, traits, place, showing, state, scene, companion, pump, on_event):
        self.traits = traits  # the widget's traits: ``projection``, ``background``, ``ball_radius``
        self.place = place  # place(box, on): the widget puts the projection's box beside the slice view, or not
        self.showing, self.state, self.scene, self.companion, self.pump = showing, state, scene, companion, pump
        self.on_event = on_event  # keys over the projection's canvas go where the slice view's go
        self.painter = None  # `connect`
        self.box = None  # the ipywidgets VBox (caption + canvas), once built
        self.shown_key = None  # (matrix, c0, version) of the state last handed to the scene
        self._skeleton_key = None  # (source, version, scale) whose skeleton the page was sent
        self._arrays = (None, None)  # (shown_key, `projection_arrays`) computed on request
        self._widgets = []
        self.events = None  # the ipyevents listener on the projection's canvas, once built
        self.canvas_class = f"rot4d-projection-{uuid.uuid4().hex[:12]}"

    def connect(self, painter) -> None:
        """The painter, whose picture a projection turned on first shows."""
        self.painter = painter

    @property
    def on(self) -> bool:
        return bool(self.traits.projection)

    # -- building ----------------------------------------------------------------------------
    def _build(self) -> None:
        import ipywidgets as widgets  # with pythreejs: only when the projection is first shown
        import pythreejs as p3  # heavy (~0.3 s): imported when the projection is first shown
        scene = self.scene
        width, height = int(scene.width), int(scene.height)

        def placeholder(rows):  # plain attributes: the companion makes its geometries of their classes
            return p3.BufferAttribute(array=np.zeros((rows, 3), dtype=np.float32), normalized=False)

        self._edge_geometry = p3.BufferGeometry(attributes={
            "position": placeholder(2), "color": placeholder(2),
            "index": p3.BufferAttribute(array=np.array([0, 1], dtype=np.uint32), normalized=False)})
        self._edge_material = p3.LineBasicMaterial(vertexColors="VertexColors", linewidth=1)
        self._lines = p3.LineSegments(geometry=self._edge_geometry, material=self._edge_material,
                                      frustumCulled=False, name="projection edges")
        self._point_geometry = p3.BufferGeometry(attributes={"position": placeholder(1)})
        ball = 4.0 * float(self.traits.ball_radius)
        self._point_material = p3.PointsMaterial(color=CROSSING_RGB, size=ball, sizeAttenuation=True)
        self._points = p3.Points(geometry=self._point_geometry, material=self._point_material,
                                 frustumCulled=False, name="projection crossings", visible=False)
        self._camera = p3.PerspectiveCamera(
            position=[c * CAMERA_FARTHER for c in camera.CAMERA_POSITION], fov=camera.CAMERA_FOV, aspect=width / height,
            near=camera.CAMERA_NEAR, far=camera.CAMERA_FAR,
        )
        self._scene = p3.Scene(children=[self._lines, self._points, self._camera], background=None)
        self._controls = p3.OrbitControls(controlling=self._camera, enableKeys=False)
        background = colours.hex_color(colours.as_rgb(self.traits.background, "background"))
        self.renderer = p3.Renderer(camera=self._camera, scene=self._scene, controls=[self._controls],
                                    width=width, height=height, background=background, background_opacity=1.0,
                                    clearColor=background)
        self.renderer.add_class("rot4d-projection")
        self.renderer.add_class(self.canvas_class)
        from ipyevents import Event  # keys over the projection turn the object as over the slice

        self.events = Event(source=self.renderer, watched_events=list(KEY_EVENTS), prevent_default_action=True,
                            ignore_modifier_key_events=True)
        self.events.on_dom_event(self.on_event)
        self.caption = markup.html_widget(self._caption_html())
        self.box = widgets.VBox([self.caption, self.renderer], layout=widgets.Layout(flex="0 0 auto"))
        self._widgets = [self.events, self.box, self.caption, self.renderer, self._controls, self._scene, self._camera,
                         self._lines, self._points, self._edge_geometry, self._edge_material,
                         self._point_geometry, self._point_material]
        self._widgets += [a for g in (self._edge_geometry, self._point_geometry) for a in g.attributes.values()]
        # the companion finds the meshes and the scene it draws into, and the canvas (key guards)
        with self.companion.hold_sync():
            self.companion.projection_model_ids = [self._lines.model_id, self._points.model_id, self._scene.model_id]
            self.companion.projection_class = self.canvas_class

    def _caption_html(self) -> markup.Markup:
        note = "this source has no edges or box to project" if skeleton(self.showing.source) is None else None
        return markup.projection_caption_html(EYE_DISTANCE, note)

    # -- showing --------------------------------------------------------------------------
    def changed(self, change=None) -> None:
        """The ``projection`` trait changed (or the widget was just wired): show or hide the canvas
        beside the slice view; when it is turned on, send the state the slice view shows (one
        message with the skeleton); later updates carry it with the slice (`message`)."""
        if self.on and self.box is None:
            self._build()
        if self.box is not None:
            self.place(self.box, self.on)
        self._skeleton_key = None  # the next message carries the skeleton again
        if change is not None and self.on:
            with self.pump.lock:
                shown = self.painter.shown
                if not self.pump.closed and shown is not None:
                    self.scene.project(self.message(shown.matrix, shown.c0, shown.version))

    def message(self, matrix, c0, version) -> dict | None:
        """What the slice view's update carries for the projection (`rot4d_widget.view.scene.Scene.show`'s
        ``projection``), None when it is not shown: ``{"state": state_message(...)}``, with
        ``"skeleton": skeleton_message(...)`` the first time and whenever the source, its version or
        the scale changed.  Called just before the scene sends the update."""
        if not self.on or self.box is None:
            return None
        out = {"state": state_message(self.showing.source, matrix, c0)}
        key = (self.showing.source, version, self.showing.scale)
        if self._skeleton_key is None or any(a is not b and a != b for a, b in zip(key, self._skeleton_key)):
            out["skeleton"] = skeleton_message(self.showing.source, self.showing.scale)
            self._skeleton_key = key
            markup.show(self.caption, self._caption_html())
        self.shown_key = (matrix, c0, version)
        return out

    @property
    def arrays(self) -> dict | None:
        """`projection_arrays` of the state last sent (what the page draws), computed here on
        request: for tests, pictures and the readout; None before any or for a source without one."""
        key = self.shown_key
        if key is None:
            return None
        if self._arrays[0] is not key:
            self._arrays = (key, projection_arrays(self.showing.source, key[0], key[1], self.showing.scale))
        return self._arrays[1]

    def readout_row(self):
        """``(label, html)`` for the readout saying which view is which, or None when off."""
        if not self.on:
            return None
        return ("views", markup.views_html())

    def close(self) -> None:
        if self.events is not None:
            self.events.on_dom_event(self.on_event, remove=True)
            self.events = None
        for x in self._widgets:
            close_quietly(x)
        self._widgets = []
        self.box = None
