"""The readout says the same things in every rendering, and nothing that misleads; sections say
where their planes are and are seen at a slant (issue 37, problem 2).

A flame-like field (T in K on 0.01-0.05 m, 1-4 ms): in surface, volume, mip and sections the
readout has the rows field, axes, level, w cut, w per unit, colour and volume in that order; a
ray-cast picture has no "colours" swatch (the colour bar says what a colour is), its level and
volume rows say that the surface rendering draws them, and a "rendering" row says what it shows.
"sections" names its planes in the data's coordinates (its w, time, after a turn into time) and the
camera moves, while the user has not moved it, to where all three planes show; the static
picture is drawn from there too (the planes' projected areas are computed here from the camera's
position with a look-at of our own).
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from test_labels import flame, turned

from rot4d_widget.core import camera

pytestmark = pytest.mark.usefixtures("recording_comms")

RENDERINGS = ("surface", "volume", "mip", "sections")


def rows(w):
    html = str(w._painter.readout_html())
    return [(re.sub("<[^>]*>", "", k), re.sub("<[^>]*>", "", v))
            for k, v in re.findall(r"<tr><td>(.*?)</td><td>(.*?)</td></tr>", html)]


@pytest.mark.parametrize("rendering", RENDERINGS)
def test_every_rendering_has_the_same_rows_and_none_misleads(make, rendering):
    w = make(flame(), rendering=rendering)
    got = rows(w)
    names = [k for k, _ in got]
    common = ["field", "axes", "level", "w cut", "w per unit", "colour", "volume"]
    assert [k for k in names if k in common] == common, names
    text = dict(got)
    if rendering == "surface":
        assert "colours" in names and text["volume"].endswith("m\u00b3"), got
    else:
        assert "colours" not in names, got  # no level swatch where no level is drawn
        assert "not drawn here" in text["level"] and "surface rendering" in text["volume"], got
        assert text["rendering"].split(":")[0] == {"mip": "maximum intensity"}.get(rendering, rendering), got


def test_sections_name_their_planes_in_the_data_s_coordinates(make):
    w = make(flame(), rendering="sections")
    assert dict(rows(w))["planes a / s / d"] == "x 0.03 m; y 0.03 m; z 0.03 m"
    w.state.matrix = turned().matrix
    w.refresh()
    assert dict(rows(w))["planes a / s / d"] == "w 0.0025 s; y 0.03 m; z 0.03 m"
    w.sections = (1.0, 0.5, 0.0)
    planes = dict(rows(w))["planes a / s / d"].split("; ")
    # the planes at the ends of the sampling grid: a spacing past the data, and said so
    assert planes[0].startswith("w 0.000") and planes[0].endswith(" s (outside the data)"), planes
    assert planes[2].startswith("z 0.00") and planes[2].endswith(" m (outside the data)"), planes
    assert planes[1] == "y 0.03 m", planes


def test_the_camera_shows_all_three_planes_unless_the_user_moved_it(make):
    w = make(flame())
    assert w.scene.eye == camera.CAMERA_POSITION
    w.rendering = "sections"
    np.testing.assert_allclose(w.scene.eye, camera.SECTIONS_CAMERA_POSITION)
    w.rendering = "mip"
    np.testing.assert_allclose(w.scene.eye, camera.CAMERA_POSITION)
    w.rendering = "sections"
    w.scene.canvas.camera.position = (0.0, 3.0, 4.0)  # the user orbits: the camera stays where it is put
    w.rendering = "surface"
    np.testing.assert_allclose(w.scene.eye, (0.0, 3.0, 4.0))
    v = make(flame(), rendering="sections")  # made to show sections
    np.testing.assert_allclose(v.scene.eye, camera.SECTIONS_CAMERA_POSITION)


def _look_at(eye):
    """Rows: the camera's x, y, z axes for an eye looking at the origin with +y up."""
    e = np.asarray(eye, dtype=float)
    z = e / np.linalg.norm(e)
    x = np.cross([0.0, 1.0, 0.0], z)
    x /= np.linalg.norm(x)
    return np.vstack([x, np.cross(z, x), z]), float(np.linalg.norm(e))


def _area(poly):
    x, y = poly[:, 0], poly[:, 1]
    return 0.5 * abs(np.dot(x, np.roll(y, 1)) - np.dot(y, np.roll(x, 1)))


def test_from_the_sections_camera_no_plane_is_edge_on():
    view, dist = _look_at(camera.default_eye("sections"))
    cube = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)

    def project(p):
        q = p @ view.T
        return q[:, :2] * dist / (dist - q[:, 2])[:, None]

    for a in range(3):  # the plane through the middle, perpendicular to axis a
        b, c = [i for i in range(3) if i != a]
        quad = np.zeros((4, 3))
        quad[:, b] = [-1, 1, 1, -1]
        quad[:, c] = [-1, -1, 1, 1]
        assert _area(project(quad)) > 0.25 * _area(project(cube[[0, 1, 3, 2]])), a
    view0, _ = _look_at(camera.default_eye("mip"))
    np.testing.assert_allclose(view0, np.eye(3))


def test_the_static_sections_picture_is_seen_from_the_sections_camera(make, tmp_path):
    from rot4d_widget.keep.pictures.state_picture import render_state

    f = flame()
    w = make(f, rendering="sections")
    fig = w.render(progress=False)
    st = w.state.copy()
    same = render_state(st, f, rendering="sections", eye=camera.SECTIONS_CAMERA_POSITION, size=(600, 500),
                        progress=False)
    front = render_state(st, f, rendering="sections", eye=camera.CAMERA_POSITION, size=(600, 500), progress=False)

    def image(fig):
        (im,) = [a for a in fig.axes[0].images if a.get_gid() == "sections"]
        return np.asarray(im.get_array())

    assert np.array_equal(image(fig), image(same)) and not np.array_equal(image(fig), image(front))
    assert math.isclose(np.linalg.norm(camera.SECTIONS_CAMERA_POSITION), 5.0)
