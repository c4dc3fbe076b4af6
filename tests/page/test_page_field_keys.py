"""A field's keys are predicted like the state's (issue 36): v / Shift+v, a s d (Shift back) and
o / i pressed and held over the view step the page's copy (page/predict.js, page/state.js) and the
kernel (`rot4d_widget.view.pagesteps.PageSteps` through `rot4d_widget.view.fieldkeys.FieldKeys`)
alike; the page, given the kernel's config and state and the same key events, ends on the
kernel's rendering, section planes and levels exactly, and the kernel's recording replays there."""

from __future__ import annotations

import numpy as np
import pytest
from page_node import run_page
from test_widget import down, key_event, up

from rot4d_widget import Field4D

pytestmark = pytest.mark.usefixtures("recording_comms")

SCRIPT = """
import { Prediction } from "page:predict.js";
import { keyId } from "page:keymap.js";
const p = new Prediction(INPUT.config, INPUT.kernel);
for (const e of INPUT.events) {
  if (e.type === "keydown") {
    const mine = p.ours(e, keyId(e));
    if (mine) p.press(mine.kid, mine.action, mine.inverted, e.timeStamp);
  } else {
    p.release(keyId(e), e.timeStamp);
  }
}
p.advance(INPUT.end);
const v = p.state.view;
console.log(JSON.stringify({ rendering: v.rendering, sections: v.sections, levels: v.levels, pending: p.pending }));
"""


def _field():
    x = np.linspace(-1, 1, 10)
    X, Y, Z, T = np.meshgrid(x, x, x, x, indexing="ij")
    return Field4D((X + 0.3 * Y + T).astype(np.float32), axes="xyzw", extent=[(-1, 1)] * 4, levels=[0.1, 0.6])


# (key, shift, down s, up s): taps, holds that repeat (a, o), holds that reach a bound (i), overlaps
PRESSES = [("v", False, 1.0, 1.05), ("v", True, 1.3, 1.32), ("v", False, 1.5, 1.55), ("a", False, 2.0, 2.6),
           ("s", True, 2.2, 2.4), ("d", False, 3.0, 3.02), ("o", False, 3.5, 4.3), ("4", False, 3.6, 3.9),
           ("i", False, 5.0, 8.5), ("o", False, 9.0, 9.05), ("a", True, 9.2, 9.8), ("v", False, 10.0, 10.05)]


def test_the_page_steps_a_field_s_keys_as_the_kernel_does(make):
    w = make(_field(), rendering="volume")
    assert {"rendering", "section"} <= set(w.companion.config["predicted_kinds"])
    assert set(w.companion.config["predicted_actions"]) == {"level up", "level down"}
    kernel = dict(w.companion.kernel_state)
    events = []
    for key, shift, t0, t1 in PRESSES:
        events.append(key_event("keydown", key.upper() if shift else key, code=f"Key{key.upper()}" if key.isalpha()
                                else f"Digit{key}", shift=shift, t=t0))
        events.append(key_event("keyup", key.upper() if shift else key, code=f"Key{key.upper()}" if key.isalpha()
                                else f"Digit{key}", shift=shift, t=t1))
    events.sort(key=lambda e: e["timeStamp"])
    for e in events:
        (down if e["type"] == "keydown" else up)(w, e["key"], code=e["code"], shift=e["shiftKey"],
                                                  t=e["timeStamp"] / 1000.0)
    page = run_page(SCRIPT, {"config": w.companion.config, "kernel": kernel, "events": events, "end": 20000.0})
    assert page["rendering"] == w.rendering
    assert tuple(page["sections"]) == tuple(w.sections)
    assert tuple(page["levels"]) == tuple(w.levels)  # bit for bit: the same steps in the same order
    assert w.rendering != "volume" and w.sections != (0.5, 0.5, 0.5)
    assert w.levels[0] < 0.1 and w.levels[0] == pytest.approx(w.source.data_range[0] - w.source.level_step, abs=0.2)
    again = make(_field(), rendering="volume")
    again.replay(w.recording)
    assert (again.rendering, again.sections, again.levels) == (w.rendering, w.sections, w.levels)
    assert np.array_equal(again.state.matrix, w.state.matrix)


def test_the_levels_are_the_kernel_s_keys_while_the_field_s_range_needs_a_read(make, monkeypatch):
    from rot4d_widget.view import fieldkeys

    monkeypatch.setattr(fieldkeys, "_levels_known", lambda field: False)
    w = make(_field(), rendering="volume")
    assert w.companion.config["predicted_actions"] == {}
    assert "level_step" not in w.companion.kernel_state["state"]["view"]
