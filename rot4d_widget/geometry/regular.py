"""The six regular polychora (the convex regular 4-polytopes), by name.

All with edge length 2 and centred on the origin, from the textbook coordinates (scaled to
edge 2):

========  ==========  ===================================================
name      Schläfli    vertices before scaling
========  ==========  ===================================================
5-cell    {3,3,3}     the paper's eqs. (8)-(12) with a = 2
8-cell    {4,3,3}     (±1, ±1, ±1, ±1)
16-cell   {3,3,4}     permutations of (±1, 0, 0, 0)
24-cell   {3,4,3}     permutations of (±1, ±1, 0, 0)
600-cell  {3,3,5}     permutations of (±1,0,0,0), (±½,±½,±½,±½), even
                      permutations of ½(±φ, ±1, ±1/φ, 0)
120-cell  {5,3,3}     the 600 points of circumradius √8 (see `cell120_vertices`)
========  ==========  ===================================================

`regular_name` reads a name, alias or Schläfli symbol; `named` builds (once) the polytope of a
canonical name.  `rot4d_widget.geometry.catalogue.polytope` resolves these and the uniform names.

>>> regular_name("Tesseract"), regular_name("{3,3,5}"), regular_name("rectified 5-cell")
('8-cell', '600-cell', None)
"""

from __future__ import annotations

import functools
import itertools
import math

import numpy as np

from ..core.validate import positive
from .mesh import Polytope

__all__ = ["PHI", "POLYTOPE_NAMES", "ALIASES", "regular_name", "named", "pentachoron"]

#: The golden ratio.
PHI = (1.0 + math.sqrt(5.0)) / 2.0

#: Canonical names, in order of vertex count.
POLYTOPE_NAMES = ("5-cell", "8-cell", "16-cell", "24-cell", "600-cell", "120-cell")

#: Other names of each, the Schläfli symbol last.
ALIASES = {
    "5-cell": ("5cell", "pentachoron", "simplex", "4-simplex", "pentatope", "hypertetrahedron", "{3,3,3}"),
    "8-cell": ("8cell", "tesseract", "hypercube", "octachoron", "4-cube", "{4,3,3}"),
    "16-cell": ("16cell", "hexadecachoron", "orthoplex", "cross-polytope", "4-orthoplex", "{3,3,4}"),
    "24-cell": ("24cell", "icositetrachoron", "octaplex", "{3,4,3}"),
    "120-cell": ("120cell", "hecatonicosachoron", "dodecaplex", "{5,3,3}"),
    "600-cell": ("600cell", "hexacosichoron", "tetraplex", "{3,3,5}"),
}
_NAME_OF = {}
for _canon, _aliases in ALIASES.items():
    for _alias in (_canon, *_aliases):
        _NAME_OF[_alias] = _canon


def _normalise_name(name: str) -> str:
    return "".join(name.lower().split()).replace("_", "-")


def regular_name(name: str) -> str | None:
    """The canonical name ("5-cell" ... "120-cell") of a regular polychoron's name, alias or
    Schläfli symbol (case, spaces and underscores do not matter), else None."""
    return _NAME_OF.get(_normalise_name(name))


def pentachoron(a: float = 2.0) -> Polytope:
    """The regular pentachoron of the paper's eqs. (8)-(12), edge ``a``, centroid at the origin."""
    a = positive(a, "edge length `a`", what="a positive number", finite_what="a positive finite number",
                 must="to be a positive finite number")
    s3, s6, s10 = math.sqrt(3.0), math.sqrt(6.0), math.sqrt(10.0)
    w = -a / (2 * s10)
    vertices = np.array(
        [
            [-a / 2, -a / (2 * s3), -a / (2 * s6), w],
            [a / 2, -a / (2 * s3), -a / (2 * s6), w],
            [0.0, a / s3, -a / (2 * s6), w],
            [0.0, 0.0, a * s3 / (2 * math.sqrt(2.0)), w],
            [0.0, 0.0, 0.0, 2 * a / s10],
        ]
    )
    return Polytope(vertices, name="5-cell" if a == 2.0 else f"5-cell (a={a:g})")


def _even_permutations():
    out = []
    for p in itertools.permutations(range(4)):
        inversions = sum(p[i] > p[j] for i in range(4) for j in range(i + 1, 4))
        if inversions % 2 == 0:
            out.append(p)
    return out


def _orbit(base, even_only: bool = False) -> np.ndarray:
    """All sign changes of the non-zero entries of ``base`` under (even) permutations."""
    perms = _even_permutations() if even_only else list(itertools.permutations(range(4)))
    base = np.asarray(base, dtype=float)
    signs = np.array(list(itertools.product((1.0, -1.0), repeat=4)))
    pts = np.concatenate([signs * base[list(p)] for p in perms])
    return pts


def _unique_rows(points: np.ndarray) -> np.ndarray:
    _, idx = np.unique(np.round(points, 9), axis=0, return_index=True)
    return points[np.sort(idx)]


def _cell8() -> np.ndarray:
    return np.array(list(itertools.product((-1.0, 1.0), repeat=4)))


def _cell16() -> np.ndarray:
    return _unique_rows(_orbit((1, 0, 0, 0))) * math.sqrt(2.0)


def _cell24() -> np.ndarray:
    return _unique_rows(_orbit((1, 1, 0, 0))) * math.sqrt(2.0)


def cell600_vertices() -> np.ndarray:
    pts = np.concatenate(
        [
            _orbit((1, 0, 0, 0)),
            _orbit((0.5, 0.5, 0.5, 0.5)),
            _orbit((PHI / 2, 0.5, 1 / (2 * PHI), 0.0), even_only=True),
        ]
    )
    return _unique_rows(pts) * (2.0 * PHI)  # edge 1/phi -> 2


def cell120_vertices() -> np.ndarray:
    """The 600 vertices of circumradius sqrt(8): permutations of (0,0,±2,±2),
    (±1,±1,±1,±√5), (±φ⁻²,±φ,±φ,±φ), (±φ⁻¹,±φ⁻¹,±φ⁻¹,±φ²) and even permutations
    of (0,±φ⁻²,±1,±φ²), (0,±φ⁻¹,±φ,±√5), (±φ⁻¹,±1,±φ,±2); edge 2/φ² scaled to 2."""
    s5 = math.sqrt(5.0)
    ip, ip2 = 1 / PHI, 1 / PHI**2
    pts = np.concatenate(
        [
            _orbit((0, 0, 2, 2)),
            _orbit((1, 1, 1, s5)),
            _orbit((ip2, PHI, PHI, PHI)),
            _orbit((ip, ip, ip, PHI**2)),
            _orbit((0, ip2, 1, PHI**2), even_only=True),
            _orbit((0, ip, PHI, s5), even_only=True),
            _orbit((ip, 1, PHI, 2), even_only=True),
        ]
    )
    return _unique_rows(pts) * PHI**2


_BUILDERS = {
    "5-cell": lambda: pentachoron(2.0).vertices,
    "8-cell": _cell8,
    "16-cell": _cell16,
    "24-cell": _cell24,
    "600-cell": cell600_vertices,
    "120-cell": cell120_vertices,
}



@functools.lru_cache(maxsize=None)
def named(canon: str) -> Polytope:
    """The regular polychoron of a canonical name (a key of `ALIASES`), built once and cached."""
    if canon == "5-cell":
        return pentachoron(2.0)
    return Polytope(_BUILDERS[canon](), name=canon)
