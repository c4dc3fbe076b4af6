"""Issue 12: the slice as a mesh (trimesh) and the state as a JSON file (rot4d_widget.keep.meshes, .statefile)."""

import json
import math
import os
import stat
import warnings

import numpy as np
import pytest

trimesh = pytest.importorskip("trimesh")

from rot4d_widget import Field4D, RotationState  # noqa: E402
from rot4d_widget.core import colours
from rot4d_widget.keep.meshes import face_colors, load_mesh, slice_mesh
from rot4d_widget.keep.rebuild import CodeNotAllowed, SourceNotRebuildable, describe_source
from rot4d_widget.keep.statefile import load_state, save_state
from rot4d_widget.sources.field.container import slice_field  # noqa: E402
from rot4d_widget.geometry.catalogue import polytope
from rot4d_widget.geometry.regular import pentachoron  # noqa: E402
from rot4d_widget.core.rotation import random_rotation  # noqa: E402
from rot4d_widget.sources.protocol import PolytopeSource  # noqa: E402
from rot4d_widget.sources.tomography import StackSource  # noqa: E402

FORMATS = ("ply", "obj", "stl", "glb")


def ball_minus_w(x, y, z, w):
    """A module-level field function (a state file can name it): a ball shrinking along w."""
    return 1.0 - (x * x + y * y + z * z) - 0.3 * w


def _field(resolution=24, levels=(0.3, 0.6)):
    return Field4D.from_function(ball_minus_w, ((-1.2, 1.2), (-1.2, 1.2), (-1.2, 1.2), (-1.0, 1.0)),
                                 resolution=resolution, coarse_resolution=16, levels=levels)


M = random_rotation(np.random.default_rng(11))


# --------------------------------------------------------------------------- comparing meshes
def _match(loaded, original):
    """Index of the original vertex each loaded vertex is (they must coincide to float32 rounding)."""
    from scipy.spatial import cKDTree

    a, b = np.asarray(loaded.vertices), np.asarray(original.vertices)
    dist, idx = cKDTree(b).query(a)
    scale = max(1.0, float(np.abs(b).max()))
    assert dist.max() <= 4e-7 * scale  # float32 rounding
    return idx


def _faces_as_set(faces):
    """Faces as cyclically normalised triples: same set <=> same triangles, same winding."""
    out = set()
    for f in np.asarray(faces).tolist():
        k = f.index(min(f))
        out.add(tuple(f[k:] + f[:k]))
    return out


def _assert_round_trip(mesh, path, ext):
    mesh.export(path)
    back = load_mesh(path)
    idx = _match(back, mesh)
    # the same vertices up to order (STL: a soup merged on loading, so compare the sets)
    assert set(idx.tolist()) == set(range(len(mesh.vertices)))
    if ext != "stl":
        assert len(back.vertices) == len(mesh.vertices)
    assert _faces_as_set(idx[np.asarray(back.faces)]) == _faces_as_set(mesh.faces)
    assert len(back.faces) == len(mesh.faces)
    assert back.volume == pytest.approx(mesh.volume, rel=1e-5)
    return back


# --------------------------------------------------------------------------- polytopes
@pytest.fixture(scope="module")
def polytope_data():
    return PolytopeSource("24-cell").slice(M, 0.3)


def test_polytope_mesh_is_the_slice(polytope_data):
    s = polytope_data.slice
    mesh = slice_mesh(polytope_data)
    assert len(mesh.faces) == len(s.triangles) and len(mesh.vertices) == len(s.vertices)
    np.testing.assert_array_equal(mesh.vertices, s.vertices)  # source units, nothing merged or moved
    np.testing.assert_array_equal(mesh.face_attributes["group"], s.triangle_cells)
    assert mesh.is_watertight and mesh.is_winding_consistent
    # trimesh's volume (divergence theorem over the faces) against the slicer's own
    assert mesh.volume == pytest.approx(s.volume, rel=1e-12)
    assert mesh.metadata["rot4d_widget"] == {"kind": "polytope", "volume": s.volume}
    # the live view's colours: the cell palette, rounded to 8 bits
    want = np.rint(colours.group_palette(int(s.triangle_cells.max()) + 1)[s.triangle_cells] * 255)
    np.testing.assert_array_equal(mesh.visual.face_colors[:, :3], want)
    assert (mesh.visual.face_colors[:, 3] == 255).all()


@pytest.mark.parametrize("ext", FORMATS)
def test_polytope_mesh_round_trip(polytope_data, tmp_path, ext):
    mesh = slice_mesh(polytope_data)
    back = _assert_round_trip(mesh, tmp_path / f"slice.{ext}", ext)
    assert back.volume == pytest.approx(polytope_data.slice.volume, rel=1e-5)
    if ext == "ply":  # PLY keeps the groups and the face colours
        np.testing.assert_array_equal(back.face_attributes["group"], mesh.face_attributes["group"])
        np.testing.assert_array_equal(back.visual.face_colors, mesh.visual.face_colors)


def test_separate_groups_keeps_face_colours_in_vertex_colour_formats(polytope_data, tmp_path):
    mesh = slice_mesh(polytope_data, separate_groups=True)
    assert len(mesh.vertices) > len(polytope_data.points)  # corners repeated per cell
    assert mesh.volume == pytest.approx(polytope_data.slice.volume, rel=1e-12)
    want = np.asarray(mesh.visual.face_colors)[:, :3]
    for ext in ("obj", "glb"):
        mesh.export(tmp_path / f"s.{ext}")
        back = load_mesh(tmp_path / f"s.{ext}")
        got = np.asarray(back.visual.vertex_colors)[:, :3][np.asarray(back.faces)]  # (k, 3 corners, rgb)
        assert (got == got[:, :1]).all()  # every face's corners carry one colour ...
        # ... and it is the face's: the same colours, face for face (by position of the centroid)
        c_back = np.asarray(back.vertices)[np.asarray(back.faces)].mean(axis=1)
        c_mesh = mesh.triangles_center
        nearest = np.linalg.norm(c_back[:, None] - c_mesh[None], axis=2).argmin(axis=1)
        assert sorted(nearest.tolist()) == list(range(len(mesh.faces)))
        np.testing.assert_array_equal(got[:, 0], want[nearest])
    # shared corners average the colours without it (why the option exists)
    plain = slice_mesh(polytope_data)
    plain.export(tmp_path / "p.obj")
    vc = np.asarray(load_mesh(tmp_path / "p.obj").visual.vertex_colors)[:, :3]
    assert len(np.unique(vc, axis=0)) > len(np.unique(mesh.visual.face_colors[:, :3], axis=0))


def test_single_colour_and_opacity(polytope_data):
    mesh = slice_mesh(polytope_data, color_by="#9fb6cd", opacity=colours.FACE_OPACITY)
    assert (mesh.visual.face_colors == [0x9f, 0xb6, 0xcd, round(255 * colours.FACE_OPACITY)]).all()
    with pytest.raises(ValueError, match="color_by"):
        slice_mesh(polytope_data, color_by="blue-ish")
    with pytest.raises(ValueError, match="opacity"):
        slice_mesh(polytope_data, opacity=2)
    with pytest.raises(TypeError, match="Expected slice data"):
        slice_mesh(np.zeros((3, 3)))


def test_an_empty_slice_is_an_empty_mesh():
    data = PolytopeSource("5-cell").slice(np.eye(4), 5.0)
    mesh = slice_mesh(data)
    assert len(mesh.faces) == 0 and len(mesh.vertices) == 0 and mesh.metadata["rot4d_widget"]["volume"] == 0.0


# --------------------------------------------------------------------------- fields
@pytest.fixture(scope="module")
def field_data():
    f = _field()
    return f, f.slice(M, 0.2)


def test_field_mesh_groups_by_level_and_volume_is_the_field_slices(field_data, tmp_path):
    field, data = field_data
    levels = data.levels
    mesh = slice_mesh(data)
    assert len(mesh.faces) == sum(len(s.triangles) for s in levels)
    counts = np.bincount(mesh.face_attributes["group"], minlength=2)
    assert counts.tolist() == [len(s.triangles) for s in levels]
    # the box outline (bars) is not part of the mesh: only the points faces use
    assert len(mesh.vertices) == sum(len(s.vertices) for s in levels)
    # volume against slice_field's own (computed separately, per level)
    again = slice_field(field, M, 0.2, list(field.levels), field.resolution)
    assert mesh.volume == pytest.approx(sum(s.volume for s in again), rel=1e-9)
    # the colours of the live view's levels (colormap over the field's data range)
    want = np.rint(colours.level_colors(field.levels, *field.data_range) * 255)
    np.testing.assert_array_equal(mesh.visual.face_colors[:, :3], want[mesh.face_attributes["group"]])
    for ext in FORMATS:
        back = _assert_round_trip(mesh, tmp_path / f"f.{ext}", ext)
        if ext == "ply":
            np.testing.assert_array_equal(back.face_attributes["group"], mesh.face_attributes["group"])


# --------------------------------------------------------------------------- stacks and lists
def test_stack_mesh_keeps_the_placement_and_the_slice_of_each_face(tmp_path):
    src = StackSource("24-cell", slices=5, spacing=0.5, arrangement="grid")
    data = src.slice(M, 0.1)
    mesh = slice_mesh(data)
    scales = np.asarray(data.scales)
    want = sum(s**3 * v for s, v in zip(scales, data.volumes))
    assert mesh.volume == pytest.approx(want, rel=1e-12)
    assert mesh.metadata["rot4d_widget"]["volume"] == pytest.approx(want, rel=1e-12)
    toff = np.asarray(data.triangle_offsets)
    np.testing.assert_array_equal(np.bincount(mesh.face_attributes["slice"], minlength=5), np.diff(toff))
    np.testing.assert_array_equal(mesh.face_attributes["group"], mesh.face_attributes["slice"])  # colour by w
    np.testing.assert_array_equal(mesh.visual.face_colors[:, :3],
                                  np.rint(np.asarray(data.group_rgb)[mesh.face_attributes["slice"]] * 255))
    # each slice's faces are around its centre in the layout
    for k in range(5):
        v = mesh.vertices[np.unique(mesh.faces[mesh.face_attributes["slice"] == k])]
        assert np.linalg.norm(v - data.centres[k], axis=1).max() <= scales[k] * src.size * (1 + 1e-9)
    back = _assert_round_trip(mesh, tmp_path / "stack.ply", "ply")
    np.testing.assert_array_equal(back.face_attributes["slice"], mesh.face_attributes["slice"])


def test_a_list_of_slices_is_concatenated_with_an_item_attribute(polytope_data, field_data):
    a, b = polytope_data, field_data[1]
    mesh = slice_mesh([a, b])
    na = len(a.triangles)
    assert len(mesh.faces) == na + len(b.triangles)
    assert (mesh.face_attributes["item"][:na] == 0).all() and (mesh.face_attributes["item"][na:] == 1).all()
    assert mesh.metadata["rot4d_widget"]["kind"] == "mixed"
    assert mesh.volume == pytest.approx(a.volume + sum(s.volume for s in b.levels), rel=1e-9)
    with pytest.raises(ValueError, match="empty sequence"):
        slice_mesh([])


def test_face_colors_group_colors_override(polytope_data):
    n = int(np.asarray(polytope_data.groups).max()) + 1
    rgb = face_colors(polytope_data, group_colors=["#ff0000"] * n)
    assert (rgb == [1.0, 0.0, 0.0]).all()
    with pytest.raises(ValueError, match="a colour for every group"):
        face_colors(polytope_data, group_colors=["#ff0000"])


# --------------------------------------------------------------------------- state files
SETTINGS = {"levels": None, "slices": None, "spacing": None, "arrangement": "oval", "face_opacity": 0.35,
            "ball_radius": 0.07, "show_faces": True, "color_by": "group", "background": "#ffffff"}


def _state():
    st = RotationState(0.1, c0=0.05, matrix=random_rotation(2))
    for k in "4z8lk":
        st.press(k)
    return st


def test_polytope_state_file_round_trip(tmp_path):
    st = _state()
    path = tmp_path / "view.json"
    doc = save_state(path, st, "24-cell", {**SETTINGS, "levels": (1, 2.5), "n": np.int64(3)})
    assert doc["source"]["kind"] == "polytope" and doc["source"]["name"] == "24-cell"
    on_disk = json.loads(path.read_text())
    assert on_disk["format"] == "rot4d_widget state" and on_disk["version"] == 1
    state, source, settings = load_state(path)
    assert np.array_equal(state.matrix, st.matrix) and (state.c0, state.alpha, state.theta0) == (st.c0, st.alpha, st.theta0)
    assert state.c0_step == st.c0_step and list(state.keymap.items()) == list(st.keymap.items())
    assert isinstance(source, PolytopeSource) and source.name == "24-cell"
    assert settings == {**SETTINGS, "levels": [1, 2.5], "n": 3}
    state.press("4")
    state.reset()  # the loaded state is the reset point
    assert np.array_equal(state.matrix, st.matrix)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["view.json"]  # no temporary file left


def test_a_scaled_polytope_keeps_its_vertices(tmp_path):
    save_state(tmp_path / "s.json", RotationState(), PolytopeSource(pentachoron(3.0)))
    _, source, _ = load_state(tmp_path / "s.json")
    np.testing.assert_array_equal(source.polytope.vertices, pentachoron(3.0).vertices)
    assert not np.allclose(source.polytope.vertices, polytope("5-cell").vertices)


def test_stack_state_file_rebuilds_the_stack(tmp_path):
    src = StackSource("16-cell", slices=7, spacing=0.25, arrangement="stack", color_by="cell")
    save_state(tmp_path / "s.json", _state(), src, SETTINGS)
    _, back, _ = load_state(tmp_path / "s.json")
    assert isinstance(back, StackSource) and back.source.name == "16-cell"
    assert (back.slices, back.spacing, back.arrangement, back.color_by) == (7, 0.25, "stack", "cell")


def test_function_field_state_file_rebuilds_the_field(tmp_path):
    f = _field(levels=(0.4,))
    save_state(tmp_path / "f.json", _state(), f)
    with pytest.raises(CodeNotAllowed, match="allow_code=True"):  # a state file runs no code unasked
        load_state(tmp_path / "f.json")
    _, back, _ = load_state(tmp_path / "f.json", allow_code=True)
    assert isinstance(back, Field4D) and back.levels == (0.4,) and back.resolution == 24
    assert back.slice(M, 0.1).volume == f.slice(M, 0.1).volume
    _, given, _ = load_state(tmp_path / "f.json", function=ball_minus_w)  # the function passed in
    assert isinstance(given, Field4D) and given.levels == (0.4,) and given.resolution == 24
    assert given.slice(M, 0.1).volume == f.slice(M, 0.1).volume


def test_file_field_state_file_reopens_the_file(tmp_path):
    xarray = pytest.importorskip("xarray")
    from rot4d_widget.keep.rebuild import open_field

    g = np.linspace(-1, 1, 9)
    t = np.linspace(0, 1, 6)
    vals = 1 - (g[None, None, None, :] ** 2 + g[None, None, :, None] ** 2 + g[None, :, None, None] ** 2) - t[:, None, None, None]
    xarray.DataArray(vals, dims=("time", "z", "y", "x"), coords={"time": t, "z": g, "y": g, "x": g},
                     name="phi").to_netcdf(tmp_path / "run.nc")
    f = open_field(tmp_path / "run.nc", w="time")
    f.levels = (0.2,)
    save_state(tmp_path / "f.json", _state(), f)
    _, back, _ = load_state(tmp_path / "f.json")
    assert back.origin["path"] == str(tmp_path / "run.nc") and back.levels == (0.2,)
    assert back.slice(M, 0.0).volume == pytest.approx(f.slice(M, 0.0).volume, rel=1e-12)


def test_an_in_memory_array_is_described_but_needs_the_source_to_load(tmp_path):
    f = Field4D(np.random.default_rng(0).random((6, 6, 6, 6)), axes="xyzw")
    with pytest.warns(SourceNotRebuildable, match="in-memory numpy.*not written into a state file.*source="):
        save_state(tmp_path / "a.json", _state(), f)
    with pytest.warns(SourceNotRebuildable, match="cannot be rebuilt.*load_state\\(path, source=...\\)"):
        state, source, settings = load_state(tmp_path / "a.json")
    assert source is None and isinstance(state, RotationState)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _, source, _ = load_state(tmp_path / "a.json", source=f)
    assert source is f
    with pytest.raises(ValueError, match="saved with a source of kind 'field', got 'polytope' \\(5-cell\\)"):
        load_state(tmp_path / "a.json", source="5-cell")
    with pytest.warns(SourceNotRebuildable, match="lambda"):
        save_state(tmp_path / "l.json", _state(), Field4D.from_function(lambda x, y, z, w: x, [(-1, 1)] * 4))


def test_a_loaded_orientation_is_validated(tmp_path):
    path = tmp_path / "s.json"
    save_state(path, RotationState(), "5-cell")
    doc = json.loads(path.read_text())
    m = np.eye(4)
    m[0, 1] = 3e-7  # within 1e-6 of orthogonal: re-orthonormalised
    doc["state"]["orientation"] = m.tolist()
    path.write_text(json.dumps(doc))
    got = load_state(path).state.matrix
    assert np.abs(got @ got.T - np.eye(4)).max() < 1e-14
    m[0, 1] = 1e-4  # too far: refused, saying how far
    doc["state"]["orientation"] = m.tolist()
    path.write_text(json.dumps(doc))
    with pytest.raises(ValueError, match=r"bad state: Expected `orientation` to be orthogonal .*deviation 0\.0001"):
        load_state(path)


@pytest.mark.parametrize("content, match", [
    ("not json {", "not a rot4d_widget state file: not JSON"),
    ('{"format": "something else"}', "not a rot4d_widget state file"),
    ('{"format": "rot4d_widget state", "version": 9, "state": {}, "source": null, "settings": {}}',
     "version 9; this rot4d_widget reads versions 1 ... 2"),
    ('{"format": "rot4d_widget state", "version": 1, "state": {}}', "lacks 'source', 'settings'"),
    ('{"format": "rot4d_widget state", "version": 1, "state": {}, "source": null, "settings": {}}',
     "bad state: A state needs its 'orientation'"),
    ('{"format": "rot4d_widget state", "version": 1, "state": {"orientation": [[1,0,0,0],[0,1,0,0],[0,0,1,0],'
     '[0,0,0,1]]}, "source": {"kind": "polytope", "name": "7-cell", "rebuild": true}, "settings": {}}', "bad source description: Unknown polytope '7-cell'"),
])
def test_bad_state_files_say_what_is_wrong(tmp_path, content, match):
    path = tmp_path / "bad.json"
    path.write_text(content)
    with pytest.raises(ValueError, match=match):
        load_state(path)


def test_settings_must_be_json_able(tmp_path):
    with pytest.raises(TypeError, match=r"settings\['f'\] is a builtin_function_or_method, which a JSON state file cannot hold"):
        save_state(tmp_path / "s.json", RotationState(), None, {"f": print})
    with pytest.raises(TypeError, match=r"settings\['x'\] = nan"):
        save_state(tmp_path / "s.json", RotationState(), None, {"x": math.nan})
    assert not (tmp_path / "s.json").exists()


def test_describe_source_says_why_not():
    class Torus:
        size, n_groups = 1.0, 1

        def slice(self, matrix, c0):
            return None

        def describe(self):
            return {"kind": "clifford-torus"}

    d = describe_source(Torus())
    assert d["rebuild"] == "a source of kind 'clifford-torus' cannot be rebuilt from its description"


def test_bare_slices_from_the_slicers(field_data):
    s = polytope("8-cell")
    from rot4d_widget import slice_polytope

    cut = slice_polytope(s, M, 0.2)
    mesh = slice_mesh(cut)
    assert mesh.volume == pytest.approx(cut.volume, rel=1e-12)
    np.testing.assert_array_equal(mesh.face_attributes["group"], cut.triangle_cells)
    fs = field_data[1].levels[0]
    assert slice_mesh(fs).volume == pytest.approx(fs.volume, rel=1e-12)


def test_a_widget_settings_go_to_a_state_file_and_a_picture(tmp_path):
    from rot4d_widget import Rot4DWidget
    from rot4d_widget.keep.statefile import settings_of
    from rot4d_widget.keep.pictures.state_picture import render_state

    w = Rot4DWidget("24-cell", slices=3, arrangement="grid", show_balls=False)
    try:
        w.press("4"), w.press("l")
        settings = settings_of(w)
        assert settings["slices"] == 3 and settings["arrangement"] == "grid" and settings["spacing"] is None
        assert settings["show_balls"] is False and settings["levels"] is None
        save_state(tmp_path / "w.json", w.state, w.source, settings)
        state, source, back = load_state(tmp_path / "w.json")
        assert back == settings and isinstance(source, StackSource) and source.slices == 3
        assert np.array_equal(state.matrix, w.state.matrix) and state.c0_step == w.state.c0_step
        render_state(state, source, tmp_path / "w.png", size=(300, 250), dpi=50, **back)
        mesh = slice_mesh(w.slice)
        assert set(np.unique(mesh.face_attributes["slice"])) == {0, 1, 2}
    finally:
        w.close()


def test_a_non_convex_polytope_keeps_its_faces_and_cells(tmp_path):
    from mesh_shapes import tesseract_union

    from rot4d_widget import slice_polytope

    p, _ = tesseract_union("L")
    save_state(tmp_path / "l.json", RotationState(), PolytopeSource(p))
    _, back, _ = load_state(tmp_path / "l.json")
    q = back.polytope
    assert q.name == p.name and len(q.cells) == len(p.cells) and len(q.faces) == len(p.faces)
    np.testing.assert_array_equal(q.vertices, p.vertices)
    m = random_rotation(5)
    a, b = slice_polytope(p, m, 0.1), slice_polytope(q, m, 0.1)
    assert b.volume == pytest.approx(a.volume, rel=1e-12) and a.volume > 0
    with pytest.raises(ValueError, match="convex hull"):  # the vertices alone would not rebuild it
        type(p)(p.vertices)


@pytest.mark.skipif(not hasattr(os, "fchmod"), reason="POSIX file modes")
@pytest.mark.parametrize("umask", [0o022, 0o077, 0o002], ids=["022", "077", "002"])
def test_save_state_leaves_the_mode_open_would(tmp_path, umask):
    """A replaced file keeps its mode; a new one gets what ``open(path, "w")`` gives under the umask."""
    old = os.umask(umask)
    try:
        with open(tmp_path / "reference.json", "w"):
            pass
        save_state(tmp_path / "new.json", RotationState(), "5-cell")
        for mode in (0o644, 0o640, 0o664, 0o600):
            path = tmp_path / f"kept-{mode:o}.json"
            path.write_text("{}")
            os.chmod(path, mode)
            save_state(path, _state(), "5-cell")
            assert stat.S_IMODE(os.stat(path).st_mode) == mode, f"{mode:o}"
            assert load_state(path).source.name == "5-cell"  # replaced, not appended to
    finally:
        os.umask(old)
    assert stat.S_IMODE(os.stat(tmp_path / "new.json").st_mode) == stat.S_IMODE(
        os.stat(tmp_path / "reference.json").st_mode) == 0o666 & ~umask
    assert not [p.name for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary file left
