// The page's own picture of a field (issue 36): while it is ahead of the kernel -- keys held,
// steps of its own beyond the kernel's state, or the kernel's picture of that state not arrived
// -- and holds the field's copy (field.js), the page draws the cut of its predicted state itself:
// the field layer's mesh ("field", glsl/field.frag) casts rays through the copy in every rendering,
// and the layers draw the outline of the box's cut (slicer.js, rows.js).  At rest, with the
// kernel's picture of the same state arrived, the kernel's surface or volume is drawn again.
//
// The page's pictures are quick ones, sampled as the kernel's held picture was (issue 21: rays every
// 2 spacings of the coarse grid, half the pixel ratio; surfaces marched every coarse spacing): the
// last one stays up after a release until the kernel's full-resolution picture replaces it (a
// picture at the kernel's own sampling at rest takes the software renderer half a second and
// more).  Drawn at rest by the test hook (`forceOwnField`), the page's picture is at that sampling.

import { fieldArrived, fieldTextures } from "./field.js";
import { fieldBoxes } from "./raycast.js";
import { sliceRows } from "./rows.js";
import { likeTexture, nextSurfaceVersion } from "./uploads.js";

export const MODES = { volume: 0, mip: 1, sections: 2, surface: 3 };
// The shader's most levels (field.frag MAX_LEVELS) and boxes with colours of their own (u_box_rgb).
export const MAX_LEVELS = 8;
export const MAX_BOXES = 64;
// Scene units of the largest distance the depth read-back encodes (tests).
export const DEPTH_SCALE = 64;

const forced = new WeakMap();  // model -> true: draw the page's own picture at rest too (tests)

export function forceOwnField(model, on) {
  forced.set(model, !!on);
}

// The page's own picture is a quick one (half the pixel ratio, the held sampling): all but the tests'.
export function quickField(model) {
  return !forced.get(model);
}

// The page's view settings of its predicted state (the kernel's, stepped by the page's keys).
function viewOf(prediction) {
  return prediction && prediction.state ? prediction.state.view : null;
}

// The page draws its own picture of the field now (see the module's comment).
export function fieldDrawsOwn(model, prediction, seq) {
  const h = fieldArrived(model);
  const cfg = model.get("field_config") || {};
  const view = viewOf(prediction);
  if (!h || !view || !Array.isArray(cfg.slices) || !cfg.slices.length || !(view.rendering in MODES)) return false;
  if (cfg.slices.length > MAX_BOXES || (view.rendering === "surface" && view.levels.length > MAX_LEVELS)) return false;
  if (prediction.held.length || prediction.pending || forced.get(model)) return true;
  const ks = model.get("kernel_state") || {};
  return ks.picture === "pending" || (Number.isInteger(ks.picture) && !(seq >= ks.picture));
}

// The colour of x in [0, 1] in the table `lut` (1024 bytes: 256 RGBA), as matplotlib looks it up.
export function lutRgb(lut, x) {
  const i = Math.min(Math.floor(Math.min(Math.max(x, 0), 1) * 256), 255);
  return [lut[4 * i] / 255, lut[4 * i + 1] / 255, lut[4 * i + 2] / 255];
}

// Each level's colour: the kernel's (by rank: they do not change as the page steps the levels) or,
// with colour limits, the table's colour at the level's place in them.
// A stack coloured by w has no level colours (its boxes carry them, `box_rgb`): black, unused.
export function levelColours(cfg, levels) {
  if (cfg.single_rgb) return levels.map(() => cfg.single_rgb);
  if (!cfg.level_by_value) {
    const table = cfg.level_rgb || [];
    return levels.map((_, i) => table[i] || table[table.length - 1] || [0, 0, 0]);
  }
  const [lo, hi] = cfg.clim;
  return levels.map((v) => lutRgb(cfg.lut, (v - lo) / (hi - lo)));
}

// The kernel's ray step (volume_layer.volume_message): `base` spacings, longer on a long ray.
function rayStep(base, nodes, maxSteps) {
  const longest = Math.hypot(...nodes.map((n) => n - 1));
  return Math.max(base, longest / (maxSteps - 8));
}

// One view's field mesh: its geometry, textures and uniforms, set for the state drawn.
export class FieldPicture {
  // `mesh`: the "field" mesh's model; `T3`: THREE.DataTexture3D; `lutLike`: a DataTexture whose
  // class and settings the colour table's texture copies.
  constructor(mesh, T3, lutLike) {
    this.mesh = mesh;
    this.T3 = T3;
    this.lutLike = lutLike;
    this.lut = null;
    this.lutOf = null;
    this.key = null;
    this.rows = null;
    this.matrices = null;
    // tests: 1 writes each pixel's first surface hit's distance from the eye (field.frag u_output)
    this.output = 0;
  }

  // The depth read-back of tests (field.frag's u_output 1, t / DEPTH_SCALE in 24 bits) on or off.
  setOutput(on) {
    this.output = on ? 1 : 0;
    this.key = null;
  }

  hide() {
    const obj = this.mesh.obj;
    if (obj) obj.visible = false;
    this.key = null;
  }

  // Draw `prediction`'s state; returns the outline rows ({rows, stride, counts, version}) the layers
  // draw with it, or null when nothing can be drawn.
  draw(model, prediction) {
    const obj = this.mesh.obj;
    const h = fieldArrived(model);
    const cfg = model.get("field_config") || {};
    if (!obj || !h || !obj.material || !obj.geometry) return null;
    const held = quickField(model);
    const key = `${prediction.version}|${held}`;
    if (this.key === key && this.cfg === cfg && this.h === h && obj.visible) return this.rows;
    const view = viewOf(prediction);
    const boxes = fieldBoxes(cfg, h.box, h.copy.shape, prediction.state, { held });
    this.upload(obj, boxes);
    this.uniforms(obj, model, h, cfg, view, boxes, held);
    const outline = { points: boxes.outline.points, segments: boxes.outline.segments, triangles: new Int32Array(0),
                      groups: new Int32Array(0), showPoints: false, convex: true };
    const { rows, counts } = sliceRows(outline, { scale: cfg.scale, palette: [] });
    this.rows = { rows, stride: 20, counts, version: prediction.version };
    this.key = key;
    this.cfg = cfg;
    this.h = h;
    obj.visible = boxes.count > 0;
    return this.rows;
  }

  upload(obj, boxes) {
    const g = obj.geometry;
    for (const [name, array] of Object.entries(boxes.arrays)) {
      const attr = g.attributes[name];
      if (!attr) continue;
      attr.setArray(array);
      attr.version = nextSurfaceVersion();
    }
    g.setDrawRange(0, boxes.arrays.position.length / 3);
  }

  uniforms(obj, model, h, cfg, view, boxes, held) {
    const m = obj.material;
    const u = m.uniforms;
    const tex = fieldTextures(h, this.T3);
    if (!this.lut || this.lutOf !== cfg.lut) {
      if (!this.lut) this.lut = likeTexture(this.lutLike);
      this.lut.image = { data: Uint8Array.from(cfg.lut), width: 256, height: 1 };
      this.lut.needsUpdate = true;
      this.lutOf = cfg.lut;
    }
    let relink = false;
    const put = (name, value) => {
      if (!u[name]) {
        u[name] = { value };
        relink = true;
      } else u[name].value = value;
    };
    if (!this.matrices) {
      const M4 = obj.matrix.constructor, M3 = obj.normalMatrix.constructor;
      this.matrices = { view: new M4(), normal: new M3() };
    }
    if (obj.onBeforeRender !== this.onBefore) {
      const mats = this.matrices;
      // the mesh's model-view matrix of the frame being drawn (three.js computes its own just after)
      this.onBefore = (_renderer, _scene, camera) => {
        mats.view.multiplyMatrices(camera.matrixWorldInverse, obj.matrixWorld);
        mats.normal.getNormalMatrix(mats.view);
      };
      obj.onBeforeRender = this.onBefore;
    }
    const c = h.copy;
    const [lo, hi] = c.range;
    const width = hi > lo ? hi - lo : 1;
    const norm = (v) => (v - lo) / width;
    const clim = cfg.clim || [lo, hi];
    const levels = view.levels.slice(0, MAX_LEVELS);
    const rgb = levelColours(cfg, levels);
    const levelArr = new Float32Array(MAX_LEVELS);
    const rgbArr = new Float32Array(3 * MAX_LEVELS);
    levels.forEach((v, i) => {
      levelArr[i] = norm(v);
      rgbArr.set(rgb[i], 3 * i);
    });
    const boxRgb = new Float32Array(3 * MAX_BOXES);
    (cfg.box_rgb || []).slice(0, MAX_BOXES).forEach((c3, i) => boxRgb.set(c3, 3 * i));
    const cell = boxes.spacing.length ? Math.min(...boxes.spacing) : 1;
    put("u_data", tex.data);
    put("u_mask", tex.mask);
    put("u_lut", this.lut);
    put("u_view", this.matrices.view);
    put("u_normal_view", this.matrices.normal);
    put("u_levels", levelArr);
    put("u_level_rgb", rgbArr);
    put("u_box_rgb", boxRgb);
    put("u_shape", c.shape.slice());
    put("u_tiles", c.tiles.slice());
    put("u_size", c.size.slice());
    put("u_masked", c.masked ? 1 : 0);
    put("u_blocks", tex.blocks);
    put("u_block", c.block);
    put("u_block_shape", c.blockShape.slice());
    put("u_block_tiles", c.blockTiles.slice());
    put("u_mode", MODES[view.rendering]);
    if (!m.defines) m.defines = {};
    if (m.defines.FIELD_MODE !== MODES[view.rendering]) {  // the rendering's own program (field.frag)
      m.defines.FIELD_MODE = MODES[view.rendering];
      relink = true;
    }
    put("u_clim", [norm(clim[0]), norm(clim[1])]);
    put("u_sections", view.sections.slice());
    put("u_density", cfg.density);
    const nodes = [cfg.resolution, cfg.resolution, cfg.resolution];
    put("u_step", held ? cfg.held_step : rayStep(cfg.step, nodes, cfg.max_steps));
    put("u_march", (held ? cfg.held_march : cfg.march) * cell);
    put("u_sign", cfg.inside === "below" ? -1 : 1);
    put("u_caps", cfg.caps ? 1 : 0);
    const translucent = view.rendering === "surface" && (levels.length > 1 || cfg.slices.length > 1);
    put("u_opacity", translucent ? cfg.surface_opacity : 1);
    put("u_nlevels", levels.length);
    put("u_box_colours", cfg.box_rgb ? 1 : 0);
    put("u_output", this.output);
    put("u_depth_scale", DEPTH_SCALE);
    m.depthWrite = view.rendering === "surface" && !translucent;
    if (relink) m.needsUpdate = true;
    m.uniformsNeedUpdate = true;
  }
}
