"""A field's rendering and its section planes: the ``rendering`` and ``sections`` traits and the
keys that change them (v cycles the rendering, Shift+v backwards; a, s, d move the x, y, z
section plane, Shift back).

Both are view settings: they change what the scene shows of the same cut, not the state or the
source.  The "sections" rendering is seen from `camera.SECTIONS_CAMERA_POSITION` (no plane
edge-on) while the camera is where the rendering before left it by default; a camera the user
moved stays.  Every change, by trait or key, redraws; the keeper records it (it watches the traits:
`rot4d_widget.view.keeping.Keeper`), so a replay and an animation draw the same.  A source that
cannot give its cut on a grid (no ``sample`` in the source protocol: polytopes) has only the
surface rendering: setting another is a ValueError that says so, and the keys do nothing there.
"""

from __future__ import annotations

from ..core import camera, renderings
from ..core.rotation import quaternion_xyzw
from .cuts import can_sample
from .fieldkeys import SECTION_STEP
from .painter import title

__all__ = ["Renderings", "SECTION_STEP"]


class Renderings:
    """One widget's rendering and sections: trait observers and key steps."""

    def __init__(self, traits, showing, scene, pump):
        self.traits = traits  # the widget's traits: ``rendering``, ``sections``
        self.showing, self.scene, self.pump = showing, scene, pump

    def observe(self) -> None:
        self.traits.observe(self.on_trait, names=["rendering", "sections"])
        self.follow_camera("surface", self.traits.rendering)  # made to show sections: seen at a slant

    def follow_camera(self, old: str, new: str) -> None:
        """The camera to ``new``'s default (`camera.default_eye`: sections at a slant, so that all three
        planes show) when it is at ``old``'s, i.e. the user has not moved it; else left alone.  The
        camera (the canvas's) gets its position and its turn in one message -- three.js turns no
        camera that moves -- looking at the origin, +y up (`camera.view_rotation`, the static
        pictures' look-at); the scene's eye callbacks follow (the faces re-sent in their order)."""
        scene = self.scene
        before, after = camera.default_eye(old), camera.default_eye(new)
        if before != after and all(abs(a - b) < 1e-9 for a, b in zip(scene.eye, before)):
            cam = scene.canvas.camera
            with cam.hold_sync():
                cam.quaternion = quaternion_xyzw(camera.view_rotation(after).T)
                cam.position = [float(v) for v in after]

    # -- traits -----------------------------------------------------------------------------
    def on_trait(self, change) -> None:
        """A user set ``rendering`` or ``sections``: checked against the source, drawn, recorded."""
        name, new = change["name"], change["new"]
        if name == "rendering" and new != "surface" and not can_sample(self.showing.source):
            self.traits.set_trait("rendering", change["old"])
            raise ValueError(f"rendering={new!r} needs a field (a source with `sample`, the cut on a grid); "
                             f"{title(self.showing.source)} has only rendering='surface'")
        with self.pump.lock:
            if self.pump.closed:
                return
            if name == "rendering":
                self.follow_camera(change["old"], new)
            self.pump.mark_dirty()
            self.pump.flush()

    # -- keys -------------------------------------------------------------------------------
    def step(self, action, inverted: bool) -> bool:
        """One step of a "rendering" or "section" key; True if it changed the view (the caller,
        holding the pump's lock, redraws)."""
        if not can_sample(self.showing.source):
            return False
        direction = -1 if inverted else 1
        if action.kind == "rendering":
            order = renderings.RENDERINGS
            old = self.traits.rendering
            new = order[(order.index(old) + direction * action.sign) % len(order)]
            self._set("rendering", new)
            self.follow_camera(old, new)
            return True
        axis = "xyz".index(action.name)
        pos = list(self.traits.sections)
        moved = min(1.0, max(0.0, round((pos[axis] + direction * action.sign * SECTION_STEP) * 1024) / 1024))
        if moved == pos[axis]:
            return False  # at the edge: refused, not clamped, so the opposite key undoes every step
        pos[axis] = moved
        self._set("sections", tuple(pos))
        return True

    def set_quietly(self, name, value) -> None:
        """Set ``rendering`` or ``sections`` without the observer's redraw (the caller marks the picture
        dirty; the keeper records the trait); nothing when it holds that value."""
        if getattr(self.traits, name) != value:
            self._set(name, value)

    def _set(self, name, value) -> None:
        """Set the trait from a key (the pump's lock is held: the observer's redraw waits for it)."""
        self.traits.unobserve(self.on_trait, names=[name])
        try:
            setattr(self.traits, name, value)
        finally:
            self.traits.observe(self.on_trait, names=[name])
