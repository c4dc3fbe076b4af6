// The row table the scene's shaders read, built in the page from a slice it cut itself: bit for
// bit what rot4d_widget.view.buffers.slice_rows builds in the kernel, so a predicted frame and
// the kernel's frame of the same state draw the same rows.
//
// One row is 20 float32 (buffers.COLUMNS): ball xyz and a 1 (0-3), bar ends a and b (4-9),
// triangle corners a, b, c (10-18) and its packed colour 0xRRGGBB (19).  Positions are computed
// in float64 (points times scale) and rounded to float32 once, as numpy casts them.

import { dot3 } from "./numpyorder.js";

export const ROW_FLOATS = 20;

// Triangle order for translucent blending seen from `eye` (buffers.slice_rows): a convex slice's
// triangles facing away first, then those facing the eye (stable); otherwise farthest centroid
// first (stable).  `p` the scaled points (3n), `t` the triangles (3k).
function blendOrder(p, t, eye, convex) {
  const k = t.length / 3;
  const key = new Float64Array(k);
  const [o0, o1, o2] = eye;
  for (let i = 0; i < k; i++) {
    const a = 3 * t[3 * i], b = 3 * t[3 * i + 1], c = 3 * t[3 * i + 2];
    if (convex) {
      const u0 = p[b] - p[a], u1 = p[b + 1] - p[a + 1], u2 = p[b + 2] - p[a + 2];
      const w0 = p[c] - p[a], w1 = p[c + 1] - p[a + 1], w2 = p[c + 2] - p[a + 2];
      const n0 = u1 * w2 - u2 * w1, n1 = u2 * w0 - u0 * w2, n2 = u0 * w1 - u1 * w0;
      key[i] = dot3(n0, n1, n2, o0 - p[a], o1 - p[a + 1], o2 - p[a + 2]) > 0.0 ? 1 : 0;  // facing: after
    } else {
      const d0 = (p[a] + p[b] + p[c]) / 3.0 - o0;
      const d1 = (p[a + 1] + p[b + 1] + p[c + 1]) / 3.0 - o1;
      const d2 = (p[a + 2] + p[b + 2] + p[c + 2]) / 3.0 - o2;
      key[i] = -dot3(d0, d1, d2, d0, d1, d2);  // farthest first
    }
  }
  const order = Array.from({ length: k }, (_, i) => i);
  return order.sort((i, j) => key[i] - key[j] || i - j);
}

// The rows of `data` ({points (3n), segments (2m), triangles (3k), groups (k), convex, and
// optionally cornerOnly (n flags: no ball there) and showPoints (false: no balls)}):
//   scale     positions are multiplied by it
//   palette   packed 0xRRGGBB per group (buffers.pack_rgb), unless singleRgb
//   capacity  rows of the table (default: the rows the slice needs)
//   eye       [x, y, z] (scaled coordinates) to order the triangles for blending, or null
//   singleRgb one packed colour for every triangle, or null
// Returns {rows: Float32Array(capacity * 20), counts: [balls, bars, triangles]}.
export function sliceRows(data, { scale = 1.0, palette = null, capacity = null, eye = null, singleRgb = null } = {}) {
  const v = data.points, e = data.segments, groups = data.groups;
  let t = data.triangles;
  const n = v.length / 3, ne = e.length / 2, nt = t.length / 3;
  const shown = (i) => data.showPoints !== false && !(data.cornerOnly && data.cornerOnly[i]);
  let nv = 0;
  for (let i = 0; i < n; i++) if (shown(i)) nv++;
  const need = Math.max(nv, ne, nt);
  const rows = capacity === null ? need : capacity;
  if (rows < need) throw new Error(`Expected \`capacity\` >= ${need} (rows this slice needs), got ${rows}`);
  const colour = new Float32Array(nt);
  for (let i = 0; i < nt; i++) {
    const packed = singleRgb !== null ? singleRgb : palette && palette[groups[i]];
    if (packed === undefined || packed === null) {
      const have = palette ? palette.length : 0;
      throw new Error(`Expected \`palette\` to have a colour for group ${groups[i]}, got ${have} colours`);
    }
    colour[i] = packed;
  }

  const p = new Float64Array(3 * n);
  for (let i = 0; i < 3 * n; i++) p[i] = v[i] * scale;
  let tc = colour;
  if (eye !== null && nt) {
    const order = blendOrder(p, t, eye, Boolean(data.convex));
    const sorted = new Int32Array(3 * nt);
    tc = new Float32Array(nt);
    order.forEach((j, i) => {
      sorted.set(t.subarray(3 * j, 3 * j + 3), 3 * i);
      tc[i] = colour[j];
    });
    t = sorted;
  }

  const out = new Float32Array(rows * ROW_FLOATS);
  let r = 0;
  for (let i = 0; i < n; i++) {  // the balls, in point order (no fill corner)
    if (!shown(i)) continue;
    put(out, r * ROW_FLOATS, p, 3 * i);
    out[r * ROW_FLOATS + 3] = 1.0;
    r++;
  }
  for (let i = 0; i < ne; i++) {
    put(out, i * ROW_FLOATS + 4, p, 3 * e[2 * i]);
    put(out, i * ROW_FLOATS + 7, p, 3 * e[2 * i + 1]);
  }
  for (let i = 0; i < nt; i++) {
    for (let k = 0; k < 3; k++) put(out, i * ROW_FLOATS + 10 + 3 * k, p, 3 * t[3 * i + k]);
    out[i * ROW_FLOATS + 19] = tc[i];
  }
  return { rows: out, counts: [nv, ne, nt] };
}

// Point p[a..a+2] (float64) into out[at..at+2] (float32: rounded to nearest, as numpy casts).
function put(out, at, p, a) {
  out[at] = p[a];
  out[at + 1] = p[a + 1];
  out[at + 2] = p[a + 2];
}
