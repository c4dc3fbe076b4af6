"""Exported meshes in the data's units: a field's mesh at the data's place, each vertex's 4-D data
coordinates kept (``mesh.vertex_attributes["data_xyzw"]``), checked against closed forms.

The field: a ball of radius R about (4, 4, 4) m in a box x, y, z in [2, 6] m (not centred at 0),
w in [100, 160] s, w_per_unit = 10 s per unit of space; c0 is the data's time (s), the hyperplane
D0 = (c0 - 130) / 10 slice units from the box's centre.
"""

import numpy as np
import pytest

trimesh = pytest.importorskip("trimesh")

from rot4d_widget import Field4D  # noqa: E402
from rot4d_widget.keep.meshes import load_mesh, slice_mesh  # noqa: E402
from rot4d_widget.core.rotation import random_rotation  # noqa: E402
from rot4d_widget.sources.protocol import PolytopeSource  # noqa: E402
from rot4d_widget.sources.tomography import StackSource  # noqa: E402

R = 1.5
EXTENT = ((2.0, 6.0), (2.0, 6.0), (2.0, 6.0), (100.0, 160.0))
CENTRE = np.array([4.0, 4.0, 4.0, 130.0])
WPU = 10.0
UNIT = np.array([1.0, 1.0, 1.0, WPU])
C0 = 135.0  # the data's time, s
D0 = 0.5  # its offset in slice units


def ball(x, y, z, w):
    return R * R - ((x - 4.0) ** 2 + (y - 4.0) ** 2 + (z - 4.0) ** 2) + 0.0 * w


def _field(levels=(0.0,), resolution=40):
    return Field4D.from_function(ball, EXTENT, w_per_unit=WPU, w_units="s", levels=list(levels),
                                 resolution=resolution)


def _array_field(levels=(0.0,)):
    axes = [np.linspace(a, b, n) for (a, b), n in zip(EXTENT, (41, 41, 41, 7))]
    X, Y, Z, W = np.meshgrid(*axes, indexing="ij")
    return Field4D(ball(X, Y, Z, W), axes="xyzw", extent=EXTENT, w_per_unit=WPU, levels=list(levels),
                   resolution=40)


def _spacing(data):
    """The grid spacing of the slice's resampling (slice units = metres here)."""
    return max(s.spacing for s in data.levels if not s.empty)


def _hyperplane(xyzw, m):
    """Slice coordinates (n, 4) of data points: m @ ((q - centre) / unit)."""
    return ((np.asarray(xyzw) - CENTRE) / UNIT) @ np.asarray(m).T


# --------------------------------------------------------------------------- at rest
@pytest.mark.parametrize("make_field", [_field, _array_field], ids=["function", "array"])
def test_at_rest_the_mesh_is_the_ball_at_its_data_place(make_field):
    data = make_field().slice(np.eye(4), C0)
    mesh = slice_mesh(data)
    d = _spacing(data)
    assert 0 < d < 0.2
    v = np.asarray(mesh.vertices)
    r = np.linalg.norm(v - CENTRE[:3], axis=1)
    assert np.abs(r - R).max() < d  # on the sphere of radius R about (4, 4, 4) m
    # not where the old export put it (about the box's centre, i.e. about 0)
    assert np.linalg.norm(v, axis=1).min() > 4.0
    xyzw = mesh.vertex_attributes["data_xyzw"]
    assert xyzw.shape == (len(v), 4) and xyzw.dtype == np.float64
    np.testing.assert_allclose(xyzw[:, :3], v, rtol=0, atol=1e-12)  # at rest: the data's x, y, z
    np.testing.assert_allclose(xyzw[:, 3], C0, rtol=0, atol=1e-12)  # the cut's time, 135 s = 130 + 10 D0
    # the shape is the slice's: the same volume, watertight
    assert mesh.is_watertight
    assert mesh.volume == pytest.approx(data.levels[0].volume, rel=1e-9)
    assert mesh.volume == pytest.approx(4 / 3 * np.pi * R**3, rel=0.03)


def test_frame_view_is_the_view_s_slice_coordinates_with_the_data_coordinates_kept():
    data = _field().slice(np.eye(4), C0)
    data_mesh = slice_mesh(data)
    view = slice_mesh(data, frame="view")
    s = data.levels[0]
    np.testing.assert_array_equal(view.vertices, s.vertices)  # today's export: centred, w scaled
    np.testing.assert_allclose(data_mesh.vertices, view.vertices + CENTRE[:3], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(view.vertex_attributes["data_xyzw"], data_mesh.vertex_attributes["data_xyzw"])
    np.testing.assert_array_equal(view.faces, data_mesh.faces)
    with pytest.raises(ValueError, match="frame"):
        slice_mesh(data, frame="world")


def test_several_levels_and_separate_groups_keep_each_vertex_s_data_coordinates():
    radii = (0.8, 1.5)
    data = _field(levels=[R * R - r * r for r in radii]).slice(np.eye(4), 120.0)  # t = 120 s
    d = _spacing(data)
    for sep in (False, True):
        mesh = slice_mesh(data, separate_groups=sep)
        xyzw = mesh.vertex_attributes["data_xyzw"]
        assert len(xyzw) == len(mesh.vertices)
        np.testing.assert_allclose(xyzw[:, :3], mesh.vertices, rtol=0, atol=1e-12)
        np.testing.assert_allclose(xyzw[:, 3], 120.0, rtol=0, atol=1e-12)
        groups = mesh.face_attributes["group"]
        for g, r in enumerate(radii):
            vv = mesh.vertices[np.unique(mesh.faces[groups == g])]
            assert np.abs(np.linalg.norm(vv - CENTRE[:3], axis=1) - r).max() < d


# --------------------------------------------------------------------------- turned
def test_after_a_turn_the_data_coordinates_lie_on_the_cut_and_on_the_ball():
    m = random_rotation(np.random.default_rng(5))
    data = _field().slice(m, C0)
    mesh = slice_mesh(data)
    xyzw = mesh.vertex_attributes["data_xyzw"]
    q = _hyperplane(xyzw, m)
    np.testing.assert_allclose(q[:, 3], D0, rtol=0, atol=1e-9)  # the hyperplane w = c0
    view = slice_mesh(data, frame="view")
    np.testing.assert_allclose(q[:, :3], view.vertices, rtol=0, atol=1e-9)  # and the point drawn
    # the 3 coordinates: the slice's own frame, moved to the data's centre (not turned back)
    np.testing.assert_allclose(mesh.vertices, view.vertices + CENTRE[:3], rtol=0, atol=1e-12)
    assert mesh.volume == pytest.approx(view.volume, rel=1e-12)
    # every vertex is a data point on the surface: |xyz - (4, 4, 4)| = R (the ball is the same at every
    # w), or on the cap where the tilted cut leaves the data's time range (within a cell of w = 100 s
    # or 160 s, inside the ball)
    d = _spacing(data)
    r = np.linalg.norm(xyzw[:, :3] - CENTRE[:3], axis=1)
    on_sphere = np.abs(r - R) < d
    on_cap = (np.minimum(np.abs(xyzw[:, 3] - 100.0), np.abs(xyzw[:, 3] - 160.0)) / WPU < d) & (r < R + d)
    assert (on_sphere | on_cap).all() and on_sphere.mean() > 0.5
    assert xyzw[:, 3].min() >= EXTENT[3][0] - 1e-4 and xyzw[:, 3].max() <= EXTENT[3][1] + 1e-4  # float32 caps
    assert np.ptp(xyzw[:, 3]) > 1.0  # the turn mixed w in: the cut spans times


def test_field_to_data_is_the_same_map():
    f = _field()
    m = random_rotation(np.random.default_rng(8))
    data = f.slice(m, C0)
    mesh = slice_mesh(data, frame="view")
    np.testing.assert_allclose(f.to_data(mesh.vertices, m, C0), mesh.vertex_attributes["data_xyzw"],
                               rtol=0, atol=1e-12)
    np.testing.assert_allclose(f.to_data([[0.0, 0.0, 0.0]], np.eye(4), 130.0), [CENTRE], rtol=0, atol=0)


def test_a_slice_turned_in_3d_keeps_its_data_coordinates():
    m = random_rotation(np.random.default_rng(9))
    data = _field().slice(m, C0)
    a = 0.7  # a turn in the xy plane, then one in yz: x, y, z only
    t = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]]) @ \
        np.array([[1, 0, 0], [0, np.cos(2 * a), -np.sin(2 * a)], [0, np.sin(2 * a), np.cos(2 * a)]])
    turned = data.turned(t)
    a, b = slice_mesh(data), slice_mesh(turned)
    # the same physical points: the same data coordinates, vertex for vertex
    np.testing.assert_allclose(b.vertex_attributes["data_xyzw"], a.vertex_attributes["data_xyzw"],
                               rtol=0, atol=1e-9)
    np.testing.assert_allclose(b.vertices, (a.vertices - CENTRE[:3]) @ t.T + CENTRE[:3], rtol=0, atol=1e-9)


def test_a_widget_turned_by_key_4_exports_data_coordinates_on_its_cut(make):
    w = make(_field(resolution=32), c0=C0)
    rest = w.slice_mesh()
    assert np.abs(np.linalg.norm(rest.vertices - CENTRE[:3], axis=1) - R).max() < _spacing(w.slice)
    np.testing.assert_allclose(rest.vertex_attributes["data_xyzw"][:, 3], 135.0, rtol=0, atol=1e-12)
    w.press("4")
    m = np.asarray(w.state.matrix)
    assert not np.allclose(m, np.eye(4))
    mesh = w.slice_mesh()
    xyzw = mesh.vertex_attributes["data_xyzw"]
    q = _hyperplane(xyzw, m)
    assert w.state.c0 == C0  # the widget's c0 is the data's time
    np.testing.assert_allclose(q[:, 3], (w.state.c0 - 130.0) / WPU, rtol=0, atol=1e-9)
    np.testing.assert_allclose(mesh.vertices, q[:, :3] + CENTRE[:3], rtol=0, atol=1e-9)
    d = _spacing(w.slice)
    r = np.linalg.norm(xyzw[:, :3] - CENTRE[:3], axis=1)
    on_cap = (np.minimum(np.abs(xyzw[:, 3] - 100.0), np.abs(xyzw[:, 3] - 160.0)) / WPU < d) & (r < R + d)
    assert ((np.abs(r - R) < d) | on_cap).all()
    view = w.slice_mesh(frame="view")
    np.testing.assert_allclose(view.vertices, q[:, :3], rtol=0, atol=1e-9)


# --------------------------------------------------------------------------- files, stacks, polytopes
def test_data_xyzw_survives_ply(tmp_path):
    m = random_rotation(np.random.default_rng(3))
    mesh = slice_mesh(_field().slice(m, C0))
    mesh.export(tmp_path / "ball.ply")
    back = load_mesh(tmp_path / "ball.ply")
    np.testing.assert_array_equal(back.vertex_attributes["data_xyzw"], mesh.vertex_attributes["data_xyzw"])
    np.testing.assert_allclose(back.vertices, mesh.vertices, rtol=1e-6, atol=0)  # float32 vertices
    np.testing.assert_array_equal(back.face_attributes["group"], mesh.face_attributes["group"])
    mesh.export(tmp_path / "ball_ascii.ply", encoding="ascii")
    back = load_mesh(tmp_path / "ball_ascii.ply")
    np.testing.assert_allclose(back.vertex_attributes["data_xyzw"], mesh.vertex_attributes["data_xyzw"],
                               rtol=1e-7, atol=0)
    for ext in ("obj", "glb", "stl"):  # the other writers take the attribute without failing
        mesh.export(tmp_path / f"ball.{ext}")


def test_a_stack_keeps_its_layout_and_each_slice_s_own_time():
    src = StackSource(_field(resolution=32), slices=3, spacing=0.5, arrangement="grid")
    data = src.slice(np.eye(4), C0)
    cuts = np.asarray(data.cuts)
    mesh = slice_mesh(data)
    view = slice_mesh(data, frame="view")
    np.testing.assert_allclose(mesh.vertices, view.vertices + CENTRE[:3], rtol=0, atol=1e-12)  # the layout, moved
    xyzw = mesh.vertex_attributes["data_xyzw"]
    np.testing.assert_array_equal(view.vertex_attributes["data_xyzw"], xyzw)
    sl = mesh.face_attributes["slice"]
    for k in range(3):
        rows = np.unique(mesh.faces[sl == k])
        np.testing.assert_allclose(xyzw[rows, 3], cuts[k], rtol=0, atol=1e-12)  # cuts in s
        assert cuts[k] == C0 + (k - 1) * 0.5  # the spacing is in the data's w units (s), like c0
        piece = data.slices[k]
        assert np.abs(np.linalg.norm(xyzw[rows, :3] - CENTRE[:3], axis=1) - R).max() < _spacing(piece)
    assert len(set(np.round(xyzw[:, 3], 9))) == 3
    # one slice: placed as a field's own mesh
    one = slice_mesh(StackSource(_field(resolution=32), slices=1).slice(np.eye(4), C0))
    plain = slice_mesh(_field(resolution=32).slice(np.eye(4), C0))
    np.testing.assert_allclose(one.vertices, plain.vertices, rtol=0, atol=1e-12)
    np.testing.assert_allclose(one.vertex_attributes["data_xyzw"], plain.vertex_attributes["data_xyzw"],
                               rtol=0, atol=1e-12)


def test_polytopes_keep_their_own_units():
    m = random_rotation(np.random.default_rng(4))
    data = PolytopeSource("24-cell").slice(m, 0.3)
    a, b = slice_mesh(data), slice_mesh(data, frame="view")
    np.testing.assert_array_equal(a.vertices, data.slice.vertices)
    np.testing.assert_array_equal(a.vertices, b.vertices)
    assert "data_xyzw" not in a.vertex_attributes
    both = slice_mesh([data, _field().slice(np.eye(4), C0)])  # not every item knows its data coordinates
    assert "data_xyzw" not in both.vertex_attributes
    na = len(data.slice.vertices)
    assert np.abs(np.linalg.norm(both.vertices[na:] - CENTRE[:3], axis=1) - R).max() < 0.2
