// The projection view's arithmetic (job 7 of companion.js): the skeleton decoded, rotated,
// projected from (0, 0, 0, d) and coloured, its crossings found -- as projection.projection_arrays.

// The projection's geometries, shared by every companion view of one widget (keyed by the
// projection's edges mesh, a three.js object).
export const projections = new WeakMap();

// 7. The projection (rot4d_widget/view/projection.py): the skeleton as the kernel sends it once
// per source (`skeleton_message`), decoded; null if there is none or it is malformed.
export const bytesAs = (dv, T) =>
  dv && dv.byteLength !== undefined ? new T(dv.buffer.slice(dv.byteOffset, dv.byteOffset + dv.byteLength)) : new T(0);

export function decodeSkeleton(sk) {
  const V = sk && Number.isInteger(sk.n_vertices) ? sk.n_vertices : 0;
  const E = sk && Number.isInteger(sk.n_edges) ? sk.n_edges : 0;
  if (!V) return null;
  const vertices = bytesAs(sk.vertices, Float64Array);
  const edges = bytesAs(sk.edges, Uint32Array);
  if (vertices.length !== 4 * V || edges.length !== 2 * E || edges.some((i) => i >= V)) return null;
  const rgb = (x) => (Array.isArray(x) && x.length === 3 ? x.map(Number) : [0.5, 0.5, 0.5]);
  return { V, E, vertices, edges, d: Number(sk.distance), size: Number(sk.size), scale: Number(sk.scale),
           below: rgb(sk.below), on: rgb(sk.on), above: rgb(sk.above) };
}

// What the projection draws for the state `st` (`state_message`: matrix row by row, offsets,
// middle), exactly as projection.projection_arrays computes it: the vertices rotated
// (v @ matrix.T) and seen from (0, 0, 0, d), xyz * d / (d - w) * scale; their colours on the
// diverging map of w about the middle hyperplane; the edges' crossings of every hyperplane,
// offset by offset then edge by edge (an edge whose ends straddle or touch it: a + t (b - a);
// edges lying in a hyperplane: their first ends, then their second ends), projected alike.
// Float32 arrays: positions (3V), rgb (3V), points (3m); index (2E) is the skeleton's own.
export function projectSkeleton(s, st) {
  const m = st && st.matrix;
  const offsets = st && Array.isArray(st.offsets) ? st.offsets.map(Number) : [];
  if (!s || !Array.isArray(m) || m.length !== 16) return null;
  const { V, vertices: v, edges: e, d, size, scale } = s;
  const r = new Float64Array(4 * V);
  let wmax = 0;
  for (let i = 0; i < V; i++) {
    const x = v[4 * i], y = v[4 * i + 1], z = v[4 * i + 2], w = v[4 * i + 3];
    for (let a = 0; a < 4; a++) r[4 * i + a] = m[4 * a] * x + m[4 * a + 1] * y + m[4 * a + 2] * z + m[4 * a + 3] * w;
    wmax = Math.max(wmax, Math.abs(r[4 * i + 3]));
  }
  const positions = new Float32Array(3 * V);
  const rgb = new Float32Array(3 * V);
  const middle = Number(st.middle);
  for (let i = 0; i < V; i++) {
    const w = r[4 * i + 3];
    const f = d / (d - w);
    const t = Math.min(1, Math.max(-1, (w - middle) / size));
    for (let j = 0; j < 3; j++) {
      positions[3 * i + j] = r[4 * i + j] * f * scale;
      rgb[3 * i + j] = s.on[j] + Math.max(t, 0) * (s.above[j] - s.on[j]) + Math.min(t, 0) * (s.on[j] - s.below[j]);
    }
  }
  const tol = 1e-12 * Math.max(1, wmax);
  const pts = [];
  const put = (x, y, z, w) => {
    const f = d / (d - w);
    pts.push(x * f * scale, y * f * scale, z * f * scale);
  };
  const flat = [];
  for (const o of offsets) {
    for (let j = 0; j < e.length; j += 2) {
      const a = 4 * e[j], b = 4 * e[j + 1];
      const wa = r[a + 3], wb = r[b + 3];
      const lo = Math.min(wa, wb), hi = Math.max(wa, wb);
      if (hi - lo <= tol) {
        if (Math.abs(lo - o) <= tol) flat.push(a, b);
        continue;
      }
      if (lo <= o + tol && hi >= o - tol) {
        const t = Math.min(1, Math.max(0, (o - wa) / (wb - wa)));
        put(r[a] + t * (r[b] - r[a]), r[a + 1] + t * (r[b + 1] - r[a + 1]), r[a + 2] + t * (r[b + 2] - r[a + 2]), o);
      }
    }
  }
  for (let k = 0; k < 2; k++) {
    for (let i = k; i < flat.length; i += 2) put(r[flat[i]], r[flat[i] + 1], r[flat[i] + 2], r[flat[i] + 3]);
  }
  return { positions, rgb, index: e, points: new Float32Array(pts) };
}

