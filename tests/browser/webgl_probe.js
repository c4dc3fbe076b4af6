// The WebGL probe (tests/browser/test_webgl_probe_browser.py): an anywidget module that asks
// pythreejs's own Renderer what it runs on, and whether three.js r97 (as pythreejs bundles it)
// uploads a DataTexture3D in the formats the page's field needs, filters it linearly and samples
// it through a sampler3D uniform of a ShaderMaterial.
//
// The kernel names a pythreejs Scene (a full-view quad with a ShaderMaterial that samples
// `u_tex`), a DataTexture3D model (for its class: THREE.DataTexture3D) and the quad's mesh.  For
// each case a texture of the companion's own is set as `u_tex`, the scene rendered, and row 0 of
// the canvas read back in `afterRender` (the drawing buffer holds the picture then).  Column i of
// the quad samples the texture at texel-space fraction frac(i) between the 2 x 2 x 2 texels'
// centres; the shader writes the value recombined from the channels, in 16-bit codes, as
// (code >> 8, code & 255, fraction) and the probe compares it with exact trilinear interpolation
// in doubles.  Results go back in the `result` trait (JSON).

const COLUMNS = 64;

function frac(i) {
  const f = (i + 0.5) / COLUMNS;
  return [f, (f * 3.7) % 1, (f * 5.3) % 1];
}

// exact trilinear interpolation of codes[x + 2 (y + 2 z)]
function trilinear(codes, [fx, fy, fz]) {
  let v = 0;
  for (let z = 0; z < 2; z++) {
    for (let y = 0; y < 2; y++) {
      for (let x = 0; x < 2; x++) {
        const w = (x ? fx : 1 - fx) * (y ? fy : 1 - fy) * (z ? fz : 1 - fz);
        v += w * codes[x + 2 * (y + 2 * z)];
      }
    }
  }
  return v;
}

// three.js r97 constants
const FORMAT = { luminance: 1024, luminanceAlpha: 1025, rgba: 1023, red: 1028 };
const MODE = { luminance: 1, luminanceAlpha: 0, rgba: 0, red: 1 };
const CHANNELS = { luminance: 1, luminanceAlpha: 2, rgba: 4, red: 1 };

function textureData(kind, codes) {
  const n = CHANNELS[kind];
  const data = new Uint8Array(8 * n);
  for (let i = 0; i < 8; i++) {
    const c = codes[i];
    if (kind === "luminanceAlpha") {
      data[2 * i] = c >> 8;
      data[2 * i + 1] = c & 255;
    } else if (kind === "rgba") {  // hi in r, lo in a (as luminance-alpha reads: r = L, a = A)
      data[4 * i] = c >> 8;
      data[4 * i + 3] = c & 255;
    } else {
      data[i] = c;
    }
  }
  return data;
}

async function render({ model, el }) {
  el.textContent = "probe";
  const manager = model.widget_manager;
  const [scene, tex3d, mesh] = await Promise.all(
    ["scene_id", "texture_id", "mesh_id"].map((k) => manager.get_model(model.get(k).replace(/^IPY_MODEL_/, ""))));
  const T3 = tex3d.obj.constructor;
  const material = mesh.obj.material;
  const out = { cases: {} };
  const rng = (() => {
    let s = 12345;
    return () => (s = (s * 1103515245 + 12345) % 2147483648) / 2147483648;
  })();
  const kinds = ["luminanceAlpha", "luminance", "rgba", "red"];
  let current = -1;
  let codes = null;
  const next = () => {
    current += 1;
    if (current >= kinds.length) return false;
    const kind = kinds[current];
    const max = kind === "luminance" || kind === "red" ? 255 : 65535;
    codes = Array.from({ length: 8 }, () => Math.floor(rng() * (max + 1)));
    const t = new T3(textureData(kind, codes), 2, 2, 2);
    t.format = FORMAT[kind];
    t.type = 1009;  // UnsignedByteType
    t.magFilter = t.minFilter = 1006;  // LinearFilter
    t.unpackAlignment = 1;
    t.needsUpdate = true;
    material.uniforms.u_tex = { value: t };
    material.uniforms.u_mode = { value: MODE[kind] };
    material.needsUpdate = true;
    return true;
  };
  let phase = "context";
  const after = (_scene, renderer) => {
    const gl = renderer.context;
    if (phase === "context") {
      const dbg = gl.getExtension("WEBGL_debug_renderer_info");
      const two = typeof WebGL2RenderingContext !== "undefined" && gl instanceof WebGL2RenderingContext;
      Object.assign(out, {
        isWebGL2: renderer.capabilities.isWebGL2,
        context: two ? "webgl2" : "webgl",
        version: gl.getParameter(gl.VERSION),
        glsl: gl.getParameter(gl.SHADING_LANGUAGE_VERSION),
        renderer: dbg ? gl.getParameter(dbg.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER),
        vendor: dbg ? gl.getParameter(dbg.UNMASKED_VENDOR_WEBGL) : gl.getParameter(gl.VENDOR),
        max_texture_size: gl.getParameter(gl.MAX_TEXTURE_SIZE),
        max_3d_texture_size: two ? gl.getParameter(gl.MAX_3D_TEXTURE_SIZE) : null,
        max_array_texture_layers: two ? gl.getParameter(gl.MAX_ARRAY_TEXTURE_LAYERS) : null,
        max_texture_image_units: gl.getParameter(gl.MAX_TEXTURE_IMAGE_UNITS),
        max_fragment_uniform_vectors: gl.getParameter(gl.MAX_FRAGMENT_UNIFORM_VECTORS),
        user_agent: navigator.userAgent,
      });
      if (!two) {
        finish();
        return;
      }
      phase = "cases";
      if (next()) setTimeout(() => scene.trigger("rerender", scene, {}), 0);
      return;
    }
    if (phase !== "cases") return;
    const kind = kinds[current];
    const err = gl.getError();
    const px = new Uint8Array(COLUMNS * 4);
    gl.readPixels(0, 0, COLUMNS, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
    let worst = 0;
    const samples = [];
    for (let i = 0; i < COLUMNS; i++) {
      const got = px[4 * i] * 256 + px[4 * i + 1] + px[4 * i + 2] / 255;
      const want = trilinear(codes, frac(i));
      worst = Math.max(worst, Math.abs(got - want));
      if (i < 4) samples.push([got, want]);
    }
    const max = kind === "luminance" || kind === "red" ? 255 : 65535;
    out.cases[kind] = { gl_error: err, worst_code_error: worst, of_codes: max, samples,
                        drew: px.some((v, i) => i % 4 !== 3 && v !== 0) };
    if (next()) setTimeout(() => scene.trigger("rerender", scene, {}), 0);
    else finish();
  };
  const finish = () => {
    phase = "done";
    scene.off("afterRender", after);
    bigUpload();
  };
  // a 256^3 luminance-alpha texture (32 MiB, the WebGL2 minimum a side): uploaded and drawn?
  const bigUpload = () => {
    if (!out.isWebGL2) return report();
    const n = 256;
    const data = new Uint8Array(n * n * n * 2);
    for (let i = 0; i < data.length; i += 2) data[i] = (i >> 9) & 255;
    const t = new T3(data, n, n, n);
    t.format = FORMAT.luminanceAlpha;
    t.type = 1009;
    t.magFilter = t.minFilter = 1006;
    t.unpackAlignment = 1;
    t.needsUpdate = true;
    material.uniforms.u_tex = { value: t };
    material.uniforms.u_mode = { value: 0 };
    material.needsUpdate = true;
    const t0 = performance.now();
    const once = (_s, renderer) => {
      scene.off("afterRender", once);
      const gl = renderer.context;
      const px = new Uint8Array(4);
      gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
      out.big = { side: n, bytes: data.length, gl_error: gl.getError(), upload_and_draw_ms: performance.now() - t0,
                  pixel: Array.from(px) };
      report();
    };
    scene.on("afterRender", once);
    scene.trigger("rerender", scene, {});
  };
  const report = () => {
    model.set("result", JSON.stringify(out));
    model.save_changes();
  };
  scene.on("afterRender", after);
  scene.trigger("rerender", scene, {});
}

export default { render };
