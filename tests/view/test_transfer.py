"""One-time transfers to the page (issue 33 item 3, issue 34): chunks under the update cap, sent
when a page asks, put together and unpacked in the page as the arrays that left."""

from __future__ import annotations

import base64

import numpy as np
import pytest

from page_node import run_page
from rot4d_widget.view import transfer as tr
from rot4d_widget.view.buffers import MAX_UPDATE_BYTES
from rot4d_widget.view.companion import Companion
from test_companion import FakeScene, from_page


pytestmark = pytest.mark.usefixtures("recording_comms")  # tests/conftest.py


def _companion(monkeypatch):
    c = Companion(FakeScene())
    sent = []
    monkeypatch.setattr(c, "send", lambda msg, buffers=None: sent.append((msg, [bytes(b) for b in buffers or ()])))
    return c, sent


def test_a_payload_goes_in_chunks_under_the_cap_only_when_asked_for_the_key_offered(monkeypatch):
    c, sent = _companion(monkeypatch)
    payload = bytes(range(256)) * (3 * tr.CHUNK_BYTES // 256 + 10)
    c.transfers.offer("polytope", "k1", {"arrays": {}}, payload)
    assert c.page_data == {"polytope": "k1"} and sent == []
    from_page(c, {"event": "want", "name": "polytope", "key": "old"})  # not what is offered: nothing
    assert sent == []
    from_page(c, {"event": "want", "name": "polytope", "key": "k1"})
    assert len(sent) == 4 and all(len(b[0]) <= tr.CHUNK_BYTES < MAX_UPDATE_BYTES for _, b in sent)
    assert b"".join(b[0] for _, b in sent) == payload
    assert [m["part"] for m, _ in sent] == [0, 1, 2, 3] and "meta" in sent[0][0] and "meta" not in sent[1][0]
    c.transfers.withdraw("polytope")
    assert c.page_data == {}


def test_pack_refuses_what_the_page_cannot_hold():
    with pytest.raises(ValueError, match="beyond int32"):
        tr.pack({"i": np.array([2**40])})
    with pytest.raises(TypeError, match="complex128"):
        tr.pack({"z": np.zeros(2, complex)})


SCRIPT = """
import { unpack, receiveChunk, transferStore } from "page:transfer.js";
const model = { get: () => ({}), send: () => {} };
const chunks = INPUT.chunks.map((b) => { const u = Uint8Array.from(Buffer.from(b, "base64")); return new DataView(u.buffer); });
const msgs = INPUT.msgs;
let done = [];
msgs.forEach((m, i) => { if (receiveChunk(model, m, chunks[i])) done.push(m.name); });
msgs.forEach((m, i) => receiveChunk(model, m, chunks[i]));  // a second view's copies: ignored
const t = transferStore(model).done.get("polytope");
const u = unpack(t.meta, t.bytes);
const out = {};
for (const [k, a] of Object.entries(u.arrays)) out[k] = Array.from(a);
console.log(JSON.stringify({ done, arrays: out, scalars: u.scalars }));
"""


def test_the_page_puts_the_chunks_together_and_reads_the_arrays_that_left(monkeypatch):
    monkeypatch.setattr(tr, "CHUNK_BYTES", 40)  # many chunks of a small payload
    c, sent = _companion(monkeypatch)
    arrays = {"v": np.linspace(-1, 1, 13), "e": np.arange(10, dtype=np.int64).reshape(5, 2),
              "f": np.array([0.5, 1.25], dtype=np.float32), "m": np.array([True, False, True])}
    meta, payload = tr.pack(arrays, {"unit": 0.25, "name": "x"})
    c.transfers.offer("polytope", "k", meta, payload)
    from_page(c, {"event": "want", "name": "polytope", "key": "k"})
    assert len(sent) > 3
    got = run_page(SCRIPT, {"msgs": [m for m, _ in sent], "chunks": [base64.b64encode(b[0]).decode() for _, b in sent]})
    assert got["done"] == ["polytope"]  # once, whatever the views
    assert got["scalars"] == {"unit": 0.25, "name": "x"}
    assert got["arrays"]["v"] == list(arrays["v"]) and got["arrays"]["e"] == list(range(10))
    assert got["arrays"]["f"] == [0.5, 1.25] and got["arrays"]["m"] == [1, 0, 1]
