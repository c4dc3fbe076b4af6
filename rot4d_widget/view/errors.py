"""The widget's ``errors`` area: exceptions raised while handling keys and updates, shown, never lost.

A callback's exception must not escape into the event loop (JupyterLab would show nothing):
it is logged and shown in an ``ipywidgets.Output`` under the readout.  The area shows what
went wrong since the last good picture: the next update that is sent clears it.
"""

from __future__ import annotations

import logging
import traceback

from ..sources.protocol import BadSlice

__all__ = ["ErrorArea", "MAX_ERRORS_SHOWN"]

log = logging.getLogger("rot4d_widget.view.widget")

#: How many error reports the ``errors`` area keeps.
MAX_ERRORS_SHOWN = 5


class ErrorArea:
    """Reports into ``output`` (an ipywidgets Output, set once built); held keys stop on an error."""

    def __init__(self, repeater, max_shown: int = MAX_ERRORS_SHOWN):
        self.output = None
        self._repeater = repeater
        self.max_shown = max_shown
        self._update_errors = ()  # error reports of failed updates: cleared by the next good one

    def report(self, exc: BaseException) -> None:
        """Show an exception in the area (and the log); never raises."""
        try:
            text = "".join(traceback.format_exception(type(exc), exc, exc.__traceback__))
            log.error("Rot4DWidget: error while handling a key\n%s", text)
            self._repeater.clear()
            if isinstance(exc, BadSlice):  # the source's fault, said in one line: no traceback of ours
                text = f"{type(exc).__name__}: {exc}\n"
            shown = tuple(self.output.outputs)
            if shown and shown[-1].get("text") == text:
                return  # the same error again (a retry of the same picture): shown once
            item = {"output_type": "stream", "name": "stderr", "text": text}
            self.output.outputs = shown[-(self.max_shown - 1):] + (item,)
            self._update_errors = self.output.outputs
        except Exception:
            log.exception("Rot4DWidget: could not report an error")

    def clear_update_errors(self) -> None:
        """A good picture was sent: the errors of failed updates go."""
        if not self._update_errors:
            return
        shown, self._update_errors = self._update_errors, ()
        if tuple(self.output.outputs) == tuple(shown):
            self.output.outputs = ()
