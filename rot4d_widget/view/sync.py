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
from .stacking import is_stack

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

    def __init__(self, traits, showing, state, pump, scene, keeper):
        self.traits = traits  # the widget's traits, kept in step
        self.showing, self.state, self.pump, self.scene, self.keeper = showing, state, pump, scene, keeper
        self.syncing = False  # the widget is copying its own state into the traits

    def observe(self) -> None:
        """Attach the observers (each with ``names=``)."""
        self.traits.observe(self.on_state_trait, names=list(STATE_TRAITS))
        self.traits.observe(self.on_display_trait, names=list(DISPLAY_TRAITS))
        self.traits.observe(self.on_color_by, names=["color_by", *COLOUR_TRAITS])
        self.traits.observe(self.on_field_trait, names=list(FIELD_TRAITS))

    # -- the widget's state into the traits -----------------------------------------------
    def state_traits(self) -> None:
        """Copy the state's parameters into the traits (observers fire for what changed)."""
        st = self.state
        self.syncing = True
        try:
            self.traits.set_trait("orientation", st.matrix)
            for name in STATE_TRAITS:
                value = getattr(st, name)
                if getattr(self.traits, name) != value:
                    setattr(self.traits, name, value)
        finally:
            self.syncing = False

    def source_traits(self) -> None:
        """Copy the source's settings (a field's levels, inside, caps; a stack's N, spacing and
        arrangement) into the traits of the same names."""
        inner = inner_source(self.showing.source)
        levels = inner.levels
        if levels is not None:
            self.set_quietly("levels", tuple(float(v) for v in levels))
        for name in ("inside", "caps"):
            if getattr(inner, name) is not None:  # inside, caps: a field's (None: the protocol's default)
                self.set_quietly(name, getattr(inner, name))
        if is_stack(self.showing.source):
            src = self.showing.source
            self.set_quietly("slices", src.slices)
            self.set_quietly("spacing", float(src.spacing))
            self.set_quietly("arrangement", src.arrangement)

    def set_quietly(self, name, value) -> None:
        """Set a trait without acting on it (the widget copying its own state)."""
        self.syncing = True
        try:
            setattr(self.traits, name, value)
        finally:
            self.syncing = False

    # -- traits a user set -----------------------------------------------------------------
    def source_setting(self, change, target, why_not: str) -> None:
        """A trait that is a setting of (part of) the source: set it on ``target`` and redraw,
        or, if ``target`` is None or refuses the value, put the trait back and raise."""
        if self.syncing:
            return
        with self.pump.lock:
            try:
                if target is None:
                    raise TypeError(why_not)
                with self.showing.lock:
                    note_matrix(self.showing.source, self.state.matrix)  # `slices`: a default spacing along today's w
                    setattr(target, change["name"], change["new"])
            except Exception:
                self.set_quietly(change["name"], change["old"])
                raise
            self.showing.changed()
            self.keeper.record_source(change["name"], change["new"])
            self.source_traits()
            self.pump.mark_dirty()
            self.pump.flush()

    def on_field_trait(self, change) -> None:
        """``levels``, ``inside``, ``caps``: settings of the (inner) source, where it has them."""
        name = change["name"]
        inner = inner_source(self.showing.source)
        has = getattr(inner, name) is not None  # levels, inside, caps: None where a source has none
        if name == "levels":
            why = f"{title(self.showing.source)} has no iso levels: `levels` applies to field sources"
        else:
            why = f"{title(self.showing.source)} has no `{name}`: it applies to field sources"
        self.source_setting(change, inner if has else None, why)

    def on_state_trait(self, change) -> None:
        if self.syncing:
            return
        with self.pump.lock:
            setattr(self.state, change["name"], change["new"])
            self.keeper.recorder.record_set(change["name"], change["new"])
            if change["name"] == "theta0":  # alpha keeps its ratio to theta0
                self.state_traits()
            self.pump.mark_dirty()
            self.pump.flush()

    def on_display_trait(self, change) -> None:
        with self.pump.lock:
            if not self.pump.closed:
                self.scene.set_display(**{change["name"]: change["new"]})

    def on_color_by(self, change) -> None:
        """``color_by``, ``cmap``, ``clim``: the same slice in other colours (and the colour bar)."""
        with self.pump.lock:
            if not self.pump.closed:
                self.pump.mark_dirty()
                self.pump.flush()
