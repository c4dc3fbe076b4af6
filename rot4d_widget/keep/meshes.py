"""Keep what you see as a mesh: a slice (any source's) as one `trimesh.Trimesh`, and back.

`slice_mesh(data)` turns what a source's ``slice(matrix, c0)`` returned -- a polytope's
slice, a field's isosurfaces, a stack of parallel slices, or a list of any of them -- into
one `trimesh.Trimesh`: the triangles of every face, concatenated, in the source's own units
(see `slice_mesh` for what a unit is for each kind; a field's in the data's units, at the
data's place, each vertex's 4-D data coordinates in ``mesh.vertex_attributes["data_xyzw"]``),
each face keeping its colour group
(``mesh.face_attributes["group"]``: a polytope's 4-D cell, a field's level index, a stack's
slice index when coloured by w) and its colour (``mesh.visual.face_colors``, the live view's
palette from `rot4d_widget.core.colours`).  ``mesh.export(path)`` writes OBJ, PLY, STL or GLB by the
extension (trimesh's own writers); what each keeps is listed in `MESH_FORMATS`.
`load_mesh(path)` reads one back with the groups a PLY file carries.
"""

from __future__ import annotations

import math
import os
from typing import Mapping

import numpy as np

from ..core import colours
from ..geometry.slicing.tables import Slice
from ..sources.protocol import PolytopeSlice, SliceData, as_slice
from ..sources.tomography import StackSliceData

#: What trimesh's writers keep of a `slice_mesh`, by extension.  Vertices are written as
#: float32 by every format (float64 in none).
MESH_FORMATS = {
    ".ply": "vertices, faces, per-face RGBA colours and the face attribute 'group' (a face property "
            "'int group'; `load_mesh` puts it back in face_attributes); a field's vertex attribute "
            "'data_xyzw' (a vertex property 'list uchar double', float64 in binary PLY; `load_mesh` puts "
            "it back in vertex_attributes)",
    ".obj": "vertices, faces, per-vertex colours (a face colour averaged over the faces at a vertex: "
            "use separate_groups=True to keep every face's colour exact); no groups",
    ".glb": "vertices, faces, per-vertex colours (as OBJ); no groups; 'data_xyzw' as the float32 "
            "attribute '_data_xyzw'",
    ".stl": "faces only (a triangle soup: trimesh merges equal vertices on loading); no colours, no groups",
}

# ============================================================================ meshes
def _field_slice_types():
    """(`FieldSlice`, `FieldSliceData`), imported when a mesh is made."""
    # sources.field.surface imports scikit-image: imported when a mesh is made, not with keep
    from ..sources.field.surface import FieldSlice, FieldSliceData

    return FieldSlice, FieldSliceData


def face_colors(data, *, color_by="group", group_colors=None) -> np.ndarray:
    """(k, 3) float64 in [0, 1]: the colour of each triangle of ``data`` as the live view draws it.

    ``color_by`` is the widget's: ``"group"`` or one colour for every face (``"#9fb6cd"``).
    Groups are coloured by ``group_colors`` (one colour per group) if given, else as the widget
    chooses: a stack coloured by w by its levels' colormap, a field by its levels' colormap
    (`colours.level_colors`), anything else by `colours.group_palette` (a polytope's cells).
    """
    data = _as_slice_data(data)
    groups = np.asarray(data.groups, dtype=np.intp)
    if color_by != "group":
        return np.tile(np.asarray(colours.as_rgb(color_by, "color_by"), dtype=np.float64), (len(groups), 1))
    n = int(groups.max()) + 1 if len(groups) else 0
    if group_colors is not None:
        palette = np.array([colours.as_rgb(c, f"group_colors[{i}]") for i, c in enumerate(group_colors)],
                           dtype=np.float64).reshape(-1, 3)
    elif isinstance(data, StackSliceData) and data.group_rgb is not None:
        palette = np.asarray(data.group_rgb, dtype=np.float64)
    elif isinstance(data, _field_slice_types()[1]) and len(data.levels):
        levels = [s.level for s in data.levels]
        palette = colours.level_colors(levels, min(levels), max(levels))
    else:
        palette = colours.group_palette(n).astype(np.float64)
    if n > len(palette):
        raise ValueError(f"Expected a colour for every group (0 ... {n - 1}), got {len(palette)} colours")
    return palette[groups].reshape(-1, 3)


def _as_slice_data(obj) -> SliceData:
    """A bare `Slice` (slice_polytope) or `FieldSlice` (slice_field) as slice data; any other slice
    (a user's source's too) as `as_slice` makes it."""
    FieldSlice, _ = _field_slice_types()
    # The two class tests left in keep/: they name the slicers' bare results (geometry's `Slice`,
    # `slice_field`'s `FieldSlice`), not source kinds -- any source's own slice is used as it is.
    if isinstance(obj, Slice):
        return PolytopeSlice.build(obj.vertices, obj.edges, obj.triangles, obj.triangle_cells,
                                   volume=None if obj.volume is None else float(obj.volume), slice=obj)
    if isinstance(obj, FieldSlice):
        return SliceData.build(obj.vertices, None, obj.triangles, None, volume=float(obj.volume))
    try:
        return as_slice(obj)
    except TypeError:
        raise TypeError(
            "Expected slice data (what a source's slice(matrix, c0) returns: points, triangles, groups), "
            f"got {type(obj).__name__}"
        ) from None


def _data_frame(data):
    """The `CutFrame` of a field's slice (where its points are in the data), or None for any other
    slice or a frame that is not a usable one (non-finite, units not > 0)."""
    fr = data.frame if isinstance(data, _field_slice_types()[1]) else None
    if fr is None or not (np.all(np.isfinite(fr.matrix)) and math.isfinite(fr.d) and np.all(np.isfinite(fr.centre))
                          and np.all(np.isfinite(fr.unit)) and np.all(fr.unit > 0)):
        return None
    return fr


def _data_coordinates(data, n_points):
    """(xyzw (n, 4) per point, or None; (scale (3,), shift (3,)) to the data's frame, or None).

    A slice with a data frame (a field's): its points' data coordinates.  A stack: each slice's
    points from its own slice's frame (``data.slices``, row for row), when every slice has one.
    """
    if isinstance(data, StackSliceData):
        pieces = data.slices
        off = np.asarray(data.point_offsets, dtype=np.intp)
        frames = [_data_frame(pc) for pc in pieces]
        if not pieces or len(off) != len(pieces) + 1 or off[-1] != n_points or any(f is None for f in frames):
            return None, None
        out = np.empty((n_points, 4))
        for k, (pc, fr) in enumerate(zip(pieces, frames)):
            pts = np.asarray(pc.points, dtype=np.float64).reshape(-1, 3)
            if len(pts) != off[k + 1] - off[k]:
                return None, None
            out[off[k]:off[k + 1]] = fr.to_data(pts)
        return out, (frames[0].unit[:3], frames[0].centre[:3])
    fr = _data_frame(data)
    if fr is None:
        return None, None
    return fr.to_data(data.points), (fr.unit[:3], fr.centre[:3])


def _one_mesh_arrays(data, color_by, group_colors):
    """vertices (n, 3), faces (k, 3), rgb (k, 3), attributes {name: (k,)}, volume or None, kind,
    data coordinates (n, 4) or None, (scale, shift) to the data's frame or None."""
    data = _as_slice_data(data)
    points = np.asarray(data.points, dtype=np.float64).reshape(-1, 3)
    tris = np.asarray(data.triangles, dtype=np.intp).reshape(-1, 3)
    groups = np.asarray(data.groups, dtype=np.intp).reshape(-1)
    rgb = face_colors(data, color_by=color_by, group_colors=group_colors)
    attrs = {"group": groups}
    if isinstance(data, StackSliceData):
        toff = np.asarray(data.triangle_offsets)
        attrs["slice"] = np.repeat(np.arange(len(toff) - 1), np.diff(toff))
        scales = np.asarray(data.scales, dtype=np.float64)
        vols = data.volumes  # each slice drawn scaled by scales[k] (1 for a single slice)
        volume = None if any(v is None for v in vols) else float(sum(s**3 * v for s, v in zip(scales, vols)))
        kind = "stack"
    elif isinstance(data, _field_slice_types()[1]):
        volume = float(sum(s.volume for s in data.levels))
        kind = "field"
    else:
        volume = None if data.volume is None else float(data.volume)
        kind = "polytope" if isinstance(data, PolytopeSlice) else "slice"
    xyzw, to_frame = _data_coordinates(data, len(points))
    return points, tris, rgb, attrs, volume, kind, xyzw, to_frame


def slice_mesh(data, *, color_by="group", group_colors=None, separate_groups: bool = False,
               opacity: float = 1.0, frame: str = "data"):
    """One `trimesh.Trimesh` of the faces of a slice (or of several), as the live view colours them.

    Parameters
    ----------
    data : slice data, or a sequence of them
        What a source's ``slice(matrix, c0)`` returns (or a bare `Slice` from `slice_polytope`,
        a `FieldSlice` from `slice_field`): a polytope's slice (its triangles, the
        polygons fanned, grouped by 4-D cell), a `Field4D`'s (the isosurface of every level,
        grouped by level index), a `StackSource`'s (the N parallel slices placed as the view
        places them, grouped by slice index when coloured by w, else by cell / level).  A
        sequence is concatenated in order.
    color_by, group_colors :
        As the widget's ``color_by`` (``"group"`` or one colour) and ``group_colors``
        (see `face_colors`).
    separate_groups : bool
        False: one vertex per slice vertex (each slice's surface closed and watertight).
        True: a vertex shared by faces of different groups is repeated for each group, so the
        formats that keep only vertex colours (OBJ, GLB) show every face in its own colour.
    opacity : float in [0, 1]
        The colours' alpha (default opaque; the live view draws polytope faces at
        `colours.FACE_OPACITY`).
    frame : "data" (default) or "view"
        Where a slice that knows its data coordinates (a `Field4D`'s, a stack of them: any slice
        data whose ``frame``, a `rot4d_widget.sources.field.surface.CutFrame`, gives the cut's ``matrix``,
        offset ``d`` and the data's ``centre`` and ``unit``, see
        `rot4d_widget.sources.field.container.Field4D.slice`) puts its vertices.
        ``"data"``: in the data's units at the data's place -- the view's 3-D picture scaled by
        the data's units of x, y, z (1 for a field) and moved by the data box's centre, so at
        rest (identity orientation) a vertex is at its data (x, y, z).  After a turn the 3
        coordinates stay the slice's own frame (the picture the view shows, not turned back;
        an axis the turn mixes w into counts w in units of ``w_per_unit``, as in the view),
        only moved to the data's centre: the mesh's shape and volume are the slice's.
        ``"view"``: the view's slice coordinates, as before (centred on the box, w scaled).
        Other slices (polytopes, user sources without a data frame) are the same in both.

    Returns
    -------
    trimesh.Trimesh (built with ``process=False``: nothing merged, reordered or dropped but the
    points no face uses -- balls and bars are not part of it, nor a field's box outline).

    * ``mesh.vertices`` (n, 3) float64 in the source's own units: a polytope's vertex
      coordinates (the six regular ones have edge 2); a field's data units, at the data's place
      (``frame="data"``, above), or with ``frame="view"`` its *slice units* -- x, y, z in the
      data's units about the centre of its box, the w axis counted in units of
      ``field.w_per_unit`` (a turn mixes them); a stack in its inner source's units, slice k
      moved to its place and shrunk by its scale (``data.centres``,
      ``data.scales``) as in the view -- with ``frame="data"`` a stack of field slices
      keeps that layout, moved as a whole by the data box's centre (so one slice is placed as
      a field's).
    * ``mesh.vertex_attributes["data_xyzw"]`` (n, 4) float64, when every slice knows its data
      coordinates (a field's, a stack of a field's; not a polytope's), in either ``frame``:
      each vertex's 4-D data coordinates (x, y, z, w in the data's own units), the slice point
      p of the cut w = c0 rotated back, ``centre + (matrix.T @ (p, d)) * (1, 1, 1, w_per_unit)`` with
      d = (c0 - centre_w) / w_per_unit the cut's offset in slice units
      (`Field4D.to_data`); a stack's vertices each from its own slice's level.  At rest,
      ``data_xyzw[:, :3] == mesh.vertices`` (``frame="data"``) and ``data_xyzw[:, 3]`` is the
      cut's time, c0.  Binary PLY keeps it exactly (a vertex
      property ``list uchar double data_xyzw``; `load_mesh` puts it back), ASCII PLY to about 8
      digits, GLB as float32 (``_data_xyzw``), OBJ and STL not at all.
    * ``mesh.faces`` (k, 3), counter-clockwise seen from outside (a field's: from where f < level).
    * ``mesh.face_attributes["group"]`` (k,) int32: each face's colour group; a stack adds
      ``"slice"`` (k,) int32, a sequence adds ``"item"`` (k,) int32 (its index in the sequence).
    * ``mesh.visual.face_colors`` (k, 4) uint8 RGBA (`face_colors`).
    * ``mesh.metadata["rot4d_widget"]``: ``{"kind", "volume"}``, the volume the slicer computed
      (a polytope's `Slice.volume`, the sum of a field's level volumes, a stack's
      ``sum scale_k^3 V_k``; None where it has no meaning), for checks against ``mesh.volume``.
    """
    # trimesh (optional, the export extra): imported when a mesh is written
    import trimesh

    opacity = float(opacity)
    if not 0.0 <= opacity <= 1.0:
        raise ValueError(f"Expected `opacity` in [0, 1], got {opacity}")
    if frame not in ("data", "view"):
        raise ValueError(f"Expected `frame` to be 'data' (the data's units and place) or 'view' (the view's "
                         f"slice coordinates), got {frame!r}")
    items = list(data) if isinstance(data, (list, tuple)) else [data]
    if not items:
        raise ValueError("Expected slice data or a non-empty sequence of them, got an empty sequence")
    many = isinstance(data, (list, tuple))
    verts, faces, rgbs, attrs, kinds, xyzws = [], [], [], {}, [], []
    volume = 0.0
    off = 0
    for i, item in enumerate(items):
        p, t, rgb, a, vol, kind, xyzw, to_frame = _one_mesh_arrays(item, color_by, group_colors)
        if frame == "data" and to_frame is not None:
            p = p * to_frame[0] + to_frame[1]  # the view's picture in the data's units, at the data's place
        if separate_groups and len(t):
            key = a["group"][:, None] * len(p) + t  # (group, vertex) pairs
            uniq, inv = np.unique(key.ravel(), return_inverse=True)
            rows, t = uniq % len(p), inv.reshape(-1, 3)
        elif len(t):
            rows, inv = np.unique(t.ravel(), return_inverse=True)  # only the points faces use
            t = inv.reshape(-1, 3)
        else:
            rows = np.zeros(0, dtype=np.intp)
        p = p[rows]
        xyzws.append(None if xyzw is None else xyzw[rows])
        if many:
            a["item"] = np.full(len(t), i)
        verts.append(p)
        faces.append(t + off)
        rgbs.append(rgb)
        for name, values in a.items():
            attrs.setdefault(name, []).append(values)
        off += len(p)
        kinds.append(kind)
        volume = None if volume is None or vol is None else volume + vol
    names = [n for n in attrs if len(attrs[n]) == len(items)]  # attributes every item has
    rgb = np.concatenate(rgbs) if rgbs else np.zeros((0, 3))
    colors = np.column_stack([np.rint(rgb * 255), np.full(len(rgb), round(opacity * 255))]).astype(np.uint8)
    mesh = trimesh.Trimesh(vertices=np.concatenate(verts), faces=np.concatenate(faces).astype(np.int64),
                           face_colors=colors, process=False, validate=False)
    for name in names:
        mesh.face_attributes[name] = np.concatenate(attrs[name]).astype(np.int32)
    if all(x is not None for x in xyzws):  # every item knows its data coordinates
        mesh.vertex_attributes["data_xyzw"] = np.concatenate(xyzws).astype(np.float64)
    mesh.metadata["rot4d_widget"] = {"kind": kinds[0] if len(set(kinds)) == 1 else "mixed", "volume": volume}
    return mesh


def _ply_column(element, name):
    """A property of a PLY element as trimesh's reader left it (``metadata["_ply_raw"]``): a
    structured array (binary files; a list property as its count and its values) or a dict of
    columns (ASCII files); None when absent."""
    data = (element or {}).get("data")
    if isinstance(data, Mapping):
        col = data.get(name)
        return None if col is None else np.asarray(col)
    names = getattr(getattr(data, "dtype", None), "names", None) or ()
    if name not in names:
        return None
    col = data[name]
    if getattr(col.dtype, "names", None):  # a list property: (count, values)
        col = col[col.dtype.names[-1]]
    return np.asarray(col)


def load_mesh(path):
    """Read a mesh file with trimesh (nothing merged), restoring ``face_attributes["group"]``
    (and "slice", "item") from a PLY file's face properties and ``vertex_attributes["data_xyzw"]``
    (n, 4) float64 from its vertex property (a list of 4 doubles)."""
    # trimesh (optional, the export extra): imported when a mesh is read
    import trimesh

    mesh = trimesh.load(os.fspath(path), force="mesh", process=False)
    raw = mesh.metadata.get("_ply_raw") if isinstance(mesh.metadata, dict) else None
    if raw is not None:
        for name in ("group", "slice", "item"):
            col = _ply_column(raw.get("face"), name)
            if col is not None and len(col) == len(mesh.faces):
                mesh.face_attributes[name] = col.reshape(-1)
        col = _ply_column(raw.get("vertex"), "data_xyzw")
        if col is not None and col.size == 4 * len(mesh.vertices):
            mesh.vertex_attributes["data_xyzw"] = col.reshape(-1, 4).astype(np.float64)
    return mesh


# ============================================================================ sources
