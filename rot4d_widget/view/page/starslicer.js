// The page's points and segments of a polytope with star faces or non-convex cells: the slice's
// points (each crossing edge's point, then every vertex on H) and segments (each face's crossing
// line, its points sorted along it and paired by the even-odd rule; and every edge lying in H),
// array for array as rot4d_widget.geometry.starslice.slice_star makes them before its fill
// corners (Slice.n_fill).  Not the polygons, triangles or fill: while it predicts, the page draws
// only balls and bars of such a polytope and shows the kernel's fills once their ids match.
//
// Which slice slice_star returns still depends on steps past the segments, so those are here
// too, reduced to what decides it: the winding-weighted volume (a cell lying in H: the side of
// the larger one is kept), and the cells' cycles (chained as the kernel chains them; when none
// keeps three distinct corners H only touches, and the slice is `touching`'s).  The one later
// step that can make the kernel move H by a hair (`_slabs`, a slab with an odd number of
// pieces) is part of the fill: the page does not see it.
//
// Steps as slice_star's, in the same order and floating-point operations (numpyorder.js: einsum's
// dot products; the volume's pairwise sum), on the unit vertices `slicer.js` turns and scales.

import { dot3, pairwiseSum } from "./numpyorder.js";

// A near-degenerate case the kernel's slicer meets by moving H a hair (slicetables.Inconsistent).
class Inconsistent extends Error {}

// Per-polytope tables derived from the message's integers, once: each face side's face and next side.
const derived = new WeakMap();

function faceTables(p) {
  let d = derived.get(p);
  if (!d) {
    const n = p.facePtr[p.F];
    const faceOf = new Int32Array(n), next = new Int32Array(n);
    for (let f = 0; f < p.F; f++) {
      for (let k = p.facePtr[f]; k < p.facePtr[f + 1]; k++) {
        faceOf[k] = f;
        next[k] = k + 1 < p.facePtr[f + 1] ? k + 1 : p.facePtr[f];
      }
    }
    d = { faceOf, next };
    derived.set(p, d);
  }
  return d;
}

// starslice.slice_star on the turned unit vertices `x` (4V) and the unit level `c0`: {vertices
// (3n, unit scale), edges (2m), volume (scaled, as the Slice has it), dim}.  H moved by a hair if
// a cut is Inconsistent; a cell lying in H: the side with the larger volume; none: `touching`.
export function sliceStarUnit(p, x, m, c0) {
  let h = null, on = null, out = null;
  for (const nudge of [0.0, p.nudge, -p.nudge]) {
    ({ h, on } = heights(p, x, nudge ? c0 + nudge : c0));
    try {
      out = cut(p, x, m, h, on, 1);
      if (cellLyingInH(p, on)) {
        const other = cut(p, x, m, h, on, -1);
        if (other !== null && (out === null || Math.abs(other.volume) > Math.abs(out.volume))) out = other;
      }
      break;
    } catch (e) {
      if (!(e instanceof Inconsistent)) throw e;
    }
  }
  return out !== null ? out : touching(p, x, on);
}

function heights(p, x, c0) {
  const h = new Float64Array(p.V), on = new Uint8Array(p.V);
  for (let i = 0; i < p.V; i++) {
    h[i] = x[4 * i + 3] - c0;
    on[i] = Math.abs(h[i]) <= p.tol ? 1 : 0;
  }
  return { h, on };
}

function cellLyingInH(p, on) {
  for (let c = 0; c < p.C; c++) {
    let all = true;
    for (let k = p.cellVptr[c]; k < p.cellVptr[c + 1] && all; k++) all = on[p.cellVidx[k]] === 1;
    if (all) return true;
  }
  return false;
}

// section.touching: the vertices on H, the edges lying in H; dim 2 / 1 / 0, or -1 missed.
function touching(p, x, on) {
  const vert = new Int32Array(p.V).fill(-1);
  const pts = [];
  for (let i = 0; i < p.V; i++) {
    if (!on[i]) continue;
    vert[i] = pts.length / 3;
    pts.push(x[4 * i], x[4 * i + 1], x[4 * i + 2]);
  }
  const edges = [];
  for (let e = 0; e < p.E; e++) {
    const a = p.edges[2 * e], b = p.edges[2 * e + 1];
    if (on[a] && on[b]) edges.push(vert[a], vert[b]);
  }
  let dim = -1;
  if (pts.length) {
    let face = false;
    for (let f = 0; f < p.F && !face; f++) {
      face = true;
      for (let k = p.facePtr[f]; k < p.facePtr[f + 1]; k++) if (!on[p.faceVidx[k]]) face = false;
    }
    dim = face ? 2 : (edges.length ? 1 : 0);
  }
  return { vertices: Float64Array.from(pts), edges: Int32Array.from(edges), volume: 0.0, dim };
}

// starslice._cut up to its polygons: the vertices on H counted above H (`side` 1) or below (-1);
// null when no edge crosses, or when every cycle shrinks below three corners.
function cut(p, x, m, h, on, side) {
  const { V, E, edges: ev4, faceEidx, faceVidx, faceCells } = p;
  const above = new Uint8Array(V);
  for (let i = 0; i < V; i++) above[i] = side < 0 ? (h[i] > 0 && !on[i] ? 1 : 0) : (h[i] > 0 || on[i] ? 1 : 0);
  const cid = new Int32Array(E).fill(-1);
  const ce = [];
  for (let e = 0; e < E; e++) {
    if (above[ev4[2 * e]] !== above[ev4[2 * e + 1]]) {
      cid[e] = ce.length;
      ce.push(e);
    }
  }
  if (!ce.length) return null;
  // each crossing's point a + s (b - a), s = 0 / 1 at an end on H, and how it moves with the level
  const n = ce.length;
  const pts = new Float64Array(3 * n), dpdc = new Float64Array(3 * n);
  const atV = new Int32Array(n).fill(-1);
  ce.forEach((e, i) => {
    const a = ev4[2 * e], b = ev4[2 * e + 1];
    const s = on[a] ? 0.0 : (on[b] ? 1.0 : h[a] / (h[a] - h[b]));
    const dw = x[4 * b + 3] - x[4 * a + 3];
    for (let k = 0; k < 3; k++) {
      const xa = x[4 * a + k], dx = x[4 * b + k] - xa;
      pts[3 * i + k] = xa + s * dx;
      dpdc[3 * i + k] = dx / dw;
    }
    atV[i] = on[a] ? a : (on[b] ? b : -1);
  });
  // the slice's vertices: the crossings not at a vertex on H, then every vertex on H; `vid` the
  // slice vertex of each crossing, `vnum` of each vertex on H
  const vid = new Int32Array(n);
  const vnum = new Int32Array(V).fill(-1);
  let nOwn = 0;
  for (let i = 0; i < n; i++) if (atV[i] < 0) vid[i] = nOwn++;
  let nOn = 0;
  for (let v = 0; v < V; v++) if (on[v]) vnum[v] = nOwn + nOn++;
  for (let i = 0; i < n; i++) if (atV[i] >= 0) vid[i] = vnum[atV[i]];
  const vertices = new Float64Array(3 * (nOwn + nOn));
  for (let i = 0; i < n; i++) if (atV[i] < 0) vertices.set(pts.subarray(3 * i, 3 * i + 3), 3 * vid[i]);
  for (let v = 0; v < V; v++) if (on[v]) vertices.set(x.subarray(4 * v, 4 * v + 3), 3 * vnum[v]);

  // each crossing face's points along its line w = c0, sorted; paired even-odd
  const { faceOf, next } = faceTables(p);
  const ks = [];
  for (let k = 0; k < faceEidx.length; k++) if (cid[faceEidx[k]] >= 0) ks.push(k);
  const uf = [], fr = new Int32Array(ks.length);
  ks.forEach((k, i) => {
    if (!uf.length || uf[uf.length - 1] !== faceOf[k]) uf.push(faceOf[k]);
    fr[i] = uf.length - 1;
  });
  const cnt = new Int32Array(uf.length);
  for (let i = 0; i < ks.length; i++) cnt[fr[i]]++;
  if (cnt.some((c) => c % 2)) throw new Inconsistent();
  // each face's line direction (J grad w) from its turned plane axes
  const d = new Float64Array(3 * uf.length);
  uf.forEach((f, u) => {
    const r0 = [0, 1, 2, 3].map((j) => turned(m, j, p.faceBasis, 8 * f));
    const r1 = [0, 1, 2, 3].map((j) => turned(m, j, p.faceBasis, 8 * f + 4));
    for (let k = 0; k < 3; k++) d[3 * u + k] = r1[k] * r0[3] - r0[k] * r1[3];
  });
  const along = (a, i, u) => dot3(a[3 * i], a[3 * i + 1], a[3 * i + 2], d[3 * u], d[3 * u + 1], d[3 * u + 2]);
  const pk = ks.map((k) => cid[faceEidx[k]]);
  const two = ks.length === 2 * uf.length;  // every face cut twice
  let order;
  if (two) {  // each pair in order along its line; equal positions (a vertex on H) as they move
    order = new Int32Array(ks.length);
    for (let u = 0; u < uf.length; u++) {
      const t0 = along(pts, pk[2 * u], u), t1 = along(pts, pk[2 * u + 1], u);
      let swap = t0 > t1;
      if (t0 === t1) swap = -side * along(dpdc, pk[2 * u], u) > -side * along(dpdc, pk[2 * u + 1], u);
      order[2 * u] = 2 * u + (swap ? 1 : 0);
      order[2 * u + 1] = order[2 * u] ^ 1;
    }
  } else {  // by face, then along its line, then as they move, then as they came (numpy's lexsort)
    const tpos = ks.map((_, i) => along(pts, pk[i], fr[i]));
    const tie = ks.map((_, i) => -side * along(dpdc, pk[i], fr[i]));
    const cmp = (a, b) => (a < b ? -1 : (a > b ? 1 : 0));
    order = Int32Array.from(ks.keys()).sort((i, j) => fr[i] - fr[j] || cmp(tpos[i], tpos[j]) || cmp(tie[i], tie[j]) || i - j);
  }
  const ns = ks.length / 2;
  const sp = new Int32Array(ks.length), sd = new Int32Array(ks.length), sk = new Int32Array(ks.length);
  const sf = new Int32Array(ks.length);  // the face (index into uf) of each sorted crossing
  order.forEach((o, i) => {
    sp[i] = pk[o];
    sd[i] = above[faceVidx[next[ks[o]]]] ? 1 : -1;  // +1 where the face's side rises through H
    sk[i] = ks[o];
    sf[i] = fr[o];
  });
  const segFace = Int32Array.from({ length: ns }, (_, s) => uf[sf[2 * s]]);

  const volume = scaledVolume(p, windingVolume(p, vertices, pts, sp, sd, sf, uf, segFace, two));
  if (!anyPolygon(p, sp, sk, segFace, vid)) return null;

  // the segments' ends as slice vertices (none of no length); with a vertex on H, and every edge
  // lying in H, each pair ascending, once, in order
  let out = [];
  for (let s = 0; s < ns; s++) if (vid[sp[2 * s]] !== vid[sp[2 * s + 1]]) out.push([vid[sp[2 * s]], vid[sp[2 * s + 1]]]);
  if (nOn) {
    for (let e = 0; e < E; e++) {
      const a = ev4[2 * e], b = ev4[2 * e + 1];
      if (on[a] && on[b]) out.push([vnum[a], vnum[b]]);
    }
    const nv = nOwn + nOn;
    const seen = new Set();
    out = out.map(([a, b]) => (a <= b ? [a, b] : [b, a]))
      .filter(([a, b]) => !seen.has(a * nv + b) && seen.add(a * nv + b))
      .sort((a, b) => a[0] - b[0] || a[1] - b[1]);
  }
  return { vertices, edges: Int32Array.from(out.flat()), volume, dim: 3 };
}

// Row j of the 4-vector a[i..i+3] turned by the row-major `m`, summed k = 0..3 (as slicer.js).
const turned = (m, j, a, i) =>
  m[4 * j] * a[i] + m[4 * j + 1] * a[i + 1] + m[4 * j + 2] * a[i + 2] + m[4 * j + 3] * a[i + 3];

// The slice's winding-weighted volume (unit scale), as starslice._cut sums it: over the stretches
// of each crossing face's line that it winds round (W != 0), in both cells of the face,
// rho W det(a_c, P, Q) about the vertices' mean, a_c the first end of the last segment of cell c.
function windingVolume(p, vertices, pts, sp, sd, sf, uf, segFace, two) {
  const nv = vertices.length / 3;
  const centre = [0, 1, 2].map((k) => {
    let s = 0;
    for (let i = 0; i < nv; i++) s += vertices[3 * i + k];
    return s / nv;
  });
  const anchor = new Float64Array(3 * p.C);
  for (let s = 0; s < segFace.length; s++) {
    for (let j = 0; j < 2; j++) {
      const c = p.faceCells[2 * segFace[s] + j];
      for (let k = 0; k < 3; k++) anchor[3 * c + k] = pts[3 * sp[2 * s] + k] - centre[k];
    }
  }
  // the stretches: (winding, face, from, to)
  const stretches = [];
  if (two) {  // a face cut twice winds once round its one stretch, the segment
    for (let s = 0; s < segFace.length; s++) stretches.push([sd[2 * s], segFace[s], sp[2 * s], sp[2 * s + 1]]);
  } else {
    let w = 0;
    for (let i = 0; i < sp.length; i++) {
      w = i && sf[i] === sf[i - 1] ? w + sd[i] : sd[i];
      const last = i + 1 === sp.length || sf[i + 1] !== sf[i];
      if (!last && w !== 0) stretches.push([w, uf[sf[i]], sp[i], sp[i + 1]]);
    }
  }
  const terms = new Float64Array(2 * stretches.length);
  stretches.forEach(([w, f, a, b], i) => {
    const p0 = pts[3 * a] - centre[0], p1 = pts[3 * a + 1] - centre[1], p2 = pts[3 * a + 2] - centre[2];
    const q0 = pts[3 * b] - centre[0], q1 = pts[3 * b + 1] - centre[1], q2 = pts[3 * b + 2] - centre[2];
    const c0 = p1 * q2 - p2 * q1, c1 = p2 * q0 - p0 * q2, c2 = p0 * q1 - p1 * q0;
    for (let j = 0; j < 2; j++) {
      const c = 3 * p.faceCells[2 * f + j];
      terms[2 * i + j] = w * p.faceRho[2 * f + j] * dot3(anchor[c], anchor[c + 1], anchor[c + 2], c0, c1, c2);
    }
  });
  return pairwiseSum(terms, 0, terms.length) / 6.0;
}

// slicetables.scaled_volume: times unit**3, one factor at a time.
function scaledVolume(p, v) {
  return p.unit === 1.0 ? v : v * p.unit * p.unit * p.unit;
}

// Whether some cell's section has a polygon: the segments chained into cycles at the crossing
// points (at each crossing of a cell's edge, its two faces' segments meet: `slot_mate`), each
// cycle run both ways (the kernel keeps one way of each; a cycle that is its own reverse it keeps
// neither way), with three corners left after dropping repeats (crossings merged at a vertex on H).
// Records r = 2 s + j (segment s in its face's cell j), ends q = 2 r + (0 or 1), as the kernel's.
function anyPolygon(p, sp, sk, segFace, vid) {
  const nEnd = 2 * sp.length;
  const at = new Int32Array(p.facePtr[p.F]).fill(-1);
  sk.forEach((k, i) => { at[k] = i; });
  const partner = new Int32Array(nEnd);
  for (let q = 0; q < nEnd; q++) {
    const mate = p.slotMate[2 * sk[((q >> 2) << 1) + (q & 1)] + ((q >> 1) & 1)];
    if (mate < 0) throw new Inconsistent();
    const q2 = at[mate >> 1];
    if (q2 < 0) throw new Inconsistent();
    partner[q] = 4 * (q2 >> 1) + 2 * (mate & 1) + (q2 & 1);
    if (partner[q] === q) throw new Inconsistent();
  }
  for (let q = 0; q < nEnd; q++) if (partner[partner[q]] !== q) throw new Inconsistent();
  const orbit = new Int32Array(nEnd).fill(-1);
  let found = false;
  for (let q0 = 0; q0 < nEnd && !found; q0++) {
    if (orbit[q0] >= 0) continue;
    const ends = [];
    for (let q = q0; orbit[q] < 0; q = partner[q] ^ 1) {
      orbit[q] = q0;
      ends.push(q);
    }
    if (orbit[q0 ^ 1] === q0) continue;  // its own reverse: not kept
    const corner = (q) => vid[sp[2 * (q >> 2) + (q & 1)]];  // the slice vertex at end q
    let corners = 0;
    ends.forEach((q, i) => {
      if (corner(q) !== corner(ends[(i || ends.length) - 1])) corners++;
    });
    found = corners >= 3;
  }
  return found;
}
