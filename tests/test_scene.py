"""rot4d_widget.scene without a browser: what the scene is made of and what one update sends.

Comm messages are recorded by a comm that serialises like ipykernel's (the
ipywidgets tests' dummy-comm pattern), so counts and sizes are those a kernel
would send.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
import pythreejs as p3
from ipywidgets.widgets import widget as ipywidget_module

from rot4d_widget import buffers as bf
from rot4d_widget import polytope, slice_polytope
from rot4d_widget.polytopes import POLYTOPE_NAMES
from rot4d_widget.scene import PENTACHORON_CIRCUMRADIUS, Scene


@pytest.fixture(autouse=True)
def log(recording_comms):
    """Every message sent: (comm_id, data, n_bytes, buffers) -- tests/recording_comm.py."""
    yield recording_comms


def random_rotation(rng):
    q, r = np.linalg.qr(rng.standard_normal((4, 4)))
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    return q


@pytest.fixture
def scenes():
    made = []

    def make(name="24-cell", **kw):
        s = Scene(polytope(name) if isinstance(name, str) else name, **kw)
        made.append(s)
        return s

    yield make
    for s in made:
        s.close()


def live_widgets():
    return len(ipywidget_module._instances)


def walk(obj):
    yield obj
    for child in getattr(obj, "children", ()):
        yield from walk(child)


# ----------------------------------------------------------------- structure
def test_multisampling_is_off_unless_asked_for(scenes):
    # off by default: it smooths no impostor outline and costs every pass (see scene docs)
    assert scenes("5-cell").renderer._antialias is False
    assert scenes("5-cell", antialias=True).renderer._antialias is True


def test_camera_controls_renderer_as_the_paper_and_the_issue_ask(scenes):
    sc = scenes("5-cell", width=420, height=300)
    cam = sc.renderer.camera
    assert isinstance(cam, p3.PerspectiveCamera)
    assert tuple(cam.position) == (0.0, 0.0, 5.0)
    assert tuple(cam.quaternion) == (0.0, 0.0, 0.0, 1.0)  # looking down -z
    assert cam.aspect == pytest.approx(420 / 300)
    (controls,) = sc.renderer.controls
    assert isinstance(controls, p3.OrbitControls) and controls.enableKeys is False
    assert controls.controlling is cam
    assert (sc.renderer.width, sc.renderer.height) == (420, 300)
    assert "rot4d-canvas" in sc.renderer._dom_classes
    assert sc.canvas_class in sc.renderer._dom_classes and sc.canvas_class.startswith("rot4d-canvas-")
    assert scenes("5-cell").canvas_class != sc.canvas_class


def test_no_directional_light_and_shaders_do_the_lighting(scenes):
    sc = scenes("5-cell")
    objects = list(walk(sc.three_scene))
    assert not any(isinstance(o, p3.DirectionalLight) for o in objects)
    meshes = [o for o in objects if isinstance(o, p3.Mesh)]
    assert [m.name for m in meshes] == ["balls", "bars", "faces"]
    for m in meshes:
        assert m.frustumCulled is False
        assert isinstance(m.material, p3.ShaderMaterial)
        # impostors are lit per pixel (their normal varies), flat faces per corner
        lit_in = m.material.vertexShader if m.name == "faces" else m.material.fragmentShader
        assert "vec3 shade(" in lit_in and "shade(" in lit_in.split("void main()")[1]
        assert {"u_ambient", "u_sky", "u_ground", "u_light_position"} <= set(m.material.uniforms)
    faces = meshes[2].material
    assert faces.transparent and faces.depthWrite is False and faces.side == "DoubleSide"
    assert faces.uniforms["u_opacity"]["value"] == pytest.approx(0.35)


def _facing(rows, eye):
    corners = rows[:, 10:19].astype(np.float64).reshape(-1, 3, 3)
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    used = np.linalg.norm(normal, axis=1) > 1e-12
    return np.einsum("ij,ij->i", normal, np.asarray(eye) - corners[:, 0])[used] > 0


@pytest.mark.parametrize("name", ["24-cell", "600-cell"])
def test_faces_facing_away_from_the_camera_come_first(scenes, name):
    """Drawn in row order, the translucent faces of the convex slice blend back to front."""
    sc = scenes(name)
    rng = np.random.default_rng(7)
    for _ in range(5):
        q, _r = np.linalg.qr(rng.standard_normal((4, 4)))
        if np.linalg.det(q) < 0:
            q[:, 0] = -q[:, 0]  # a rotation
        s = slice_polytope(sc.polytope, q, 0.0)
        for eye in [(0.0, 0.0, 5.0), (3.0, -4.0, 1.0)]:
            sc.camera.position = eye
            sc.show(s)
            facing = _facing(sc.rows, eye)
            assert len(facing) == len(s.triangles)
            assert 0 < facing.sum() < len(facing)  # both kinds seen from outside
            k = int(np.argmax(facing))  # first front-facing triangle
            assert not facing[:k].any() and facing[k:].all()


def test_meshes_share_one_buffer_through_the_documented_columns(scenes):
    sc = scenes("24-cell")
    geos = [m.geometry for m in sc.three_scene.children if isinstance(m, p3.Mesh)]
    buffers = set()
    for g in geos:
        assert isinstance(g, p3.InstancedBufferGeometry)
        assert g.maxInstancedCount == sc.capacity
        for name, attr in g.attributes.items():
            if isinstance(attr, p3.InterleavedBufferAttribute):
                buffers.add(attr.data.model_id)
                assert (attr.offset, attr.itemSize) == bf.COLUMNS[name]
    assert buffers == {sc.buffer_model_id}
    arr = sc._buffer.array
    assert arr.dtype == np.float32 and arr.shape == (sc.capacity, 20)
    # no sphere or cylinder per instance: the templates are small and fixed
    assert geos[0].attributes["position"].array.shape == (6, 3)
    assert geos[1].attributes["position"].array.shape == (6, 3)  # bars are impostors too
    assert "normal" not in geos[1].attributes
    assert geos[2].attributes["position"].array.shape == (3, 3)


@pytest.mark.parametrize("which", [0, 1], ids=["balls", "bars"])
def test_impostor_shaders_write_depth_under_webgl1_and_webgl2(scenes, which):
    """three r97 in pythreejs runs on WebGL2 when it can (seen in Chromium): there the
    extension macro is undefined and gl_FragDepthEXT is #defined to gl_FragDepth."""
    sc = scenes("5-cell")
    mat = sc._materials[which]
    frag = mat.fragmentShader
    assert "#if defined(GL_EXT_frag_depth) || __VERSION__ >= 300" in frag
    assert "gl_FragDepthEXT =" in frag
    assert "uniform mat4 projectionMatrix;" in frag  # not given to fragment shaders by r97
    assert "discard" in frag
    assert mat.extensions == {"fragDepth": True}


def test_shader_attributes_match_the_columns(scenes):
    sc = scenes("5-cell")
    decl = {}
    for m in sc.three_scene.children:
        if isinstance(m, p3.Mesh):
            for typ, name in re.findall(r"attribute (vec[234]|float) (\w+);", m.material.vertexShader):
                decl[name] = {"float": 1, "vec2": 2, "vec3": 3, "vec4": 4}[typ]
    assert decl == {name: size for name, (col, size) in bf.COLUMNS.items()}


@pytest.mark.parametrize("name", POLYTOPE_NAMES)
def test_every_polytope_appears_the_size_of_the_pentachoron(scenes, name):
    p = polytope(name)
    sc = scenes(p, capacity=16)
    assert sc.scale * p.circumradius == pytest.approx(PENTACHORON_CIRCUMRADIUS)
    assert PENTACHORON_CIRCUMRADIUS == pytest.approx(polytope("5-cell").circumradius)
    s = slice_polytope(p, np.eye(4), 0.0)
    sc.show(s)
    np.testing.assert_allclose(sc.rows[: len(s.vertices), :3], s.vertices * sc.scale, rtol=1e-6, atol=1e-7)
    if name == "120-cell":
        assert p.circumradius == pytest.approx(7.4, abs=0.01)


# ----------------------------------------------------------------- updates
def test_one_show_is_one_message_to_the_buffer(scenes, log):
    rng = np.random.default_rng(1)
    p = polytope("120-cell")
    sc = scenes(p)
    before = live_widgets()
    for k in range(1, 6):
        log.clear()
        s = slice_polytope(p, random_rotation(rng), 0.0)
        sent = sc.show(s)
        assert len(log) == 1
        cid, data, n, bufs = log[0]
        assert cid == sc.buffer_model_id
        assert data["method"] == "update"
        assert set(data["state"]) == {"array", "_rot4d_seq"}
        assert data["state"]["_rot4d_seq"] == sc.update_id == k
        assert data["state"]["array"]["dtype"] == "float32"
        assert tuple(data["state"]["array"]["shape"]) == (sc.capacity, 20)
        assert len(bufs) == 1 and bufs[0].nbytes == sc.capacity * 80
        rows = bufs[0].view(np.float32).reshape(sc.capacity, 20)
        np.testing.assert_array_equal(rows, bf.slice_rows(s, scale=sc.scale, cell_rgb=sc._cell_rgb, capacity=sc.capacity, eye=sc.eye))
        assert abs(sent - n) < 200  # show() reports the payload the comm sends
        assert n <= 40 * 1024
    assert live_widgets() == before  # show() never creates widgets


@pytest.mark.parametrize("name", POLYTOPE_NAMES)
def test_bytes_per_update_at_most_64KB(scenes, log, name):
    rng = np.random.default_rng(4)
    p = polytope(name)
    sc = scenes(p)
    sizes = []
    for _ in range(8):
        log.clear()
        sc.show(slice_polytope(p, random_rotation(rng), 0.0))
        sizes += [n for cid, data, n, b in log]
    assert max(sizes) <= 64 * 1024


def test_unchanged_slice_sends_nothing_unless_forced(scenes, log):
    p = polytope("24-cell")
    sc = scenes(p)
    s = slice_polytope(p, np.eye(4), 0.0)
    assert sc.show(s) > 0 and sc.update_id == 1
    log.clear()
    assert sc.show(slice_polytope(p, np.eye(4), 0.0)) == 0
    assert log == [] and sc.update_id == 1
    assert sc.show(s, force=True) > 0 and sc.update_id == 2 and len(log) == 1


def test_growth_keeps_every_intermediate_state_whole(scenes, log):
    """Capacity growth: old picture padded (same id) -> counts -> new picture (new id)."""
    p = polytope("600-cell")
    sc = scenes(p, capacity=32)
    small = slice_polytope(p, np.eye(4), 0.9 * p.circumradius)
    assert 0 < bf.rows_needed(small) <= 32
    sc.show(small)
    old = sc.rows.copy()
    widgets_before = live_widgets()
    log.clear()
    big = slice_polytope(p, random_rotation(np.random.default_rng(0)), 0.0)
    sc.show(big)
    assert live_widgets() == widgets_before
    geo_ids = {g.model_id for g in sc._geometries.values()}
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
    # afterwards, normal updates are one message again
    log.clear()
    sc.show(slice_polytope(p, random_rotation(np.random.default_rng(1)), 0.0))
    assert len(log) == 1


def test_show_after_close_raises_and_close_closes_everything(scenes):
    sc = scenes("5-cell")
    widgets = list(sc._widgets)
    assert all(w.comm is not None for w in widgets)
    sc.close()
    assert all(w.comm is None for w in widgets)
    sc.close()  # idempotent
    with pytest.raises(RuntimeError, match="closed"):
        sc.show(slice_polytope(polytope("5-cell"), np.eye(4), 0.0))


def test_default_radii_follow_the_displayed_edge(scenes):
    big = scenes("5-cell")
    dense = scenes("120-cell")
    assert big.ball_radius == pytest.approx(0.07)
    edge120 = 2.0 * dense.scale
    assert dense.ball_radius == pytest.approx(0.1 * edge120)
    assert dense.bar_radius == pytest.approx(0.4 * dense.ball_radius)
    custom = scenes("5-cell", ball_radius=0.1, bar_radius=0.02, face_opacity=1, background=(0, 0, 0))
    assert (custom.ball_radius, custom.bar_radius, custom.face_opacity) == (0.1, 0.02, 1.0)
    assert custom.renderer.clearColor == "#000000"


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
        ({"cell_colors": ["#ff0000"] * 4}, ValueError, r"at least 24 colours \(one per cell\), got 4"),
        ({"cell_colors": "#ff0000"}, ValueError, "sequence of colours"),
        ({"capacity": 0}, ValueError, r"`capacity` to be an int >= 1 or None"),
        ({"antialias": "yes"}, TypeError, "`antialias` to be True or False"),
    ],
)
def test_bad_options_raise_naming_what_is_allowed(kw, exc, match):
    with pytest.raises(exc, match=match):
        Scene(polytope("24-cell"), **kw)


def test_not_a_polytope():
    with pytest.raises(TypeError, match="`polytope` to be a rot4d_widget.Polytope"):
        Scene("24-cell")


def test_cell_colors_are_used(scenes):
    p = polytope("5-cell")
    colors = ["#ff0000", "#00ff00", "#0000ff", "#ffff00", "#00ffff"]
    sc = scenes(p, cell_colors=colors)
    s = slice_polytope(p, np.eye(4), 0.0)
    sc.show(s)
    got = bf.unpack_rgb(sc.rows[: len(s.triangles), 19])
    want = np.array([[int(c[i : i + 2], 16) for i in (1, 3, 5)] for c in colors], dtype=np.uint8)
    np.testing.assert_array_equal(got, want[s.triangle_cells])
