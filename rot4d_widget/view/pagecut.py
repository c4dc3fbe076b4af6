"""Whether the page cuts the source itself (issue 34), and what it needs for it.

A single polytope, or parallel slices of one with convex cells (a ``StackSource`` around such a
``PolytopeSource``), is cut in the page while it is ahead of the kernel (``page/pictures.js``,
``page/stack.js``) -- a polytope with star faces or non-convex cells as its balls and bars only
(its fills are the kernel's, at rest: never a picture mixing two states): the polytope's slicer
tables go to the page once (`rot4d_widget.view.pagegeometry.polytope_message`, as the one-time
transfer ``"polytope"``), and how it is drawn -- the scale, the group colours packed as the row
buffer holds them, one colour for every face or none, and a stack's cuts and layout
(`stack_config`) -- is the companion's synced ``draw_config``.  A stack's N, Δ, arrangement and
colouring change by the kernel's own keys and traits: they travel in ``draw_config``, the polytope
is not sent again.  Once the page says it holds the polytope the kernel offers, the kernel makes
no picture while keys are held (`page_draws`): the page draws those, the kernel the one the keys
rest on.
"""

from __future__ import annotations

import uuid

import numpy as np

from ..sources.protocol import PolytopeSource
from ..sources.tomography import StackSource
from . import buffers as bf
from .pagegeometry import polytope_message
from .transfer import pack

__all__ = ["PageCut", "page_cuttable", "stack_config"]

#: the arrays of `polytope_message` that are float64 (the others are int32 indices)
_FLOATS = frozenset({"vertices", "cell_normals", "cell_centres", "face_basis", "face_rho"})


def page_cuttable(source):
    """The polytope the page cuts for ``source`` -- a single polytope, or parallel slices
    (`StackSource`) of one with convex cells -- else None.  Exact types: a subclass may slice
    otherwise."""
    if type(source) is PolytopeSource:
        return source.polytope
    inner = source.source if type(source) is StackSource else None
    if type(inner) is PolytopeSource and inner.polytope.star is None:
        return inner.polytope
    return None


def stack_config(source) -> dict | None:
    """What the page needs to build a stack's rows as `StackSource.slice` and `buffers.slice_rows`
    do, the kernel's own float64 numbers (JSON carries each double exactly); None for a single slice.

    ``offsets`` (N,) each cut's offset from c0 (`StackSource.cut_offsets`: slice k is cut at
    ``c0 + offsets[k]``); ``centres`` (3N,) and ``scales`` (N,) the layout (`StackSource.layout`:
    with N > 1 a point p of slice k is drawn at ``p * scales[k] + centres[k]``); ``by_w`` the
    triangles of slice k are group k (`StackSource.groups_by_w`), else their 4-D cell's.
    """
    if type(source) is not StackSource:
        return None
    centres, scales = source.layout()
    return {"offsets": [float(x) for x in source.cut_offsets()],
            "centres": [float(x) for x in np.asarray(centres, dtype=np.float64).reshape(-1)],
            "scales": [float(x) for x in np.asarray(scales, dtype=np.float64).reshape(-1)],
            "by_w": bool(source.groups_by_w)}


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
        self._stack = (None, None)  # (the settings a stack's config was made from, `stack_config`)

    def sync(self, source, colours, scale: float, single_rgb) -> None:
        """Offer ``source``'s polytope if the page can cut it (withdraw it otherwise), and say how to
        draw it: ``colours`` (G, 3) the group colours, ``scale``, ``single_rgb`` one colour or None,
        a stack's `stack_config`."""
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
               "single": None if single_rgb is None else float(bf.pack_rgb([single_rgb])[0]),
               "stack": self._stack_config(source)}
        if cfg != self.companion.draw_config:
            self.companion.draw_config = cfg

    def _stack_config(self, source) -> dict | None:
        """`stack_config`, made again only when the stack or its settings changed (sync runs with
        every tick of a held key; the oval's layout takes most of a millisecond)."""
        if type(source) is not StackSource:
            return None
        made_from = (source, source.slices, source.spacing, source.arrangement, source.color_by, source.size)
        if self._stack[0] is None or any(a is not b and a != b for a, b in zip(made_from, self._stack[0])):
            self._stack = (made_from, stack_config(source))
        return self._stack[1]

    def holds(self, name, key) -> None:
        """The page holds transfer ``name`` at ``key`` (the companion's "holds" message)."""
        if name == "polytope":
            self._held = key

    @property
    def page_draws(self) -> bool:
        """The page holds the polytope offered: it draws the pictures of keys held."""
        return self._offered is not None and self._held == self._offered[1]
