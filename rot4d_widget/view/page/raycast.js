// What the page's field shader (glsl/field.frag) needs to draw one state (issue 36): for each cut
// (one, or a stack's several at their offsets), a box to cast rays through and the affine map
// from a scene point of that box to the data's 4-D index coordinates; and the outline bars of
// the box's cut.  Plain arrays from the state and the field's config (rot4d_widget.view.fieldview:
// `field_config`), nothing of three.js: Node runs it (tests/page/test_page_field.py).
//
// A cut k lies at w = c0 + dc_k (data w), d_k = (c0 + dc_k - origin) / per_unit slice units from
// the box's centre along the turned w axis, and is drawn at X = scale (centre_k + sigma_k p) for a
// slice point p (a stack places its cuts; a single field: centre 0, sigma 1).  Its 4-D point is
// q = M^T (p, d_k) (slice units about the box's centre) and its index coordinates
// g_j = (q_j + hw_j) (n_j - 1) / (2 hw_j), n the copy's nodes along x, y, z, w.  The box of the
// rays is the kernel's grid box: the grid `_sample_grid` (rot4d_widget/sources/field_slicing.py)
// lays over the box's cut (`res` nodes along its longest side, one spacing of padding), so the
// page samples where the kernel's picture does.

import { sliceData } from "./slicer.js";
import { CUBE } from "./uploads.js";

// The kernel's sampling grid over a cut whose points are `pts` (3n, slice units): {origin (3),
// spacing, nodes (3)} as _sample_grid makes it, or null when the cut is not solid.
export function kernelGrid(pts, res) {
  const n = pts.length / 3;
  if (n < 4) return null;
  const lo = [Infinity, Infinity, Infinity];
  const hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < n; i++) {
    for (let a = 0; a < 3; a++) {
      lo[a] = Math.min(lo[a], pts[3 * i + a]);
      hi[a] = Math.max(hi[a], pts[3 * i + a]);
    }
  }
  const side = [0, 1, 2].map((a) => hi[a] - lo[a]);
  const L = Math.max(...side);
  if (!(L > 0)) return null;
  const d = L / (res - 1);
  const nodes = side.map((s) => Math.max(Math.ceil(s / d - 1e-9) + 1, 2));
  const origin = [0, 1, 2].map((a) => (lo[a] + hi[a]) / 2 - ((nodes[a] - 1) * d) / 2 - d);
  return { origin, spacing: d, nodes: nodes.map((k) => k + 2) };
}

// Nodes along the longest side of each cut's grid: the field's resolution (coarse while keys are
// held), a stack's shared out among its cuts (rot4d_widget/view/cuts.py grid_cut).
export function gridResolution(cfg, held) {
  const res = held ? cfg.coarse_resolution : cfg.resolution;
  const n = cfg.slices.length;
  if (n <= 1) return res;
  return Math.max(8, Math.min(res, Math.round(Math.pow(cfg.stack_nodes / n, 1 / 3))));
}

// The boxes of a state ({matrix: 16 numbers row by row, c0}) of the field in `cfg`, its box's
// polytope `box` (decodePolytope of the box's tables) and its copy's node counts `shape`
// [nx, ny, nz, nw]:
//   {count, arrays: {position, a_g0, a_gx, a_gy, a_gz, a_lo, a_span, a_cell} (Float32Array, 36 a
//    box), outline: {points (Float64Array 3n, source units as placed), segments (Int32Array 2m)},
//    spacing: [each box's grid spacing, scene units]}
export function fieldBoxes(cfg, box, shape, state, { held = false } = {}) {
  const m = state.matrix;
  const s = cfg.scale;
  const res = gridResolution(cfg, held);
  const a = [0, 1, 2, 3].map((j) => (shape[j] - 1) / (2 * cfg.hw[j]));
  const boxes = [];
  const outPts = [];
  const outSegs = [];
  let base = 0;
  cfg.slices.forEach((sl, k) => {
    const dk = (state.c0 + sl.dc - cfg.origin) / cfg.per_unit;
    const cut = sliceData(box, m, dk);
    const grid = cut.slice.dim === 3 ? kernelGrid(cut.points, res) : null;
    const sigma = sl.scale;
    const c = sl.centre;
    const placed = cfg.slices.length > 1;
    const np = cut.points.length / 3;
    for (let i = 0; i < np; i++) {
      for (let j = 0; j < 3; j++) outPts.push(placed ? cut.points[3 * i + j] * sigma + c[j] : cut.points[3 * i + j]);
    }
    for (const e of cut.segments) outSegs.push(e + base);
    base += np;
    if (!grid) return;
    const ss = s * sigma;
    const g0 = [], gx = [], gy = [], gz = [];
    for (let j = 0; j < 4; j++) {
      const mj = [m[j], m[4 + j], m[8 + j], m[12 + j]];  // column j of M: row j of M^T
      g0.push(a[j] * (cfg.hw[j] + mj[3] * dk - (mj[0] * c[0] + mj[1] * c[1] + mj[2] * c[2]) / sigma));
      gx.push((a[j] * mj[0]) / ss);
      gy.push((a[j] * mj[1]) / ss);
      gz.push((a[j] * mj[2]) / ss);
    }
    const lo = [0, 1, 2].map((j) => s * (c[j] + sigma * grid.origin[j]));
    const span = grid.nodes.map((n) => ss * grid.spacing * (n - 1));
    boxes.push({ g0, gx, gy, gz, lo, span, cell: ss * grid.spacing, index: k });
  });
  const V = CUBE.length / 3;
  const arrays = {
    position: new Float32Array(boxes.length * V * 3), a_g0: new Float32Array(boxes.length * V * 4),
    a_gx: new Float32Array(boxes.length * V * 4), a_gy: new Float32Array(boxes.length * V * 4),
    a_gz: new Float32Array(boxes.length * V * 4), a_lo: new Float32Array(boxes.length * V * 3),
    a_span: new Float32Array(boxes.length * V * 3), a_cell: new Float32Array(boxes.length * V * 2),
  };
  boxes.forEach((b, i) => {
    for (let v = 0; v < V; v++) {
      const o = i * V + v;
      for (let j = 0; j < 3; j++) {
        arrays.position[3 * o + j] = b.lo[j] + CUBE[3 * v + j] * b.span[j];
        arrays.a_lo[3 * o + j] = b.lo[j];
        arrays.a_span[3 * o + j] = b.span[j];
      }
      for (let j = 0; j < 4; j++) {
        arrays.a_g0[4 * o + j] = b.g0[j];
        arrays.a_gx[4 * o + j] = b.gx[j];
        arrays.a_gy[4 * o + j] = b.gy[j];
        arrays.a_gz[4 * o + j] = b.gz[j];
      }
      arrays.a_cell[2 * o] = b.cell;
      arrays.a_cell[2 * o + 1] = b.index;
    }
  });
  return { count: boxes.length, arrays, spacing: boxes.map((b) => b.cell),
           outline: { points: Float64Array.from(outPts), segments: Int32Array.from(outSegs) } };
}

// The index coordinates of scene point x in box i (for tests: what the shader computes).
export function indexAt(boxes, i, x) {
  const o = i * (CUBE.length / 3) * 4;
  const A = boxes.arrays;
  return [0, 1, 2, 3].map((j) => A.a_g0[o + j] + A.a_gx[o + j] * x[0] + A.a_gy[o + j] * x[1] + A.a_gz[o + j] * x[2]);
}
