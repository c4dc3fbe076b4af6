"""The field kernels are compiled once ever, also for a package installed where it cannot write
(issue 35: the first widget on a field took 9.5 s in every new kernel).

Two fresh processes run the serial and the parallel kernels on a tiny array; numba's in-tree cache
(``__pycache__`` beside the module) is made unavailable in both, as for a package installed
read-only, so numba must use the user's cache folder (``$XDG_CACHE_HOME/numba`` here, a temporary
folder).  The second process must load every kernel from there and compile none.  The serial and
the parallel kernel each have their own entry: one function jitted both ways shared one, and the
parallel dispatcher loaded the serial code.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

pytest.importorskip("numba")

CHILD = r"""
import json
import numba.core.caching as caching
import numpy as np

# a package installed read-only: its folder is no place for a cache (numba renamed the class in 0.61)
in_tree = getattr(caching, "InTreeCacheLocator", None) or getattr(caching, "_InTreeCacheLocator")
in_tree.from_function = classmethod(lambda cls, py_func, py_file: None)
from rot4d_widget.sources.field import kernels as fk

a = np.zeros((3, 3, 3, 3))
out = {}
for parallel in (False, True):
    affine, points = fk._get_kernels(parallel)
    fk.resample_points(a, np.ones((2, 4)), np.ones(2, bool)) if not parallel else None
    n = np.array((2, 2, 2))
    affine(a, np.zeros(4), np.eye(3, 4), n, np.ones(4), np.ones(4), np.ones(4), np.empty((2, 2, 2)), np.empty((2, 2, 2)))
    points(a, np.ones((2, 4)), np.ones(2, bool), np.empty(2))
    for k in (affine, points):
        out[k.py_func.__name__] = [sum(k.stats.cache_hits.values()), sum(k.stats.cache_misses.values()),
                                   k._cache.cache_path]
print("RESULT" + json.dumps(out))
"""


def _run(env):
    proc = subprocess.run([sys.executable, "-c", CHILD], env=env, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    return json.loads(proc.stdout.split("RESULT", 1)[1])


def test_the_kernels_are_loaded_from_the_user_cache_in_a_new_process(tmp_path):
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env["XDG_CACHE_HOME"] = str(tmp_path / "cache")
    first = _run(env)
    assert set(first) == {"_affine_serial", "_points_serial", "_affine_parallel", "_points_parallel"}
    for name, (_, _, path) in first.items():
        assert path.startswith(str(tmp_path / "cache")), (name, path)  # the user's cache, not the package's folder
    second = _run(env)
    for name, (hits, misses, _) in second.items():
        assert hits >= 1 and misses == 0, f"{name}: {hits} cache hits, {misses} compiled in the second process"
    files = os.listdir(first["_affine_serial"][2])
    assert any(f.startswith("kernels._affine_parallel") for f in files)
    assert any(f.startswith("kernels._affine_serial") for f in files)
