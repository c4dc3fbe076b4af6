"""The page cuts parallel slices of a polytope itself, as the kernel does (issue 34).

A widget showing a stack (`StackSource` around a polytope with convex cells) offers the polytope
to the page (`pagecut.page_cuttable`) and says how its stack is laid out (`pagecut.stack_config`,
the kernel's own float64 numbers in ``draw_config``).  Under Node the page's modules take what the
kernel sends -- the polytope's one-time transfer (unpacked by ``transfer.js`` as the page does),
``draw_config``, the state and the camera -- and build the stack's rows (``stack.js`` `stackData`,
``rows.js`` `sliceRows`); they are compared float for float with the rows the widget's scene
holds after drawing that state (`Scene.show`: `StackSource.slice` + `buffers.slice_rows`).

Unturned (at c0 = 0 and at vertex heights) the rows are the kernel's bit for bit.  Turned, the
kernel's slicer rotates the vertices with BLAS, which fuses multiply-adds where the page cannot
(``slicer.js``): its float64 points may differ in the last bits, so a float32 of the rows may
round the other way; the test asserts every index and colour equal, every point within 1e-12 of
the size and every row's position within one float32 step, and prints how many differ (``-s``:
none of the 1,246,840 turned floats here, on numpy's OpenBLAS Haswell kernel).  Stacks of more
than one slice come from the kernel's batched `slice_polytope`, the page cuts each level alone:
the same arrays (tests/sources/test_tomography.py), which this test sees again through the rows.
"""

from __future__ import annotations

import base64
import json
import math

import numpy as np
import pytest
from page_node import run_page
from test_widget import down, up
from test_widget_scene import companion_says, drawn, run_ticker

from rot4d_widget.core.rotation import random_rotation
from rot4d_widget.geometry.catalogue import polytope
from rot4d_widget.sources.protocol import PolytopeSource
from rot4d_widget.sources.arrangements import ARRANGEMENTS
from rot4d_widget.sources.tomography import StackSource
from rot4d_widget.view.pagecut import page_cuttable, polytope_transfer, stack_config
from rot4d_widget.view.projection import state_message

pytestmark = pytest.mark.usefixtures("recording_comms")

NAMES = ["5-cell", "8-cell", "16-cell", "24-cell", "120-cell", "600-cell"]

STACK_SCRIPT = """
import { decodePolytope } from "page:slicer.js";
import { sliceRows } from "page:rows.js";
import { decodeStack, stackData, stackHyperplanes } from "page:stack.js";
import { unpack } from "page:transfer.js";
const polytopes = INPUT.polytopes.map(({ meta, payload }) => {
  const bytes = Buffer.from(payload, "base64");
  const { arrays, scalars } = unpack(meta, new Uint8Array(bytes.buffer, bytes.byteOffset, bytes.byteLength));
  const msg = { ...scalars };
  for (const [name, a] of Object.entries(arrays)) msg[name] = new DataView(a.buffer, a.byteOffset, a.byteLength);
  return decodePolytope(msg);
});
console.log(JSON.stringify(INPUT.cases.map((c) => {
  const cfg = c.config;
  const stack = decodeStack(cfg.stack);
  const data = stackData(polytopes[c.polytope], c.matrix, c.c0, stack);
  const { rows, counts } = sliceRows(data, { scale: cfg.scale, palette: cfg.palette, eye: c.eye,
                                             singleRgb: Number.isFinite(cfg.single) ? cfg.single : null });
  return { rows: Buffer.from(rows.buffer).toString("base64"), counts, planes: stackHyperplanes(stack, c.c0),
           points: Buffer.from(data.points.buffer).toString("base64"), segments: Array.from(data.segments),
           triangles: Array.from(data.triangles), groups: Array.from(data.groups), convex: data.convex };
})));
"""


def _state(w, matrix, c0):
    """Draw ``matrix``, ``c0`` in the widget; (matrix, c0) as its state holds them."""
    drawn(w)  # the previous picture drawn: nothing holds this one back
    w.state.matrix = matrix
    w.state.c0 = c0
    w.refresh()
    drawn(w)
    return np.asarray(w.state.matrix, dtype=np.float64), float(w.state.c0)


def _cases(w, states):
    """What the page gets for each state, and what the kernel drew: (case, rows, counts, planes)."""
    out = []
    for m, c0 in states:
        m, c0 = _state(w, m, c0)
        cfg = json.loads(json.dumps(w.companion.draw_config))  # as the page receives it
        assert cfg["stack"] == stack_config(w.source)
        case = {"config": cfg, "matrix": m.reshape(-1).tolist(), "c0": c0, "eye": list(w.scene.eye)}
        out.append((case, w.scene.rows.copy(), list(w.scene.counts), state_message(w.source, m, c0),
                    w.source.slice(m, c0), not np.array_equal(m, np.eye(4))))
    return out


def compare(runs):
    """``runs``: (widget, states) pairs; every state's rows from Node against the kernel's.  Returns
    (floats compared, floats one float32 step apart) over the turned states."""
    polytopes, cases, expected = [], [], []
    for w, states in runs:
        poly = page_cuttable(w.source)
        assert poly is not None, w.source
        meta, payload = polytope_transfer(poly)
        polytopes.append({"meta": meta, "payload": base64.b64encode(payload).decode()})
        for case, rows, counts, planes, data, turned in _cases(w, states):
            cases.append({**case, "polytope": len(polytopes) - 1})
            expected.append((w.source, case, rows, counts, planes, data, turned))
    page = run_page(STACK_SCRIPT, {"polytopes": polytopes, "cases": cases})
    compared = off = 0
    for (src, case, want, counts, planes, data, turned), got in zip(expected, page):
        where = f"{src!r} at c0 = {case['c0']!r}" + (" (turned)" if turned else "")
        # the stack's slice data, before the rows round it to float32: the kernel's `StackSource.slice`
        for name in ("segments", "triangles", "groups"):
            assert got[name] == np.asarray(getattr(data, name)).reshape(-1).tolist(), f"{where}: {name}"
        assert got["convex"] == bool(data.convex), where
        points = np.frombuffer(base64.b64decode(got["points"]), dtype="<f8").reshape(-1, 3)
        if turned:  # BLAS's fused rotation: within 1e-12 of the layout's size
            np.testing.assert_allclose(points, data.points, rtol=0, atol=1e-12 * src.size, err_msg=where)
        else:
            assert points.shape == data.points.shape, where
            bad = np.argwhere(points.view("<u8") != data.points.view("<u8"))
            assert not len(bad), f"{where}: {len(bad)} coordinates differ, the first at point, axis {bad[0].tolist()}"
        assert got["counts"] == counts, where
        rows = np.frombuffer(base64.b64decode(got["rows"]), dtype="<f4").reshape(-1, 20)
        n = max(counts)
        assert len(rows) == n and not want[n:].any(), where  # the kernel's spare rows are empty
        a, b = rows.view("<u4"), want[:n].view(np.uint32)
        if not turned:
            bad = np.argwhere(a != b)
            assert not len(bad), f"{where}: {len(bad)} floats differ, the first at row, column {bad[0].tolist()}"
        else:
            assert np.array_equal(rows[:, 3], want[:n, 3]) and np.array_equal(rows[:, 19], want[:n, 19]), where
            step = np.abs(rows.astype(np.float64) - want[:n])
            ulp = np.spacing(np.maximum(np.abs(rows), np.abs(want[:n])).astype(np.float32)).astype(np.float64)
            assert (step <= ulp).all(), f"{where}: a position more than one float32 step off"
            compared += a.size
            off += int((a != b).sum())
        assert got["planes"]["offsets"] == planes["offsets"], where  # the projection's hyperplanes
        assert got["planes"]["middle"] == planes["middle"], where
    return compared, off


def _states(p, n, seed, turns=2):
    """Unturned at 0 and at every distinct vertex height (odd n: the middle cut there exactly);
    ``turns`` random orientations at a random level and at a turned vertex's height."""
    out = [(np.eye(4), 0.0)] + [(np.eye(4), float(h)) for h in np.unique(np.asarray(p.vertices)[:, 3])]
    rng = np.random.default_rng(seed)
    for _ in range(turns):
        m = random_rotation(rng)
        w = (np.asarray(p.vertices) @ m.T)[:, 3]
        out += [(m, float(rng.uniform(-0.6, 0.6) * p.circumradius)), (m, float(w[rng.integers(len(w))]))]
    return out


@pytest.mark.parametrize("arrangement", ARRANGEMENTS)
def test_the_regular_six_in_every_arrangement(make, arrangement):
    """N = 1, 2, 5, 12 of each regular polytope, coloured by w and by cell (alternately)."""
    runs = []
    for seed, name in enumerate(NAMES):
        for i, n in enumerate((1, 2, 5, 12)):
            by = ("w", "cell")[(seed + i) % 2]
            src = StackSource(name, slices=n, arrangement=arrangement, color_by=by)
            runs.append((make(src), _states(polytope(name), n, 10 * seed + n, turns=1)))
    compared, off = compare(runs)
    print(f"{arrangement}: turned, {off} of {compared} floats one float32 step from the kernel's")


def test_a_12_slice_oval_of_the_24_cell(make):
    """The issue's case, by w and by cell, one colour for all, and N = 2, 5 beside it."""
    p = polytope("24-cell")
    runs = [(make(StackSource("24-cell", slices=12, arrangement="oval", color_by=by)), _states(p, 12, 3, turns=6))
            for by in ("w", "cell")]
    runs.append((make(StackSource("24-cell", slices=12), color_by="#3080ff"), _states(p, 12, 4, turns=2)))
    runs += [(make(StackSource("24-cell", slices=n, spacing=0.3)), _states(p, n, n)) for n in (2, 5)]
    compared, off = compare(runs)
    print(f"turned, {off} of {compared} floats one float32 step from the kernel's")


def test_the_widgets_stack_keys_reach_the_config(make):
    """n / b / g and the traits change the stack the page builds; the polytope is offered once."""
    w = make("24-cell", slices=5)
    key = w.companion.page_data["polytope"]
    w.press("n")
    w.press("g")
    w.arrangement = "grid"
    w.refresh()
    cfg = w.companion.draw_config["stack"]
    assert len(cfg["offsets"]) == 6 and cfg == stack_config(w.source)
    assert cfg["offsets"] == (w.source.cuts_at(0.0) - 0.0).tolist()
    assert w.companion.page_data["polytope"] == key  # the same polytope: not sent again
    compare([(w, [(random_rotation(np.random.default_rng(1)), 0.2)])])


def test_what_the_page_does_not_cut(make):
    """A stack of a star polytope or of a user's source: no polytope, no stack config."""
    star = make(StackSource("great grand stellated 120-cell", slices=3))
    assert page_cuttable(star.source) is None and "polytope" not in star.companion.page_data

    class Users(PolytopeSource):  # a subclass may slice otherwise: not cut in the page
        pass

    assert page_cuttable(StackSource(Users(polytope("5-cell")), slices=3)) is None
    assert page_cuttable(StackSource("5-cell", slices=3)) is polytope("5-cell")
    assert stack_config(PolytopeSource(polytope("5-cell"))) is None


def test_offsets_are_the_kernels_cuts_less_c0():
    """`cuts_at` adds c0 to `cut_offsets` (the numbers the page gets): c0 + offsets[k] is each cut."""
    src = StackSource("120-cell", slices=12, spacing=0.37)
    for c0 in (0.0, -0.0, 0.1, -1.3, math.pi):
        assert (src.cuts_at(c0) == np.array([c0 + o for o in stack_config(src)["offsets"]])).all()


def test_while_the_page_holds_the_polytope_the_kernel_makes_no_picture_of_held_keys(make, clock):
    """The page says it holds the 24-cell of a 12-slice oval: a held key makes no kernel picture
    (the state goes out as "pending"); the release makes one, of the state the keys rest on."""
    w = make("24-cell", slices=12, arrangement="oval")
    companion_says(w, {"event": "holds", "name": "polytope", "key": w.companion.page_data["polytope"]})
    drawn(w)
    updates = w.stats.updates
    down(w, "4")
    run_ticker(w, clock, clock.t + 1.0)
    assert w.stats.updates == updates and w.companion.kernel_state["picture"] == "pending"
    up(w, "4")
    run_ticker(w, clock, clock.t + 0.2)
    assert w.stats.updates == updates + 1
    assert w.companion.kernel_state["picture"] == w.scene.update_id  # the picture of the state now
