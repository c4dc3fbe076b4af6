"""A catalogue of names: `polytope(name)` resolves the six regular polychora, the ten regular star
ones and every uniform one; `polytope_names()` lists them by family.

The regular six come from `rot4d_widget.geometry.regular` (by name, alias or Schläfli symbol), the
ten star polychora from `rot4d_widget.geometry.star_regular` (the same), the others from
`rot4d_widget.geometry.uniform` (common names and linear Dynkin symbols).  This module sits above
them, so none imports another's resolver: the imports run ``mesh <- regular <- uniform, star_regular
<- catalogue``.
"""

from __future__ import annotations

from . import star_regular, uniform
from .mesh import Polytope
from .regular import ALIASES, POLYTOPE_NAMES, named, regular_name

__all__ = ["polytope", "polytope_names"]


def polytope_names() -> dict:
    """``{family: [canonical names]}``: the uniform families (`rot4d_widget.geometry.uniform.polytope_names`,
    the regular six among them), then the ten regular star polychora (`STAR_FAMILY`)."""
    names = uniform.polytope_names()
    names[star_regular.STAR_FAMILY] = list(star_regular.STAR_NAMES)
    return names


def polytope(name) -> Polytope:
    """A uniform or regular star polychoron with edge 2, centred on the origin, by name.

    The six regular ones by name, alias or Schläfli symbol: ``"5-cell"`` (pentachoron,
    ``"{3,3,3}"``), ``"8-cell"`` (tesseract), ``"16-cell"``, ``"24-cell"``, ``"120-cell"``,
    ``"600-cell"``; the ten regular star (Schläfli–Hess) polychora by name, Schläfli symbol or
    alias (``"great grand stellated 120-cell"``, ``"{5/2,3,3}"``:
    `rot4d_widget.geometry.star_regular`); every other uniform one
    (`rot4d_widget.geometry.uniform`: the Wythoff families,
    the snub 24-cell, the grand antiprism, prisms, duoprisms, antiprismatic prisms) by its
    common name (``"rectified 5-cell"``, ``"5-7 duoprism"``) or linear Dynkin symbol
    (``"o3x3o3o"``, ``"x5x3x3x"``); ``rot4d_widget.polytope_names()`` lists them.  A
    `Polytope` is returned as is.  The result is built once and cached.

    >>> polytope("tesseract").counts, polytope("{3,3,3}") is polytope("5-cell")
    ((16, 32, 24, 8), True)
    """
    if isinstance(name, Polytope):
        return name
    if not isinstance(name, str):
        raise TypeError(f"Expected a polytope name (str) or a Polytope, got {type(name).__name__}")
    canon = regular_name(name)
    if canon is not None:
        return named(canon)
    if star_regular.star_name(name) is not None:
        return star_regular.star_polytope(name)
    if uniform.canonical_name(name) is not None:
        return uniform.build(name)
    allowed = ", ".join(f"{n!r} ({', '.join(ALIASES[n][1:3])}, {ALIASES[n][-1]})" for n in POLYTOPE_NAMES)
    stars = ", ".join(f"{n!r} ({s.symbol})" for n, s in star_regular.SPECS.items())
    raise ValueError(f"Unknown polytope {name!r}; expected one of {allowed}; a regular star polychoron: {stars}; "
                     "or a uniform polychoron by name or Dynkin symbol (rot4d_widget.polytope_names() lists them)")
