"""Stella4D's 4OFF format: read and write 4-polytopes with explicit faces and cells.

The format (one item per line; ``#`` starts a comment, blank lines are skipped)::

    4OFF
    V F E C                  # counts: vertices, 2-faces, edges, cells
    x y z w                  # V lines
    n v0 v1 ... v(n-1)       # F lines: a face, its n vertex indices in cyclic order
    k f0 f1 ... f(k-1)       # C lines: a cell, its k FACE indices

A face or cell line may end with a colour ``r g b`` or ``r g b a``: integers
0...255, or numbers with a decimal point or exponent in 0...1.  Colours are
checked and returned by `read_off`; a `Polytope` keeps none.  E may be 0
(not counted) or the true number of edges (checked once the faces are).

Geomview also has a ``4OFF``, with another meaning: homogeneous coordinates of
a 3-D surface (x y z w per vertex, faces on vertices, no cells).  It is
recognised and refused, by this heuristic: the header has one of Geomview's
prefixes (``ST``, ``C``, ``N``, ``n``: ``C4OFF``, ``4nOFF``, ...), or the
counts line has three numbers (Geomview's ``V F E``) instead of four, or it
declares no cells.

Every error is a ValueError that names the line (1-based) it is about.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass

import numpy as np

__all__ = ["OffData", "read_off", "write_off", "parse_off"]

_GEOMVIEW_HEADER = re.compile(r"^(ST|S|T)?C?N?4?n?OFF$")


@dataclass(frozen=True)
class OffData:
    """What a 4OFF file holds.

    vertices : (V, 4) float64
    faces : list of F lists of vertex indices
    cells : list of C lists of face indices
    face_colours, cell_colours : (F, 4) / (C, 4) float64 RGBA in 0...1 (alpha 1 when not
        given; NaN rows for items without a colour), or None when no line has one
    vertex_lines, face_lines, cell_lines : the 1-based line number of each item
    edge_count : E as written (0: not counted; `Polytope.from_off` checks any other value
        against the edges the faces make), counts_line : the line it is on
    """

    vertices: np.ndarray
    faces: list
    cells: list
    face_colours: np.ndarray | None
    cell_colours: np.ndarray | None
    vertex_lines: list
    face_lines: list
    cell_lines: list
    edge_count: int
    counts_line: int


def _lines(text: str):
    """(line number, tokens) of every line with content, comments removed."""
    for no, line in enumerate(text.splitlines(), start=1):
        content = line.split("#", 1)[0].split()
        if content:
            yield no, content


def _colour(tokens, no: int, what: str) -> np.ndarray:
    if len(tokens) not in (3, 4):
        raise ValueError(f"line {no}: {what} ends with {len(tokens)} extra numbers {' '.join(tokens)!r}; "
                         f"expected none or a colour r g b [a]")
    floats = any(("." in t) or ("e" in t.lower()) for t in tokens)
    try:
        vals = np.array([float(t) if floats else int(t) for t in tokens], dtype=float)
    except ValueError:
        raise ValueError(f"line {no}: {what} has a colour that is not numbers: {' '.join(tokens)!r}") from None
    if floats:
        if not np.all((vals >= 0) & (vals <= 1)):
            raise ValueError(f"line {no}: colour {' '.join(tokens)!r} out of range; expected numbers in 0...1 "
                             f"(or integers 0...255)")
    else:
        if not np.all((vals >= 0) & (vals <= 255)):
            raise ValueError(f"line {no}: colour {' '.join(tokens)!r} out of range; expected integers 0...255 "
                             f"(or numbers in 0...1)")
        vals = vals / 255.0
    return np.append(vals, 1.0) if len(vals) == 3 else vals


def _indices(tokens, no: int, what: str, item: str, limit: int):
    """``n i0 ... i(n-1) [colour]`` -> (indices, colour or None)."""
    try:
        n = int(tokens[0])
    except ValueError:
        raise ValueError(f"line {no}: {what} should start with its number of {item}s, got {tokens[0]!r}") from None
    if n < 1 or len(tokens) < n + 1:
        raise ValueError(f"line {no}: {what} says {n} {item}s but gives {len(tokens) - 1} numbers")
    try:
        idx = [int(t) for t in tokens[1 : n + 1]]
    except ValueError:
        raise ValueError(f"line {no}: {what} has a {item} index that is not an integer: "
                         f"{' '.join(tokens[1 : n + 1])!r}") from None
    bad = [i for i in idx if not 0 <= i < limit]
    if bad:
        raise ValueError(f"line {no}: {what} refers to {item} {bad[0]}; expected 0 to {limit - 1}")
    colour = _colour(tokens[n + 1 :], no, what) if len(tokens) > n + 1 else None
    return idx, colour


def parse_off(text: str) -> OffData:
    """Parse the text of a Stella4D 4OFF file (see the module docstring)."""
    if not isinstance(text, str):
        raise TypeError(f"Expected the 4OFF text as str, got {type(text).__name__}")
    lines = list(_lines(text))
    if not lines:
        raise ValueError("line 1: empty file; expected the header 4OFF")
    no, head = lines[0]
    word = head[0]
    if word != "4OFF":
        if _GEOMVIEW_HEADER.match(word) and word != "OFF":
            raise ValueError(f"line {no}: header {word!r} is Geomview's OFF variant (homogeneous or N-D "
                             f"coordinates of a surface, no cells); expected Stella4D's 4OFF with cells")
        raise ValueError(f"line {no}: expected the header 4OFF (Stella4D), got {word!r}")
    rest = head[1:]
    it = iter(lines[1:])
    if rest:  # counts on the header line
        counts_no, counts = no, rest
    else:
        try:
            counts_no, counts = next(it)
        except StopIteration:
            raise ValueError(f"line {no + 1}: missing the counts line V F E C") from None
    if len(counts) == 3:
        raise ValueError(f"line {counts_no}: three counts {' '.join(counts)!r} (V F E) and no cells: this looks "
                         f"like Geomview's 4OFF (homogeneous 3-D coordinates of a surface), which is not a "
                         f"4-polytope; expected Stella4D's 4OFF with counts V F E C")
    if len(counts) != 4:
        raise ValueError(f"line {counts_no}: expected four counts V F E C, got {' '.join(counts)!r}")
    try:
        nv, nf, ne, nc = (int(c) for c in counts)
    except ValueError:
        raise ValueError(f"line {counts_no}: expected four integer counts V F E C, got {' '.join(counts)!r}") from None
    if min(nv, nf, ne, nc) < 0:
        raise ValueError(f"line {counts_no}: negative count in {' '.join(counts)!r}")
    if nc == 0:
        raise ValueError(f"line {counts_no}: no cells (C = 0): a 4OFF without cells is a surface (Geomview's "
                         f"meaning?), not a 4-polytope; Stella4D's 4OFF lists the cells")

    def take(n: int, what: str):
        out = []
        for k in range(n):
            try:
                out.append(next(it))
            except StopIteration:
                last = lines[-1][0]
                raise ValueError(f"line {last + 1}: file ends after {k} of {n} {what} lines") from None
        return out

    vertices = np.empty((nv, 4))
    vertex_lines = []
    for k, (no, tok) in enumerate(take(nv, "vertex")):
        if len(tok) != 4:
            raise ValueError(f"line {no}: vertex {k} has {len(tok)} numbers; expected 4 coordinates x y z w")
        try:
            vertices[k] = [float(t) for t in tok]
        except ValueError:
            raise ValueError(f"line {no}: vertex {k} has a coordinate that is not a number: {' '.join(tok)!r}") from None
        if not np.all(np.isfinite(vertices[k])):
            raise ValueError(f"line {no}: vertex {k} is not finite: {' '.join(tok)!r}")
        vertex_lines.append(no)
    faces, face_lines, fcol = [], [], []
    for k, (no, tok) in enumerate(take(nf, "face")):
        idx, col = _indices(tok, no, f"face {k}", "vertex", nv)
        faces.append(idx)
        face_lines.append(no)
        fcol.append(col)
    cells, cell_lines, ccol = [], [], []
    for k, (no, tok) in enumerate(take(nc, "cell")):
        idx, col = _indices(tok, no, f"cell {k}", "face", nf)
        cells.append(idx)
        cell_lines.append(no)
        ccol.append(col)
    extra = next(it, None)
    if extra is not None:
        raise ValueError(f"line {extra[0]}: unexpected content after the {nc} cells: {' '.join(extra[1])!r}")

    def colours(cols):
        if all(c is None for c in cols):
            return None
        return np.array([np.full(4, np.nan) if c is None else c for c in cols])

    return OffData(vertices, faces, cells, colours(fcol), colours(ccol), vertex_lines, face_lines, cell_lines,
                   ne, counts_no)


def read_off(path_or_text) -> OffData:
    """Parse a 4OFF file given as a path (str or path-like) or as its text (a str containing
    a line break, or starting with ``4OFF``)."""
    if isinstance(path_or_text, (bytes, bytearray)):
        return parse_off(path_or_text.decode("utf-8"))
    if isinstance(path_or_text, str) and ("\n" in path_or_text or path_or_text.lstrip().startswith("4OFF")):
        return parse_off(path_or_text)
    if isinstance(path_or_text, (str, os.PathLike)):
        with open(path_or_text, encoding="utf-8") as fh:
            return parse_off(fh.read())
    raise TypeError(f"Expected a path or the text of a 4OFF file, got {type(path_or_text).__name__}")


def write_off(vertices, faces, cells, comment: str | None = None) -> str:
    """The 4OFF text of a mesh (coordinates written so that they read back exactly)."""
    v = np.asarray(vertices, dtype=float)
    edges = {tuple(sorted((int(f[i]), int(f[(i + 1) % len(f)])))) for f in faces for i in range(len(f))}
    out = ["4OFF"]
    if comment:
        out += [f"# {line}" for line in str(comment).splitlines()]
    out += ["# vertices faces edges cells", f"{len(v)} {len(faces)} {len(edges)} {len(cells)}", "", "# vertices"]
    out += [" ".join(repr(float(c)) for c in row) for row in v.tolist()]
    out += ["", "# faces: corner count, vertex indices in cyclic order"]
    out += [" ".join(str(int(i)) for i in (len(f), *f)) for f in faces]
    out += ["", "# cells: face count, face indices"]
    out += [" ".join(str(int(i)) for i in (len(c), *c)) for c in cells]
    return "\n".join(out) + "\n"
