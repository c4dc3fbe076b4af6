"""Parallel slices at run time: a single view becomes a stack when `slices` is set (or n pressed).

A stack is a source whose ``wraps`` is not None (the source protocol); this module is where
the view makes one (`rot4d_widget.sources.tomography.StackSource`, oval, default spacing), binds
its keys and keeps its traits in step.  Nothing else in the view asks what kind a source is.
"""

from __future__ import annotations

from ..core.state import without_source_keys
from ..sources.protocol import inner_source
from ..sources.tomography import StackSource

__all__ = ["Stacking", "make_stack", "is_stack"]


def is_stack(source) -> bool:
    """True for a source made around another (its ``wraps`` is not None): parallel slices."""
    return inner_source(source) is not source


def make_stack(source, slices, spacing=None, arrangement="oval", matrix=None):
    """``slices`` parallel slices of ``source`` (raises before anything changes if not allowed), a
    default spacing spread along the w of ``matrix`` (the view's orientation; None: the identity)."""
    return StackSource(source, slices=slices, spacing=spacing, arrangement=arrangement, matrix=matrix)


class Stacking:
    """One widget's single view <-> stack: wraps the source when asked, applies the stack's traits."""

    def __init__(self, showing, state, pump, sync, keeper):
        self.showing, self.state, self.pump, self.sync, self.keeper = showing, state, pump, sync, keeper
        self.keys = None  # `connect`

    def connect(self, keys) -> None:
        """The key path, which binds a stack's keys when a view becomes one."""
        self.keys = keys

    @property
    def is_stack(self) -> bool:
        return is_stack(self.showing.source)

    def wrap(self, slices) -> None:
        """Show ``slices`` parallel slices of the current source from now on (the lock is held).

        The source is wrapped in a stack (oval, default spacing), its keys n / b / g / f join the
        keymap and the help.  Raises before any change if ``slices`` is not allowed.
        """
        stack = make_stack(self.showing.source, slices, matrix=self.state.matrix)
        # the stack brings the inner source's keys too: rebind them from the reserved ones
        self.keys.use_keymap(without_source_keys(self.state.keymap), stack)
        self.showing.replace(stack)  # a new version: nothing sliced from the single view is shown again
        self.sync.source_traits()

    def on_stack_trait(self, change) -> None:
        """``slices``, ``spacing``, ``arrangement``: a stack's settings; ``slices`` on a single
        view wraps it first."""
        sync = self.sync
        if change["name"] == "slices" and not sync.syncing and not self.is_stack and change["new"] is not None:
            with self.pump.lock:  # parallel slices asked for at run time: wrap the source now
                try:
                    self.wrap(change["new"])
                except Exception:
                    sync.set_quietly("slices", change["old"])
                    raise
                self.keeper.record_source("slices", change["new"])
                self.pump.mark_dirty()
                self.pump.flush()
            return
        sync.source_setting(change, self.showing.source if self.is_stack else None,
                            f"`{change['name']}` applies to parallel slices: set `slices` (or press n) first")
