"""The page's volume layer: a field's cut drawn by ray casting in a shader ("volume", "mip",
"sections"), from the cut's values sampled on a grid by the kernel.

The kernel's picture of a cut: its grid travels as a 2-D texture whose tiles are its z layers
(``LuminanceAlpha``, 8 bits each: the value quantised over the colour limits, and 255 where the
node is finite, 0 where it is not); the shader interpolates within a tile bilinearly (the
texture's filter) and between two tiles linearly: trilinear.  A sample counts only where both
layers' alpha is 1, i.e. where its cell's nodes are finite: the static renders' rule
(`rot4d_widget.keep.pictures.ray_caster`), whose camera, step, colour table and optical depth the shader
repeats, so the page and ``w.render`` agree.  The context is WebGL2 wherever the browser has it
(pythreejs's `Renderer` asks for it; measured in Chromium on SwiftShader:
``tests/browser/test_webgl_probe_browser.py``, docs/design.md "The field on the GPU"), and the atlas
needs nothing of WebGL2: the kernel's pictures draw on a WebGL1 context too.  The page's own copy
of the 4-D field (a 3-D texture, `rot4d_widget.view.pagefield`) needs WebGL2; without it the page
never asks for the copy and every picture is the kernel's.

One update is still one message: `volume_message` is a dict put on the scene's row buffer in the
same ``hold_sync`` as the rows (the box's outline as bars); the companion uploads the atlas and
the colour table into the textures and the boxes into the mesh's geometry as it applies it.

Message (``{}``: no volume shown)::

    n_boxes        int, one box per cut (a stack has several)
    boxes          (n, 12) float32 bytes: lo (3), span (3) in scene units, nodes (3), atlas u0, v0, tiles per row
    atlas          (H, W, 2) uint8 bytes, atlas_size [W, H]
    lut            (256, 4) uint8 bytes: the colour map's table
    mode           0 volume, 1 mip, 2 sections;  sections [fx, fy, fz];  density;  step
    held           keys are held: a quicker, coarser picture (`HELD_STEP`, half the pixel ratio)
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pythreejs as p3

from ..core import colours, renderings

__all__ = ["VolumeLayer", "volume_message", "pack_atlas", "colour_table", "MODES", "ATLAS_MAX"]

#: The renderings the layer draws, by the shader's mode number.
MODES = {"volume": 0, "mip": 1, "sections": 2}
#: The atlas's widest side, in texels (every WebGL1 and WebGL2 implementation takes 4096).
ATLAS_MAX = 4096
#: Samples every this many grid spacings along a ray (the static renders' default).
STEP = 0.5
#: While keys are held: samples this far apart, and the page draws at half its pixel ratio (a
#: quarter of the rays), so a software renderer keeps up; at rest the picture is the exact one.
HELD_STEP = 2.0
#: The shader's most samples per ray (``MAX_STEPS`` in volume.frag): a longer ray takes longer steps.
MAX_STEPS = 1024


@functools.lru_cache(maxsize=16)
def _table_bytes(cmap: str) -> bytes:
    return colour_table(cmap).tobytes()


def colour_table(cmap: str) -> np.ndarray:
    """(256, 4) uint8: matplotlib's table of ``cmap`` (entry i = ``cmap(i / 255)``), alpha 255."""
    # matplotlib's colour map registry, looked up by name (core.colours names the maps)
    from matplotlib import colormaps

    rgba = np.asarray(colormaps[colours.check_cmap(cmap)](np.arange(256) / 255.0))
    return np.round(np.clip(rgba, 0.0, 1.0) * 255.0).astype(np.uint8)


def quantise(values, clim) -> np.ndarray:
    """(nx, ny, nz, 2) uint8: (value over ``clim`` clamped to 0 ... 255, 255 where finite else 0)."""
    v = np.asarray(values, dtype=np.float32)
    lo, hi = clim
    finite = np.isfinite(v)
    with np.errstate(invalid="ignore"):
        q = np.clip((np.where(finite, v, lo) - lo) * (255.0 / (hi - lo)), 0.0, 255.0)
    out = np.empty(v.shape + (2,), dtype=np.uint8)
    out[..., 0] = np.rint(q)
    out[..., 1] = np.where(finite, 255, 0)
    return out


def _tiles(values_la):
    """(rows * ny, cols * nx, 2) uint8 and cols: the z layers of one grid laid out as tiles, layer k
    at row k // cols, column k % cols; texel (u, v) of tile k holds node (u, v, k)."""
    nx, ny, nz, _ = values_la.shape
    cols = max(1, min(nz, ATLAS_MAX // nx, math.ceil(math.sqrt(nz * ny / nx))))
    rows = -(-nz // cols)
    pad = np.zeros((nx, ny, rows * cols - nz, 2), dtype=np.uint8)
    full = np.concatenate([values_la, pad], axis=2) if len(pad[0, 0]) else values_la
    band = full.reshape(nx, ny, rows, cols, 2).transpose(2, 1, 3, 0, 4).reshape(rows * ny, cols * nx, 2)
    return band, cols


def pack_atlas(grids, clim):
    """``(atlas (H, W, 2) uint8, tiles [(u0, v0, cols)])``: every grid's tiles (`_tiles`) placed on
    shelves at most `ATLAS_MAX` wide.  A ValueError when they do not fit in ATLAS_MAX²."""
    bands = [_tiles(quantise(g, clim)) for g in grids]
    x = y = shelf = 0
    width = 0
    places = []
    for band, cols in bands:
        h, w = band.shape[:2]
        if x + w > ATLAS_MAX:
            x, y, shelf = 0, y + shelf, 0
        places.append((x, y, cols))
        x, shelf = x + w, max(shelf, h)
        width = max(width, x)
    height = y + shelf
    if height > ATLAS_MAX or width > ATLAS_MAX:
        raise ValueError(f"the cuts' grids need a {width} x {height} atlas, more than {ATLAS_MAX} texels a side: "
                         f"sample them more coarsely")
    atlas = np.zeros((max(height, 1), max(width, 1), 2), dtype=np.uint8)
    for (band, _), (u0, v0, _) in zip(bands, places):
        atlas[v0:v0 + band.shape[0], u0:u0 + band.shape[1]] = band
    return atlas, places


def volume_message(parts, rendering: str, cmap: str, clim, sections, density: float = renderings.DEFAULT_DENSITY, *,
                   held: bool = False) -> dict:
    """The synced dict of one volume update.

    parts : sequence of ``(values (nx, ny, nz), lo (3,), span (3,))``: each cut's grid (at least 2
        nodes a side) and its box in scene units (the nodes span ``lo`` ... ``lo + span``).
    rendering : "volume", "mip" or "sections";  cmap : a matplotlib name;  clim : (lo, hi)
    sections : (fx, fy, fz) in [0, 1];  density : optical depth across the longest side.
    held : keys are held: rays sampled every `HELD_STEP` spacings and the page draws at half its
        pixel ratio (``"held"`` in the message); at rest every `STEP`, at full resolution.
    """
    parts = [(np.asarray(v), np.asarray(lo, dtype=np.float64), np.asarray(span, dtype=np.float64))
             for v, lo, span in parts if min(np.shape(v)) >= 2]
    if not parts:
        return {}
    atlas, places = pack_atlas([v for v, _, _ in parts], clim)
    boxes = np.zeros((len(parts), 12), dtype=np.float32)
    longest = 0.0
    for i, ((values, lo, span), (u0, v0, cols)) in enumerate(zip(parts, places)):
        boxes[i, 0:3], boxes[i, 3:6] = lo, span
        boxes[i, 6:9] = values.shape
        boxes[i, 9:12] = (u0, v0, cols)
        longest = max(longest, float(np.linalg.norm(np.asarray(values.shape) - 1)))
    step = max(HELD_STEP if held else STEP, longest / (MAX_STEPS - 8))
    h, w = atlas.shape[:2]
    return {
        "n_boxes": len(parts),
        "boxes": memoryview(boxes.astype("<f4").tobytes()),
        "atlas": memoryview(np.ascontiguousarray(atlas).tobytes()),
        "atlas_size": [int(w), int(h)],
        "lut": memoryview(_table_bytes(colours.check_cmap(cmap))),
        "mode": MODES[rendering],
        "sections": [float(s) for s in renderings.check_sections(sections)],
        "density": float(density),
        "step": float(step),
        "held": bool(held),
    }


class VolumeLayer:
    """The pythreejs objects of the volume layer: one mesh named "volume" (placeholder geometry
    and textures the companion fills), drawn after the opaque layers, hidden until a volume
    arrives."""

    def __init__(self):
        f32 = np.float32
        self.attributes = {
            name: p3.BufferAttribute(array=np.zeros((3, 3), dtype=f32))
            for name in ("position", "a_lo", "a_span", "a_shape", "a_tile")
        }
        self.geometry = p3.BufferGeometry(attributes=self.attributes)
        self.atlas = p3.DataTexture(data=np.zeros((1, 1, 2), dtype=np.uint8), format="LuminanceAlphaFormat",
                                    type="UnsignedByteType", magFilter="LinearFilter", minFilter="LinearFilter")
        self.lut = p3.DataTexture(data=np.zeros((1, 256, 4), dtype=np.uint8), format="RGBAFormat",
                                  type="UnsignedByteType", magFilter="NearestFilter", minFilter="NearestFilter")

    def build(self, shader_source) -> p3.Mesh:
        """The mesh (its material reads ``volume.vert`` / ``volume.frag`` via ``shader_source``)."""
        self.material = p3.ShaderMaterial(
            vertexShader=shader_source("volume.vert"),
            fragmentShader=shader_source("volume.frag"),
            uniforms={
                # the textures are set by the companion (pythreejs drops texture uniforms of a
                # ShaderMaterial): placeholders, so that the names are in the material's uniforms
                "u_atlas": {"value": None}, "u_lut": {"value": None},
                "u_atlas_size": {"value": [1.0, 1.0]}, "u_mode": {"value": 0.0},
                "u_sections": {"value": list(renderings.DEFAULT_SECTIONS)},
                "u_density": {"value": renderings.DEFAULT_DENSITY},
                "u_step": {"value": STEP},
            },
            side="BackSide", transparent=True, depthWrite=False,
        )
        self.mesh = p3.Mesh(geometry=self.geometry, material=self.material, frustumCulled=False, name="volume",
                            visible=False)
        return self.mesh

    @property
    def texture_model_ids(self) -> list:
        """Model ids of the atlas and colour-table textures (the companion puts them in the material)."""
        return [self.atlas.model_id, self.lut.model_id]

    @property
    def widgets(self) -> list:
        return [self.mesh, self.material, self.geometry, *self.attributes.values(), self.atlas, self.lut]
