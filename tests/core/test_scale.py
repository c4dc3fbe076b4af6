"""Numbers at any scale: polytopes, slices, fields and the widget from 1e-150 to 1e150.

A polytope or field scaled by s must give the unscaled one's results scaled by s (slice
vertices by s, volumes by s**3), or a ValueError naming `COORDINATE_RANGE` outside
1e-150 .. 1e150 -- never a segfault.  The crash cases run in a subprocess so that a segfault
fails the test instead of ending pytest.  Oracles: the unscaled object, brute-force edge
crossings with scipy's ConvexHull, and the volume of a ball.
"""

from __future__ import annotations

import math
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings, strategies as st
from scipy.spatial import ConvexHull
from scipy.stats import special_ortho_group

from rot4d_widget import Field4D, Polytope, polytope
from rot4d_widget.sources.field.container import slice_field
from rot4d_widget.geometry.slicing.polytope_slice import slice_polytope

RANGE_MSG = r"1e-150 to 1e\+150"
TINY = sys.float_info.min  # smallest normal float64

# a scale for the largest |coordinate|: mantissa and decimal exponent over the whole range
targets = st.builds(lambda m, e: m * 10.0**e, st.floats(1.0, 9.99), st.integers(-150, 149))
seeds = st.integers(0, 2**32 - 1)
fractions = st.floats(-0.9, 0.9)
NAMES = ("5-cell", "8-cell", "24-cell", "rectified 5-cell")
SETTINGS = dict(deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])


def scaled(p: Polytope, target: float) -> tuple[np.ndarray, float]:
    """``p``'s vertices scaled so that the largest |coordinate| is ``target``, and the factor."""
    s = target / float(np.abs(p.vertices).max())
    return p.vertices * s, s


def rotation(seed: int) -> np.ndarray:
    return special_ortho_group.rvs(4, random_state=np.random.default_rng(seed))


def check_volume(got: float, unit_volume: float, s: float) -> None:
    """``got`` is ``unit_volume * s**3`` where that is a normal float64, else inf (or under 1e-308)."""
    assert not math.isnan(got)
    want = unit_volume * s * s * s
    if math.isinf(want):
        assert got == math.inf
    elif want < TINY * 1e3:  # at or near underflow: 0 or a subnormal, never more
        assert 0.0 <= got < TINY * 1e3
    else:
        assert got == pytest.approx(want, rel=1e-9)


def same_rows(a, b, atol: float, *, halves: bool = False) -> None:
    """``a`` and ``b`` hold the same rows in some order (each row of one within ``atol`` of its match);
    ``halves``: a row's two halves may come swapped (a segment's ends)."""
    from scipy.optimize import linear_sum_assignment

    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    assert a.shape == b.shape
    if not len(a):
        return
    d = np.abs(a[:, None, :] - b[None, :, :]).max(axis=2)
    if halves:
        k = a.shape[1] // 2
        sw = np.concatenate([b[:, k:], b[:, :k]], axis=1)
        d = np.minimum(d, np.abs(a[:, None, :] - sw[None, :, :]).max(axis=2))
    i, j = linear_sum_assignment(d)
    assert d[i, j].max(initial=0.0) <= atol


def close_sets(a, b, atol: float) -> None:
    """Every point of ``a`` within ``atol`` of a point of ``b`` and back (symmetric Hausdorff)."""
    from scipy.spatial import cKDTree

    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    assert len(a) and len(b)
    assert cKDTree(b).query(a)[0].max() <= atol and cKDTree(a).query(b)[0].max() <= atol


def cycles(s) -> list:
    """A slice's polygons as vertex cycles, each started at its least vertex, sorted: the same for
    any numbering of the polytope's cells and faces (qhull may list them in another order)."""
    out = []
    for poly in s.polygons:
        k = int(np.argmin(poly))
        out.append(tuple(np.roll(poly, -k).tolist()))
    return sorted(out)


def brute_slice_volume(vertices: np.ndarray, edges: np.ndarray, m: np.ndarray, c0: float) -> float:
    """Volume of a convex polytope's slice w = c0: the hull of its edges' crossing points."""
    x = vertices @ m.T
    h = x[:, 3] - c0
    pts = [x[a, :3] + h[a] / (h[a] - h[b]) * (x[b, :3] - x[a, :3]) for a, b in edges if h[a] * h[b] < 0]
    return ConvexHull(np.array(pts)).volume


# --------------------------------------------------------------------- crashes, in a subprocess
CRASHES = {
    "polytope 1e154": "Polytope(polytope('8-cell').vertices * 1e154)",
    "field extent 1e200": "Field4D.from_function(ball, [(-1e200, 1e200)] * 4).slice(np.eye(4), 0.0)",
    "field extent 1e-300": "Field4D.from_function(ball, [(-1e-300, 1e-300)] * 4).slice(np.eye(4), 0.0)",
    "polytope 1e100": "print(Polytope(polytope('8-cell').vertices * 1e100))",
    "polytope 3e7": "print(Polytope(polytope('8-cell').vertices * 3e7))",
}


@pytest.mark.parametrize("case", sorted(CRASHES))
def test_former_crashes_work_or_name_the_allowed_range(case):
    code = textwrap.dedent(f"""
        import numpy as np
        from rot4d_widget import Field4D, Polytope, polytope
        ball = lambda x, y, z, w: 1.0 - (x * x + y * y + z * z + w * w)
        try:
            {CRASHES[case]}
        except ValueError as exc:
            print("ValueError:", exc)
        """)
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, f"exit {r.returncode}: {r.stderr[-2000:]}"
    if "1e-300" in case or "1e154" in case or "1e200" in case:
        assert "ValueError:" in r.stdout and "1e-150 to 1e+150" in r.stdout, r.stdout
    else:  # inside the range: built, with the 8-cell's combinatorics
        assert "V=16, E=32, F=24, C=8" in r.stdout, r.stdout


@pytest.mark.parametrize("target", [1.01e150, 1e151, 1e300, 9.9e-151, 1e-200, 5e-324])
def test_polytopes_outside_the_range_name_it(target):
    code = textwrap.dedent(f"""
        import numpy as np
        from rot4d_widget import Polytope, polytope
        p = polytope("8-cell")
        v = p.vertices * {target!r}
        for args in ((v,), (v, p.faces, p.cells)):
            try:
                Polytope(*args)
                print("built")
            except ValueError as exc:
                print("ValueError:", exc)
        """)
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)  # qhull may crash
    assert r.returncode == 0, f"exit {r.returncode}: {r.stderr[-2000:]}"
    lines = r.stdout.splitlines()
    assert len(lines) == 2 and all("ValueError:" in ln and "1e-150 to 1e+150" in ln for ln in lines), r.stdout


@pytest.mark.parametrize("extent, match", [
    ([(-2e150, 2e150)] * 4, r"reaches 2e\+150.*<= 1e\+150"),
    ([(0.0, 1.0)] * 3 + [(1e160, 1e160 * (1 + 1e-9))], r"reaches"),
    ([(0.0, 1e-300)] + [(0.0, 1.0)] * 3, "half width of `extent` along x.*" + RANGE_MSG),
])
def test_field_extents_outside_the_range_name_it(extent, match):
    with pytest.raises(ValueError, match=match):
        Field4D.from_function(lambda x, y, z, w: x + 0 * y, extent)


def test_w_per_unit_outside_the_range_names_it_and_changes_nothing():
    f = Field4D.from_function(lambda x, y, z, w: x + 0 * w, [(-1.0, 1.0)] * 4)
    with pytest.raises(ValueError, match="w_per_unit.*" + RANGE_MSG):
        f.w_per_unit = 1e-160
    assert f.w_per_unit == 1.0 and f.half_widths == (1.0,) * 4


# --------------------------------------------------------------------- polytopes and slices
@settings(max_examples=60, **SETTINGS)
@given(name=st.sampled_from(NAMES), target=targets, seed=seeds, frac=fractions)
def test_a_scaled_polytope_slices_as_the_unit_one_scaled(name, target, seed, frac):
    p = polytope(name)
    v, s = scaled(p, target)
    ps = Polytope(v)
    assert ps.counts == p.counts
    assert ps.circumradius == pytest.approx(p.circumradius * s, rel=1e-12)
    # the same cells (qhull may list them in another order at another scale)
    same_rows(np.column_stack([ps.cell_normals, ps.cell_offsets / s]),
              np.column_stack([p.cell_normals, p.cell_offsets]), atol=1e-12)
    m = rotation(seed)
    c0 = frac * p.circumradius
    a, b = slice_polytope(p, m, c0), slice_polytope(ps, m, c0 * s)
    assert b.dim == a.dim
    assert np.all(np.isfinite(b.vertices))
    np.testing.assert_allclose(b.vertices / s, a.vertices, rtol=0, atol=1e-11 * p.circumradius)
    same_rows(np.sort(b.edges, axis=1), np.sort(a.edges, axis=1), atol=0)
    assert cycles(b) == cycles(a) and len(b.triangles) == len(a.triangles)
    # the volume: the unit slice's, checked against an independent hull, times s**3
    if a.dim == 3:
        assert a.volume == pytest.approx(brute_slice_volume(p.vertices, p.edges, m, c0), rel=1e-9)
        if 1e-30 < s < 1e30:  # where qhull itself is sound on the scaled points
            assert b.volume == pytest.approx(ConvexHull(np.asarray(b.vertices)).volume, rel=1e-9)
    check_volume(b.volume, a.volume, s)
    # a stack of levels equals the single slices, at the scale too
    levels = np.array([-0.7, -0.2, 0.0, frac, 0.5]) * p.circumradius * s
    for c, sl in zip(levels, slice_polytope(ps, m, levels)):
        one = slice_polytope(ps, m, float(c))
        np.testing.assert_array_equal(sl.vertices, one.vertices)
        np.testing.assert_array_equal(sl.triangles, one.triangles)
        assert sl.dim == one.dim and not math.isnan(sl.volume)
        assert sl.volume == (one.volume if math.isinf(one.volume) else pytest.approx(one.volume, rel=1e-12, abs=0))


@settings(max_examples=25, **SETTINGS)
@given(target=targets, seed=seeds, frac=fractions)
def test_a_scaled_mesh_passes_its_checks_and_slices_as_the_unit_one(target, seed, frac):
    p = polytope("24-cell")
    v, s = scaled(p, target)
    ps = Polytope(v, p.faces, p.cells)  # the explicit-mesh path: every check relative to the scale
    assert ps.convex
    np.testing.assert_allclose(ps.cell_normals, p.cell_normals, atol=1e-12)  # the cells as given, in order
    np.testing.assert_allclose(ps.cell_offsets / s, p.cell_offsets, rtol=1e-12)
    m = rotation(seed)
    a, b = slice_polytope(p, m, frac * 2.0), slice_polytope(ps, m, frac * 2.0 * s)
    np.testing.assert_allclose(b.vertices / s, a.vertices, rtol=0, atol=1e-11)
    check_volume(b.volume, a.volume, s)


@pytest.mark.parametrize("target", [1e-150, 1e150])
def test_a_not_quite_planar_mesh_is_refused_alike_at_every_scale(target):
    p = polytope("8-cell")
    for t in (1.0, target):
        v, s = scaled(p, t)
        v = v.copy()
        v[0, 0] += 1e-3 * s  # a face no longer planar, by 1e-3 of the size: refused at every scale
        with pytest.raises(ValueError, match="not planar"):
            Polytope(v, p.faces, p.cells)


# --------------------------------------------------------------------- fields
R = 0.8


def ball_values(n: int = 17) -> np.ndarray:
    q = np.linspace(-1.0, 1.0, n)
    x, y, z, w = np.meshgrid(q, q, q, q, indexing="ij")
    return R * R - (x * x + y * y + z * z + w * w)


@settings(max_examples=30, **SETTINGS)
@given(target=targets, seed=seeds, frac=st.floats(-0.5, 0.5), function=st.booleans())
def test_a_scaled_field_slices_as_the_unit_one_scaled(target, seed, frac, function):
    s = target
    if function:
        def f(x, y, z, w, s=s):
            return R * R - ((x / s) ** 2 + (y / s) ** 2 + (z / s) ** 2 + (w / s) ** 2)

        f1 = Field4D.from_function(lambda x, y, z, w: f(x, y, z, w, 1.0), [(-1.0, 1.0)] * 4, resolution=16)
        fs = Field4D.from_function(f, [(-s, s)] * 4, resolution=16)
    else:
        f1 = Field4D(ball_values(), axes="xyzw", extent=[(-1.0, 1.0)] * 4, resolution=16)
        fs = Field4D(ball_values(), axes="xyzw", extent=[(-s, s)] * 4, resolution=16)
    m = rotation(seed)
    a = slice_field(f1, m, frac, 0.0, 16)
    b = slice_field(fs, m, frac * s, 0.0, 16)
    assert not a.empty and not b.empty
    assert np.all(np.isfinite(b.vertices)) and np.all(np.isfinite(b.normals))
    # the same surface scaled; not always the same mesh: a sample within rounding of the level or
    # of the box's face (the cap) may fall on the other side at another scale and move a corner
    # within its cell, so the sets of points are compared to a sample spacing, the volumes to 1e-3
    # (exactly the same numbers at power-of-two scales: the next test)
    close_sets(b.vertices / s, a.vertices, atol=a.spacing)
    assert b.spacing == pytest.approx(a.spacing * s, rel=1e-12)
    # a ball of radius sqrt(R^2 - c0^2): marching cubes' volume within 20 % (16 samples across)
    assert a.volume == pytest.approx(4 / 3 * math.pi * (R * R - frac * frac) ** 1.5, rel=0.2)
    check_field_measure(b.volume, a.volume, s * s * s)
    check_field_measure(b.area, a.area, s * s)
    # the widget's slice: the same points scaled, a volume only where float64 holds it
    da, db = f1.slice(m, frac), fs.slice(m, frac * s)
    close_sets(np.asarray(db.points) / s, np.asarray(da.points), atol=a.spacing)
    if 1e-100 < s < 1e100:
        assert db.volume == pytest.approx(da.volume * s**3, rel=1e-3)
    elif s > 1e103 or s < 1e-103:
        assert db.volume is None


def check_field_measure(got: float, unit: float, factor: float) -> None:
    """A marching-cubes volume or area scaled: to 1e-3 (see above), inf or underflowed beyond float64."""
    want = unit * factor
    assert not math.isnan(got)
    if math.isinf(want):
        assert got == math.inf
    elif want < TINY * 1e6:
        assert 0.0 <= got < TINY * 1e6
    else:
        assert got == pytest.approx(want, rel=1e-3)


@pytest.mark.parametrize("k", [-490, -200, -1, 3, 200, 490])
def test_power_of_two_scales_give_exactly_the_unit_results_scaled(k):
    """Scaling by 2**k is exact, and so is the normalisation: the results are bitwise the unit ones."""
    s = math.ldexp(1.0, k)
    m = rotation(7)
    for name in NAMES:
        p = Polytope(polytope(name).vertices)  # by the hull, like the scaled one (uniform ones come as meshes)
        ps = Polytope(p.vertices * s)
        for c in (0.0, 0.3, -0.61):
            a, b = slice_polytope(p, m, c), slice_polytope(ps, m, c * s)
            np.testing.assert_array_equal(b.vertices, a.vertices * s)
            np.testing.assert_array_equal(b.triangles, a.triangles)
            assert b.volume == a.volume * s * s * s
    f1 = Field4D(ball_values(), axes="xyzw", extent=[(-1.0, 1.0)] * 4)
    fs = Field4D(ball_values(), axes="xyzw", extent=[(-s, s)] * 4)
    a, b = slice_field(f1, m, 0.2, 0.0, 20), slice_field(fs, m, 0.2 * s, 0.0, 20)
    np.testing.assert_array_equal(b.vertices, a.vertices * s)
    np.testing.assert_array_equal(b.triangles, a.triangles)
    assert b.volume == a.volume * s * s * s


# --------------------------------------------------------------------- the widget
KEYS = ("4", "l", "4", "l", "1", "h")


def press_all(w, keys=KEYS) -> None:
    for k in keys:
        w.press(k)


def drawn_rows(w) -> np.ndarray:
    rows = np.array(w.scene.rows, dtype=np.float64)
    assert np.all(np.isfinite(rows))
    return rows


def widget_case(make, src, unit_src, s):
    w, u = make(src), make(unit_src)
    press_all(w)
    press_all(u)
    assert not w.errors.outputs, w.errors.outputs
    assert np.all(np.isfinite(np.asarray(w.slice.points)))
    spacing = min([lv.spacing for lv in getattr(u.slice, "levels", ())] or [1e-9])  # fields: see above
    close_sets(np.asarray(w.slice.points) / s, np.asarray(u.slice.points), atol=spacing)
    return w, u


@pytest.mark.usefixtures("recording_comms")
@settings(max_examples=8, **SETTINGS)
@given(target=st.builds(lambda m, e: m * 10.0**e, st.floats(1.0, 9.99), st.integers(-100, 99)))
def test_the_widget_shows_a_scaled_polytope_as_the_unit_one(make, target):
    p = polytope("24-cell")
    v, s = scaled(p, target)
    w, u = widget_case(make, Polytope(v), p, s)
    # the view is scale-free: the same balls in order, bars and triangles in some order (the cells'
    # colours follow qhull's order of the cells, which may differ)
    rw, ru = drawn_rows(w), drawn_rows(u)
    np.testing.assert_allclose(rw[:, :4], ru[:, :4], rtol=0, atol=1e-5)
    same_rows(rw[:, 4:10], ru[:, 4:10], atol=1e-5, halves=True)
    same_rows(rw[:, 10:19], ru[:, 10:19], atol=1e-5)


@pytest.mark.usefixtures("recording_comms")
@settings(max_examples=8, **SETTINGS)
@given(target=targets)
def test_the_widget_shows_a_scaled_field_as_the_unit_one(make, target):
    s = target
    f1 = Field4D(ball_values(), axes="xyzw", extent=[(-1.0, 1.0)] * 4, resolution=16, coarse_resolution=8)
    fs = Field4D(ball_values(), axes="xyzw", extent=[(-s, s)] * 4, resolution=16, coarse_resolution=8)
    w, u = widget_case(make, fs, f1, s)
    sw, su = w.scene.surface, u.scene.surface
    assert sw["n_vertices"] > 0 and su["n_vertices"] > 0
    np.testing.assert_allclose(np.asarray(sw["lo"]), np.asarray(su["lo"]), atol=1e-6)
    np.testing.assert_allclose(np.asarray(sw["span"]), np.asarray(su["span"]), atol=1e-6)


# Polytopes beyond ~1e-102 and ~1e102 in the widget: their volume leaves float64 (the readout
# then gives none; it once overflowed in the readout and was refused by check_slice).
@pytest.mark.usefixtures("recording_comms")
@pytest.mark.parametrize("target", [1e-150, 1e-120, 1e120, 1e150])
def test_the_widget_shows_a_polytope_at_the_ends_of_the_range(make, target):
    p = polytope("24-cell")
    v, s = scaled(p, target)
    widget_case(make, Polytope(v), p, s)


STAR = ("small stellated 120-cell", "great 120-cell", "great stellated 120-cell")  # star faces / star cells


@settings(max_examples=20, **SETTINGS)
@given(name=st.sampled_from(STAR), target=targets, seed=seeds, frac=fractions)
def test_a_scaled_star_polychoron_slices_as_the_unit_one_scaled(name, target, seed, frac):
    """The general slicer (star faces, non-convex cells: even-odd segments, cycles, the fills and
    their extra corners, the winding-weighted volume) is scale-free too: the same picture, scaled,
    anywhere in the range."""
    p = polytope(name)
    v, s = scaled(p, target)
    ps = Polytope(v, [f.tolist() for f in p.faces], [list(c) for c in p.cells])
    assert ps.star is not None and not ps.convex
    m = rotation(seed)
    c0 = frac * p.circumradius
    a, b = slice_polytope(p, m, c0), slice_polytope(ps, m, c0 * s)
    assert (b.dim, b.n_fill, len(b.vertices)) == (a.dim, a.n_fill, len(a.vertices))
    assert np.all(np.isfinite(b.vertices))
    np.testing.assert_allclose(b.vertices / s, a.vertices, rtol=0, atol=1e-10 * p.circumradius)
    np.testing.assert_array_equal(b.edges, a.edges)
    np.testing.assert_array_equal(b.triangles, a.triangles)
    assert cycles(b) == cycles(a)
    check_volume(b.volume, a.volume, s)
