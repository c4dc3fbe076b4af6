"""Traits <-> state: the widget's traits say what the state and the source are, and setting a
trait changes them (``ipywidgets.link`` and ``observe`` work both ways).

`TraitSync` copies the state's parameters and the source's settings into the traits
(quietly: the widget copying its own state acts on nothing) and applies a trait a user set to
the state or to the source, recording it.  The source's settings are read through the source
protocol (`settings_of`, `inner_source`), never from its class.
"""

from __future__ import annotations

from ..sources.protocol import inner_source, note_matrix
from .painter import title

__all__ = ["TraitSync", "STATE_TRAITS", "DISPLAY_TRAITS", "FIELD_TRAITS", "STACK_TRAITS", "COLOUR_TRAITS"]

STATE_TRAITS = ("theta0", "alpha", "c0")
DISPLAY_TRAITS = ("ball_radius", "bar_radius", "face_opacity", "background", "show_balls", "show_bars", "show_faces")
#: A field's settings (a stack's inner source's), each a trait of the same name.
FIELD_TRAITS = ("levels", "inside", "caps")
#: A stack's settings, each a trait of the same name.
STACK_TRAITS = ("slices", "spacing", "arrangement")
#: The colour scale of a field's surfaces and colour bar (display settings: saved, not recorded).
COLOUR_TRAITS = ("cmap", "clim")


class TraitSync:
    """Keeps one widget's traits in step with its state and source."""

    def __init__(self, widget):
        self.w = widget
        self.syncing = False  # the widget is copying its own state into the traits

    def observe(self) -> None:
        """Attach the observers (each with ``names=``)."""
        w = self.w
        w.observe(self.on_state_trait, names=list(STATE_TRAITS))
        w.observe(self.on_display_trait, names=list(DISPLAY_TRAITS))
        w.observe(self.on_color_by, names=["color_by", *COLOUR_TRAITS])
        w.observe(self.on_field_trait, names=list(FIELD_TRAITS))
        w.observe(w._stacking.on_stack_trait, names=list(STACK_TRAITS))

    # -- the widget's state into the traits -----------------------------------------------
    def state_traits(self) -> None:
        """Copy the state's parameters into the traits (observers fire for what changed)."""
        w = self.w
        st = w.state
        self.syncing = True
        try:
            w.set_trait("orientation", st.matrix)
            for name in STATE_TRAITS:
                value = getattr(st, name)
                if getattr(w, name) != value:
                    setattr(w, name, value)
        finally:
            self.syncing = False

    def source_traits(self) -> None:
        """Copy the source's settings (a field's levels, inside, caps; a stack's N, spacing and
        arrangement) into the traits of the same names."""
        w = self.w
        inner = inner_source(w.source)
        levels = getattr(inner, "levels", None)
        if levels is not None:
            self.set_quietly("levels", tuple(float(v) for v in levels))
        for name in ("inside", "caps"):
            if hasattr(inner, name):
                self.set_quietly(name, getattr(inner, name))
        if w._stacking.is_stack:
            src = w.source
            self.set_quietly("slices", src.slices)
            self.set_quietly("spacing", float(src.spacing))
            self.set_quietly("arrangement", src.arrangement)

    def set_quietly(self, name, value) -> None:
        """Set a trait without acting on it (the widget copying its own state)."""
        self.syncing = True
        try:
            setattr(self.w, name, value)
        finally:
            self.syncing = False

    # -- traits a user set -----------------------------------------------------------------
    def source_setting(self, change, target, why_not: str) -> None:
        """A trait that is a setting of (part of) the source: set it on ``target`` and redraw,
        or, if ``target`` is None or refuses the value, put the trait back and raise."""
        if self.syncing:
            return
        w = self.w
        with w._pump.lock:
            try:
                if target is None:
                    raise TypeError(why_not)
                with w._source_lock:
                    note_matrix(w.source, w.state.matrix)  # `slices`: a default spacing spread along today's w
                    setattr(target, change["name"], change["new"])
            except Exception:
                self.set_quietly(change["name"], change["old"])
                raise
            w._source_version += 1
            w._keeper.record_source(change["name"], change["new"])
            self.source_traits()
            w._pump.mark_dirty()
            w._pump.flush()

    def on_field_trait(self, change) -> None:
        """``levels``, ``inside``, ``caps``: settings of the (inner) source, where it has them."""
        w = self.w
        name = change["name"]
        inner = inner_source(w.source)
        has = hasattr(inner, name)
        if name == "levels":
            why = f"{title(w.source)} has no iso levels: `levels` applies to field sources"
        else:
            why = f"{title(w.source)} has no `{name}`: it applies to field sources"
        self.source_setting(change, inner if has else None, why)

    def on_state_trait(self, change) -> None:
        if self.syncing:
            return
        w = self.w
        with w._pump.lock:
            setattr(w.state, change["name"], change["new"])
            w._recorder.record_set(change["name"], change["new"])
            if change["name"] == "theta0":  # alpha keeps its ratio to theta0
                self.state_traits()
            w._pump.mark_dirty()
            w._pump.flush()

    def on_display_trait(self, change) -> None:
        w = self.w
        with w._pump.lock:
            if not w._closed:
                w.scene.set_display(**{change["name"]: change["new"]})

    def on_color_by(self, change) -> None:
        """``color_by``, ``cmap``, ``clim``: the same slice in other colours (and the colour bar)."""
        w = self.w
        with w._pump.lock:
            if not w._closed:
                w._pump.mark_dirty()
                w._pump.flush()
