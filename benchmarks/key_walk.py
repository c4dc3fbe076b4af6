"""The rooms one key press walks through: the package's modules in call order, and its climbs back up.

    python benchmarks/key_walk.py                      # this checkout
    PYTHONPATH=<old checkout> python benchmarks/key_walk.py   # an older one (e.g. a worktree of 7ba6e62)

One keydown of "4" on a 24-cell view (no ticker, a fixed clock) is traced with ``sys.setprofile``:
each call into a rot4d_widget function names its module; consecutive calls in one module are one
visit.  Printed: the module sequence, the same folded to wings (core, geometry, sources, keep,
view; an older flat module is placed in the wing it moved to, by ``rot4d_widget._MOVED`` of this
checkout's table below), the number of wing changes and of "climbs back up" (a step to a higher
wing: the walk returning to or calling back into a wing it came down from).
"""

from __future__ import annotations

import sys
import warnings

RANK = {"core": 0, "geometry": 1, "sources": 2, "keep": 3, "view": 4}
#: flat module (before the wings) -> its wing
FLAT = {"rotation": "core", "keymap": "core", "state": "core", "look": "core", "_arrays": "core",
        "progress": "core", "polytopes": "geometry", "uniform": "geometry", "slicing": "geometry",
        "offfile": "geometry", "source": "sources", "fields": "sources", "tomography": "sources",
        "datasets": "sources", "export": "keep", "recording": "keep", "figures": "keep", "widget": "view",
        "scene": "view", "buffers": "view", "companion": "view", "pump": "view", "keyhold": "view",
        "readout": "view"}


def wing(module: str) -> str:
    parts = module.split(".")
    if len(parts) > 1 and parts[1] in RANK:
        return parts[1]
    return FLAT.get(parts[-1], "?")


def main() -> None:
    warnings.simplefilter("ignore")
    from rot4d_widget import Rot4DWidget

    kwargs = {"_autotick": False, "_clock": lambda: 0.0} if "_autotick" in Rot4DWidget.__init__.__code__.co_varnames else {}
    w = Rot4DWidget("24-cell", **kwargs)
    seq: list = []

    def prof(frame, event, arg):
        if event == "call":
            mod = frame.f_globals.get("__name__", "")
            if mod.startswith("rot4d_widget") and (not seq or seq[-1] != mod):
                seq.append(mod)

    event = {"type": "keydown", "key": "4", "code": "Digit4", "shiftKey": False, "repeat": False, "timeStamp": 1000.0}
    sys.setprofile(prof)
    try:
        w._handle_event(event)
    finally:
        sys.setprofile(None)
        w.close()
    short = [m.replace("rot4d_widget.", "") for m in seq]
    print("modules:", " -> ".join(short))
    print(f"  {len(set(seq))} modules, {len(seq) - 1} steps between them")
    wings = []
    for m in seq:
        x = wing(m)
        if not wings or wings[-1] != x:
            wings.append(x)
    climbs = sum(RANK.get(b, 9) > RANK.get(a, 9) for a, b in zip(wings, wings[1:]))
    print("wings:", " -> ".join(wings))
    print(f"  {len(wings) - 1} wing changes, {climbs} climbs back up")


if __name__ == "__main__":
    main()
