"""A stand-in for the kernel's comm: records what widgets send, sized as ipykernel sends it.

Used by the widget, scene and companion tests and by benchmarks/widget_update.py
(the pattern of ipywidgets' widgets/tests/utils.py, plus real serialisation so
the byte counts are those of the wire).
"""

from __future__ import annotations

import uuid

import comm as comm_package
import numpy as np
from ipykernel.jsonutil import json_clean
from jupyter_client.session import json_packer


class RecordingComm:
    kernel = "Truthy"  # ipywidgets sends only when the comm has a kernel
    #: every message of every comm: (comm_id, data, n_bytes, [uint8 views of the binary buffers])
    log: list = []

    def __init__(self, *args, comm_id=None, **kwargs):
        self.comm_id = comm_id or uuid.uuid4().hex
        self.handler = None
        self.closed = False

    def open(self, *args, **kwargs):
        pass

    def on_msg(self, callback):
        self.handler = callback

    def on_close(self, callback):
        pass

    def send(self, data=None, metadata=None, buffers=None):
        content = json_clean(dict(data=data, comm_id=self.comm_id))
        bufs = [np.frombuffer(b, dtype=np.uint8) for b in (buffers or ())]
        n = len(json_packer(content)) + sum(b.nbytes for b in bufs)
        RecordingComm.log.append((self.comm_id, data, n, bufs))

    def close(self, *args, **kwargs):
        self.closed = True


def install(monkeypatch=None) -> list:
    """Make new widgets use RecordingComm; return the (fresh) log."""
    RecordingComm.log = []
    factory = lambda *a, **k: RecordingComm(*a, **k)  # noqa: E731
    if monkeypatch is None:
        comm_package.create_comm = factory
    else:
        monkeypatch.setattr(comm_package, "create_comm", factory)
    return RecordingComm.log
