"""The progress bar a kernel shows: an ipywidgets ``IntProgress`` and a label ("12/33, 4 s").

`rot4d_widget.core.progress` counts and decides when to show; this module draws in a kernel and
registers itself there on import (`rot4d_widget.core.progress.register_widget_bar`).
"""

from __future__ import annotations

import ipywidgets
from IPython.display import display

from ..core.progress import register_widget_bar

__all__ = ["WidgetBar"]


class WidgetBar:
    """An ``IntProgress`` with a label, displayed in the cell's output when first shown."""

    def __init__(self, total: int, description: str = ""):
        self.bar = ipywidgets.IntProgress(value=0, min=0, max=max(int(total), 1), description=description[:20])
        self.label = ipywidgets.Label()
        display(ipywidgets.HBox([self.bar, self.label]))

    def show(self, count: int, text: str) -> None:
        self.bar.value = count
        self.label.value = text

    def close(self, done: bool) -> None:
        self.bar.bar_style = "success" if done else ""


register_widget_bar(WidgetBar)
