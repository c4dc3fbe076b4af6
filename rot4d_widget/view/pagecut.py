"""Whether the page cuts the source itself (issue 34), and what it needs for it.

A single polytope is cut in the page while it is ahead of the kernel (``page/pictures.js``) -- one
with star faces or non-convex cells as its balls and bars only (its fills are the kernel's, at
rest: never a picture mixing two states): its slicer's tables go
to the page once (`rot4d_widget.view.pagegeometry.polytope_message`, as the one-time transfer
``"polytope"``), and how it is drawn -- the scale, the group colours packed as the row buffer
holds them, one colour for every face or none -- is the companion's synced ``draw_config``.
Once the page says it holds the polytope the kernel offers, the kernel makes no picture while
keys are held (`page_draws`): the page draws those, the kernel the one the keys rest on.
"""

from __future__ import annotations

import uuid

import numpy as np

from ..sources.protocol import PolytopeSource
from . import buffers as bf
from .pagegeometry import polytope_message
from .transfer import pack

__all__ = ["PageCut", "page_cuttable"]

#: the arrays of `polytope_message` that are float64 (the others are int32 indices)
_FLOATS = frozenset({"vertices", "cell_normals", "cell_centres", "face_basis", "face_rho"})


def page_cuttable(source):
    """The polytope of ``source`` if the page can cut it (a single polytope), else None."""
    return source.polytope if type(source) is PolytopeSource else None


def polytope_transfer(polytope) -> tuple[dict, bytes]:
    """`polytope_message` as a one-time transfer's ``(meta, payload)`` (`transfer.pack`)."""
    msg = polytope_message(polytope)
    arrays = {k: np.frombuffer(v, dtype="<f8" if k in _FLOATS else "<i4") for k, v in msg.items()
              if isinstance(v, memoryview)}
    scalars = {k: v for k, v in msg.items() if not isinstance(v, memoryview)}
    return pack(arrays, scalars)


class PageCut:
    """One widget's page cut: what is offered, what the page holds, how the page draws (``companion``:
    the widget's `Companion`)."""

    def __init__(self, companion):
        self.companion = companion
        self._offered = None  # (polytope, key) offered to the page
        self._held = None  # the key the page says it holds

    def sync(self, source, colours, scale: float, single_rgb) -> None:
        """Offer ``source``'s polytope if the page can cut it (withdraw it otherwise), and say how to
        draw it: ``colours`` (G, 3) the group colours, ``scale``, ``single_rgb`` one colour or None."""
        poly = page_cuttable(source)
        if poly is None:
            if self._offered is not None:
                self.companion.transfers.withdraw("polytope")
                self._offered = None
            return
        if self._offered is None or self._offered[0] is not poly:
            key = uuid.uuid4().hex
            self.companion.transfers.offer("polytope", key, *polytope_transfer(poly))
            self._offered = (poly, key)
        cfg = {"scale": float(scale), "palette": [float(x) for x in bf.pack_rgb(colours)],
               "single": None if single_rgb is None else float(bf.pack_rgb([single_rgb])[0])}
        if cfg != self.companion.draw_config:
            self.companion.draw_config = cfg

    def holds(self, name, key) -> None:
        """The page holds transfer ``name`` at ``key`` (the companion's "holds" message)."""
        if name == "polytope":
            self._held = key

    @property
    def page_draws(self) -> bool:
        """The page holds the polytope offered: it draws the pictures of keys held."""
        return self._offered is not None and self._held == self._offered[1]
