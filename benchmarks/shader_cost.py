"""What each pass of the widget's drawing costs in software WebGL, shader by shader, without Jupyter.

    python benchmarks/shader_cost.py [--case "great icosahedral 120-cell"] [--rev HEAD~1,WORK]
        [--rounds 20] [--diagnose] [--screenshots DIR] [--keys KEYS]

About a minute.  The widget is built here (for a git revision: in a subprocess running a clean
``git archive`` of it) and put in the fixed state of ``browser_draw.py``'s rest phase (reset,
then the keys ``SHOT_KEYS``).  Its balls, bars and faces, as pythreejs hands them to three.js
-- the row table, each mesh's template, columns, shaders, uniforms and material settings, the
camera -- are drawn in a bare page of headless Chromium (SwiftShader) on a WebGL2 canvas made as
pythreejs makes it, with three.js r97's shader prefix and draw state, each layer unpacked into a
plain geometry by that code's own ``page/expand.js`` (as the companion does; the "unpack" column
is its time for the three layers, once per update on the page).  Every frame draws the layers of each code
in turn, so a busy machine loads them alike (runs minutes apart are not comparable on the shared
machine; ``browser_draw.py`` measures the real page, this one only the drawing, with less noise).
Each pass is timed between 1-pixel reads; the table gives medians over ``--rounds`` frames.

``--diagnose`` adds, for the first code, what the passes cost when

* ``colour only``: every fragment shader writes a constant colour -- the cost of covering the
  pixels (rasterising, interpolating, writing) without the shaders' own work;
* ``depth never``: the depth test rejects every pixel -- whether SwiftShader skips the fragment
  shader of a pixel its depth test rejects (an early depth test);
* ``half size``: a 300 x 250 canvas, a quarter of the pixels (a pixel ratio of 0.5);
* ``opaque faces``: the faces drawn without blending -- what blending costs.

``--screenshots DIR`` saves each code's picture and compares it with the first code's.  The
figures this benchmark produced, and the commands, are in docs/performance.md.
"""

from __future__ import annotations

import argparse
import base64
import json
import math
import os
import pathlib
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "browser"))
sys.path.insert(0, str(ROOT / "benchmarks"))

LAYERS = ("balls", "bars", "faces")


# -- the widget's layers, as pythreejs hands them to three.js ----------------------------------
def describe(case: str, keys: str | None = None) -> dict:
    """The layers of ``Rot4DWidget(case)`` after reset and ``keys`` (default: browser_draw's
    ``SHOT_KEYS``, its rest state), as plain JSON-able data."""
    from browser_draw import SHOT_KEYS

    from rot4d_widget import Rot4DWidget
    from rot4d_widget.view.bundle import PAGE_DIR
    from rot4d_widget.view.pump import ACK_TIMEOUT

    w = Rot4DWidget(case)
    w.press("r")
    for k in SHOT_KEYS if keys is None else keys:
        w.press(k)
    # no page acknowledges updates here: the pump sends the latest state when the oldest in flight
    # times out (ACK_TIMEOUT); then the scene holds the slice of the last key
    time.sleep(4 * ACK_TIMEOUT)
    sc = w.scene
    canvas = sc.canvas
    meshes = {m.name: m for m in canvas.scene.children if getattr(m, "name", "") in LAYERS}
    layers = []
    for name, count in zip(LAYERS, sc.counts):
        g, m = meshes[name].geometry, meshes[name].material
        layers.append({
            "name": name, "count": int(count), "vert": m.vertexShader, "frag": m.fragmentShader,
            "uniforms": {k: v["value"] for k, v in m.uniforms.items()},
            "transparent": bool(m.transparent), "depthWrite": bool(m.depthWrite), "depthTest": bool(m.depthTest),
            "side": m.side,
            "template": np.asarray(g.attributes["position"].array, dtype=np.float64).ravel().tolist(),
            "columns": {n: [a.offset, a.itemSize] for n, a in g.attributes.items() if n != "position"},
        })
    cam = canvas.camera
    rows = np.ascontiguousarray(sc.rows, dtype="<f4")
    return {"expand": (PAGE_DIR / "expand.js").read_text(), "layers": layers,
            "rows": base64.b64encode(rows.tobytes()).decode(), "stride": rows.shape[1],
            "camera": {"position": list(cam.position), "fov": cam.fov, "aspect": cam.aspect, "near": cam.near,
                       "far": cam.far},
            "size": [canvas.width, canvas.height], "counts": list(sc.counts)}


def describe_revision(rev: str, case: str, keys: str | None, tmp: pathlib.Path) -> tuple[dict, str]:
    from browser_latency import export_revision

    src = tmp / ("src-" + "".join(ch if ch.isalnum() else "_" for ch in rev))
    label = export_revision(rev, src)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(src), os.environ.get("PYTHONPATH")])))
    extra = [] if keys is None else ["--keys", keys]
    out = subprocess.run([sys.executable, __file__, "--describe", case, *extra], env=env, check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out), label


# -- the drawing, as three.js r97 in pythreejs does it ------------------------------------------
def matrices(camera: dict) -> dict:
    """Column-major view and projection matrices of a three.js PerspectiveCamera looking at the origin."""
    eye = np.asarray(camera["position"], dtype=np.float64)
    z = eye / np.linalg.norm(eye)
    x = np.cross([0.0, 1.0, 0.0], z)
    x = x / np.linalg.norm(x) if np.linalg.norm(x) > 1e-12 else np.array([1.0, 0.0, 0.0])
    y = np.cross(z, x)
    world = np.eye(4)
    world[:3, 0], world[:3, 1], world[:3, 2], world[:3, 3] = x, y, z, eye
    view = np.linalg.inv(world)
    near, far = camera["near"], camera["far"]
    top = near * math.tan(math.radians(camera["fov"]) / 2)
    right = top * camera["aspect"]
    proj = np.zeros((4, 4))
    proj[0, 0], proj[1, 1] = near / right, near / top
    proj[2, 2], proj[2, 3], proj[3, 2] = -(far + near) / (far - near), -2 * far * near / (far - near), -1.0
    col = lambda m: m.T.ravel().tolist()  # noqa: E731
    return {"viewMatrix": col(view), "modelViewMatrix": col(view), "modelMatrix": col(np.eye(4)),
            "projectionMatrix": col(proj), "normalMatrix": view[:3, :3].T.ravel().tolist(),
            "cameraPosition": eye.tolist()}


PAGE = r"""
<canvas id="c"></canvas>
<script>
// three.js r97's WebGL2 prefixes for a ShaderMaterial written in GLSL ES 1.0
const VERT = '#version 300 es\n#define attribute in\n#define varying out\n#define texture2D texture\n' +
  'precision highp float;\nprecision highp int;\nuniform mat4 modelMatrix;\nuniform mat4 modelViewMatrix;\n' +
  'uniform mat4 projectionMatrix;\nuniform mat4 viewMatrix;\nuniform mat3 normalMatrix;\n' +
  'uniform vec3 cameraPosition;\n' +
  'attribute vec3 position;\nattribute vec3 normal;\nattribute vec2 uv;\n';
const FRAG = '#version 300 es\n#define varying in\nout highp vec4 pc_fragColor;\n#define gl_FragColor pc_fragColor\n' +
  '#define gl_FragDepthEXT gl_FragDepth\nprecision highp float;\nprecision highp int;\n#define DOUBLE_SIDED\n' +
  'uniform mat4 viewMatrix;\nuniform vec3 cameraPosition;\n';
const b64 = (s) => {
  const b = atob(s);
  const u = new Uint8Array(b.length);
  for (let i = 0; i < b.length; i++) u[i] = b.charCodeAt(i);
  return new Float32Array(u.buffer);
};
// three.js r97 in miniature, for expand.js: the instanced geometry's parent class is the plain one
class BufferGeometry {
  constructor() { this.attributes = {}; this.drawRange = { start: 0, count: Infinity }; }
  addAttribute(name, a) { this.attributes[name] = a; return this; }
  setDrawRange(start, count) { this.drawRange = { start, count }; }
  dispose() {}
}
class InstancedBufferGeometry extends BufferGeometry {}
InstancedBufferGeometry.prototype.isInstancedBufferGeometry = true;
class BufferAttribute {
  constructor(array, itemSize) { this.array = array; this.itemSize = itemSize; this.version = 0; }
  set needsUpdate(v) { if (v) this.version++; }
}
window.setup = async (codes, size) => {
  const canvas = document.getElementById('c');
  canvas.width = size[0]; canvas.height = size[1];
  // as pythreejs makes its renderer's context
  const gl = canvas.getContext('webgl2', {alpha: false, depth: true, stencil: true, antialias: false,
                                          premultipliedAlpha: true, preserveDrawingBuffer: true});
  const px = new Uint8Array(4);
  const sync = () => gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
  const compile = (type, src) => {
    const s = gl.createShader(type); gl.shaderSource(s, src); gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
    return s;
  };
  const built = {};
  const unpacks = {};
  for (const [key, code] of Object.entries(codes)) {
    const expand = await import(URL.createObjectURL(new Blob([code.expand], { type: 'text/javascript' })));
    const rows = b64(code.rows);
    const unpack = () => code.layers.map((layer) => {
      const g = new InstancedBufferGeometry();
      g.addAttribute('position', new BufferAttribute(Float32Array.from(layer.template), 3));
      for (const [name, [offset, itemSize]] of Object.entries(layer.columns)) {
        g.addAttribute(name, { isInterleavedBufferAttribute: true, offset, itemSize });
      }
      const e = expand.makeExpansion(g, expand.layerLayout(g), rows.length / code.stride);
      const t0 = performance.now();
      expand.fillExpansion(e, rows, code.stride, layer.count);
      return [e.geometry, performance.now() - t0];
    });
    unpacks[key] = unpack;
    const geometries = unpack().map(([g]) => g);
    built[key] = code.layers.map((layer, li) => {
      const p = gl.createProgram();
      gl.attachShader(p, compile(gl.VERTEX_SHADER, VERT + layer.vert));
      gl.attachShader(p, compile(gl.FRAGMENT_SHADER, FRAG + layer.frag));
      gl.linkProgram(p);
      if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
      const vao = gl.createVertexArray(); gl.bindVertexArray(vao);
      const geometry = geometries[li];
      for (const [name, a] of Object.entries(geometry.attributes)) {
        const loc = gl.getAttribLocation(p, name);
        if (loc < 0) continue;
        const b = gl.createBuffer();
        gl.bindBuffer(gl.ARRAY_BUFFER, b);
        gl.bufferData(gl.ARRAY_BUFFER, a.array, gl.STATIC_DRAW);
        gl.enableVertexAttribArray(loc); gl.vertexAttribPointer(loc, a.itemSize, gl.FLOAT, false, 0, 0);
      }
      gl.bindVertexArray(null);
      gl.useProgram(p);
      const values = Object.assign({}, code.matrices, layer.uniforms);
      const n = gl.getProgramParameter(p, gl.ACTIVE_UNIFORMS);
      for (let i = 0; i < n; i++) {
        const info = gl.getActiveUniform(p, i), loc = gl.getUniformLocation(p, info.name), v = values[info.name];
        if (v === undefined) continue;
        if (info.type === gl.FLOAT_MAT4) gl.uniformMatrix4fv(loc, false, v);
        else if (info.type === gl.FLOAT_MAT3) gl.uniformMatrix3fv(loc, false, v);
        else if (info.type === gl.FLOAT_VEC3) gl.uniform3fv(loc, v);
        else if (info.type === gl.FLOAT) gl.uniform1f(loc, v);
      }
      return {layer, p, vao, count: geometry.drawRange.count};
    });
  }
  // one frame of one code: three.js's order (opaque layers, then transparent) and state
  window.frame = (key, depthFunc, blend) => {
    const t = {};
    gl.viewport(0, 0, canvas.width, canvas.height);
    gl.clearColor(1, 1, 1, 1); gl.depthMask(true); gl.colorMask(true, true, true, true);
    sync();
    let t0 = performance.now();
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT | gl.STENCIL_BUFFER_BIT);
    sync();
    t.clear = performance.now() - t0;
    t.unpack = unpacks[key]().reduce((sum, [, ms]) => sum + ms, 0);  // the page does it once per update
    const order = built[key].filter((d) => !d.layer.transparent).concat(built[key].filter((d) => d.layer.transparent));
    for (const d of order) {
      gl.useProgram(d.p); gl.bindVertexArray(d.vao);
      // three.js: FrontSide culls the back faces (counter-clockwise in front), DoubleSide none
      if (d.layer.side === 'FrontSide') { gl.enable(gl.CULL_FACE); gl.cullFace(gl.BACK); gl.frontFace(gl.CCW); }
      else gl.disable(gl.CULL_FACE);
      if (d.layer.depthTest) { gl.enable(gl.DEPTH_TEST); gl.depthFunc(depthFunc === 'never' ? gl.NEVER : gl.LEQUAL); }
      else gl.disable(gl.DEPTH_TEST);
      gl.depthMask(d.layer.depthWrite);
      if (d.layer.transparent && blend) {
        gl.enable(gl.BLEND); gl.blendEquation(gl.FUNC_ADD);
        gl.blendFuncSeparate(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA, gl.ONE, gl.ONE_MINUS_SRC_ALPHA);
      } else gl.disable(gl.BLEND);
      sync();
      t0 = performance.now();
      gl.drawArrays(gl.TRIANGLES, 0, d.count);
      sync();
      t[d.layer.name] = performance.now() - t0;
    }
    gl.bindVertexArray(null);
    return t;
  };
  window.picture = () => canvas.toDataURL('image/png');
  // the pixels each layer's triangles cover (every one runs the fragment shader), counted by adding
  // 1/255 per fragment (a code whose shaders write that colour): per layer, and the layers' union
  window.coverage = (key) => {
    const all = new Uint8Array(canvas.width * canvas.height * 4);
    const out = {};
    const union = new Uint8Array(canvas.width * canvas.height);
    gl.disable(gl.DEPTH_TEST); gl.depthMask(false); gl.colorMask(true, true, true, true);
    gl.enable(gl.BLEND); gl.blendEquation(gl.FUNC_ADD); gl.blendFunc(gl.ONE, gl.ONE);
    for (const d of built[key]) {
      gl.clearColor(0, 0, 0, 0); gl.clear(gl.COLOR_BUFFER_BIT);
      gl.useProgram(d.p); gl.bindVertexArray(d.vao);
      gl.drawArrays(gl.TRIANGLES, 0, d.count);
      gl.readPixels(0, 0, canvas.width, canvas.height, gl.RGBA, gl.UNSIGNED_BYTE, all);
      let n = 0, deepest = 0;
      for (let i = 0; i < union.length; i++) {
        const k = all[4 * i];
        n += k; deepest = Math.max(deepest, k);
        if (k) union[i] = 1;
      }
      out[d.layer.name] = { covered: n, deepest, drawn: d.count / (d.layer.template.length / 3) };
    }
    gl.bindVertexArray(null); gl.disable(gl.BLEND);
    out.union = union.reduce((a, b) => a + b, 0);
    return out;
  };
};
</script>
"""


def colour_only(desc: dict, colour: str = "vec4(0.5, 0.5, 0.5, 0.35)") -> dict:
    """``desc`` with every fragment shader's main() writing a constant colour (and no depth)."""
    out = json.loads(json.dumps(desc))
    for layer in out["layers"]:
        head = layer["frag"][: layer["frag"].rindex("void main()")]
        layer["frag"] = head + f"void main() {{\n    gl_FragColor = {colour};\n}}\n"
    return out


def run(codes: dict, rounds: int, shots: pathlib.Path | None) -> tuple[dict, dict]:
    """({code key: {pass: [ms per frame]}}, {code key: coverage}); codes = {key: {"desc": ...,
    "size": [w, h], "depth": func, "blend": bool, "count": bool -- only counted, not timed}}."""
    from browser_latency import find_chromium
    from browser_setup import CHROMIUM_FLAGS
    from playwright.sync_api import sync_playwright

    groups: dict = {}
    for key, c in codes.items():  # one page per canvas size
        groups.setdefault(tuple(c["size"]), {})[key] = c
    times = {key: {} for key, c in codes.items() if not c.get("count")}
    covered = {}
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=find_chromium(), headless=True, args=CHROMIUM_FLAGS)
        try:
            pages = []
            for size, group in groups.items():
                page = browser.new_page(viewport={"width": size[0] + 20, "height": size[1] + 20})
                page.set_content(PAGE)
                payload = {key: {**{k: c["desc"][k] for k in ("layers", "expand", "rows", "stride")},
                                 "matrices": matrices(c["desc"]["camera"])} for key, c in group.items()}
                page.evaluate("([codes, size]) => setup(codes, size)", [payload, list(size)])
                pages.append((page, group))
            for page, group in pages:
                for key in [key for key, c in group.items() if c.get("count")]:
                    covered[key] = page.evaluate("key => coverage(key)", key)
            for k in range(-1, rounds):  # round -1 warms the shaders up (compiled at first draw)
                for page, group in pages:
                    keys = [key for key, c in group.items() if not c.get("count")]
                    for key in keys[k % len(keys):] + keys[: k % len(keys)]:
                        t = page.evaluate("([key, f, b]) => frame(key, f, b)",
                                          [key, group[key].get("depth", "lequal"), group[key].get("blend", True)])
                        if k >= 0:
                            t["sum"] = sum(ms for name, ms in t.items() if name != "unpack")
                            for name, ms in t.items():
                                times[key].setdefault(name, []).append(ms)
            if shots is not None:
                for page, group in pages:
                    for key, c in ((key, c) for key, c in group.items() if not c.get("count")):
                        page.evaluate("([key, f, b]) => frame(key, f, b)",
                                      [key, c.get("depth", "lequal"), c.get("blend", True)])
                        png = page.evaluate("() => picture()").split(",", 1)[1]
                        (shots / f"{key}.png").write_bytes(base64.b64decode(png))
        finally:
            browser.close()
    return times, covered


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--case", default="great icosahedral 120-cell", help="a polychoron's name")
    ap.add_argument("--rev", default="WORK", help="the code measured, comma-separated: git revisions and WORK "
                                                  "(the working tree); every frame draws each (default WORK)")
    ap.add_argument("--rounds", type=int, default=20, help="frames per code (default 20)")
    ap.add_argument("--diagnose", action="store_true",
                    help="also colour only, depth never, half size, opaque faces (of the first code)")
    ap.add_argument("--screenshots", default=None, help="save each code's picture here and compare with the first")
    ap.add_argument("--keys", default=None,
                    help="keys pressed after reset (default: browser_draw.py's SHOT_KEYS; '' for the reset view)")
    ap.add_argument("--describe", default=None, help=argparse.SUPPRESS)  # the subprocess of a --rev
    args = ap.parse_args(argv)
    if args.describe:
        print(json.dumps(describe(args.describe, args.keys)))
        return 0
    revs = [r.strip() for r in args.rev.split(",") if r.strip()]
    if not revs or len(set(revs)) != len(revs):
        ap.error("--rev: distinct revisions or WORK, comma-separated")
    from browser_draw import working_tree_description

    tmp = pathlib.Path(tempfile.mkdtemp(prefix="rot4d-shader-"))
    load_before = os.getloadavg()
    try:
        codes, labels = {}, {}
        for rev in revs:
            if rev == "WORK":
                desc, labels[rev] = describe(args.case, args.keys), working_tree_description()
            else:
                desc, labels[rev] = describe_revision(rev, args.case, args.keys, tmp)
            codes[rev] = {"desc": desc, "size": desc["size"]}
        if args.diagnose:
            first = codes[revs[0]]["desc"]
            codes["colour only"] = {"desc": colour_only(first), "size": first["size"]}
            codes["depth never"] = {"desc": first, "size": first["size"], "depth": "never"}
            codes["half size"] = {"desc": first, "size": [first["size"][0] // 2, first["size"][1] // 2]}
            codes["opaque faces"] = {"desc": first, "size": first["size"], "blend": False}
            codes["count"] = {"desc": colour_only(first, "vec4(1.0 / 255.0)"), "size": first["size"], "count": True}
        shots = pathlib.Path(args.screenshots) if args.screenshots else None
        if shots is not None:
            shots.mkdir(parents=True, exist_ok=True)
        times, covered = run(codes, args.rounds, shots)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    passes = ["clear", *LAYERS]
    counts = codes[revs[0]]["desc"]["counts"]
    state = "rest state" if args.keys is None else f"reset, then {args.keys!r}"
    print(f"{args.case}, {state}: {counts[0]} balls, {counts[1]} bars, {counts[2]} faces\n")
    print("| code | " + " | ".join(passes) + " | sum | unpack |")
    print("|---|" + "---:|" * (len(passes) + 2))
    for key, t in times.items():
        meds = [statistics.median(t[p]) if t.get(p) else math.nan for p in passes]
        print(f"| {key} | " + " | ".join(f"{m:.1f}" for m in meds) + f" | {sum(meds):.1f} | "
              f"{statistics.median(t['unpack']):.1f} |")
    if "count" in covered:
        c = covered["count"]
        w, h = codes[revs[0]]["size"]
        print(f"\nPixels each layer covers in {revs[0]}'s picture (its fragment shader runs on each), "
              f"{w} x {h} canvas, {c['union']:,} covered by any layer: "
              + "; ".join(f"{name} {c[name]['covered']:,} ({c[name]['covered'] / c['union']:.1f} deep on average, "
                          f"{c[name]['deepest']} at most; {c[name]['drawn']:,} drawn)" for name in LAYERS))
    if len(revs) > 1:  # each frame drew every code: the ratio frame by frame is steadier than the medians'
        print(f"\nFrame by frame, against {revs[0]} (median of the ratios): "
              + "; ".join(f"{r}: " + ", ".join(f"{p} {statistics.median(np.divide(times[r][p], times[revs[0]][p])):.2f}"
                                                for p in ("balls", "bars", "faces", "sum", "unpack"))
                         for r in revs[1:]))
    if shots is not None and len(revs) > 1:
        import matplotlib.image

        ref = matplotlib.image.imread(str(shots / f"{revs[0]}.png"))[..., :3] * 255.0
        print(f"\nPictures in {shots}, against {revs[0]}'s: pixels differing by more than 2/255 and 8/255 in "
              "some channel")
        for rev in revs[1:]:
            d = np.abs(matplotlib.image.imread(str(shots / f"{rev}.png"))[..., :3] * 255.0 - ref).max(axis=-1)
            print(f"- {rev}: {100 * np.mean(d > 2):.2f} %, {100 * np.mean(d > 8):.2f} % "
                  f"(largest difference {d.max():.0f}/255)")
    version = subprocess.run([__import__("browser_latency").find_chromium(), "--version"], capture_output=True,
                             text=True).stdout.strip()
    print(f"\nMedians of {args.rounds} frames, ms per pass, synchronised by 1-pixel reads; every frame draws each "
          f"code in turn. {os.cpu_count()} CPUs, load {' '.join(f'{x:.1f}' for x in load_before)} before, "
          f"{' '.join(f'{x:.1f}' for x in os.getloadavg())} after; {version.split(' built')[0]}, headless, "
          f"SwiftShader; code: {'; '.join(f'{r} = {labels[r]}' for r in revs)}.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
