"""The page cuts polytopes itself, array for array as the kernel does (issue 34).

``page/slicer.js`` gets a polytope as the kernel sends it (`rot4d_widget.view.pagegeometry.
polytope_message`, its arrays as bytes: base64 here, DataViews in the page) and slices it under
Node; every array is compared with `slice_polytope`'s: vertices, edges, polygons and their corner
order, cell ids, fan triangles, volume and dimension.  Unturned, at c0 = 0 and at every distinct
vertex height, the page's numbers are the kernel's exactly; turned (numpy's BLAS fuses
multiply-adds, the page does not), the vertices agree within 1e-12 of the circumradius and the
volumes within 1e-12 relative, and every index array exactly.  The cases reach every row of the
slicer's case table: faces and cells lying in H, faces inside a non-convex slice (`_faces_in_h`),
vertices on H and edges in H inside the slice (kept, issue 33), H touching in a face, an edge or a
vertex, missing, a face almost parallel to H (the fallback to exact signs), and polytopes scaled
by 1e-100 and 1e100 (the power-of-two `unit`).  ``page/rows.js`` builds the scene's row table bit
for bit as `slice_rows` (the triangles ordered for blending from an eye, convex or not).
"""

from __future__ import annotations

import base64
import math

import numpy as np
import pytest
from mesh_shapes import stellated_tesseract_mesh, tesseract_union, tesseract_union_mesh
from page_node import run_page
from test_slicing import check_against_halfspaces, check_closed_ccw_surface

from rot4d_widget import Polytope
from rot4d_widget.core.rotation import random_rotation, simple_rotation
from rot4d_widget.geometry.slicing import single_level
from rot4d_widget.geometry.catalogue import polytope
from rot4d_widget.geometry.slicing.tables import Slice
from rot4d_widget.geometry.slicing.polytope_slice import slice_polytope
from rot4d_widget.sources.protocol import PolytopeSource, SliceData
from rot4d_widget.view.buffers import ball_count, group_palette, pack_rgb, rows_needed, slice_rows
from rot4d_widget.view.pagegeometry import polytope_message, polytope_message_bytes

SLICE_SCRIPT = """
import { decodePolytope, slicePolytope } from "page:slicer.js";
const out = INPUT.map((c) => {
  const msg = { ...c.msg };
  for (const k of c.binary) msg[k] = Buffer.from(msg[k], "base64");
  const p = decodePolytope(msg);
  return c.cases.map(([m, c0]) => {
    const s = slicePolytope(p, m, c0);
    const r = { volume: s.volume, dim: s.dim };
    for (const k of ["vertices", "edges", "flat", "offsets", "cellIds", "triangles", "triangleCells"]) {
      r[k] = Array.from(s[k]);
    }
    return r;
  });
});
console.log(JSON.stringify(out));
"""

# Python's name of each array the page returns
ARRAYS = {"edges": "edges", "flat": "polygon_indices", "offsets": "polygon_offsets", "cellIds": "cell_ids",
          "triangles": "triangles", "triangleCells": "triangle_cells"}
IDENTITY = np.eye(4)
NAMES = ["5-cell", "8-cell", "16-cell", "24-cell", "120-cell", "600-cell"]


def wire(p) -> dict:
    """`polytope_message` as it reaches Node: binary arrays in base64, named in ``binary``."""
    msg = polytope_message(p)
    binary = [k for k, v in msg.items() if isinstance(v, memoryview)]
    return {"msg": {k: base64.b64encode(bytes(v)).decode() if k in binary else v for k, v in msg.items()},
            "binary": binary}


def cases(p, seed, turns=3):
    """(matrix, c0) pairs: unturned at 0 and at every distinct vertex height; ``turns`` random
    orientations each at a random level and at the height of a turned vertex, exactly."""
    out = [(IDENTITY, 0.0)] + [(IDENTITY, float(h)) for h in np.unique(np.asarray(p.vertices)[:, 3])]
    rng = np.random.default_rng(seed)
    for _ in range(turns):
        m = random_rotation(rng)
        w = (np.asarray(p.vertices) @ m.T)[:, 3]
        out += [(m, float(rng.uniform(-1, 1) * p.circumradius)), (m, float(w[rng.integers(len(w))]))]
    return out


class Paths:
    """What the kernel's slicer did over the cases (spies on its steps): dimensions seen, slices
    cut again with exact signs, faces lying in H left out of S."""

    def __init__(self, monkeypatch):
        self.dims, self.exact_signs, self.faces_inside = set(), 0, 0
        cut, faces = single_level._slice, single_level._faces_in_h

        def spy_cut(t, x, m, c0, tol):
            self.exact_signs += tol == 0.0
            return cut(t, x, m, c0, tol)

        def spy_faces(*args):
            keep, outward = faces(*args)
            self.faces_inside += int((~keep).sum())
            return keep, outward

        monkeypatch.setattr(single_level, "_slice", spy_cut)
        monkeypatch.setattr(single_level, "_faces_in_h", spy_faces)


def compare(groups, paths=None) -> list:
    """Slice every (polytope, cases) of ``groups`` in Node and in Python and compare them (turned
    vertices within 1e-12 of the circumradius); the page's slices, per group and case."""
    page = run_page(SLICE_SCRIPT, [{**wire(p), "cases": [(np.asarray(m).reshape(-1).tolist(), c0) for m, c0 in cs]}
                                   for p, cs in groups])
    worst = 0.0
    for (p, cs), got in zip(groups, page):
        for (m, c0), g in zip(cs, got):
            s = slice_polytope(p, m, c0)
            where = f"{p.name} at c0 = {c0!r}" + ("" if m is IDENTITY else " (turned)")
            if paths is not None:
                paths.dims.add(s.dim)
            for js, py in ARRAYS.items():
                assert g[js] == getattr(s, py).reshape(-1).tolist(), f"{where}: {js}"
            assert g["dim"] == s.dim, where
            v = np.asarray(g["vertices"], dtype=np.float64).reshape(-1, 3)
            assert v.shape == s.vertices.shape, where
            volume = math.inf if g["volume"] is None else g["volume"]  # JSON has no inf
            if m is IDENTITY:
                assert np.array_equal(v, s.vertices), where
                assert volume == s.volume, where
            else:
                if len(v):
                    worst = max(worst, float(np.abs(v - s.vertices).max()) / p.circumradius)
                assert volume == pytest.approx(s.volume, rel=1e-12, abs=0.0), where
    assert worst <= 1e-12, worst
    return page


def test_the_regular_six(monkeypatch):
    paths = Paths(monkeypatch)
    eight = polytope("8-cell")
    on_top = simple_rotation("xw", math.pi / 4)  # a square on top
    edge_top = simple_rotation("yw", math.atan(1 / math.sqrt(2))) @ on_top  # an edge on top
    special = [(m, float((np.asarray(eight.vertices) @ m.T)[:, 3].max())) for m in (on_top, edge_top)]
    special.append((IDENTITY, 1.5))  # misses it
    compare([(polytope(n), cases(polytope(n), seed)) for seed, n in enumerate(NAMES)] + [(eight, special)], paths)
    assert paths.dims == {-1, 0, 1, 2, 3}  # missed; touching in a vertex, an edge, a face; solid


def test_vertex_heights_of_turned_polytopes():
    """test_slicing's vertex-height property on the page's slices: 20 random orientations of each
    regular polytope, cut exactly at the height of one of its turned vertices, give a closed,
    outward surface holding that vertex once, of the volume the half-spaces give."""
    rng = np.random.default_rng(11)
    groups = []
    for name in NAMES:
        p, hits = polytope(name), []
        for _ in range(20):
            m = random_rotation(rng)
            k = int(rng.integers(len(p.vertices)))
            hits.append((m, float((np.asarray(p.vertices) @ m.T)[k, 3]), k))
        groups.append((p, hits))
    page = compare([(p, [(m, c0) for m, c0, _ in hits]) for p, hits in groups])
    for (p, hits), got in zip(groups, page):
        for (m, c0, k), g in zip(hits, got):
            s = Slice(np.reshape(g["vertices"], (-1, 3)), np.reshape(g["edges"], (-1, 2)), np.asarray(g["flat"]),
                      np.asarray(g["offsets"]), np.asarray(g["cellIds"]), np.reshape(g["triangles"], (-1, 3)),
                      np.asarray(g["triangleCells"]), g["volume"], g["dim"])
            if s.dim == 3:
                check_closed_ccw_surface(s)
                x = (np.asarray(p.vertices) @ m.T)[k, :3]
                assert np.sum(np.linalg.norm(s.vertices - x, axis=1) < 1e-9) == 1
            check_against_halfspaces(p.name, m, c0, s)


def test_uniform_polychora():
    names = ["rectified 5-cell", "truncated tesseract", "runcinated tesseract", "cantellated 24-cell",
             "snub 24-cell", "grand antiprism", "bitruncated 120-cell", "5-7 duoprism", "icosahedral prism",
             "12-antiprismatic prism"]
    compare([(polytope(n), cases(polytope(n), seed)) for seed, n in enumerate(names)])


def test_the_omnitruncated_120_cell():
    p = polytope("omnitruncated 120-cell")
    compare([(p, cases(p, 7, turns=4))])


def test_scaled_by_powers_of_ten():
    groups = []
    for scale in (1e-100, 1e100):
        for name in ("8-cell", "24-cell"):
            q = polytope(name)
            p = Polytope(np.asarray(q.vertices) * scale, [f.tolist() for f in q.faces], q.cells,
                         name=f"{name} x {scale}")
            assert p.unit != 1.0
            groups.append((p, cases(p, 3)))
    compare(groups)


def _nonconvex():
    out = [tesseract_union(shape)[0] for shape in ("L", "ring", "tripod", "staircase")]
    v, f, c, _ = stellated_tesseract_mesh(2.0)  # reflex ridges
    out.append(Polytope(v, f, c, name="stellated tesseract"))
    v, f, c, _ = tesseract_union_mesh([(0, 0, 0, 0), (0, 0, 0, 3)], centre=False)  # two pieces apart in w
    out.append(Polytope(v, f, c, name="two tesseracts"))
    out += [polytope("grand 600-cell"), polytope("icosahedral 120-cell")]  # convex cells, winding round
    return out


def test_nonconvex_polytopes_with_convex_cells(monkeypatch):
    paths = Paths(monkeypatch)
    groups = []
    for seed, p in enumerate(_nonconvex()):
        assert p.star is None and not p.convex
        groups.append((p, cases(p, seed)))
    compare(groups, paths)
    assert paths.faces_inside  # faces inside S


def test_faces_almost_parallel_to_h_are_cut_with_exact_signs(monkeypatch):
    """A pentagon tilted by less than the tolerance: its chord has three ends under the tolerance,
    so the kernel cuts again by exact signs (`Inconsistent`); the page does the same."""
    p = polytope("dodecahedral prism")
    top = float(np.asarray(p.vertices)[:, 3].max())
    tol = 1e-9 * p.circumradius
    rng = np.random.default_rng(0)
    paths = Paths(monkeypatch)
    found = []
    for _ in range(200):
        a = rng.standard_normal(3) * tol * rng.uniform(0.2, 3) / p.circumradius
        m = simple_rotation("xw", a[0]) @ simple_rotation("yw", a[1]) @ simple_rotation("zw", a[2])
        c0 = top + float(rng.uniform(-1.5, 1.5)) * tol
        before = paths.exact_signs
        slice_polytope(p, m, c0)
        if paths.exact_signs > before:
            found.append((m, c0))
    assert len(found) >= 5
    compare([(p, found)])


def test_slice_data_is_what_the_source_returns():
    """`sliceData` = `PolytopeSource.slice`: points, segments, triangles, groups, no fill corners,
    the volume (None where it left float64's range: scaled by 1e150 or 1e-150), convex."""
    script = """
    import { decodePolytope, sliceData } from "page:slicer.js";
    console.log(JSON.stringify(INPUT.map((c) => {
      const msg = { ...c.msg };
      for (const k of c.binary) msg[k] = Buffer.from(msg[k], "base64");
      const d = sliceData(decodePolytope(msg), c.matrix, c.c0);
      return { points: Array.from(d.points), segments: Array.from(d.segments), triangles: Array.from(d.triangles),
               groups: Array.from(d.groups), cornerOnly: d.cornerOnly, volume: d.volume, convex: d.convex };
    })));
    """
    eight = polytope("8-cell")
    big, small = (Polytope(np.asarray(eight.vertices) * s, [f.tolist() for f in eight.faces], eight.cells)
                  for s in (1e150, 1e-150))
    runs = [(polytope("24-cell"), 0.0), (polytope("24-cell"), math.sqrt(2)), (tesseract_union("L")[0], 0.25),
            (big, 0.0), (small, 0.0)]
    page = run_page(script, [{**wire(p), "matrix": IDENTITY.reshape(-1).tolist(), "c0": c0} for p, c0 in runs])
    for (p, c0), got in zip(runs, page):
        d = PolytopeSource(p).slice(IDENTITY, c0)
        assert got["points"] == d.points.reshape(-1).tolist()
        for name in ("segments", "triangles", "groups"):
            assert got[name] == getattr(d, name).reshape(-1).tolist(), name
        assert got["cornerOnly"] is None and d.corner_only is None
        assert got["volume"] == d.volume and got["convex"] == d.convex
    assert page[3]["volume"] is None and page[4]["volume"] is None  # inf; underflowed


def test_the_message_decodes_from_any_view_of_its_bytes():
    """As anywidget delivers buffers (DataViews, here at an odd offset into a larger buffer), as
    bare ArrayBuffers, or as Node Buffers: one decoding, the same slice."""
    script = """
    import { decodePolytope, slicePolytope } from "page:slicer.js";
    const forms = {
      buffer: (b) => b,
      arraybuffer: (b) => b.buffer.slice(b.byteOffset, b.byteOffset + b.byteLength),
      dataview: (b) => {
        const big = new Uint8Array(b.byteLength + 3);
        big.set(b, 1);
        return new DataView(big.buffer, 1, b.byteLength);
      },
    };
    const out = {};
    for (const [name, form] of Object.entries(forms)) {
      const msg = { ...INPUT.msg };
      for (const k of INPUT.binary) msg[k] = form(Buffer.from(msg[k], "base64"));
      const s = slicePolytope(decodePolytope(msg), INPUT.matrix, 0.1);
      out[name] = [Array.from(s.vertices), Array.from(s.flat), s.volume];
    }
    console.log(JSON.stringify(out));
    """
    p = polytope("24-cell")
    m = random_rotation(np.random.default_rng(2))
    out = run_page(script, {**wire(p), "matrix": m.reshape(-1).tolist()})
    assert out["buffer"] == out["arraybuffer"] == out["dataview"]
    assert out["buffer"][1] == slice_polytope(p, m, 0.1).polygon_indices.tolist()


def test_the_message_and_what_the_page_refuses():
    """Sent once: the omnitruncated 120-cell's tables are 2.4 MB.  The page refuses a star
    polytope by name, and a message whose arrays do not fit its counts, naming the array."""
    assert polytope_message_bytes(polytope_message(polytope("omnitruncated 120-cell"))) < 2.5e6
    p = polytope("24-cell")
    msg, inc = polytope_message(p), p.incidence
    for name in ("face_ptr", "face_vidx", "face_eidx", "cell_vptr", "cell_vidx", "cell_eptr", "cell_eidx"):
        assert np.array_equal(np.frombuffer(msg[name], "<i4"), getattr(inc, name)), name
    assert np.array_equal(np.frombuffer(msg["vertices"], "<f8").reshape(-1, 4), p.unit_vertices)
    script = """
    import { decodePolytope, slicePolytope } from "page:slicer.js";
    const errors = INPUT.map((c) => {
      const msg = { ...c.msg };
      for (const k of c.binary) msg[k] = Buffer.from(msg[k], "base64");
      if (c.cut) msg[c.cut] = msg[c.cut].subarray(4);
      if (c.bad) msg[c.bad] = Buffer.from(new Int32Array(msg[c.bad].length / 4).fill(1e6).buffer);
      try { slicePolytope(decodePolytope(msg), Array.from({ length: 16 }, (_, i) => +(i % 5 === 0)), 0); return null; }
      catch (e) { return e.message; }
    });
    console.log(JSON.stringify(errors));
    """
    star, five = polytope("great grand stellated 120-cell"), polytope("5-cell")
    errors = run_page(script, [wire(star), {**wire(five), "cut": "cell_normals"}, {**wire(five), "bad": "face_vidx"},
                               wire(five)])
    assert "great grand stellated 120-cell has star faces or non-convex cells" in errors[0]
    assert "cell_normals has 156 bytes, expected 20 x 8" in errors[1]
    assert "face_vidx[0] = 1000000 is not in [0, 5)" in errors[2]
    assert errors[3] is None


ROWS_SCRIPT = """
import { decodePolytope, sliceData } from "page:slicer.js";
import { sliceRows } from "page:rows.js";
const typed = (b64, T) => {
  const u = Buffer.from(b64, "base64");
  return new T(u.buffer.slice(u.byteOffset, u.byteOffset + u.byteLength));
};
console.log(JSON.stringify(INPUT.map((c) => {
  let data;
  if (c.polytope) {  // the page's own slice
    const msg = { ...c.polytope.msg };
    for (const k of c.polytope.binary) msg[k] = Buffer.from(msg[k], "base64");
    data = sliceData(decodePolytope(msg), c.matrix, c.c0);
  } else {  // the kernel's slice, its very bytes
    data = { points: typed(c.points, Float64Array), segments: typed(c.segments, Int32Array),
             triangles: typed(c.triangles, Int32Array), groups: typed(c.groups, Int32Array), convex: c.convex,
             cornerOnly: c.cornerOnly, showPoints: c.showPoints };
  }
  const { rows, counts } = sliceRows(data, c.options);
  return { rows: Buffer.from(rows.buffer).toString("base64"), counts };
})));
"""


def _b64(a, dtype) -> str:
    return base64.b64encode(np.ascontiguousarray(a, dtype=dtype).tobytes()).decode()


def _rows_case(data, *, scale, n_groups=None, capacity=None, eye=None, single_rgb=None):
    """(what Node gets, slice_rows's table): the slice's arrays as bytes, the options as the page
    takes them (colours packed, as `pack_rgb` packs them)."""
    palette = None if n_groups is None else group_palette(n_groups)
    want = slice_rows(data, scale=scale, group_rgb=palette, capacity=capacity, eye=eye, single_rgb=single_rgb)
    corner = getattr(data, "corner_only", None)
    case = {"points": _b64(data.points, "<f8"), "segments": _b64(data.segments, "<i4"),
            "triangles": _b64(data.triangles, "<i4"), "groups": _b64(data.groups, "<i4"), "convex": bool(data.convex),
            "cornerOnly": None if corner is None else corner.tolist(), "showPoints": bool(data.show_points),
            "options": {"scale": scale, "capacity": capacity, "eye": None if eye is None else list(eye),
                        "palette": None if palette is None else pack_rgb(palette).tolist(),
                        "singleRgb": None if single_rgb is None else float(pack_rgb([single_rgb])[0])}}
    return case, want, data


def _check_rows(cases):
    """Each case's rows from Node equal ``slice_rows``'s bit for bit (signed zeros too), and its
    counts are the balls, bars and triangles of the slice."""
    page = run_page(ROWS_SCRIPT, [c for c, _, _ in cases])
    for i, ((_, want, data), got) in enumerate(zip(cases, page)):
        rows = np.frombuffer(base64.b64decode(got["rows"]), dtype="<f4")
        assert rows.shape == (want.size,), f"case {i}: {rows.size // 20} rows, expected {len(want)}"
        bad = np.flatnonzero(rows.view("<u4") != want.reshape(-1).view(np.uint32))
        assert not len(bad), f"case {i}: {len(bad)} floats differ, the first in row {bad[0] // 20} column {bad[0] % 20}"
        assert got["counts"] == [ball_count(data), len(data.segments), len(data.triangles)]


def test_rows_bit_for_bit():
    """Convex slices (away-facing triangles first) and non-convex ones (farthest first) seen from
    an eye, one colour for all, spare capacity, fill corners without balls, no balls at all."""
    rng = np.random.default_rng(5)
    cases = []
    for name, c0 in (("24-cell", 0.3), ("omnitruncated 120-cell", 2.0), ("grand 600-cell", 0.1)):
        src = PolytopeSource(name)
        data = src.slice(random_rotation(rng), c0)
        direction = rng.standard_normal(3)
        eye = tuple(5.0 * direction / np.linalg.norm(direction))  # outside the slice, drawn 1.7 across
        cases.append(_rows_case(data, scale=1.7 / src.size, n_groups=src.n_groups, eye=eye,
                                capacity=rows_needed(data) + 5))
    src = PolytopeSource(tesseract_union("L")[0])
    data = src.slice(random_rotation(rng), 0.1)
    cases.append(_rows_case(data, scale=0.4, n_groups=src.n_groups, eye=(0.5, -2.0, 3.0)))
    cases.append(_rows_case(data, scale=0.4, single_rgb=(0.2, 0.6, 1.0)))
    fill = SliceData.build(rng.standard_normal((6, 3)), [[0, 1], [1, 2]], [[0, 1, 2], [3, 4, 5], [0, 2, 5]], [0, 1, 0],
                           corner_only=[False, False, True, False, True, False])
    cases.append(_rows_case(fill, scale=2.0, n_groups=2, eye=(1.0, 1.0, 1.0)))
    bare = SliceData.build(rng.standard_normal((4, 3)), [[0, 1]], [[0, 1, 2]], [0], show_points=False)
    cases.append(_rows_case(bare, scale=1.0, n_groups=1))
    _check_rows(cases)


def test_rows_of_the_pages_own_slice_are_the_kernels():
    """Unturned, the page's slice and rows are the kernel's: the whole path, bit for bit."""
    cases = []
    for p, c0, eye in ((polytope("24-cell"), 0.0, [0.3, -2.0, 5.0]), (tesseract_union("L")[0], 0.25, [2.0, 1.0, -4.0]),
                       (polytope("120-cell"), 1.0, [-3.0, 0.5, 0.5])):
        src = PolytopeSource(p)
        case, want, data = _rows_case(src.slice(IDENTITY, c0), scale=1.3, n_groups=src.n_groups, eye=eye)
        cases.append(({"polytope": wire(p), "matrix": IDENTITY.reshape(-1).tolist(), "c0": c0,
                       "options": case["options"]}, want, data))
    _check_rows(cases)
