// The page's own polytope slicer: the slice w = c0 of a turned polytope whose cells are convex,
// array for array as rot4d_widget.geometry.slicing.slice_polytope computes it (section.py:
// slice_level, _slice, touching, _faces_in_h; slicetables.py: fan,
// inplane_axes, scaled, scaled_volume), so the page can draw the slice of the state it
// predicts without waiting for the kernel.
//
// The polytope comes once from the kernel (rot4d_widget.view.pagegeometry.polytope_message: the
// slicer's own tables, in the unit scale) and is read by `decodePolytope`.  Every step below is
// the Python step written as loops, in the same order, with the same floating-point operations
// where the order decides a result (numpyorder.js: einsum's dot products, signed zeros too, and
// the pairwise sum of the volume; bincount's running sums; the sort keys rank * 8 + angle).
// Ties in a sort are broken by position (numpy's argsort of the angles is not stable; no tie has
// been seen).  Rotated vertices are summed k = 0..3 left to right, where numpy's BLAS fuses
// multiply-adds: turned slices agree to rounding, unturned ones exactly.
//
// Polytopes with star faces or non-convex cells (`star`: rot4d_widget.geometry.starslice) are
// not cut here: `slicePolytope` throws for them; `sliceStarEdges` gives their points and
// segments (starslicer.js), all the page draws of them.

import { dot3, mod2pi, pairwiseSum } from "./numpyorder.js";
import { sliceStarUnit } from "./starslicer.js";

// Spacing of the per-polygon sort keys (> 2 pi): section._TWO_PI_PLUS.
const TWO_PI_PLUS = 8.0;
// sys.float_info.min: a solid slice's volume below it has underflowed (protocol._volume_or_none).
const FLOAT_MIN = 2.2250738585072014e-308;

// -- the polytope, as it arrives --------------------------------------------------------------

const LITTLE_ENDIAN = new Uint8Array(new Uint16Array([1]).buffer)[0] === 1;

// `bytes` (an ArrayBuffer, or any view of one: a DataView as anywidget's buffers arrive, a
// Uint8Array or Node Buffer) as a typed array `T` of `length` elements, copied (aligned, owned).
function typed(bytes, T, length, name) {
  let u8;
  if (bytes instanceof ArrayBuffer) u8 = new Uint8Array(bytes);
  else if (ArrayBuffer.isView(bytes)) u8 = new Uint8Array(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  else throw new Error(`polytope message: ${name} is not binary (${typeof bytes})`);
  if (u8.byteLength !== length * T.BYTES_PER_ELEMENT) {
    const want = `${length} x ${T.BYTES_PER_ELEMENT}`;
    throw new Error(`polytope message: ${name} has ${u8.byteLength} bytes, expected ${want}`);
  }
  const out = new T(length);
  new Uint8Array(out.buffer).set(u8);
  return out;
}

function indices(msg, name, length, bound) {
  const a = typed(msg[name], Int32Array, length, name);
  for (let i = 0; i < a.length; i++) {
    if (!(a[i] >= 0 && a[i] < bound)) {
      throw new Error(`polytope message: ${name}[${i}] = ${a[i]} is not in [0, ${bound})`);
    }
  }
  return a;
}

// Offsets of a ragged table: n + 1 of them, from 0, never decreasing.
function offsets(msg, name, n) {
  const a = typed(msg[name], Int32Array, n + 1, name);
  for (let i = 0; i <= n; i++) {
    if (!(i ? a[i] >= a[i - 1] : a[i] === 0)) throw new Error(`polytope message: ${name} does not rise from 0 at ${i}`);
  }
  return a;
}

function count(msg, name) {
  const n = msg[name];
  if (!Number.isInteger(n) || n < 0) throw new Error(`polytope message: ${name} is not a count (${n})`);
  return n;
}

// The polytope from `polytope_message` (arrays as little-endian bytes, scalars as numbers);
// throws naming the first array that does not fit the counts.
export function decodePolytope(msg) {
  if (!LITTLE_ENDIAN) throw new Error("the page's slicer reads little-endian arrays: this platform is big-endian");
  const V = count(msg, "n_vertices"), E = count(msg, "n_edges"), F = count(msg, "n_faces"), C = count(msg, "n_cells");
  const facePtr = offsets(msg, "face_ptr", F);
  const cellVptr = offsets(msg, "cell_vptr", C);
  const cellEptr = offsets(msg, "cell_eptr", C);
  const p = {
    name: String(msg.name), V, E, F, C,
    unit: Number(msg.unit), tol: Number(msg.tol), radius: Number(msg.radius), nudge: Number(msg.nudge),
    convex: Boolean(msg.convex), star: Boolean(msg.star), nGroups: count(msg, "n_groups"),
    vertices: typed(msg.vertices, Float64Array, 4 * V, "vertices"),
    edges: indices(msg, "edges", 2 * E, V),
    facePtr,
    faceVidx: indices(msg, "face_vidx", facePtr[F], V),
    faceEidx: indices(msg, "face_eidx", facePtr[F], E),
    cellVptr,
    cellVidx: indices(msg, "cell_vidx", cellVptr[C], V),
    cellEptr,
    cellEidx: indices(msg, "cell_eidx", cellEptr[C], E),
    faceCells: indices(msg, "face_cells", 2 * F, C),
    cellNormals: typed(msg.cell_normals, Float64Array, 4 * C, "cell_normals"),
    cellCentres: typed(msg.cell_centres, Float64Array, 4 * C, "cell_centres"),
  };
  if (p.star) {  // the star slicer's tables (starslicer.js)
    const sides = facePtr[F];
    p.faceBasis = typed(msg.face_basis, Float64Array, 8 * F, "face_basis");
    p.faceRho = typed(msg.face_rho, Float64Array, 2 * F, "face_rho");
    p.slotMate = typed(msg.slot_mate, Int32Array, 2 * sides, "slot_mate");
    p.slotMate.forEach((v, i) => {
      if (!(v >= -1 && v < 2 * sides)) throw new Error(`polytope message: slot_mate[${i}] = ${v} is not in [-1, ${2 * sides})`);
    });
    p.volumeDefined = Boolean(msg.volume_defined);
  }
  return p;
}

// Row j of the 4-vector a[i..i+3] turned by the row-major `m` (vertices @ m.T), summed k = 0..3.
const turned = (m, j, a, i) =>
  m[4 * j] * a[i] + m[4 * j + 1] * a[i + 1] + m[4 * j + 2] * a[i + 2] + m[4 * j + 3] * a[i + 3];

// slicetables.inplane_axes of one normal: u = n x (e_x, or e_y near e_x), v = n x u, not unit.
function inplaneAxes(nx, ny, nz) {
  if (nx * nx < 0.5 * (ny * ny + nz * nz + nx * nx)) return [0.0, nz, -ny, -(ny * ny + nz * nz), nx * ny, nx * nz];
  return [-nz, 0.0, nx, nx * ny, -(nx * nx + nz * nz), ny * nz];
}

// A face chord without exactly two ends (tables.Inconsistent): classification hit a
// near-degenerate case; `sliceLevel` classifies again.
class Inconsistent extends Error {}

// The slice of polytope `p` (decodePolytope) turned by `matrix16` (4 x 4 row-major rotation:
// rotated = vertices @ matrix.T) at w = `c0`, in the polytope's units:
//   vertices Float64Array(3n), edges Int32Array(2m), flat + offsets (polygon i's corners are
//   flat[offsets[i]:offsets[i+1]], counter-clockwise seen from outside), cellIds (P),
//   triangles Int32Array(3k) (the polygons fanned), triangleCells (k), volume, dim (3 solid;
//   2 / 1 / 0 when H touches a face / edge / vertex; -1 empty) -- geometry.slicetables.Slice.
export function slicePolytope(p, matrix16, c0) {
  if (p.star) {
    throw new Error(`${p.name} has star faces or non-convex cells: the page does not cut it (the kernel does)`);
  }
  const { m, x } = turnedVertices(p, matrix16);
  // cut the unit vertices at c0 / unit (dividing by the power of two is exact, and by 1 changes nothing)
  return sliceLevel(p, x, m, c0 / p.unit);
}

// The rotation (row-major Float64Array) and the unit vertices it turns (4 per vertex).
function turnedVertices(p, matrix16) {
  if (!matrix16 || matrix16.length !== 16) throw new Error("Expected `matrix16` to be 16 numbers (4 x 4, row by row)");
  const m = Float64Array.from(matrix16);
  const x = new Float64Array(4 * p.V);
  for (let i = 0; i < 4 * p.V; i += 4) for (let j = 0; j < 4; j++) x[i + j] = turned(m, j, p.vertices, i);
  return { m, x };
}

// What the page draws of a polytope with star faces or non-convex cells (`p.star`) turned by
// `matrix16` at w = `c0`: the slice's points and segments (starslice.slice_star's vertices before
// its fill corners, and its edges), as sliceData's fields so that rows.js draws balls and bars
// (no triangles: the page shows no fill of its own); `volume` as sliceData's (null for a polytope
// with no inside), `dim` as the Slice's.
export function sliceStarEdges(p, matrix16, c0) {
  if (!p.star) throw new Error(`${p.name} has no star faces or non-convex cells: slicePolytope cuts it`);
  const { m, x } = turnedVertices(p, matrix16);
  const s = sliceStarUnit(p, x, m, c0 / p.unit);
  const u = p.unit;
  const v = p.volumeDefined ? s.volume : null;
  const volume = v === null || !Number.isFinite(v) || (s.dim === 3 && Math.abs(v) < FLOAT_MIN) ? null : v;
  return { points: u === 1.0 ? s.vertices : s.vertices.map((c) => c * u), segments: s.edges,
           triangles: new Int32Array(0), groups: new Int32Array(0), cornerOnly: null, volume, dim: s.dim,
           convex: p.convex };
}

// section.slice_level: the tolerance, then exact signs, then (never seen) H moved by a hair.
function sliceLevel(p, x, m, c0) {
  try {
    return cut(p, x, m, c0, p.tol);
  } catch (e) {
    if (!(e instanceof Inconsistent)) throw e;
  }
  try {
    return cut(p, x, m, c0, 0.0);
  } catch (e) {
    if (!(e instanceof Inconsistent)) throw e;
  }
  return cut(p, x, m, c0 + p.nudge, p.tol);
}

// section._slice: one level with one tolerance, step by step.  (Python skips the crossing
// edges, chords and cells when no vertex lies on each side of H; here the loops find none.)
function cut(p, x, m, c0, tol) {
  const { side, h, onIdx, crossing } = classify(p, x, c0, tol);
  const cOn = cellsInH(p, side, onIdx);
  const { vertices, crossE, edgeSv, vertSv } = points(p, x, h, side, onIdx);
  const edges = sliceEdges(p, side, crossE, edgeSv, vertSv);
  const faceIds = facesLyingInH(p, side, onIdx);
  const solid = crossing || (onIdx.length > 0 && cOn.includes(1));
  if (!solid) return touching(p, vertices, edges, onIdx, faceIds);
  const polys = polygons(p, x, m, side, crossE, edgeSv, vertSv, faceIds, cOn);
  // no cell crosses H and no face in H bounds a solid part (a polytope's pieces may lie apart)
  if (!polys.ids.length) return touching(p, vertices, edges, onIdx, faceIds);
  const { flat, offsets } = cornerOrder(vertices, polys);
  // the 4-D cell of each polygon: a face's cell lying in H if one is, else its lower-numbered cell
  const cellIds = Int32Array.from(polys.ids, (id) => {
    if (id < p.C) return id;
    const a = p.faceCells[2 * (id - p.C)], b = p.faceCells[2 * (id - p.C) + 1];
    return cOn[b] && !cOn[a] ? b : a;
  });
  const { triangles, triangleCells } = fan(flat, offsets, cellIds);
  const slice = { vertices, edges, flat, offsets, cellIds, triangles, triangleCells,
                  volume: volumeOf(vertices, triangles), dim: 3 };
  return scaled(p, slice);
}

// Each vertex above (side 1), below (-1) or on H (0) within `tol`; its height h = w - c0.
function classify(p, x, c0, tol) {
  const h = new Float64Array(p.V);
  const side = new Int8Array(p.V);
  const onIdx = [];
  let anyPos = false, anyNeg = false;
  for (let i = 0; i < p.V; i++) {
    h[i] = x[4 * i + 3] - c0;
    if (h[i] > tol) {
      side[i] = 1;
      anyPos = true;
    } else if (h[i] < -tol) {
      side[i] = -1;
      anyNeg = true;
    } else {
      onIdx.push(i);
    }
  }
  return { side, h, onIdx, crossing: anyPos && anyNeg };
}

// 1 for each cell whose vertices are all on H (none unless some vertex is).
function cellsInH(p, side, onIdx) {
  const cOn = new Uint8Array(p.C);
  if (!onIdx.length) return cOn;
  for (let c = 0; c < p.C; c++) {
    cOn[c] = 1;
    for (let k = p.cellVptr[c]; k < p.cellVptr[c + 1]; k++) if (side[p.cellVidx[k]] !== 0) cOn[c] = 0;
  }
  return cOn;
}

// The faces whose corners are all on H, ascending.
function facesLyingInH(p, side, onIdx) {
  const out = [];
  if (!onIdx.length) return out;
  for (let f = 0; f < p.F; f++) {
    let all = true;
    for (let k = p.facePtr[f]; k < p.facePtr[f + 1]; k++) if (side[p.faceVidx[k]] !== 0) all = false;
    if (all) out.push(f);
  }
  return out;
}

// The slice's vertices (3 per point): each crossing edge's point a + s (b - a), s = ha / (ha - hb),
// in edge order, then the vertices on H; with each crossing edge's (`edgeSv`) and each on-H
// vertex's (`vertSv`) index among them.
function points(p, x, h, side, onIdx) {
  const { E, edges } = p;
  const crossE = new Uint8Array(E);
  const edgeSv = new Int32Array(E).fill(-1);
  let nE = 0;
  for (let e = 0; e < E; e++) {
    if (side[edges[2 * e]] * side[edges[2 * e + 1]] === -1) {
      crossE[e] = 1;
      edgeSv[e] = nE++;
    }
  }
  const vertices = new Float64Array(3 * (nE + onIdx.length));
  for (let e = 0; e < E; e++) {
    if (!crossE[e]) continue;
    const a = edges[2 * e], b = edges[2 * e + 1];
    const s = h[a] / (h[a] - h[b]);
    for (let k = 0; k < 3; k++) vertices[3 * edgeSv[e] + k] = x[4 * a + k] + s * (x[4 * b + k] - x[4 * a + k]);
  }
  const vertSv = new Int32Array(p.V).fill(-1);
  onIdx.forEach((v, j) => {
    vertSv[v] = nE + j;
    for (let k = 0; k < 3; k++) vertices[3 * (nE + j) + k] = x[4 * v + k];
  });
  return { vertices, crossE, edgeSv, vertSv };
}

// The slice's edges (pairs): each crossing face's chord -- its crossing sides' points, then its
// corners on H -- face by face, then the polytope's edges lying in H.  A face whose chord has an
// odd number of ends is `Inconsistent`.
function sliceEdges(p, side, crossE, edgeSv, vertSv) {
  const { facePtr, faceVidx, faceEidx, edges } = p;
  const out = [];
  for (let f = 0; f < p.F; f++) {
    const ends = [];
    let fPos = false, fNeg = false;
    for (let k = facePtr[f]; k < facePtr[f + 1]; k++) {
      if (crossE[faceEidx[k]]) ends.push(edgeSv[faceEidx[k]]);
      fPos = fPos || side[faceVidx[k]] === 1;
      fNeg = fNeg || side[faceVidx[k]] === -1;
    }
    if (fPos && fNeg) {
      for (let k = facePtr[f]; k < facePtr[f + 1]; k++) if (side[faceVidx[k]] === 0) ends.push(vertSv[faceVidx[k]]);
    }
    if (ends.length % 2) throw new Inconsistent();
    out.push(...ends);
  }
  for (let e = 0; e < p.E; e++) {
    const a = edges[2 * e], b = edges[2 * e + 1];
    if (side[a] === 0 && side[b] === 0) out.push(vertSv[a], vertSv[b]);
  }
  return Int32Array.from(out);
}

// The polygons of a solid slice, by id: each cell crossing H (id = cell; corners: its crossing
// edges' points, then its vertices on H), then each face lying in H that bounds the slice (id =
// C + face; corners: its own, in cycle order), each with its outward normal within H.
function polygons(p, x, m, side, crossE, edgeSv, vertSv, faceIds, cOn) {
  const { C, facePtr, faceVidx, cellVptr, cellVidx, cellEptr, cellEidx } = p;
  const out = { ids: [], corners: [], normals: [] };
  for (let c = 0; c < C; c++) {
    const corners = [];
    for (let k = cellEptr[c]; k < cellEptr[c + 1]; k++) if (crossE[cellEidx[k]]) corners.push(edgeSv[cellEidx[k]]);
    let cPos = false, cNeg = false;
    for (let k = cellVptr[c]; k < cellVptr[c + 1]; k++) {
      cPos = cPos || side[cellVidx[k]] === 1;
      cNeg = cNeg || side[cellVidx[k]] === -1;
    }
    if (cPos && cNeg) {
      for (let k = cellVptr[c]; k < cellVptr[c + 1]; k++) {
        if (side[cellVidx[k]] === 0) corners.push(vertSv[cellVidx[k]]);
      }
    }
    if (!corners.length) continue;
    out.ids.push(c);
    out.corners.push(corners);
    out.normals.push([0, 1, 2].map((j) => turned(m, j, p.cellNormals, 4 * c)));  // cell_normals @ m[:3].T
  }
  if (!faceIds.length) return out;
  // each face's normal within H from its first three corners, (b - a) x (c - b)
  const fn = faceIds.map((f) => {
    const a = 4 * faceVidx[facePtr[f]], b = 4 * faceVidx[facePtr[f] + 1], c = 4 * faceVidx[facePtr[f] + 2];
    const u0 = x[b] - x[a], u1 = x[b + 1] - x[a + 1], u2 = x[b + 2] - x[a + 2];
    const w0 = x[c] - x[b], w1 = x[c + 1] - x[b + 1], w2 = x[c + 2] - x[b + 2];
    return [u1 * w2 - u2 * w1, u2 * w0 - u0 * w2, u0 * w1 - u1 * w0];
  });
  const { keep, outward } = facesInH(p, x, m, faceIds, fn, cOn);
  faceIds.forEach((f, i) => {
    if (!keep[i]) return;
    const corners = [];
    for (let k = facePtr[f]; k < facePtr[f + 1]; k++) corners.push(vertSv[faceVidx[k]]);
    out.ids.push(C + f);
    out.corners.push(corners);
    out.normals.push(outward[i] ? fn[i] : fn[i].map((v) => v * -1.0));
  });
  return out;
}

// Each polygon's corners by angle about their mean (bincount's running sums), seen along its
// outward normal: sort keys rank * 8 + atan2(d . v, d . u) as section._slice makes them.
function cornerOrder(vertices, polys) {
  const n = polys.ids.length;
  const offsets = new Int32Array(n + 1);
  polys.corners.forEach((corners, r) => { offsets[r + 1] = offsets[r] + corners.length; });
  const flat = new Int32Array(offsets[n]);
  polys.corners.forEach((corners, r) => {
    const centre = [0, 1, 2].map((k) => {
      let s = 0;
      for (const sv of corners) s += vertices[3 * sv + k];
      return s / corners.length;
    });
    const [u0, u1, u2, v0, v1, v2] = inplaneAxes(...polys.normals[r]);
    const key = corners.map((sv) => {
      const d0 = vertices[3 * sv] - centre[0];
      const d1 = vertices[3 * sv + 1] - centre[1];
      const d2 = vertices[3 * sv + 2] - centre[2];
      return r * TWO_PI_PLUS + Math.atan2(dot3(d0, d1, d2, v0, v1, v2), dot3(d0, d1, d2, u0, u1, u2));
    });
    const order = corners.map((_, i) => i).sort((i, j) => key[i] - key[j] || i - j);
    order.forEach((i, k) => { flat[offsets[r] + k] = corners[i]; });
  });
  return { flat, offsets };
}

// slicetables.fan: corners 1 .. k-2 of each polygon open a triangle with its first corner.
function fan(flat, offsets, cellIds) {
  let n = 0;
  for (let r = 0; r + 1 < offsets.length; r++) n += Math.max(0, offsets[r + 1] - offsets[r] - 2);
  const triangles = new Int32Array(3 * n);
  const triangleCells = new Int32Array(n);
  let t = 0;
  for (let r = 0; r + 1 < offsets.length; r++) {
    for (let k = offsets[r] + 1; k < offsets[r + 1] - 1; k++) {
      triangles[3 * t] = flat[offsets[r]];
      triangles[3 * t + 1] = flat[k];
      triangles[3 * t + 2] = flat[k + 1];
      triangleCells[t++] = cellIds[r];
    }
  }
  return { triangles, triangleCells };
}

// The volume enclosed by the triangles (outward), by the divergence theorem about the vertex
// centroid, each triangle's triple product summed as numpy sums them (pairwise).
function volumeOf(vertices, triangles) {
  const n = vertices.length / 3;
  const mean = [0, 1, 2].map((k) => {
    let s = 0;
    for (let i = 0; i < n; i++) s += vertices[3 * i + k];
    return s / n;
  });
  const r = vertices.map((v, i) => v - mean[i % 3]);
  const terms = new Float64Array(triangles.length / 3);
  for (let i = 0; i < terms.length; i++) {
    const a = 3 * triangles[3 * i], b = 3 * triangles[3 * i + 1], d = 3 * triangles[3 * i + 2];
    terms[i] = r[a] * (r[b + 1] * r[d + 2] - r[b + 2] * r[d + 1])
      + r[a + 1] * (r[b + 2] * r[d] - r[b] * r[d + 2])
      + r[a + 2] * (r[b] * r[d + 1] - r[b + 1] * r[d]);
  }
  return pairwiseSum(terms, 0, terms.length) / 6.0;
}

// The slice's vertices and volume from the unit scale back to the polytope's (exact: a power of
// two, one factor of the volume at a time; by 1 nothing changes).
function scaled(p, s) {
  const u = p.unit;
  return { ...s, vertices: s.vertices.map((v) => v * u), volume: s.volume * u * u * u };
}

// section.touching: no polygons; H touches P in faces (dim 2), edges (1) or vertices (0), or misses it.
function touching(p, vertices, edges, onIdx, faceIds) {
  let dim = -1;
  if (onIdx.length) dim = faceIds.length ? 2 : (edges.length ? 1 : 0);
  return scaled(p, { vertices, edges, flat: new Int32Array(0), offsets: new Int32Array(1), cellIds: new Int32Array(0),
                     triangles: new Int32Array(0), triangleCells: new Int32Array(0), volume: 0.0, dim });
}

// section._faces_in_h: which faces lying in H bound the solid slice (`keep`), and whether +fn is
// their outside (`outward`).  Seen in the plane of the face's normal within H and w, each of its
// two cells is a ray from the face towards the cell's centre, and the polytope fills the angle
// between them on the inner side of the first cell; a direction +-fn is filled when strictly
// inside that angle or along a cell lying in H.  The face bounds S when exactly one is filled.
function facesInH(p, x, m, faceIds, fn, cOn) {
  const { facePtr, faceVidx, faceCells, cellCentres, cellNormals } = p;
  const keep = [], outward = [];
  // counter-clockwise angle from a to b in [0, 2 pi)
  const angle = (ax, ay, bx, by) => mod2pi(Math.atan2(ax * by - ay * bx, ax * bx + ay * by));
  faceIds.forEach((f, i) => {
    const [nx, ny, nz] = fn[i];
    const n = facePtr[f + 1] - facePtr[f];
    const pf = [0, 1, 2, 3].map((k) => {
      let s = 0;
      for (let j = facePtr[f]; j < facePtr[f + 1]; j++) s += x[4 * faceVidx[j] + k];
      return s / n;
    });
    const fc = [faceCells[2 * f], faceCells[2 * f + 1]];
    // the two rays in (fn, w) coordinates
    const ray = fc.map((c) => {
      const r = [0, 1, 2, 3].map((j) => turned(m, j, cellCentres, 4 * c) - pf[j]);
      return [dot3(r[0], r[1], r[2], nx, ny, nz), cOn[c] ? 0.0 : r[3]];
    });
    const [[a1, b1], [a2, b2]] = ray;
    const nrm = [0, 1, 2, 3].map((j) => turned(m, j, cellNormals, 4 * fc[0]));  // the first cell's outward normal
    const na = dot3(nrm[0], nrm[1], nrm[2], nx, ny, nz), nb = nrm[3];
    const ccw = a1 * (-nb) - b1 * (-na) > 0;  // the polytope lies counter-clockwise from ray 1
    const filled = [1.0, -1.0].map((sgn) => {
      const ang1x = angle(a1, b1, sgn, 0.0), ang12 = angle(a1, b1, a2, b2);
      const angx1 = angle(sgn, 0.0, a1, b1), ang21 = angle(a2, b2, a1, b1);
      const inside = ccw ? ang1x > 0 && ang1x < ang12 : angx1 > 0 && angx1 < ang21;
      const along = (cOn[fc[0]] && Math.sign(a1) === sgn) || (cOn[fc[1]] && Math.sign(a2) === sgn);
      return Boolean(inside || along);
    });
    keep.push(filled[0] !== filled[1]);
    outward.push(filled[1]);
  });
  return { keep, outward };
}

// What rot4d_widget.sources.protocol.PolytopeSource.slice returns for the page's state: points,
// segments, triangles, groups (each triangle's cell), cornerOnly (null: no fill corners without
// star faces), volume (null where it left float64's range), convex, and the slice itself.
export function sliceData(p, matrix16, c0) {
  const s = slicePolytope(p, matrix16, c0);
  const v = s.volume;
  const volume = !Number.isFinite(v) || (s.dim === 3 && Math.abs(v) < FLOAT_MIN) ? null : v;
  return { points: s.vertices, segments: s.edges, triangles: s.triangles, groups: s.triangleCells, cornerOnly: null,
           volume, convex: p.convex, slice: s };
}
