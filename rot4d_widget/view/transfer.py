"""One-time transfers to the page: data the page keeps (a polytope to cut, a field to ray-cast),
sent once, in chunks under the update cap, and again only to a page that asks.

A transfer is named (``"polytope"``) and keyed (what it holds: the key changes when the data
does).  The companion's synced ``page_data`` says which key of each name the kernel offers; a
view that does not hold it asks (``{"event": "want", "name": ..., "key": ...}``) -- a new view, a
reloaded page -- and the kernel sends it as custom messages ``{"event": "transfer", "name", "key",
"part", "parts", "meta"}`` with one binary buffer each: the payload's bytes in order, at most
`CHUNK_BYTES` a message.  Custom messages are not part of the widget's state: a saved notebook or
a Voila page never embeds the data.  Several views asking at once are served once.

A large transfer (a field's data, ``paced``) goes `WINDOW` chunks ahead of what the page has
acknowledged (``{"event": "got", "name", "key", "part"}`` after each chunk it put in place): the
comm never holds megabytes queued ahead of the pictures and states that share it, and the
widget's bar (``bar``: `rot4d_widget.view.progress.ViewBar`) counts the chunks the page has.

`pack` lays named numpy arrays end to end in one payload with a table of where each is
(``page/transfer.js`` `unpack` reads it back as typed arrays).
"""

from __future__ import annotations

import numpy as np

from ..core.progress import progress
from .buffers import MAX_UPDATE_BYTES

__all__ = ["Transfers", "pack", "CHUNK_BYTES", "WINDOW"]

#: Bytes of one transfer message: well under the update cap, small enough to keep the comm
#: responsive between chunks.
CHUNK_BYTES = 4 * 2**20
assert CHUNK_BYTES < MAX_UPDATE_BYTES
#: Chunks of a paced transfer sent ahead of the page's acknowledgements.
WINDOW = 2

_DTYPES = {"float64": "<f8", "float32": "<f4", "int32": "<i4", "uint32": "<u4", "uint8": "<u1", "int8": "<i1",
           "uint16": "<u2", "int16": "<i2"}


def pack(arrays: dict, scalars: dict | None = None) -> tuple[dict, bytes]:
    """``(meta, payload)``: the arrays (each cast to one of the page's typed-array types: int64
    indices to int32, bool to uint8) laid end to end, 8-byte aligned, and ``meta`` = ``{"arrays":
    {name: {"type", "shape", "offset", "length"}}, "scalars": scalars}``."""
    parts, table, offset = [], {}, 0
    for name, a in arrays.items():
        a = np.asarray(a)
        if a.dtype == np.bool_:
            a = a.astype(np.uint8)
        elif a.dtype.kind in "iu" and a.dtype.itemsize == 8:
            if a.size and (a.min() < np.iinfo(np.int32).min or a.max() > np.iinfo(np.int32).max):
                raise ValueError(f"{name}: indices beyond int32 cannot go to the page")
            a = a.astype(np.int32)
        kind = a.dtype.name
        if kind not in _DTYPES:
            raise TypeError(f"{name}: a {a.dtype} array cannot go to the page (one of {', '.join(_DTYPES)})")
        data = np.ascontiguousarray(a, dtype=_DTYPES[kind]).tobytes()
        pad = (-offset) % 8
        if pad:
            parts.append(b"\0" * pad)
            offset += pad
        table[name] = {"type": kind, "shape": list(a.shape), "offset": offset, "length": int(a.size)}
        parts.append(data)
        offset += len(data)
    return {"arrays": table, "scalars": dict(scalars or {})}, b"".join(parts)


class Transfers:
    """The one-time transfers of one companion: what is offered (`offer`), sent when asked."""

    def __init__(self, companion):
        self.companion = companion
        self._offers: dict = {}  # name -> (key, meta, payload, paced)
        self._sending: dict = {}  # name -> paced sending under way: {key, next, acked, parts, counter}
        self.sent_bytes = 0  # every chunk's payload bytes sent so far (tests and benchmarks)
        #: where a paced transfer's progress shows (`ViewBar`), or None
        self.bar = None

    def offer(self, name: str, key: str, meta: dict, payload: bytes, *, paced: bool = False) -> None:
        """Offer ``payload`` (with ``meta``) as transfer ``name`` under ``key``; the page asks for it.
        ``paced``: sent `WINDOW` chunks ahead of the page's acknowledgements, counted on `bar`."""
        self._stop(name)
        self._offers[name] = (str(key), meta, payload, bool(paced))
        self.companion.page_data = {**self.companion.page_data, name: str(key)}

    def withdraw(self, name: str) -> None:
        """No transfer ``name`` any more (the page drops what it holds)."""
        self._stop(name)
        self._offers.pop(name, None)
        if name in self.companion.page_data:
            self.companion.page_data = {k: v for k, v in self.companion.page_data.items() if k != name}

    def sending(self, name: str):
        """``(parts the page has, parts)`` of a paced transfer under way, else None."""
        s = self._sending.get(name)
        return None if s is None else (s["acked"], s["parts"])

    def want(self, name, key) -> None:
        """A view asks for transfer ``name`` at ``key``: sent, if that is what is offered (a paced one
        from its first chunk again: a page that asks has none of it)."""
        offer = self._offers.get(name)
        if offer is None or offer[0] != key:
            return  # an old key: the page will ask for the new one when page_data says so
        _, meta, payload, paced = offer
        parts = max(1, -(-len(payload) // CHUNK_BYTES))
        if not paced:
            for i in range(parts):
                self._send(name, key, i, parts, meta, payload)
            return
        self._stop(name)
        counter = progress(parts, f"sending {name} to the page", mode="none")
        if self.bar is not None:
            counter.attach(self.bar)
        self._sending[name] = {"key": key, "next": 0, "acked": 0, "parts": parts, "counter": counter}
        self._pace(name)

    def got(self, name, key, part) -> None:
        """The page put chunk ``part`` of a paced transfer in place: the next ones go."""
        s = self._sending.get(name)
        if s is None or s["key"] != key or not isinstance(part, int) or isinstance(part, bool):
            return
        if part + 1 > s["acked"]:
            s["counter"].update(part + 1 - s["acked"])
            s["acked"] = part + 1
        if s["acked"] >= s["parts"]:
            self._stop(name)
            return
        self._pace(name)

    def _pace(self, name) -> None:
        s = self._sending[name]
        _, meta, payload, _ = self._offers[name]
        while s["next"] < s["parts"] and s["next"] < s["acked"] + WINDOW:
            self._send(name, s["key"], s["next"], s["parts"], meta, payload)
            s["next"] += 1

    def _stop(self, name) -> None:
        s = self._sending.pop(name, None)
        if s is not None:
            s["counter"].close()

    def _send(self, name, key, i, parts, meta, payload) -> None:
        chunk = payload[i * CHUNK_BYTES:(i + 1) * CHUNK_BYTES]
        msg = {"event": "transfer", "name": name, "key": key, "part": i, "parts": parts, "bytes": len(payload)}
        if i == 0:
            msg["meta"] = meta
        self.companion.send(msg, buffers=[chunk])
        self.sent_bytes += len(chunk)
