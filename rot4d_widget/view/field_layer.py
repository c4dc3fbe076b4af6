"""The page's field layer (issue 36): the pythreejs objects the page draws its own picture of a
field's cut with, while it is ahead of the kernel -- a mesh named "field" whose material
(``glsl/field.vert``, ``glsl/field.frag``) casts rays through the page's copy of the 4-D data.

The kernel never sends this layer an array: the page fills the geometry (one box per cut, from
the state it predicts: ``page/raycast.js``) and the textures (the data, from the one-time
transfer ``"field"``: `rot4d_widget.view.pagefield`; the colour table) and sets the uniforms.
The placeholder `DataTexture3D` is here for its class (``THREE.DataTexture3D``, which the page
takes from it: three.js's classes are not reachable otherwise); pythreejs drops texture uniforms
of a ``ShaderMaterial``, so the page puts its own textures in.  Hidden until the page draws.
"""

from __future__ import annotations

import numpy as np
import pythreejs as p3

from ..core import renderings

__all__ = ["FieldLayer", "ATTRIBUTES"]

#: The geometry's attributes and their sizes (field.vert), each constant over a box.
ATTRIBUTES = {"position": 3, "a_g0": 4, "a_gx": 4, "a_gy": 4, "a_gz": 4, "a_lo": 3, "a_span": 3, "a_cell": 2}


class FieldLayer:
    """The mesh "field", its material and placeholders (built once per scene)."""

    def __init__(self, light: dict):
        f32 = np.float32
        self.attributes = {name: p3.BufferAttribute(array=np.zeros((3, k), dtype=f32))
                           for name, k in ATTRIBUTES.items()}
        self.geometry = p3.BufferGeometry(attributes=self.attributes)
        self.texture = p3.DataTexture3D(data=np.zeros((1, 1, 2), dtype=np.uint8), format="LuminanceAlphaFormat",
                                        type="UnsignedByteType", magFilter="LinearFilter",
                                        minFilter="LinearFilter")
        self.light = light
        self.material = self.mesh = None

    @staticmethod
    def _uniforms(light: dict) -> dict:
        # the textures, arrays and matrices are set by the page (placeholders name them here)
        return dict(
            light,
            u_mode={"value": 0.0}, u_clim={"value": [0.0, 1.0]},
            u_sections={"value": list(renderings.DEFAULT_SECTIONS)},
            u_density={"value": renderings.DEFAULT_DENSITY}, u_step={"value": 0.5}, u_march={"value": 0.01},
            u_sign={"value": 1.0}, u_caps={"value": 1.0}, u_opacity={"value": 1.0}, u_nlevels={"value": 0.0},
            u_box_colours={"value": 0.0}, u_output={"value": 0.0}, u_depth_scale={"value": 100.0},
            u_shape={"value": [1.0, 1.0, 1.0, 1.0]}, u_tiles={"value": [1.0, 1.0, 1.0]},
            u_size={"value": [1.0, 1.0, 1.0]}, u_masked={"value": 0.0},
        )

    def build(self, shader_source) -> p3.Mesh:
        """The mesh (its material reads ``field.vert`` / ``field.frag`` via ``shader_source``)."""
        self.material = p3.ShaderMaterial(
            vertexShader=shader_source("field.vert"), fragmentShader=shader_source("field.frag"),
            uniforms=self._uniforms(self.light), side="BackSide", transparent=True, depthWrite=False,
        )
        self.mesh = p3.Mesh(geometry=self.geometry, material=self.material, frustumCulled=False, name="field",
                            visible=False)
        return self.mesh

    @property
    def texture_model_id(self) -> str:
        """Model id of the placeholder 3-D texture (the page takes its class)."""
        return self.texture.model_id

    @property
    def widgets(self) -> list:
        return [self.mesh, self.material, self.geometry, *self.attributes.values(), self.texture]
