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
  return columns.length ? { template: tmpl.array, Attribute: tmpl.constructor, columns } : null;
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
  return { geometry, columns, capacity, rows: null };
}

export function makeExpansion(inst, layout, capacity) {
  const V = layout.template.length / 3;
  return { inst, layout, V, version: null, count: -1, users: 0, ...buildGeometry(inst, layout, capacity) };
}

// Copy rows [0, count) of the interleaved `rows` (stride floats per row) into the expansion.
export function fillExpansion(e, rows, stride, count) {
  const n = Math.max(0, Math.min(count, e.capacity, Math.floor(rows.length / stride)));
  const V = e.V;
  for (const c of e.columns) {
    const dst = c.attr.array;
    const size = c.size;
    for (let i = 0; i < n; i++) {
      const src = i * stride + c.offset;
      for (let k = 0, o = i * V * size; k < V; k++, o += size) {
        for (let j = 0; j < size; j++) dst[o + j] = rows[src + j];
      }
    }
    if (n > 0) c.attr.needsUpdate = true;
  }
  e.geometry.setDrawRange(0, n * V);
  return n;
}

