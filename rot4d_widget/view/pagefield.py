"""Whether the page holds a field's 4-D data itself, and the copy it is sent.

A field (`rot4d_widget.sources.field.container.Field4D`, alone or in a stack) whose values are
an array on evenly spaced nodes is cut in the page while the page is ahead of the kernel
(``page/field.js``, ``glsl/field.frag``).  For that the page holds one copy of the data, sent
once as the one-time transfer ``"field"`` (`rot4d_widget.view.transfer`): the data themselves
when in memory and their texture fits `PAGE_FIELD_BUDGET`, else the coarse copy once made;
quantised to 16 bits over the copy's own range (`CODES`), time tiled into one 3-D texture
(`tile_layout`), with the least and greatest code of each `BLOCK`-cell block for empty-space
skipping (`block_ranges`).  The box's outline travels as ``"field_box"``; how the page draws is
the companion's ``field_config`` (`rot4d_widget.view.fieldview`).  The layout and why:
docs/design.md, "The field on the GPU".
"""

from __future__ import annotations

import math
import uuid

import numpy as np

from ..sources.field.container import Field4D
from ..sources.field.slicing import box_polytope
from ..sources.protocol import inner_source
from .fieldview import copy_clim
from .pagecut import polytope_transfer
from .transfer import pack

__all__ = ["PageField", "page_field", "field_copy", "field_transfer", "tile_layout", "PAGE_FIELD_BUDGET",
           "MAX_SIDE", "CODES"]

#: Bytes of texture the page's copy of a field may take (`texture_bytes`: four a node, each node's
#: code beside the next time's, one more where a mask is needed): the data themselves up to this,
#: else their coarse copy.  128 MiB: a 64^4 field (64 MiB of texture, 32 MiB sent) is held whole; a
#: 96^4 one (324 MiB) sends its 48^4 coarse copy (10 MiB).
PAGE_FIELD_BUDGET = 128 * 2**20
#: The longest side of the 3-D texture, in texels: MAX_3D_TEXTURE_SIZE measured in Chromium on
#: SwiftShader (tests/browser/test_webgl_probe_browser.py); a page whose limit is lower does not ask.
MAX_SIDE = 2048
#: The largest code of a quantised value (16 bits).
CODES = 65535
#: Cells a side of a block of the block ranges (empty-space skipping).
BLOCK = 4


def page_field(source):
    """The `Field4D` whose data the page can hold for ``source`` (itself, or the field inside a
    stack): an array (not a function) on evenly spaced nodes; else None."""
    inner = inner_source(source)
    if type(inner) is not Field4D or inner.kind == "function" or any(c is not None for c in inner.coords):
        return None
    return inner


def field_copy(field):
    """``(values, which)``: the array the page is to hold (in the field's array axis order) and
    ``"data"`` or ``"coarse"``; None while the copy it needs is not in memory yet."""
    resident = field.resident
    if resident is not None and texture_bytes(resident.shape, False) <= PAGE_FIELD_BUDGET:
        return resident, "data"
    if not field.coarse_ready:
        return None
    coarse = field.coarse()
    return coarse.values, ("data" if coarse is field else "coarse")


def texture_bytes(shape, masked: bool) -> int:
    """Bytes of the page's textures of an array of ``shape``: 4 a node (its 16-bit code and the next
    time's: page/field.js pairedTexels), 5 with a mask; tiles padded aside.  Twice what is sent."""
    return math.prod(int(n) for n in shape) * (5 if masked else 4)


def tile_layout(shape, max_side: int = MAX_SIDE) -> tuple:
    """``(tx, ty, tz)``: how the ``nw`` tiles of ``shape`` = (nx, ny, nz, nw) are placed, the
    texture's longest side as short as it can be (then the fewest unused tiles, then the first
    found).  A ValueError when no placement keeps every side within ``max_side``."""
    nx, ny, nz, nw = (int(n) for n in shape)
    best = None
    for tz in range(1, nw + 1):
        for ty in range(1, -(-nw // tz) + 1):
            tx = -(-nw // (ty * tz))
            sides = (nx * tx, ny * ty, nz * tz)
            key = (max(sides), tx * ty * tz - nw)
            if max(sides) <= max_side and (best is None or key < best[0]):
                best = (key, (tx, ty, tz))
    if best is None:
        raise ValueError(f"a field of {nx} x {ny} x {nz} nodes and {nw} times does not fit a 3-D texture of "
                         f"{max_side} texels a side")
    return best[1]


def field_transfer(values, axis_of) -> tuple[dict, bytes]:
    """The page's copy of ``values`` (a 4-D array, its axes x, y, z, w at array axes ``axis_of``)
    as a one-time transfer's ``(meta, payload)`` (`transfer.pack`): arrays ``texels`` (uint8,
    2 a texel: high byte, low byte) and, when some value is not finite, ``mask`` (uint8, 1 a
    texel); scalars ``shape`` [nx, ny, nz, nw], ``tiles`` [tx, ty, tz], ``size`` [W, H, D] (the
    texture's texels), ``range`` [lo, hi] (the finite values' min and max: code c stands for
    ``lo + c (hi - lo) / 65535``), ``masked``.  Quantised time by time (memory: one time in
    float64 at a time)."""
    a = np.asarray(values)
    order = tuple(int(axis_of[j]) for j in (3, 2, 1, 0))  # -> (w, z, y, x): x the fastest
    v = a.transpose(order)
    nw, nz, ny, nx = v.shape
    lo, hi, masked = math.inf, -math.inf, False
    for k in range(nw):
        t = np.asarray(v[k], dtype=np.float64)
        fin = np.isfinite(t)
        masked = masked or not fin.all()
        if fin.any():
            lo, hi = min(lo, float(t[fin].min())), max(hi, float(t[fin].max()))
    if not math.isfinite(lo):
        lo = hi = 0.0
    tx, ty, tz = tile_layout((nx, ny, nz, nw))
    codes = np.zeros((tx * ty * tz, nz, ny, nx), dtype=np.uint16)
    mask = np.zeros(codes.shape, dtype=np.uint8) if masked else None
    span = hi - lo
    for k in range(nw):
        t = np.asarray(v[k], dtype=np.float64)
        fin = np.isfinite(t)
        q = np.rint((np.where(fin, t, lo) - lo) * (CODES / span)) if span > 0 else np.zeros(t.shape)
        codes[k] = np.clip(q, 0, CODES).astype(np.uint16)
        if mask is not None:
            mask[k] = np.where(fin, 255, 0)
    # (tz, ty, tx, nz, ny, nx) -> (tz, nz, ty, ny, tx, nx): the texture's (depth, height, width)
    tiled = codes.reshape(tz, ty, tx, nz, ny, nx).transpose(0, 3, 1, 4, 2, 5).reshape(tz * nz, ty * ny, tx * nx)
    texels = np.empty(tiled.shape + (2,), dtype=np.uint8)
    texels[..., 0] = tiled >> 8
    texels[..., 1] = tiled & 255
    arrays = {"texels": texels.reshape(-1)}
    if mask is not None:
        arrays["mask"] = mask.reshape(tz, ty, tx, nz, ny, nx).transpose(0, 3, 1, 4, 2, 5).reshape(-1)
    bmin, bmax = block_ranges(codes[:nw], None if mask is None else mask[:nw] == 0)
    bw, bz, by, bx = bmin.shape
    btx, bty, btz = tile_layout((bx, by, bz, bw))
    blocks = np.zeros((btx * bty * btz, bz, by, bx, 4), dtype=np.uint8)
    blocks[:bw, ..., 0], blocks[:bw, ..., 1] = bmin >> 8, bmin & 255
    blocks[:bw, ..., 2], blocks[:bw, ..., 3] = bmax >> 8, bmax & 255
    arrays["blocks"] = blocks.reshape(btz, bty, btx, bz, by, bx, 4).transpose(0, 3, 1, 4, 2, 5, 6).reshape(-1)
    scalars = {"shape": [nx, ny, nz, nw], "tiles": [tx, ty, tz], "size": [tx * nx, ty * ny, tz * nz],
               "range": [lo, hi], "masked": masked, "block": BLOCK, "block_shape": [bx, by, bz, bw],
               "block_tiles": [btx, bty, btz], "block_size": [btx * bx, bty * by, btz * bz]}
    return pack(arrays, scalars)


def _block_reduce(a, axis, op):
    """``op`` over each block of `BLOCK` cells along ``axis`` (its BLOCK + 1 nodes; the last block
    shorter): (ceil((n - 1) / BLOCK) or 1) blocks."""
    n = a.shape[axis]
    starts = np.arange(0, max(n - 1, 1), BLOCK)
    out = op.reduceat(a, starts, axis=axis)
    nxt = np.minimum(starts + BLOCK, n - 1)  # each block's last node, shared with the next block
    return op(out, np.take(a, nxt, axis=axis))


def block_ranges(codes, bad=None):
    """(min, max) uint16 codes of each block of ``codes`` ((nw, nz, ny, nx), `BLOCK` cells a side);
    ``bad`` (same shape, True where a node is not finite): its blocks get the whole range (never
    skipped)."""
    lo, hi = codes, codes
    for axis in range(4):
        lo = _block_reduce(lo, axis, np.minimum)
        hi = _block_reduce(hi, axis, np.maximum)
    if bad is not None:
        b = bad
        for axis in range(4):
            b = _block_reduce(b, axis, np.logical_or)
        lo = np.where(b, 0, lo).astype(np.uint16)
        hi = np.where(b, CODES, hi).astype(np.uint16)
    return lo, hi


class PageField:
    """One widget's page copy of its field: what is offered, what the page holds (``companion``:
    the widget's `Companion`)."""

    def __init__(self, companion):
        self.companion = companion
        self._offered = None  # (values array, key) offered as "field"
        self._box = None  # (half widths, key) offered as "field_box"
        self._held = {}  # name -> the key the page says it holds
        self.which = None  # "data" or "coarse": the copy offered
        self.shape = None  # its nodes along x, y, z, w
        self.texture_side = 0  # its texture's longest side (texels)
        self.clim = None  # its 1st-99th percentile (`fieldview.copy_clim`)

    def sync(self, source) -> None:
        """Offer ``source``'s field to the page once its copy is in memory (withdraw it for a source
        the page cannot hold); the box's tables whenever its half widths change."""
        field = page_field(source)
        transfers = self.companion.transfers
        if field is None:
            if self._offered is not None or self._box is not None:
                transfers.withdraw("field")
                transfers.withdraw("field_box")
                self._offered = self._box = None
                self.which = None
            return
        hw = tuple(float(h) for h in field.half_widths)
        if self._box is None or self._box[0] != hw:
            key = uuid.uuid4().hex
            transfers.offer("field_box", key, *polytope_transfer(box_polytope(hw)))
            self._box = (hw, key)
        if self._offered is not None and self._offered[2] is field:
            return
        if self._offered is not None:  # another field: the page drops the old copy
            transfers.withdraw("field")
            self._offered = None
        copy = field_copy(field)
        if copy is None:
            return
        values, which = copy
        key = uuid.uuid4().hex
        meta, payload = field_transfer(values, field.axis_of)
        transfers.offer("field", key, meta, payload, paced=True)
        self._offered = (values, key, field)
        self.which = which
        self.shape = tuple(meta["scalars"]["shape"])
        self.texture_side = max(meta["scalars"]["size"])
        self.clim = copy_clim(values)

    def holds(self, name, key) -> None:
        """The page holds transfer ``name`` at ``key`` (the companion's "holds" message)."""
        if name in ("field", "field_box"):
            self._held[name] = key

    @property
    def offered(self) -> bool:
        """A copy of the field is offered (the page may be fetching it)."""
        return self._offered is not None

    @property
    def page_draws(self) -> bool:
        """The page holds the field and its box as offered: it draws the pictures of keys held."""
        return (self._offered is not None and self._box is not None
                and self._held.get("field") == self._offered[1] and self._held.get("field_box") == self._box[1])
