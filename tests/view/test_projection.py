"""The whole object beside its slice (`rot4d_widget.view.projection`, ``projection=True``)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rot4d_widget.core.rotation import random_rotation
from rot4d_widget.keep.recorder import ViewSetting
from rot4d_widget.sources.field.container import Field4D
from rot4d_widget.sources.protocol import PolytopeSource, as_source
from rot4d_widget.sources.tomography import StackSource
from rot4d_widget.view import projection as pj
from rot4d_widget.view.widget import Rot4DWidget


def key_event(kind, key, code=None):
    code = code or (f"Digit{key}" if key.isdigit() else f"Key{key.upper()}")
    return {"type": kind, "event": kind, "key": key, "code": code, "shiftKey": False, "altKey": False,
            "ctrlKey": False, "metaKey": False, "repeat": False, "location": 0, "target": {}}


def press(w, key):
    w._handle_event(key_event("keydown", key))
    w._handle_event(key_event("keyup", key))


@pytest.fixture
def widgets():
    made = []

    def make(*args, **kwargs):
        w = Rot4DWidget(*args, _autotick=False, **kwargs)
        made.append(w)
        return w

    yield make
    for w in made:
        w.close()


def small_field(n=9):
    x = np.linspace(-1, 1, n)
    q = np.stack(np.meshgrid(x, x, x, x, indexing="ij"), -1)
    f = Field4D((0.6 - (q ** 2).sum(-1)).astype(np.float32), axes="xyzw", extent=((-1, 1),) * 4, name="ball")
    f.levels = 0.0
    return f


def _match(a, b, atol=1e-6):
    """Every row of ``a`` has a row of ``b`` within ``atol`` and back."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    d = np.linalg.norm(a[:, None] - b[None], axis=-1)
    return bool(d.min(axis=1).max() <= atol and d.min(axis=0).max() <= atol)


def test_projected_points_are_the_closed_form():
    src = PolytopeSource("24-cell")
    m = random_rotation(np.random.default_rng(1))
    scale = 0.7
    out = pj.projection_arrays(src, m, 0.2, scale)
    v, e = np.asarray(src.polytope.vertices, float), np.asarray(src.polytope.edges)
    d = 3.0 * src.size
    r = v @ m.T
    expect = np.concatenate([[r[a, :3] * d / (d - r[a, 3]), r[b, :3] * d / (d - r[b, 3])] for a, b in e])
    assert out["distance"] == pytest.approx(d)
    assert out["positions"].dtype == np.float32 and out["points"].dtype == np.float32
    np.testing.assert_array_equal(out["index"], e.reshape(-1))
    edges = out["positions"][out["index"]]  # what the line segments draw
    np.testing.assert_allclose(edges, expect.reshape(-1, 3) * scale, rtol=1e-6, atol=1e-6)


def test_edge_colours_follow_w():
    src = PolytopeSource("120-cell")
    m = random_rotation(np.random.default_rng(2))
    c0 = 0.5
    out = pj.projection_arrays(src, m, c0)
    w = (np.asarray(src.polytope.vertices) @ m.T)[:, 3]
    rgb = out["rgb"]
    redder = rgb[:, 0] - rgb[:, 2]
    far = np.abs(w - c0) > 1e-6
    assert np.all(np.sign(redder[far]) == np.sign(w - c0)[far])  # red above c0, blue below
    # the diverging map's closed form: coolwarm's blue end at c0 - size, grey at c0, red end at c0 + size
    t = np.clip((w - c0) / src.size, -1, 1)[:, None]
    blue, grey, red = np.array([0.230, 0.299, 0.754]), np.array([0.865] * 3), np.array([0.706, 0.016, 0.150])
    expect = np.where(t > 0, grey + t * (red - grey), grey - t * (blue - grey))
    np.testing.assert_allclose(rgb, expect, atol=1e-6)
    top, bottom = np.argmax(w), np.argmin(w)
    assert redder[top] == pytest.approx(redder.max()) and redder[bottom] == pytest.approx(redder.min())


@pytest.mark.parametrize("name", ["5-cell", "24-cell", "120-cell"])
def test_highlighted_points_are_the_slice_points_projected(name):
    src = PolytopeSource(name)
    rng = np.random.default_rng(3)
    for _ in range(4):
        m = random_rotation(rng)
        w = np.asarray(src.polytope.vertices) @ m[3]
        c0 = float(rng.uniform(w.min(), w.max()))
        out = pj.projection_arrays(src, m, c0)
        d = out["distance"]
        sl = np.asarray(src.slice(m, c0).points)
        assert len(sl) and _match(out["points"], sl * d / (d - c0), atol=1e-5)
    # every crossing lies on an edge whose ends straddle c0
    r = np.asarray(src.polytope.vertices) @ m.T
    e = np.asarray(src.polytope.edges)
    cross = pj.crossings(r, e, [c0])
    a, b = r[e[:, 0]], r[e[:, 1]]
    straddle = (np.minimum(a[:, 3], b[:, 3]) <= c0) & (np.maximum(a[:, 3], b[:, 3]) >= c0)
    for p in cross:
        ab, ap = b[straddle] - a[straddle], p - a[straddle]
        t = np.einsum("ij,ij->i", ap, ab) / np.einsum("ij,ij->i", ab, ab)
        off = np.linalg.norm(ap - t[:, None] * ab, axis=1)
        assert np.any((off < 1e-9) & (t >= -1e-9) & (t <= 1 + 1e-9))


def test_field_shows_its_box_and_cut(widgets):
    f = small_field()
    corners, edges = pj.skeleton(f)
    assert corners.shape == (16, 4) and edges.shape == (32, 2)
    assert len({tuple(sorted(x)) for x in edges.tolist()}) == 32
    lengths = np.linalg.norm(corners[edges[:, 0]] - corners[edges[:, 1]], axis=1)
    np.testing.assert_allclose(np.sort(lengths), np.sort(2 * np.repeat(np.asarray(f.half_widths), 8)))
    w = widgets(f, projection=True)
    out = w._projection.arrays
    assert out["positions"].shape == (16, 3) and out["index"].shape == (64,)
    assert len(out["points"]) == 8  # at rest w = c0 cuts the 8 edges along w at their middles


def test_stack_marks_every_slice(widgets):
    w = widgets("24-cell", slices=3, projection=True)
    out = w._projection.arrays
    assert len(out["offsets"]) == 3 and len(set(np.round(out["offsets"], 9))) == 3
    src = PolytopeSource("24-cell")
    r = np.asarray(src.polytope.vertices) @ np.asarray(w.state.matrix).T
    d = out["distance"]
    wanted = []
    for o in out["offsets"]:
        c = pj.crossings(r, src.polytope.edges, [o])
        assert len(c), "every slice has crossings"
        wanted.append(pj.perspective(c, d) * w._showing.scale)
    assert _match(out["points"], np.concatenate(wanted), atol=1e-5)


def test_both_views_update_from_one_message(widgets, recording_comms):
    """A key press sends ONE message for both views: the slice's rows and the projection's state
    (the 4x4 matrix and the hyperplane's offset, `state_message` of the new state) in the
    scene buffer's update; nothing goes to the projection's own widgets (the page projects).
    The skeleton went once, with the first picture."""
    log = recording_comms
    w = widgets("24-cell", projection=True)
    buf = w.scene.buffer
    sk = buf.skeleton
    vertices, edges = pj.skeleton(w.source)
    np.testing.assert_array_equal(np.frombuffer(sk["vertices"], "<f8").reshape(-1, 4), vertices)
    np.testing.assert_array_equal(np.frombuffer(sk["edges"], "<u4").reshape(-1, 2), edges)
    assert sk["distance"] == pytest.approx(3.0 * w.source.size) and sk["scale"] == w._showing.scale
    own = {x.model_id for x in w._projection._widgets}
    for key in ("4", "l", "c"):  # a rotation in w, c0 up, a rotation in xy
        log.clear()
        seq = w.scene.update_id
        press(w, key)
        sent = [(cid, data) for cid, data, n, bufs in log if data.get("method") == "update"]
        assert not [cid for cid, _ in sent if cid in own], "the projection's widgets get no message"
        ((data,),) = [[d for cid, d in sent if cid == w.scene.buffer_model_id and "array" in d["state"]]]
        assert data["state"]["_rot4d_seq"] == w.scene.update_id == seq + 1
        assert data["state"]["_rot4d_project"] == pj.state_message(w.source, w.state.matrix, w.state.c0)
        assert "_rot4d_skeleton" not in data["state"]
        assert w._projection.shown_key[0] is w.state.matrix and w._projection.shown_key[1] == w.state.c0
    now = pj.projection_arrays(w.source, w.state.matrix, w.state.c0, w._showing.scale)
    np.testing.assert_array_equal(w._projection.arrays["positions"], now["positions"])


def test_turned_on_later_sends_skeleton_and_state_once(widgets, recording_comms):
    w = widgets("5-cell")
    press(w, "4")
    assert w.scene.buffer.projection == {}  # off: the slice's messages carry nothing for it
    recording_comms.clear()
    w.projection = True
    sent = [d for cid, d, n, b in recording_comms if cid == w.scene.buffer_model_id]
    assert len(sent) == 1 and set(sent[0]["state"]) == {"_rot4d_project", "_rot4d_skeleton"}
    assert sent[0]["state"]["_rot4d_project"] == pj.state_message(w.source, w.state.matrix, w.state.c0)
    assert w.companion.projection_model_ids == [w._projection._lines.model_id, w._projection._points.model_id,
                                                w._projection._scene.model_id]
    assert w.companion.projection_class == w._projection.canvas_class


# -- the page's projection (companion.js) under Node against projection_arrays ------------
NODE_DRIVER = r"""
import { pathToFileURL } from "node:url";
import { readFileSync } from "node:fs";
const m = await import(pathToFileURL(process.argv[2]).href);
const cases = JSON.parse(readFileSync(0, "utf8"));
const out = cases.map(({ skeleton, state }) => {
  const sk = { ...skeleton, vertices: Buffer.from(skeleton.vertices, "base64"),
               edges: Buffer.from(skeleton.edges, "base64") };
  const r = m.projectSkeleton(m.decodeSkeleton(sk), state);
  return r && { positions: Array.from(r.positions), rgb: Array.from(r.rgb), index: Array.from(r.index),
                points: Array.from(r.points) };
});
console.log(JSON.stringify(out));
"""


def _page_projection(tmp_path, cases):
    """companion.js's ``projectSkeleton`` for ``(source, matrix, c0, scale)`` cases, run by Node."""
    import base64
    import shutil
    import subprocess

    from test_companion import JS, _apt_install_node

    node = shutil.which("node") or shutil.which("nodejs") or _apt_install_node()
    if node is None:
        pytest.skip("Node.js is not installed: companion.js's projection not run (apt-get install nodejs)")
    msgs = []
    for src, m, c0, scale in cases:
        sk = pj.skeleton_message(src, scale)
        sk.update({k: base64.b64encode(bytes(sk[k])).decode() for k in ("vertices", "edges")})
        msgs.append({"skeleton": sk, "state": json.loads(json.dumps(pj.state_message(src, m, c0)))})
    driver = tmp_path / "projection.mjs"
    driver.write_text(NODE_DRIVER)
    proc = subprocess.run([node, str(driver), str(JS)], input=json.dumps(msgs), capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.strip().splitlines()[-1])


def test_page_projects_as_python_does(tmp_path):
    """What the page draws (companion.js ``projectSkeleton`` on the messages the kernel sends)
    equals `projection_arrays`: positions and colours to float32 rounding, the same edges, the
    same crossings in the same order -- random rotations and levels, a level at a vertex (edges
    touching it), a field's box with edges lying in the hyperplane, a stack's three hyperplanes."""
    rng = np.random.default_rng(11)
    cases = []
    for name in ("5-cell", "24-cell", "120-cell"):
        src = PolytopeSource(name)
        for k in range(3):
            m = random_rotation(rng)
            w = np.asarray(src.polytope.vertices) @ m[3]
            c0 = float(w[rng.integers(len(w))]) if k == 2 else float(rng.uniform(w.min(), w.max()))
            cases.append((src, m, c0, float(rng.uniform(0.2, 2.0))))
    f = small_field()
    hw = float(np.asarray(f.half_widths)[3])
    cases += [(f, np.eye(4), hw, 1.0), (f, np.eye(4), 0.0, 0.5), (f, random_rotation(rng), 0.1, 1.0)]
    stack = StackSource(PolytopeSource("24-cell"), slices=3)
    cases.append((stack, random_rotation(rng), 0.05, 0.8))
    page = _page_projection(tmp_path, cases)
    touched = flat = 0
    for (src, m, c0, scale), got in zip(cases, page):
        want = pj.projection_arrays(src, m, c0, scale)
        np.testing.assert_allclose(np.reshape(got["positions"], (-1, 3)), want["positions"], rtol=2e-7, atol=1e-7)
        np.testing.assert_allclose(np.reshape(got["rgb"], (-1, 3)), want["rgb"], rtol=2e-7, atol=1e-7)
        np.testing.assert_array_equal(got["index"], want["index"])
        pts = np.reshape(got["points"], (-1, 3))
        assert pts.shape == want["points"].shape
        np.testing.assert_allclose(pts, want["points"], rtol=1e-6, atol=1e-6)
        touched += len(want["points"]) > len(np.unique(np.round(want["points"], 5), axis=0))
        flat += src is f and c0 == hw
    assert touched >= 1 and flat == 1  # the cases meant to hit a vertex and a flat edge did


def test_page_projection_shows_nothing_without_a_skeleton(tmp_path):
    class Bare:
        size, n_groups = 1.0, 1

        def slice(self, m, c0):  # pragma: no cover - never sliced here
            raise AssertionError

        def describe(self):  # pragma: no cover - never described here
            return {"kind": "bare"}

    bare = as_source(Bare())  # the view is handed the widget's source: a user's object wrapped once
    assert pj.skeleton_message(bare) == {"n_vertices": 0, "n_edges": 0}
    assert pj.projection_arrays(bare, np.eye(4), 0.0) is None


def test_projection_trait_recorded_saved_loaded(widgets, tmp_path):
    w = widgets("5-cell")
    w.projection = True
    assert any(isinstance(e, ViewSetting) and e.name == "projection" and e.value is True
               for e in w.recording.events)
    path = tmp_path / "s.json"
    w.save_state(path)
    assert json.loads(path.read_text())["settings"]["projection"] is True
    other = widgets("5-cell")
    other.load_state(path)
    assert other.projection is True and other._projection.box in other.children
    # a file from before `projection` loads with it off
    doc = json.loads(path.read_text())
    del doc["settings"]["projection"]
    path.write_text(json.dumps(doc))
    other.load_state(path)
    assert other.projection is False and other._projection.box not in other.children
    loaded = Rot4DWidget.from_state(tmp_path / "s.json", _autotick=False)
    try:
        assert loaded.projection is False
    finally:
        loaded.close()


def test_bad_projection_is_refused(widgets):
    with pytest.raises(TypeError, match="Expected `projection` to be True or False, got 'yes'"):
        widgets("5-cell", projection="yes")
    w = widgets("5-cell")
    with pytest.raises(TypeError, match="True or False"):
        w.projection = "yes"


def test_off_by_default_changes_nothing(widgets):
    plain, shown = widgets("24-cell"), widgets("24-cell", projection=True)
    assert plain.projection is False and plain._projection.box is None and len(plain.children) == 2
    assert len(shown.children) == 3
    for w in (plain, shown):
        press(w, "4")
        press(w, "c")
    np.testing.assert_array_equal(plain.scene.buffer.array, shown.scene.buffer.array)
    assert "views" not in plain.readout.value and "views" in shown.readout.value


def test_keys_over_the_projection_turn_the_object(widgets):
    """A key pressed with the mouse over the projection's canvas goes the same way as over the slice:
    its ipyevents listener hands the event to the widget's key handler."""
    w = widgets("24-cell", projection=True)
    ev = w._projection.events
    assert ev is not None and ev.source is w._projection.renderer
    assert set(ev.watched_events) == {"keydown", "keyup", "mouseleave"}
    m0 = np.array(w.state.matrix)
    for kind in ("keydown", "keyup"):
        ev._handle_mouse_msg(None, key_event(kind, "4"), None)
    assert not np.allclose(w.state.matrix, m0)
    assert w._projection.shown_key[0] is w.state.matrix  # both views show the turn
    w._projection.close()
    assert w._projection.events is None
