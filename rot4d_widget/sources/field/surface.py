"""A field's isosurfaces in one slice: marching cubes on a step's samples, and what it returns.

`level_surface` runs scikit-image's marching cubes (Lewiner) on ``min(±(f - level), K g)`` (capped on
the box's faces) or on ``±(f - level)`` alone (open), in index space, and scales vertices,
volume and area afterwards in float64; `FieldSlice` is one level's surface, `FieldSliceData`
the `SliceData` a `Field4D` gives the widget.
"""

from __future__ import annotations

import dataclasses
import math
import sys
from dataclasses import dataclass

import numpy as np
from scipy.ndimage import binary_dilation, distance_transform_edt, map_coordinates
from skimage.measure import marching_cubes

from ...core._arrays import sealed as _sealed
from ..protocol import SliceData

__all__ = ["FieldSlice", "FieldSliceData", "CutFrame"]


@dataclass(frozen=True, eq=False)
class FieldSlice:
    """The isosurface {f = level} closing {f >= level} (or {f <= level} for a field with
    ``inside="below"``) in one slice (all arrays read-only).

    vertices : (n, 3) float64 -- in slice coordinates
    triangles : (k, 3) intp -- counter-clockwise seen from outside the enclosed side
        (outward from {f >= level}); the surface is closed, capped on the box's faces
        (open there, and ``volume`` NaN, for a field with ``caps=False``)
    normals : (n, 3) float64 -- unit, outward
    volume : float -- 3-volume of {f >= level} in the slice (inf, or 0, when beyond float64's
        range: slice coordinates above about 5e102 or below about 2e-103)
    area : float -- area of the surface (likewise beyond about 1e154 and 1e-154)
    level : float
    spacing : float -- the sample spacing of the step (slice units); 0 when nothing was sampled
    """

    vertices: np.ndarray
    triangles: np.ndarray
    normals: np.ndarray
    volume: float
    area: float
    level: float
    spacing: float

    @property
    def empty(self) -> bool:
        return len(self.triangles) == 0

    def __repr__(self) -> str:
        return (f"FieldSlice(level={self.level:.6g}, V={len(self.vertices)}, T={len(self.triangles)}, "
                f"volume={self.volume:.6g}, area={self.area:.6g})")


_EMPTY3 = _sealed(np.zeros((0, 3)))
_EMPTY_T = _sealed(np.zeros((0, 3), dtype=np.intp))


def empty_slice(level: float, spacing: float) -> FieldSlice:
    return FieldSlice(_EMPTY3, _EMPTY_T, _EMPTY3, 0.0, 0.0, level, spacing)


def _representable(s: FieldSlice):
    """The slice's volume, or None when it left float64's range (inf, or a non-empty surface whose
    volume underflowed: coordinates beyond about 1e102 or below about 1e-102)."""
    v = float(s.volume)
    if not math.isfinite(v) or (not s.empty and abs(v) < sys.float_info.min):
        return None
    return v


def _turned_slice(s: FieldSlice, t: np.ndarray) -> FieldSlice:
    if s.empty:
        return s
    return FieldSlice(_sealed(s.vertices @ t.T), s.triangles, _sealed(s.normals @ t.T), s.volume, s.area,
                      s.level, s.spacing)


@dataclass(frozen=True, eq=False)
class CutFrame:
    """Where a field's cut lies in its data: a point p of the cut, ``d`` slice units along the turned
    w axis from the box's centre, is at data ``centre + (matrix.T @ (p, d)) * unit`` (`Field4D.to_data`).

    matrix : (4, 4) float64 -- the cut's rotation
    d : float -- the cut's offset, in slice units
    centre : (4,) float64 -- the data box's centre, in the data's units
    unit : (4,) float64 -- the data's units per slice unit along x, y, z, w
    """

    matrix: np.ndarray
    d: float
    centre: np.ndarray
    unit: np.ndarray

    def __post_init__(self):
        for name in ("matrix", "centre", "unit"):
            object.__setattr__(self, name, _sealed(np.array(getattr(self, name), dtype=np.float64)))
        object.__setattr__(self, "d", float(self.d))

    def to_data(self, points) -> np.ndarray:
        """(n, 4) data coordinates of slice points (n, 3) of this cut."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        return self.centre + (np.column_stack([p, np.full(len(p), self.d)]) @ self.matrix) * self.unit


@dataclass(frozen=True, eq=False)
class FieldSliceData(SliceData):
    """`SliceData` of a `Field4D`: ``levels`` holds one `FieldSlice` per level, ``box`` the exact
    cut of the data's box (a `rot4d_widget.geometry.slicing.Slice`) and ``frame`` the cut's place
    in the data (a `CutFrame`: the cut's matrix and offset and the field's centre and units,
    `Field4D.slice`)."""

    levels: tuple = ()
    box: object = None
    frame: CutFrame | None = None

    def turned(self, t) -> "FieldSliceData":
        """The same slice turned by the 3-D rotation ``t`` (3, 3): the slice at ``T @ matrix``
        when T turns x, y, z only (points and normals ``@ t.T``; nothing is resampled).
        ``box`` stays the unturned cut; ``frame`` gets the turned matrix."""
        t = np.asarray(t, dtype=np.float64)
        if t.shape != (3, 3) or not np.allclose(t @ t.T, np.eye(3), atol=1e-9):
            raise ValueError(f"Expected `t` to be a (3, 3) rotation, got shape {t.shape}")
        frame = self.frame
        if frame is not None:  # the slice at T @ matrix (T turning x, y, z only)
            t4 = np.eye(4)
            t4[:3, :3] = t
            frame = dataclasses.replace(frame, matrix=t4 @ frame.matrix)
        return self.replaced(points=self.points @ t.T, normals=None if self.normals is None else self.normals @ t.T,
                             levels=tuple(_turned_slice(s, t) for s in self.levels), frame=frame)

    @classmethod
    def assemble(cls, slices, box, readout, frame) -> "FieldSliceData":
        """The slice a `Field4D` gives the widget: the surfaces of ``slices`` (one `FieldSlice` per
        level, group = level index) and the box's cut ``box`` as bars; ``frame``: the cut's place in
        the data (a `CutFrame`)."""
        pts, tris, nrm, groups = [], [], [], []
        off = 0
        for g, s in enumerate(slices):
            pts.append(s.vertices)
            nrm.append(s.normals)
            tris.append(s.triangles + off)
            groups.append(np.full(len(s.triangles), g, dtype=np.intp))
            off += len(s.vertices)
        bv = np.asarray(box.vertices)
        r = np.linalg.norm(bv, axis=1, keepdims=True)
        bn = np.where(r > 0, bv / np.where(r > 0, r, 1.0), np.array([0.0, 0.0, 1.0]))
        pts.append(bv)
        nrm.append(bn)
        segments = np.asarray(box.edges) + off
        return cls.build(
            points=np.concatenate(pts), segments=segments, triangles=np.concatenate(tris),
            groups=np.concatenate(groups), normals=np.concatenate(nrm),
            volume=_representable(slices[0]) if len(slices) == 1 else None,
            readout=readout, convex=False, show_points=False,
            levels=tuple(slices), box=box, frame=frame,
        )


def level_surface(s, level: float, inside: str = "above", caps: bool = True) -> FieldSlice:
    """Marching cubes of min(±(f - level), K g) = 0 on one step's samples (+ for inside="above",
    - for "below"); without caps, of ±(f - level) alone within the box (an open surface)."""
    d = s.spacing
    sign = 1.0 if inside == "above" else -1.0
    with np.errstate(invalid="ignore"):
        v = sign * (s.f - level)
        v[v == 0] = 1e-9 * s.k * d  # f == level belongs to the enclosed side
        v[np.isnan(v)] = -s.k * d  # NaN: never enclosed (below every level for inside="above")
        out = s.g < 0
        if caps:
            v[out] = np.inf  # outside the box f means nothing: v is K g alone, so caps sit on the faces
            v = np.minimum(v, s.k * s.g).astype(np.float32)
        else:
            v = v.astype(np.float32)
    mask = None
    if not caps:
        if out.all():
            return empty_slice(level, d)
        if out.any():
            # outside the box: the nearest inside sample's value (so cells across a face see the data
            # carried on, not zeros); cells wholly outside are skipped; triangles beyond the faces dropped
            idx = distance_transform_edt(out, return_distances=False, return_indices=True)
            v = v[tuple(idx)]
            mask = binary_dilation(~out, structure=np.ones((3, 3, 3), dtype=bool))
        if not (v.max() > 0 and v.min() < 0):
            return empty_slice(level, d)
    elif not v.max() > 0:
        return empty_slice(level, d)
    # in index space (spacing 1): skimage scales in float32, which overflows beyond ~3e38; the
    # vertices, volume and area are scaled here in float64, so any field scale works alike
    try:
        verts, faces, normals, _ = marching_cubes(v, 0.0, method="lewiner", mask=mask)
    except (ValueError, RuntimeError):
        if caps:
            raise
        return empty_slice(level, d)  # no crossing within the box
    if not caps and len(faces):
        gc = map_coordinates(s.g, verts[faces].mean(axis=1).T, order=1, mode="nearest")
        faces = faces[gc >= 0]  # keep triangles centred in the box: the open edge lies within a cell of a face
        used = np.unique(faces)
        remap = np.full(len(verts), -1, dtype=np.int64)
        remap[used] = np.arange(len(used))
        verts, normals, faces = verts[used], normals[used], remap[faces]
    if len(faces) == 0:
        return empty_slice(level, d)
    iv = verts.astype(np.float64)  # index coordinates
    vertices = iv * d + s.origin
    tri = faces.astype(np.intp)
    # skimage (gradient 'descent') winds faces clockwise seen from the low side: flip to CCW
    tri = tri[:, ::-1].copy()
    nrm = normals.astype(np.float64)  # skimage's normals (gradient 'descent') point out of {f >= level}
    ln = np.linalg.norm(nrm, axis=1)
    bad = ~(ln > 1e-12)
    if bad.any():
        fn = np.cross(iv[tri[:, 1]] - iv[tri[:, 0]], iv[tri[:, 2]] - iv[tri[:, 0]])
        acc = np.zeros_like(iv)
        for c in range(3):
            for axis in range(3):
                acc[:, axis] += np.bincount(tri[:, c], weights=fn[:, axis], minlength=len(vertices))
        nrm[bad] = acc[bad]
        ln = np.linalg.norm(nrm, axis=1)
        still = ~(ln > 1e-300)
        nrm[still] = (0.0, 0.0, 1.0)
        ln[still] = 1.0
    nrm /= ln[:, None]
    # volume and area in index units (of order resolution**3 and **2), then times d**3 and d**2:
    # only a result beyond float64's range over- or underflows (inf, 0), never the products
    c = iv.mean(axis=0)
    A, B, C = (iv - c)[tri[:, 0]], (iv - c)[tri[:, 1]], (iv - c)[tri[:, 2]]
    cr = np.cross(B - A, C - A)
    volume = float(np.einsum("ij,ij->", A, np.cross(B, C))) / 6.0 * d * d * d if caps else math.nan
    area = float(np.linalg.norm(cr, axis=1).sum()) / 2.0 * d * d
    return FieldSlice(_sealed(vertices), _sealed(tri), _sealed(nrm), volume, area, level, d)
