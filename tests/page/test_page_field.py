"""The page's copy of a field (issue 36): which copy is offered, how it is quantised and laid out
in the 3-D texture, how it travels, and the page's geometry of a state against the kernel's
sampling grid (Node runs page/raycast.js)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from page_node import run_page
from test_companion import FakeScene, from_page

from rot4d_widget import Field4D
from rot4d_widget.core.rotation import random_rotation
from rot4d_widget.sources.field.slicing import box_polytope
from rot4d_widget.view import pagefield as pf
from rot4d_widget.view import transfer as tr
from rot4d_widget.view.companion import Companion
from rot4d_widget.view.cuts import grid_cut
from rot4d_widget.view.pagegeometry import polytope_message

pytestmark = pytest.mark.usefixtures("recording_comms")  # tests/conftest.py


def _blob(n=12, nw=9, axes="xyzw", dtype=np.float32):
    x = np.linspace(-1, 1, n)
    t = np.linspace(-1, 1, nw)
    X, Y, Z, T = np.meshgrid(x, x, x, t, indexing="ij")
    a = np.exp(-((X - 0.5 * T) ** 2 + Y ** 2 + Z ** 2) / 0.3).astype(dtype)
    return np.moveaxis(a, [0, 1, 2, 3], ["xyzw".index(c) for c in axes]) if axes != "xyzw" else a


def _texel_of(scalars, i, j, k, t):
    """Index of node (i, j, k) at time t in the texture (the shader's tileOrigin + p)."""
    nx, ny, nz, _ = scalars["shape"]
    tx, ty, _ = scalars["tiles"]
    W, H, _ = scalars["size"]
    kx, ky, kz = t % tx, (t // tx) % ty, t // (tx * ty)
    x, y, z = kx * nx + i, ky * ny + j, kz * nz + k
    return x + W * (y + H * z)


@pytest.mark.parametrize("axes", ["xyzw", "wzyx", "zwxy"])
def test_every_node_is_where_the_shader_reads_it_within_one_code(axes):
    a = _blob(axes=axes) * 7.0 - 2.0
    field = Field4D(a, axes=axes, extent=[(-1, 1)] * 4)
    meta, payload = pf.field_transfer(a, field.axis_of)
    sc = meta["scalars"]
    assert sc["shape"] == [12, 12, 12, 9] and not sc["masked"] and "mask" not in meta["arrays"]
    lo, hi = sc["range"]
    assert lo == pytest.approx(float(a.min())) and hi == pytest.approx(float(a.max()))
    tex = np.frombuffer(payload, dtype=np.uint8, count=meta["arrays"]["texels"]["length"],
                        offset=meta["arrays"]["texels"]["offset"]).reshape(-1, 2)
    assert len(tex) == math.prod(sc["size"])
    xyzw = np.transpose(a, [field.axis_of[j] for j in range(4)])
    rng = np.random.default_rng(1)
    for _ in range(200):
        i, j, k, t = (int(rng.integers(n)) for n in xyzw.shape)
        code = 256 * int(tex[_texel_of(sc, i, j, k, t), 0]) + int(tex[_texel_of(sc, i, j, k, t), 1])
        value = lo + code * (hi - lo) / pf.CODES
        assert abs(value - xyzw[i, j, k, t]) <= 0.5 * (hi - lo) / pf.CODES + 1e-6


PAIRED = """
import { decodeField, pairedTexels } from "page:field.js";
const bytes = Buffer.from(INPUT.payload, "base64");
const copy = decodeField(INPUT.meta, new Uint8Array(bytes.buffer, bytes.byteOffset, bytes.length));
console.log(JSON.stringify(Buffer.from(pairedTexels(copy)).toString("base64")));
"""


def test_the_page_s_texture_holds_each_node_beside_the_next_time_s():
    """page/field.js pairedTexels: the texel of node (i, j, k) at time t holds its code and time
    t + 1's (the last time's own again), as the shader's one read mixes them; the rest stays 0."""
    import base64

    a = _blob(nw=7) * 3.0 - 1.0  # 7 times of 12^3: tiles left over
    field = Field4D(a, axes="xyzw", extent=[(-1, 1)] * 4)
    meta, payload = pf.field_transfer(a, field.axis_of)
    sc = meta["scalars"]
    assert math.prod(sc["tiles"]) > 7
    tex = np.frombuffer(payload, dtype=np.uint8, count=meta["arrays"]["texels"]["length"],
                        offset=meta["arrays"]["texels"]["offset"]).reshape(-1, 2)
    got = np.frombuffer(base64.b64decode(run_page(PAIRED, {"meta": meta, "payload": base64.b64encode(payload).decode()})),
                        dtype=np.uint8).reshape(-1, 4)
    assert len(got) == len(tex)
    want = np.zeros_like(got)
    for t in range(7):
        for i, j, k in np.ndindex(12, 12, 12):
            at = _texel_of(sc, i, j, k, t)
            want[at, :2] = tex[at]
            want[at, 2:] = tex[_texel_of(sc, i, j, k, min(t + 1, 6))]
    assert np.array_equal(got, want)


RELEASED = """
import { fieldArrived, fieldTextures } from "page:field.js";
import { transferStore } from "page:transfer.js";
const b64 = (s) => { const b = Buffer.from(s, "base64"); return new Uint8Array(b.buffer, b.byteOffset, b.length); };
const model = { send() {}, get: (k) => (k === "page_data" ? { field: "f1", field_box: "b1" } : null) };
const store = transferStore(model);
store.done.set("field", { key: "f1", meta: INPUT.field.meta, bytes: b64(INPUT.field.payload) });
store.done.set("field_box", { key: "b1", meta: INPUT.box.meta, bytes: b64(INPUT.box.payload) });
const transfer = store.done.get("field").bytes.buffer;
const h = fieldArrived(model);
class T3 { constructor(data) { this.image = { data }; } dispose() {} }
const tex = fieldTextures(h, T3);
const again = fieldArrived(model);
console.log(JSON.stringify({
  same: again === h && fieldTextures(again, T3) === tex,
  storeBytes: store.done.get("field").bytes, storeKey: store.done.get("field").key,
  copy: [h.copy.texels, h.copy.mask, h.copy.blocks], masked: h.copy.masked, shape: h.copy.shape,
  own: Object.values(tex).map((t) => t.image.data.buffer !== transfer),
  mask: Buffer.from(tex.mask.image.data).toString("base64"),
  blocks: Buffer.from(tex.blocks.image.data).toString("base64"),
}));
"""


def test_the_transfer_s_bytes_go_once_the_textures_hold_the_copy():
    """page/field.js fieldTextures: the textures' arrays are their own (the mask and the block
    ranges copied out of the transfer, the data paired), and the transfer's bytes are let go -- the
    copy's and the store's -- its key kept, so the page neither asks for the same copy again nor
    decodes it again."""
    import base64

    from rot4d_widget.view.pagecut import polytope_transfer

    a = _blob(nw=5).astype(np.float64)
    a[1, 2, 3, 4] = np.nan  # a mask too
    field = Field4D(a, axes="xyzw", extent=[(-1, 1)] * 4)
    meta, payload = pf.field_transfer(a, field.axis_of)
    bmeta, bpayload = polytope_transfer(box_polytope(np.ones(4)))
    got = run_page(RELEASED, {"field": {"meta": meta, "payload": base64.b64encode(payload).decode()},
                              "box": {"meta": bmeta, "payload": base64.b64encode(bpayload).decode()}})
    assert got["same"] and got["storeKey"] == "f1" and got["storeBytes"] is None
    assert got["copy"] == [None, None, None] and got["masked"] and got["shape"] == [12, 12, 12, 5]
    assert got["own"] == [True, True, True]

    def array(name):
        m = meta["arrays"][name]
        return np.frombuffer(payload, dtype=np.uint8, count=m["length"], offset=m["offset"])

    assert np.array_equal(np.frombuffer(base64.b64decode(got["mask"]), np.uint8), array("mask"))
    assert np.array_equal(np.frombuffer(base64.b64decode(got["blocks"]), np.uint8), array("blocks"))


def test_values_that_are_not_finite_get_a_mask_and_do_not_widen_the_range():
    a = _blob().astype(np.float64)
    a[3, 4, 5, 2] = np.nan
    a[0, 0, 0, 0] = np.inf
    field = Field4D(a, axes="xyzw", extent=[(-1, 1)] * 4)
    meta, payload = pf.field_transfer(a, field.axis_of)
    sc = meta["scalars"]
    assert sc["masked"] and np.isfinite(sc["range"]).all()
    mask = np.frombuffer(payload, dtype=np.uint8, count=meta["arrays"]["mask"]["length"],
                         offset=meta["arrays"]["mask"]["offset"])
    assert mask[_texel_of(sc, 3, 4, 5, 2)] == 0 and mask[_texel_of(sc, 0, 0, 0, 0)] == 0
    assert mask[_texel_of(sc, 1, 1, 1, 1)] == 255 and (mask == 0).sum() == 2


def test_time_tiles_keep_the_texture_small():
    assert pf.tile_layout((64, 64, 64, 64)) == (4, 4, 4)  # 256 texels a side: WebGL2's minimum
    tx, ty, tz = pf.tile_layout((64, 64, 30, 200))
    assert tx * ty * tz >= 200 and max(64 * tx, 64 * ty, 30 * tz) <= pf.MAX_SIDE
    assert pf.tile_layout((48, 48, 48, 1)) == (1, 1, 1)
    with pytest.raises(ValueError, match="does not fit"):
        pf.tile_layout((2048, 2048, 2048, 2))


def _companion(monkeypatch):
    c = Companion(FakeScene())
    sent = []
    monkeypatch.setattr(c, "send", lambda msg, buffers=None: sent.append((msg, [bytes(b) for b in buffers or ()])))
    return c, sent


def test_the_data_in_memory_go_to_the_page_beyond_the_budget_its_coarse_copy(monkeypatch):
    c, _ = _companion(monkeypatch)
    field = Field4D(_blob(n=20, nw=20), axes="xyzw", extent=[(-1, 1)] * 4)
    c.page_field.sync(field)
    assert set(c.page_data) == {"field", "field_box"} and c.page_field.which == "data"
    assert c.page_field.shape == (20, 20, 20, 20)
    monkeypatch.setattr(pf, "PAGE_FIELD_BUDGET", 1000)
    c2, _ = _companion(monkeypatch)
    big = Field4D(_blob(n=60, nw=60), axes="xyzw", extent=[(-1, 1)] * 4)
    c2.page_field.sync(big)
    assert "field" not in c2.page_data  # the coarse copy is not made yet: nothing offered
    big.coarse()
    c2.page_field.sync(big)
    assert c2.page_field.which == "coarse" and c2.page_field.shape == (48, 48, 48, 48)


def test_a_function_s_field_stays_the_kernel_s(monkeypatch):
    c, _ = _companion(monkeypatch)
    field = Field4D.from_function(lambda x, y, z, w: x + w, extent=[(-1, 1)] * 4)
    c.page_field.sync(field)
    assert c.page_data == {} and not c.page_field.page_draws


def test_the_page_draws_once_it_holds_both_copies_it_was_offered(monkeypatch):
    c, _ = _companion(monkeypatch)
    field = Field4D(_blob(), axes="xyzw", extent=[(-1, 1)] * 4)
    c.page_field.sync(field)
    assert not c.page_field.page_draws
    from_page(c, {"event": "holds", "name": "field", "key": c.page_data["field"]})
    assert not c.page_field.page_draws
    from_page(c, {"event": "holds", "name": "field_box", "key": "old"})
    assert not c.page_field.page_draws
    from_page(c, {"event": "holds", "name": "field_box", "key": c.page_data["field_box"]})
    assert c.page_field.page_draws
    field.w_per_unit = 2.0  # another box: its tables again, the data not
    key = c.page_data["field"]
    c.page_field.sync(field)
    assert not c.page_field.page_draws and c.page_data["field"] == key


def test_a_paced_transfer_stays_two_chunks_ahead_of_the_page_and_counts_what_it_has(monkeypatch):
    monkeypatch.setattr(tr, "CHUNK_BYTES", 10)
    c, sent = _companion(monkeypatch)
    shown = []

    class Bar:
        def show(self, description, count, total, text):
            shown.append((description, count, total))

        def close(self, done):
            shown.append(("closed", done))

    c.transfers.bar = Bar()
    payload = bytes(range(55))
    c.transfers.offer("field", "k", {"arrays": {}}, payload, paced=True)
    from_page(c, {"event": "want", "name": "field", "key": "k"})
    assert [m["part"] for m, _ in sent] == [0, 1] and c.transfers.sending("field") == (0, 6)
    from_page(c, {"event": "got", "name": "field", "key": "k", "part": 0})
    assert [m["part"] for m, _ in sent] == [0, 1, 2]
    for part in range(1, 6):
        from_page(c, {"event": "got", "name": "field", "key": "k", "part": part})
    assert [m["part"] for m, _ in sent] == [0, 1, 2, 3, 4, 5]
    assert b"".join(b[0] for _, b in sent) == payload
    assert c.transfers.sending("field") is None and shown[-1] == ("closed", True)
    # a page that asks again (reloaded) gets it from the start
    from_page(c, {"event": "want", "name": "field", "key": "k"})
    assert [m["part"] for m, _ in sent[6:]] == [0, 1]


BOXES = """
import { decodePolytope } from "page:slicer.js";
import { fieldBoxes, indexAt, kernelGrid } from "page:raycast.js";
const msg = {};
for (const [k, v] of Object.entries(INPUT.box)) msg[k] = typeof v === "string" ? Buffer.from(v, "base64") : v;
const box = decodePolytope(msg);
const out = INPUT.states.map((s) => {
  const b = fieldBoxes(INPUT.cfg, box, INPUT.shape, s, { held: s.held });
  const first = (a, i) => Array.from(a.slice(108 * i, 108 * i + 3));  // box i's first vertex (36 a box)
  const lo = Array.from({ length: b.count }, (_, i) => first(b.arrays.a_lo, i));
  const span = Array.from({ length: b.count }, (_, i) => first(b.arrays.a_span, i));
  return { count: b.count, lo, span, cell: b.spacing, g: s.points.map((x) => indexAt(b, 0, x)),
           outline: Array.from(b.outline.points).length / 3 };
});
console.log(JSON.stringify(out));
"""


def _box_message(hw):
    import base64

    msg = polytope_message(box_polytope(hw))
    return {k: base64.b64encode(bytes(v)).decode() if isinstance(v, memoryview) else v for k, v in msg.items()}


def test_the_page_s_rays_start_on_the_kernel_s_grid_and_read_the_kernel_s_4d_points():
    shape = (12, 10, 14, 9)
    a = np.zeros(shape, dtype=np.float32)
    field = Field4D(a, axes="xyzw", extent=[(-1, 1), (-0.8, 0.8), (-1.2, 1.1), (0, 16)], w_per_unit=8.0,
                    resolution=40, coarse_resolution=20)
    scale = 0.7
    cfg = {"hw": list(field.half_widths), "origin": field.w_frame[0], "per_unit": field.w_frame[1], "scale": scale,
           "slices": [{"dc": 0.0, "centre": [0, 0, 0], "scale": 1.0}], "resolution": 40, "coarse_resolution": 20,
           "stack_nodes": 4 * 64 ** 3}
    rng = np.random.default_rng(3)
    states, want = [], []
    for k in range(6):
        m = np.eye(4) if k == 0 else random_rotation(rng)
        c0 = 8.0 + rng.uniform(-2, 2)
        held = bool(k % 2)
        grid = field.sample(m, c0, 20 if held else 40)
        pts = [list(grid.origin + grid.spacing * rng.uniform(0, 5, 3)) for _ in range(4)]
        q = field.to_data(np.asarray(pts), m, c0)  # data coordinates of those slice points
        e = np.asarray(field.extent)
        idx = (q - e[:, 0]) / (e[:, 1] - e[:, 0]) * (np.asarray(shape) - 1)
        states.append({"matrix": [float(x) for x in m.reshape(-1)], "c0": c0, "held": held,
                       "points": [[scale * v for v in p] for p in pts]})
        want.append((grid, idx))
    got = run_page(BOXES, {"box": _box_message(field.half_widths), "cfg": cfg, "shape": list(shape), "states": states})
    for (grid, idx), g in zip(want, got):
        assert g["count"] == 1 and g["outline"] >= 4
        assert np.allclose(g["lo"][0], scale * grid.origin, atol=1e-5)
        assert np.allclose(g["span"][0], scale * grid.spacing * (np.asarray(grid.values.shape) - 1), atol=1e-5)
        assert g["cell"][0] == pytest.approx(scale * grid.spacing, rel=1e-6)
        assert np.allclose(g["g"], idx, atol=2e-4)


def test_a_stack_s_boxes_are_placed_as_the_kernel_places_its_grids():
    from rot4d_widget.sources.tomography import StackSource

    field = Field4D(_blob(), axes="xyzw", extent=[(-1, 1)] * 4)
    stack = StackSource(field, slices=3, arrangement="grid")
    m = random_rotation(np.random.default_rng(5))
    c0 = field.w_frame[0] + 0.1
    scale = 0.9
    cut = grid_cut(stack, m, c0, False, __import__("threading").RLock(), scale)
    dc = stack.cuts_at(0.0)
    centres, scales = stack.layout()
    cfg = {"hw": list(field.half_widths), "origin": field.w_frame[0], "per_unit": field.w_frame[1], "scale": scale,
           "slices": [{"dc": float(dc[k]), "centre": [float(x) for x in centres[k]], "scale": float(scales[k])}
                      for k in range(3)],
           "resolution": field.resolution, "coarse_resolution": field.coarse_resolution, "stack_nodes": 4 * 64 ** 3}
    got = run_page(BOXES, {"box": _box_message(field.half_widths), "cfg": cfg, "shape": [12, 12, 12, 9],
                            "states": [{"matrix": [float(x) for x in m.reshape(-1)], "c0": c0, "held": False,
                                        "points": []}]})[0]
    assert got["count"] == 3
    for k, (_values, lo, span) in enumerate(cut.parts):
        assert np.allclose(got["lo"][k], lo, atol=1e-5) and np.allclose(got["span"][k], span, atol=1e-5)


def test_each_block_range_holds_every_node_of_its_cells():
    """A block's range is the least and greatest code of its BLOCK + 1 nodes a side (shared with the next
    block), so the shader may skip a block no level or colour reaches; a non-finite node opens it whole."""
    rng = np.random.default_rng(0)
    codes = rng.integers(0, pf.CODES + 1, (9, 7, 6, 10)).astype(np.uint16)
    lo, hi = pf.block_ranges(codes)
    assert lo.shape == (2, 2, 2, 3)
    B = pf.BLOCK
    for idx in np.ndindex(lo.shape):
        part = codes[tuple(slice(b * B, min(b * B + B, n - 1) + 1) for b, n in zip(idx, codes.shape))]
        assert lo[idx] == part.min() and hi[idx] == part.max()
    bad = np.zeros(codes.shape, dtype=bool)
    bad[4, 0, 0, 0] = True  # a node two blocks share along w
    lo, hi = pf.block_ranges(codes, bad)
    assert (lo[:, 0, 0, 0] == 0).all() and (hi[:, 0, 0, 0] == pf.CODES).all() and hi[0, 1, 1, 1] < pf.CODES + 1


def test_a_stack_coloured_by_w_gives_every_level_a_colour(make):
    """A field stack coloured by w sends no level colours (its boxes carry them): the page must
    still give each level one, or the shader's uniforms fail on every frame (CI: a TypeError from
    FieldPicture.uniforms for a 3-slice stack with its projection)."""
    from rot4d_widget.view.fieldview import field_config

    field = Field4D(_blob(), axes="xyzw", extent=[(-1, 1)] * 4, levels=[0.2, 0.5])
    w = make(field, slices=3)
    cfg = field_config(w.source, w._showing.scale, field, cmap=w.cmap, clim=w.clim, color_by=w.color_by,
                       cast_clim=None, default_clim_=[0.0, 1.0], texture_side=64, painted=w._painter.colours())
    assert cfg["level_rgb"] == [] and cfg["box_rgb"]
    got = run_page(LEVEL_COLOURS, {"cfg": cfg, "levels": [0.2, 0.5]})
    assert len(got) == 2 and all(len(c) == 3 and all(isinstance(x, (int, float)) for x in c) for c in got)


LEVEL_COLOURS = """
import { levelColours } from "page:fieldpicture.js";
console.log(JSON.stringify(levelColours(INPUT.cfg, INPUT.levels)));
"""
