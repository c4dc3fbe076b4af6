"""Grids of slice panels: one panel, a key held down, the paper's Figs. 3 and 4.

``render_key_sequence(key, n_panels)`` shows what holding a key does: panel k is drawn after k
presses; :func:`paper_figure_3` and :func:`paper_figure_4` reproduce the paper's figures.
"""

from __future__ import annotations

import copy
import string

import numpy as np
from matplotlib.figure import Figure

from ...core import colours, sizes
from ...core.sizes import REFERENCE_RADIUS
from ...core.state import RotationState
from ...geometry.mesh import Polytope
from ...geometry.regular import pentachoron
from ...geometry.slicing.polytope_slice import slice_polytope
from .canvas import LiteralTextFigure
from .slice_drawing import (
    FIG3_THETA0,
    FIG4_ALPHA,
    FIG4_THETA0,
    TITLE_HEIGHT,
    as_polytope,
    checked_count,
    checked_real,
    draw_slice,
    save_figure,
)


# --------------------------------------------------------------------------- grids of panels
def _panel_label(k: int) -> str:
    return f"({string.ascii_lowercase[k]})" if k < 26 else f"({k + 1})"


def _grid_figure(n_panels: int, ncols: int, panel_size: float, dpi: float, title: str | None):
    ncols = min(ncols, n_panels)
    nrows = -(-n_panels // ncols)
    top = TITLE_HEIGHT if title else 0.0
    width, height = ncols * panel_size, nrows * panel_size + top
    fig = LiteralTextFigure(figsize=(width, height), dpi=dpi, facecolor=colours.BACKGROUND)
    axes = []
    for k in range(nrows * ncols):
        r, c = divmod(k, ncols)
        # [left, bottom, width, height] in figure fractions: panels tile the figure exactly
        rect = [c * panel_size / width, (height - top - (r + 1) * panel_size) / height,
                panel_size / width, panel_size / height]
        ax = fig.add_axes(rect)
        ax.set_axis_off()
        axes.append(ax)
    if title:
        fig.text(0.5, 1.0 - 0.5 * TITLE_HEIGHT / height, title, ha="center", va="center", fontsize=11)
    return fig, axes


def _check_grid_args(ncols, panel_size, dpi, title):
    ncols = checked_count("ncols", ncols)
    panel_size = checked_real("panel_size", panel_size, minimum=0.0, inclusive=False)
    dpi = checked_real("dpi", dpi, minimum=0.0, inclusive=False)
    if title is not None and not isinstance(title, str):
        raise TypeError(f"Expected `title` to be a string or None, got {type(title).__name__}")
    return ncols, panel_size, dpi


def _default_scale(poly: Polytope, scale):
    if scale is None:
        return REFERENCE_RADIUS / float(poly.circumradius)
    return checked_real("scale", scale, minimum=0.0, inclusive=False)


def panel_style(polytope, scale: float | None = None) -> dict:
    """Keywords for :func:`draw_slice` that suit ``polytope``: ``scale``, ``radius``, ball and bar sizes.

    ``scale`` defaults to ``REFERENCE_RADIUS / circumradius`` (every polytope the size of the paper's
    pentachoron); the ``radius`` is the scaled circumradius; balls and bars follow the scaled
    edge length as in the live view (``sizes.default_ball_radius`` and ``sizes.default_bar_radius``:
    the pentachoron's 0.07 and 0.028 at most, so that the 600 vertices of the 120-cell do not
    merge).  Use as ``draw_slice(ax, s, **panel_style(p))``.
    """
    poly = as_polytope(polytope)
    s = _default_scale(poly, scale)
    e = np.asarray(poly.edges, dtype=np.int64).reshape(-1, 2)
    edge = float(np.linalg.norm(poly.vertices[e[:, 0]] - poly.vertices[e[:, 1]], axis=1).mean()) if len(e) else 1.0
    ball = sizes.default_ball_radius(edge * s)
    return {"scale": s, "radius": s * float(poly.circumradius), "ball_radius": ball,
            "bar_radius": sizes.default_bar_radius(ball)}


def render_slice(
    polytope="5-cell",
    matrix=None,
    c0: float = 0.0,
    *,
    scale: float | None = None,
    panel_size: float = 3.0,
    dpi: float = 100,
    title: str | None = None,
    **draw_kwargs,
) -> Figure:
    """One panel: the slice w = ``c0`` of ``polytope`` turned by ``matrix`` (identity by default).

    ``polytope`` is a name ("5-cell" ... "600-cell") or a Polytope; ``scale`` defaults to
    ``REFERENCE_RADIUS / circumradius`` (every polytope appears the size of the paper's
    pentachoron), sizes to :func:`panel_style`.  Other keywords go to :func:`draw_slice`.
    """
    poly = as_polytope(polytope)
    matrix = np.eye(4) if matrix is None else matrix
    c0 = checked_real("c0", c0)
    s = _default_scale(poly, scale)
    _, panel_size, dpi = _check_grid_args(1, panel_size, dpi, title)
    fig, (ax,) = _grid_figure(1, 1, panel_size, dpi, title)
    kwargs = {**panel_style(poly, s), **draw_kwargs}
    draw_slice(ax, slice_polytope(poly, matrix, c0), **kwargs)
    return fig


def render_key_sequence(
    key: str,
    n_panels: int = 16,
    *,
    state: RotationState | None = None,
    polytope="5-cell",
    shift: bool = False,
    ncols: int = 4,
    scale: float | None = None,
    panel_size: float = 2.0,
    dpi: float = 100,
    labels: bool = True,
    title: str | None = None,
    **draw_kwargs,
) -> Figure:
    """A grid of panels showing what pressing ``key`` repeatedly does.

    Panel k (k = 0 ... ``n_panels`` - 1, labelled (a), (b), ...) shows the slice w = c0 after k
    presses of ``key`` (with ``shift`` for the inverse) starting from ``state`` (default: a fresh
    :class:`RotationState`).  ``state`` is copied, never modified.  Any bound key works: "4" turns
    in the x-w plane, "z" is a double rotation, "l" raises c0.  ``ncols`` panels per row
    (fewer if there are fewer panels), each ``panel_size`` inches square at ``dpi``; all panels
    share one frame.  Sizes default to :func:`panel_style`; other keywords go to :func:`draw_slice`.
    """
    if not isinstance(key, str):
        raise TypeError(f"Expected `key` to be a string such as '4' or 'z', got {type(key).__name__}")
    n_panels = checked_count("n_panels", n_panels)
    ncols, panel_size, dpi = _check_grid_args(ncols, panel_size, dpi, title)
    if state is None:
        state = RotationState()
    elif not isinstance(state, RotationState):
        raise TypeError(f"Expected `state` to be a rot4d_widget.RotationState, got {type(state).__name__}")
    state = copy.deepcopy(state)
    if state.keymap.resolve(key, bool(shift)) is None:
        bound = " ".join(sorted(k for k in state.keymap if len(k) == 1))
        raise ValueError(f"Key {key!r} is not bound to an action; bound keys: {bound}")
    poly = as_polytope(polytope)
    kwargs = {**panel_style(poly, scale), **draw_kwargs}

    fig, axes = _grid_figure(n_panels, ncols, panel_size, dpi, title)
    for k in range(n_panels):
        if k:
            state.press(key, shift=bool(shift))
        label = _panel_label(k) if labels else None
        draw_slice(axes[k], slice_polytope(poly, state.matrix, state.c0), label=label, **kwargs)
    return fig



def paper_figure_3(path=None, *, panel_size: float = 2.0, dpi: float = 100, title: bool = True) -> Figure:
    """The paper's Fig. 3: 16 slices w = 0 of the a = 2 pentachoron under key "4" (R_xw, theta0 = pi/16).

    Panel k shows the slice after k presses; panel (a) is the regular tetrahedron of edge 1.6.
    (The paper's caption says R_yw; its key table, which wins, binds "4" to R_xw.)
    Saved to ``path`` (.png, .pdf or .svg) if given.
    """
    fig = render_key_sequence(
        "4", 16, state=RotationState(theta0=FIG3_THETA0), polytope=pentachoron(2.0), ncols=4,
        scale=1.0, panel_size=panel_size, dpi=dpi,
        title="Fig. 3: key \u201c4\u201d, R_xw(\u03c0/16) per panel; pentachoron a = 2, slice w = 0"
        if title else None,
    )
    save_figure(fig, path)
    return fig


def paper_figure_4(path=None, *, panel_size: float = 2.0, dpi: float = 100, title: bool = True) -> Figure:
    """The paper's Fig. 4: 16 slices w = 0 of the a = 2 pentachoron under key "z" (R_xz,yw).

    alpha = pi sqrt2 / (8 sqrt3) and beta = 1 - alpha (theta0 = 1 rad); alpha/beta is irrational, so
    the sequence never returns to panel (a).  Saved to ``path`` (.png, .pdf or .svg) if given.
    """
    fig = render_key_sequence(
        "z", 16, state=RotationState(theta0=FIG4_THETA0, alpha=FIG4_ALPHA), polytope=pentachoron(2.0),
        ncols=4, scale=1.0, panel_size=panel_size, dpi=dpi,
        title="Fig. 4: key \u201cz\u201d, R_xz,yw(\u03b1, \u03b2), \u03b1 = \u03c0\u221a2/(8\u221a3), "
        "\u03b2 = 1 \u2212 \u03b1; w = 0" if title else None,
    )
    save_figure(fig, path)
    return fig
