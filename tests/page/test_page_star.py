"""The page's points and segments of polytopes with star faces or non-convex cells (issue 34).

While it predicts such a polytope the page draws balls and bars only (its fills are the
kernel's): ``page/slicer.js`` ``sliceStarEdges`` (``page/starslicer.js``) gives the slice's points
and segments as `rot4d_widget.geometry.slicing.star.slice_star` makes them, before the fill corners
(`Slice.n_fill`).  Compared under Node with `slice_polytope` on every polytope with ``star`` that
the package builds or tests/data/off_library holds (the seven regular star polychora with star
faces or cells -- the other three of the ten have convex faces and cells, and the page cuts them
whole -- and the library's star files): unturned at c0 = 0 and at every distinct vertex height
(40 of them from 600 vertices on), points and segments exactly; turned (numpy's BLAS fuses
multiply-adds, the page does not) in three orientations at vertex heights and at a random level,
segments and dimension exactly and points within 1e-12 of the circumradius; the volume too (it
picks the side of a cell lying in H), exactly unturned.  The page's slices of every non-convex
polytope pass test_vertex_heights' property against its oracle, at its levels.  ``python
tests/page/test_page_star.py`` compares the page with the kernel at every level of that property test
and prints the worst deviation.
"""

from __future__ import annotations

import base64

import numpy as np
import pytest
import test_vertex_heights as vh
from page_node import run_page
from test_page_slicer import wire

from rot4d_widget import Polytope
from rot4d_widget.core.rotation import random_rotation
from rot4d_widget.geometry.slicing import star
from rot4d_widget.geometry.catalogue import polytope
from rot4d_widget.geometry.slicing.tables import tables
from rot4d_widget.geometry.slicing.polytope_slice import slice_polytope
from rot4d_widget.geometry.slicing.star import star_tables
from rot4d_widget.sources.protocol import PolytopeSource, _volume_or_none
from rot4d_widget.view.buffers import slice_rows
from rot4d_widget.view.pagegeometry import polytope_message

# the page's slice of each case: sliceStarEdges for a star polytope, sliceData's points and
# segments for another (its cells convex); arrays as base64 bytes (exact)
SCRIPT = """
import { decodePolytope, sliceData, sliceStarEdges } from "page:slicer.js";
const b64 = (a) => Buffer.from(a.buffer, a.byteOffset, a.byteLength).toString("base64");
console.log(JSON.stringify(INPUT.map((c) => {
  const msg = { ...c.msg };
  for (const k of c.binary) msg[k] = Buffer.from(msg[k], "base64");
  const p = decodePolytope(msg);
  return c.cases.map(([m, c0]) => {
    const s = p.star ? sliceStarEdges(p, m, c0) : sliceData(p, m, c0);
    return { points: b64(s.points), segments: b64(s.segments), triangles: s.triangles.length, volume: s.volume,
             dim: p.star ? s.dim : s.slice.dim };
  });
})));
"""

IDENTITY = np.eye(4)


def _stars():
    return [pytest.param(kind, name, id=name.removesuffix(".off"))
            for kind, name in vh._names() if vh._polytope(kind, name).star is not None]


def page_slices(groups) -> list:
    """[(polytope, [(matrix, c0), ...]), ...] -> the page's slices: per group, per case, {points (n, 3),
    segments (m, 2), triangles (count), volume, dim}."""
    page = run_page(SCRIPT, [{**wire(p), "cases": [(np.asarray(m).reshape(-1).tolist(), c0) for m, c0 in cs]}
                             for p, cs in groups])
    for got in page:
        for g in got:
            g["points"] = np.frombuffer(base64.b64decode(g["points"]), "<f8").reshape(-1, 3)
            g["segments"] = np.frombuffer(base64.b64decode(g["segments"]), "<i4").reshape(-1, 2)
    return page


def compare(p, cases) -> float:
    """The page's slices of ``p`` at ``cases`` = the kernel's points (before its fill corners), edges,
    dimension and volume (as PolytopeSource gives it); the worst turned point's deviation over the
    circumradius."""
    worst = 0.0
    for (m, c0), g in zip(cases, page_slices([(p, cases)])[0]):
        s = slice_polytope(p, m, c0)
        where = f"{p.name} at c0 = {c0!r}" + ("" if m is IDENTITY else " (turned)")
        want = s.vertices[: len(s.vertices) - s.n_fill]
        assert g["points"].shape == want.shape, where
        assert np.array_equal(g["segments"], s.edges), where
        assert g["dim"] == s.dim and g["triangles"] == 0, where
        volume = _volume_or_none(s)
        if m is IDENTITY:
            assert np.array_equal(g["points"], want), where
            assert g["volume"] == volume, where
        else:
            if len(want):
                worst = max(worst, float(np.abs(g["points"] - want).max()) / p.circumradius)
            assert (g["volume"] is None) == (volume is None), where
            if volume is not None:
                assert g["volume"] == pytest.approx(volume, rel=1e-12, abs=1e-12 * p.circumradius ** 3), where
    return worst


def compared_cases(p) -> list:
    """Unturned at c0 = 0 and at every distinct vertex height (exactly; 40 of them, seeded, from
    test_vertex_heights' `BIG` vertices on); in its three orientations, at 8 of the turned vertices'
    heights (exactly, seeded) and a random level."""
    heights = np.unique(np.asarray(p.vertices)[:, 3])
    if len(p.vertices) >= vh.BIG:
        heights = np.sort(np.random.default_rng(0).choice(heights, min(40, len(heights)), replace=False))
    out = [(IDENTITY, 0.0)] + [(IDENTITY, float(h)) for h in heights]
    for seed in vh.SEEDS:
        m = random_rotation(seed)
        rng = np.random.default_rng(seed)
        w = (np.asarray(p.vertices) @ m.T)[:, 3]
        out += [(m, float(c)) for c in rng.choice(w, 8, replace=False)]
        out.append((m, float(rng.uniform(-1, 1) * p.circumradius)))
    return out


@pytest.mark.parametrize("kind, name", _stars())
def test_points_and_segments_are_the_kernels(kind, name):
    p = vh._polytope(kind, name)
    assert compare(p, compared_cases(p)) <= 1e-12


@pytest.mark.parametrize("kind, name", vh._cases())
def test_the_pages_slices_pass_the_vertex_height_property(kind, name):
    """test_vertex_heights' property and oracle on the page's slices, at its levels: every point of
    P ∩ H is a point of the slice and every edge lying in H an edge of it (star or not)."""
    p = vh._polytope(kind, name)
    cases = [(m, c0) for _, m, levels in vh._turns(p) for c0 in levels]
    problems = [why for (m, c0), g in zip(cases, page_slices([(p, cases)])[0])
                if (why := vh.points_mismatch(p, m, c0, g["points"], g["segments"]))]
    assert not problems, f"{len(problems)} levels:\n" + "\n".join(problems[:12])


def test_scaled_by_powers_of_ten():
    """The unit scale (a power of two) as the kernel's: scaled by 1e-100 and 1e100 the page's slices
    are the kernel's; by 1e149 and 1e-149 the volume leaves float64's range (None, as the source's)."""
    q = polytope("small stellated 120-cell")
    m = random_rotation(5)
    for scale in (1e-100, 1e100, 1e149, 1e-149):
        p = Polytope(np.asarray(q.vertices) * scale, [f.tolist() for f in q.faces], q.cells, name=f"{q.name} x {scale}")
        w = np.unique(np.asarray(p.vertices)[:, 3])
        compare(p, [(IDENTITY, 0.0)] + [(IDENTITY, float(c)) for c in w[::3]] + [(m, 0.1 * scale)])
        if abs(np.log10(scale)) > 120:
            assert _volume_or_none(slice_polytope(p, IDENTITY, 0.0)) is None


def test_the_kernels_paths_are_reached(monkeypatch):
    """The compared cases reach slice_star's every outcome: a cut with no polygon left (H touching
    at a top vertex: `touching`'s slice), a cell lying in H cut from the side of the larger volume
    (and two sides of exactly equal volume, the first kept: 17-tho at c0 = 0, whose points and
    segments are the same from either side), points at equal places along a face's line (ordered
    by how they move: numpy's lexsort).  The page's slices there are the kernel's."""
    seen = {"touching": 0, "side below": 0, "equal volumes": 0, "ties along a line": 0}
    cut, lexsort = star._cut, np.lexsort
    calls = []

    def spy_cut(*args):
        calls.append(cut(*args))
        return calls[-1]

    def spy_lexsort(keys):
        seen["ties along a line"] += 1
        return lexsort(keys)

    monkeypatch.setattr(star, "_cut", spy_cut)
    monkeypatch.setattr(star.np, "lexsort", spy_lexsort)
    for kind, name in (("star", "small stellated 120-cell"), ("off", "pardesco/17-tho.off"),
                       ("off", "pardesco/60-ihi.off")):
        p = vh._polytope(kind, name)
        for c0 in [0.0] + vh.vertex_heights(p, IDENTITY):
            calls.clear()
            s = slice_polytope(p, IDENTITY, c0)
            seen["touching"] += calls[0] is None and s.dim < 3
            if len(calls) == 2 and calls[1] is not None:
                a, b = calls
                seen["side below"] += a is None or abs(b.volume) > abs(a.volume)
                seen["equal volumes"] += a is not None and abs(a.volume) == abs(b.volume)
    monkeypatch.undo()
    assert all(seen.values()), seen
    for kind, name in (("star", "small stellated 120-cell"), ("off", "pardesco/17-tho.off"),
                       ("off", "pardesco/60-ihi.off")):
        p = vh._polytope(kind, name)
        compare(p, [(IDENTITY, c0) for c0 in [0.0] + vh.vertex_heights(p, IDENTITY)])


def test_rows_draw_the_kernels_balls_and_bars():
    """rows.js draws the page's star slice as balls and bars only: those rows are the kernel's
    (slice_rows of the same state, fill corners without balls) bit for bit, no triangle."""
    script = """
    import { decodePolytope, sliceStarEdges } from "page:slicer.js";
    import { sliceRows } from "page:rows.js";
    console.log(JSON.stringify(INPUT.map((c) => {
      const msg = { ...c.msg };
      for (const k of c.binary) msg[k] = Buffer.from(msg[k], "base64");
      const { rows, counts } = sliceRows(sliceStarEdges(decodePolytope(msg), c.matrix, c.c0), { scale: c.scale });
      return { rows: Buffer.from(rows.buffer).toString("base64"), counts };
    })));
    """
    rng = np.random.default_rng(4)
    runs = [(polytope("great grand stellated 120-cell"), IDENTITY, 0.3),
            (vh._polytope("off", "pardesco/34-quitit.off"), random_rotation(rng), 0.2)]
    page = run_page(script, [{**wire(p), "matrix": m.reshape(-1).tolist(), "c0": c0, "scale": 1.5 / p.circumradius}
                             for p, m, c0 in runs])
    for (p, m, c0), got in zip(runs, page):
        data = PolytopeSource(p).slice(m, c0)
        assert data.corner_only is not None and len(data.triangles)  # the kernel fills, with extra corners
        want = slice_rows(data, scale=1.5 / p.circumradius, group_rgb=None, single_rgb=(1.0, 1.0, 1.0))
        rows = np.frombuffer(base64.b64decode(got["rows"]), "<f4").reshape(-1, 20)
        n_balls = int((~data.corner_only).sum())
        assert got["counts"] == [n_balls, len(data.segments), 0]
        assert len(rows) == max(n_balls, len(data.segments))
        if m is IDENTITY:
            assert np.array_equal(rows[:, :10].view(np.uint32), want[: len(rows), :10].view(np.uint32))
        else:
            assert np.allclose(rows[:, :10], want[: len(rows), :10], rtol=0, atol=1e-6)
        assert not rows[:, 10:].any() and not want[len(rows):, :10].any()


def test_the_message_carries_the_star_tables():
    """A star polytope's message adds the star slicer's own tables; the page refuses to cut it whole
    (slicePolytope), to give the points and segments of a polytope it cuts whole (sliceStarEdges),
    and a slot_mate entry outside the table, naming it."""
    p = polytope("great grand stellated 120-cell")
    msg, st = polytope_message(p), star_tables(p, tables(p))
    assert np.array_equal(np.frombuffer(msg["face_basis"], "<f8"), st.face_basis.reshape(-1))
    assert np.array_equal(np.frombuffer(msg["face_rho"], "<f8"), st.face_rho.reshape(-1))
    assert np.array_equal(np.frombuffer(msg["slot_mate"], "<i4"), st.slot_mate)
    assert msg["volume_defined"] is True and polytope_message(vh._polytope("off", "pardesco/60-ihi.off"))[
        "volume_defined"] is False
    assert "slot_mate" not in polytope_message(polytope("24-cell"))
    script = """
    import { decodePolytope, slicePolytope, sliceStarEdges } from "page:slicer.js";
    const eye = Array.from({ length: 16 }, (_, i) => +(i % 5 === 0));
    console.log(JSON.stringify(INPUT.map((c) => {
      const msg = { ...c.msg };
      for (const k of c.binary) msg[k] = Buffer.from(msg[k], "base64");
      if (c.bad) msg[c.bad] = Buffer.from(new Int32Array(msg[c.bad].length / 4).fill(-2).buffer);
      try { (c.whole ? slicePolytope : sliceStarEdges)(decodePolytope(msg), eye, 0); return null; }
      catch (e) { return e.message; }
    })));
    """
    errors = run_page(script, [{**wire(p), "whole": True}, wire(polytope("24-cell")), {**wire(p), "bad": "slot_mate"},
                               wire(p)])
    assert "great grand stellated 120-cell has star faces or non-convex cells" in errors[0]
    assert "24-cell has no star faces or non-convex cells: slicePolytope cuts it" in errors[1]
    assert "slot_mate[0] = -2 is not in [-1, " in errors[2]
    assert errors[3] is None


def main() -> None:
    """Every level of test_vertex_heights (and c0 = 0), page against kernel, for every star polytope."""
    worst, n = 0.0, 0
    for param in _stars():
        kind, name = param.values
        p = vh._polytope(kind, name)
        cases = [(IDENTITY, 0.0)] + [(m, c0) for _, m, levels in vh._turns(p) for c0 in levels]
        w = compare(p, cases)
        worst, n = max(worst, w), n + len(cases)
        print(f"{name}: {len(cases)} levels equal, turned points within {w:.2e} of the circumradius", flush=True)
    print(f"{n} levels of {len(_stars())} polytopes: indices and unturned points exact, turned points within "
          f"{worst:.2e} of the circumradius")


if __name__ == "__main__":
    main()
