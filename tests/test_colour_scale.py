"""The colour scale: `cmap` / `clim` checks and colours (core.look), the widget's traits, and the
colour bar in the readout."""

from __future__ import annotations

import numpy as np
import pytest

from rot4d_widget.core import look


# -- core.look ------------------------------------------------------------------------------------
def test_default_level_colours_are_todays_viridis_by_rank():
    from matplotlib import colormaps

    levels = [0.3, -0.2, 0.9]
    want = np.asarray(colormaps["viridis"]([0.52, 0.12, 0.92]))[:, :3]
    np.testing.assert_allclose(look.level_colors(levels, -1.0, 1.0), want)
    np.testing.assert_allclose(look.level_colors([0.1], -1.0, 1.0), np.asarray(colormaps["viridis"]([0.75]))[:, :3])


def test_level_colours_take_the_cmap_and_by_value_the_limits():
    from matplotlib import colormaps

    got = look.level_colors([0.0, 5.0, 20.0], 0.0, 10.0, "magma", by_value=True)
    np.testing.assert_allclose(got, np.asarray(colormaps["magma"]([0.0, 0.5, 1.0]))[:, :3])  # clamped above
    assert not np.allclose(look.level_colors([0.0, 1.0], 0, 1, "magma"), look.level_colors([0.0, 1.0], 0, 1))


@pytest.mark.parametrize("bad, exc, match", [
    ("virdis", ValueError, r"matplotlib colour map name.*did you mean 'viridis'.*sorted\(matplotlib.colormaps\)"),
    ("no such map at all", ValueError, r"sorted\(matplotlib.colormaps\).*'no such map at all'"),
    (3, TypeError, r"`cmap` to be a matplotlib colour map name \(a str; list them with sorted\(matplotlib.colormaps\)"),
    (None, TypeError, "colour map name"),
])
def test_bad_cmap_names_how_to_list_them(bad, exc, match):
    with pytest.raises(exc, match=match):
        look.check_cmap(bad)


@pytest.mark.parametrize("bad, exc", [
    ((1.0, 1.0), ValueError), ((2.0, 1.0), ValueError), ((0.0, float("nan")), ValueError),
    ((float("-inf"), 1.0), ValueError), (3.0, TypeError), ("0,1", TypeError), ((0, 1, 2), TypeError),
    ((True, 2), TypeError), (("0", "1"), TypeError),
])
def test_bad_clim_names_what_is_allowed(bad, exc):
    with pytest.raises(exc, match=r"`clim` to be None \(the data's range\) or \(lo, hi\), two finite numbers "
                                  r"with lo < hi"):
        look.check_clim(bad)


def test_good_clim_and_stops():
    assert look.check_clim(np.array([1, 2])) == (1.0, 2.0)
    assert look.check_clim(None) is None
    assert look.cmap_stops("viridis", 2) == ("#440154", "#fde725")
    assert look.cmap_stops("viridis") != look.cmap_stops("magma")
