// Parallel slices of a polytope cut in the page (issue 34): what
// rot4d_widget.sources.tomography.StackSource.slice returns for the page's state, array for array,
// so that rows.js builds the kernel's rows of a stack from it.
//
// The stack comes as the kernel computed it (view/pagecut.stack_config, in the companion's
// draw_config): each cut's offset from c0, the layout's centres and scales, whether triangles are
// grouped by slice.  The page never recomputes those; per state it only adds its c0 to each
// offset (float(c0) + offsets, as StackSource.cuts_at does) and places each slice's points with
// the kernel's two roundings (p * scale_k, then + centre_k).  Each cut is the single slicer's
// (slicer.js): the kernel's batched slice_polytope gives every level the single slice's arrays
// (tests/sources/test_tomography.py; only the volumes may differ in the last bits, and rows carry none).

import { sliceData } from "./slicer.js";
import { pairwiseSum } from "./numpyorder.js";

// The stack of draw_config (`stack_config`) checked, as typed arrays: {n, offsets, centres (3n),
// scales, byW}; throws naming what does not fit.
export function decodeStack(cfg) {
  const list = (name, length) => {
    const a = cfg && cfg[name];
    if (!Array.isArray(a) || a.length !== length || !a.every(Number.isFinite)) {
      throw new Error(`stack config: ${name} is not ${length} finite numbers`);
    }
    return Float64Array.from(a);
  };
  const n = cfg && Array.isArray(cfg.offsets) ? cfg.offsets.length : 0;
  if (!n) throw new Error("stack config: no offsets");
  return { n, offsets: list("offsets", n), centres: list("centres", 3 * n), scales: list("scales", n),
           byW: Boolean(cfg.by_w) };
}

// The w of each slice for the plane w = c0 (StackSource.cuts_at): c0 + offsets[k].
export function stackCuts(stack, c0) {
  return stack.offsets.map((o) => c0 + o);
}

// StackSource.slice of the polytope `p` (slicer.js decodePolytope) turned by `matrix16` at `c0`,
// as rows.js reads it: points (3n), segments (2m), triangles (3k), groups (k), convex, cornerOnly
// (null: no fill corners without star faces).  One slice is the slice itself (its cells'
// groups, convex as the polytope); more are placed one after another, their indices shifted by
// the points before them, and are not convex together.
export function stackData(p, matrix16, c0, stack) {
  const parts = Array.from(stackCuts(stack, c0), (w) => sliceData(p, matrix16, w));
  if (stack.n === 1) {
    const d = parts[0];
    return { points: d.points, segments: d.segments, triangles: d.triangles, groups: d.groups, convex: d.convex,
             cornerOnly: null };
  }
  let nv = 0, ns = 0, nt = 0;
  for (const d of parts) {
    nv += d.points.length;
    ns += d.segments.length;
    nt += d.groups.length;
  }
  const points = new Float64Array(nv);
  const segments = new Int32Array(ns);
  const triangles = new Int32Array(3 * nt);
  const groups = new Int32Array(nt);
  let pv = 0, ps = 0, pt = 0;
  parts.forEach((d, k) => {
    const s = stack.scales[k];
    const first = pv / 3;  // points before this slice
    for (let i = 0; i < d.points.length; i++) points[pv + i] = d.points[i] * s + stack.centres[3 * k + (i % 3)];
    for (let i = 0; i < d.segments.length; i++) segments[ps + i] = d.segments[i] + first;
    for (let i = 0; i < d.triangles.length; i++) triangles[3 * pt + i] = d.triangles[i] + first;
    for (let i = 0; i < d.groups.length; i++) groups[pt + i] = stack.byW ? k : d.groups[i];
    pv += d.points.length;
    ps += d.segments.length;
    pt += d.groups.length;
  });
  return { points, segments, triangles, groups, convex: false, cornerOnly: null };
}

// The hyperplanes the projection marks for a stack at c0 (view/projection.hyperplane_offsets
// and middle_offset of a polytope's stack, whose w frame is (0, 1)): every cut, and the middle one
// (odd N) or their mean (even N: numpy's pairwise sum, then / N).
export function stackHyperplanes(stack, c0) {
  const offsets = Array.from(stackCuts(stack, c0));
  const n = offsets.length;
  const middle = n % 2 ? offsets[(n - 1) / 2] : pairwiseSum(offsets, 0, n) / n;
  return { offsets, middle };
}
