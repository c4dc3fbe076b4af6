"""rot4d_widget.view.companion: the Python side, and companion.js run under Node with a fake page.

The JavaScript is exercised without a browser: Node imports the shipped ES
module and calls its ``render`` with a fake anywidget model, fake pythreejs
models (Backbone-style ``on``/``off``/``trigger``), a fake ``window`` and
``document`` and a manual ``requestAnimationFrame`` queue.  (The real-browser
proof, in JupyterLab 4 and Notebook 7, is described in the scene module's
report; it needs Chromium.)
"""

from __future__ import annotations

import json
import os
import pathlib
import shutil
import subprocess
import tempfile

import pytest

import rot4d_widget
from rot4d_widget.view.bundle import ENTRY, PAGE_DIR, page_module
from rot4d_widget.view.companion import Companion

#: The module the front end receives (the page's modules joined), as a file Node can import.
JS = pathlib.Path(tempfile.mkdtemp(prefix="rot4d-page-")) / "page.mjs"
JS.write_text(page_module())


pytestmark = pytest.mark.usefixtures("recording_comms")  # tests/conftest.py


class FakeScene:
    buffer_model_id = "buf123"
    scene_model_id = "scn456"
    canvas_class = "rot4d-canvas-abc"
    geometry_model_ids = ["g1", "g2", "g3"]
    mesh_model_ids = ["m1", "m2", "m3"]


def from_page(w, content):
    """Deliver a message from the companion's JavaScript as the front end does."""
    w.comm.handler({"content": {"data": {"method": "custom", "content": content}}, "buffers": []})


# ------------------------------------------------------------------ Python side
def test_reads_the_scene_and_is_invisible():
    c = Companion(FakeScene())
    assert (c.buffer_model_id, c.scene_model_id, c.canvas_class) == ("buf123", "scn456", "rot4d-canvas-abc")
    assert c.layout.display == "none"
    with pytest.raises(TypeError, match="Expected `scene` to be a rot4d_widget Scene"):
        Companion(object())


def test_reads_a_real_scene_s_interface():
    """What the companion needs from the Scene: the buffer's and the three.js scene's model ids
    and the canvas's CSS class -- all public on the new Scene."""
    from rot4d_widget.view.scene import Scene

    sc = Scene(scale=1.0, n_groups=5, capacity=16)
    c = Companion(sc)
    try:
        assert (c.buffer_model_id, c.scene_model_id, c.canvas_class) == (
            sc.buffer_model_id, sc.scene_model_id, sc.canvas_class,
        )
        assert sc.scene_model_id == sc.canvas.scene.model_id and sc.canvas_class in sc.canvas._dom_classes
    finally:
        c.close()
        sc.close()


def test_the_pages_time_for_an_update_is_kept_in_seconds_if_it_is_one():
    c = Companion(FakeScene())
    try:
        from_page(c, {"event": "drawn", "seq": 7, "draw_ms": 42.5})
        assert (c.last_drawn, c.last_draw_time) == (7, 0.0425)
        for bad in ("42", -1, True, None, float("nan")):
            from_page(c, {"event": "drawn", "seq": 8, "draw_ms": bad})
            assert (c.last_drawn, c.last_draw_time) == (8, None)
        from_page(c, {"event": "drawn", "seq": 9})
        assert (c.last_drawn, c.last_draw_time) == (9, None)
    finally:
        c.close()


def test_on_drawn_and_on_focus_lost_dispatch_and_can_be_removed():
    c = Companion(FakeScene())
    drawn, lost = [], []
    c.on_drawn(drawn.append)
    c.on_focus_lost(lambda reason, t: lost.append((reason, t)))
    from_page(c, {"event": "drawn", "seq": 7})
    from_page(c, {"event": "focus_lost", "reason": "hidden"})
    from_page(c, {"event": "focus_lost", "reason": "blur", "t": 1234.5})  # the page's time, issue 34
    assert drawn == [7] and lost == [("hidden", None), ("blur", 1234.5)]
    c.on_drawn(drawn.append, remove=True)
    from_page(c, {"event": "drawn", "seq": 8})
    assert drawn == [7]


@pytest.mark.parametrize(
    "content",
    [{"event": "drawn"}, {"event": "drawn", "seq": "3"}, {"event": "drawn", "seq": True}, {"event": "other"}, ["drawn"], "x", None],
)
def test_malformed_messages_are_ignored(content):
    c = Companion(FakeScene())
    got = []
    c.on_drawn(got.append)
    c.on_focus_lost(got.append)
    from_page(c, content)
    assert got == []


def test_a_failing_callback_does_not_escape(caplog):
    c = Companion(FakeScene())
    got = []

    def bad(seq):
        raise RuntimeError("boom")

    c.on_drawn(bad)
    c.on_drawn(got.append)
    from_page(c, {"event": "drawn", "seq": 1})  # must not raise
    assert got == [1]


def test_the_module_ships_inside_the_package():
    assert (PAGE_DIR / ENTRY).is_file()
    assert PAGE_DIR == pathlib.Path(rot4d_widget.__file__).parent / "view" / "page"  # hatch packages the folder
    text = JS.read_text()
    assert "export default" in text
    assert Companion(FakeScene())._esm == text  # what the front end receives is the shipped modules, joined


# ------------------------------------------------------------------ JavaScript under Node
DRIVER = r"""
import { pathToFileURL } from "node:url";
const out = {};
function target() {
  const L = {};
  return {
    L,
    addEventListener(t, f, capture) { (L[t] ||= []).push([f, !!capture]); },
    removeEventListener(t, f, capture) { L[t] = (L[t] || []).filter(([g, c]) => !(g === f && c === !!capture)); },
    fire(t, ev) { for (const [f] of (L[t] || []).slice()) f(ev); },
    count() { return Object.values(L).reduce((n, a) => n + a.length, 0); },
  };
}
function backbone(attrs) {
  const L = {};
  return {
    L, attrs,
    get: (k) => attrs[k],
    // like Backbone's set: attributes first, then change:<name> events, then "change"
    setState(state) { Object.assign(attrs, state); for (const k of Object.keys(state)) (L["change:" + k] || []).slice().forEach((f) => f()); (L.change || []).slice().forEach((f) => f()); },
    on(t, f) { (L[t] ||= []).push(f); },
    off(t, f) { L[t] = (L[t] || []).filter((g) => g !== f); },
    trigger(t) { (L[t] || []).slice().forEach((f) => f()); },
    count() { return Object.values(L).reduce((n, a) => n + a.length, 0); },
  };
}
const CLS = "rot4d-canvas-abc";
let hovered = false;
globalThis.window = target();
globalThis.document = Object.assign(target(), {
  visibilityState: "visible",
  querySelector: (sel) => (hovered && sel === "." + CLS + ":hover" ? {} : null),
  getElementsByClassName: () => [],
});
globalThis.CSS = { escape: (s) => s };
let raf = [];
globalThis.requestAnimationFrame = (f) => raf.push(f);
let clock = 1000;  // the page's clock (performance.now), moved by hand
Object.defineProperty(globalThis.performance, "now", { value: () => clock, configurable: true });
const frame = () => { const q = raf; raf = []; q.forEach((f) => f(0)); };

// the pythreejs buffer model: its three.js object (`obj`) takes a new array on "change"
// (set `applyLate` to hold it back, `bump = false` to skip the version bump)
const wrap = (name) => ({ data: "data-" + name });
const buffer = backbone({ _rot4d_seq: 0, array: wrap("a0") });
let saved = 0;  // what pythreejs's syncToModel would send to the kernel (the buffer's version)
buffer.save_changes = () => { saved++; };
buffer.obj = { array: "data-a0", version: 1, stride: 1 };  // rows = the fake array's length (7)
let applyLate = false, bump = true;
const apply = () => { buffer.obj.array = buffer.attrs.array.data; if (bump) buffer.obj.version++; };
buffer.on("change", () => { if (!applyLate) apply(); });
const scene = backbone({});
let rerenders = 0;
scene.on("rerender", () => rerenders++);
const geometries = [0, 1, 2].map(() => ({ obj: { maxInstancedCount: 16 } }));
const meshes = [0, 1, 2].map(() => ({ obj: { matrix: { elements: new Array(16).fill(0) },
  quaternion: { setFromRotationMatrix(m) { this.from = m.elements.slice(); } } } }));
// the surface mesh: three.js BufferAttributes (setArray; needsUpdate bumps the version)
const attr = (array) => ({ array, version: 0, setArray(a) { this.array = a; }, set needsUpdate(v) { if (v) this.version++; } });
const surfaceGeometry = {
  attributes: { position: attr(new Uint16Array(9)), normal: attr(new Int8Array(9)), a_rgb: attr(new Uint8Array(9)) },
  index: attr(new Uint32Array(0)), drawRange: null, setDrawRange(start, count) { this.drawRange = { start, count }; },
};
meshes.push({ obj: { name: "surface", geometry: surfaceGeometry, matrix: { elements: new Array(16).fill(0) },
  quaternion: { setFromRotationMatrix(m) { this.from = m.elements.slice(); } }, material: { uniforms: { u_lo: {}, u_span: {}, u_opacity: {} } } } });
const sent = [];
const model = {
  get: (k) => ({ buffer_model_id: "IPY_MODEL_buf", scene_model_id: "scn", canvas_class: CLS,
                 geometry_model_ids: ["IPY_MODEL_g0", "g1", "g2"], mesh_model_ids: ["m0", "m1", "m2", "m3"] })[k],
  send: (m) => sent.push(m),
  // the buffer model is not registered at first: get_model rejects twice
  widget_manager: {
    misses: 0,
    async get_model(id) {
      if (id === "buf" && this.misses < 2) { this.misses++; throw new Error("widget model not found"); }
      return ({ buf: buffer, scn: scene, g0: geometries[0], g1: geometries[1], g2: geometries[2],
                m0: meshes[0], m1: meshes[1], m2: meshes[2], m3: meshes[3] })[id];
    },
  },
};
const el = { style: {} };
const mod = await import(pathToFileURL(process.argv[2]).href);
const cleanup = await mod.default.render({ model, el });
out.display = el.style.display;
out.getModelMisses = model.widget_manager.misses;

buffer.save_changes(); buffer.save_changes();
out.savedWhileShown = saved;

// 3. shortcut guard
const key = (type, extra = {}) => { const ev = { type, prevented: false, ctrlKey: false, metaKey: false, altKey: false, ...extra, preventDefault() { this.prevented = true; } }; window.fire(type, ev); return ev.prevented; };
out.capture = ["keydown", "keyup", "keypress"].map((t) => (window.L[t] || []).map(([, c]) => c));
out.notHovered = key("keydown");
hovered = true;
out.hovered = ["keydown", "keypress", "keyup"].map((t) => key(t));
out.ctrl = key("keydown", { ctrlKey: true });
out.meta = key("keydown", { metaKey: true });
hovered = false;

// 1. drawn acknowledgement
const step = (label) => { out[label] = sent.splice(0); };
const set = (seq, name) => buffer.setState(seq === null ? { array: wrap(name) } : { _rot4d_seq: seq, array: wrap(name) });
set(5, "a1");
await null;  // the message's burst of changes settled: the update has arrived (at 1000)
step("beforeRender");
clock += 30;
scene.trigger("afterRender");
step("sameFrame");
clock += 12.5;
frame();
step("nextFrame");
scene.trigger("afterRender"); frame();
step("renderWithoutChange");
set(6, "a2");
set(7, "a3");
scene.trigger("afterRender"); frame();
step("coalesced");
set(null, "a4");  // growth step (a): same id, same picture
scene.trigger("afterRender"); frame();
step("sameId");
set(8, "a5");
frame();
step("noRenderNoAck");
scene.trigger("afterRender"); frame();
step("late");
applyLate = true;  // the array arrived, three.js does not hold it yet
set(9, "a6");
scene.trigger("afterRender"); frame();
step("notYetInThree");
apply();
scene.trigger("afterRender"); frame();
step("nowInThree");
applyLate = false; bump = false;  // three.js holds it but was not told to upload it
set(10, "a7");
scene.trigger("afterRender"); frame();
step("notUploaded");
bump = true;
set(11, "a8");
scene.trigger("afterRender"); frame();
step("uploaded");

// drawn counts travel with the rows and are applied with them (never above the rows held)
buffer.setState({ _rot4d_seq: 12, array: wrap("b1"), _rot4d_counts: [3, 5, 9] });
await null;  // applied in a microtask after the message's burst of change events
out.counts = geometries.map((g) => g.obj.maxInstancedCount);
scene.trigger("afterRender"); frame();
step("countsAck");
// a 3-D turn alone: applied to every mesh, a render requested, acknowledged at the next frame drawn
const turn = [0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];
const before = rerenders;
buffer.setState({ _rot4d_seq: 13, _rot4d_turn: turn });
await null;
out.turned = meshes.map((m) => JSON.stringify(m.obj.quaternion.from) === JSON.stringify(turn));
out.rerendered = rerenders - before;
step("turnBeforeRender");
scene.trigger("afterRender"); frame();
step("turnAck");

// 4. a smooth surface.  Like three.js, the fake GPU re-uploads an attribute only when its version
// exceeds the one uploaded last; pythreejs may put its placeholder arrays back with a small version.
const gpu = new Map();
const surfaceAttrs = () => [...Object.values(surfaceGeometry.attributes), surfaceGeometry.index];
const draw = () => {
  for (const a of surfaceAttrs()) {
    const d = gpu.get(a);
    if (!d || d.version < a.version) gpu.set(a, { version: a.version, length: a.array.length });
  }
  scene.trigger("afterRender"); frame();
};
const stale = () => surfaceAttrs().filter((a) => gpu.get(a).length !== a.array.length).length;
const bytes = (n) => new DataView(new ArrayBuffer(n));
const surface = (seq, n, k) => buffer.setState({ _rot4d_seq: seq, _rot4d_surface: {
  n_vertices: n, n_indices: k, lo: [0, 0, 0], span: 1, opacity: 1,
  position: bytes(6 * n), normal: bytes(3 * n), rgb: bytes(3 * n), index: bytes(4 * k) } });
out.staleSurfaces = [];
for (const [seq, n, k] of [[20, 4, 6], [21, 5, 9], [22, 3, 3]]) {
  surface(seq, n, k); await null; draw();
  out.staleSurfaces.push(stale());
}
out.surfaceLengths = surfaceAttrs().map((a) => a.array.length);
out.drawRange = surfaceGeometry.drawRange;
for (const a of surfaceAttrs()) { a.array = new a.array.constructor(9); a.version = 1; }  // pythreejs re-sync
draw(); draw();  // the companion puts the surface back (and asks for a render)
out.staleSurfaces.push(stale());
out.restoredLengths = surfaceAttrs().map((a) => a.array.length);
surface(23, 6, 12); await null; draw();  // a bigger surface after the re-sync
out.staleSurfaces.push(stale());
step("surfaceMessages");

// 2. focus loss
window.fire("blur", {});
document.visibilityState = "hidden"; document.fire("visibilitychange", {});
document.visibilityState = "visible"; document.fire("visibilitychange", {});
step("focus");

// cleanup
cleanup();
buffer.save_changes();
out.savedAfterCleanup = saved;
out.left = { window: window.count(), document: document.count(), buffer: buffer.count(), scene: scene.count() };
set(14, "a9"); scene.trigger("afterRender"); frame();
window.fire("blur", {});
hovered = true;
out.afterCleanupPrevented = key("keydown");
step("afterCleanup");

// a view opened on a state the kernel sent before any view was shown: acknowledged once drawn
const cleanup2 = await mod.default.render({ model, el: { style: {} } });
step("openedBeforeRender");
scene.trigger("afterRender"); frame();
step("openedOnState");
cleanup2();
console.log(JSON.stringify(out));
"""


def _apt_install_node():
    """As root with apt (CI, a fresh machine): install Debian's nodejs, like the browser tests' Chromium."""
    if not (hasattr(os, "geteuid") and os.geteuid() == 0 and shutil.which("apt-get")):
        return None
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    subprocess.run(["apt-get", "update", "-qq"], env=env, check=False, capture_output=True, timeout=600)
    subprocess.run(["apt-get", "install", "-y", "-qq", "nodejs"], env=env, check=False, capture_output=True,
                   timeout=900)
    return shutil.which("node") or shutil.which("nodejs")


def _run_driver(tmp_path_factory, name, driver_text):
    """Run a Node driver script against the shipped companion.js; its last stdout line is JSON."""
    node = shutil.which("node") or shutil.which("nodejs") or _apt_install_node()
    if node is None:
        pytest.skip("Node.js is not installed: companion.js unit test not run (apt-get install nodejs)")
    driver = tmp_path_factory.mktemp(name) / "driver.mjs"
    driver.write_text(driver_text)
    proc = subprocess.run([node, str(driver), str(JS)], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.strip().splitlines()[-1])


@pytest.fixture(scope="module")
def js_run(tmp_path_factory):
    return _run_driver(tmp_path_factory, "companion", DRIVER)


def test_js_the_surface_is_uploaded_even_after_pythreejs_resets_its_versions(js_run):
    # three.js uploads an attribute only when its version exceeds the last one uploaded; pythreejs
    # re-syncing the placeholder arrays sets a small version: counting up from it, the next surface
    # stayed below the GPU's version and its upload was skipped (a shorter buffer drawn with the
    # new index count: "glDrawElements: Insufficient buffer size", no surface)
    assert js_run["surfaceLengths"] == [9, 9, 9, 3] and js_run["drawRange"] == {"start": 0, "count": 3}
    assert js_run["restoredLengths"] == [9, 9, 9, 3]  # the re-synced placeholders replaced by ours
    assert js_run["staleSurfaces"] == [0, 0, 0, 0, 0]


def test_js_is_invisible(js_run):
    assert js_run["display"] == "none"


def test_js_the_page_does_not_send_the_row_buffer_back(js_run):
    # pythreejs syncs the three.js buffer's version to the kernel after every update; the
    # companion makes that a no-op while it lives (one message each way fewer per update)
    assert js_run["savedWhileShown"] == 0
    assert js_run["savedAfterCleanup"] == 1  # restored by cleanup


def test_js_shortcut_guard_prevents_only_while_hovered(js_run):
    # capture phase on window: the shortcut guard (every key event) and the page's own steps (issue 34)
    assert js_run["capture"] == [[True, True], [True, True], [True]]
    assert js_run["notHovered"] is False
    assert js_run["hovered"] == [True, True, True]
    assert js_run["ctrl"] is False and js_run["meta"] is False


def _acks(msgs):
    """The page's messages without ``draw_ms`` (checked on its own)."""
    return [{k: v for k, v in m.items() if k != "draw_ms"} for m in msgs]


def test_js_drawn_ack_says_how_long_the_page_took_since_the_update_arrived(js_run):
    # arrived at 1000, rendered at 1030, acknowledged at the next frame, 1042.5: the kernel's pump
    # gives a page this slow fewer updates in flight
    assert js_run["nextFrame"][0]["draw_ms"] == 42.5
    assert all(m["draw_ms"] >= 0 for k in ("coalesced", "late", "uploaded") for m in js_run[k])
    assert "draw_ms" not in js_run["openedOnState"][0]  # the state a view opens on: no arrival time


def test_js_drawn_ack_waits_for_a_rendered_and_presented_frame(js_run):
    assert js_run["beforeRender"] == []  # arrival is not drawing
    assert js_run["sameFrame"] == []  # rendered; sent once that frame is presented
    assert _acks(js_run["nextFrame"]) == [{"event": "drawn", "seq": 5}]
    assert js_run["renderWithoutChange"] == []  # orbiting the camera acknowledges nothing
    assert _acks(js_run["coalesced"]) == [{"event": "drawn", "seq": 7}]
    assert js_run["sameId"] == []  # a re-sent picture keeps its id: acknowledged once already
    assert js_run["noRenderNoAck"] == []
    assert _acks(js_run["late"]) == [{"event": "drawn", "seq": 8}]


def test_js_drawn_ack_needs_the_array_in_the_three_js_buffer(js_run):
    # rendered before three.js held the new array: that frame shows the old picture
    assert js_run["notYetInThree"] == []
    assert _acks(js_run["nowInThree"]) == [{"event": "drawn", "seq": 9}]
    # held but its version did not move: not uploaded, not drawn
    assert js_run["notUploaded"] == []
    assert _acks(js_run["uploaded"]) == [{"event": "drawn", "seq": 11}]


def test_js_a_view_opened_on_a_sent_state_acknowledges_it_once_drawn(js_run):
    # keys pressed from code before the widget is displayed: the kernel awaits those updates, and
    # the view that opens draws the latest of them (so acknowledges them all), not before a render
    assert js_run["openedBeforeRender"] == []
    assert _acks(js_run["openedOnState"]) == [{"event": "drawn", "seq": 14}]


def test_js_draws_only_the_rows_in_use_set_with_the_rows(js_run):
    # counts arrive in the buffer's message; never more than the rows the array holds (7 here)
    assert js_run["counts"] == [3, 5, 7]
    assert _acks(js_run["countsAck"]) == [{"event": "drawn", "seq": 12}]


def test_js_a_turn_alone_turns_every_mesh_and_is_acknowledged_when_drawn(js_run):
    assert js_run["turned"] == [True, True, True, True]  # balls, bars, faces, surface
    assert js_run["rerendered"] == 1  # no buffer changed: the scene is asked to render
    assert js_run["turnBeforeRender"] == []
    assert _acks(js_run["turnAck"]) == [{"event": "drawn", "seq": 13}]


def test_js_retries_get_model_until_the_model_is_registered(js_run):
    assert js_run["getModelMisses"] == 2  # and the acks above still came


def test_js_focus_loss(js_run):
    # with the page's time (issue 34): the kernel releases held keys then, as the page does
    assert [{k: v for k, v in m.items() if k != "t"} for m in js_run["focus"]] == [
        {"event": "focus_lost", "reason": "blur"}, {"event": "focus_lost", "reason": "hidden"}]
    assert all(isinstance(m["t"], (int, float)) for m in js_run["focus"])


def test_js_cleanup_removes_every_listener(js_run):
    # (the buffer's one "change" listener is the fake pythreejs model's own, the scene's
    # one "rerender" listener the driver's counter)
    assert js_run["left"] == {"window": 0, "document": 0, "buffer": 1, "scene": 1}
    assert js_run["afterCleanupPrevented"] is False
    assert js_run["afterCleanup"] == []


# ------------------------------------------------ rows drawn without instancing (job 6)
EXPAND_DRIVER = r"""
import { pathToFileURL } from "node:url";
const out = {};
const target = () => ({ addEventListener() {}, removeEventListener() {} });
globalThis.window = target();
globalThis.document = Object.assign(target(), { visibilityState: "visible", querySelector: () => null,
  getElementsByClassName: () => [] });
let raf = [];
globalThis.requestAnimationFrame = (f) => raf.push(f);
let clock = 1000;  // the page's clock (performance.now), moved by hand
Object.defineProperty(globalThis.performance, "now", { value: () => clock, configurable: true });
const frame = () => { const q = raf; raf = []; q.forEach((f) => f(0)); };
function backbone(attrs) {
  const L = {};
  return {
    attrs, get: (k) => attrs[k],
    setState(state) { Object.assign(attrs, state); for (const k of Object.keys(state)) (L["change:" + k] || []).slice().forEach((f) => f()); (L.change || []).slice().forEach((f) => f()); },
    on(t, f) { (L[t] ||= []).push(f); }, off(t, f) { L[t] = (L[t] || []).filter((g) => g !== f); },
    trigger(t) { (L[t] || []).slice().forEach((f) => f()); },
  };
}
// three.js r97 in miniature: the classes the companion finds through the objects it is given
class BufferGeometry {
  constructor() { this.attributes = {}; this.drawRange = { start: 0, count: Infinity }; this.disposed = false; }
  addAttribute(name, a) { this.attributes[name] = a; return this; }
  setDrawRange(start, count) { this.drawRange = { start, count }; }
  dispose() { this.disposed = true; }
}
class InstancedBufferGeometry extends BufferGeometry {}
InstancedBufferGeometry.prototype.isInstancedBufferGeometry = true;
class BufferAttribute {
  constructor(array, itemSize) { this.array = array; this.itemSize = itemSize; this.version = 0; }
  set needsUpdate(v) { if (v) this.version++; }
}
// rows of 6 floats: [ball x y z flag | bar_a x y z]... as in buffers.COLUMNS, smaller
const STRIDE = 6;
const rowsOf = (n, base) => Float32Array.from({ length: n * STRIDE }, (_, i) => base + i);
const buffer = backbone({ _rot4d_seq: 0, array: { data: rowsOf(4, 0) }, _rot4d_counts: [4, 4, 4] });
buffer.save_changes = () => {};
buffer.obj = { array: buffer.attrs.array.data, version: 1, stride: STRIDE };
buffer.on("change", () => { buffer.obj.array = buffer.attrs.array.data; buffer.obj.version++; });
const col = (offset, itemSize) => ({ isInterleavedBufferAttribute: true, offset, itemSize, data: buffer.obj });
const quad = new Float32Array([-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, -1, 0, 1, 1, 0, -1, 1, 0]);
const inst = (columns, template) => {
  const g = new InstancedBufferGeometry();
  g.addAttribute("position", new BufferAttribute(template, 3));
  for (const [name, [o, s]] of Object.entries(columns)) g.addAttribute(name, col(o, s));
  g.maxInstancedCount = 4;
  return g;
};
const geometries = [
  { obj: inst({ ball: [0, 4] }, quad) },
  { obj: inst({ bar_a: [1, 3], bar_b: [3, 3] }, quad) },
  { obj: inst({ tri_a: [0, 3], tri_rgb: [5, 1] }, new Float32Array([1, 0, 0, 0, 1, 0, 0, 0, 1])) },
];
const meshes = geometries.map((g) => ({ obj: { geometry: g.obj, matrix: { elements: [] }, quaternion: { setFromRotationMatrix() {} } } }));
const scene = backbone({});
const sent = [];
const ids = { buf: buffer, scn: scene, g0: geometries[0], g1: geometries[1], g2: geometries[2], m0: meshes[0], m1: meshes[1], m2: meshes[2] };
const model = () => ({
  get: (k) => ({ buffer_model_id: "buf", scene_model_id: "scn", canvas_class: "c", geometry_model_ids: ["g0", "g1", "g2"],
                 mesh_model_ids: ["m0", "m1", "m2"] })[k],
  send: (m) => sent.push(m), on() {}, off() {},
  widget_manager: { async get_model(id) { return ids[id]; } },
});
const mod = await import(pathToFileURL(process.argv[2]).href);
const cleanup = await mod.default.render({ model: model(), el: { style: {} } });

// what a frame draws: per layer, the vertices in the draw range with their attributes
const drawn = () => meshes.map((m) => {
  const g = m.obj.geometry;
  if (g.isInstancedBufferGeometry) return { instanced: true };
  const n = g.drawRange.count;
  const attrs = {};
  for (const [name, a] of Object.entries(g.attributes)) attrs[name] = Array.from(a.array.slice(0, n * a.itemSize));
  return { n, attrs, versions: Object.values(g.attributes).map((a) => a.version) };
});
const draw = () => { scene.trigger("beforeRender"); const d = drawn(); scene.trigger("afterRender"); frame(); return d; };

buffer.setState({ _rot4d_seq: 1, array: { data: rowsOf(4, 100) }, _rot4d_counts: [2, 3, 1] });
out.first = draw();
out.firstAck = sent.splice(0);
out.unchanged = draw();  // nothing new: nothing re-uploaded
buffer.setState({ _rot4d_seq: 2, array: { data: rowsOf(4, 200) }, _rot4d_counts: [1, 1, 2] });
out.second = draw();
out.secondAck = sent.splice(0);
const before = meshes.map((m) => m.obj.geometry);
buffer.setState({ _rot4d_seq: 3, array: { data: rowsOf(9, 300) }, _rot4d_counts: [9, 7, 8] });  // capacity grew
out.grown = draw();
out.grownAck = sent.splice(0);
out.oldDisposed = before.map((g) => g.disposed);
// pythreejs rebuilds a geometry's three.js object: the new one is expanded, the old expansion released
const rebuilt = inst({ ball: [0, 4] }, quad);
geometries[0].obj = rebuilt;
meshes[0].obj.geometry = rebuilt;
out.rebuilt = draw()[0].n;
// a second view of the same companion shares the expansions; removing it keeps them
const cleanup2 = await mod.default.render({ model: model(), el: { style: {} } });
const shared = meshes.map((m) => m.obj.geometry);
draw();
out.sharedSame = meshes.map((m, i) => m.obj.geometry === shared[i]);
cleanup2();
draw();
out.afterOneCleanup = meshes.map((m, i) => m.obj.geometry === shared[i] && !shared[i].disposed);
cleanup();
out.restored = meshes.map((m, i) => m.obj.geometry === geometries[i].obj);
out.disposedAtEnd = shared.map((g) => g.disposed);
console.log(JSON.stringify(out));
"""


@pytest.fixture(scope="module")
def js_expand(tmp_path_factory):
    return _run_driver(tmp_path_factory, "companion_expand", EXPAND_DRIVER)


def _expected(rows, count, columns, template):
    """Independent unpacking: each of `count` rows becomes the template's vertices carrying its columns."""
    stride = 6
    V = len(template) // 3
    attrs = {"position": [float(x) for _ in range(count) for x in template]}
    for name, (offset, size) in columns.items():
        attrs[name] = [float(rows[i * stride + offset + j]) for i in range(count) for _ in range(V) for j in range(size)]
    return {"n": count * V, "attrs": attrs}


QUAD = [-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, -1, 0, 1, 1, 0, -1, 1, 0]
TRI = [1, 0, 0, 0, 1, 0, 0, 0, 1]
LAYERS = [({"ball": (0, 4)}, QUAD), ({"bar_a": (1, 3), "bar_b": (3, 3)}, QUAD), ({"tri_a": (0, 3), "tri_rgb": (5, 1)}, TRI)]


def _rows(n, base):
    return [base + i for i in range(n * 6)]


def _check(frame, rows, counts):
    for layer, (columns, template), count in zip(frame, LAYERS, counts):
        want = _expected(rows, count, columns, template)
        assert layer["n"] == want["n"]
        assert layer["attrs"] == want["attrs"]


def test_js_each_frame_draws_the_rows_of_its_update_without_instancing(js_expand):
    # the frame right after an update draws that update's rows, as plain vertices (no instancing)
    _check(js_expand["first"], _rows(4, 100), [2, 3, 1])
    _check(js_expand["second"], _rows(4, 200), [1, 1, 2])
    assert _acks(js_expand["firstAck"]) == [{"event": "drawn", "seq": 1}]
    assert _acks(js_expand["secondAck"]) == [{"event": "drawn", "seq": 2}]


def test_js_unchanged_rows_are_not_uploaded_again(js_expand):
    assert [layer["versions"] for layer in js_expand["unchanged"]] == [layer["versions"] for layer in js_expand["first"]]
    # a new update re-uploads every column
    for a, b in zip(js_expand["first"], js_expand["second"]):
        assert all(y > x for x, y in zip(a["versions"][1:], b["versions"][1:]))


def test_js_a_grown_capacity_gets_new_geometries(js_expand):
    _check(js_expand["grown"], _rows(9, 300), [9, 7, 8])
    assert _acks(js_expand["grownAck"]) == [{"event": "drawn", "seq": 3}]
    assert js_expand["oldDisposed"] == [True, True, True]  # a GL buffer cannot take a longer array in place
    assert js_expand["rebuilt"] == 9 * 6  # a geometry pythreejs rebuilt is expanded too


def test_js_views_share_the_expansions_and_the_last_one_gives_the_instanced_geometry_back(js_expand):
    assert js_expand["sharedSame"] == [True, True, True]
    assert js_expand["afterOneCleanup"] == [True, True, True]
    assert js_expand["restored"] == [True, True, True]
    assert js_expand["disposedAtEnd"] == [True, True, True]
