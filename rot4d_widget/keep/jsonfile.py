"""The package's JSON files (state files, recordings) read as plain data, within bounds.

A file from elsewhere is data: `read_json` parses it with the standard library (no object
hooks: only dicts, lists, strings, numbers, booleans and null come out) and refuses, with a
ValueError naming the file, what is not JSON, not UTF-8, or nested deeper than `MAX_DEPTH`
(the package's own files are a few levels deep; a 100,000-deep file made the parser raise
RecursionError, and deep values would make every later walk over them recurse as deep).
"""

from __future__ import annotations

import json
import os

__all__ = ["read_json", "MAX_DEPTH"]

#: Nesting deeper than this is refused: a state file or recording is at most about 8 deep.
MAX_DEPTH = 64


def read_json(path, what: str):
    """The JSON value in the file at ``path``; ValueError "``path`` is not a ``what``: ..." when it
    cannot be read as one (``what``: "rot4d_widget state file", "rot4d_widget recording")."""
    name = os.fspath(path)
    try:
        with open(name, encoding="utf-8") as fh:
            doc = json.load(fh)
    except json.JSONDecodeError as exc:
        raise ValueError(f"{name!r} is not a {what}: not JSON ({exc})") from None
    except UnicodeDecodeError:
        raise ValueError(f"{name!r} is not a {what}: not UTF-8 text") from None
    except RecursionError:
        raise ValueError(f"{name!r} is not a {what}: nested deeper than {MAX_DEPTH} levels") from None
    if _depth(doc) > MAX_DEPTH:
        raise ValueError(f"{name!r} is not a {what}: nested deeper than {MAX_DEPTH} levels")
    return doc


def _depth(value) -> int:
    """How deep lists and dicts nest in ``value`` (0 for a number or a string), without recursion."""
    deepest, todo = 0, [(value, 0)]
    while todo:
        v, d = todo.pop()
        if isinstance(v, dict):
            v = list(v.values())
        if isinstance(v, list):
            d += 1
            deepest = max(deepest, d)
            if d > MAX_DEPTH:
                return d
            todo.extend((x, d) for x in v)
    return deepest
