"""A field's keys as the page steps them (issue 36): v / Shift+v (the rendering), a s d and Shift
(the section planes), o / i (the iso levels) -- predicted by the page like the state's keys, the
kernel applying exactly the page's steps (`rot4d_widget.view.pagesteps.PageSteps`).

`FieldKeys` is what `PageSteps` steps besides the `RotationState`: the widget's ``rendering`` and
``sections`` traits and the field's ``levels``, with a snapshot a rebuild returns to exactly.  A
step is the kernel's own step of that key (`rot4d_widget.view.keys.KeyPath.apply_step`: the
rendering and sections through `rot4d_widget.view.renderings.Renderings`, recorded as the traits
they set; the levels through the field's own action, recorded as a step), so a recording and a
replay are what they were.

The page applies the same rules (``page/state.js``): the rendering cycle of `renderings.RENDERINGS`, the
section step (`SECTION_STEP`, rounded to 1/1024, refused at 0 and 1) and the level step
(`rot4d_widget.sources.field.levels.FieldLevels.step_levels`: every level by ``level_step``,
refused beyond the data range widened by one step) with the numbers `view_rules` gives.  The levels
are predicted only while the field's range is known without reading it (in memory, or its coarse
copy made): before that, o / i are the kernel's keys alone.
"""

from __future__ import annotations

from ..core import renderings
from ..sources.field.levels import FieldLevels
from ..sources.protocol import inner_source
from .cuts import can_sample

__all__ = ["FieldKeys", "VIEW_KINDS", "SECTION_STEP", "level_actions", "view_rules"]

#: One key step of a section plane, as a fraction of the cut's extent (`renderings.Renderings.step`).
SECTION_STEP = 1.0 / 32.0
#: The view's own kinds the page steps (for a source with renderings).
VIEW_KINDS = frozenset({"rendering", "section"})


def _levels_known(field) -> bool:
    """The field's data range is known without a read (what the level step is a fiftieth of)."""
    return field.kind in ("numpy", "function") or field.coarse_ready or field.resident is not None


def level_actions(source) -> dict:
    """``{action name: sign}`` of the field's o / i keys the page steps (empty for another source,
    or while the field's range would need a read)."""
    inner = inner_source(source)
    if not isinstance(inner, FieldLevels) or not _levels_known(inner):
        return {}
    acts = inner.actions
    return {acts["o"].name: 1, acts["i"].name: -1}


def view_rules(source) -> dict:
    """The numbers the page steps a field's view by: the renderings in key order, the section step
    and, while the levels are predicted, ``level_step`` and ``level_range`` (`FieldLevels`)."""
    out = {"renderings": list(renderings.RENDERINGS), "section_step": SECTION_STEP}
    inner = inner_source(source)
    if level_actions(source):
        lo, hi = inner.data_range
        out["level_step"] = float(inner.level_step)
        out["level_range"] = [float(lo), float(hi)]
    return out


class FieldKeys:
    """One widget's field view as `PageSteps` steps it (the pump's lock held by every caller)."""

    def __init__(self, traits, showing, renderings, keeper, sync, apply_step):
        self.traits = traits  # the widget's traits: ``rendering``, ``sections``
        self.showing, self.renderings, self.keeper, self.sync = showing, renderings, keeper, sync
        self.apply_step = apply_step  # the kernel's own step of a key (`KeyPath.apply_step`)

    def kinds(self) -> frozenset:
        """The view's kinds the page steps for the source shown (none for a source without renderings)."""
        return VIEW_KINDS if can_sample(self.showing.source) else frozenset()

    def steps(self, action) -> bool:
        """True for an action the page steps here: a view kind of a field, a level key of one."""
        if action.kind in VIEW_KINDS:
            return can_sample(self.showing.source)
        return action.kind == "custom" and action.name in level_actions(self.showing.source)

    def snapshot(self) -> tuple:
        """``(rendering, sections, levels)`` now (levels None for a source without them)."""
        inner = inner_source(self.showing.source)
        levels = tuple(inner.levels) if isinstance(inner, FieldLevels) else None
        return (self.traits.rendering, tuple(self.traits.sections), levels)

    def restore(self, snap: tuple) -> None:
        """Set a `snapshot` back exactly (a rebuild): the traits recorded as they are set."""
        rendering, sections, levels = snap
        self.renderings.set_quietly("rendering", rendering)
        self.renderings.set_quietly("sections", sections)
        inner = inner_source(self.showing.source)
        if levels is not None and isinstance(inner, FieldLevels) and tuple(inner.levels) != levels:
            inner.levels = levels
            self.showing.changed()
            self.keeper.record_changed_settings()
            self.sync.source_traits()

    def apply(self, action, inverted: bool) -> bool:
        """One step of a field key, as the kernel's own path makes it (recorded there)."""
        return self.apply_step(action, inverted)
