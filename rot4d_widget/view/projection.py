"""The whole object beside its slice: a second 3-D view of the 4-D source projected to 3-D.

``Rot4DWidget(..., projection=True)`` (also a trait) puts a second canvas beside the slice view.
It shows the source's skeleton -- a polytope's edges, a field's data box (a tesseract: 16
corners, 32 edges) -- rotated by the same matrix as the slice and projected to 3-D, its edges
coloured by w on a diverging map (blue below the hyperplane w = c0, grey on it, red above),
and the points where the hyperplane cuts the edges (the slice's points) as yellow balls.  A
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

The arrays are computed vectorised (no Python loop over vertices or edges) and sent as float32,
in the same update as the slice (`rot4d_widget.view.painter.Painter.send` calls `follow`), so
the two views never show different states.  The geometry functions (`skeleton`,
`hyperplane_offsets`, `perspective`, `crossings`, `w_colours`, `projection_arrays`) need no
browser; `ProjectionView` builds the pythreejs objects, only when the projection is first shown:
``projection=False`` (the default) makes no widget and changes nothing of the picture.

What the view knows of the source comes from the source protocol's members, never from its
class: a source that has ``polytope`` (vertices, edges) shows its edges; one that has
``half_widths`` (a field's box, in slice units about the rotation centre) shows its box; a
stack (``wraps``) shows its inner source with ``cuts_at(c0)`` marked; any other source shows
nothing in the projection (the caption says so).
"""

from __future__ import annotations

import html

import numpy as np

from ..core import look
from ..sources.protocol import inner_source, w_frame
from .keypad import close_quietly
from .traits import Checked

__all__ = ["EYE_DISTANCE", "BELOW_RGB", "ON_RGB", "ABOVE_RGB", "skeleton", "tesseract", "hyperplane_offsets",
           "perspective", "crossings", "w_colours", "projection_arrays", "pack_rows", "crossing_capacity",
           "ProjectionView", "ProjectionFlag"]

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
    """The ``projection`` trait: True or False (`rot4d_widget.core.look.check_projection`)."""

    info_text = "True or False"

    def check(self, name, value):
        return look.check_projection(value)


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
    poly = getattr(inner, "polytope", None)
    if poly is not None:
        return (np.asarray(poly.vertices, dtype=np.float64).reshape(-1, 4),
                np.asarray(poly.edges, dtype=np.intp).reshape(-1, 2))
    hw = getattr(inner, "half_widths", None)
    if hw is not None:
        return tesseract(hw)
    return None


def hyperplane_offsets(source, c0) -> np.ndarray:
    """(K,) float64: the offsets d of the hyperplanes shown (slice units along the turned w axis,
    c0 = origin + per_unit * d, `w_frame`): one, or a stack's every slice (``cuts_at(c0)``)."""
    origin, per = w_frame(source)
    cuts_at = getattr(source, "cuts_at", None) if inner_source(source) is not source else None
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


def projection_arrays(source, matrix, c0, scale: float = 1.0) -> dict | None:
    """What the projection draws, in displayed units (``scale`` x slice units), float32, or None for
    a source without a skeleton: ``positions`` (V, 3) the vertices projected, ``rgb`` (V, 3) their
    colours by w (`w_colours` about the middle hyperplane; an edge blends its ends' colours),
    ``index`` (2E,) uint32 the edges as pairs of rows, ``points`` (m, 3) the hyperplanes'
    crossings (`crossings`) projected, ``distance`` d and ``offsets`` (K,).  Only positions,
    colours and points change with the state: the index is sent once per source."""
    sk = skeleton(source)
    if sk is None:
        return None
    vertices, edges = sk
    m = np.asarray(matrix, dtype=np.float64).reshape(4, 4)
    size = float(inner_source(source).size)
    d = EYE_DISTANCE * size
    rotated = vertices @ m.T
    offsets = hyperplane_offsets(source, c0)
    middle = float(offsets[len(offsets) // 2]) if len(offsets) % 2 else float(offsets.mean())
    cross = crossings(rotated, edges, offsets)
    return {
        "positions": (perspective(rotated, d) * scale).astype(np.float32),
        "rgb": w_colours(rotated[:, 3], middle, size).astype(np.float32),
        "index": edges.reshape(-1).astype(np.uint32),
        "points": (perspective(cross, d) * scale).astype(np.float32),
        "distance": d,
        "offsets": offsets,
    }


#: Where an unused crossing slot is put: far behind the projection's camera (on the +z axis,
#: looking down -z), so it is clipped and never drawn.
HIDDEN = (0.0, 0.0, 1.0e6)


def crossing_capacity(n_edges: int, n_offsets: int) -> int:
    """Crossing slots kept in the buffer: every edge crossing every hyperplane once (an edge in a
    hyperplane gives two ends, whose vertices other edges also cross: rarely more; more grows it)."""
    return max(1, int(n_edges) * max(1, int(n_offsets)))


def pack_rows(arrays, capacity: int) -> np.ndarray:
    """(V + capacity, 6) float32 rows ``x, y, z, r, g, b``: the projected vertices with their colours
    (`projection_arrays`), then the crossings (colour unused: the balls have one), then `HIDDEN`
    rows up to ``capacity`` crossings.  None: one hidden row per slot."""
    if arrays is None:
        rows = np.zeros((capacity, 6), dtype=np.float32)
        rows[:, :3] = HIDDEN
        return rows
    pos, rgb, pts = arrays["positions"], arrays["rgb"], arrays["points"]
    n = len(pos)
    rows = np.zeros((n + capacity, 6), dtype=np.float32)
    rows[:n, :3] = pos
    rows[:n, 3:] = rgb
    rows[n:n + len(pts), :3] = pts
    rows[n + len(pts):, :3] = HIDDEN
    return rows


class ProjectionView:
    """The projection's canvas, caption and pythreejs objects for one widget (``widget``): built
    the first time it is shown, updated by `follow` in the painter's update, closed with the widget."""

    def __init__(self, widget):
        self.w = widget
        self.box = None  # the ipywidgets VBox (caption + canvas), once built
        self.shown_key = None  # (matrix, c0, version) last drawn
        self.arrays = None  # what was last sent (`projection_arrays`), for tests and the readout
        self._widgets = []
        self.events = None  # the ipyevents listener on the projection's canvas, once built

    @property
    def on(self) -> bool:
        return bool(getattr(self.w, "projection", False))

    # -- building ----------------------------------------------------------------------------
    def _build(self) -> None:
        import ipywidgets as widgets  # with pythreejs: only when the projection is first shown
        import pythreejs as p3  # heavy (~0.3 s): imported when the projection is first shown

        w = self.w
        scene = w.scene
        width, height = int(scene.width), int(scene.height)
        # one interleaved float32 buffer (rows x, y, z, r, g, b): the V projected vertices, then
        # `capacity` crossing slots; lines and balls index into it, so a held key's update of the
        # projection is one message (positions, colours and balls together)
        self._rows = pack_rows(None, 1)
        self._buffer = p3.InterleavedBuffer(array=self._rows)
        self._edge_index = p3.BufferAttribute(array=np.array([0, 0], dtype=np.uint32), normalized=False)
        self._edge_geometry = p3.BufferGeometry(attributes={
            "position": p3.InterleavedBufferAttribute(data=self._buffer, itemSize=3, offset=0),
            "color": p3.InterleavedBufferAttribute(data=self._buffer, itemSize=3, offset=3),
            "index": self._edge_index})
        self._edge_material = p3.LineBasicMaterial(vertexColors="VertexColors", linewidth=1)
        self._lines = p3.LineSegments(geometry=self._edge_geometry, material=self._edge_material,
                                      frustumCulled=False, name="projection edges")
        self._point_index = p3.BufferAttribute(array=np.array([0], dtype=np.uint32), normalized=False)
        self._point_geometry = p3.BufferGeometry(attributes={
            "position": p3.InterleavedBufferAttribute(data=self._buffer, itemSize=3, offset=0),
            "index": self._point_index})
        ball = 4.0 * float(getattr(w, "ball_radius", 0.07))
        self._point_material = p3.PointsMaterial(color=CROSSING_RGB, size=ball, sizeAttenuation=True)
        self._points = p3.Points(geometry=self._point_geometry, material=self._point_material,
                                 frustumCulled=False, name="projection crossings", visible=False)
        self._camera = p3.PerspectiveCamera(
            position=[c * CAMERA_FARTHER for c in look.CAMERA_POSITION], fov=look.CAMERA_FOV, aspect=width / height,
            near=look.CAMERA_NEAR, far=look.CAMERA_FAR,
        )
        self._scene = p3.Scene(children=[self._lines, self._points, self._camera], background=None)
        self._controls = p3.OrbitControls(controlling=self._camera, enableKeys=False)
        background = look.hex_color(look.as_rgb(w.background, "background"))
        self.renderer = p3.Renderer(camera=self._camera, scene=self._scene, controls=[self._controls],
                                    width=width, height=height, background=background, background_opacity=1.0,
                                    clearColor=background)
        self.renderer.add_class("rot4d-projection")
        from ipyevents import Event  # keys over the projection turn the object as over the slice

        self.events = Event(source=self.renderer, watched_events=list(KEY_EVENTS), prevent_default_action=True,
                            ignore_modifier_key_events=True)
        self.events.on_dom_event(w._handle_event)
        self.caption = widgets.HTML(self._caption_html())
        self.box = widgets.VBox([self.caption, self.renderer], layout=widgets.Layout(flex="0 0 auto"))
        self._widgets = [self.events, self.box, self.caption, self.renderer, self._controls, self._scene, self._camera,
                         self._lines, self._points, self._edge_geometry, self._edge_material, self._buffer,
                         self._edge_index, self._point_geometry, self._point_material, self._point_index]
        self._widgets += [a for g in (self._edge_geometry, self._point_geometry) for a in g.attributes.values()
                          if a not in self._widgets]

    def _caption_html(self) -> str:
        d = EYE_DISTANCE
        text = (f"<b>projection</b>: the whole object, perspective from w = {d:g}&times;size; edges "
                "<span style='color:#3b4cc0'>blue below</span> / <span style='color:#b40426'>red above</span> "
                "w = c0, <span style='color:#e07b00'>balls</span>: where w = c0 cuts (the slice)")
        if skeleton(self.w.source) is None:
            text += " &mdash; " + html.escape("this source has no edges or box to project")
        return f"<div style='font-size:0.85em;max-width:36em'>{text}</div>"

    # -- showing --------------------------------------------------------------------------
    def changed(self, change=None) -> None:
        """The ``projection`` trait changed (or the widget was just wired): show or hide the canvas
        beside the slice view, and draw it in the next update."""
        w = self.w
        if self.on and self.box is None:
            self._build()
        if self.box is not None:
            kids = [c for c in w.children if c is not self.box]
            if self.on:
                kids.insert(1, self.box)
            if tuple(kids) != tuple(w.children):
                w.children = tuple(kids)
        self.shown_key = None
        if change is not None:
            with w._pump.lock:
                if not w._closed:
                    w._pump.mark_dirty()
                    w._pump.flush()

    def follow(self, matrix, c0, version) -> None:
        """Draw the state ``(matrix, c0)`` of the source at ``version`` if it is not drawn yet: the
        painter calls this in every update, so both views change together."""
        if not self.on or self.box is None:
            return
        key = (matrix, c0, version)
        if self.shown_key is not None and self.shown_key[0] is matrix and self.shown_key[1:] == key[1:]:
            return
        w = self.w
        arrays = projection_arrays(w.source, matrix, c0, w._scale)
        self.shown_key, self.arrays = key, arrays
        if arrays is None:
            self._lines.visible = self._points.visible = False
            return
        index, pts = arrays["index"], arrays["points"]
        n_vertices = len(arrays["positions"])
        capacity = len(self._rows) - n_vertices
        if len(pts) > capacity or len(index) != len(self._edge_index.array) or capacity < 1:
            capacity = max(len(pts), crossing_capacity(len(index) // 2, len(arrays["offsets"])))
        rows = pack_rows(arrays, capacity)
        with self.renderer.hold_sync():
            if len(rows) != len(self._rows) or not np.array_equal(index, self._edge_index.array):
                # a new source (or more crossings than slots): its edges and the balls' slots, once
                self._edge_index.array = index if len(index) else np.array([0, 0], dtype=np.uint32)
                self._point_index.array = np.arange(n_vertices, len(rows), dtype=np.uint32)
            self._buffer.array = self._rows = rows
            self._lines.visible = bool(len(index))
            self._points.visible = bool(len(pts))

    def readout_row(self):
        """``(label, html)`` for the readout saying which view is which, or None when off."""
        if not self.on:
            return None
        return ("views", "left: the slice w = c0 &middot; right: the whole object projected (balls: the slice)")

    def close(self) -> None:
        if self.events is not None:
            self.events.on_dom_event(self.w._handle_event, remove=True)
            self.events = None
        for x in self._widgets:
            close_quietly(x)
        self._widgets = []
        self.box = None
