"""The figures pictures are drawn in: text as written, and the animation frame canvas (one reused
figure, text drawn from kept glyph bitmaps).

`FrameCanvas` is what `render_state(..., _canvas=)` draws an animation's frames into.
"""

from __future__ import annotations

import math

import numpy as np
from matplotlib.figure import Figure
from matplotlib.text import Text


class LiteralTextFigure(Figure):
    """A matplotlib ``Figure`` whose text is drawn as written.  Names, units and labels come from
    data and state files: "$\\bad$" must not be parsed as mathtext (it raises) and no text goes
    to LaTeX (``text.usetex``, which reads files).  Every text is made literal as the figure
    draws, so text added after the figure was made is covered too (PNG, SVG, PDF, frames)."""

    def draw(self, renderer):
        for text in self.findobj(Text):
            text.set_parse_math(False)
            text.set_usetex(False)
        return super().draw(renderer)


_TEXT_CACHE_SIZE = 512  # rendered lines of text an animation's canvas keeps


_GLYPH_CACHE_SIZE = 4096  # glyph bitmaps (each at one sub-pixel offset) an animation's canvas keeps


def _glyph_caching_renderer():
    """`RendererAgg` that keeps the bitmap of every glyph it renders, by font, size, glyph and
    sub-pixel offset (1/64 pixel, FreeType's unit), and draws a glyph it rendered before from
    that bitmap: the same ``draw_text_image`` call with the same bitmap as matplotlib's own,
    so the same pixels, without FreeType (~40 µs a glyph).  A new line of text (an animation's
    "t = ..., frame k/n", "w cut ...") then costs its layout and one small blit per glyph.
    Only for matplotlib's glyph-by-glyph text (3.11+: ``_draw_text_glyphs_and_boxes``,
    ``FT2Font._render_glyph``) and unrotated text; anything else is drawn as usual."""
    global _GLYPH_RENDERER
    if _GLYPH_RENDERER is not None:
        return _GLYPH_RENDERER
    # matplotlib's Agg internals: imported when the first frame is drawn
    from matplotlib import ft2font
    from matplotlib.backends import backend_agg
    from matplotlib.backends.backend_agg import RendererAgg

    usable = (hasattr(RendererAgg, "_draw_text_glyphs_and_boxes") and hasattr(backend_agg, "get_hinting_flag")
              and hasattr(ft2font, "RenderMode")
              and all(hasattr(ft2font.FT2Font, a) for a in ("_render_glyph", "_set_transform", "_layout")))

    class GlyphCachingRenderer(RendererAgg):
        glyphs_cached = usable

        def __init__(self, *args, glyphs=None):
            super().__init__(*args)
            self._glyphs: dict = {} if glyphs is None else glyphs

        def _draw_text_glyphs_and_boxes(self, gc, x, y, angle, glyphs, boxes):
            if angle or boxes or not usable:
                return super()._draw_text_glyphs_and_boxes(gc, x, y, angle, glyphs, boxes)
            RenderMode = ft2font.RenderMode
            flags = backend_agg.get_hinting_flag()
            aa = bool(gc.get_antialiased())
            up = self.height - y  # FreeType's y is upwards
            height = int(self.height)
            cache = self._glyphs
            for font, size, index, slant, extend, dx, dy in glyphs:
                # the pen in 26.6 fixed point, as matplotlib places it (angle 0)
                tx, ty = round(0x40 * (x + dx)), round(0x40 * (up + dy))
                key = (font, size, self.dpi, index, slant, extend, tx & 63, ty & 63, flags, aa)
                hit = cache.get(key)
                if hit is None:  # rendered at the same sub-pixel offset, whole pixels apart
                    font.set_size(size, self.dpi)
                    font._set_transform(np.round(0x10000 * np.array([[extend, extend * slant], [0.0, 1.0]]))
                                        .astype(int), [tx & 63, ty & 63])
                    bitmap = font._render_glyph(index, flags, RenderMode.NORMAL if aa else RenderMode.MONO)
                    buffer = np.array(bitmap.buffer)
                    if not aa:
                        buffer *= 0xff
                    hit = (buffer, bitmap.left, bitmap.top)
                    if len(cache) >= _GLYPH_CACHE_SIZE:
                        cache.clear()
                    cache[key] = hit
                buffer, left, top = hit
                # draw_text_image's y is downwards and the bitmap's bottom side
                self._renderer.draw_text_image(buffer, left + (tx >> 6), height - (top + (ty >> 6)) + buffer.shape[0],
                                               0, gc)

    _GLYPH_RENDERER = GlyphCachingRenderer
    return GlyphCachingRenderer


_GLYPH_RENDERER = None


def _text_caching_canvas(fig):
    """A `FigureCanvasAgg` for ``fig`` whose renderer draws a line of text it drew before from a
    picture of it: matplotlib renders text glyph by glyph (FreeType, a few tens of µs each), and
    an animation's annotation, legend and title repeat from frame to frame but for a line or two.
    A line is rendered once into a transparent buffer at the same sub-pixel offset (so the same
    glyph bitmaps), cropped, and blended where it goes (Agg's draw_image, the same blending as
    drawing the glyphs there: the pixels agree up to rounding).  Glyphs are rendered once too
    (`_glyph_caching_renderer`): a new line is its layout and a blit per glyph.  Rotated text and
    mathtext are drawn as usual."""
    # matplotlib backend: imported when a frame canvas is made
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    GlyphCachingRenderer = _glyph_caching_renderer()

    class TextCachingRenderer(GlyphCachingRenderer):
        def __init__(self, *args):
            super().__init__(*args)
            self._lines: dict = {}

        def draw_text(self, gc, x, y, s, prop, angle, ismath=False, mtext=None):
            if ismath or angle or not s or gc.get_url() is not None:
                return super().draw_text(gc, x, y, s, prop, angle, ismath=ismath, mtext=mtext)
            up = self.height - y  # FreeType's y is upwards
            ix, iy = math.floor(x), math.floor(up)
            feats = (tuple(mtext.get_fontfeatures() or ()), mtext.get_language()) if mtext is not None else None
            font = (tuple(prop.get_family()), prop.get_style(), prop.get_variant(), prop.get_weight(),
                    prop.get_stretch(), prop.get_size(), prop.get_file(), prop.get_math_fontfamily())
            key = (s, font, tuple(gc.get_rgb()), gc.get_alpha(), gc.get_forced_alpha(), gc.get_antialiased(),
                   x - ix, up - iy, feats)
            hit = self._lines.get(key)
            if hit is None:
                hit = self._render_line(gc, x - ix, up - iy, s, prop, mtext)
                if len(self._lines) >= _TEXT_CACHE_SIZE:
                    self._lines.clear()
                self._lines[key] = hit
            img, dx, dy = hit
            if img is None:
                return
            gc1 = self.new_gc()
            gc1.copy_properties(gc)
            gc1.set_alpha(1.0)  # the picture carries the text's alpha already
            self.draw_image(gc1, ix + dx, iy + dy, img)
            gc1.restore()

        def _render_line(self, gc, fx, fy, s, prop, mtext):
            """``(rgba, dx, dy)``: line ``s`` drawn at (fx, fy) in a transparent buffer, cropped to
            its ink; (dx, dy) the crop's lower left corner relative to the pen's whole pixel."""
            em = self.points_to_pixels(prop.get_size_in_points())
            m = int(math.ceil(3.0 * em)) + 4  # room enough around the pen for any glyph (cropped below)
            wd, ht = int(math.ceil(1.5 * em * len(s))) + 2 * m, 2 * m
            off = GlyphCachingRenderer(wd, ht, self.dpi, glyphs=self._glyphs)
            gc1 = off.new_gc()
            gc1.copy_properties(gc)
            gc1.set_clip_rectangle(None)
            gc1.set_clip_path(None)
            oy = ht // 2
            GlyphCachingRenderer.draw_text(off, gc1, m + fx, ht - (oy + fy), s, prop, 0.0, ismath=False, mtext=mtext)
            gc1.restore()
            rgba = np.asarray(off.buffer_rgba())
            rows = np.flatnonzero(rgba[..., 3].any(axis=1))
            cols = np.flatnonzero(rgba[..., 3].any(axis=0))
            if not len(rows):
                return None, 0, 0
            r0, r1, c0, c1 = rows[0], rows[-1] + 1, cols[0], cols[-1] + 1
            # draw_image takes the rows bottom up (as matplotlib's images hand them over)
            return np.ascontiguousarray(rgba[r0:r1, c0:c1][::-1]), int(c0 - m), int(ht - r1 - oy)

    class TextCachingCanvas(FigureCanvasAgg):
        def get_renderer(self):
            w, h = self.get_width_height(physical=True)
            key = w, h, self.figure.dpi
            if self._lastKey != key:
                self.renderer = TextCachingRenderer(w, h, self.figure.dpi)
                self._lastKey = key
            return self.renderer

    return TextCachingCanvas(fig)


class FrameCanvas:
    """One figure, axes and Agg canvas that an animation's frames are drawn into in turn
    (`render_state(..., _canvas=)`): building a figure and its axes was a third of a frame's time.
    `begin` takes the figure (a new one when the size, dpi, title or colour bar strip or background change)
    and removes what the frame before added; the annotation, its legend and the title are kept
    and given the new frame's text (`draw_annotation`), and removed when a frame has none.
    A polytope's slice is drawn as one collection (`slice_collection`) instead of a patch per
    ball, highlight, bar and face.  `rgb()` draws the frame and returns its pixels."""

    def __init__(self):
        self.fig = self.ax = self.canvas = None
        self.key = None
        self.note = self.title = None
        self.legend_key = None
        self.keep: set = set()

    def begin(self, width, height, top, dpi, background, right=0.0):
        """The figure and axes for a frame ``width`` x ``height`` inches, a title strip ``top``
        high above it and a strip ``right`` wide beside it (a field's colour bar)."""
        key = (width, height, top, dpi, tuple(background), right)
        if self.fig is None or key != self.key:
            self.fig = LiteralTextFigure(figsize=(width + right, height + top), dpi=dpi, facecolor=background)
            self.ax = self.fig.add_axes([0, 0, width / (width + right), height / (height + top)])
            self.ax.set_axis_off()
            self.ax.set_facecolor(background)
            self.ax.set_aspect("equal")
            self.canvas = _text_caching_canvas(self.fig)
            self.key = key
            self.note = self.title = self.legend_key = None
        else:  # the frame before's artists go, but for the annotation and the title (kept if used)
            ax = self.ax
            for a in (*ax.collections, *ax.patches, *ax.texts, *ax.lines, *ax.images, *self.fig.texts):
                if a is not self.note and a is not self.title:
                    a.remove()
            for other in self.fig.axes:  # a colour bar: drawn again for the frame
                if other is not ax:
                    other.remove()
        self.keep = set()
        return self.fig, self.ax

    def end(self):
        """After a frame is built: what it did not use of the kept artists goes."""
        if self.note is not None and self.note not in self.keep:
            self.note.remove()
            self.note = None
            if self.ax.get_legend() is not None:
                self.ax.get_legend().remove()
            self.legend_key = None
        if self.title is not None and self.title not in self.keep:
            self.title.remove()
            self.title = None

    @staticmethod
    def as_picture(artist) -> None:
        """Draw ``artist`` (one that stays the same from frame to frame: the legend) from a picture
        of it taken the first time: rendered alone into a transparent buffer of the canvas's size,
        cropped, then blended in place each frame (Agg's draw_image: the same pixels up to rounding)."""
        draw = artist.draw
        kept = {}

        def drawn_from_picture(renderer):
            if not artist.get_visible():
                return
            key = (renderer.width, renderer.height, renderer.dpi, type(renderer))
            if key not in kept:
                # matplotlib backend: imported when a kept picture is drawn
                from matplotlib.backends.backend_agg import RendererAgg

                if not isinstance(renderer, RendererAgg):
                    return draw(renderer)
                off = RendererAgg(int(renderer.width), int(renderer.height), renderer.dpi)
                draw(off)
                rgba = np.asarray(off.buffer_rgba())
                rows = np.flatnonzero(rgba[..., 3].any(axis=1))
                cols = np.flatnonzero(rgba[..., 3].any(axis=0))
                if not len(rows):
                    kept[key] = None
                else:
                    r0, r1, c0, c1 = rows[0], rows[-1] + 1, cols[0], cols[-1] + 1
                    kept[key] = (np.ascontiguousarray(rgba[r0:r1, c0:c1][::-1]), int(c0),
                                 int(renderer.height) - int(r1))
            if kept[key] is not None:
                img, x, y = kept[key]
                gc = renderer.new_gc()
                renderer.draw_image(gc, x, y, img)
                gc.restore()
            artist.stale = False

        artist.draw = drawn_from_picture

    def rgba(self) -> np.ndarray:
        """Draw the frame; its (H, W, 4) uint8 pixels, a view valid until the next frame is drawn."""
        self.canvas.draw()
        return np.asarray(self.canvas.buffer_rgba())

    def rgb(self) -> np.ndarray:
        """The frame's (H, W, 3) uint8 pixels (a copy), drawn by Agg at the figure's size."""
        self.canvas.draw()
        return np.asarray(self.canvas.buffer_rgba())[..., :3].copy()
