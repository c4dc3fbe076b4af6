"""What the page's WebGL is, measured through pythreejs's own Renderer (issue 36's probe), in
JupyterLab 4 and Notebook 7.

pythreejs 2.4.2 asks for a WebGL2 context when the browser has one (``Renderer(webgl_version=2)``,
the default; it falls back to WebGL1 otherwise) and bundles three.js r97, whose ShaderMaterial
compiles as GLSL ES 3.00 under WebGL2 (it prefixes ``#version 300 es`` and maps
``texture2D``/``gl_FragColor``).  The probe (``webgl_probe.js``) reports the context, its limits
and whether a ``THREE.DataTexture3D`` in unsized luminance, luminance-alpha, RGBA and red
formats uploads, filters linearly and samples through a ``sampler3D`` uniform: the value read
back, recombined from two byte channels into a 16-bit code, against exact trilinear
interpolation.  The figures are written to test-artifacts/webgl-probe-<front end>.json (quoted in
docs/design.md).
"""

from __future__ import annotations

import json
import shutil

import pytest
from browser_setup import ROOT
from jupyter_page import JupyterPage, write_notebook

pytestmark = pytest.mark.browser

CELL = '''\
import pathlib, numpy as np, anywidget, traitlets, pythreejs as p3

VERT = """varying vec2 v_uv;
void main() { v_uv = uv; gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0); }"""
FRAG = """precision highp sampler3D;
uniform sampler3D u_tex;
uniform float u_mode;
varying vec2 v_uv;
void main() {
  float i = floor(v_uv.x * 64.0);
  float f = (i + 0.5) / 64.0;
  vec3 fr = vec3(f, fract(f * 3.7), fract(f * 5.3));
  vec4 t = texture(u_tex, (0.5 + fr) / 2.0);
  float v = u_mode < 0.5 ? t.r * 255.0 * 256.0 + t.a * 255.0 : t.r * 255.0;
  float hi = floor(v / 256.0);
  float lo = floor(v - hi * 256.0);
  gl_FragColor = vec4(hi / 255.0, lo / 255.0, v - hi * 256.0 - lo, 1.0);
}"""

class Probe(anywidget.AnyWidget):
    _esm = pathlib.Path("webgl_probe.js").read_text()
    scene_id = traitlets.Unicode().tag(sync=True)
    texture_id = traitlets.Unicode().tag(sync=True)
    mesh_id = traitlets.Unicode().tag(sync=True)
    result = traitlets.Unicode("").tag(sync=True)

material = p3.ShaderMaterial(vertexShader=VERT, fragmentShader=FRAG,
                             uniforms={"u_tex": {"value": None}, "u_mode": {"value": 0.0}})
mesh = p3.Mesh(p3.PlaneBufferGeometry(2, 2), material)
scene = p3.Scene(children=[mesh])
camera = p3.OrthographicCamera(-1, 1, 1, -1, -10, 10, position=[0, 0, 1])
renderer = p3.Renderer(camera=camera, scene=scene, width=64, height=8)
tex = p3.DataTexture3D(data=np.zeros((2, 2, 2), dtype=np.uint8), format="LuminanceFormat", type="UnsignedByteType")
probe = Probe(scene_id=scene.model_id, texture_id=tex.model_id, mesh_id=mesh.model_id)
display(renderer, probe)
'''


def test_webgl_probe(jupyter_server, page, artifacts):
    shutil.copy(ROOT / "tests" / "browser" / "webgl_probe.js", jupyter_server.root / "webgl_probe.js")
    write_notebook(jupyter_server.root / "webgl_probe.ipynb", [CELL])
    jp = JupyterPage(page, jupyter_server, "webgl_probe.ipynb").open()
    jp.run_all()
    got = jp.wait_for(lambda: jp.kernel("print(probe.result)").strip(), timeout=60)
    assert got, f"the probe reported nothing; console: {page.console_messages[-10:]}"
    out = json.loads(got)
    (artifacts / f"webgl-probe-{jupyter_server.kind}.json").write_text(json.dumps(out, indent=1))
    print(json.dumps(out, indent=1))
    # what the page's field needs (docs/design.md, "The field on the GPU")
    assert out["context"] == "webgl2" and out["isWebGL2"], out
    assert out["max_3d_texture_size"] >= 256 and out["max_texture_size"] >= 4096, out
    for kind in ("luminanceAlpha", "luminance"):
        case = out["cases"][kind]
        assert case["gl_error"] == 0 and case["drew"], (kind, case)
        # linear filtering of the byte channels, recombined: within 1/256 of the codes' spread per
        # axis (the hardware's sub-texel weight precision), whatever the format
        assert case["worst_code_error"] <= case["of_codes"] / 128, (kind, case)
    assert out["big"]["gl_error"] == 0, out["big"]
