"""The compiled generic level of the general slicer (`rot4d_widget.geometry._cstar`, ``_starcut.c``)
against the numpy slicer it stands in for (issue 22's speed target).

The same polytope, orientation and level are cut twice: by the C code and, with the polytope's
compiled tables switched off, by `starslice._cut` (the reference, itself checked against
independent computation in test_star_cells.py, test_star_fill.py, test_nonconvex.py).  They must
agree on everything a slice is, up to the order of its parts: the points (the edges' crossings),
the segments, every cell's cycles (as cyclic sequences, either start), the volume, and each cell's
fill (the area its triangles cover, signed about the cell's normal: the even-odd region, counter-
clockwise), with every fill corner on the cell's segments' plane.

Shapes: the seven regular star polychora with star faces or star cells (the other three have
convex faces and cells and go through the convex slicer) and non-convex polytopes (4-D prisms over a dented
octahedron, a great icosahedron and a small stellated dodecahedron: non-convex, star-celled) and
the {5/2}-{5} duoprism (pentagram faces).
"""

from __future__ import annotations

import json
import os
import pathlib
import shutil
import subprocess
import sys
import time
import zlib
from collections import Counter

import numpy as np
import pytest

from mesh_shapes import prism_mesh
from reference_geometry import random_rotation
from test_wheel import COMPILER
from test_star_cells import dented_octahedron, great_icosahedron, small_stellated_dodecahedron, star_duoprism_mesh
from rot4d_widget import Polytope, polytope
from rot4d_widget.geometry import _cstar, starslice
from rot4d_widget.geometry.slicetables import tables
from rot4d_widget.geometry.star_regular import SPECS

#: every test but the first needs the library; the first fails where it should have been built
needs_c = pytest.mark.skipif(not _cstar.available, reason="the compiled level is not built here")


def test_the_compiled_level_is_built_where_there_is_a_c_compiler():
    """The install builds it (hatch_build.py) wherever a C compiler is found, as on this machine."""
    if os.environ.get("ROT4D_NO_C"):
        pytest.skip("switched off by ROT4D_NO_C")
    if not COMPILER:
        pytest.skip("no C compiler here (none of those hatch_build.py tries)")
    assert _cstar.available


@needs_c
def test_a_library_built_from_another_source_is_not_used(tmp_path):
    """An edited _starcut.c beside an old build: the build is refused, with a warning saying why."""
    here = pathlib.Path(_cstar.__file__).parent
    shutil.copy(here / _cstar.LIBRARY, tmp_path / _cstar.LIBRARY)
    shutil.copy(here / "_starcut.c", tmp_path / "_starcut.c")
    assert _cstar._load(tmp_path) is not None  # the same source: used
    with open(tmp_path / "_starcut.c", "a") as f:
        f.write("/* edited */\n")
    with pytest.warns(UserWarning, match="built from another _starcut.c"):
        assert _cstar._load(tmp_path) is None


@needs_c
def test_without_the_library_the_numpy_slicer_gives_the_same_slices():
    """ROT4D_NO_C=1 (as an install without a C compiler): not available, and the same slice."""
    code = ("import json, numpy as np\n"
            "from rot4d_widget import polytope\n"
            "from rot4d_widget.geometry import _cstar\n"
            "from rot4d_widget.geometry.slicing import slice_polytope\n"
            "from rot4d_widget.core.rotation import random_rotation\n"
            "s = slice_polytope(polytope('great stellated 120-cell'), random_rotation(np.random.default_rng(3)), 0.2)\n"
            "print(json.dumps([_cstar.available, s.volume, s.vertices[:len(s.vertices) - s.n_fill].tolist()]))\n")
    out = {}
    for flag in ("", "1"):
        env = dict(os.environ, ROT4D_NO_C=flag)
        proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=300)
        assert proc.returncode == 0, proc.stderr[-2000:]
        out[flag] = json.loads(proc.stdout.strip().splitlines()[-1])
    assert out[""][0] is True and out["1"][0] is False
    assert out["1"][1] == pytest.approx(out[""][1], rel=1e-9)
    assert out["1"][2] == out[""][2]


@needs_c
def test_the_compiled_level_declines_what_is_not_a_number_or_on_the_hyperplane():
    """NaN or infinite coordinates or level, a vertex on H: None (the numpy slicer's), no crash."""
    p = polytope("small stellated 120-cell")
    t = tables(p)
    st = starslice.star_tables(p, t)
    m = np.eye(4)
    x = t.vertices @ m.T
    assert _cstar.cut(st.c, x, m, 0.1, t.tol) is not None
    for level in (np.nan, np.inf, -np.inf, float(x[7, 3])):
        assert _cstar.cut(st.c, x, m, level, t.tol) is None, level
    bad = x.copy()
    bad[3, 0] = np.nan
    assert _cstar.cut(st.c, bad, m, 0.1, t.tol) is None
    bad[3] = [0, 0, 0, np.inf]
    assert _cstar.cut(st.c, bad, m, 0.1, t.tol) is None


def _polytopes():
    # the seven with star faces ({5/2,...}) or star cells ({p,5/2,...}); the other three go through the convex slicer
    out = [(name, lambda n=name: polytope(n)) for name, spec in SPECS.items() if "/" in "".join(spec.symbol.split(",")[:2])]
    for solid in (dented_octahedron, great_icosahedron, small_stellated_dodecahedron):
        out.append((f"prism over {solid.__name__}", lambda s=solid: Polytope(*prism_mesh(*s()))))
    out.append(("{5/2}-{5} duoprism", lambda: Polytope(*star_duoprism_mesh()[:3])))
    return out


def _both(p, m, c0, slabs_only=False):
    """(C slice, numpy slice) of one level, or (None, numpy) where the C code declines it."""
    t = tables(p)
    st = starslice.star_tables(p, t)
    assert st.c is not None
    x = t.vertices @ m.T
    level = c0 / t.unit
    r = _cstar.cut(st.c, x, m, level, t.tol, slabs_only=slabs_only)
    keep, st.c = st.c, None
    try:
        ref = starslice.slice_star(p, t, x, m, level)
    finally:
        st.c = keep
    return r, ref


def _cycles(flat, offsets, cells):
    out = Counter()
    for i, c in enumerate(cells):
        cyc = [int(v) for v in flat[offsets[i]:offsets[i + 1]]]
        k = cyc.index(min(cyc))
        out[(int(c), tuple(cyc[k:] + cyc[:k]))] += 1
    return out


def _fill_area(v, tri, tcell, normals):
    """Per cell: the triangles' area, signed about the cell's unit normal."""
    a, b, c = v[tri[:, 0]], v[tri[:, 1]], v[tri[:, 2]]
    n = normals[tcell] / np.linalg.norm(normals[tcell], axis=1)[:, None]
    area = 0.5 * np.einsum("ij,ij->i", np.cross(b - a, c - a), n)
    return np.bincount(tcell, weights=area, minlength=len(normals))


@needs_c
@pytest.mark.parametrize("name,make", _polytopes(), ids=[n for n, _ in _polytopes()])
def test_the_compiled_level_is_the_numpy_slicers(name, make):
    p = make()
    assert p.star is not None
    t = tables(p)
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    done = 0
    for _ in range(6):
        m = random_rotation(rng)
        for frac in (-0.37, 0.05, 0.51):
            c0 = frac * p.circumradius
            r, ref = _both(p, m, c0)
            if r is None:  # declined: the numpy slicer does it (a tie or a check the C code does not make)
                continue
            if ref is None or ref.dim != 3:
                continue
            v, edges, flat, offsets, cells, tri, tcell, volume, n_fill = r
            v = v * t.unit
            n = len(v) - n_fill
            assert n == len(ref.vertices) - ref.n_fill
            # the same fills chosen (fans, arrangement, slabs): as many fill corners and triangles
            assert (n_fill, len(tri)) == (ref.n_fill, len(ref.triangles))
            np.testing.assert_array_equal(v[:n], ref.vertices[:n])  # the same crossings, in edge order
            assert Counter(map(tuple, np.sort(edges, axis=1).tolist())) == \
                Counter(map(tuple, np.sort(ref.edges, axis=1).tolist()))
            assert _cycles(flat, offsets, cells) == _cycles(ref.polygon_indices, ref.polygon_offsets, ref.cell_ids)
            vol = volume * t.unit ** 3
            assert vol == pytest.approx(ref.volume if ref.volume is not None else vol, rel=1e-9, abs=1e-12)
            normals = t.cell_normals @ m[:3].T
            got = _fill_area(v, tri, tcell, normals)
            want = _fill_area(ref.vertices, ref.triangles, ref.triangle_cells, normals)
            scale = max(1.0, float(np.abs(want).max()))
            np.testing.assert_allclose(got, want, rtol=0, atol=1e-9 * scale)
            assert (got >= -1e-12 * scale).all()  # counter-clockwise about the normal: no negative cover
            # every fill corner lies in its cell's plane (on the cell's segments, not off in space)
            corners = np.unique(np.concatenate([tri.ravel(), tcell.repeat(3)]).reshape(2, -1).T, axis=0)
            cn = normals / np.linalg.norm(normals, axis=1)[:, None]
            anchor = np.zeros((len(normals), 3))
            anchor[cells] = v[flat[offsets[:-1]]]
            off = np.einsum("ij,ij->i", v[corners[:, 0]] - anchor[corners[:, 1]], cn[corners[:, 1]])
            assert np.abs(off).max(initial=0) <= 1e-9 * max(1.0, float(np.abs(v).max()))
            done += 1
    assert done >= 6, "the compiled level declined nearly every level"


@needs_c
@pytest.mark.parametrize("name", ["great icosahedral 120-cell", "great grand 120-cell", "great 120-cell"])
def test_the_compiled_slab_fill_of_crossing_sections_covers_what_the_arrangement_does(name):
    """The slab fill, which takes a section the arrangement fill leaves (rare: a crossing at a
    segment's end, an odd face that is not convex), made to take all of them: on these polychora
    every such section's segments cross, so each crossing must be a slab line.  The area covered per
    cell (signed about its normal) is the numpy slicer's, with more fill corners."""
    p = polytope(name)
    t = tables(p)
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    for _ in range(3):
        m = random_rotation(rng)
        r, ref = _both(p, m, 0.05 * p.circumradius, slabs_only=True)
        assert r is not None and ref.dim == 3
        v, edges, flat, offsets, cells, tri, tcell, volume, n_fill = r
        normals = t.cell_normals @ m[:3].T
        got = _fill_area(v * t.unit, tri, tcell, normals)
        want = _fill_area(ref.vertices, ref.triangles, ref.triangle_cells, normals)
        scale = max(1.0, float(np.abs(want).max()))
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-9 * scale)
        assert n_fill > ref.n_fill  # the slabs' corners, not the crossings alone


def _same(a, b):
    """Two results of `_cstar.cut`, bit for bit."""
    assert a is not None and b is not None
    for x, y in zip(a, b):
        if isinstance(x, np.ndarray):
            assert x.dtype == y.dtype and x.shape == y.shape
            np.testing.assert_array_equal(x, y)
        else:
            assert x == y


@needs_c
@pytest.mark.parametrize("slabs_only", [False, True], ids=["arrangement", "slabs"])
def test_two_threads_give_the_slice_one_thread_gives(slabs_only):
    """A level with many crossing sections has some of their fills made by a second thread, which
    takes cells as the first does (its corners renumbered in cell order when the two are joined):
    the same arrays, in the same order, as one thread's, for the arrangement fill and for the slab
    fill.  A level with few stays on one."""
    name = "great icosahedral 120-cell"
    p = polytope(name)
    t = tables(p)
    st = starslice.star_tables(p, t)
    rng = np.random.default_rng(zlib.crc32(name.encode()) + slabs_only)
    for _ in range(4):
        m = random_rotation(rng)
        x = t.vertices @ m.T
        one = _cstar.cut(st.c, x, m, 0.07, t.tol, slabs_only=slabs_only, threads=1)
        assert st.c.threads_used == 1
        assert one[8] > 0  # fill corners made
        # levels back to back (a batch: two threads; levels further apart stay on one), the second
        # taking cells once it is awake: the same arrays either way.  Batches of 30, compared after
        # each (comparing between levels would part them by more than the batch gap), until the
        # second thread has taken cells in one where there are two processors (a busy machine may
        # be slow to schedule it: up to 20 s)
        used, start = [], time.monotonic()
        while not used or ((os.cpu_count() or 1) >= 2 and 2 not in used and time.monotonic() - start < 20):
            runs = []
            for _ in range(30):
                runs.append(_cstar.cut(st.c, x, m, 0.07, t.tol, slabs_only=slabs_only, threads=2))
                used.append(st.c.threads_used)
            for two in runs:
                _same(one, two)
        if (os.cpu_count() or 1) >= 2:  # (one processor: the second thread may never run in time)
            assert 2 in used  # (it did take some: this level is over the threshold)
        time.sleep(0.01)  # a level on its own (a key's next step): one thread
        _same(one, _cstar.cut(st.c, x, m, 0.07, t.tol, slabs_only=slabs_only, threads=2))
        assert st.c.threads_used == 1
    small = polytope("great grand 120-cell")  # its crossing sections are few and small: not worth a thread
    t = tables(small)
    _cstar.cut(starslice.star_tables(small, t).c, t.vertices @ m.T, m, 0.07, t.tol, threads=2)
    assert starslice.star_tables(small, t).c.threads_used == 1


@needs_c
def test_a_level_reuses_the_last_ones_memory_and_nothing_else():
    """Levels cut one after another reuse the arrays the last one grew (a pool per polytope): a
    large level, then a small one, then the large one again give what fresh memory gives (the pool
    held by another caller), whatever was left in it."""
    p = polytope("great icosahedral 120-cell")
    t = tables(p)
    st = starslice.star_tables(p, t)
    m = random_rotation(np.random.default_rng(11))
    x = t.vertices @ m.T
    top = float(x[:, 3].max())
    big = _cstar.cut(st.c, x, m, 0.05, t.tol)
    small = _cstar.cut(st.c, x, m, top - 0.05 * (top - float(x[:, 3].min())), t.tol)
    again = _cstar.cut(st.c, x, m, 0.05, t.tol)
    assert len(small[0]) < len(big[0]) / 4
    with st.c.pool_lock:  # another thread has the pool: this level takes fresh memory
        fresh_big = _cstar.cut(st.c, x, m, 0.05, t.tol)
        fresh_small = _cstar.cut(st.c, x, m, top - 0.05 * (top - float(x[:, 3].min())), t.tol)
    _same(big, fresh_big)
    _same(again, fresh_big)
    _same(small, fresh_small)
    assert not np.shares_memory(big[0], again[0])  # the caller's own arrays, not the pool's


@needs_c
@pytest.mark.skipif(not hasattr(os, "fork"), reason="no fork here")
def test_a_forked_process_slices_with_a_second_thread_of_its_own():
    """The pool's second thread, started in the parent, is not in a forked child (multiprocessing's
    fork): the child starts its own, gets the parent's slice, and both exit (no wait on a thread
    that is not there)."""
    code = ("import multiprocessing as mp, numpy as np\n"
            "from rot4d_widget import polytope\n"
            "from rot4d_widget.geometry import _cstar, starslice\n"
            "from rot4d_widget.geometry.slicing import slice_polytope\n"
            "from rot4d_widget.core.rotation import random_rotation\n"
            "p = polytope('great icosahedral 120-cell')\n"
            "m = random_rotation(np.random.default_rng(1))\n"
            "a = slice_polytope(p, m, 0.1)\n"
            "def child(q):\n"
            "    import time\n"
            "    same, used, start = True, [], time.monotonic()\n"
            "    while not used or (_cstar.THREADS == 2 and 2 not in used and time.monotonic() - start < 20):\n"
            "        ss = []  # batches back to back (two threads); the first levels may end before the\n"
            "        for _ in range(30):  # new thread takes a cell, and a busy machine may be slow to run it\n"
            "            ss.append(slice_polytope(p, m, 0.1))\n"
            "            used.append(starslice.star_tables(p, None).c.threads_used)\n"
            "        same = same and all(s.volume == a.volume and np.array_equal(s.triangles, a.triangles) for s in ss)\n"
            "    q.put((ss[-1].volume, same, max(used)))\n"
            "if __name__ == '__main__':\n"
            "    q = mp.get_context('fork').Queue()\n"
            "    pr = mp.get_context('fork').Process(target=child, args=(q,))\n"
            "    pr.start()\n"
            "    vol, same, used = q.get(timeout=120)\n"
            "    pr.join(60)\n"
            "    print(vol == a.volume, same, used if _cstar.THREADS == 2 else 2, pr.exitcode)\n")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.split() == ["True", "True", "2", "0"]
