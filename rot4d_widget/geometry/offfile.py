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

Every error is a ValueError that names the line (1-based) it is about (and the file, when
read from one).  A file is read one line at a time and never trusted for sizes: a line longer
than `MAX_LINE_CHARS`, bytes that are not UTF-8 text, and counts that the rest of the file
cannot hold (or above `MAX_COUNT`) are refused before anything is allocated for them.  The
reader only parses numbers: nothing in a file is imported or evaluated.
"""

from __future__ import annotations

import io
import os
import re
from dataclasses import dataclass

import numpy as np

__all__ = ["OffData", "read_off", "write_off", "parse_off", "MAX_LINE_CHARS", "MAX_COUNT"]

_GEOMVIEW_HEADER = re.compile(r"^(ST|S|T)?C?N?4?n?OFF$")
#: The longest line read (a face of 100 000 corners fits); a longer one is refused when that much is read.
MAX_LINE_CHARS = 1 << 20
#: The most vertices, faces, edges or cells a file may declare (each is also checked against the
#: bytes the file has left, when its size is known).
MAX_COUNT = 100_000_000
#: Bytes that were not UTF-8, as ``errors="surrogateescape"`` decodes them.
_UNDECODED = re.compile("[\udc80-\udcff]")


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


class _Lines:
    """``(line number, tokens)`` of every line with content, comments removed, read one line at a
    time from ``stream`` (a text stream: ``readline(limit)`` returning str).

    A line longer than `MAX_LINE_CHARS` is refused as soon as that much is read; so is a NUL
    character (a binary file) and, when ``decoded`` (the text was decoded from bytes with
    ``errors="surrogateescape"``), a byte that is not UTF-8.  ``consumed`` counts the characters
    read so far, ``last`` is the number of the last line with content.
    """

    def __init__(self, stream, decoded: bool = False):
        self._readline = stream.readline
        self._decoded = decoded
        self.no = 0
        self.last = 0
        self.consumed = 0

    def __iter__(self):
        return self

    def __next__(self):
        while True:
            line = self._readline(MAX_LINE_CHARS + 1)
            if not line:
                raise StopIteration
            self.no += 1
            self.consumed += len(line)
            if len(line) > MAX_LINE_CHARS and not line.endswith("\n"):
                raise ValueError(f"line {self.no}: longer than {MAX_LINE_CHARS} characters; a 4OFF line holds one "
                                 f"count line, vertex, face or cell (is this a 4OFF file?)")
            if self._decoded:
                bad = _UNDECODED.search(line)
                if bad:
                    raise ValueError(f"line {self.no}: not UTF-8 text (byte 0x{ord(bad.group()) - 0xDC00:02x} at "
                                     f"column {bad.start() + 1}): a 4OFF file is text")
            if "\x00" in line:
                raise ValueError(f"line {self.no}: a NUL byte at column {line.index(chr(0)) + 1}: a binary file, "
                                 f"not 4OFF text")
            if self.no == 1 and line.startswith("\ufeff"):  # a byte order mark
                line = line[1:]
            content = line.split("#", 1)[0].split()
            if content:
                self.last = self.no
                return self.no, content


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
    return _parse(_Lines(io.StringIO(text, newline=None)), len(text))


def _parse(lines: _Lines, size: int | None) -> OffData:
    """Parse what ``lines`` reads; ``size``: an upper bound of the characters (bytes) of the
    whole input, or None if unknown, to refuse counts that cannot fit before allocating."""
    first = next(lines, None)
    if first is None:
        raise ValueError("line 1: empty file; expected the header 4OFF")
    no, head = first
    word = head[0]
    if word != "4OFF":
        if _GEOMVIEW_HEADER.match(word) and word != "OFF":
            raise ValueError(f"line {no}: header {word!r} is Geomview's OFF variant (homogeneous or N-D "
                             f"coordinates of a surface, no cells); expected Stella4D's 4OFF with cells")
        raise ValueError(f"line {no}: expected the header 4OFF (Stella4D), got {word!r}")
    rest = head[1:]
    if rest:  # counts on the header line
        counts_no, counts = no, rest
    else:
        try:
            counts_no, counts = next(lines)
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
    # every vertex line is at least "x y z w\n" (8 characters), a face or cell line "n i\n" (4):
    # counts the rest of the file cannot hold are refused before anything is allocated
    need = 8 * nv + 4 * nf + 4 * nc - 1
    left = None if size is None else size - lines.consumed
    if left is not None and need > left:
        raise ValueError(f"line {counts_no}: the counts {' '.join(counts)!r} declare {nv} vertices, {nf} faces and "
                         f"{nc} cells, which take at least {need} more bytes, but the file has {max(left, 0)} left: "
                         f"the counts are wrong or the file is cut short")
    if max(nv, nf, ne, nc) > MAX_COUNT:
        raise ValueError(f"line {counts_no}: counts {' '.join(counts)!r} above {MAX_COUNT:,}; this reader takes at "
                         f"most {MAX_COUNT:,} of each")

    def take(n: int, what: str):
        for k in range(n):
            try:
                yield k, next(lines)
            except StopIteration:
                raise ValueError(f"line {lines.last + 1}: file ends after {k} of {n} {what} lines") from None

    vertices = np.empty((nv if left is not None else min(nv, 1 << 16), 4))  # grown below if the size is unknown
    vertex_lines = []
    for k, (no, tok) in take(nv, "vertex"):
        if len(tok) != 4:
            raise ValueError(f"line {no}: vertex {k} has {len(tok)} numbers; expected 4 coordinates x y z w")
        if k == len(vertices):
            vertices = np.concatenate([vertices, np.empty((min(len(vertices), nv - k), 4))])
        try:
            vertices[k] = [float(t) for t in tok]
        except ValueError:
            raise ValueError(f"line {no}: vertex {k} has a coordinate that is not a number: "
                             f"{' '.join(tok)!r}") from None
        if not np.all(np.isfinite(vertices[k])):
            raise ValueError(f"line {no}: vertex {k} is not finite: {' '.join(tok)!r}")
        vertex_lines.append(no)
    vertices = vertices[:nv]
    faces, face_lines, fcol = [], [], []
    for k, (no, tok) in take(nf, "face"):
        idx, col = _indices(tok, no, f"face {k}", "vertex", nv)
        faces.append(idx)
        face_lines.append(no)
        fcol.append(col)
    cells, cell_lines, ccol = [], [], []
    for k, (no, tok) in take(nc, "cell"):
        idx, col = _indices(tok, no, f"cell {k}", "face", nf)
        cells.append(idx)
        cell_lines.append(no)
        ccol.append(col)
    extra = next(lines, None)
    if extra is not None:
        raise ValueError(f"line {extra[0]}: unexpected content after the {nc} cells: {' '.join(extra[1])!r}")

    def colours(cols):
        if all(c is None for c in cols):
            return None
        return np.array([np.full(4, np.nan) if c is None else c for c in cols])

    return OffData(vertices, faces, cells, colours(fcol), colours(ccol), vertex_lines, face_lines, cell_lines,
                   ne, counts_no)


def _stream_size(fh) -> int | None:
    """Bytes from ``fh``'s position to its end, if it is a seekable file; else None."""
    try:
        return os.fstat(fh.fileno()).st_size - fh.tell()
    except (AttributeError, OSError, ValueError, io.UnsupportedOperation):
        return None


def read_off(path_or_text) -> OffData:
    """Parse a 4OFF file given as a path (str or path-like), as its text (a str containing a line
    break, or starting with ``4OFF``), as bytes, or as an open file (binary or text).

    The file is read one line at a time: an over-long line (`MAX_LINE_CHARS`), bytes that are
    not UTF-8 or counts the file's size cannot hold are refused at once, as a ValueError that
    names the file and the line.
    """
    if isinstance(path_or_text, (bytes, bytearray)):
        data = bytes(path_or_text)
        text = io.TextIOWrapper(io.BytesIO(data), encoding="utf-8", errors="surrogateescape", newline=None)
        return _parse(_Lines(text, decoded=True), len(data))
    if isinstance(path_or_text, str) and ("\n" in path_or_text or path_or_text.lstrip().startswith("4OFF")):
        return parse_off(path_or_text)
    if isinstance(path_or_text, (str, os.PathLike)):
        path = os.fspath(path_or_text)
        with open(path, encoding="utf-8", errors="surrogateescape", newline=None) as fh:
            size = os.fstat(fh.fileno()).st_size
            try:
                return _parse(_Lines(fh, decoded=True), size)
            except ValueError as exc:
                raise ValueError(f"{path!r}, {exc}") from None
    if hasattr(path_or_text, "readline") and hasattr(path_or_text, "read"):
        fh = path_or_text
        name = getattr(fh, "name", None)
        if isinstance(fh.read(0), str):
            lines, size, wrapper = _Lines(fh), None, None
        else:
            size = _stream_size(fh)
            wrapper = io.TextIOWrapper(fh, encoding="utf-8", errors="surrogateescape", newline=None)
            lines = _Lines(wrapper, decoded=True)
        try:
            return _parse(lines, size)
        except ValueError as exc:
            if isinstance(name, str):
                raise ValueError(f"{name!r}, {exc}") from None
            raise
        finally:
            if wrapper is not None:
                wrapper.detach()  # the caller's file stays open
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
