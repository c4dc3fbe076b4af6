"""A field's rendering and its section planes: the ``rendering`` and ``sections`` traits and the
keys that change them (v cycles the rendering, Shift+v backwards; a, s, d move the x, y, z
section plane, Shift back).

Both are view settings: they change what the scene shows of the same cut, not the state or the
source.  Every change, by trait or key, redraws; the keeper records it (it watches the traits:
`rot4d_widget.view.keeping.Keeper`), so a replay and an animation draw the same.  A source that
cannot give its cut on a grid (no ``sample`` in the source protocol: polytopes) has only the
surface rendering: setting another is a ValueError that says so, and the keys do nothing there.
"""

from __future__ import annotations

from ..core import look
from .cuts import can_sample
from .fieldkeys import SECTION_STEP
from .painter import title

__all__ = ["Renderings", "SECTION_STEP"]


class Renderings:
    """One widget's rendering and sections: trait observers and key steps."""

    def __init__(self, widget):
        self.w = widget

    def observe(self) -> None:
        self.w.observe(self.on_trait, names=["rendering", "sections"])

    # -- traits -----------------------------------------------------------------------------
    def on_trait(self, change) -> None:
        """A user set ``rendering`` or ``sections``: checked against the source, drawn, recorded."""
        w = self.w
        name, new = change["name"], change["new"]
        if name == "rendering" and new != "surface" and not can_sample(w.source):
            w.set_trait("rendering", change["old"])
            raise ValueError(f"rendering={new!r} needs a field (a source with `sample`, the cut on a grid); "
                             f"{title(w.source)} has only rendering='surface'")
        with w._pump.lock:
            if w._closed:
                return
            w._pump.mark_dirty()
            w._pump.flush()

    # -- keys -------------------------------------------------------------------------------
    def step(self, action, inverted: bool) -> bool:
        """One step of a "rendering" or "section" key; True if it changed the view (the caller,
        holding the pump's lock, redraws)."""
        w = self.w
        if not can_sample(w.source):
            return False
        direction = -1 if inverted else 1
        if action.kind == "rendering":
            order = look.RENDERINGS
            new = order[(order.index(w.rendering) + direction * action.sign) % len(order)]
            self._set("rendering", new)
            return True
        axis = "xyz".index(action.name)
        pos = list(w.sections)
        moved = min(1.0, max(0.0, round((pos[axis] + direction * action.sign * SECTION_STEP) * 1024) / 1024))
        if moved == pos[axis]:
            return False  # at the edge: refused, not clamped, so the opposite key undoes every step
        pos[axis] = moved
        self._set("sections", tuple(pos))
        return True

    def set_quietly(self, name, value) -> None:
        """Set ``rendering`` or ``sections`` without the observer's redraw (the caller marks the picture
        dirty; the keeper records the trait); nothing when it holds that value."""
        if getattr(self.w, name) != value:
            self._set(name, value)

    def _set(self, name, value) -> None:
        """Set the trait from a key (the pump's lock is held: the observer's redraw waits for it)."""
        w = self.w
        w.unobserve(self.on_trait, names=[name])
        try:
            setattr(w, name, value)
        finally:
            w.observe(self.on_trait, names=[name])
