// Rows drawn without instancing (job 6 of companion.js): a plain geometry per layer, filled from the
// rows in use of the shared row buffer just before a frame is drawn.

// 6. Plain geometries drawn in place of the instanced ones, shared by every companion view
// of one scene (keyed by the layer's three.js instanced geometry).
export const expansions = new WeakMap();

// THREE.BufferGeometry without importing three.js: the instanced geometry's parent class.
export function plainGeometryClass(inst) {
  const parent = inst && Object.getPrototypeOf(inst.constructor.prototype);
  const C = parent && parent.constructor;
  return typeof C === "function" && C !== Object && !C.prototype.isInstancedBufferGeometry ? C : null;
}

// The layer's template (`position`, V vertices) and the row columns its attributes read;
// null if the geometry is not one this module knows how to expand.
export function layerLayout(inst) {
  const attrs = inst && inst.attributes;
  const tmpl = attrs && attrs.position;
  if (!tmpl || !tmpl.array || tmpl.itemSize !== 3 || !plainGeometryClass(inst)) return null;
  const columns = [];
  for (const [name, a] of Object.entries(attrs)) {
    if (name === "position") continue;
    if (!a || !a.isInterleavedBufferAttribute || !Number.isInteger(a.offset) || !Number.isInteger(a.itemSize)) return null;
    columns.push({ name, offset: a.offset, size: a.itemSize });
  }
  if (!columns.length) return null;
  const at = (name) => columns.find((c) => c.name === name && c.size === 3);
  const corners = at("tri_a") && at("tri_b") && at("tri_c") ? [at("tri_a").offset, at("tri_b").offset, at("tri_c").offset] : null;
  return { template: tmpl.array, Attribute: tmpl.constructor, columns, corners };
}

// Whether the triangle whose corners start at rows[i + a], rows[i + b], rows[i + c] has no area: its
// corners coincide, or its sides' directions differ by less than a millionth of a radian.  A star
// section's fill has thousands at symmetric orientations, where several crossings fall on one
// point (9,875 of the great icosahedral 120-cell's 17,809 triangles at its reset view).  Such a
// triangle covers no pixel (it is at most a millionth of its length wide); drawn, it costs three
// vertices' lighting.
export function flatTriangle(rows, i, [a, b, c]) {
  const ux = rows[i + b] - rows[i + a], uy = rows[i + b + 1] - rows[i + a + 1], uz = rows[i + b + 2] - rows[i + a + 2];
  const vx = rows[i + c] - rows[i + a], vy = rows[i + c + 1] - rows[i + a + 1], vz = rows[i + c + 2] - rows[i + a + 2];
  const nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
  return nx * nx + ny * ny + nz * nz <= 1e-12 * (ux * ux + uy * uy + uz * uz) * (vx * vx + vy * vy + vz * vz);
}

// A plain geometry for `capacity` rows of the layer: the template repeated per row and one
// attribute per column (Float32, filled by fillExpansion).
export function buildGeometry(inst, layout, capacity) {
  const Geometry = plainGeometryClass(inst);
  const geometry = new Geometry();
  const add = (name, attr) => (geometry.addAttribute ? geometry.addAttribute(name, attr) : geometry.setAttribute(name, attr));
  const V = layout.template.length / 3;
  const position = new Float32Array(capacity * V * 3);
  for (let i = 0; i < capacity; i++) position.set(layout.template, i * V * 3);
  add("position", new layout.Attribute(position, 3));
  const columns = layout.columns.map((c) => {
    const attr = new layout.Attribute(new Float32Array(capacity * V * c.size), c.size);
    add(c.name, attr);
    return { ...c, attr };
  });
  geometry.setDrawRange(0, 0);
  return { geometry, columns, capacity, rows: null, kept: new Int32Array(capacity) };
}

export function makeExpansion(inst, layout, capacity) {
  const V = layout.template.length / 3;
  return { inst, layout, V, version: null, count: -1, users: 0, ...buildGeometry(inst, layout, capacity) };
}

// Copy rows [0, count) of the interleaved `rows` (stride floats per row) into the expansion, in order,
// leaving out a triangles layer's rows of no area (flatTriangle); returns the rows copied.
export function fillExpansion(e, rows, stride, count) {
  const n = Math.max(0, Math.min(count, e.capacity, Math.floor(rows.length / stride)));
  const V = e.V;
  const corners = e.layout.corners;
  const kept = e.kept;
  let m = 0;
  for (let i = 0; i < n; i++) {
    if (!corners || !flatTriangle(rows, i * stride, corners)) kept[m++] = i;
  }
  for (const c of e.columns) {
    const dst = c.attr.array;
    const size = c.size;
    for (let k = 0; k < m; k++) {
      const src = kept[k] * stride + c.offset;
      for (let v = 0, o = k * V * size; v < V; v++, o += size) {
        for (let j = 0; j < size; j++) dst[o + j] = rows[src + j];
      }
    }
    if (m > 0) c.attr.needsUpdate = true;
  }
  e.geometry.setDrawRange(0, m * V);
  return m;
}
