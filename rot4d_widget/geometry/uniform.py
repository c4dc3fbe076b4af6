"""Convex uniform 4-polytopes (polychora): the Wythoff construction, its combinatorics, names.

Here: the 45 distinct polychora of the 60 ring patterns of the linear diagrams A4, B4, F4 and H4;
the snub 24-cell and the grand antiprism (the two non-Wythoffian convex ones); prisms over the
Platonic and Archimedean solids, the p-q duoprisms and the p-antiprismatic prisms for
3 <= p, q <= 32.  Every one has edge length 2 and is centred on the origin, like the regular six
of :mod:`rot4d_widget.geometry.regular`, and ``build("x3o3o3o")`` returns ``polytope("5-cell")``
itself.  The combinatorics come from the group, not from the geometry (docs/design.md, "Uniform
polychora from the group").  This module holds the table of names (`canonical_name`,
``polytope_names()``) and the public API; the groups and the construction are in
`rot4d_widget.geometry.wythoff`, the snubs, the grand antiprism, the polyhedra and the prismatic
families in `rot4d_widget.geometry.constructions`.
"""

from __future__ import annotations

import functools
import re

from .constructions import (
    ADJECTIVE,
    POLYHEDRA,
    antiprism,
    duoprism,
    grand_antiprism,
    polyhedron,
    prism,
    snub_24_cell,
)
from .mesh import Polytope
from .regular import ALIASES, PHI, POLYTOPE_NAMES, named
from .wythoff import POLYGON_WORDS, Combinatorics, wythoff

__all__ = ["build", "canonical_name", "polytope_names", "dynkin_symbol", "Combinatorics", "combinatorics"]

#: ``PHI`` (the golden ratio), `wythoff`, `polyhedron`: importable here as before
_REEXPORTED = (PHI, wythoff, polyhedron)

MAX_P = 32  #: largest p, q of the duoprisms and antiprismatic prisms


# ---------------------------------------------------------------------------------------------
# The table of names
# ---------------------------------------------------------------------------------------------

_GROUPS = {"A4": (3, 3, 3), "B4": (4, 3, 3), "F4": (3, 4, 3), "H4": (5, 3, 3)}
#: the regular polytope at each end of a diagram: (node 0 ringed, node 3 ringed)
_ENDS = {"A4": ("5-cell", "5-cell"), "B4": ("tesseract", "16-cell"), "F4": ("24-cell", "24-cell"),
         "H4": ("120-cell", "600-cell")}
#: ring pattern (node 0 .. node 3) -> operator on P (node 0 end) or Q (node 3 end)
_OPERATORS = {
    "xooo": ("", "P"), "oxoo": ("rectified", "P"), "ooxo": ("rectified", "Q"), "ooox": ("", "Q"),
    "xxoo": ("truncated", "P"), "xoxo": ("cantellated", "P"), "xoox": ("runcinated", "P"),
    "oxxo": ("bitruncated", "P"), "oxox": ("cantellated", "Q"), "ooxx": ("truncated", "Q"),
    "xxxo": ("cantitruncated", "P"), "xxox": ("runcitruncated", "P"), "xoxx": ("runcitruncated", "Q"),
    "oxxx": ("cantitruncated", "Q"), "xxxx": ("omnitruncated", "P"),
}
#: the same polytope under two names: B4 patterns that are F4 polytopes, regular names of the core
_SAME = {"rectified 16-cell": "24-cell", "cantellated 16-cell": "rectified 24-cell",
         "cantitruncated 16-cell": "truncated 24-cell", "tesseract": "8-cell"}
#: the family label of each group in `polytope_names`
_FAMILY = {"A4": "A4: 5-cell family [3,3,3]", "B4": "B4: tesseract / 16-cell family [4,3,3]",
           "F4": "F4: 24-cell family [3,4,3]", "H4": "H4: 120-cell / 600-cell family [5,3,3]"}
_REGULAR_DYNKIN = {"5-cell": "x3o3o3o", "8-cell": "x4o3o3o", "16-cell": "o4o3o3x", "24-cell": "x3o4o3o",
                   "120-cell": "x5o3o3o", "600-cell": "o5o3o3x"}
_POLYGON_PREFIX = POLYGON_WORDS


def _symbol(labels, pattern: str) -> str:
    return "".join(c + (str(m) if k < len(labels) else "") for k, (c, m) in enumerate(zip(pattern, (*labels, 0))))


@functools.lru_cache(maxsize=None)
def _table():
    """(entries, alias, families): canonical name -> entry dict; normalised alias -> canonical
    name; family label -> canonical names in order."""
    entries, alias = {}, {}
    families = {_FAMILY[g]: [] for g in _GROUPS}

    def add(canon, family, kind, symbol=None, *aliases, **data):
        if canon not in entries:
            entries[canon] = dict(name=canon, family=family, kind=kind, symbol=symbol, **data)
            families.setdefault(family, []).append(canon)
        for a in (canon, symbol, *aliases):
            if a:
                alias.setdefault(_norm(a), canon)

    # F4 before B4: three B4 patterns are F4 polytopes and are named (and built) as those
    for gname in ("A4", "F4", "B4", "H4"):
        labels = _GROUPS[gname]
        P, Q = _ENDS[gname]
        for pattern, (op, end) in _OPERATORS.items():  # every "P" pattern precedes its reverse
            name = f"{op} {P if end == 'P' else Q}".strip()
            name = {"tesseract": "8-cell"}.get(name, name)
            canon = _SAME.get(name, name)
            sym = _symbol(labels, pattern)
            extra = [f"{op} {Q}"] if op in ("runcinated", "bitruncated", "omnitruncated") and P != Q else []
            if canon in entries:  # a reversed A4 / F4 diagram, or a B4 pattern of an F4 polytope
                for a in (sym, name, *extra):
                    alias.setdefault(_norm(a), canon)
                continue
            add(canon, _FAMILY[gname], "regular" if op == "" else "wythoff", sym, *extra,
                labels=labels, rings=tuple(c == "x" for c in pattern))
    fam = "non-Wythoffian: snub 24-cell and grand antiprism"
    add("snub 24-cell", fam, "snub24", "s3s4o3o", "o3o4s3s", "snub icositetrachoron")
    add("grand antiprism", fam, "grand", None, "gap", "pentagonal double antiprismoid")
    fam = "prisms over the Platonic and Archimedean solids"
    for poly, (psym, _, _) in POLYHEDRA.items():
        canon = f"{ADJECTIVE[poly]} prism"
        if poly == "cube":  # the cubic prism is the tesseract
            for a in (canon, f"{poly} prism", psym + " x"):
                alias.setdefault(_norm(a), "8-cell")
            continue
        add(canon, fam, "prism", psym + " x", f"{poly} prism", base=poly)
    fam = f"duoprisms p-q (3 <= p <= q <= {MAX_P})"
    for p in range(3, MAX_P + 1):
        for q in range(p, MAX_P + 1):
            names = [f"{p}-{q} duoprism", f"{q}-{p} duoprism", f"x{q}o x{p}o"]
            if p == 4 or q == 4:  # the prism over a q-gonal (p-gonal) prism
                names += [f"{w} prism prism" for w in _polygon_words(q if p == 4 else p)]
            if p == 4 and q == 4:  # the tesseract
                for a in names + [f"x{p}o x{q}o"]:
                    alias.setdefault(_norm(a), "8-cell")
                continue
            add(f"{p}-{q} duoprism", fam, "duoprism", f"x{p}o x{q}o", *names, p=p, q=q)
    fam = f"antiprismatic prisms (3 <= p <= {MAX_P})"
    for p in range(3, MAX_P + 1):
        words = [f"{p}-antiprismatic prism", f"{p}-gonal antiprismatic prism", f"{p}-gonal antiprism prism",
                 f"{p}-antiprism prism", f"s2s{2 * p}o x"]
        if p in _POLYGON_PREFIX:
            words += [f"{_POLYGON_PREFIX[p]} antiprismatic prism", f"{_POLYGON_PREFIX[p]} antiprism prism"]
        if p == 3:  # the triangular antiprism is the octahedron
            for a in words:
                alias.setdefault(_norm(a), "octahedral prism")
            continue
        add(f"{p}-antiprismatic prism", fam, "antiprism", f"s2s{2 * p}o x", *words, p=p)
    # the regular six under the core's own names and aliases
    for canon in POLYTOPE_NAMES:
        for a in (canon, *ALIASES[canon]):
            alias.setdefault(_norm(a), canon)
    return entries, alias, families


def _polygon_words(m: int) -> list:
    """How a regular m-gonal prism may be called: "pentagonal", "5-gonal", "5"."""
    out = [f"{m}-gonal", f"{m}"]
    if m in _POLYGON_PREFIX:
        out.append(_POLYGON_PREFIX[m])
    return out


def _norm(name: str) -> str:
    """Case, spaces, underscores and hyphens do not matter, except a hyphen between two numbers."""
    s = name.strip().lower().replace("_", " ")
    s = re.sub(r"(?<=\d)\s*-\s*(?=\d)", "~", s)  # keep "5-7"
    return re.sub(r"[\s\-]+", "", s)


# ---------------------------------------------------------------------------------------------
# Public API
# ---------------------------------------------------------------------------------------------


def canonical_name(name) -> str | None:
    """The canonical name of a polychoron given by any accepted name or Dynkin symbol, else None.

    Accepted: the common names ("rectified 5-cell", "omnitruncated 120-cell", "snub 24-cell",
    "grand antiprism", "5-7 duoprism", "truncated cubic prism", "pentagonal prism prism",
    "7-antiprismatic prism", ...), the linear Dynkin notation ("x3o3o3o", "o3x3o3o", "x4x3o3o",
    "x5x3x3x", "s3s4o3o"; a diagram read backwards is the same polytope; prismatic ones "x5o x7o",
    "x4x3o x", "s2s14o x") and the aliases of the regular six.

    >>> canonical_name("o3x3o3o"), canonical_name("Truncated Tesseract"), canonical_name("7-5 duoprism")
    ('rectified 5-cell', 'truncated tesseract', '5-7 duoprism')
    """
    if not isinstance(name, str):
        raise TypeError(f"Expected a polychoron name (str), got {type(name).__name__}")
    return _table()[1].get(_norm(name))


def _canonical_or_raise(name) -> str:
    canon = canonical_name(name)
    if canon is None:
        raise ValueError(
            f"Unknown polychoron {name!r}; rot4d_widget.geometry.uniform.polytope_names() lists the accepted names "
            "by family (e.g. 'rectified 5-cell', 'truncated tesseract', 'omnitruncated 120-cell', "
            "'snub 24-cell', 'grand antiprism', '5-7 duoprism', 'truncated cubic prism', "
            "'7-antiprismatic prism'), and linear Dynkin symbols such as 'o3x3o3o', 'x4x3o3o', 'x5x3x3x' "
            "are accepted too")
    return canon


def polytope_names() -> dict:
    """``{family: [canonical names]}``: the 47 non-prismatic polychora in four Coxeter families
    plus the two non-Wythoffian ones, then the prismatic families.  The regular six appear in
    their families under the core's names ("5-cell", "8-cell", ...)."""
    return {fam: list(names) for fam, names in _table()[2].items()}


def dynkin_symbol(name) -> str | None:
    """The linear Coxeter–Dynkin symbol of a polychoron ("x5x3x3x"), or None for the grand antiprism.

    Prismatic ones are written as products: "x5o x7o" (5-7 duoprism), "x4x3o x" (truncated
    cubic prism), "s2s14o x" (7-antiprismatic prism); "s" marks a snub (alternated) node.
    """
    canon = _canonical_or_raise(name)
    if canon in _REGULAR_DYNKIN:
        return _REGULAR_DYNKIN[canon]
    return _table()[0][canon]["symbol"]


def family(name) -> str:
    """The family label (a key of `polytope_names`) of a polychoron."""
    return _table()[0][_canonical_or_raise(name)]["family"]


def combinatorics(name) -> Combinatorics:
    """Vertices, edges, 2-faces (vertex cycles) and cells (face indices) of a polychoron.

    For the regular six this is the Wythoff construction (vertices in the group's order and
    orientation, not the core's arrays): `build` returns the core's objects instead.  Cached:
    treat the arrays as read-only.
    """
    return _combinatorics(_canonical_or_raise(name))


@functools.lru_cache(maxsize=64)
def _combinatorics(canon: str) -> Combinatorics:
    if canon in _REGULAR_DYNKIN:
        sym = _REGULAR_DYNKIN[canon]
        labels = tuple(int(c) for c in sym[1::2])
        return wythoff(labels, tuple(c == "x" for c in sym[0::2]))
    e = _table()[0][canon]
    kind = e["kind"]
    if kind == "wythoff":
        return wythoff(e["labels"], e["rings"])
    if kind == "snub24":
        return snub_24_cell()
    if kind == "grand":
        return grand_antiprism()
    if kind == "prism":
        return prism(polyhedron(e["base"]), e["base"])
    if kind == "duoprism":
        return duoprism(e["p"], e["q"])
    if kind == "antiprism":
        return prism(antiprism(e["p"]), f"{_POLYGON_PREFIX.get(e['p'], str(e['p']) + '-gonal')} antiprism")
    raise AssertionError(kind)


def _as_polytope(comb: Combinatorics, name: str):
    """A core `Polytope` from explicit combinatorics (``Polytope(vertices, faces, cells)``).

    Validated even though the construction is exact: the constructor's checks (planar convex
    faces, closed convex cells, orientable boundary) are part of the build times in
    docs/performance.md (`benchmarks/uniform_build.py`).
    """
    return Polytope(comb.vertices, comb.faces, comb.cells, name=name)


@functools.lru_cache(maxsize=None)
def _built(canon: str):
    if canon in _REGULAR_DYNKIN:
        return named(canon)
    return _as_polytope(combinatorics(canon), canon)


def build(name):
    """The polychoron called ``name`` as a `rot4d_widget.geometry.mesh.Polytope` (edge 2, centred).

    ``name``: a canonical or common name, an alias or a linear Dynkin symbol (see
    `canonical_name`; `polytope_names` lists the canonical names).  The regular six are the core's own
    objects (``build("x3o3o3o") is polytope("5-cell")``).  Built once and cached.

    Raises TypeError for a non-str and ValueError, saying where the names are listed, for an
    unknown name.
    """
    return _built(_canonical_or_raise(name))
