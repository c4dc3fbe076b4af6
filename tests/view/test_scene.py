"""rot4d_widget.view.scene without a browser: what the scene is made of and what one update sends.

Comm messages are recorded by a comm that serialises like ipykernel's
(tests/recording_comm.py, the ipywidgets tests' dummy-comm pattern), so counts
and sizes are those a kernel would send.  The scene is read through its public
interface only: `canvas` (a pythreejs Renderer, whose own public traits --
camera, scene, controls, the meshes in it -- are what the page receives),
`rows`, `update_id`, `capacity`, `display`, the model ids and the recorded
messages.  What the front end sends (OrbitControls syncing the camera, the
view count) is delivered on the widget's comm as the page would.
"""

from __future__ import annotations

import math
import pathlib
import re

import numpy as np
import pytest
import pythreejs as p3
from ipywidgets.widgets import widget as ipywidget_module

import rot4d_widget
from rot4d_widget.view import buffers as bf
from rot4d_widget import polytope
from rot4d_widget.core import camera, colours, sizes
from rot4d_widget.core.rotation import random_rotation
from rot4d_widget.geometry.regular import POLYTOPE_NAMES
from rot4d_widget.sources.protocol import PolytopeSource
from rot4d_widget.view.scene import Scene, shader_source

#: The shipped GLSL files (package data).
GLSL = pathlib.Path(rot4d_widget.__file__).parent / "view" / "glsl"

#: Bytes of JSON around the binary array in one buffer message (method, buffer path, dtype,
#: shape, the sequence number); measured 195 with ipykernel's packer.
JSON_OVERHEAD = 256

#: KB (1000 bytes) of comm payload per buffer update before the source refactor (ef53a77),
#: as the scene's docs gave them: capacity rows x 80 bytes + JSON, rounded to 0.1 KB.
BEFORE_KB = {"5-cell": 1.5, "8-cell": 2.8, "16-cell": 2.8, "24-cell": 6.6, "120-cell": 20.7, "600-cell": 33.5}


def before_capacity(name):
    """The row capacity behind the old documented figure: the largest multiple of 16 whose
    rows (80 bytes each) fit in it, as the docs computed it (16, 32, 32, 80, 256, 416)."""
    return int(BEFORE_KB[name] * 1000 // bf.ROW_BYTES) // 16 * 16


@pytest.fixture(autouse=True)
def log(recording_comms):
    """Every message sent: (comm_id, data, n_bytes, buffers) -- tests/recording_comm.py."""
    yield recording_comms


def scene_options(src, **kw):
    """What Rot4DWidget gives the Scene for a source: its scale, groups and estimated capacity."""
    kw.setdefault("scale", sizes.REFERENCE_RADIUS / src.size)
    kw.setdefault("n_groups", src.n_groups)
    kw.setdefault("capacity", bf.estimate_capacity(src))
    return kw


@pytest.fixture
def scenes():
    """``make(name_or_polytope, **options) -> (scene, source)``; scenes closed afterwards."""
    made = []

    def make(name="24-cell", **kw):
        src = PolytopeSource(name)
        s = Scene(**scene_options(src, **kw))
        made.append(s)
        return s, src

    yield make
    for s in made:
        s.close()


def live_widgets():
    return len(ipywidget_module._instances)


def walk(obj):
    yield obj
    for child in getattr(obj, "children", ()):
        yield from walk(child)


def meshes(sc):
    """The scene's meshes by name, read from the canvas (what the page draws)."""
    return {o.name: o for o in walk(sc.canvas.scene) if isinstance(o, p3.Mesh)}


def from_page(widget, **state):
    """A state change made by the front end (OrbitControls, view counting), as the page sends it."""
    widget.comm.handler({"content": {"data": {"method": "update", "state": state, "buffer_paths": []}}, "buffers": []})


def buffer_messages(sc, log):
    return [(data, n, bufs) for cid, data, n, bufs in log if cid == sc.buffer_model_id]


# ----------------------------------------------------------------- structure
def test_multisampling_is_off_unless_asked_for(scenes):
    # off by default: it smooths no impostor outline and costs every pass (see scene docs);
    # pythreejs keeps the flag as the Renderer's synced _antialias trait
    assert scenes("5-cell")[0].canvas._antialias is False
    assert scenes("5-cell", antialias=True)[0].canvas._antialias is True


def test_camera_controls_renderer_as_the_paper_and_the_issue_ask(scenes):
    sc, _ = scenes("5-cell", width=420, height=300)
    canvas = sc.canvas
    assert isinstance(canvas, p3.Renderer)
    cam = canvas.camera
    assert isinstance(cam, p3.PerspectiveCamera)
    assert tuple(cam.position) == camera.CAMERA_POSITION == (0.0, 0.0, 5.0)
    assert sc.eye == (0.0, 0.0, 5.0)
    assert tuple(cam.quaternion) == (0.0, 0.0, 0.0, 1.0)  # looking down -z
    assert cam.aspect == pytest.approx(420 / 300)
    (controls,) = canvas.controls
    assert isinstance(controls, p3.OrbitControls) and controls.enableKeys is False
    assert controls.controlling is cam
    assert (canvas.width, canvas.height) == (420, 300)
    assert "rot4d-canvas" in canvas._dom_classes
    assert sc.canvas_class in canvas._dom_classes and sc.canvas_class.startswith("rot4d-canvas-")
    assert scenes("5-cell")[0].canvas_class != sc.canvas_class
    assert sc.scene_model_id == canvas.scene.model_id


def test_no_directional_light_and_shaders_do_the_lighting(scenes):
    sc, _ = scenes("5-cell")
    objects = list(walk(sc.canvas.scene))
    assert not any(isinstance(o, p3.DirectionalLight) for o in objects)
    parts = [o for o in objects if isinstance(o, p3.Mesh)]
    assert [m.name for m in parts] == ["balls", "bars", "faces", "surface", "volume", "field"]
    assert parts[4].visible is False  # the ray-cast layer (emission, not lit) waits for a field's volume
    assert parts[5].visible is False  # the page's own field picture: shown by the page alone (issue 36)
    field = parts[5].material  # its isosurfaces lit as the surface layer's
    assert "vec3 shade(" in field.fragmentShader and {"u_ambient", "u_light_position"} <= set(field.uniforms)
    for m in parts[:4]:
        assert m.frustumCulled is False
        assert isinstance(m.material, p3.ShaderMaterial)
        # impostors and smooth surfaces are lit per pixel (their normal varies), flat faces per corner
        lit_in = m.material.vertexShader if m.name == "faces" else m.material.fragmentShader
        assert "vec3 shade(" in lit_in and "shade(" in lit_in.split("void main()")[1]
        assert {"u_ambient", "u_sky", "u_ground", "u_light_position"} <= set(m.material.uniforms)
    faces = parts[2].material
    assert faces.transparent and faces.depthWrite is False and faces.side == "DoubleSide"
    assert faces.uniforms["u_opacity"]["value"] == pytest.approx(colours.FACE_OPACITY) == pytest.approx(0.35)


def _facing(rows, eye):
    corners = rows[:, 10:19].astype(np.float64).reshape(-1, 3, 3)
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    used = np.linalg.norm(normal, axis=1) > 1e-12
    return np.einsum("ij,ij->i", normal, np.asarray(eye) - corners[:, 0])[used] > 0


@pytest.mark.parametrize("name", ["24-cell", "600-cell"])
def test_faces_facing_away_from_the_camera_come_first(scenes, name):
    """Drawn in row order, the translucent faces of the convex slice blend back to front."""
    sc, src = scenes(name)
    rng = np.random.default_rng(7)
    for _ in range(5):
        s = src.slice(random_rotation(rng), 0.0)
        assert s.convex
        for eye in [(0.0, 0.0, 5.0), (3.0, -4.0, 1.0)]:
            from_page(sc.canvas.camera, position=list(eye))  # an orbit ended
            assert sc.eye == eye
            sc.show(s)
            facing = _facing(sc.rows, eye)
            assert len(facing) == len(s.triangles)
            assert 0 < facing.sum() < len(facing)  # both kinds seen from outside
            k = int(np.argmax(facing))  # first front-facing triangle
            assert not facing[:k].any() and facing[k:].all()


def test_meshes_share_one_buffer_through_the_documented_columns(scenes):
    sc, _ = scenes("24-cell")
    geos = [m.geometry for name, m in meshes(sc).items() if name not in ("surface", "volume", "field")]
    buffers = set()
    for g in geos:
        assert isinstance(g, p3.InstancedBufferGeometry)
        assert g.maxInstancedCount == sc.capacity
        for name, attr in g.attributes.items():
            if isinstance(attr, p3.InterleavedBufferAttribute):
                buffers.add(attr.data.model_id)
                assert (attr.offset, attr.itemSize) == bf.COLUMNS[name]
    assert buffers == {sc.buffer_model_id}
    arr = sc.rows
    assert arr.dtype == np.float32 and arr.shape == (sc.capacity, 20)
    # no sphere or cylinder per instance: the templates are small and fixed
    assert geos[0].attributes["position"].array.shape == (6, 3)
    assert geos[1].attributes["position"].array.shape == (6, 3)  # bars are impostors too: a quad
    np.testing.assert_array_equal(geos[1].attributes["position"].array, bf.quad_template())
    assert "normal" not in geos[1].attributes
    assert geos[2].attributes["position"].array.shape == (3, 3)


@pytest.mark.parametrize("which", ["balls", "bars"])
def test_impostor_shaders_write_depth_under_webgl1_and_webgl2(scenes, which):
    """three r97 in pythreejs runs on WebGL2 when it can (seen in Chromium): there the
    extension macro is undefined and gl_FragDepthEXT is #defined to gl_FragDepth."""
    sc, _ = scenes("5-cell")
    mat = meshes(sc)[which].material
    frag = mat.fragmentShader
    assert "#if defined(GL_EXT_frag_depth) || __VERSION__ >= 300" in frag
    assert "gl_FragDepthEXT =" in frag
    assert "uniform mat4 projectionMatrix;" in frag  # not given to fragment shaders by r97
    assert "discard" in frag
    assert mat.extensions == {"fragDepth": True}


def test_shader_attributes_match_the_columns(scenes):
    sc, _ = scenes("5-cell")
    decl = {}
    for name_, m in meshes(sc).items():
        if name_ in ("surface", "volume", "field"):  # their own geometries (test_surface_*, test_volume_layer.py)
            continue
        for typ, name in re.findall(r"attribute (vec[234]|float) (\w+);", m.material.vertexShader):
            decl[name] = {"float": 1, "vec2": 2, "vec3": 3, "vec4": 4}[typ]
    assert decl == {name: size for name, (col, size) in bf.COLUMNS.items()}


def test_shader_source_expands_every_include(scenes):
    names = sorted(p.name for p in GLSL.iterdir())
    assert {"ball.vert", "ball.frag", "bar.vert", "bar.frag", "face.vert", "face.frag"} <= set(names)
    lighting = shader_source("lighting.glsl")
    depth = shader_source("impostor_depth.glsl")
    for name in names:
        assert "@include" not in shader_source(name), name
    assert lighting in shader_source("ball.frag") and depth in shader_source("ball.frag")
    assert lighting in shader_source("bar.frag") and depth in shader_source("bar.frag")
    assert lighting in shader_source("face.vert")
    # what the page receives is the expanded text
    sc, _ = scenes("5-cell")
    for part, stem in (("balls", "ball"), ("bars", "bar"), ("faces", "face")):
        mat = meshes(sc)[part].material
        assert mat.vertexShader == shader_source(f"{stem}.vert")
        assert mat.fragmentShader == shader_source(f"{stem}.frag")
        assert "@include" not in mat.vertexShader + mat.fragmentShader


@pytest.mark.parametrize("name", POLYTOPE_NAMES)
def test_every_polytope_appears_the_size_of_the_pentachoron(scenes, name):
    """At the scale the widget gives (REFERENCE_RADIUS / size) the rows hold the points scaled."""
    p = polytope(name)
    sc, src = scenes(p, capacity=16)
    assert sizes.REFERENCE_RADIUS == pytest.approx(polytope("5-cell").circumradius)
    s = src.slice(np.eye(4), 0.0)
    sc.show(s)
    scale = sizes.REFERENCE_RADIUS / p.circumradius
    np.testing.assert_allclose(sc.rows[: len(s.points), :3], s.points * scale, rtol=1e-6, atol=1e-7)
    assert np.linalg.norm(sc.rows[:, :3], axis=1).max() <= sizes.REFERENCE_RADIUS * (1 + 1e-6)
    if name == "120-cell":
        assert p.circumradius == pytest.approx(7.4, abs=0.01)


# ----------------------------------------------------------------- updates
def test_one_show_is_one_message_to_the_buffer(scenes, log):
    rng = np.random.default_rng(1)
    p = polytope("120-cell")
    sc, src = scenes(p)
    before = live_widgets()
    for k in range(1, 6):
        log.clear()
        s = src.slice(random_rotation(rng), 0.0)
        assert sc.show(s) is True
        assert len(log) == 1
        cid, data, n, bufs = log[0]
        assert cid == sc.buffer_model_id
        assert data["method"] == "update"
        assert {"array", "_rot4d_seq"} <= set(data["state"]) <= {"array", "_rot4d_seq", "_rot4d_counts", "_rot4d_turn"}
        assert data["state"]["_rot4d_seq"] == sc.update_id == k
        assert data["state"]["array"]["dtype"] == "float32"
        assert tuple(data["state"]["array"]["shape"]) == (sc.capacity, 20)
        assert len(bufs) == 1 and bufs[0].nbytes == sc.capacity * bf.ROW_BYTES
        rows = bufs[0].view(np.float32).reshape(sc.capacity, 20)
        want = bf.slice_rows(
            s, scale=sizes.REFERENCE_RADIUS / src.size, group_rgb=colours.group_palette(src.n_groups),
            capacity=sc.capacity, eye=sc.eye,
        )
        np.testing.assert_array_equal(rows, want)
        np.testing.assert_array_equal(sc.rows, want)  # what the scene says it shows is what it sent
        assert n <= sc.capacity * bf.ROW_BYTES + JSON_OVERHEAD  # the array and a little JSON
        assert n <= 40 * 1024
    assert live_widgets() == before  # show() never creates widgets


def test_rows_are_read_only_and_replaced_not_edited(scenes):
    sc, src = scenes("5-cell")
    first = sc.rows
    with pytest.raises(ValueError):
        first[0, 0] = 1.0
    sc.show(src.slice(random_rotation(np.random.default_rng(3)), 0.0))
    assert not np.shares_memory(first, sc.rows)  # a new array each update, never edited in place


@pytest.mark.parametrize("name", POLYTOPE_NAMES)
def test_bytes_per_update_at_most_64KB(scenes, log, name):
    rng = np.random.default_rng(4)
    p = polytope(name)
    sc, src = scenes(p)
    sizes = []
    for _ in range(8):
        log.clear()
        sc.show(src.slice(random_rotation(rng), 0.0))
        sizes += [n for cid, data, n, b in log]
    assert max(sizes) <= 64 * 1024


@pytest.mark.parametrize("name", POLYTOPE_NAMES)
def test_bytes_per_buffer_update_no_more_than_before_the_source_refactor(scenes, log, name):
    """Before: 5-cell 1.5, 8-cell 2.8, 16-cell 2.8, 24-cell 6.6, 120-cell 20.7, 600-cell 33.5 KB."""
    sc, src = scenes(name)
    old = before_capacity(name)
    assert old in (16, 32, 80, 256, 416)
    assert sc.capacity <= old  # the estimate from the source sizes the table as before
    rng = np.random.default_rng(6)
    for _ in range(8):
        log.clear()
        assert sc.show(src.slice(random_rotation(rng), 0.0))  # central slices: the largest
        ((data, n, bufs),) = buffer_messages(sc, log)
        assert bufs[0].nbytes == sc.capacity * bf.ROW_BYTES
        assert n <= old * bf.ROW_BYTES + JSON_OVERHEAD
        assert n <= BEFORE_KB[name] * 1000 + 50  # the documented figure, to its rounding
    assert sc.capacity <= old  # no growth was needed


def test_unchanged_slice_sends_nothing_unless_forced(scenes, log):
    sc, src = scenes("24-cell")
    s = src.slice(np.eye(4), 0.0)
    assert sc.show(s) is True and sc.update_id == 1
    log.clear()
    assert sc.show(src.slice(np.eye(4), 0.0)) is False
    assert log == [] and sc.update_id == 1
    assert sc.show(s, force=True) is True and sc.update_id == 2 and len(log) == 1


def test_growth_keeps_every_intermediate_state_whole(scenes, log):
    """Capacity growth: old picture padded (same id) -> counts -> new picture (new id)."""
    p = polytope("600-cell")
    sc, src = scenes(p, capacity=32)
    small = src.slice(np.eye(4), 0.9 * p.circumradius)
    assert 0 < bf.rows_needed(small) <= 32
    sc.show(small)
    old = sc.rows.copy()
    widgets_before = live_widgets()
    log.clear()
    big = src.slice(random_rotation(np.random.default_rng(0)), 0.0)
    sc.show(big)
    assert live_widgets() == widgets_before
    geo_ids = {m.geometry.model_id for name, m in meshes(sc).items() if name not in ("surface", "volume", "field")}
    assert len(geo_ids) == 3
    kinds = [("buffer" if cid == sc.buffer_model_id else "geometry" if cid in geo_ids else cid) for cid, *_ in log]
    assert kinds == ["buffer", "geometry", "geometry", "geometry", "buffer"]
    cap = sc.capacity
    assert cap >= bf.rows_needed(big) and cap % 16 == 0
    # (a) the picture already shown, padded with hidden rows; its id unchanged
    first = log[0]
    assert "_rot4d_seq" not in first[1]["state"]
    a = first[3][0].view(np.float32).reshape(cap, 20)
    np.testing.assert_array_equal(a[:32], old)
    assert old.any() and not a[32:].any()
    # (b) the drawn count follows, for balls, bars and faces
    assert [d["state"] for _, d, *_ in log[1:4]] == [{"maxInstancedCount": cap}] * 3
    # (c) the new slice with the next id
    assert log[4][1]["state"]["_rot4d_seq"] == sc.update_id == 2
    np.testing.assert_array_equal(log[4][3][0].view(np.float32).reshape(cap, 20), sc.rows)
    # afterwards, normal updates are one message again
    log.clear()
    sc.show(src.slice(random_rotation(np.random.default_rng(1)), 0.0))
    assert len(log) == 1


def test_show_after_close_raises_and_close_closes_everything(scenes):
    before = set(ipywidget_module._instances)
    sc, src = scenes("5-cell")
    made = {k: ipywidget_module._instances[k] for k in set(ipywidget_module._instances) - before}
    assert len(made) > 10 and all(w.comm is not None for w in made.values())
    # the renderer's own Layout and ShadowMap are pythreejs's: they outlive the scene
    renderer_parts = {sc.canvas.layout.model_id, sc.canvas.shadowMap.model_id}
    sc.close()
    left = set(ipywidget_module._instances) & set(made)
    assert left <= renderer_parts
    assert all(w.comm is None for k, w in made.items() if k not in renderer_parts)
    sc.close()  # idempotent
    with pytest.raises(RuntimeError, match="closed"):
        sc.show(src.slice(np.eye(4), 0.0))


def test_options_are_the_display_in_force(scenes):
    sc, _ = scenes("5-cell", ball_radius=0.1, bar_radius=0.02, face_opacity=1, background=(0, 0, 0))
    d = sc.display
    assert (d["ball_radius"], d["bar_radius"], d["face_opacity"]) == (0.1, 0.02, 1.0)
    assert sc.canvas.clearColor == "#000000"
    m = meshes(sc)
    assert m["balls"].material.uniforms["u_ball_radius"]["value"] == 0.1
    assert m["bars"].material.uniforms["u_bar_radius"]["value"] == 0.02
    assert m["faces"].material.uniforms["u_opacity"]["value"] == 1.0
    d["ball_radius"] = 5.0  # a copy
    assert sc.display["ball_radius"] == 0.1


# ----------------------------------------------------------------- live display options
def _messages_by_widget(log):
    return [(cid, data["state"]) for cid, data, *_ in log if data.get("method") == "update"]


def test_set_display_sends_one_synced_trait_and_no_rows(scenes, log):
    sc, _ = scenes("24-cell")
    m = meshes(sc)
    shown = sc.update_id
    # a uniform: the material's uniforms, all in one message
    log.clear()
    sc.set_display(face_opacity=0.6)
    ((cid, state),) = _messages_by_widget(log)
    assert cid == m["faces"].material.model_id
    assert state["uniforms"]["u_opacity"]["value"] == pytest.approx(0.6)
    assert {"u_ambient", "u_light_position"} <= set(state["uniforms"])  # the lighting stays
    log.clear()
    sc.set_display(ball_radius=0.05, bar_radius=0.01)
    assert [cid for cid, _ in _messages_by_widget(log)] == [m["balls"].material.model_id, m["bars"].material.model_id]
    assert m["balls"].material.uniforms["u_ball_radius"]["value"] == 0.05
    assert m["bars"].material.uniforms["u_bar_radius"]["value"] == 0.01
    # a mesh's visibility
    log.clear()
    sc.set_display(show_bars=False)
    assert _messages_by_widget(log) == [(m["bars"].model_id, {"visible": False})]
    assert m["bars"].visible is False and m["balls"].visible is True
    # the background: both renderer colours in one message
    log.clear()
    sc.set_display(background="#123")
    assert _messages_by_widget(log) == [(sc.canvas.model_id, {"background": "#112233", "clearColor": "#112233"})]
    assert sc.display == {
        "ball_radius": 0.05, "bar_radius": 0.01, "face_opacity": 0.6, "background": "#123",
        "show_balls": True, "show_bars": False, "show_faces": True,
    }
    assert sc.update_id == shown and sc.buffer_model_id not in {cid for cid, *_ in log}  # no rows re-sent


@pytest.mark.parametrize(
    "kw,exc,match",
    [
        ({"face_opacity": 2}, ValueError, r"`face_opacity` to be a number in \[0, 1\]"),
        ({"face_opacity": "half"}, TypeError, r"`face_opacity` to be a number in \[0, 1\]"),
        ({"ball_radius": 0}, ValueError, r"`ball_radius` in \(0, 10.0\]"),
        ({"bar_radius": [1]}, TypeError, "`bar_radius` to be a positive number"),
        ({"background": "navy"}, ValueError, r"`background` to be '#rgb', '#rrggbb' or three floats in \[0, 1\]"),
        ({"show_faces": 1}, TypeError, "`show_faces` to be True or False"),
        ({"show_balls": "no"}, TypeError, "`show_balls` to be True or False"),
        ({"opacity": 0.5}, ValueError, "Unknown display option 'opacity'; expected one of ball_radius, bar_radius, "
                                       "face_opacity, background, show_balls, show_bars, show_faces"),
    ],
)
def test_set_display_rejects_bad_values_naming_what_is_allowed(scenes, log, kw, exc, match):
    sc, _ = scenes("5-cell")
    before = sc.display
    log.clear()
    with pytest.raises(exc, match=match):
        sc.set_display(**kw)
    assert sc.display == before and log == []
    with pytest.raises(exc, match=match):  # all checked before anything changes
        sc.set_display(**{"face_opacity": 0.9, "show_bars": False, **kw})
    assert sc.display == before and log == []


# ----------------------------------------------------------------- callbacks
def test_on_view_count_and_on_eye_moved_fire_and_can_be_removed(scenes):
    sc, _ = scenes("5-cell")
    views, eyes = [], []
    sc.on_view_count(views.append)
    sc.on_eye_moved(eyes.append)
    sc.on_view_count(views.append)  # registered once
    assert sc.view_count == 0
    from_page(sc.canvas, _view_count=2)  # two views of the canvas on the page
    assert views == [2] and sc.view_count == 2
    from_page(sc.canvas.camera, position=[1.0, 2.0, 4.0])  # OrbitControls: a drag ended
    assert eyes == [(1.0, 2.0, 4.0)] and sc.eye == (1.0, 2.0, 4.0)
    from_page(sc.canvas, _view_count=0)
    assert views == [2, 0]
    sc.on_view_count(views.append, remove=True)
    sc.on_eye_moved(eyes.append, remove=True)
    from_page(sc.canvas, _view_count=1)
    from_page(sc.canvas.camera, position=[0.0, 0.0, 5.0])
    assert views == [2, 0] and eyes == [(1.0, 2.0, 4.0)]
    assert sc.view_count == 1 and sc.eye == (0.0, 0.0, 5.0)


def test_callbacks_stop_after_close(scenes):
    sc, _ = scenes("5-cell")
    views, eyes = [], []
    sc.on_view_count(views.append)
    sc.on_eye_moved(eyes.append)
    camera = sc.canvas.camera
    sc.close()
    camera.position = (1.0, 1.0, 1.0)
    assert eyes == [] and views == []


# ----------------------------------------------------------------- bad options
@pytest.mark.parametrize(
    "kw,exc,match",
    [
        ({"ball_radius": -0.1}, ValueError, r"`ball_radius` in \(0, 10.0\]"),
        ({"bar_radius": 0}, ValueError, r"`bar_radius` in \(0, 10.0\]"),
        ({"ball_radius": math.nan}, ValueError, "`ball_radius`"),
        ({"ball_radius": "big"}, TypeError, "`ball_radius` to be a positive number"),
        ({"width": 0}, ValueError, r"`width` to be an int number of pixels in \[16, 8192\]"),
        ({"height": 600.5}, TypeError, "`height` to be an int"),
        ({"face_opacity": 1.5}, ValueError, r"`face_opacity` to be a number in \[0, 1\]"),
        ({"background": "blue-ish"}, ValueError, r"`background` to be '#rgb', '#rrggbb'"),
        ({"ball_color": (1, 0)}, ValueError, "`ball_color`"),
        ({"group_colors": ["#ff0000"] * 4}, ValueError, r"at least 24 colours \(one per group\), got 4"),
        ({"group_colors": "#ff0000"}, ValueError, "sequence of colours"),
        ({"group_colors": ["#ff0000"] * 23 + ["reddish"]}, ValueError, r"`group_colors\[23\]`"),
        ({"capacity": 0}, ValueError, r"`capacity` to be an int >= 1"),
        ({"n_groups": 0}, ValueError, r"`n_groups` to be an int >= 1"),
        ({"scale": 0}, ValueError, r"`scale` > 0 and finite"),
        ({"scale": "1"}, TypeError, "`scale` to be a positive number"),
        ({"antialias": "yes"}, TypeError, "`antialias` to be True or False"),
        ({"show_faces": None}, TypeError, "`show_faces` to be True or False"),
    ],
)
def test_bad_options_raise_naming_what_is_allowed(kw, exc, match):
    before = live_widgets()
    with pytest.raises(exc, match=match):
        Scene(**scene_options(PolytopeSource("24-cell"), **kw))
    assert live_widgets() == before  # nothing left open


def test_scene_takes_no_polytope_only_keywords():
    with pytest.raises(TypeError):
        Scene(polytope("24-cell"))  # the widget turns a source into scale, groups and capacity
    with pytest.raises(TypeError, match="scale"):
        Scene()


def test_group_colors_are_used(scenes):
    colors = ["#ff0000", "#00ff00", "#0000ff", "#ffff00", "#00ffff"]
    sc, src = scenes("5-cell", group_colors=colors)
    s = src.slice(np.eye(4), 0.0)
    sc.show(s)
    nt = len(s.triangles)
    rgb = [[int(c[i : i + 2], 16) for i in (1, 3, 5)] for c in colors]
    # rows are in the order for the eye: match each to its triangle by its corners
    scale = sizes.REFERENCE_RADIUS / src.size
    want = {tuple(np.round((s.points[t] * scale).astype(np.float32), 4).ravel()): rgb[g]
            for t, g in zip(s.triangles, s.groups)}
    corners = sc.rows[:nt, 10:19]
    got = {tuple(np.round(c, 4)): u.tolist() for c, u in zip(corners, bf.unpack_rgb(sc.rows[:nt, 19]))}
    assert got == want and len(set(map(tuple, want.values()))) > 1


def test_single_rgb_paints_every_face_and_is_an_update(scenes, log):
    sc, src = scenes("24-cell")
    s = src.slice(random_rotation(np.random.default_rng(2)), 0.0)
    assert sc.show(s)
    log.clear()
    assert sc.show(s, single_rgb=colours.as_rgb(colours.SINGLE_FACE_COLOR)) is True  # same slice, new colours
    nt = len(s.triangles)
    assert np.all(bf.unpack_rgb(sc.rows[:nt, 19]) == [0x9F, 0xB6, 0xCD])
    assert len(buffer_messages(sc, log)) == 1
    assert sc.show(s) is True  # back to group colours
    assert len(np.unique(sc.rows[:nt, 19])) > 1


# ----------------------------------------------------------------- the projection's fields
def test_projection_travels_in_the_slice_message_and_only_when_it_changed(scenes, log):
    """`show(projection=...)` puts the projection's state (and, when new, its skeleton) into the
    buffer's own update message; an unchanged state is not re-sent, a changed one alone is an
    update (with its id), `project` sends it without one, `turn` carries it too."""
    from rot4d_widget.view import projection as pj

    sc, src = scenes("24-cell")
    rng = np.random.default_rng(8)
    m = random_rotation(rng)
    first = {"state": pj.state_message(src, m, 0.1), "skeleton": pj.skeleton_message(src, sc.scale)}
    log.clear()
    assert sc.show(src.slice(m, 0.1), projection=first)
    ((data, n, bufs),) = buffer_messages(sc, log)
    assert len(log) == 1 and {"array", "_rot4d_seq", "_rot4d_project", "_rot4d_skeleton"} <= set(data["state"])
    assert data["state"]["_rot4d_project"] == first["state"]
    log.clear()  # the same state again: nothing
    assert sc.show(src.slice(m, 0.1), projection={"state": pj.state_message(src, m, 0.1)}) is False and log == []
    # the slice unchanged (c0 beyond the object: empty) but the projection's colours move with c0
    far = 2 * src.size
    assert sc.show(src.slice(m, far), projection={"state": pj.state_message(src, m, far)})
    log.clear()
    seq = sc.update_id
    assert sc.show(src.slice(m, far + 1), projection={"state": pj.state_message(src, m, far + 1)}) is True
    ((data, n, bufs),) = buffer_messages(sc, log)
    assert data["state"]["_rot4d_project"]["offsets"] == [far + 1] and "_rot4d_skeleton" not in data["state"]
    assert sc.update_id == seq + 1
    log.clear()
    assert sc.project({"state": pj.state_message(src, m, 0.3)}) is True and sc.update_id == seq + 1
    ((data, n, bufs),) = buffer_messages(sc, log)
    assert set(data["state"]) == {"_rot4d_project"}
    log.clear()
    c, s_ = math.cos(0.3), math.sin(0.3)
    r = np.array([[c, -s_, 0.0], [s_, c, 0.0], [0.0, 0.0, 1.0]])  # a turn about z: w unchanged
    m2 = np.eye(4)
    m2[:3, :3] = r
    assert sc.turn(r, projection={"state": pj.state_message(src, m2 @ m, 0.3)})
    ((data, n, bufs),) = buffer_messages(sc, log)
    assert {"_rot4d_turn", "_rot4d_seq", "_rot4d_project"} <= set(data["state"]) and "array" not in data["state"]
