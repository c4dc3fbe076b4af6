"""The page unpacks rows into plain geometry (``page/expand.js``) leaving out triangles of no area.

A star section's fill has thousands of triangles whose corners coincide at symmetric orientations
(9,875 of the great icosahedral 120-cell's 17,809 at its reset view): they cover no pixel and cost
three vertices each.  Here a triangles layer's rows of no area -- coincident corners, corners on a line,
in the kernel's float32 -- are not drawn and the others are, in their order (the kernel orders
them for blending); a triangle only small is drawn; layers without three corner columns (balls,
bars) draw every row in use.  The unpacking itself, frame by frame, is tested through the
companion in test_companion.py.
"""

from __future__ import annotations

import numpy as np

from page_node import run_page
from rot4d_widget.view import buffers as bf

SCRIPT = """
import { layerLayout, makeExpansion, fillExpansion } from "page:expand.js";
// three.js in miniature: the instanced geometry's parent class is the plain one
class BufferGeometry {
  constructor() { this.attributes = {}; this.drawRange = { start: 0, count: Infinity }; }
  addAttribute(name, a) { this.attributes[name] = a; return this; }
  setDrawRange(start, count) { this.drawRange = { start, count }; }
}
class InstancedBufferGeometry extends BufferGeometry {}
InstancedBufferGeometry.prototype.isInstancedBufferGeometry = true;
class BufferAttribute {
  constructor(array, itemSize) { this.array = array; this.itemSize = itemSize; this.version = 0; }
  set needsUpdate(v) { if (v) this.version++; }
}
const out = {};
const rows = Float32Array.from(INPUT.rows.flat());
for (const [name, layer] of Object.entries(INPUT.layers)) {
  const g = new InstancedBufferGeometry();
  g.addAttribute("position", new BufferAttribute(Float32Array.from(layer.template), 3));
  for (const [col, [offset, itemSize]] of Object.entries(layer.columns)) {
    g.addAttribute(col, { isInterleavedBufferAttribute: true, offset, itemSize });
  }
  const e = makeExpansion(g, layerLayout(g), INPUT.rows.length);
  const copied = fillExpansion(e, rows, INPUT.stride, INPUT.count);
  const n = e.geometry.drawRange.count;
  const attrs = {};
  for (const [col, a] of Object.entries(e.geometry.attributes)) attrs[col] = Array.from(a.array.slice(0, n * a.itemSize));
  out[name] = { copied, n, attrs };
}
console.log(JSON.stringify(out));
"""

FACE = {"tri_a": bf.COLUMNS["tri_a"], "tri_b": bf.COLUMNS["tri_b"], "tri_c": bf.COLUMNS["tri_c"],
        "tri_rgb": bf.COLUMNS["tri_rgb"]}
BAR = {"bar_a": bf.COLUMNS["bar_a"], "bar_b": bf.COLUMNS["bar_b"]}


def _rows():
    """Row i: triangle i of the list below (and a bar from row i's corner a to b), colour i."""
    p = np.array([0.3, -0.2, 1.1])
    x, y = np.array([0.5, 0.0, 0.0]), np.array([0.0, 0.4, 0.1])
    tris = [
        (p, p + x, p + y),              # 0 a triangle
        (p, p, p + y),                  # 1 two corners the same point
        (p, p, p),                      # 2 all three
        (p, p + x, p + 2 * x),          # 3 corners on a line
        (p, p + 1e-3 * x, p + 1e-3 * y),  # 4 small, not flat: drawn
        (p + y, p + x, p),              # 5 a triangle (the other way round)
        (p, p + x, p + x + 1e-9),       # 6 b and c the same point in float32
        (p, p + y, p + x),              # 7 past the count: not drawn
    ]
    rows = np.zeros((len(tris), bf.ROW_FLOATS), dtype=np.float32)
    for i, (a, b, c) in enumerate(tris):
        rows[i, 10:19] = np.concatenate([a, b, c])
        rows[i, 4:10] = np.concatenate([a, b])
        rows[i, 19] = i
    return rows


def test_a_triangles_layer_leaves_out_rows_of_no_area_and_keeps_the_order_of_the_others():
    rows = _rows()
    got = run_page(SCRIPT, {
        "rows": rows.tolist(), "stride": bf.ROW_FLOATS, "count": 7,
        "layers": {"faces": {"template": bf.triangle_template().ravel().tolist(), "columns": FACE},
                   "bars": {"template": bf.quad_template().ravel().tolist(), "columns": BAR}},
    })
    faces = got["faces"]
    kept = [0, 4, 5]
    assert faces["copied"] == len(kept) and faces["n"] == 3 * len(kept)
    for name, (offset, size) in FACE.items():
        want = np.repeat(rows[kept, offset:offset + size], 3, axis=0).ravel()
        np.testing.assert_array_equal(np.float32(faces["attrs"][name]), want, err_msg=name)
    np.testing.assert_array_equal(faces["attrs"]["position"], np.tile(bf.triangle_template().ravel(), len(kept)))
    # a layer without three corner columns draws every row in use, whatever is in it
    bars = got["bars"]
    assert bars["copied"] == 7 and bars["n"] == 7 * 6
    np.testing.assert_array_equal(np.float32(bars["attrs"]["bar_a"]), np.repeat(rows[:7, 4:7], 6, axis=0).ravel())
